//! Subcommands and exit codes: 0 ok, 1 runtime error, 2 usage error.

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand};
use pdeshape_core::limits::Limits;
use pdeshape_io::export::{Format, write_atomic, write_meshes};
use pdeshape_io::model;
use pdeshape_io::scene::{LoadOptions, Scene};
use std::collections::HashMap;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

/// PDE-based shape design: surfaces, blends, solids and trims as solutions of elliptic
/// PDEs through boundary curves.
#[derive(Parser, Debug)]
#[command(name = "pdeshape", version, about, long_about = None)]
pub struct Cli {
    /// Print nothing but errors (no progress bars).
    #[arg(long, short, global = true)]
    quiet: bool,
    /// Raise or lower a cap on what a scene may ask for: order (PDE order, default 64),
    /// modes (Fourier modes, sine terms, bubbles, solid terms; 512), collocation (points
    /// of one solve; 250000), vertices (per patch; 4000000), memory (MiB of meshes; 4096).
    #[arg(long = "limit", global = true, value_name = "CAP=VALUE")]
    limit: Vec<String>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Build a scene into meshes: OUT with a mesh extension (obj, ply, stl, glb, vtu) gets
    /// every patch as a group; OUT ending in .png gets a picture; any other OUT is a
    /// directory that receives one file per patch and format of the scene's [output].
    Build {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output file or directory.
        #[arg(short, long)]
        out: PathBuf,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
    /// Diagnose a scene: solver, condition errors, conditioning, continuity.
    Check {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Solver for blends: auto, exact or collocation (overrides the scene).
        #[arg(long)]
        solver: Option<String>,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
    /// Evaluate a patch at parameters read as CSV `u,v` from stdin; writes `u,v,x,y,z`.
    Sample {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Patch to evaluate (default: the first).
        #[arg(long)]
        patch: Option<String>,
        /// Time, for dynamic blends.
        #[arg(long)]
        time: Option<f64>,
        /// Solver for blends: auto, exact or collocation (overrides the scene).
        #[arg(long)]
        solver: Option<String>,
        /// Sine terms K of a dynamic blend's collocation solver (overrides the scene).
        #[arg(long)]
        terms: Option<usize>,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
    /// Render a scene to PNG.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        out: PathBuf,
        /// Image width in pixels.
        #[arg(long)]
        width: Option<u32>,
        /// Image height in pixels.
        #[arg(long)]
        height: Option<u32>,
        /// Camera azimuth (degrees).
        #[arg(long, allow_hyphen_values = true)]
        azimuth: Option<f64>,
        /// Camera elevation (degrees).
        #[arg(long, allow_hyphen_values = true)]
        elevation: Option<f64>,
        /// Draw mesh lines.
        #[arg(long)]
        wireframe: bool,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE")]
        set: Vec<String>,
    },
    /// Build every built-in example into DIR: meshes, pictures and index.html.
    Gallery {
        /// Output directory.
        #[arg(default_value = "gallery")]
        dir: PathBuf,
    },
    /// Reproduce the papers' timing and accuracy tables beside their published figures.
    Bench {
        /// Print JSON instead of Markdown.
        #[arg(long)]
        json: bool,
        /// Timed runs per measurement (medians are reported).
        #[arg(long, default_value_t = 21)]
        runs: usize,
        /// Also write the tables to OUT.md and OUT.json.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run the scaling study instead (resolution, order, modes, collocation size on one
        /// and two threads; minutes) and write its tables and plots into DIR.
        #[arg(long, value_name = "DIR")]
        scaling: Option<PathBuf>,
        /// Largest grid side of the scaling study.
        #[arg(long, default_value_t = 2000)]
        max_side: usize,
    },
    /// Serve the interactive editor (a local web page) on 127.0.0.1.
    Serve {
        /// Scene to open (default: a chooser of the built-in examples).
        scene: Option<PathBuf>,
        /// Port (0 picks a free one).
        #[arg(long, default_value_t = 8080)]
        port: u16,
        /// Address to bind; anything but loopback exposes the editor to the network.
        #[arg(long, default_value = "127.0.0.1")]
        host: String,
        /// Print the URL to open (it is always printed on start).
        #[arg(long)]
        open: bool,
    },
}

/// Parses the arguments, runs, and returns the exit code.
pub fn run() -> i32 {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return code;
        }
    };
    let mut limits = Limits::default();
    for l in &cli.limit {
        if let Err(e) = limits.apply(l) {
            eprintln!("error: --limit {e}");
            return 2;
        }
    }
    let _ = LIMITS.set(limits);
    match execute(cli) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e:#}");
            1
        }
    }
}

