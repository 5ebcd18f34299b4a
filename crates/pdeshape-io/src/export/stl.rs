//! Binary STL.

use pdeshape_core::mesh::Mesh;
use std::io::{self, Write};

/// Writes all faces of all meshes as binary STL triangles with facet normals from the
/// vertex winding (quads split along the shorter diagonal).
pub fn write_stl(w: &mut dyn Write, meshes: &[&Mesh]) -> io::Result<()> {
    let tris: Vec<(usize, [u32; 3])> =
        meshes.iter().enumerate().flat_map(|(k, m)| m.all_triangles().into_iter().map(move |t| (k, t))).collect();
    let mut header = [0u8; 80];
    let text = b"pdeshape binary STL";
    header[..text.len()].copy_from_slice(text);
    w.write_all(&header)?;
    w.write_all(&(tris.len() as u32).to_le_bytes())?;
    for (k, t) in tris {
        let m = meshes[k];
        let p = t.map(|i| m.positions[i as usize]);
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalized().unwrap_or_default();
        for c in n.to_array().into_iter().chain(p.iter().flat_map(|q| q.to_array())) {
            w.write_all(&(c as f32).to_le_bytes())?;
        }
        w.write_all(&[0u8, 0u8])?;
    }
    Ok(())
}
