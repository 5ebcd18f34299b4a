//! Mesh exporters (SPEC §8): OBJ, binary PLY, binary STL, glTF 2.0 binary, VTK `.vtu`;
//! and B-spline surface models as STEP.
//!
//! Every writer goes through [`write_atomic`]: the file is written to a temporary file in
//! the target directory and renamed into place, so an interrupted or failed run never
//! leaves a truncated output.

mod gltf;
mod obj;
mod ply;
mod step;
mod stl;
mod vtu;

pub use gltf::write_glb;
pub use obj::write_obj;
pub use ply::write_ply;
pub use step::{StepFace, StepHole, write_step};
pub use stl::write_stl;
pub use vtu::{write_vtu_hex, write_vtu_surface};

use pdeshape_core::mesh::Mesh;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Writes `path` atomically: `f` writes into a temporary file in the same directory,
/// which is renamed to `path` only when `f` succeeds.
pub fn write_atomic(path: &Path, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".pdeshape-").suffix(".tmp");
    #[cfg(unix)]
    {
        // Outputs are ordinary files (the temporary file would otherwise keep mode 0600).
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o644));
    }
    let tmp = builder.tempfile_in(dir)?;
    {
        let mut w = BufWriter::new(tmp.as_file());
        f(&mut w)?;
        w.flush()?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// An export format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ.
    Obj,
    /// Binary little-endian PLY.
    Ply,
    /// Binary STL.
    Stl,
    /// glTF 2.0 binary.
    Glb,
    /// VTK XML unstructured grid.
    Vtu,
}

impl Format {
    /// The format for a file extension.
    pub fn from_extension(ext: &str) -> Option<Format> {
        Some(match ext.to_ascii_lowercase().as_str() {
            "obj" => Format::Obj,
            "ply" => Format::Ply,
            "stl" => Format::Stl,
            "glb" => Format::Glb,
            "vtu" => Format::Vtu,
            _ => return None,
        })
    }

    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Ply => "ply",
            Format::Stl => "stl",
            Format::Glb => "glb",
            Format::Vtu => "vtu",
        }
    }
}

/// Writes meshes to `path` in `format` (atomically). Refuses meshes with non-finite
/// values: no NaN ever reaches a file.
pub fn write_meshes(path: &Path, format: Format, meshes: &[&Mesh]) -> io::Result<()> {
    check_finite(meshes)?;
    write_atomic(path, |w| encode(w, format, meshes))
}

/// The bytes of `meshes` in `format`, in memory (the editor's downloads: no file is
/// involved). Refuses meshes with non-finite values.
pub fn to_bytes(format: Format, meshes: &[&Mesh]) -> io::Result<Vec<u8>> {
    check_finite(meshes)?;
    let mut out = Vec::new();
    encode(&mut out, format, meshes)?;
    Ok(out)
}

fn check_finite(meshes: &[&Mesh]) -> io::Result<()> {
    for m in meshes {
        m.check_finite().map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
    }
    Ok(())
}

fn encode(w: &mut dyn Write, format: Format, meshes: &[&Mesh]) -> io::Result<()> {
    match format {
        Format::Obj => write_obj(w, meshes),
        Format::Ply => write_ply(w, meshes),
        Format::Stl => write_stl(w, meshes),
        Format::Glb => write_glb(w, meshes),
        Format::Vtu => write_vtu_surface(w, meshes),
    }
}

#[cfg(test)]
mod tests;
