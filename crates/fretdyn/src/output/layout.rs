//! The names of a run folder's files, the `.npy` layout of its series and what `results.nc`
//! says besides its arrays: shared by [`super::stream`], which writes them, and `netcdf`, which
//! packs them.

/// File names in a run folder.
pub const SERIES_DIR: &str = "series";
pub const CHECKPOINT_FILE: &str = "checkpoint.bin";
pub const IMPACTS_FILE: &str = "impacts.csv";
pub const BLOCKS_FILE: &str = "blocks.csv";
pub const RESULTS_FILE: &str = "results.npz";
/// `results.nc`, written with the `netcdf` feature (`output/netcdf.rs`).
pub const NETCDF_FILE: &str = "results.nc";

/// The global attributes of `results.nc` that the library does not know: a front end gives
/// them through [`StreamObserver::metadata`]. Without the `netcdf` feature, not used.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ResultsMetadata {
    /// The case's title.
    pub title: Option<String>,
    /// The text of the case file (TOML).
    pub case_toml: Option<String>,
    /// The text of `summary.json`.
    pub summary_json: Option<String>,
}

/// Element type of a series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Dtype {
    F64,
    I8,
}

impl Dtype {
    pub(crate) fn descr(self) -> &'static str {
        match self {
            Dtype::F64 => "<f8",
            Dtype::I8 => "|i1",
        }
    }

    pub(crate) fn size(self) -> u64 {
        match self {
            Dtype::F64 => 8,
            Dtype::I8 => 1,
        }
    }
}

/// Header room of the `.npy` files: fixed, so that the row count can be rewritten in place.
pub(crate) const NPY_HEADER: usize = 256;
