//! The fuzz targets' bodies: each takes arbitrary bytes and asserts "no panic" (and the
//! target's own properties). The libFuzzer binaries in `fuzz_targets/` call them; the
//! workspace's test `crates/pdeshape/tests/fuzz_replay.rs` includes this file and replays
//! the seed corpora and every crash input kept in `regressions/`, so the bodies are
//! compiled and run by `cargo test` too.
use pdeshape_core::Vec3;
use pdeshape_core::data::{BSplineCurve, Field};
use pdeshape_core::expr::Expr;
use pdeshape_core::jet::{Jet, JetShape};
use pdeshape_core::limits::Limits;
use pdeshape_core::trim::{LaplaceMap, Rect, TrimCurve, TrimOptions, TrimRegion, count_folds, trim_grid};
use pdeshape_io::scene::Scene;
use pdeshape_io::scene::{LoadOptions, edit};

/// Expression parser and evaluator: any text parses or fails with an error, and a parsed
/// expression evaluates (values and Taylor jets) without panicking.
pub fn expr(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(e) = Expr::parse(text) else { return };
    let Ok(b) = e.bind(&["u", "v", "t"], &|n| if n == "a" { Some(1.5) } else { None }) else { return };
    let _ = b.eval(&[0.3, -1.2, 2.0]);
    let shape = JetShape::new(&[3, 2, 1]);
    let vars = [Jet::variable(shape, 0, 0.3), Jet::variable(shape, 1, -1.2), Jet::variable(shape, 2, 2.0)];
    let _ = b.eval_jet(&vars);
    let _ = pdeshape_core::expr::expand(&b);
}

/// Scene loader: any text loads or fails with a located error; never a panic.
pub fn scene(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = Scene::parse(text, "fuzz.toml", "fuzz", &Default::default());
}

/// B-spline input: any control points, degree, closure and range build a curve or fail
/// with an error; a built curve evaluates with derivatives everywhere.
pub fn bspline(data: &[u8]) {
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
}

/// Trim-curve input: any ellipses, B-spline or polygon control points in (u, v) either
/// give a validated region whose map meshes into an unfolded grid with ring 0 on the trim
/// loop, or fail with a `TrimError`; never a panic, a hang or a folded grid.
pub fn trim(data: &[u8]) {
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
}

/// The editor's path for whole scenes: the first line is a JSON array of edits (as the
/// page sends them), the rest the scene text; the edits are applied, the scene is loaded
/// under small caps and every patch is meshed. Any input gives a scene or an error.
pub fn edit(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let (first, scene) = text.split_once('\n').unwrap_or((text, ""));
    let Ok(edits) = serde_json::from_str::<Vec<edit::Edit>>(first) else { return };
    let Ok(text) = edit::apply(scene, &edits) else { return };
    let _ = edit::editables(&text);
    let limits = Limits {
        order: 16,
        modes: 32,
        collocation: 5_000,
        vertices: 20_000,
        memory: 64,
        scene: 1,
        model: 1,
        entities: 10_000,
    };
    let opts = LoadOptions { limits, ..Default::default() };
    let Ok(s) = pdeshape_io::scene::Scene::parse_with(&text, "fuzz.toml", "fuzz", &opts) else { return };
    for p in &s.patches {
        let _ = pdeshape_io::model::editor_mesh(p, Some(0.5));
    }
}
