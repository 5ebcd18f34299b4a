//! Static blends of 2nd, 4th, 6th and mixed order (SPEC §4) through the scene files, the
//! diagnostics and the CLI.

use assert_cmd::Command;
use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::collections::HashMap;
use std::path::PathBuf;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

/// The paper's conclusion in numbers: 2nd order and every mix with a 2nd-order component
/// are C0 only; 4th order (and 4 + 6) are C1 with G1 angles at round-off; 6th order is C2.
#[test]
fn continuity_table_of_the_cone_cylinder_blends() {
    let scene = Scene::load(&example("blend-cone-cylinder.toml")).unwrap();
    let want = [("o2", "C0"), ("o2-4", "C0"), ("o2-6", "C0"), ("o4", "C1"), ("o4-6", "C1"), ("o6", "C2")];
    assert_eq!(scene.patches.len(), 6);
    for (p, (name, class)) in scene.patches.iter().zip(want) {
        assert_eq!(p.name, name);
        let d = model::patch_diagnostics(p).to_json();
        assert!(d["condition_error"]["max_rel"].as_f64().unwrap() <= 1e-10, "{name}: {}", d["condition_error"]);
        assert_eq!(d["continuity"]["class"], class, "{name}: {}", d["continuity"]);
        assert_eq!(d["solver"], "exact");
        let dist = d["blend"]["exact_vs_collocation_max_distance"].as_f64().unwrap();
        assert!(dist < 1e-9, "{name}: exact vs collocation {dist}");
        for end in ["start", "end"] {
            let g1 = d["continuity"][end]["g1_radians"].as_f64().unwrap();
            if class == "C0" {
                assert!(g1 > 1e-2, "{name}: a blend with a 2nd-order component has a crease ({g1} rad)");
            } else {
                assert!(g1 <= 1e-8, "{name}: G1 angle {g1}");
            }
            let c2 = d["continuity"][end]["c2"].as_f64().unwrap();
            assert_eq!(c2 <= 1e-8, class == "C2", "{name}: C2 gap {c2}");
        }
        // the worst place of each measure: its value is the larger end's maximum, and its
        // point is the patch at its (u, v), on its trimline
        for key in ["c0", "c1", "g1_radians", "c2", "g2"] {
            let w = &d["continuity"]["worst"][key];
            let c = &d["continuity"];
            let (a, b) = (c["start"][key].as_f64().unwrap(), c["end"][key].as_f64().unwrap());
            assert_eq!(w["value"].as_f64(), Some(if b > a { b } else { a }), "{name} {key}: {w}");
            assert_eq!(w["end"], if b > a { "end" } else { "start" });
            let (u, v) = (w["u"].as_f64().unwrap(), w["v"].as_f64().unwrap());
            assert_eq!(u, if b > a { 1.0 } else { 0.0 });
            let q = p.surface.point(u, v);
            let pt: Vec<f64> = w["point"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            assert_eq!(pt, vec![q.x, q.y, q.z], "{name} {key}");
        }
    }
}

#[test]
fn torus_hyperboloid_blends_and_per_vertex_continuity_fields() {
    let scene = Scene::load(&example("blend-torus-hyperboloid.toml")).unwrap();
    let classes: Vec<String> = scene
        .patches
        .iter()
        .map(|p| model::patch_diagnostics(p).to_json()["continuity"]["class"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(classes, ["C0", "C2"]);
    let m = model::patch_mesh(&scene.patches[1]).unwrap();
    let names: Vec<&str> = m.fields.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["c0_gap", "c1_gap", "g1_angle", "c2_gap", "g2_gap"]);
    assert!(m.fields.iter().all(|f| f.values.len() == m.positions.len() && f.values.iter().all(|x| *x < 1e-10)));
    let m = model::patch_mesh(&scene.patches[0]).unwrap();
    assert!(
        m.fields[2].values.iter().copied().fold(0.0f64, pdeshape_core::num::max_nan) > 0.1,
        "the 2nd-order blend creases"
    );
}

/// `--solver` overrides the scene: both solvers through `sample` agree on eigenfunction
/// data, and `check` says which ran.
#[test]
fn solver_override_in_sample_and_check() {
    let input: String = (0..50).map(|i| format!("{},{}\n", (i as f64 * 0.618) % 1.0, i as f64 * 0.37)).collect();
    let run = |solver: &str| -> Vec<Vec<f64>> {
        let out = Command::cargo_bin("pdeshape")
            .unwrap()
            .args(["sample", "--patch", "o4", "--solver", solver])
            .arg(example("blend-cone-cylinder.toml"))
            .write_stdin(input.clone())
            .assert()
            .success()
            .get_output()
            .stdout
            .clone();
        String::from_utf8(out)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect()
    };
    let (a, b) = (run("exact"), run("collocation"));
    assert_eq!(a.len(), 50);
    for (x, y) in a.iter().zip(&b) {
        for k in 2..5 {
            assert!((x[k] - y[k]).abs() < 1e-9, "{x:?} vs {y:?}");
        }
    }
    let out = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["check", "--json", "--solver", "collocation"])
        .arg(example("blend-torus-hyperboloid.toml"))
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let d: serde_json::Value = serde_json::from_slice(&out).unwrap();
    assert_eq!(d["patches"][1]["solver"], "collocation");
    // the collocation solver ran: a small, non-zero PDE residual at its points (the
    // torus/hyperboloid data are not in the polynomial trial space), far below the data's O(1)
    let rms = d["patches"][1]["blend"]["components"][0]["collocation_rms_residual"].as_f64().unwrap();
    assert!(rms > 0.0 && rms < 1e-3, "collocation RMS residual {rms:e}");
    let a = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["check", "--solver", "magic"])
        .arg(example("blend-torus-hyperboloid.toml"))
        .assert()
        .code(2); // a flag's value: a usage error
    assert!(String::from_utf8_lossy(&a.get_output().stderr).contains("unknown solver `magic`"));
}

