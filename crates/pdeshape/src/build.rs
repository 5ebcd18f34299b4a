//! The build step shared by `build DIR` and the gallery: a scene's outputs written into a
//! directory, all or nothing.

use anyhow::{Context, Result, anyhow};
use pdeshape_io::export::{Format, write_atomic, write_meshes};
use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::path::{Path, PathBuf};

/// Writes the scene's outputs into a directory: one file per patch and format, plus
/// `NAME.png` for the picture. Returns the files written.
///
/// All or nothing: every file is first written into a staging directory inside `dir` and
/// renamed into place only when all of them were written; a failure on the way removes the
/// staging directory (and whatever was already renamed), so no partial set is left.
pub fn build_into_dir(scene: &Scene, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create the directory {}", dir.display()))?;
    let meshes = model::patch_meshes(scene).map_err(|e| anyhow!(e))?;
    let stage = tempfile::Builder::new()
        .prefix(".pdeshape-build-")
        .tempdir_in(dir)
        .with_context(|| format!("cannot write into the directory {}", dir.display()))?;
    // (file name, path in the staging directory)
    let mut staged: Vec<String> = Vec::new();
    let mut put = |name: String, write: &dyn Fn(&Path) -> Result<()>| -> Result<()> {
        write(&stage.path().join(&name)).with_context(|| format!("cannot write {}", dir.join(&name).display()))?;
        staged.push(name);
        Ok(())
    };
    for f in &scene.formats {
        if f == "png" {
            let img = match model::blend_strip(scene).or_else(|| model::dynamic_strip(scene)) {
                Some(strip) => strip.map_err(|e| anyhow!(e))?,
                None => {
                    let context = model::context_meshes(scene).map_err(|e| anyhow!(e))?;
                    let colors: Vec<_> = scene.patches.iter().map(|p| p.color).collect();
                    model::render_meshes(&meshes, &context, &colors, &scene.render)
                }
            };
            put(format!("{}.png", scene.name), &|p| Ok(write_atomic(p, |w| img.write_png(w))?))?;
            continue;
        }
        let fmt = Format::from_extension(f).ok_or_else(|| anyhow!("unknown format `{f}`"))?;
        for m in &meshes {
            put(format!("{}-{}.{}", scene.name, m.name, fmt.extension()), &|p| Ok(write_meshes(p, fmt, &[m])?))?;
        }
    }
    // solid blends: the hexahedral volume mesh (with residual and Jacobian cell fields)
    for p in &scene.patches {
        if let Some(h) = model::solid_volume(p) {
            put(format!("{}-{}-volume.vtu", scene.name, p.name), &|path| {
                Ok(write_atomic(path, |w| pdeshape_io::export::write_vtu_hex(w, &h))?)
            })?;
        }
    }
    // dynamic blends: a numbered frame sequence beside the animated glTF
    for p in &scene.patches {
        if let Some(frames) = model::frame_meshes(p) {
            for m in frames.map_err(|e| anyhow!(e))? {
                put(format!("{}-{}.obj", scene.name, m.name), &|path| Ok(write_meshes(path, Format::Obj, &[&m])?))?;
            }
        }
    }
    // everything is written: move it into place
    let mut written = Vec::new();
    for name in &staged {
        let to = dir.join(name);
        if let Err(e) = std::fs::rename(stage.path().join(name), &to) {
            for w in &written {
                let _ = std::fs::remove_file(w);
            }
            return Err(anyhow!(e).context(format!("cannot move {} into place", to.display())));
        }
        written.push(to);
    }
    Ok(written)
}
