//! `[import.NAME] step = …` in scenes: an OpenCASCADE-written model's faces, edges and
//! holes used by fills and curves, against the same fills built from the model directly,
//! against the faces' own geometry, and the refusals.

use pdeshape_core::Vec3;
use pdeshape_core::brep::{FaceSurface, fill_hole, holes};
use pdeshape_core::fill::{FillOptions, foot_of};
use pdeshape_core::num::max_nan;
use pdeshape_core::patch::Surface;
use pdeshape_io::import::step::read_step;
use pdeshape_io::scene::{ImportRoot, LoadOptions, Scene, SceneError};
use std::path::{Path, PathBuf};

/// The STEP models the OCCT suite builds (`crates/pdeshape/tests/data/step/make_models.py`).
fn data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../pdeshape/tests/data/step")
}

// built once per test scene: the error's size on the error path does not matter
#[allow(clippy::result_large_err)]
fn load_in(text: &str, root: ImportRoot) -> Result<Scene, SceneError> {
    Scene::parse_with(text, "imports.toml", "imports", &LoadOptions { imports: root, ..Default::default() })
}

fn load(text: &str) -> Scene {
    load_in(text, ImportRoot::Dir(data())).unwrap_or_else(|e| panic!("{e}"))
}

fn refused(text: &str, root: ImportRoot) -> SceneError {
    match load_in(text, root) {
        Ok(_) => panic!("the scene was accepted:\n{text}"),
        Err(e) => e,
    }
}

/// Points spread over the domain `[0, 1] × [v0, v1]` (a fixed low-discrepancy walk).
fn spread(n: usize, v0: f64, v1: f64) -> Vec<[f64; 2]> {
    (0..n)
        .map(|k| {
            let a = (k as f64 * 0.618_033_988_749_895).fract();
            let b = (k as f64 * 0.754_877_666_246_693).fract();
            [a, v0 + (v1 - v0) * b]
        })
        .collect()
}

const BOX_CORNER: &str = r#"
[import.box]
step = "rounded-box-corners.step"

[patches.by_hole]
kind = "fill"
hole = "box.hole1"
order = 6

[patches.by_edges]
kind = "fill"
order = 6
edges = [{ edge = "box.edge142" }, { edge = "box.edge717" }, { edge = "box.edge205" }]
"#;

#[test]
fn a_hole_of_an_imported_model_fills_as_fill_holes_fills_it() {
    let scene = load(BOX_CORNER);
    let m = read_step(&data().join("rounded-box-corners.step"), &Default::default()).unwrap();
    let hs = holes(&m.brep);
    let direct = fill_hole(&m.brep, &hs[0], &FillOptions { order: 6, ..Default::default() }).unwrap();
    let reference = direct.fill.patch();
    let dom = reference.v_domain();
    for name in ["by_hole", "by_edges"] {
        let p = scene.patch(name).unwrap();
        assert_eq!(p.surface.v_domain(), dom, "{name}");
        for [u, v] in spread(500, dom.start, dom.end) {
            // the same edges, options and solve: the same bits
            assert_eq!(p.surface.derivatives(u, v, 1, 1), reference.derivatives(u, v, 1, 1), "{name} at ({u}, {v})");
        }
    }
    assert_eq!(scene.imports.len(), 1);
    assert_eq!(scene.imports[0].model.holes.len(), 8);
}

