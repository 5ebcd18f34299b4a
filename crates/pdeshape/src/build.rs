//! `pdeshape build`: a scene's condition check, then its outputs — one mesh file, a STEP
//! file, a picture, or a directory of everything (the build step the gallery shares), all
//! or nothing.

use crate::check::{cad_lines, check_finite_report, continuity_line, not_finite};
use anyhow::{Context, Result, anyhow, bail};
use pdeshape_io::export::{Format, write_atomic, write_meshes};
use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::path::{Path, PathBuf};

/// `--tolerance`, `--relative-tolerance` and `--degree` (STEP output only).
#[derive(Clone, Copy, Debug)]
pub struct StepOptions {
    /// The measured maximum deviation to reach (absolute).
    pub tolerance: Option<f64>,
    /// The same relative to each face's size.
    pub relative_tolerance: Option<f64>,
    /// B-spline degree.
    pub degree: Option<usize>,
}

/// Runs `build` on a loaded scene: the output's kind comes from `out`'s extension (none: a
/// directory).
pub fn command(sc: &Scene, out: &Path, step: &StepOptions, quiet: bool) -> Result<()> {
    let StepOptions { tolerance, relative_tolerance, degree } = *step;
    // the condition check runs before anything is written: a scene that fails it
    // leaves no file (quiet: the check alone; otherwise the whole report, printed below)
    let diagnostics = if quiet {
        for p in &sc.patches {
            let r = model::condition_report(p);
            if !(r.max_abs.is_finite() && r.max_rel.is_finite()) {
                bail!(not_finite(&p.name));
            }
        }
        None
    } else {
        let d = model::scene_diagnostics(sc);
        check_finite_report(&d)?;
        Some(d)
    };
    let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    if (tolerance.is_some() || relative_tolerance.is_some() || degree.is_some()) && ext != "step" && ext != "stp" {
        return Err(crate::usage::usage(
            "--tolerance, --relative-tolerance and --degree apply to STEP output only (-o FILE.step)",
        ));
    }
    if (ext == "step" || ext == "stp") && !sc.imports.is_empty() {
        return imported_step(sc, out, step, quiet);
    }
    if ext == "step" || ext == "stp" {
        if sc.patches.is_empty() {
            bail!("the scene {} has no patches to write", sc.file);
        }
        let o = pdeshape_io::cad::CadOptions {
            tolerance,
            relative: relative_tolerance.unwrap_or(1e-6),
            degree: degree.unwrap_or(3),
            time: None,
        };
        let fitted = pdeshape_io::cad::fit_scene(sc, &o).map_err(|e| anyhow!(e))?;
        pdeshape_io::cad::write_scene_step(out, sc, &fitted)
            .with_context(|| format!("cannot write {}", out.display()))?;
        if !quiet {
            for line in cad_lines(&fitted) {
                eprintln!("{line}");
            }
            eprintln!("wrote {} ({} face{})", out.display(), fitted.len(), if fitted.len() == 1 { "" } else { "s" });
        }
    } else if ext == "png" {
        let img = model::render_scene(sc).map_err(|e| anyhow!(e))?;
        write_png(out, &img)?;
        if !quiet {
            eprintln!("wrote {}", out.display());
        }
    } else if let Some(fmt) = Format::from_extension(&ext) {
        let meshes = model::patch_meshes(sc).map_err(|e| anyhow!(e))?;
        let refs: Vec<_> = meshes.iter().collect();
        write_meshes(out, fmt, &refs).with_context(|| format!("cannot write {}", out.display()))?;
        if !quiet {
            let nv: usize = meshes.iter().map(|m| m.positions.len()).sum();
            eprintln!(
                "wrote {} ({} patch{}, {nv} vertices)",
                out.display(),
                meshes.len(),
                if meshes.len() == 1 { "" } else { "es" }
            );
        }
    } else if !ext.is_empty() {
        return Err(crate::usage::usage(format!(
            "unknown output format `.{}` (known: obj, ply, stl, glb, vtu, step, png, or a directory)",
            crate::clip::clip(&ext, 16)
        )));
    } else {
        let files = build_into_dir(sc, out)?;
        if !quiet {
            for f in files {
                eprintln!("wrote {}", f.display());
            }
        }
    }
    if !quiet {
        for d in diagnostics.iter().flat_map(|d| &d.patches) {
            eprintln!(
                "patch {}: {} ({}), max condition error {:.2e} (relative)",
                d.name,
                d.kind.name(),
                d.solver,
                d.condition_error.max_rel
            );
            if let Some(line) = continuity_line(d) {
                eprintln!("  {line}");
            }
        }
    }
    Ok(())
}

pub fn write_png(path: &Path, img: &pdeshape_io::render::Image) -> Result<()> {
    write_atomic(path, |w| img.write_png(w)).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes the scene's outputs into a directory: one file per patch and format, plus
/// `NAME.png` for the picture. Returns the files written.
///
/// All or nothing: every file is first written into a staging directory inside `dir` and
/// renamed into place only when all of them were written; a failure on the way removes the
/// staging directory (and whatever was already renamed), so no partial set is left.
pub fn build_into_dir(scene: &Scene, dir: &Path) -> Result<Vec<PathBuf>> {
    if dir.exists() && !dir.is_dir() {
        bail!(
            "{} exists and is not a directory (a file output needs an extension: obj, ply, stl, glb, vtu, step, png)",
            dir.display()
        );
    }
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

/// `build -o OUT.step` of a scene that imports a model: the model written back exactly with
/// the scene's fills of its holes sewn in, fitted as `fill-holes` fits them (the fill's
/// faces are of degree 5).
fn imported_step(sc: &Scene, out: &Path, step: &StepOptions, quiet: bool) -> Result<()> {
    if step.degree.is_some() {
        return Err(crate::usage::usage(
            "--degree does not apply to a scene that imports a model: its fills' faces are of degree 5, as fill-holes writes them",
        ));
    }
    let defaults = pdeshape_io::holes::FillHolesOptions::default();
    let size = sc.imports.first().map_or(1.0, |i| i.model.model.brep.size());
    let relative = match (step.tolerance, step.relative_tolerance) {
        (Some(t), _) => t / size,
        (None, Some(r)) => r,
        (None, None) => defaults.relative,
    };
    let (m, filled) = pdeshape_io::holes::scene_fills(sc, relative).map_err(|e| anyhow!("{}: {e}", sc.file))?;
    pdeshape_io::holes::write_filled(&m.model, &m.holes, &filled, out).map_err(|e| anyhow!(e))?;
    if !quiet {
        for line in crate::holes::filled_lines(&filled) {
            eprintln!("{line}");
        }
        eprintln!("wrote {} ({} with {} new face(s))", out.display(), m.path.display(), filled.len());
    }
    Ok(())
}
