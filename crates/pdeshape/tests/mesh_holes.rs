//! `pdeshape holes` and `fill-holes` on triangle meshes the tests make (an icosphere with
//! caps cut away, a height field with a hole): the loops found, the filled mesh keeping
//! every input vertex and triangle and closing the holes, its seams as measured, and the
//! refusals of bad input.

use pdeshape_core::Vec3;
use pdeshape_core::limits::Limits;
use pdeshape_core::trimesh::shapes::{cut_cap, height_grid, icosphere};
use pdeshape_core::trimesh::{TriMesh, boundary};
use pdeshape_io::import::mesh::read_mesh;
use std::path::Path;
use std::process::{Command, Output};

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdeshape")).args(args).output().unwrap()
}

fn write_obj(path: &Path, m: &TriMesh) {
    let mut s = String::new();
    for p in &m.positions {
        s += &format!("v {:?} {:?} {:?}\n", p.x, p.y, p.z);
    }
    for t in &m.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(path, s).unwrap();
}

/// The icosphere (level 4) with two caps cut away: 30° and 20°.
fn two_holes() -> TriMesh {
    let m = cut_cap(&icosphere(4), Vec3::new(0.3, 0.2, 0.9).normalized().unwrap(), 30f64.to_radians());
    cut_cap(&m, Vec3::new(-0.5, 0.8, -0.3).normalized().unwrap(), 20f64.to_radians())
}

