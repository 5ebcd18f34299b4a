//! Binary little-endian PLY with per-vertex scalar fields.

use pdeshape_core::mesh::Mesh;
use std::io::{self, Write};

/// Writes all meshes as one binary PLY: `double x y z`, `float nx ny nz`, `float s t`, one
/// `float` property per scalar field present in every mesh, and polygon faces
/// (`list uchar int`). Meshes without normals or UVs get zeros.
pub fn write_ply(w: &mut dyn Write, meshes: &[&Mesh]) -> io::Result<()> {
    let nv: usize = meshes.iter().map(|m| m.positions.len()).sum();
    let nf: usize = meshes.iter().map(|m| m.quads.len() + m.triangles.len()).sum();
    let fields: Vec<String> = meshes
        .first()
        .map(|m| {
            m.fields
                .iter()
                .filter(|f| meshes.iter().all(|o| o.field(&f.name).is_some()))
                .map(|f| f.name.clone())
                .collect()
        })
        .unwrap_or_default();
    write!(w, "ply\nformat binary_little_endian 1.0\ncomment pdeshape export\n")?;
    for m in meshes {
        writeln!(
            w,
            "comment mesh {} vertices {}",
            if m.name.is_empty() { "patch" } else { &m.name },
            m.positions.len()
        )?;
    }
    write!(
        w,
        "element vertex {nv}\nproperty double x\nproperty double y\nproperty double z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n"
    )?;
    for f in &fields {
        writeln!(w, "property float {}", sanitize(f))?;
    }
    write!(w, "element face {nf}\nproperty list uchar int vertex_indices\nend_header\n")?;
    for m in meshes {
        for (i, p) in m.positions.iter().enumerate() {
            for c in p.to_array() {
                w.write_all(&c.to_le_bytes())?;
            }
            let n = m.normals.get(i).copied().unwrap_or_default();
            for c in n.to_array() {
                w.write_all(&(c as f32).to_le_bytes())?;
            }
            let t = m.uvs.get(i).copied().unwrap_or([0.0, 0.0]);
            for c in t {
                w.write_all(&(c as f32).to_le_bytes())?;
            }
            for f in &fields {
                let v = m.field(f).map(|f| f.values[i]).unwrap_or(0.0);
                w.write_all(&(v as f32).to_le_bytes())?;
            }
        }
    }
    let mut base = 0i32;
    for m in meshes {
        for q in &m.quads {
            w.write_all(&[4u8])?;
            for &i in q {
                w.write_all(&(i as i32 + base).to_le_bytes())?;
            }
        }
        for t in &m.triangles {
            w.write_all(&[3u8])?;
            for &i in t {
                w.write_all(&(i as i32 + base).to_le_bytes())?;
            }
        }
        base += m.positions.len() as i32;
    }
    Ok(())
}

fn sanitize(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect()
}