static LIMITS: std::sync::OnceLock<Limits> = std::sync::OnceLock::new();

/// The caps in force for this process (`--limit`, else the defaults).
pub fn limits() -> Limits {
    LIMITS.get().copied().unwrap_or_default()
}

fn overrides(set: &[String]) -> Result<HashMap<String, f64>> {
    let mut m = HashMap::new();
    for s in set {
        let (k, v) = s.split_once('=').ok_or_else(|| anyhow!("--set {s:?}: expected NAME=VALUE"))?;
        let x: f64 = v.trim().parse().map_err(|_| anyhow!("--set {s:?}: `{v}` is not a number"))?;
        if !x.is_finite() {
            bail!("--set {s:?}: the value is not finite");
        }
        m.insert(k.trim().to_string(), x);
    }
    Ok(m)
}

pub fn load(path: &Path, set: &[String]) -> Result<Scene> {
    load_with(path, set, None)
}

/// Loads a scene with parameter overrides and an optional solver override.
pub fn load_with(path: &Path, set: &[String], solver: Option<&str>) -> Result<Scene> {
    load_opts(path, set, solver, None)
}

/// Loads a scene with parameter, solver and sine-term overrides.
pub fn load_opts(path: &Path, set: &[String], solver: Option<&str>, terms: Option<usize>) -> Result<Scene> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read the scene file {}", path.display()))?;
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let opts = LoadOptions { params: overrides(set)?, solver: solver.map(str::to_string), terms, limits: limits() };
    Ok(Scene::parse_with(&text, &path.display().to_string(), &name, &opts)?)
}

/// The continuity line of a blend's diagnostics: the gaps at both trimlines and the class.
pub fn continuity_line(p: &serde_json::Value) -> Option<String> {
    let c = &p["continuity"];
    if !c.is_object() {
        return None;
    }
    let f = |x: &serde_json::Value| x.as_f64().map(|v| format!("{v:.1e}")).unwrap_or_else(|| "-".into());
    let end = |e: &serde_json::Value| {
        format!(
            "C0 {} C1 {} G1 {} rad C2 {} G2 {}",
            f(&e["c0"]),
            f(&e["c1"]),
            f(&e["g1_radians"]),
            f(&e["c2"]),
            f(&e["g2"])
        )
    };
    Some(format!(
        "continuity {}: u=0 [{}]  u=1 [{}]",
        c["class"].as_str().unwrap_or("?"),
        end(&c["start"]),
        end(&c["end"])
    ))
}

fn write_png(path: &Path, img: &pdeshape_io::render::Image) -> Result<()> {
    write_atomic(path, |w| img.write_png(w)).with_context(|| format!("cannot write {}", path.display()))
}

/// Writes the scene's outputs into a directory: one file per patch and format, plus
/// `NAME.png` for the picture. Returns the files written.
pub fn build_into_dir(scene: &Scene, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create the directory {}", dir.display()))?;
    let meshes = model::patch_meshes(scene).map_err(|e| anyhow!(e))?;
    let mut written = Vec::new();
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
            let path = dir.join(format!("{}.png", scene.name));
            write_png(&path, &img)?;
            written.push(path);
            continue;
        }
        let fmt = Format::from_extension(f).ok_or_else(|| anyhow!("unknown format `{f}`"))?;
        for m in &meshes {
            let path = dir.join(format!("{}-{}.{}", scene.name, m.name, fmt.extension()));
            write_meshes(&path, fmt, &[m]).with_context(|| format!("cannot write {}", path.display()))?;
            written.push(path);
        }
    }
    // solid blends: the hexahedral volume mesh (with residual and Jacobian cell fields)
    for p in &scene.patches {
        if let Some(h) = model::solid_volume(p) {
            let path = dir.join(format!("{}-{}-volume.vtu", scene.name, p.name));
            write_atomic(&path, |w| pdeshape_io::export::write_vtu_hex(w, &h))
                .with_context(|| format!("cannot write {}", path.display()))?;
            written.push(path);
        }
    }
    // dynamic blends: a numbered frame sequence beside the animated glTF
    for p in &scene.patches {
        if let Some(frames) = model::frame_meshes(p) {
            for m in frames.map_err(|e| anyhow!(e))? {
                let path = dir.join(format!("{}-{}.obj", scene.name, m.name));
                write_meshes(&path, Format::Obj, &[&m]).with_context(|| format!("cannot write {}", path.display()))?;
                written.push(path);
            }
        }
    }
    Ok(written)
}

