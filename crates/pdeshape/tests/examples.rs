//! Every scene file under examples/ is built and checked: it parses, meshes without
//! non-finite values, meets its conditions to 1e-10 (relative) at 1000 v samples, and
//! renders.

use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::path::PathBuf;

#[test]
fn every_example_builds_and_meets_its_conditions() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        n += 1;
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(!scene.patches.is_empty(), "{}: no patches", path.display());
        let meshes = model::patch_meshes(&scene).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for m in &meshes {
            m.check_finite().unwrap();
        }
        let d = model::scene_diagnostics(&scene);
        for p in d["patches"].as_array().unwrap() {
            let e = p["condition_error"]["max_rel"].as_f64().unwrap();
            assert!(e <= 1e-10, "{}: patch {} misses its conditions by {e:e}", path.display(), p["name"]);
        }
        let mut small = scene;
        small.render.size = (64, 48);
        let img = model::render_scene(&small).unwrap();
        // one 64 × 48 picture, or a strip of panels for an order study of blends
        assert!(img.width >= 64 && img.height >= 48, "{}: {} × {}", path.display(), img.width, img.height);
        assert_eq!(img.data.len(), (img.width * img.height * 4) as usize);
        assert!(img.data.chunks(4).any(|px| px[..3] != img.data[..3]), "{}: a blank picture", path.display());
    }
    assert!(n >= 3, "only {n} examples found");
}
