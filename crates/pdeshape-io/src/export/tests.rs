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
    // triangles too, so both kinds of face go through every writer
    let q = m.quads.pop().unwrap();
    m.triangles.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
    let values = m.positions.iter().map(|p| p.z + 0.25 * p.x).collect();
    m.fields.push(ScalarField { name: "height".into(), values });
    m
}

/// Faces as the writers emit them: quads, then triangles, indices offset by `base`.
fn faces(m: &Mesh, base: u32) -> Vec<Vec<u32>> {
    m.quads
        .iter()
        .map(|q| q.iter().map(|i| i + base).collect())
        .chain(m.triangles.iter().map(|t| t.iter().map(|i| i + base).collect()))
        .collect()
}

/// f32 storage of an f64: equal to the value rounded to f32.
fn same32(a: f32, b: f64) -> bool {
    a == b as f32
}

/// An f32 parsed from the f64's shortest decimal text: within one f32 ulp of it (rounding
/// the decimal to f32 and rounding the f64 to f32 can differ by one ulp).
fn near32(a: f32, b: f64) -> bool {
    (a as f64 - b).abs() <= f32::EPSILON as f64 * b.abs().max(f32::MIN_POSITIVE as f64)
}

#[test]
fn obj_reads_back_with_tobj() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (sample_mesh("first"), sample_mesh("second"));
    let path = dir.path().join("m.obj");
    write_meshes(&path, Format::Obj, &[&a, &b]).unwrap();
    // separate index lists for positions, normals and texture coordinates
    let (models, _) =
        tobj::load_obj(&path, &tobj::LoadOptions { single_index: false, triangulate: false, ..Default::default() })
            .unwrap();
    assert_eq!(models.len(), 2);
    for (model, m, name) in [(&models[0], &a, "first"), (&models[1], &b, "second")] {
        assert_eq!(model.name, name);
        let t = &model.mesh;
        let want = faces(m, 0);
        assert_eq!(t.face_arities, want.iter().map(|f| f.len() as u32).collect::<Vec<_>>());
        let flat: Vec<u32> = want.into_iter().flatten().collect();
        assert_eq!(
            (t.indices.len(), t.normal_indices.len(), t.texcoord_indices.len()),
            (flat.len(), flat.len(), flat.len())
        );
        // tobj numbers the vertices of each object in its own order: every face corner
        // must lead to the mesh vertex's position, normal and texture coordinate
        for (k, &want_vertex) in flat.iter().enumerate() {
            let w = want_vertex as usize;
            let (pi, ni, ti) = (t.indices[k] as usize, t.normal_indices[k] as usize, t.texcoord_indices[k] as usize);
            for c in 0..3 {
                assert!(near32(t.positions[3 * pi + c], m.positions[w][c]), "corner {k}: position");
                assert!(near32(t.normals[3 * ni + c], m.normals[w][c]), "corner {k}: normal");
            }
            for c in 0..2 {
                assert!(near32(t.texcoords[2 * ti + c], m.uvs[w][c]), "corner {k}: uv");
            }
        }
        // and every vertex of the mesh is there once
        assert_eq!(t.positions.len(), 3 * m.positions.len());
    }
}

#[test]
fn ply_reads_back_with_ply_rs() {
    use ply_rs::ply::Property;
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (sample_mesh("a"), sample_mesh("b"));
    let path = dir.path().join("m.ply");
    write_meshes(&path, Format::Ply, &[&a, &b]).unwrap();
    let mut f = std::fs::File::open(&path).unwrap();
    let ply = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new().read_ply(&mut f).unwrap();
    let verts = &ply.payload["vertex"];
    assert_eq!(verts.len(), 2 * a.positions.len());
    let double = |p: &Property| match p {
        Property::Double(x) => *x,
        other => panic!("not a double: {other:?}"),
    };
    let float = |p: &Property| match p {
        Property::Float(x) => *x,
        other => panic!("not a float: {other:?}"),
    };
    let all: Vec<(&Mesh, usize)> =
        [&a, &b].into_iter().flat_map(|m| (0..m.positions.len()).map(move |i| (m, i))).collect();
    for (v, (m, i)) in verts.iter().zip(all) {
        for (k, c) in ["x", "y", "z"].into_iter().enumerate() {
            assert_eq!(double(&v[c]), m.positions[i][k], "{c} of vertex {i}");
        }
        for (k, c) in ["nx", "ny", "nz"].into_iter().enumerate() {
            assert!(same32(float(&v[c]), m.normals[i][k]), "{c} of vertex {i}");
        }
        assert!(same32(float(&v["s"]), m.uvs[i][0]) && same32(float(&v["t"]), m.uvs[i][1]), "uv {i}");
        assert!(same32(float(&v["height"]), m.fields[0].values[i]), "field at {i}");
    }
    let got: Vec<Vec<u32>> = ply.payload["face"]
        .iter()
        .map(|f| match &f["vertex_indices"] {
            Property::ListInt(l) => l.iter().map(|&i| i as u32).collect(),
            other => panic!("not a list of ints: {other:?}"),
        })
        .collect();
    let mut want = faces(&a, 0);
    want.extend(faces(&b, a.positions.len() as u32));
    assert_eq!(got, want);
}

