//! Every exporter's output is read back by an independent reader.

use super::*;
use pdeshape_core::Vec3;
use pdeshape_core::data::{ExprField, FieldRef};
use pdeshape_core::mesh::{GridOptions, HexMesh, MorphAnimation, ScalarField, grid_mesh};
use pdeshape_core::patch::{Condition, HermitePatch, VDomain};
use std::sync::Arc;

fn sample_mesh(name: &str) -> Mesh {
    let f = |s: [&str; 3]| -> FieldRef { Arc::new(ExprField::parse(s, &["v", "t"], &|_| None).unwrap()) };
    let conds = vec![
        Condition { u: 0.0, order: 0, data: f(["cos(v)", "sin(v)", "0"]) },
        Condition { u: 0.0, order: 1, data: f(["0", "0", "1"]) },
        Condition { u: 1.0, order: 0, data: f(["0.5*cos(v)", "0.5*sin(v)", "1"]) },
        Condition { u: 1.0, order: 1, data: f(["0", "0", "1"]) },
    ];
    let p = HermitePatch::new(&conds, VDomain::PERIODIC).unwrap();
    let mut m = grid_mesh(&p, &GridOptions::new(5, 9)).unwrap();
    m.name = name.into();
    let values = m.positions.iter().map(|p| p.z).collect();
    m.fields.push(ScalarField { name: "height".into(), values });
    m
}

fn close32(a: f32, b: f64) -> bool {
    (a as f64 - b).abs() <= 1e-6 * (1.0 + b.abs())
}

#[test]
fn obj_reads_back_with_tobj() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (sample_mesh("first"), sample_mesh("second"));
    let path = dir.path().join("m.obj");
    write_meshes(&path, Format::Obj, &[&a, &b]).unwrap();
    let (models, _) =
        tobj::load_obj(&path, &tobj::LoadOptions { single_index: true, triangulate: false, ..Default::default() })
            .unwrap();
    assert_eq!(models.len(), 2);
    assert_eq!(models[0].name, "first");
    let pos = &models[1].mesh.positions;
    assert_eq!(pos.len(), 3 * b.positions.len());
    for v in pos.chunks(3) {
        let nearest = b
            .positions
            .iter()
            .map(|p| (*p - Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-6);
    }
    assert_eq!(models[0].mesh.face_arities.len(), a.quads.len());
    assert_eq!(models[0].mesh.normals.len(), 3 * a.normals.len());
}

#[test]
fn ply_reads_back_with_ply_rs() {
    use ply_rs::ply::Property;
    let dir = tempfile::tempdir().unwrap();
    let a = sample_mesh("a");
    let path = dir.path().join("m.ply");
    write_meshes(&path, Format::Ply, &[&a]).unwrap();
    let mut f = std::fs::File::open(&path).unwrap();
    let ply = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new().read_ply(&mut f).unwrap();
    let verts = &ply.payload["vertex"];
    assert_eq!(verts.len(), a.positions.len());
    for (v, p) in verts.iter().zip(&a.positions) {
        let Property::Double(x) = v["x"] else { panic!("x is not a double") };
        let Property::Double(z) = v["z"] else { panic!("z is not a double") };
        assert_eq!((x, z), (p.x, p.z));
        let Property::Float(h) = v["height"] else { panic!("field missing") };
        assert!(close32(h, p.z));
    }
    assert_eq!(ply.payload["face"].len(), a.quads.len());
}

#[test]
fn stl_reads_back_with_stl_io() {
    let dir = tempfile::tempdir().unwrap();
    let a = sample_mesh("a");
    let path = dir.path().join("m.stl");
    write_meshes(&path, Format::Stl, &[&a]).unwrap();
    let mut f = std::fs::File::open(&path).unwrap();
    let stl = stl_io::read_stl(&mut f).unwrap();
    assert_eq!(stl.faces.len(), 2 * a.quads.len());
    for v in &stl.vertices {
        let nearest = a
            .positions
            .iter()
            .map(|p| (p.x - v[0] as f64).abs() + (p.y - v[1] as f64).abs() + (p.z - v[2] as f64).abs())
            .fold(f64::INFINITY, f64::min);
        assert!(nearest < 1e-6);
    }
}

