//! Wavefront OBJ: one group per mesh, with normals and texture coordinates.

use pdeshape_core::mesh::Mesh;
use std::io::{self, Write};

/// Writes meshes as OBJ groups (`o`/`g` per mesh), full-precision coordinates, `vn`, `vt`,
/// and 1-based `v/vt/vn` faces (quads stay quads).
///
/// Each line is assembled in one reused buffer and handed to `w` whole: coordinates in
/// Rust's shortest round-trip form (`{:?}`), indices by `itoa`, no allocation a line.
pub fn write_obj(w: &mut dyn Write, meshes: &[&Mesh]) -> io::Result<()> {
    writeln!(w, "# pdeshape OBJ export")?;
    let mut base = 1usize;
    let mut line: Vec<u8> = Vec::with_capacity(96);
    for m in meshes {
        let name = if m.name.is_empty() { "patch" } else { &m.name };
        writeln!(w, "o {name}\ng {name}")?;
        for p in &m.positions {
            numbers(&mut line, b"v", &[p.x, p.y, p.z], w)?;
        }
        for n in &m.normals {
            numbers(&mut line, b"vn", &[n.x, n.y, n.z], w)?;
        }
        for t in &m.uvs {
            numbers(&mut line, b"vt", t, w)?;
        }
        // `k`, `k/k`, `k//k` or `k/k/k` as the mesh has texture coordinates and normals
        let (ht, hn) = (!m.uvs.is_empty(), !m.normals.is_empty());
        let tail: &[&[u8]] = match (ht, hn) {
            (true, true) => &[b"/", b"/"],
            (false, true) => &[b"//"],
            (true, false) => &[b"/"],
            (false, false) => &[],
        };
        for q in &m.quads {
            face(&mut line, q, base, tail, w)?;
        }
        for t in &m.triangles {
            face(&mut line, t, base, tail, w)?;
        }
        base += m.positions.len();
    }
    Ok(())
}

/// One line of a tag and coordinates, each in Rust's shortest round-trip form (`{:?}`).
fn numbers(line: &mut Vec<u8>, tag: &[u8], xs: &[f64], w: &mut dyn Write) -> io::Result<()> {
    line.clear();
    line.extend_from_slice(tag);
    for x in xs {
        write!(line, " {x:?}")?;
    }
    line.push(b'\n');
    w.write_all(line)
}

/// One face line: each corner's 1-based index, repeated after each separator of `tail`.
fn face(line: &mut Vec<u8>, corners: &[u32], base: usize, tail: &[&[u8]], w: &mut dyn Write) -> io::Result<()> {
    let mut int = itoa::Buffer::new();
    line.clear();
    line.push(b'f');
    for &i in corners {
        let k = int.format(i as usize + base).as_bytes();
        line.push(b' ');
        line.extend_from_slice(k);
        for sep in tail {
            line.extend_from_slice(sep);
            line.extend_from_slice(k);
        }
    }
    line.push(b'\n');
    w.write_all(line)
}

#[cfg(test)]
mod tests {
    use super::*;
    use pdeshape_core::Vec3;

    /// Every combination of normals and texture coordinates gives its own face form, the
    /// second mesh's indices continue after the first's, and coordinates keep `{:?}`'s
    /// shortest round-trip digits.
    #[test]
    fn faces_and_coordinates_as_obj_writes_them() {
        let base = Mesh {
            name: String::new(),
            positions: vec![Vec3::new(0.1, -2.5e-7, 1e16), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        };
        let with = |normals: bool, uvs: bool, name: &str| Mesh {
            name: name.into(),
            normals: if normals { vec![Vec3::new(0.0, 0.0, 1.0); 3] } else { vec![] },
            uvs: if uvs { vec![[0.5, 0.25]; 3] } else { vec![] },
            ..base.clone()
        };
        let meshes = [with(false, false, ""), with(true, false, "n"), with(false, true, "t"), with(true, true, "nt")];
        let mut out = Vec::new();
        write_obj(&mut out, &meshes.iter().collect::<Vec<_>>()).unwrap();
        let text = String::from_utf8(out).unwrap();
        let faces: Vec<&str> = text.lines().filter(|l| l.starts_with("f ")).collect();
        assert_eq!(faces, ["f 1 2 3", "f 4//4 5//5 6//6", "f 7/7 8/8 9/9", "f 10/10/10 11/11/11 12/12/12"]);
        assert!(
            text.starts_with("# pdeshape OBJ export\no patch\ng patch\nv 0.1 -2.5e-7 1e16\nv 1.0 0.0 0.0\n"),
            "{text}"
        );
        assert!(text.contains("\nvn 0.0 0.0 1.0\n") && text.contains("\nvt 0.5 0.25\n"), "{text}");
    }
}
