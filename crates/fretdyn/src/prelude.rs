//! The public API in one import: `use fretdyn::prelude::*;` (the crate doc's table).

pub use crate::{
    Case, Error, LifeResults, LifeSettings, Model, Result, RunResults, RunSettings, StreamObserver,
    StreamSettings, Study, resume, run, service_life, simulate,
};