#[test]
fn glb_reads_back_with_gltf_including_morph_targets() {
    let dir = tempfile::tempdir().unwrap();
    let mut a = sample_mesh("animated");
    let frames: Vec<Vec<Vec3>> =
        (0..3).map(|k| a.positions.iter().map(|p| *p + Vec3::new(0.0, 0.0, k as f64)).collect()).collect();
    a.animation =
        Some(MorphAnimation { times: vec![0.0, 0.5, 1.0], positions: frames, normals: vec![a.normals.clone(); 3] });
    let b = sample_mesh("still");
    let path = dir.path().join("m.glb");
    write_meshes(&path, Format::Glb, &[&a, &b]).unwrap();
    let (doc, buffers, _) = ::gltf::import(&path).unwrap();
    let meshes: Vec<_> = doc.meshes().collect();
    assert_eq!(meshes.len(), 2);
    assert_eq!(doc.nodes().map(|n| n.name().unwrap_or("").to_string()).collect::<Vec<_>>(), ["animated", "still"]);
    let prim = meshes[0].primitives().next().unwrap();
    let reader = prim.reader(|buf| Some(&buffers[buf.index()]));
    let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
    assert_eq!(pos.len(), a.positions.len());
    for (p, q) in pos.iter().zip(&a.positions) {
        assert!(close32(p[0], q.x) && close32(p[2], q.z));
    }
    assert_eq!(reader.read_indices().unwrap().into_u32().count(), 6 * a.quads.len());
    let targets: Vec<_> = reader.read_morph_targets().collect();
    assert_eq!(targets.len(), 3);
    let (dp, _, _) = &targets[2];
    let dz: Vec<[f32; 3]> = dp.clone().unwrap().collect();
    assert!(dz.iter().all(|d| (d[2] - 2.0).abs() < 1e-6));
    assert_eq!(doc.animations().count(), 1);
    assert!(prim.attributes().any(|(sem, _)| sem == ::gltf::Semantic::Extras("HEIGHT".into())));
}

#[test]
fn vtu_reads_back_with_vtkio() {
    use vtkio::model::{DataSet, Piece};
    let dir = tempfile::tempdir().unwrap();
    let a = sample_mesh("a");
    let path = dir.path().join("m.vtu");
    write_meshes(&path, Format::Vtu, &[&a, &a]).unwrap();
    let vtk = vtkio::Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
    let pts: Vec<f64> = piece.points.clone().cast_into().unwrap();
    assert_eq!(pts.len(), 6 * a.positions.len());
    assert_eq!(pts[3 * 7 + 1], a.positions[7].y);
    assert_eq!(piece.cells.types.len(), 2 * a.quads.len());

    let hex = HexMesh {
        name: "cube".into(),
        positions: (0..8).map(|i| Vec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64)).collect(),
        hexes: vec![[0, 1, 3, 2, 4, 5, 7, 6]],
        point_fields: vec![],
        cell_fields: vec![ScalarField { name: "residual".into(), values: vec![0.5] }],
    };
    let path = dir.path().join("h.vtu");
    write_atomic(&path, |w| write_vtu_hex(w, &hex)).unwrap();
    let vtk = vtkio::Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
    assert_eq!(piece.cells.types, vec![vtkio::model::CellType::Hexahedron]);
}

#[test]
fn failed_writes_leave_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.obj");
    let r = write_atomic(&path, |w| {
        w.write_all(b"partial")?;
        Err(std::io::Error::other("interrupted"))
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "no file and no temporary left");
    let mut bad = sample_mesh("nan");
    bad.positions[3].x = f64::NAN;
    assert!(write_meshes(&path, Format::Obj, &[&bad]).is_err());
    assert!(!path.exists());
}
