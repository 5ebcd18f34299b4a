//! Models from other programs in: each format a module yielding the core's values
//! (`pdeshape_core::brep::Brep` for CAD files).

pub mod mesh;
pub mod step;
