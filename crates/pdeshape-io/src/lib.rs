//! # pdeshape-io
//!
//! Scene files, exporters and pictures for pdeshape: everything that touches a file
//! format. The mathematics lives in `pdeshape-core`.

#![warn(missing_docs)]

pub mod cad;
pub mod export;
pub mod holes;
pub mod import;
pub mod mesh_holes;
pub mod model;
pub mod render;
pub mod sample;
pub mod scene;
