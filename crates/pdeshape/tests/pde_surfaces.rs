//! PDE surfaces of any even order (SPEC §3) through the scene files and `check`.

use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::collections::HashMap;
use std::path::PathBuf;

fn example_text(name: &str) -> String {
    std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).unwrap()
}

fn diagnostics(text: &str) -> serde_json::Value {
    let scene = Scene::parse(text, "test.toml", "test", &HashMap::new()).unwrap_or_else(|e| panic!("{e}"));
    model::patch_diagnostics(&scene.patches[0]).to_json()
}

/// The Klein bottle at Chebyshev sections stays near the analytic bottle; the same 40
/// sections at equispaced u give the exact solution of a Runge-type swing, which `check`
/// warns about (SPEC §3 "Many sections").
#[test]
fn klein_bottle_sections_chebyshev_versus_equispaced() {
    let text = example_text("klein-bottle.toml");
    let d = diagnostics(&text);
    assert_eq!(d["spectral"]["order"], 40);
    assert!(d["condition_error"]["max_rel"].as_f64().unwrap() <= 1e-10);
    let dist = d["section_reference_distance"].as_f64().unwrap();
    assert!(dist < 0.25, "distance to the analytic bottle {dist}");
    let leb = d["spectral"]["lebesgue_mode0"].as_f64().unwrap();
    assert!((3.0..3.5).contains(&leb), "Lebesgue constant {leb}");
    assert!(d["warnings"].as_array().unwrap().is_empty());

    let d = diagnostics(&text.replace("spacing = \"chebyshev\"", "spacing = \"uniform\""));
    assert!(d["condition_error"]["max_rel"].as_f64().unwrap() <= 1e-10, "still exact at the sections");
    let swing = d["section_reference_distance"].as_f64().unwrap();
    assert!(swing > 1e5, "equispaced sections swing by {swing:e} between the first sections");
    let w = d["warnings"].as_array().unwrap();
    assert!(w.iter().any(|w| w.as_str().unwrap().contains("chebyshev")), "{w:?}");
}

#[test]
fn check_reports_solver_modes_conditioning_and_residuals() {
    let d = diagnostics(&example_text("four-curve-patch.toml"));
    assert_eq!(d["solver"], "spectral");
    let s = &d["spectral"];
    assert_eq!(s["modes"], 6);
    // order 4, a = 1.1, M = 6: every mode is well conditioned and solved in f64 (the
    // condition number of a 4 × 4 system of e^{±a m u}, u e^{±a m u} at u = 0, 1/3, 2/3, 1)
    let cond = s["max_mode_condition_number"].as_f64().unwrap();
    assert!((1.0..1e4).contains(&cond), "max mode condition {cond:e}");
    assert_eq!(s["modes_solved_in_f64"], 7, "{s}");
    assert_eq!(s["modes_solved_in_multiprecision"], 0, "{s}");
    assert!(s["rms_residual_truncated"].as_f64().unwrap() < 1e-8);
    // the polylines' creases are carried by the remainder, which is no solution of the PDE
    // (its residual measured 506); the truncated part's is round-off, so the whole patch's
    // residual is the remainder's
    let (whole, rem) = (s["rms_residual_whole"].as_f64().unwrap(), s["rms_residual_remainder"].as_f64().unwrap());
    assert!(rem > 100.0, "remainder residual {rem}");
    assert!((whole - rem).abs() <= 1e-9 * rem, "whole {whole}, remainder {rem}");
    assert!(d["condition_error"]["max_rel"].as_f64().unwrap() <= 1e-10);
}