fn json(path: &Path) -> serde_json::Value {
    let o = run(&["holes", path.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Both caps' rims are simple loops; at order 6 both are filled, every input vertex and
/// triangle is written back in place and bit for bit, the mesh is closed and consistently
/// oriented, the new vertices lie near the sphere, and each seam is measured.
#[test]
fn sphere_holes_listed_filled_and_closed() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.obj");
    let m = two_holes();
    write_obj(&input, &m);
    let r = json(&input);
    assert_eq!(r["format"], "OBJ");
    let h = r["holes"].as_array().unwrap();
    assert_eq!(h.len(), 2);
    assert!(h.iter().all(|x| x["kind"] == "hole"));
    for (out, order) in [("filled.obj", "6"), ("filled.ply", "4")] {
        let out = dir.path().join(out);
        let o = run(&["fill-holes", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--order", order]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert_eq!(err.matches("hole ").count(), 2, "{err}");
        let back = read_mesh(&out, &Limits::default()).unwrap().mesh;
        assert_eq!(&back.positions[..m.positions.len()], &m.positions[..], "input vertices bit for bit");
        assert_eq!(&back.triangles[..m.triangles.len()], &m.triangles[..], "input triangles in place");
        assert!(boundary(&back).unwrap().is_empty(), "closed and consistently oriented");
        // the fills' vertices against the unit sphere: the least-bending fill is a little
        // flatter than the sphere (measured 5.2e-3 at the 30° cap's pole)
        let off = back.positions[m.positions.len()..].iter().map(|p| (p.norm() - 1.0).abs()).fold(0.0, f64::max);
        assert!(off < 6e-3, "{off}");
    }
}

/// A height field's outer rim and its hole are both loops, told apart: the rim is left
/// open (by default, and by `--max-edges`) and the hole filled; asking for a hole that
/// does not exist is an error.
#[test]
fn max_edges_leaves_the_rim_open() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("field.obj");
    let m = height_grid(40, 0.35, |x, y| 0.3 * (x * x - 0.5 * y * y) + 0.1 * x * y);
    write_obj(&input, &m);
    let r = json(&input);
    let h = r["holes"].as_array().unwrap();
    assert_eq!(h.len(), 2);
    let rim = h.iter().map(|x| x["edges"].as_u64().unwrap()).max().unwrap();
    assert_eq!(rim, 160, "the grid's rim: 4 × 40 edges");
    for x in h {
        let facing = x["facing"].as_f64().unwrap();
        if x["edges"] == 160 {
            // the saddle tilts the normals along the rim (|∇z| up to 0.6 there): 0.88 seen
            assert!(x["kind"] == "rim" && facing > 0.8, "{x}");
        } else {
            assert!(x["kind"] == "hole" && facing < -0.9, "{x}");
        }
    }
    let out = dir.path().join("filled.stl");
    for extra in [&[][..], &["--max-edges", "100"][..]] {
        let mut args = vec!["fill-holes", input.to_str().unwrap(), "-o", out.to_str().unwrap()];
        args.extend(extra);
        let o = run(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        assert!(err.contains("left open (rim, 160 edges)"), "{err}");
        let back = read_mesh(&out, &Limits::default()).unwrap().mesh;
        let loops = boundary(&back).unwrap();
        assert_eq!(loops.len(), 1, "only the rim remains");
        assert_eq!(loops[0].vertices.len(), 160);
    }
    let o = run(&["fill-holes", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--holes", "3"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("hole 3 does not exist: the mesh has 2"));
}

/// Bad meshes are refused with the element named, exit 1, and nothing written; a format
/// that is not a mesh or a model is a usage error.
#[test]
fn bad_meshes_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    let cases: Vec<(&str, String, &str)> = vec![
        ("nan.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n".into(), "vertex 1: a coordinate is not finite"),
        (
            "fin.obj",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n".into(),
            "edge (0, 1) is non-manifold: triangles [0, 1, 2] share it",
        ),
        ("dup.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 2 3 1\n".into(), "triangle 1 repeats triangle 0"),
        ("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".into(), "triangle 0 is degenerate (zero area)"),
        ("index.obj", "v 0 0 0\nf 1 2 3\n".into(), "vertex index 2 is out of range"),
        // the reader's line numbers: formatted only when a line is refused
        ("short.obj", "v 0 0 0\nv 1 0\n".into(), "short.obj:2: a vertex needs 3 coordinates, found 2"),
        ("word.obj", "# c\nv 0 0 0\nv 1 x 0\n".into(), "word.obj:3: `x` is not a number"),
        ("edge.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2\n".into(), "edge.obj:5: a face of 2 vertices"),
        ("cut.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n".into(), "vertex 2: the file ends before property `x`"),
    ];
    for (name, text, want) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        for args in
            [vec!["holes", p.to_str().unwrap()], vec!["fill-holes", p.to_str().unwrap(), "-o", out.to_str().unwrap()]]
        {
            let o = run(&args);
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(1), "{name}: {err}");
            assert!(err.contains(want), "{name}: {err}");
            assert!(err.contains(name), "{name}: the file is named: {err}");
        }
        assert!(!out.exists(), "{name}: nothing written");
    }
    let o = run(&["holes", "model.xyz"]);
    assert_eq!(o.status.code(), Some(2));
    let m = dir.path().join("m.obj");
    write_obj(&m, &two_holes());
    let o = run(&["fill-holes", m.to_str().unwrap(), "-o", dir.path().join("m.step").to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
}

/// A small closed ball (no loops of its own) sits where the sphere's hole is: the fill
/// would pass through it, so the hole is reported, not filled, exit 1, nothing written.
/// Without the ball the same hole fills.
#[test]
fn a_fill_that_would_cross_the_mesh_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = Vec3::new(0.3, 0.2, 0.9).normalized().unwrap();
    let sphere = cut_cap(&icosphere(4), d, 30f64.to_radians());
    let ball = icosphere(1);
    let mut m = sphere.clone();
    let base = m.positions.len() as u32;
    // radius 0.08 about the true sphere's point: the fill, within ~1e-2 of the sphere
    // there, passes through the ball
    m.positions.extend(ball.positions.iter().map(|&p| d + p * 0.08));
    m.triangles.extend(ball.triangles.iter().map(|t| t.map(|i| i + base)));
    assert_eq!(boundary(&m).unwrap().len(), 1);
    let input = dir.path().join("blocked.obj");
    let out = dir.path().join("out.obj");
    write_obj(&input, &m);
    let o = run(&["fill-holes", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("hole 1: the fill would cross the mesh") && err.contains("input triangle"), "{err}");
    assert!(!out.exists());
    // the ball moved inside the sphere, clear of the fill: filled
    let mut clear = sphere;
    let base = clear.positions.len() as u32;
    clear.positions.extend(ball.positions.iter().map(|&p| d * 0.5 + p * 0.08));
    clear.triangles.extend(ball.triangles.iter().map(|t| t.map(|i| i + base)));
    write_obj(&input, &clear);
    let o = run(&["fill-holes", input.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
}

/// `render` draws a mesh file in zebra stripes (a PNG of the size asked); a curvature
/// view or `--set` on a mesh file is a usage error, nothing written.
#[test]
fn render_draws_a_mesh_file() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("sphere.obj");
    write_obj(&input, &two_holes());
    let png = dir.path().join("zebra.png");
    let o = run(&[
        "render",
        input.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--view",
        "zebra",
        "--width",
        "120",
        "--height",
        "90",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&png).unwrap();
    // the IHDR chunk: width and height, big-endian, at bytes 16..24
    assert_eq!(&bytes[1..4], b"PNG");
    assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 120);
    assert_eq!(u32::from_be_bytes(bytes[20..24].try_into().unwrap()), 90);
    for (args, what) in
        [(&["--view", "mean"][..], "needs a scene's exact curvature"), (&["--set", "a=1"][..], "a mesh file has none")]
    {
        let out = dir.path().join("no.png");
        let mut a = vec!["render", input.to_str().unwrap(), "-o", out.to_str().unwrap()];
        a.extend(args);
        let o = run(&a);
        assert_eq!(o.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&o.stderr).contains(what), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(!out.exists());
    }
}
