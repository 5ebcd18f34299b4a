//! `pdeshape build SCENE -o X.step`: measured B-spline faces in a complete AP214 file.
//! OpenCASCADE reads these files back in `crates/pdeshape-io/tests/occt` (run by `.ci/run`);
//! here: the file's structure (every reference defined, the product chain, one face per
//! patch, the seam and pole edges), the report, and the refusals.

use std::collections::{HashMap, HashSet};
use std::path::Path;
use std::process::Command;

mod common;
use common::example;

fn build(scene: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .arg("build")
        .arg(scene)
        .arg("-o")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// Entities `#n=TYPE(...)` (their text after `=`) by number, and every `#n` referenced.
fn entities(text: &str) -> (HashMap<usize, String>, HashSet<usize>) {
    let data = &text[text.find("DATA;").expect("a DATA section")..];
    let (mut defs, mut refs) = (HashMap::new(), HashSet::new());
    for stmt in data.split(";\n").skip(1) {
        let stmt = stmt.trim();
        if stmt.is_empty() || stmt.starts_with("ENDSEC") {
            break;
        }
        let (id, body) = stmt.split_once('=').expect("#n=...");
        let id: usize = id.trim_start_matches('#').parse().expect("a number");
        assert!(defs.insert(id, body.to_string()).is_none(), "#{id} twice");
        let mut rest = body;
        while let Some(k) = rest.find('#') {
            let digits: String = rest[k + 1..].chars().take_while(|c| c.is_ascii_digit()).collect();
            refs.insert(digits.parse().expect("a reference"));
            rest = &rest[k + 1 + digits.len()..];
        }
    }
    (defs, refs)
}

fn count(defs: &HashMap<usize, String>, ty: &str) -> usize {
    defs.values().filter(|t| t.starts_with(&format!("{ty}("))).count()
}

/// The `#n` references in an entity's text, in order.
fn refs_in(body: &str) -> Vec<usize> {
    body.split('#')
        .skip(1)
        .map(|r| r.chars().take_while(|c| c.is_ascii_digit()).collect::<String>().parse().unwrap())
        .collect()
}

#[test]
fn a_fill_is_one_face_in_a_complete_ap214_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pentagon.step");
    let o = build(&example("fill-sphere-pentagon.toml"), &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    // the report: control points and the measured deviation within the default tolerance
    let line = err.lines().find(|l| l.starts_with("face cap: B-spline")).expect("a fit line");
    assert_eq!(err.lines().filter(|l| l.starts_with("face surface-edge")).count(), 5, "{err}");
    let nums: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let (dev, tol) = (nums[nums.len() - 2], nums[nums.len() - 1]);
    assert!(dev <= tol && tol > 1e-7 && tol < 1e-5, "{line}");

    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("ISO-10303-21;\nHEADER;"));
    assert!(text.contains("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));"));
    assert!(text.trim_end().ends_with("END-ISO-10303-21;"));
    let (defs, refs) = entities(&text);
    for r in &refs {
        assert!(defs.contains_key(r), "#{r} is referenced but not defined");
    }
    // the product chain a CAD reader follows from the product to the geometry
    for ty in [
        "PRODUCT",
        "PRODUCT_DEFINITION_FORMATION",
        "PRODUCT_DEFINITION",
        "PRODUCT_DEFINITION_SHAPE",
        "SHAPE_DEFINITION_REPRESENTATION",
        "MANIFOLD_SURFACE_SHAPE_REPRESENTATION",
        "SHELL_BASED_SURFACE_MODEL",
    ] {
        assert_eq!(count(&defs, ty), 1, "{ty}");
    }
    // the fill and the five neighbouring surfaces' drawn parts, one open shell each
    for ty in ["OPEN_SHELL", "ADVANCED_FACE", "B_SPLINE_SURFACE_WITH_KNOTS"] {
        assert_eq!(count(&defs, ty), 6, "{ty}");
    }
    // the fill's loop is closed in v (one seam edge used twice) and ends in a pole (no
    // edge): the seam (v = v₀) forward, the seam (v = v₁) back, the rim u = 0 reversed
    let face = defs.values().find(|b| b.starts_with("ADVANCED_FACE('cap',")).expect("the fill's face");
    let bound = &defs[&refs_in(face)[0]];
    let lp = &defs[&refs_in(bound)[0]];
    let oriented: Vec<&String> = refs_in(lp).iter().map(|r| &defs[r]).collect();
    assert_eq!(oriented.len(), 3, "{lp}");
    let edges: Vec<usize> = oriented.iter().map(|o| refs_in(o)[0]).collect();
    assert_eq!(edges[0], edges[1], "the seam, forward and back");
    assert_ne!(edges[0], edges[2]);
    assert!(oriented[0].ends_with(".T.)") && oriented[1].ends_with(".F.)") && oriented[2].ends_with(".F.)"));
    for e in &edges {
        assert!(defs[e].starts_with("EDGE_CURVE("));
    }
    assert!(text.contains("UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE("));
    // the corners of the pentagon are C0 lines of the fill: knots of multiplicity 3 in v
    let srf = &defs[&refs_in(face)[1]];
    let flags = ".UNSPECIFIED.,.F.,.T.,.F.,(";
    let rest = &srf[srf.find(flags).expect("closed in v") + flags.len()..];
    let (_umults, rest) = rest.split_once("),(").unwrap();
    let vmults: Vec<usize> = rest.split(')').next().unwrap().split(',').map(|m| m.parse().unwrap()).collect();
    assert_eq!((vmults[0], vmults[vmults.len() - 1]), (4, 4), "clamped");
    assert_eq!(vmults.iter().filter(|&&m| m == 3).count(), 4, "four interior triple knots in v: {vmults:?}");
}