/// The red blood cell's auxiliary curves were designed from the Evans–Fung biconcave
/// profile (radius sin πu, height ½ cos πu (0.207 + 2.003 sin²πu − 1.123 sin⁴πu)); the
/// order-8 surface through them follows that profile closely, with no spike at the poles.
#[test]
fn red_blood_cell_follows_the_biconcave_profile() {
    let scene = Scene::parse(&example_text("red-blood-cell.toml"), "t.toml", "t", &HashMap::new()).unwrap();
    let s = &scene.patches[0].surface;
    let mut worst: f64 = 0.0;
    for i in 0..=200 {
        let u = i as f64 / 200.0;
        let (sn, cs) = (std::f64::consts::PI * u).sin_cos();
        let (r, z) = (sn, 0.5 * cs * (0.207 + 2.003 * sn * sn - 1.123 * sn.powi(4)));
        for j in 0..16 {
            let v = j as f64 * std::f64::consts::TAU / 16.0;
            let p = s.point(u, v);
            worst = pdeshape_core::num::max_nan(
                worst,
                ((p.x - r * v.cos()).powi(2) + (p.y - r * v.sin()).powi(2) + (p.z - z).powi(2)).sqrt(),
            );
        }
    }
    assert!(worst < 0.03, "distance from the biconcave profile {worst}");
}

/// Order 40 in plain f64 at both ends of the Klein bottle's slider (`a` = 0.3 and 3.0):
/// every mode and the remainder take an f64 path (the exponential basis or the
/// ultraspherical Chebyshev system, none multiple precision), and the 40 sections hold to
/// 1e-10 relative at the check's 1000 samples. The example's sections are trigonometric
/// polynomials of degree 1 in `v`, so only modes 0 and 1 are solved; with a term of degree
/// above M = 6 in their `z` every mode and the remainder are.
#[test]
fn klein_bottle_is_exact_in_f64_across_the_slider() {
    let example = example_text("klein-bottle.toml");
    let every_mode = example.replace("\"4*(1 - cos(s)/2)*sin(v)\"", "\"4*(1 - cos(s)/2)*sin(v) + 0.01*exp(cos(v))\"");
    assert_ne!(example, every_mode);
    for (text, kept) in [(&example, 1), (&every_mode, 6)] {
        for a in [0.3, 3.0] {
            let scene = Scene::parse(text, "k.toml", "k", &HashMap::from([("a".to_string(), a)])).unwrap();
            let r = model::condition_report(&scene.patches[0]);
            assert!(r.max_rel <= 1e-10, "a = {a}: sections met to {:e}", r.max_rel);
            let rep = scene.patches[0].spectral.as_ref().unwrap().report();
            assert_eq!(rep.kept, kept, "a = {a}: {:?}", rep.mode_paths);
            assert_eq!(rep.methods, (kept + 1, 0), "a = {a}: {:?}", rep.mode_paths);
            assert_eq!(rep.mode_paths.len(), 8, "modes 0…6 and the remainder");
            let (solved, zero) = rep.mode_paths.split_at(kept + 1);
            assert!(solved.iter().all(|p| p.starts_with("f64")), "a = {a}: {:?}", rep.mode_paths);
            assert!(solved.contains(&"f64-ultraspherical"), "a = {a}: {:?}", rep.mode_paths);
            // the modes above the data's degree and the remainder are zero, not solved; with
            // a datum of higher degree only the remainder is left after mode 6
            let want_zero =
                |p: &&str| if kept == 6 { p.starts_with("f64") } else { *p == pdeshape_core::spectral::NO_DATA };
            assert!(zero.iter().all(want_zero), "a = {a}: {:?}", rep.mode_paths);
            // the truncated part's PDE residual at order 40, per mode, from the Chebyshev
            // coefficients (relative to the operator's terms): measured 4e-14 … 2.3e-10 over
            // a = 0.3 … 3, the largest for mode 1 at a = 0.3, nearly a polynomial of degree
            // < 40, whose coefficients' round-off D^40 amplifies
            assert_eq!(rep.mode_residuals.len(), 8);
            for (m, r) in rep.mode_residuals.iter().enumerate() {
                assert!(*r <= 1e-9, "a = {a}, mode {m}: residual {r:e} ({})", rep.mode_paths[m]);
            }
            // derivative orders beyond the tabulated ones are derived, not a panic
            let deep = scene.patches[0].surface.derivatives(0.37, 1.1, 4, 1);
            assert!(deep.len() == 10 && deep.iter().all(|x| x.is_finite()), "a = {a}");
            let d = model::patch_diagnostics(&scene.patches[0]).to_json();
            let t = d["spectral"]["truncated_residual_relative"].as_f64().unwrap();
            assert!(t <= 1e-9, "a = {a}: {t:e}");
        }
    }
}