#[test]
fn stl_reads_back_with_stl_io() {
    let dir = tempfile::tempdir().unwrap();
    let a = sample_mesh("a");
    let path = dir.path().join("m.stl");
    write_meshes(&path, Format::Stl, &[&a]).unwrap();
    let mut f = std::fs::File::open(&path).unwrap();
    let stl = stl_io::read_stl(&mut f).unwrap();
    let tris = a.all_triangles();
    assert_eq!(stl.faces.len(), tris.len());
    for (face, t) in stl.faces.iter().zip(&tris) {
        let p = t.map(|i| a.positions[i as usize]);
        for (k, &vi) in face.vertices.iter().enumerate() {
            let v = stl.vertices[vi];
            for c in 0..3 {
                assert!(same32(v[c], p[k][c]), "corner {k} of {t:?}");
            }
        }
        // the facet normal: the unit normal of the corners, counter-clockwise
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalized().unwrap();
        for c in 0..3 {
            assert!(same32(face.normal[c], n[c]), "normal of {t:?}");
        }
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
    for (gm, m) in meshes.iter().zip([&a, &b]) {
        let prim = gm.primitives().next().unwrap();
        let reader = prim.reader(|buf| Some(&buffers[buf.index()]));
        let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let nrm: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
        let uv: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
        assert_eq!((pos.len(), nrm.len(), uv.len()), (m.positions.len(), m.positions.len(), m.positions.len()));
        for i in 0..m.positions.len() {
            for c in 0..3 {
                assert!(same32(pos[i][c], m.positions[i][c]) && same32(nrm[i][c], m.normals[i][c]), "vertex {i}");
            }
            assert!(same32(uv[i][0], m.uvs[i][0]) && same32(uv[i][1], m.uvs[i][1]), "uv {i}");
        }
        let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        assert_eq!(idx, m.all_triangles().into_iter().flatten().collect::<Vec<_>>());
        // the field, as an application attribute `_HEIGHT`, every value
        let (_, acc) = prim
            .attributes()
            .find(|(sem, _)| *sem == ::gltf::Semantic::Extras("HEIGHT".into()))
            .expect("the field attribute");
        let view = acc.view().unwrap();
        let data = &buffers[view.buffer().index()][view.offset() + acc.offset()..];
        for (i, want) in m.fields[0].values.iter().enumerate() {
            let got = f32::from_le_bytes(data[4 * i..4 * i + 4].try_into().unwrap());
            assert!(same32(got, *want), "field at {i}");
        }
    }
    let prim = meshes[0].primitives().next().unwrap();
    let reader = prim.reader(|buf| Some(&buffers[buf.index()]));
    let targets: Vec<_> = reader.read_morph_targets().collect();
    assert_eq!(targets.len(), 3);
    for (k, (dp, dn, _)) in targets.into_iter().enumerate() {
        // frame k moves every vertex by (0, 0, k); the normals do not change
        let dp: Vec<[f32; 3]> = dp.unwrap().collect();
        assert!(dp.iter().all(|d| d[0] == 0.0 && d[1] == 0.0 && (d[2] - k as f32).abs() < 1e-6), "frame {k}");
        assert!(dn.unwrap().all(|d| d == [0.0; 3]), "frame {k}");
    }
    assert_eq!(doc.animations().count(), 1);
}

#[test]
fn vtu_reads_back_with_vtkio() {
    use vtkio::model::{Attribute, DataSet, Piece, VertexNumbers};
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (sample_mesh("a"), sample_mesh("b"));
    let path = dir.path().join("m.vtu");
    write_meshes(&path, Format::Vtu, &[&a, &b]).unwrap();
    let vtk = vtkio::Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
    let pts: Vec<f64> = piece.points.clone().cast_into().unwrap();
    let want_pts: Vec<f64> = [&a, &b].iter().flat_map(|m| m.positions.iter().flat_map(|p| p.to_array())).collect();
    assert_eq!(pts, want_pts);
    let mut want = faces(&a, 0);
    want.extend(faces(&b, a.positions.len() as u32));
    let (conn, offsets) = match &piece.cells.cell_verts {
        VertexNumbers::XML { connectivity, offsets } => (connectivity.clone(), offsets.clone()),
        other => panic!("{other:?}"),
    };
    assert_eq!(conn, want.iter().flatten().map(|&i| i as u64).collect::<Vec<_>>());
    let mut end = 0;
    assert_eq!(
        offsets,
        want.iter()
            .map(|f| {
                end += f.len() as u64;
                end
            })
            .collect::<Vec<_>>()
    );
    use vtkio::model::CellType::{Quad, Triangle};
    assert_eq!(piece.cells.types, want.iter().map(|f| if f.len() == 4 { Quad } else { Triangle }).collect::<Vec<_>>());
    let arrays: Vec<(String, Vec<f64>)> = piece
        .data
        .point
        .iter()
        .map(|att| match att {
            Attribute::DataArray(d) => (d.name.clone(), d.data.clone().cast_into().unwrap()),
            Attribute::Field { name, .. } => panic!("unexpected field {name}"),
        })
        .collect();
    let get = |n: &str| arrays.iter().find(|(k, _)| k == n).unwrap_or_else(|| panic!("no {n} in {arrays:?}")).1.clone();
    let want_n: Vec<f64> = [&a, &b].iter().flat_map(|m| m.normals.iter().flat_map(|p| p.to_array())).collect();
    assert_eq!(get("Normals"), want_n);
    let want_f: Vec<f64> = [&a, &b].iter().flat_map(|m| m.fields[0].values.clone()).collect();
    assert_eq!(get("height"), want_f);

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
    match &piece.cells.cell_verts {
        VertexNumbers::XML { connectivity, .. } => assert_eq!(connectivity, &vec![0, 1, 3, 2, 4, 5, 7, 6]),
        other => panic!("{other:?}"),
    }
    let pts: Vec<f64> = piece.points.clone().cast_into().unwrap();
    assert_eq!(pts, hex.positions.iter().flat_map(|p| p.to_array()).collect::<Vec<_>>());
    match &piece.data.cell[..] {
        [Attribute::DataArray(d)] => {
            assert_eq!(d.name, "residual");
            assert_eq!(d.data.clone().cast_into::<f64>().unwrap(), vec![0.5]);
        }
        other => panic!("{other:?}"),
    }
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
