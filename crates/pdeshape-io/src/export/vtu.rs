//! VTK XML unstructured grids (`.vtu`): surfaces (quads, triangles) and hexahedra.

use pdeshape_core::Vec3;
use pdeshape_core::mesh::{HexMesh, Mesh, ScalarField};
use std::io::{self, Write};

const VTK_TRIANGLE: u8 = 5;
const VTK_QUAD: u8 = 9;
const VTK_HEXAHEDRON: u8 = 12;

fn header(w: &mut dyn Write, npts: usize, ncells: usize) -> io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">"
    )?;
    writeln!(w, "<UnstructuredGrid>\n<Piece NumberOfPoints=\"{npts}\" NumberOfCells=\"{ncells}\">")
}

fn points(w: &mut dyn Write, pts: &[Vec3]) -> io::Result<()> {
    writeln!(w, "<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">")?;
    for p in pts {
        writeln!(w, "{:?} {:?} {:?}", p.x, p.y, p.z)?;
    }
    writeln!(w, "</DataArray>\n</Points>")
}

fn cells(w: &mut dyn Write, conn: &[Vec<u32>], types: &[u8]) -> io::Result<()> {
    writeln!(w, "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">")?;
    for c in conn {
        writeln!(w, "{}", c.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" "))?;
    }
    writeln!(w, "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">")?;
    let mut off = 0;
    for c in conn {
        off += c.len();
        writeln!(w, "{off}")?;
    }
    writeln!(w, "</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">")?;
    for t in types {
        writeln!(w, "{t}")?;
    }
    writeln!(w, "</DataArray>\n</Cells>")
}

fn scalar(w: &mut dyn Write, f: &ScalarField) -> io::Result<()> {
    writeln!(w, "<DataArray type=\"Float64\" Name=\"{}\" format=\"ascii\">", xml_name(&f.name))?;
    for x in &f.values {
        writeln!(w, "{x:?}")?;
    }
    writeln!(w, "</DataArray>")
}

fn xml_name(s: &str) -> String {
    s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect()
}

fn footer(w: &mut dyn Write) -> io::Result<()> {
    writeln!(w, "</Piece>\n</UnstructuredGrid>\n</VTKFile>")
}

/// Writes surface meshes as one unstructured grid of quads and triangles, with normals,
/// the patch index (`patch`, a cell field) and every scalar field present in all meshes.
pub fn write_vtu_surface(w: &mut dyn Write, meshes: &[&Mesh]) -> io::Result<()> {
    let pts: Vec<Vec3> = meshes.iter().flat_map(|m| m.positions.iter().copied()).collect();
    let mut conn = Vec::new();
    let mut types = Vec::new();
    let mut patch_id = Vec::new();
    let mut base = 0u32;
    for (k, m) in meshes.iter().enumerate() {
        for q in &m.quads {
            conn.push(q.iter().map(|i| i + base).collect());
            types.push(VTK_QUAD);
            patch_id.push(k as f64);
        }
        for t in &m.triangles {
            conn.push(t.iter().map(|i| i + base).collect());
            types.push(VTK_TRIANGLE);
            patch_id.push(k as f64);
        }
        base += m.positions.len() as u32;
    }
    header(w, pts.len(), conn.len())?;
    points(w, &pts)?;
    cells(w, &conn, &types)?;
    writeln!(w, "<PointData>")?;
    if meshes.iter().all(|m| m.normals.len() == m.positions.len()) && !pts.is_empty() {
        writeln!(w, "<DataArray type=\"Float64\" Name=\"Normals\" NumberOfComponents=\"3\" format=\"ascii\">")?;
        for n in meshes.iter().flat_map(|m| m.normals.iter()) {
            writeln!(w, "{:?} {:?} {:?}", n.x, n.y, n.z)?;
        }
        writeln!(w, "</DataArray>")?;
    }
    if let Some(first) = meshes.first() {
        for f in &first.fields {
            if meshes.iter().all(|m| m.field(&f.name).is_some()) {
                let values = meshes
                    .iter()
                    .flat_map(|m| m.field(&f.name).map(|f| f.values.clone()).unwrap_or_default())
                    .collect();
                scalar(w, &ScalarField { name: f.name.clone(), values })?;
            }
        }
    }
    writeln!(w, "</PointData>\n<CellData>")?;
    scalar(w, &ScalarField { name: "patch".into(), values: patch_id })?;
    writeln!(w, "</CellData>")?;
    footer(w)
}

/// Writes a hexahedral volume mesh with its point and cell fields.
pub fn write_vtu_hex(w: &mut dyn Write, m: &HexMesh) -> io::Result<()> {
    let conn: Vec<Vec<u32>> = m.hexes.iter().map(|h| h.to_vec()).collect();
    header(w, m.positions.len(), conn.len())?;
    points(w, &m.positions)?;
    cells(w, &conn, &vec![VTK_HEXAHEDRON; conn.len()])?;
    writeln!(w, "<PointData>")?;
    for f in &m.point_fields {
        scalar(w, f)?;
    }
    writeln!(w, "</PointData>\n<CellData>")?;
    for f in &m.cell_fields {
        scalar(w, f)?;
    }
    writeln!(w, "</CellData>")?;
    footer(w)
}
