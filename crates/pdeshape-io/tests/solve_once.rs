//! Each instant of a dynamic blend is solved once per loaded scene, however many of the
//! model's consumers (mesh and animation, editor meshes, condition report, diagnostics,
//! the frame strip) ask for it.

use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::path::PathBuf;

fn everything(sc: &Scene) {
    for p in sc.patches.iter().filter(|p| p.dynamic.is_some()) {
        let d = p.dynamic.as_ref().unwrap();
        model::patch_mesh(p).unwrap();
        for t in d.frame_times() {
            model::editor_mesh(p, Some(t)).unwrap();
        }
        model::condition_report(p);
        model::patch_diagnostics(p);
    }
    model::scene_diagnostics(sc);
    if let Some(strip) = model::dynamic_strip(sc) {
        strip.unwrap();
    }
}

#[test]
fn dynamic_frames_are_solved_once() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for name in ["dynamic-elliptic-cylinders", "dynamic-sine", "dynamic-linear"] {
        let sc = Scene::load(&root.join(format!("{name}.toml"))).unwrap();
        let d = sc.patches.iter().find_map(|p| p.dynamic.as_ref()).expect("a dynamic patch");
        let mut times: Vec<u64> = d.frame_times().iter().chain([&d.times.0, &d.times.1]).map(|t| t.to_bits()).collect();
        times.sort_unstable();
        times.dedup();
        everything(&sc);
        let solved = d.blend.frames_solved();
        // at most one solve per instant asked for (the frame times and the ends)
        assert!(solved >= 1 && solved <= times.len(), "{name}: {solved} solves for {} instants", times.len());
        eprintln!("{name}: {solved} solves for {} instants", times.len());
        // asking again solves nothing
        everything(&sc);
        assert_eq!(d.blend.frames_solved(), solved, "{name}: frames solved again");
    }
}