/// Along the fill's boundary (`u = 0`), the fill against the faces of the file, found by
/// their own surfaces: on a face (distance), tangent to it (angle between normals).
#[test]
fn an_imported_hole_fill_meets_the_files_faces_g1() {
    let scene = load(BOX_CORNER);
    let b = &scene.imports[0].model.model.brep;
    let hole = &scene.imports[0].model.holes[0];
    let faces: Vec<&FaceSurface> = hole.faces().iter().map(|&f| b.faces[f].surface.as_ref().unwrap()).collect();
    let fill = scene.patch("by_hole").unwrap();
    let dom = fill.surface.v_domain();
    let (mut gap, mut angle) = (0.0_f64, 0.0_f64);
    let n = 600;
    for k in 0..n {
        let v = dom.start + (dom.end - dom.start) * (k as f64 + 0.5) / n as f64;
        let d = fill.surface.derivatives(0.0, v, 1, 1);
        let (p, normal) = (d[0], d[2].cross(d[1]).normalized().unwrap());
        let mut best: Option<(f64, Vec3)> = None;
        for s in &faces {
            let Some(c) = foot_of(s.field().as_ref(), p, s.invert_near(p), 0.0) else { continue };
            let dist = (s.field().eval(&c) - p).norm();
            if best.is_none_or(|x| dist < x.0) {
                best = Some((dist, s.normal(c).unwrap()));
            }
        }
        let (dist, m) = best.expect("a face near every boundary point");
        gap = max_nan(gap, dist);
        angle = max_nan(angle, normal.cross(m).norm().atan2(normal.dot(m).abs()));
    }
    // the model is 2 units across; round-off of the foot and of the fill's boundary data
    // is ~1e-15, the normals' ~1e-14 (measured: gap 7.3e-16, angle 2.8e-14 rad)
    assert!(gap <= 1e-13, "gap {gap:e}");
    assert!(angle <= 1e-12, "G1 {angle:e} rad");
    let g = fill.fill.as_ref().unwrap().edge_continuity(200);
    assert!(g.g1 <= 1e-12, "{g:?}");
}

#[test]
fn an_imported_face_is_a_surface_for_curves() {
    let scene = load(
        r#"
[import.box]
step = "rounded-box-corners.step"

[curves.line]
surface = "box.face137"
s = 0.3
"#,
    );
    let face = scene.surfaces.iter().find(|s| s.name == "box.face137").expect("the face is a surface");
    let curve = &scene.curves["line"];
    for k in 0..20 {
        let v = -0.5 + 0.1 * k as f64;
        assert_eq!(curve.eval(&[v, 0.0]), face.field.eval(&[0.3, v, 0.0]), "v = {v}");
    }
    // every face of the file is there
    let named = scene.surfaces.iter().filter(|s| s.name.starts_with("box.face")).count();
    assert_eq!(named, scene.imports[0].model.model.brep.faces.len());
}

#[test]
fn imports_are_read_only_from_where_the_scene_may_read() {
    let text = "[import.part]\nstep = \"cylinder-open.step\"\n";
    // scene text without a folder (Scene::parse): nothing is read
    let e = Scene::parse(text, "t.toml", "t", &Default::default()).unwrap_err();
    assert_eq!(e.key, "import.part.step");
    assert!(e.message.contains("not read from a file"), "{e}");
    assert_eq!(e.line, Some(2));
    // the editor: only what its own scene imported at start
    let opened = load(text);
    let e = refused("[import.other]\nstep = \"/etc/passwd\"\n", opened.imported());
    assert!(
        e.message.contains("only the models the scene imported") && e.message.contains("cylinder-open.step"),
        "{e}"
    );
    // and what it did import, without reading the file again
    let again = load_in(text, opened.imported()).unwrap();
    assert!(std::sync::Arc::ptr_eq(&again.imports[0].model, &opened.imports[0].model));
}

