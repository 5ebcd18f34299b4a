//! Benchmarks of pdeshape: the papers' tables beside ours (`tables`) and the scaling study
//! (`scaling`), which `pdeshape bench` prints, and the criterion benches of the SPEC §10
//! and issue targets (`benches/surfaces.rs`). A layer above `pdeshape-io`: nothing below
//! depends on it.
#![warn(missing_docs)]

pub mod scaling;
pub mod tables;