fn execute(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Build { scene, out, set } => {
            let sc = load(&scene, &set)?;
            let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
            if ext == "png" {
                let img = model::render_scene(&sc).map_err(|e| anyhow!(e))?;
                write_png(&out, &img)?;
                if !cli.quiet {
                    eprintln!("wrote {}", out.display());
                }
            } else if let Some(fmt) = Format::from_extension(&ext) {
                let meshes = model::patch_meshes(&sc).map_err(|e| anyhow!(e))?;
                let refs: Vec<_> = meshes.iter().collect();
                write_meshes(&out, fmt, &refs).with_context(|| format!("cannot write {}", out.display()))?;
                if !cli.quiet {
                    let nv: usize = meshes.iter().map(|m| m.positions.len()).sum();
                    eprintln!(
                        "wrote {} ({} patch{}, {nv} vertices)",
                        out.display(),
                        meshes.len(),
                        if meshes.len() == 1 { "" } else { "es" }
                    );
                }
            } else if !ext.is_empty() {
                bail!("unknown output format `.{ext}` (known: obj, ply, stl, glb, vtu, png, or a directory)");
            } else {
                let files = build_into_dir(&sc, &out)?;
                if !cli.quiet {
                    for f in files {
                        eprintln!("wrote {}", f.display());
                    }
                }
            }
            if !cli.quiet {
                for p in &sc.patches {
                    let d = model::patch_diagnostics(p);
                    eprintln!(
                        "patch {}: {} ({}), max condition error {:.2e} (relative)",
                        p.name,
                        d["kind"].as_str().unwrap_or(""),
                        d["solver"].as_str().unwrap_or(""),
                        d["condition_error"]["max_rel"].as_f64().unwrap_or(f64::NAN)
                    );
                    if let Some(line) = continuity_line(&d) {
                        eprintln!("  {line}");
                    }
                }
            }
            Ok(())
        }
        Command::Check { scene, json, set, solver } => {
            let sc = load_with(&scene, &set, solver.as_deref())?;
            let d = model::scene_diagnostics(&sc);
            if json {
                println!("{}", serde_json::to_string_pretty(&d)?);
            } else {
                println!("scene {}{}", sc.name, sc.title.as_ref().map(|t| format!(": {t}")).unwrap_or_default());
                for p in d["patches"].as_array().into_iter().flatten() {
                    println!(
                        "  patch {:<16} kind {:<10} solver {:<22} conditions {:>2}  max condition error {:.2e} abs, {:.2e} rel",
                        p["name"].as_str().unwrap_or(""),
                        p["kind"].as_str().unwrap_or(""),
                        p["solver"].as_str().unwrap_or(""),
                        p["conditions"].as_array().map(|a| a.len()).unwrap_or(0),
                        p["condition_error"]["max_abs"].as_f64().unwrap_or(f64::NAN),
                        p["condition_error"]["max_rel"].as_f64().unwrap_or(f64::NAN),
                    );
                    let sp = &p["spectral"];
                    if sp.is_object() {
                        println!(
                            "      order {}, M = {}, ω = {}, max mode condition {:.2e} ({} modes f64, {} multiprecision), Lebesgue {:.3}",
                            sp["order"],
                            sp["modes"],
                            sp["omega"],
                            sp["max_mode_condition_number"].as_f64().unwrap_or(f64::NAN),
                            sp["modes_solved_in_f64"],
                            sp["modes_solved_in_multiprecision"],
                            sp["lebesgue_mode0"].as_f64().unwrap_or(f64::NAN),
                        );
                    }
                    if let Some(line) = continuity_line(p) {
                        println!("      {line}");
                    }
                    if let (Some(so), Some(mp)) = (p["solid"].as_object(), p["mass_properties"].as_object()) {
                        println!(
                            "      terms {}, condition {:.2e}, RMS residual {:.3e}; volume {:.6}, centroid {}, det J in [{:.3e}, {:.3e}]",
                            so["terms"],
                            so["condition_number"].as_f64().unwrap_or(f64::NAN),
                            so["rms_residual"].as_f64().unwrap_or(f64::NAN),
                            mp["volume"].as_f64().unwrap_or(f64::NAN),
                            mp["centroid"],
                            mp["min_jacobian"].as_f64().unwrap_or(f64::NAN),
                            mp["max_jacobian"].as_f64().unwrap_or(f64::NAN),
                        );
                    }
                    if let Some(b) = p["blend"].as_object() {
                        for c in b["components"].as_array().into_iter().flatten() {
                            println!(
                                "      {}: order {}, solver {}, {} basis functions, condition {:.2e}{}",
                                c["component"].as_str().unwrap_or(""),
                                c["order"],
                                c["solver"].as_str().unwrap_or(""),
                                c["basis"].as_array().map(|a| a.len()).unwrap_or(0),
                                c["condition_number"].as_f64().unwrap_or(f64::NAN),
                                c["collocation_rms_residual"]
                                    .as_f64()
                                    .map(|r| format!(", collocation RMS residual {r:.2e}"))
                                    .unwrap_or_default()
                            );
                        }
                        if let Some(x) = b["exact_vs_collocation_max_distance"].as_f64() {
                            println!("      max distance between the exact and the collocation solution: {x:.3e}");
                        }
                    }
                    if let Some(x) = p["section_reference_distance"].as_f64() {
                        let lin = p["section_reference_distance_linear_s"].as_f64().unwrap_or(f64::NAN);
                        println!(
                            "      max distance to the section family at the fractional section index: {x:.4} \
                             (s linear in u between sections: {lin:.4})"
                        );
                    }
                    for w in p["warnings"].as_array().into_iter().flatten() {
                        println!("      warning: {}", w.as_str().unwrap_or(""));
                    }
                }
            }
            Ok(())
        }
        Command::Sample { scene, patch, time, set, solver, terms } => {
            if terms == Some(0) {
                bail!("--terms 0: at least one sine term is needed");
            }
            let sc = load_opts(&scene, &set, solver.as_deref(), terms)?;
            let p = match &patch {
                Some(n) => sc.patch(n).ok_or_else(|| {
                    anyhow!(
                        "no patch named `{n}` in {} (patches: {})",
                        sc.file,
                        sc.patches.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
                    )
                })?,
                None => sc.patches.first().ok_or_else(|| anyhow!("the scene {} has no patches", sc.file))?,
            };
            if let Some(t) = time {
                if !t.is_finite() {
                    bail!("--time {t} is not finite");
                }
                if t != 0.0 && p.dynamic.is_none() && !cli.quiet {
                    eprintln!("note: patch `{}` is not a dynamic blend: --time does not change it", p.name);
                }
            }
            match (&p.dynamic, time, &p.solid) {
                (_, _, Some(sd)) => sample_solid(&sd.blend),
                (Some(d), Some(t), _) => {
                    let f = d.blend.frame(t).map_err(|e| anyhow!("patch `{}` at t = {t}: {e}", p.name))?;
                    sample(&f)
                }
                _ => sample(p.surface.as_ref()),
            }
        }
        Command::Render { scene, out, width, height, azimuth, elevation, wireframe, set } => {
            let mut sc = load(&scene, &set)?;
            if let Some(w) = width {
                sc.render.size.0 = w.clamp(16, 8192);
            }
            if let Some(h) = height {
                sc.render.size.1 = h.clamp(16, 8192);
            }
            if let Some(a) = azimuth {
                sc.render.azimuth = a;
            }
            if let Some(e) = elevation {
                sc.render.elevation = e.clamp(-90.0, 90.0);
            }
            sc.render.wireframe |= wireframe;
            let img = model::render_scene(&sc).map_err(|e| anyhow!(e))?;
            write_png(&out, &img)?;
            if !cli.quiet {
                eprintln!("wrote {}", out.display());
            }
            Ok(())
        }
        Command::Gallery { dir } => crate::gallery::run(&dir, cli.quiet),
        Command::Bench { scaling: Some(dir), runs, max_side, .. } => {
            crate::bench::scaling(&dir, runs, max_side, cli.quiet)
        }
        Command::Bench { json, runs, out, .. } => crate::bench::run(runs, json, out.as_deref()),
        Command::Serve { scene, port, host, open: _ } => {
            crate::serve::run(crate::serve::ServeOptions { scene, host, port })
        }
    }
}

