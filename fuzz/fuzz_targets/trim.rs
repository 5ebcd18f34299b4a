//! Trim-curve input: any ellipses, B-spline or polygon control points in (u, v) either
//! give a validated region whose map meshes into an unfolded grid with ring 0 on the trim
//! loop, or fail with a `TrimError`; never a panic, a hang or a folded grid.
#![no_main]
use libfuzzer_sys::fuzz_target;
use pdeshape_core::trim::{LaplaceMap, Rect, TrimCurve, TrimOptions, TrimRegion, count_folds, trim_grid};

fuzz_target!(|data: &[u8]| {
    if data.len() < 3 {
        return;
    }
    let domain = Rect { min: [0.0, 0.0], max: [1.0, 1.0 + data[0] as f64 / 64.0] };
    let rings = 2 + data[1] as usize % 12;
    let columns = 8 + data[2] as usize % 56;
    let at = |b: u8| b as f64 / 255.0;
    let mut curves = Vec::new();
    let mut rest = &data[3..];
    while let Some((&kind, tail)) = rest.split_first() {
        let n = 3 + (kind >> 2) as usize % 8;
        let take = match kind % 3 {
            0 => 4,
            _ => 2 * n,
        };
        if tail.len() < take || curves.len() == 4 {
            break;
        }
        let (bytes, next) = tail.split_at(take);
        rest = next;
        let pts: Vec<[f64; 2]> = bytes.chunks_exact(2).map(|c| [at(c[0]), at(c[1]) * domain.max[1]]).collect();
        let curve = match kind % 3 {
            0 => Ok(TrimCurve::ellipse(pts[0], [at(bytes[2]) * 0.5, at(bytes[3]) * 0.5])),
            1 => TrimCurve::bspline(&pts),
            _ => TrimCurve::polygon(&pts),
        };
        let Ok(c) = curve else { return };
        curves.push((format!("c{}", curves.len()), c));
    }
    if curves.is_empty() {
        return;
    }
    let Ok(region) = TrimRegion::new(domain, curves) else { return };
    let map = LaplaceMap::new(region, 8, Some(columns));
    let o = TrimOptions { rings, columns, modes: 8, max_sweeps: 200, verify: true };
    if let Ok(g) = trim_grid(&map, &o) {
        assert_eq!(count_folds(&g.points, rings, columns), 0, "a folded grid was returned");
        assert!(g.points.iter().all(|p| p[0].is_finite() && p[1].is_finite()));
        for j in 0..columns {
            let q = g.points[g.index(0, j)];
            assert!(map.region().loop_distance(q) < 1e-9, "ring 0 left the trim loop at column {j}");
        }
    }
});
