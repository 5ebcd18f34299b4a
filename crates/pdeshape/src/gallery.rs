//! `pdeshape gallery`: every built-in example built into a directory with an HTML index.

use crate::EXAMPLES;
use anyhow::{Result, bail};
use indicatif::{ProgressBar, ProgressStyle};
use pdeshape_io::model;
use pdeshape_io::scene::Scene;
use std::fmt::Write as _;
use std::path::Path;

struct Entry {
    name: String,
    title: String,
    description: String,
    reference: String,
    picture: Option<String>,
    plots: Vec<String>,
    files: Vec<String>,
    diagnostics: String,
    error: Option<String>,
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn build_one(name: &str, text: &str, dir: &Path, limits: pdeshape_core::limits::Limits) -> Entry {
    let mut e = Entry {
        name: name.to_string(),
        title: name.to_string(),
        description: String::new(),
        reference: String::new(),
        picture: None,
        plots: Vec::new(),
        files: Vec::new(),
        diagnostics: String::new(),
        error: None,
    };
    let opts = pdeshape_io::scene::LoadOptions { limits, ..Default::default() };
    let scene = match Scene::parse_with(text, &format!("examples/{name}.toml"), name, &opts) {
        Ok(s) => s,
        Err(err) => {
            e.error = Some(err.to_string());
            return e;
        }
    };
    e.title = scene.title.clone().unwrap_or_else(|| name.to_string());
    e.description = scene.description.clone().unwrap_or_default();
    e.reference = scene.reference.clone().unwrap_or_default();
    let sub = dir.join(name);
    match crate::build::build_into_dir(&scene, &sub) {
        Ok(files) => {
            for f in files {
                let rel =
                    format!("{name}/{}", f.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default());
                if rel.ends_with(".png") {
                    e.picture = Some(rel);
                } else {
                    e.files.push(rel);
                }
            }
        }
        Err(err) => {
            e.error = Some(format!("{err:#}"));
            return e;
        }
    }
    // blends and fills beside their zebra picture: the stripes show the seams' continuity (a
    // jump at C0, a kink at G1/C1, smooth at G2/C2) on the patches and their neighbours
    if scene.patches.iter().any(|p| p.blend.is_some() || p.dynamic.is_some() || p.fill.is_some()) {
        let zebra =
            pdeshape_io::scene::RenderSettings { view: pdeshape_io::render::View::Zebra, ..scene.render.clone() };
        match model::render_scene_with(&scene, &zebra) {
            Ok(img) => {
                let rel = format!("{name}/{name}-zebra.png");
                if pdeshape_io::export::write_atomic(&dir.join(&rel), |w| img.write_png(w)).is_ok() {
                    e.plots.push(rel);
                }
            }
            Err(err) => e.error = Some(err),
        }
    }
    for (i, st) in scene.studies.iter().enumerate() {
        match model::study_strip(&scene, st) {
            Ok(img) => {
                let rel = format!("{name}/{name}-study-{i}.png");
                if pdeshape_io::export::write_atomic(&dir.join(&rel), |w| img.write_png(w)).is_ok() {
                    e.plots.push(rel);
                }
            }
            Err(err) => e.error = Some(err),
        }
    }
    if let Some(plot) = model::blend_convergence_plot(&scene) {
        match plot {
            Ok(img) => {
                let rel = format!("{name}/{name}-collocation-convergence.png");
                if pdeshape_io::export::write_atomic(&dir.join(&rel), |w| img.write_png(w)).is_ok() {
                    e.plots.push(rel);
                }
            }
            Err(err) => e.error = Some(err),
        }
    }
    for p in &scene.patches {
        for (suffix, pic) in [
            ("trim", model::trim_picture(p)),
            ("sections", model::solid_sections_picture(&scene, p)),
            ("convergence", model::solid_convergence_plot(p)),
            ("convergence", model::convergence_plot(p)),
        ] {
            match pic {
                Some(Ok(img)) => {
                    let rel = format!("{name}/{name}-{}-{suffix}.png", p.name);
                    if pdeshape_io::export::write_atomic(&dir.join(&rel), |w| img.write_png(w)).is_ok() {
                        e.plots.push(rel);
                    }
                }
                Some(Err(err)) => e.error = Some(err),
                None => {}
            }
        }
    }
    let d = model::scene_diagnostics(&scene);
    let mut t =
        String::from("<table><tr><th>patch</th><th>kind</th><th>solver</th><th>max condition error (rel.)</th></tr>");
    for p in &d.patches {
        let _ = write!(
            t,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.2e}</td></tr>",
            esc(&p.name),
            esc(p.kind.name()),
            esc(&p.solver),
            p.condition_error.max_rel
        );
    }
    t.push_str("</table>");
    e.diagnostics = t;
    e
}