/// Reads CSV rows of `N` finite numbers from stdin (a header line and `#` comments are
/// skipped) and writes `header` then one line per row from `f`; errors name the line.
fn sample_rows<const N: usize>(
    header: &str,
    mut f: impl FnMut(usize, [f64; N], &mut dyn Write) -> Result<()>,
) -> Result<()> {
    let names = header.split(',').take(N).collect::<Vec<_>>().join(",");
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    writeln!(out, "{header}")?;
    for (ln, line) in stdin.lock().lines().enumerate() {
        let line = line.context("cannot read stdin")?;
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = l.split(',').map(|c| c.trim()).collect();
        if ln == 0 && cols.first().is_some_and(|c| c.parse::<f64>().is_err()) {
            continue; // header
        }
        if cols.len() != N {
            bail!("stdin line {}: expected {N} columns `{names}`, got {}: {l:?}", ln + 1, cols.len());
        }
        let mut vals = [0.0f64; N];
        for (k, c) in cols.iter().enumerate() {
            vals[k] = c.parse().map_err(|_| anyhow!("stdin line {}: `{c}` is not a number", ln + 1))?;
            if !vals[k].is_finite() {
                bail!("stdin line {}: `{c}` is not finite", ln + 1);
            }
        }
        f(ln + 1, vals, &mut out)?;
    }
    out.flush()?;
    Ok(())
}

