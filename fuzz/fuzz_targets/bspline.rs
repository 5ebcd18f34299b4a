//! B-spline input: any control points, degree, closure and range build a curve or fail
//! with an error; a built curve evaluates with derivatives everywhere.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| pdeshape_fuzz::bspline(data));
