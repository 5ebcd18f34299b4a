//! Time-dependent blends (SPEC §5) through the scene files, `sample --time` and `build`.

use assert_cmd::Command;
use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::path::PathBuf;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

/// At every frame of every dynamic example the four C1 conditions hold at 1000 v samples.
#[test]
fn every_frame_meets_the_c1_conditions() {
    for (name, solver) in [
        ("dynamic-elliptic-cylinders.toml", "exact"),
        ("dynamic-linear.toml", "collocation"),
        ("dynamic-sine.toml", "collocation"),
    ] {
        let scene = Scene::load(&example(name)).unwrap();
        let d = model::patch_diagnostics(&scene.patches[0]);
        assert_eq!(d["dynamic"]["solver"], solver, "{name}");
        let frames = d["dynamic"]["frames"].as_array().unwrap();
        assert!(frames.len() >= 4);
        for f in frames {
            let e = f["max_rel"].as_f64().unwrap_or_else(|| panic!("{name}: {f}"));
            assert!(e <= 1e-10, "{name} at t = {}: {e}", f["t"]);
        }
    }
}

fn sample(args: &[&str], input: &str) -> Vec<[f64; 5]> {
    let out = Command::cargo_bin("pdeshape")
        .unwrap()
        .arg("sample")
        .args(args)
        .arg(example("dynamic-elliptic-cylinders.toml"))
        .write_stdin(input.to_string())
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    String::from_utf8(out)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4]]
        })
        .collect()
}

/// `sample --time` evaluates any instant; the closed form at u = 0 reproduces eq. 19's data
/// and the paper's approximation (K = 5, 11 × 11) stays within a few hundredths of it.
#[test]
fn sample_any_time_with_either_solver() {
    let input: String = (0..40).map(|i| format!("{},{}\n", i as f64 / 39.0, 0.3 + i as f64 * 0.15)).collect();
    for t in [0.0f64, 0.17, 0.3] {
        let ts = t.to_string();
        let exact = sample(&["--time", &ts, "--solver", "exact"], &input);
        let approx = sample(&["--time", &ts, "--solver", "collocation", "--terms", "5"], &input);
        let mut worst: f64 = 0.0;
        for (e, a) in exact.iter().zip(&approx) {
            worst = worst.max((0..3).map(|k| (e[2 + k] - a[2 + k]).abs()).fold(0.0, f64::max));
        }
        assert!(worst > 1e-6 && worst < 0.05, "t = {t}: approximation differs by {worst}");
        let top = exact[0];
        assert!((top[2] - 1.6 * t.exp() * top[1].sin()).abs() < 1e-13);
        assert!((top[3] - (-t).exp() * top[1].cos()).abs() < 1e-13);
    }
}

#[test]
fn build_writes_an_animated_gltf_and_a_frame_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("blend.glb");
    Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["build", "-q"])
        .arg(example("dynamic-elliptic-cylinders.toml"))
        .arg("-o")
        .arg(&glb)
        .assert()
        .success();
    let (doc, _, _) = gltf::import(&glb).unwrap();
    assert_eq!(doc.animations().count(), 1);
    let prim = doc.meshes().next().unwrap().primitives().next().unwrap();
    assert_eq!(prim.morph_targets().count(), 4, "one morph target per frame");
    let out = dir.path().join("out");
    Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["build", "-q"])
        .arg(example("dynamic-elliptic-cylinders.toml"))
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    for i in 0..4 {
        let f = out.join(format!("dynamic-elliptic-cylinders-blend-{i:03}.obj"));
        assert!(f.exists(), "{} missing", f.display());
    }
}