/// Builds the gallery; fails (after building the rest) when any example fails.
pub fn run(dir: &Path, quiet: bool, limits: pdeshape_core::limits::Limits) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        anyhow::bail!("{} exists and is not a directory: the gallery is written into a directory", dir.display());
    }
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("cannot create the directory {}: {e}", dir.display()))?;
    let bar = if quiet { ProgressBar::hidden() } else { ProgressBar::new(EXAMPLES.len() as u64) };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} {msg}").unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut entries = Vec::new();
    for (name, text) in EXAMPLES {
        bar.set_message(name.to_string());
        entries.push(build_one(name, text, dir, limits));
        bar.inc(1);
    }
    bar.finish_and_clear();
    let mut html = String::from(
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>pdeshape gallery</title><style>\
         body{font-family:system-ui,sans-serif;margin:2em;background:#f6f7f9;color:#222}\
         .card{background:#fff;border-radius:8px;padding:1em;margin:0 0 1.5em;box-shadow:0 1px 3px #0002}\
         img{max-width:100%;border:1px solid #ddd}table{border-collapse:collapse;margin-top:.5em}\
         td,th{border:1px solid #ccc;padding:2px 8px;font-size:90%}.err{color:#a00;white-space:pre-wrap}\
         </style></head><body><h1>pdeshape gallery</h1>\n",
    );
    for e in &entries {
        let _ = write!(
            html,
            "<div class=\"card\" id=\"{0}\"><h2>{1}</h2><p><code>examples/{0}.toml</code>",
            esc(&e.name),
            esc(&e.title)
        );
        if !e.reference.is_empty() {
            let _ = write!(html, " — {}", esc(&e.reference));
        }
        let _ = write!(html, "</p><p>{}</p>", esc(&e.description));
        if let Some(p) = &e.picture {
            let _ = write!(html, "<img src=\"{}\" alt=\"{}\">", esc(p), esc(&e.title));
        }
        for p in &e.plots {
            let _ = write!(html, "<img class=\"plot\" src=\"{}\" alt=\"convergence\">", esc(p));
        }
        if let Some(err) = &e.error {
            let _ = write!(html, "<p class=\"err\">{}</p>", esc(err));
        }
        html.push_str(&e.diagnostics);
        if !e.files.is_empty() {
            html.push_str("<p>");
            for f in &e.files {
                let _ = write!(html, "<a href=\"{0}\">{0}</a> ", esc(f));
            }
            html.push_str("</p>");
        }
        html.push_str("</div>\n");
    }
    html.push_str("</body></html>\n");
    let index = dir.join("index.html");
    pdeshape_io::export::write_atomic(&index, |w| w.write_all(html.as_bytes()))?;
    let failed: Vec<_> = entries.iter().filter(|e| e.error.is_some()).collect();
    if !quiet {
        eprintln!("gallery: {} examples → {}", entries.len(), index.display());
    }
    if !failed.is_empty() {
        for e in &failed {
            eprintln!("example {} failed: {}", e.name, e.error.as_deref().unwrap_or(""));
        }
        bail!("{} of {} examples failed", failed.len(), entries.len());
    }
    Ok(())
}