#[test]
fn bad_imports_name_the_key_and_the_cause() {
    let dir = ImportRoot::Dir(data());
    let head = "[import.box]\nstep = \"rounded-box-corners.step\"\n";
    let fill = |body: &str| format!("{head}[patches.f]\nkind = \"fill\"\n{body}\n");
    let cases: Vec<(String, &str, &str)> = vec![
        ("[import.m]\nstep = \"no-such-file.step\"\n".into(), "import.m.step", "cannot read the model"),
        ("[import.m]\nstep = \"make_models.py\"\n".into(), "import.m.step", "not a STEP"),
        ("[import.m]\nfile = \"x.step\"\n".into(), "", "unknown field `file`"),
        ("[import.pi]\nstep = \"x.step\"\n".into(), "import.pi", "reserved"),
        (fill("hole = \"box.hole9\""), "patches.f.hole", "has 8 hole(s)"),
        (fill("hole = \"box.hole0\""), "patches.f.hole", "has 8 hole(s)"),
        (fill("hole = \"box.face3\""), "patches.f.hole", "not an imported hole's name"),
        (fill("hole = \"part.hole1\""), "patches.f.hole", "no model `part` is imported (imported: box)"),
        (fill("hole = \"box.hole1\"\nedges = []"), "patches.f.hole", "not both"),
        (fill("edges = [{ edge = \"box.edge1\" }]"), "patches.f.edges[0].edge", "has no edge #1"),
        (
            fill("edges = [{ edge = \"box.edge142\" }, { edge = \"box.edge205\" }, { edge = \"box.edge717\" }]"),
            "patches.f.edges[1]",
            "does not start where the edge before it (142) ends",
        ),
        (
            fill("edges = [{ edge = \"box.edge142\", s = 0 }, { edge = \"box.edge717\" }, { edge = \"box.edge205\" }]"),
            "patches.f.edges[0]",
            "takes no `s`, `w` or `t`",
        ),
        (
            fill(
                "edges = [{ edge = \"box.edge142\", face = \"box.face201\" }, { edge = \"box.edge717\" }, { edge = \"box.edge205\" }]",
            ),
            "patches.f.edges[0].face",
            "face #201 does not bound edge #142 (its faces: box.face137)",
        ),
        // two copies: 36 faces, the first 24 listed
        (
            "[curves.c]\nsurface = \"box.face99999\"\ns = 0\n[import.copy]\nstep = \"rounded-box-corners.step\"\n"
                .to_string()
                + head,
            "curves.c.surface",
            "copy.face1074, box.face17, box.face137, box.face201, box.face263, box.face326, box.face389 and 12 more",
        ),
    ];
    for (text, key, message) in cases {
        let e = refused(&text, dir.clone());
        assert_eq!(e.key, key, "{text}\n{e}");
        assert!(e.message.contains(message), "{text}\nexpected `{message}` in: {e}");
    }
}

/// An edge between two faces names the face the fill meets; without it the scene says which
/// faces bound it.
#[test]
fn an_edge_of_two_faces_needs_its_face() {
    let scene = load("[import.box]\nstep = \"rounded-box-corners.step\"\n");
    let b = &scene.imports[0].model.model.brep;
    let (index, e) = b.edges.iter().enumerate().find(|(i, _)| b.uses_of(*i).len() == 2).expect("an inner edge");
    let faces: Vec<u64> = b.uses_of(index).iter().map(|u| b.faces[u.face].id).collect();
    let text = format!(
        "[import.box]\nstep = \"rounded-box-corners.step\"\n[patches.f]\nkind = \"fill\"\nedges = [{{ edge = \"box.edge{}\" }}, {{ edge = \"box.edge142\" }}, {{ edge = \"box.edge717\" }}]\n",
        e.id
    );
    let err = refused(&text, ImportRoot::Dir(data()));
    assert_eq!(err.key, "patches.f.edges[0].edge");
    let expected = format!("bounds 2 faces (box.face{}, box.face{}): name the one", faces[0], faces[1]);
    assert!(err.message.contains(&expected), "{err}");
}

/// The area of a triangle.
fn triangle_area(a: Vec3, b: Vec3, c: Vec3) -> f64 {
    (b - a).cross(c - a).norm() / 2.0
}

/// The imported faces drawn in context: the rounded box's six flat faces (1.2 × 1.2) and
/// twelve quarter cylinders (radius 0.4, length 1.2) meshed from their loops, against the
/// closed-form area 6 · 1.44 + 12 · 0.24π; every normal the face's outward one.
#[test]
fn imported_faces_are_meshed_from_their_loops() {
    let scene = load("[import.box]\nstep = \"rounded-box-corners.step\"\n");
    let meshes = pdeshape_io::model::import_meshes(&scene);
    assert_eq!(meshes.len(), 18);
    let mut total = 0.0;
    for m in &meshes {
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            total += triangle_area(a, b, c);
            // counter-clockwise about the outward normal: the box's centre is behind
            let n = (b - a).cross(c - a);
            let centre = Vec3::new(1.0, 1.0, 1.0);
            assert!(n.dot(a - centre) > 0.0, "{}: a triangle faces inward", m.name);
        }
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(n.dot(*p - Vec3::new(1.0, 1.0, 1.0)) > 0.0, "{}: an inward normal", m.name);
        }
    }
    let exact = 6.0 * 1.44 + 12.0 * 0.24 * std::f64::consts::PI;
    // chords of the arcs, edges ~0.06 on radius 0.4: relative error ~ h²/(12 r²) ≈ 2e-3 of
    // the fillets' part; measured 1.3e-4 over all
    let rel = (total - exact).abs() / exact;
    assert!(rel < 1e-3, "area {total} against {exact}: {rel:e}");
}
