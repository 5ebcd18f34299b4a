//! Trim-curve input: any ellipses, B-spline or polygon control points in (u, v) either
//! give a validated region whose map meshes into an unfolded grid with ring 0 on the trim
//! loop, or fail with a `TrimError`; never a panic, a hang or a folded grid.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| pdeshape_fuzz::trim(data));
