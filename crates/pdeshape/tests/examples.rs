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

/// The examples of the repository, in file-name order.
const EXAMPLES: [&str; 26] = [
    "blend-cone-cylinder",
    "blend-torus-hyperboloid",
    "bloor-wilson-blend",
    "dolphin",
    "dynamic-elliptic-cylinders",
    "dynamic-linear",
    "dynamic-sine",
    "fill-box-corner",
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
