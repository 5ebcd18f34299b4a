//! Wavefront OBJ: one group per mesh, with normals and texture coordinates.

use pdeshape_core::mesh::Mesh;
use std::io::{self, Write};

/// Writes meshes as OBJ groups (`o`/`g` per mesh), full-precision coordinates, `vn`, `vt`,
/// and 1-based `v/vt/vn` faces (quads stay quads).
pub fn write_obj(w: &mut dyn Write, meshes: &[&Mesh]) -> io::Result<()> {
    writeln!(w, "# pdeshape OBJ export")?;
    let mut base = 1usize;
    for m in meshes {
        let name = if m.name.is_empty() { "patch" } else { &m.name };
        writeln!(w, "o {name}\ng {name}")?;
        for p in &m.positions {
            writeln!(w, "v {:?} {:?} {:?}", p.x, p.y, p.z)?;
        }
        for n in &m.normals {
            writeln!(w, "vn {:?} {:?} {:?}", n.x, n.y, n.z)?;
        }
        for t in &m.uvs {
            writeln!(w, "vt {:?} {:?}", t[0], t[1])?;
        }
        let (hn, ht) = (!m.normals.is_empty(), !m.uvs.is_empty());
        let vert = |i: u32| -> String {
            let k = i as usize + base;
            match (ht, hn) {
                (true, true) => format!("{k}/{k}/{k}"),
                (false, true) => format!("{k}//{k}"),
                (true, false) => format!("{k}/{k}"),
                (false, false) => format!("{k}"),
            }
        };
        for q in &m.quads {
            writeln!(w, "f {} {} {} {}", vert(q[0]), vert(q[1]), vert(q[2]), vert(q[3]))?;
        }
        for t in &m.triangles {
            writeln!(w, "f {} {} {}", vert(t[0]), vert(t[1]), vert(t[2]))?;
        }
        base += m.positions.len();
    }
    Ok(())
}