#[test]
fn step_refusals_name_the_cause_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    for (scene, extra, expect) in [
        // the disc's √(1 − x²) has no derivative at its rim, where the face u = 0 starts
        ("solid-cylinder-cube.toml", vec![], "face u0: the patch is not finite"),
        ("four-curve-patch.toml", vec!["--tolerance", "1e-15"], "was not reached"),
    ] {
        let out = dir.path().join("x.step");
        let o = build(&example(scene), &out, &extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{scene}: {err}");
        assert!(err.contains(expect) && !err.contains("panicked"), "{scene}: {err}");
        assert!(!out.exists(), "{scene}: a file was written");
    }
    // --tolerance with a mesh format is a mistake, not ignored
    let out = dir.path().join("x.obj");
    let o = build(&example("four-curve-patch.toml"), &out, &["--tolerance", "1e-6"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("STEP output only"));
    assert!(!out.exists());
}

/// `check --cad --json` keeps its keys: the dolphin (faces with holes, a seam) gives every
/// key path of the CAD report written before the report was typed.
#[test]
fn the_cad_report_keeps_its_keys() {
    let scene = pdeshape_io::scene::Scene::load(&example("dolphin.toml")).unwrap();
    let fitted = pdeshape_io::cad::fit_scene(&scene, &Default::default()).unwrap();
    let report = pdeshape_io::cad::CadReport::of(&fitted);
    assert!(!report.seams.is_empty() && report.faces.iter().any(|f| !f.holes.is_empty()));
    let json = serde_json::json!({ "cad": serde_json::to_value(&report).unwrap() });
    let mut keys = std::collections::BTreeSet::new();
    common::key_paths(&json, "", &mut keys);
    let want: std::collections::BTreeSet<String> =
        include_str!("data/report_keys_cad.txt").lines().map(str::to_string).collect();
    assert_eq!(keys, want);
}

/// `check --cad --json`: the figures of the export without writing it. The Bloor–Wilson
/// blend (C1) and its two surfaces share v knots and interpolate parallel cross
/// derivatives at the seams: the fitted faces meet G1 to round-off (a few 1e-14 rad; the
/// independently fitted faces were 9e-5 … 1.8e-4 rad apart).
#[test]
fn check_reports_the_fit_and_the_seams_after_export() {
    let o = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(["check", "--cad", "--json"])
        .arg(example("bloor-wilson-blend.toml"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let faces = d["cad"]["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 3);
    for f in faces {
        let (dev, tol) = (f["measured_deviation"].as_f64().unwrap(), f["tolerance"].as_f64().unwrap());
        assert!(dev <= tol, "{f}");
        // all three share the blend's v knots
        assert_eq!(f["control_points"][1], faces[0]["control_points"][1], "{f}");
    }
    let seams = d["cad"]["seams"].as_array().unwrap();
    assert_eq!(seams.len(), 2, "{seams:?}");
    for s in seams {
        let (gap, angle) = (s["gap"].as_f64().unwrap(), s["normal_angle_radians"].as_f64().unwrap());
        assert!(gap <= 1e-13 && angle <= 1e-12, "{s}");
    }
}

/// The Bloor–Wilson blend and its cylinder and plane are one open shell: the seams are
/// single edges used by both faces (3 seam edges of the closed faces, 2 rims, 2 shared
/// trimlines: 7 edges where unshared faces would have 9), and the cylinder is flipped so
/// that its shared edge runs against the blend's (OCCT confirms the orientation in
/// `crates/pdeshape-io/tests/occt`).
#[test]
fn a_blend_and_its_surfaces_are_one_shell() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bw.step");
    let o = build(&example("bloor-wilson-blend.toml"), &out, &["-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let (defs, _) = entities(&text);
    assert_eq!(count(&defs, "OPEN_SHELL"), 1);
    assert_eq!(count(&defs, "ADVANCED_FACE"), 3);
    assert_eq!(count(&defs, "EDGE_CURVE"), 7);
    let flipped: Vec<&String> =
        defs.values().filter(|b| b.starts_with("ADVANCED_FACE(") && b.ends_with(",.F.)")).collect();
    assert_eq!(flipped.len(), 1, "{flipped:?}");
    assert!(flipped[0].starts_with("ADVANCED_FACE('surface-cylinder',"), "{}", flipped[0]);
}

/// A solid blend is a solid: the cylinders' three bounding faces (the lateral face `u = 1`,
/// the end discs `w = 0, 1`; the axis `u = 0` and the seam faces `v = 0, 1` bound nothing)
/// share their two rims, so every edge is used twice — by two faces, or by one face along
/// its seam — and the shell is closed: a `MANIFOLD_SOLID_BREP` in an advanced B-rep
/// representation. Within the shell each edge runs once each way (OCCT confirms that the
/// orientation is outward, by the volume, in `crates/pdeshape-io/tests/occt`).
#[test]
fn a_solid_blend_is_a_closed_shell() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.step");
    let o = build(&example("solid-cylinders.toml"), &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    for face in ["solid-u1", "solid-w0", "solid-w1"] {
        assert!(err.contains(&format!("face {face}: B-spline")), "{err}");
    }
    let text = std::fs::read_to_string(&out).unwrap();
    let (defs, refs) = entities(&text);
    assert!(refs.iter().all(|r| defs.contains_key(r)));
    assert_eq!(count(&defs, "CLOSED_SHELL"), 1);
    assert_eq!(count(&defs, "MANIFOLD_SOLID_BREP"), 1);
    assert_eq!(count(&defs, "OPEN_SHELL"), 0);
    assert_eq!(count(&defs, "ADVANCED_BREP_SHAPE_REPRESENTATION"), 1);
    assert_eq!(count(&defs, "ADVANCED_FACE"), 3);
    // every edge twice, once each way about the faces' normals
    let mut uses: HashMap<usize, Vec<bool>> = HashMap::new();
    for face in defs.values().filter(|b| b.starts_with("ADVANCED_FACE(")) {
        for b in refs_in(face)
            .iter()
            .filter(|r| defs[r].starts_with("FACE_OUTER_BOUND(") || defs[r].starts_with("FACE_BOUND("))
        {
            let bound = &defs[b];
            // the bound's orientation says how its loop runs about the face's normal
            let with = bound.ends_with(",.T.)");
            let lp = &defs[&refs_in(bound)[0]];
            for oe in refs_in(lp) {
                let body = &defs[&oe];
                let edge = refs_in(body)[0];
                uses.entry(edge).or_default().push(body.ends_with(",.T.)") == with);
            }
        }
    }
    assert_eq!(uses.len(), count(&defs, "EDGE_CURVE"));
    for (e, u) in &uses {
        assert!(u.len() == 2 && u[0] != u[1], "edge #{e}: {u:?}");
    }
}

/// The dolphin is one shell: each fin's root edge (its isocurve `u = 0`) is the edge of
/// one of the body's three holes, used once by the body's inner loop and once by the
/// fin's outer loop, in opposite directions.
#[test]
fn the_dolphins_fins_share_their_roots_with_the_body() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("d.step");
    let o = build(&example("dolphin.toml"), &out, &["-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let (defs, _) = entities(&text);
    assert_eq!(count(&defs, "OPEN_SHELL"), 1);
    let face = |name: &str| defs.values().find(|b| b.starts_with(&format!("ADVANCED_FACE('{name}',"))).unwrap();
    // (edge, direction about the face's normal: the bound's orientation already says how
    // the loop runs about it, `same_sense` included) of a face's loops
    let loops = |f: &String, outer: bool| -> Vec<(usize, bool)> {
        let kind = if outer { "FACE_OUTER_BOUND(" } else { "FACE_BOUND(" };
        let mut out = Vec::new();
        for b in refs_in(f).into_iter().filter(|r| defs[r].starts_with(kind)) {
            let bound = &defs[&b];
            let with = bound.ends_with(",.T.)");
            for oe in refs_in(&defs[&refs_in(bound)[0]]) {
                let body = &defs[&oe];
                out.push((refs_in(body)[0], body.ends_with(",.T.)") == with));
            }
        }
        out
    };
    let holes = loops(face("body"), false);
    assert_eq!(holes.len(), 3);
    for fin in ["dorsal", "right_fin", "left_fin"] {
        let shared: Vec<(usize, bool)> =
            loops(face(fin), true).into_iter().filter(|(e, _)| holes.iter().any(|h| h.0 == *e)).collect();
        assert_eq!(shared.len(), 1, "{fin}");
        let hole = holes.iter().find(|h| h.0 == shared[0].0).unwrap();
        assert_ne!(hole.1, shared[0].1, "{fin}: the root edge runs the same way in both faces");
    }
}

/// `--degree 5`: the faces interpolate the second cross derivative at their ends as well,
/// so the 6th-order (C2) blend of blend-cone-cylinder stays curvature-continuous with its
/// cone and cylinder after export (cross curvature gap 5e-3 … 6e-3 bicubic, ~1e-13
/// quintic, measured); the 4th-order blend, C1 only, keeps its curvature jump of order 1.
/// Degrees other than 3 and 5 are usage errors; `--degree` with a mesh format is refused.
#[test]
fn degree_five_keeps_curvature_across_c2_seams() {
    let seams = |degree: &str| -> Vec<serde_json::Value> {
        let o = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
            .args(["check", "--cad", "--json", "--degree", degree])
            .arg(example("blend-cone-cylinder.toml"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        d["cad"]["seams"].as_array().unwrap().clone()
    };
    let gap = |seams: &[serde_json::Value], face: &str| -> f64 {
        let mine: Vec<f64> =
            seams.iter().filter(|s| s["faces"][0] == face).map(|s| s["curvature_gap"].as_f64().unwrap()).collect();
        assert_eq!(mine.len(), 2, "{face}: {seams:?}");
        mine.into_iter().fold(0.0, |m, x| if x.is_nan() || x > m { x } else { m })
    };
    let (cubic, quintic) = (seams("3"), seams("5"));
    assert!(gap(&cubic, "o6") > 1e-4, "{}", gap(&cubic, "o6"));
    // round-off of second derivatives of the fitted faces (curvatures of order 1)
    assert!(gap(&quintic, "o6") < 1e-10, "{}", gap(&quintic, "o6"));
    assert!(gap(&quintic, "o4") > 0.1, "{}", gap(&quintic, "o4"));
    for s in &quintic {
        let (face, angle) = (s["faces"][0].as_str().unwrap(), s["normal_angle_radians"].as_f64().unwrap());
        if face.starts_with("o2") {
            // second-order blends are C0: they crease at their seams (0.18 … 0.43 rad)
            assert!(angle > 0.1, "{s}");
        } else {
            // C1 blends: round-off of the fitted faces' first derivatives (measured ≤ 1.8e-14)
            assert!(angle <= 1e-12, "{s}");
        }
    }
    let dir = tempfile::tempdir().unwrap();
    let o = build(&example("bloor-wilson-blend.toml"), &dir.path().join("x.step"), &["--degree", "4"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("degree 3 or 5"));
    let out = dir.path().join("x.obj");
    let o = build(&example("bloor-wilson-blend.toml"), &out, &["--degree", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("STEP output only") && !out.exists());
}

/// A hole's edge is a `SURFACE_CURVE`: the 3D curve (master) and, as its `PCURVE` on the
/// trimmed face's surface, the trim curve in `(u, v)` — a planar B-spline with 2D points
/// in a 2D parametric context (OCCT reads it back on the circle to 2.9e-7 in
/// `crates/pdeshape-io/tests/occt`).
#[test]
fn a_hole_edge_carries_its_pcurve() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.step");
    let o = build(&example("trim-circle.toml"), &out, &["-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    let (defs, refs) = entities(&text);
    assert!(refs.iter().all(|r| defs.contains_key(r)));
    let face = defs.values().find(|b| b.starts_with("ADVANCED_FACE(")).unwrap();
    let surface = refs_in(face).into_iter().find(|r| defs[r].starts_with("B_SPLINE_SURFACE_WITH_KNOTS(")).unwrap();
    let pcurves: Vec<&String> = defs.values().filter(|b| b.starts_with("PCURVE(")).collect();
    assert_eq!(pcurves.len(), 1);
    let r = refs_in(pcurves[0]);
    assert_eq!(r[0], surface, "the pcurve lies on the face's surface");
    let rep = &defs[&r[1]];
    assert!(rep.starts_with("DEFINITIONAL_REPRESENTATION("), "{rep}");
    let rr = refs_in(rep);
    assert!(defs[&rr[1]].contains("GEOMETRIC_REPRESENTATION_CONTEXT(2)PARAMETRIC_REPRESENTATION_CONTEXT()"));
    let c2 = &defs[&rr[0]];
    assert!(c2.starts_with("B_SPLINE_CURVE_WITH_KNOTS('',3,"), "{c2}");
    for p in refs_in(c2) {
        let pt = &defs[&p];
        // CARTESIAN_POINT('',(u,v)): two coordinates
        assert_eq!(pt.matches(',').count(), 2, "{pt}");
    }
    let sc: Vec<&String> = defs.values().filter(|b| b.starts_with("SURFACE_CURVE(")).collect();
    assert_eq!(sc.len(), 1);
    assert!(
        sc[0].ends_with(".CURVE_3D.)")
            && refs_in(sc[0])[1] == *defs.iter().find(|(_, b)| b.starts_with("PCURVE(")).unwrap().0
    );
    assert!(defs.values().any(|b| b.starts_with("EDGE_CURVE(")
        && refs_in(b)[2] == *defs.iter().find(|(_, b)| b.starts_with("SURFACE_CURVE(")).unwrap().0));
}

/// The face lines of a build's report: (name, measured deviation, tolerance).
fn face_figures(err: &str) -> Vec<(String, f64, f64)> {
    err.lines()
        .filter_map(|l| {
            let rest = l.strip_prefix("face ")?;
            let (name, rest) = rest.split_once(": B-spline")?;
            let rest = rest.split("measured deviation ").nth(1)?;
            let (d, t) = rest.split_once(" ≤ ")?;
            Some((name.to_string(), d.trim().parse().ok()?, t.trim().parse().ok()?))
        })
        .collect()
}

/// A Hermite sheet between two parallel lines at `scale`: its fit is measured alike at
/// every scale. Scaled to 1e-160 the squared deviations underflowed ("0 ≤ 5.7e-166"); here
/// the measured deviation over the tolerance is the same at 1e-160, 1 and 1e160 (to 1e-6:
/// the three fits run the same refinement on numbers that differ by round-off).
#[test]
fn the_fit_is_measured_alike_at_every_scale() {
    let dir = tempfile::tempdir().unwrap();
    let mut ratios = Vec::new();
    for scale in ["1e-160", "1", "1e160"] {
        let scene = format!(
            "[curves.a]\nexpr = [\"{scale}*cos(v)\", \"{scale}*sin(v)\", \"0\"]\n\
             [curves.b]\nexpr = [\"{scale}*(1.5 + 0.2*cos(3*v))*cos(v)\", \"{scale}*1.5*sin(v)\", \"{scale}\"]\n\
             [patches.p]\nkind = \"hermite\"\nconditions = [{{ u = 0, curve = \"a\" }}, {{ u = 1, curve = \"b\" }}]\n"
        );
        let path = dir.path().join("s.toml");
        std::fs::write(&path, scene).unwrap();
        let out = dir.path().join(format!("s{scale}.step"));
        let o = build(&path, &out, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(0), "{scale}: {err}");
        let f = face_figures(&err);
        assert_eq!(f.len(), 1, "{err}");
        let (_, dev, tol) = &f[0];
        assert!(*dev > 0.0 && dev.is_finite() && dev <= tol, "{scale}: {dev} ≤ {tol}");
        ratios.push(dev / tol);
    }
    for r in &ratios[1..] {
        // the report prints 4 significant digits
        assert!((r / ratios[0] - 1.0).abs() < 1e-3, "{ratios:?}");
    }
}

/// A tolerance that exceeds the geometry (`--relative-tolerance 10`, `--tolerance` above a
/// face's sides) wrote empty `EDGE_LOOP`s and one-face closed shells with exit 0; it is
/// refused, naming the face, and nothing is written.
#[test]
fn a_tolerance_beyond_the_geometry_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.step");
    for args in [["--relative-tolerance", "10"], ["--tolerance", "5"]] {
        let o = build(&example("bloor-wilson-blend.toml"), &out, &args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("the tolerance exceeds the geometry") && err.contains("face `"), "{args:?}: {err}");
        assert!(!out.exists());
    }
}

/// A patch that is one point was fitted for 1.2 s to "tolerance 0 was not reached": it is
/// refused at once as having no face.
#[test]
fn a_patch_that_is_one_point_has_no_face() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("point.toml");
    std::fs::write(
        &scene,
        "[curves.a]\nexpr = [\"1\", \"2\", \"3\"]\n[patches.p]\nkind = \"hermite\"\n\
         conditions = [{ u = 0, curve = \"a\" }, { u = 1, curve = \"a\" }]\n",
    )
    .unwrap();
    let out = dir.path().join("x.step");
    let t = std::time::Instant::now();
    let o = build(&scene, &out, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("single point"), "{err}");
    assert!(t.elapsed().as_secs_f64() < 1.0, "{:?}", t.elapsed());
    assert!(!out.exists());
}
