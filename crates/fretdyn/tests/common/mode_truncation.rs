//! The clamped tube of `examples/tube_clamped_one_support.toml` with its modes truncated, as
//! the mode-convergence test (`tests/tube_modal_physical.rs`) and the figure of
//! docs/VERIFICATION.md (`crates/fretdyn-cli/examples/mode_convergence.rs`) both run it.

/// The example with `n` modes, 0.1 s at Δt = 1e-6 s (stable with every mode), statistics over
/// the whole run: set by key path, whatever the example's own durations.
pub fn with_modes(text: &str, n: usize) -> String {
    use fretdyn::case::key_path::{KeyPath, Missing};
    let mut case = toml::Value::Table(text.parse().expect("example case"));
    let n = toml::Value::Integer(n as i64);
    for (key, value) in [
        ("structure.modes", n),
        ("time.duration", 0.1.into()),
        ("time.dt", 1e-6.into()),
        ("statistics.t_start", 0.0.into()),
    ] {
        let path = KeyPath::parse(key).expect("a key path");
        path.set(&mut case, &value, Missing::Create)
            .expect("settable");
    }
    toml::to_string(&case).expect("a TOML table")
}
