//! Solid blends (SPEC §6) through the scene files, `check`, `sample` and `build`.

use assert_cmd::Command;
use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::collections::HashMap;
use std::path::PathBuf;
use vtkio::model::{DataSet, Piece};

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

const SOLIDS: [&str; 3] = ["solid-cubes.toml", "solid-cylinders.toml", "solid-cylinder-cube.toml"];

/// Every example meets its four boundary conditions on a 50 × 50 grid, does not fold, and
/// its boundary mesh is closed and consistently oriented (each directed edge once, its
/// reverse once) with an enclosed volume matching the quadrature.
#[test]
fn solid_examples_meet_conditions_and_have_closed_boundaries() {
    for name in SOLIDS {
        let scene = Scene::load(&example(name)).unwrap();
        let p = &scene.patches[0];
        let d = model::patch_diagnostics(p).to_json();
        assert!(d["condition_error"]["max_rel"].as_f64().unwrap() <= 1e-10, "{name}: {}", d["condition_error"]);
        assert_eq!(d["mass_properties"]["folds"], false, "{name}: {}", d["mass_properties"]);
        let m = model::patch_mesh(p).unwrap();
        let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert!(
                n == 1 && edges.get(&(b, a)) == Some(&1),
                "{name}: edge ({a}, {b}) is not shared by exactly two triangles"
            );
        }
        let enclosed: f64 = m.enclosed_volume();
        let vol = d["mass_properties"]["volume"].as_f64().unwrap();
        assert!(enclosed > 0.0 && (enclosed - vol).abs() < 0.03 * vol, "{name}: mesh {enclosed} vs quadrature {vol}");
    }
}

/// The cube example is the closed form: its volume is 8 ∫ f g dw (exact by Gauss rules).
#[test]
fn cube_volume_matches_the_analytic_integral() {
    let scene = Scene::load(&example("solid-cubes.toml")).unwrap();
    let d = model::patch_diagnostics(&scene.patches[0]).to_json();
    // f g = (1 − 0.01w + 1.535w² − 1.025w³)(1 − 0.01w + 3.04w² − 2.03w³), integrated exactly
    let f = [1.0, -0.01, 1.535, -1.025];
    let g = [1.0, -0.01, 3.04, -2.03];
    let mut int = 0.0;
    for (i, a) in f.iter().enumerate() {
        for (j, b) in g.iter().enumerate() {
            int += a * b / (i + j + 1) as f64;
        }
    }
    let vol = d["mass_properties"]["volume"].as_f64().unwrap();
    assert!((vol - 8.0 * int).abs() < 1e-10 * vol, "{vol} vs {}", 8.0 * int);
    assert!(d["solid"]["max_coefficient"].as_f64().unwrap() < 1e-13);

    // The boundary mesh, exactly: at height z = 4 − 2w the solid's section is the
    // rectangle |x| ≤ f(w), |y| ≤ g(w); the mesh's side faces are planar trapezoids
    // between its w nodes, so its sections interpolate f and g linearly there and it
    // encloses 8 Σ_i ∫ f_lin g_lin dw = 8 Σ_i h_i (2f_i g_i + f_i g_{i+1} + f_{i+1} g_i +
    // 2 f_{i+1} g_{i+1}) / 6 over the mesh's nodes (read from its z values).
    let m = model::patch_mesh(&scene.patches[0]).unwrap();
    let poly = |c: &[f64; 4], w: f64| c.iter().rev().fold(0.0, |acc, a| acc * w + a);
    let mut ws: Vec<f64> = m.positions.iter().map(|p| (4.0 - p.z) / 2.0).collect();
    ws.sort_by(f64::total_cmp);
    ws.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    assert_eq!(ws.len(), 17, "the mesh's vertex rows in w");
    let mut want = 0.0;
    for k in 0..ws.len() - 1 {
        let (w0, w1) = (ws[k], ws[k + 1]);
        let (f0, f1, g0, g1) = (poly(&f, w0), poly(&f, w1), poly(&g, w0), poly(&g, w1));
        want += 8.0 * (w1 - w0) * (2.0 * f0 * g0 + f0 * g1 + f1 * g0 + 2.0 * f1 * g1) / 6.0;
    }
    let enclosed: f64 = m.enclosed_volume();
    // a sum of a few thousand O(1) tetrahedra: round-off
    assert!((enclosed - want).abs() < 1e-12 * want, "mesh encloses {enclosed}, the polyhedron {want}");
}

#[test]
fn the_papers_trial_space_is_rejected_as_singular() {
    let text = std::fs::read_to_string(example("solid-cylinders.toml"))
        .unwrap()
        .replace("lmn = [6, 6, 6]", "trial = \"paper\"\nlmn = [3, 3, 3]");
    let e = Scene::parse(&text, "t.toml", "t", &HashMap::new()).unwrap_err().to_string();
    assert!(e.contains("singular") && e.contains("symmetric about w = 1/2"), "{e}");
}

#[test]
fn build_writes_a_hexahedral_vtu_and_sample_reads_uvw() {
    let dir = tempfile::tempdir().unwrap();
    Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["build", "-q"])
        .arg(example("solid-cylinders.toml"))
        .arg("-o")
        .arg(dir.path())
        .assert()
        .success();
    let vtk = vtkio::Vtk::import(dir.path().join("solid-cylinders-solid-volume.vtu")).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
    assert_eq!(piece.cells.types.len(), 8 * 48 * 16, "(9 − 1)(49 − 1)(17 − 1) hexahedra");
    assert!(piece.cells.types.iter().all(|t| *t == vtkio::model::CellType::Hexahedron));
    let out = Command::cargo_bin("pdeshape")
        .unwrap()
        .arg("sample")
        .arg(example("solid-cubes.toml"))
        .write_stdin("u,v,w\n0.25,0.5,0.5\n")
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let line = String::from_utf8(out).unwrap().lines().nth(1).unwrap().to_string();
    let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
    let f = 1.0 - 0.005 + 1.535 * 0.25 - 1.025 * 0.125;
    assert!((v[3] - f * 0.5).abs() < 1e-12 && v[4].abs() < 1e-12 && (v[5] - 3.0).abs() < 1e-12, "{v:?}");
}