#[test]
fn overriding_coefficients_by_parameters_keeps_exactness() {
    let text = std::fs::read_to_string(example("blend-torus-hyperboloid.toml")).unwrap().replace(
        "orders = [6, 6, 6]",
        "orders = [6, 6, 6]\ncoefficients = [[1, 0.5, 2, 0.7], [2, 1, 1, 1], [1, 3, 3, 1]]",
    );
    let scene = Scene::parse(&text, "t.toml", "t", &HashMap::new()).unwrap();
    let d = model::patch_diagnostics(&scene.patches[1]).to_json();
    assert!(d["condition_error"]["max_rel"].as_f64().unwrap() <= 1e-10);
    assert_eq!(d["continuity"]["class"], "C2");
}

mod common;
use common::hermite_ode::{self, Basis};

/// A blend between two surfaces of revolution whose trimlines carry `cos v`, `sin v` data:
/// `r(s) = 1 + 0.5 s + 0.3 s²` below (trimline s = 0), `r(s) = 0.6 − 0.4 (s − 1) +
/// 0.2 (s − 1)²` above (trimline s = 1), `z = s` on both.
fn revolution_blend(orders: usize, coefficients: &str) -> String {
    format!(
        r#"
[surfaces.bottom]
expr = ["(1 + 0.5*s + 0.3*s^2)*cos(v)", "(1 + 0.5*s + 0.3*s^2)*sin(v)", "s"]
s_range = [-1, 0]

[surfaces.top]
expr = ["(0.6 - 0.4*(s - 1) + 0.2*(s - 1)^2)*cos(v)", "(0.6 - 0.4*(s - 1) + 0.2*(s - 1)^2)*sin(v)", "s"]
s_range = [1, 2]

[patches.b]
kind = "blend"
orders = [{orders}, {orders}, {orders}]
coefficients = [{coefficients}, {coefficients}, {coefficients}]
solver = "exact"
start = {{ surface = "bottom", s = 0 }}
end = {{ surface = "top", s = 1 }}
resolution = [9, 9]
"#
    )
}

/// Compares the blend with `x = G(u) cos v, y = G(u) sin v, z = u` where `G` is the closed
/// form from `basis` (a real basis of the ODE's kernel for the `cos v` mode, derived by hand
/// from the characteristic roots) fitted to the radii's Hermite data; values and the first
/// two u-derivatives at 2000 scattered points.
fn matches_closed_form(orders: usize, coefficients: &str, basis: Vec<Basis>) {
    let text = revolution_blend(orders, coefficients);
    let scene = Scene::parse(&text, "revolution.toml", "revolution", &HashMap::new()).unwrap();
    let p = &scene.patches[0];
    let r = orders / 2;
    // r(s) and its derivatives at the trimlines
    let at0 = [1.0, 0.5, 0.6];
    let at1 = [0.6, -0.4, 0.4];
    let c = hermite_ode::fit(&basis, &at0[..r], &at1[..r]);
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        let u = (k as f64 * 0.618_033_988_749_895).fract();
        let v = (k as f64 * 0.414_213_562_373_095).fract() * std::f64::consts::TAU;
        let d = p.surface.derivatives(u, v, 2, 0);
        for (order, x) in d.iter().enumerate() {
            let g = hermite_ode::eval(&basis, &c, u, order);
            let want = [
                g * v.cos(),
                g * v.sin(),
                if order == 0 {
                    u
                } else if order == 1 {
                    1.0
                } else {
                    0.0
                },
            ];
            for k in 0..3 {
                // relative to the size of the derivative (G″ reaches a few units)
                let e = (x[k] - want[k]).abs() / (1.0 + want[k].abs());
                worst = pdeshape_core::num::max_nan(worst, e);
            }
        }
    }
    // the closed form is evaluated in f64 from O(1) coefficients: round-off, a few ulps × 10
    assert!(worst < 1e-12, "order {orders}: differs from the closed form by {worst:e}");
}

/// 4th order `∂u⁴ + ∂u²∂v² + ∂v⁴`: on `G(u) cos v` it is `G⁗ − G″ + G = 0`, characteristic
/// `s⁴ − s² + 1 = 0`, so `s² = e^{±iπ/3}` and `s = ±(√3/2 ± i/2)`: complex roots, kernel
/// `e^{±√3u/2} cos(u/2)`, `e^{±√3u/2} sin(u/2)`.
#[test]
fn fourth_order_blend_equals_the_hand_derived_closed_form() {
    let (a, b) = (3f64.sqrt() / 2.0, 0.5);
    let basis = vec![
        hermite_ode::exp_trig(a, b, false),
        hermite_ode::exp_trig(a, b, true),
        hermite_ode::exp_trig(-a, b, false),
        hermite_ode::exp_trig(-a, b, true),
    ];
    matches_closed_form(4, "[1, 1, 1]", basis);
}

/// 6th order `∂u⁶ + 14∂u⁴∂v² + 49∂u²∂v⁴ + 36∂v⁶`: on `G(u) cos v` it is
/// `G⁽⁶⁾ − 14G⁽⁴⁾ + 49G″ − 36G = 0`, characteristic `(s² − 1)(s² − 4)(s² − 9)`, kernel
/// `e^{±u}, e^{±2u}, e^{±3u}`.
#[test]
fn sixth_order_blend_equals_the_hand_derived_closed_form() {
    let basis = [1.0, -1.0, 2.0, -2.0, 3.0, -3.0].into_iter().map(hermite_ode::exp).collect();
    matches_closed_form(6, "[1, 14, 49, 36]", basis);
}