/// `u,v,w` from stdin to `u,v,w,x,y,z` for a solid blend.
fn sample_solid(s: &pdeshape_core::solid::SolidBlend) -> Result<()> {
    sample_rows("u,v,w,x,y,z", |ln, [u, v, w], out| {
        for (name, x) in [("u", u), ("v", v), ("w", w)] {
            if !(0.0..=1.0).contains(&x) {
                bail!("stdin line {ln}: {name} = {x} is outside [0, 1]");
            }
        }
        let x = s.point(u, v, w);
        if !x.is_finite() {
            bail!("stdin line {ln}: the solid is not finite at (u, v, w) = ({u}, {v}, {w})");
        }
        writeln!(out, "{u:.17e},{v:.17e},{w:.17e},{:.17e},{:.17e},{:.17e}", x.x, x.y, x.z)?;
        Ok(())
    })
}

/// `u,v` from stdin to `u,v,x,y,z` for a patch.
fn sample(surface: &dyn pdeshape_core::patch::Surface) -> Result<()> {
    let dom = surface.v_domain();
    sample_rows("u,v,x,y,z", |ln, [u, v], out| {
        if !(0.0..=1.0).contains(&u) {
            bail!("stdin line {ln}: u = {u} is outside [0, 1]");
        }
        if !dom.periodic && !(dom.start..=dom.end).contains(&v) {
            bail!("stdin line {ln}: v = {v} is outside [{}, {}]", dom.start, dom.end);
        }
        let x = surface.point(u, v);
        if !x.is_finite() {
            bail!("stdin line {ln}: the patch is not finite at (u, v) = ({u}, {v})");
        }
        writeln!(out, "{u:.17e},{v:.17e},{:.17e},{:.17e},{:.17e}", x.x, x.y, x.z)?;
        Ok(())
    })
}
