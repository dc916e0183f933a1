//! Criterion benchmarks of fretdyn's time step: `cargo bench -p fretdyn-bench --bench step`.
//!
//! They live in their own crate, outside the workspace's default members, because criterion's
//! dependencies switch on features of crates fretdyn shares (serde, syn): in the library's own
//! dev-dependencies they made `cargo test --release` rebuild ~50 crates after
//! `cargo run --release`. The benchmarks are in `benches/step.rs`; this library is empty.
