//! B-spline input: any control points, degree, closure and range build a curve or fail
//! with an error; a built curve evaluates with derivatives everywhere.
#![no_main]
use libfuzzer_sys::fuzz_target;
use pdeshape_core::Vec3;
use pdeshape_core::data::{BSplineCurve, Field};

fuzz_target!(|data: &[u8]| {
    if data.len() < 4 {
        return;
    }
    let degree = data[0] as usize % 9;
    let closed = data[1] & 1 == 1;
    let r0 = (data[2] as f64 - 128.0) / 16.0;
    let r1 = (data[3] as f64 - 128.0) / 16.0;
    let pts: Vec<Vec3> = data[4..]
        .chunks_exact(3)
        .map(|c| Vec3::new((c[0] as f64 - 128.0) / 8.0, (c[1] as f64 - 128.0) / 8.0, (c[2] as f64 - 128.0) / 8.0))
        .collect();
    let Ok(b) = BSplineCurve::new(pts, degree, closed, (r0, r1)) else { return };
    for k in 0..=16 {
        let v = r0 + (r1 - r0) * k as f64 / 16.0;
        let _ = b.eval(&[v, 0.0]);
        let _ = b.derivatives(v, 4);
    }
});
