//! Every scene file under examples/ is built and checked: it parses, meshes without
//! non-finite values, meets its conditions to 1e-10 (relative) at 1000 v samples, and
//! renders.

mod common;

use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::path::PathBuf;

#[test]
fn every_example_builds_and_meets_its_conditions() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut visited = Vec::new();
    let mut keys = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        visited.push(path.file_stem().unwrap().to_string_lossy().into_owned());
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.patches.is_empty(), "{}: no patches", path.display());
        let meshes = model::patch_meshes(&scene).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for m in &meshes {
            m.check_finite().unwrap();
        }
        let d = model::scene_diagnostics(&scene);
        common::key_paths(&d.to_json(), "", &mut keys);
        for p in &d.patches {
            // `<=` is false for NaN
            let e = p.condition_error.max_rel;
            assert!(e <= 1e-10, "{}: patch {} misses its conditions by {e:e}", path.display(), p.name);
        }
        let mut small = scene;
        small.render.size = (64, 48);
        let img = model::render_scene(&small).unwrap();
        // one 64 × 48 picture, or a strip of panels for an order study of blends
        assert!(img.width >= 64 && img.height >= 48, "{}: {} × {}", path.display(), img.width, img.height);
        assert_eq!(img.data.len(), (img.width * img.height * 4) as usize);
        assert!(img.data.chunks(4).any(|px| px[..3] != img.data[..3]), "{}: a blank picture", path.display());
    }
    // every example named here was built and checked (a new example is added to the list)
    visited.sort();
    assert_eq!(visited, EXAMPLES);
    // `check --json` keeps its keys: the union over the examples of every key path of the
    // report equals the list written from the report before it was typed (hand-built JSON)
    let want: std::collections::BTreeSet<String> =
        include_str!("data/report_keys.txt").lines().map(str::to_string).collect();
    let missing: Vec<_> = want.difference(&keys).collect();
    let extra: Vec<_> = keys.difference(&want).collect();
    assert!(missing.is_empty() && extra.is_empty(), "report keys: missing {missing:?}, new {extra:?}");
}

/// Every example's patches evaluated at 10⁴ pseudo-random parameters in batches
/// (`Surface::points_at`, `firsts_at`: no row cache; spectral patches fold their modes)
/// equal the pointwise `Surface::derivatives` to round-off: the largest difference, over
/// the points, relative to the largest magnitude of the value, `X_u` and `X_v`.
#[test]
fn every_example_evaluates_the_same_in_batches() {
    use pdeshape_core::Vec3;
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut seen = 0;
    for name in EXAMPLES {
        let scene = Scene::load(&dir.join(format!("{name}.toml"))).unwrap_or_else(|e| panic!("{e}"));
        for p in scene.patches.iter().filter(|p| p.solid.is_none()) {
            let s = p.surface.as_ref();
            let dom = s.v_domain();
            let mut x: u64 = 0x2545_F491_4F6C_DD1D;
            let mut next = || {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                (x >> 11) as f64 / (1u64 << 53) as f64
            };
            let mut uv: Vec<[f64; 2]> = (0..10_000).map(|_| [next(), dom.at(next())]).collect();
            uv.extend([[0.0, dom.start], [1.0, dom.end], [0.5, dom.at(0.5)]]);
            let mut vals = vec![Vec3::ZERO; uv.len()];
            s.points_at(&uv, &mut vals);
            let mut firsts = vec![[Vec3::ZERO; 3]; uv.len()];
            s.firsts_at(&uv, &mut firsts);
            let (mut err, mut size) = ([0.0f64; 4], [0.0f64; 3]);
            for (k, q) in uv.iter().enumerate() {
                let d = s.derivatives(q[0], q[1], 1, 1);
                let want = [d[0], d[2], d[1]];
                for c in 0..3 {
                    err[c] = pdeshape_core::num::max_nan(err[c], (firsts[k][c] - want[c]).norm());
                    size[c] = pdeshape_core::num::max_nan(size[c], want[c].norm());
                }
                err[3] = pdeshape_core::num::max_nan(err[3], (vals[k] - want[0]).norm());
            }
            let rel = [err[0] / size[0], err[1] / size[1], err[2] / size[2], err[3] / size[0]];
            for (what, e) in ["value (with derivatives)", "X_u", "X_v", "value"].iter().zip(rel) {
                // reassociated sums of the same products: a few ulps (7e-16 … 3e-15 seen)
                assert!(e <= 1e-14, "{name}, patch {}: {what} differs by {e:e} (relative)", p.name);
            }
            seen += 1;
        }
    }
    assert!(seen >= 30, "{seen} patches compared");
}

/// The examples of the repository, in file-name order.
const EXAMPLES: [&str; 27] = [
    "blend-cone-cylinder",
    "blend-torus-hyperboloid",
    "bloor-wilson-blend",
    "dolphin",
    "dynamic-elliptic-cylinders",
    "dynamic-linear",
    "dynamic-sine",
    "fill-box-corner",
    "fill-bspline-hole",
    "fill-sphere-hexagon",
    "fill-sphere-pentagon",
    "fill-sphere-triangle",
    "fill-wing-root",
    "four-curve-patch",
    "hermite-blend",
    "hermite-pole",
    "hermite-ruled",
    "klein-bottle",
    "order8-patch",
    "red-blood-cell",
    "solid-cubes",
    "solid-cylinder-cube",
    "solid-cylinders",
    "trim-circle",
    "trim-disjoint",
    "trim-nonconvex",
    "trim-spline",
];
