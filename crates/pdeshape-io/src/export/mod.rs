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
mod step_sew;
mod stl;
mod vtu;

pub use gltf::write_glb;
pub use obj::write_obj;
pub use ply::write_ply;
pub use step::{StepFace, StepHole, check_uncertainty, write_step};
pub use step_sew::{SewnFace, sewn_step};
pub use stl::write_stl;
pub use vtu::{write_vtu_hex, write_vtu_surface};

use pdeshape_core::mesh::Mesh;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Writes `path` atomically: `f` writes into a temporary file in the same directory,
/// which is renamed to `path` only when `f` succeeds.
///
/// A path that exists and is not a regular file (a FIFO, a character or block device, a
/// socket) is never replaced: renaming a regular file over it would leave a FIFO's reader
/// without data and turn a device node into a file. Its content is first produced in
/// memory — so a failing `f` writes nothing there either — and then written straight into
/// it, with every write error reported (a full device answers "no space left"). A directory
/// is refused. A symbolic link is followed for that decision; a link to a regular file is
/// replaced by the new file, as before.
pub fn write_atomic(path: &Path, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => {
            return Err(io::Error::new(io::ErrorKind::IsADirectory, format!("{} is a directory", path.display())));
        }
        Ok(m) if !m.is_file() => return write_into_special(path, f),
        _ => {}
    }
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

/// Writes into an existing FIFO or device node: the whole content is made first, then
/// written in one pass (no truncation, no rename).
fn write_into_special(path: &Path, f: impl FnOnce(&mut dyn Write) -> io::Result<()>) -> io::Result<()> {
    let mut bytes = Vec::new();
    f(&mut bytes)?;
    let mut file = std::fs::OpenOptions::new().write(true).open(path)?;
    file.write_all(&bytes)?;
    file.flush()?;
    // a device that buffers (a disk partition) reports a late failure here; a FIFO or a
    // character device cannot sync, which is no error of the write
    match file.sync_all() {
        Err(e) if e.kind() != io::ErrorKind::InvalidInput => Err(e),
        _ => Ok(()),
    }
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

    /// Whether the format stores coordinates as 32-bit floats (binary PLY, STL, glTF);
    /// OBJ and VTU write `f64` values.
    pub fn single_precision(self) -> bool {
        matches!(self, Format::Ply | Format::Stl | Format::Glb)
    }

    /// The format's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Format::Obj => "OBJ",
            Format::Ply => "PLY",
            Format::Stl => "STL",
            Format::Glb => "glTF",
            Format::Vtu => "VTU",
        }
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
/// values, and values that overflow a single-precision format's `f32`: no NaN or inf ever
/// reaches a file.
pub fn write_meshes(path: &Path, format: Format, meshes: &[&Mesh]) -> io::Result<()> {
    check_representable(format, meshes)?;
    write_atomic(path, |w| encode(w, format, meshes))
}

/// The bytes of `meshes` in `format`, in memory (the editor's downloads: no file is
/// involved). Refuses what [`write_meshes`] refuses.
pub fn to_bytes(format: Format, meshes: &[&Mesh]) -> io::Result<Vec<u8>> {
    check_representable(format, meshes)?;
    let mut out = Vec::new();
    encode(&mut out, format, meshes)?;
    Ok(out)
}

/// Every value of `meshes` is finite and, for a format that stores `f32`, finite as `f32`.
pub fn check_representable(format: Format, meshes: &[&Mesh]) -> io::Result<()> {
    for m in meshes {
        let r = if format.single_precision() { m.check_fits_f32(format.name()) } else { m.check_finite() };
        r.map_err(|e| io::Error::new(io::ErrorKind::InvalidData, e))?;
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
