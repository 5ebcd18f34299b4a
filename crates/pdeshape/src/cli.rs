//! Subcommands and exit codes: 0 ok, 1 runtime error, 2 usage error.

use anyhow::{Context, Result, anyhow, bail};
use clap::{Parser, Subcommand};
use pdeshape_core::limits::Limits;
use pdeshape_core::solves::Solves;
use pdeshape_io::export::{Format, write_atomic, write_meshes};
use pdeshape_io::model;
use pdeshape_io::model::report::{GapsReport, PatchReport, SceneReport};
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
    #[arg(long = "limit", global = true, value_name = "CAP=VALUE", value_parser = limit)]
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
        /// STEP only: the certified maximum deviation of every B-spline face from its patch
        /// (absolute; default 1e-6 × each patch's bounding-box diagonal).
        #[arg(long, value_parser = positive, conflicts_with = "relative_tolerance")]
        tolerance: Option<f64>,
        /// STEP only: the tolerance relative to each patch's bounding-box diagonal
        /// (default 1e-6).
        #[arg(long, value_parser = positive)]
        relative_tolerance: Option<f64>,
        /// STEP only: B-spline degree of the faces, 3 (default; seams stay G1) or 5 (the
        /// curvature across seams survives too).
        #[arg(long, value_parser = spline_degree)]
        degree: Option<usize>,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true, value_parser = setting)]
        set: Vec<(String, f64)>,
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
        /// Also fit the faces a STEP export would write and report each face's certified
        /// deviation and control points, and each seam's gap and angle after the fit.
        #[arg(long)]
        cad: bool,
        /// With --cad: B-spline degree of the faces, 3 (default) or 5.
        #[arg(long, value_parser = spline_degree, requires = "cad")]
        degree: Option<usize>,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true, value_parser = setting)]
        set: Vec<(String, f64)>,
    },
    /// Evaluate a patch at parameters read as CSV `u,v` from stdin; writes `u,v,x,y,z`.
    Sample {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Patch to evaluate (default: the first).
        #[arg(long)]
        patch: Option<String>,
        /// Time, for dynamic blends.
        #[arg(long, allow_hyphen_values = true, value_parser = finite)]
        time: Option<f64>,
        /// Solver for blends: auto, exact or collocation (overrides the scene).
        #[arg(long)]
        solver: Option<String>,
        /// Sine terms K of a dynamic blend's collocation solver (overrides the scene).
        #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
        terms: Option<u64>,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true, value_parser = setting)]
        set: Vec<(String, f64)>,
    },
    /// Render a scene to PNG.
    Render {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        out: PathBuf,
        /// Image width in pixels (16 to 8192).
        #[arg(long, value_parser = clap::value_parser!(u32).range(16..=8192))]
        width: Option<u32>,
        /// Image height in pixels (16 to 8192).
        #[arg(long, value_parser = clap::value_parser!(u32).range(16..=8192))]
        height: Option<u32>,
        /// Camera azimuth (degrees, finite).
        #[arg(long, allow_hyphen_values = true, value_parser = finite)]
        azimuth: Option<f64>,
        /// Camera elevation (degrees, −90 to 90).
        #[arg(long, allow_hyphen_values = true, value_parser = elevation)]
        elevation: Option<f64>,
        /// Draw mesh lines.
        #[arg(long)]
        wireframe: bool,
        /// What the surfaces show: shaded, zebra (reflection lines), isophotes, or a curvature
        /// map: gauss, mean, k1 (smaller principal), k2 (larger principal).
        #[arg(long, default_value = "shaded", value_parser = view)]
        view: pdeshape_io::render::View,
        /// Zebra and isophote stripes, black and white each over a half turn (1 to 200).
        #[arg(long, value_parser = stripes)]
        stripes: Option<f64>,
        /// Zebra stripe direction in the image plane, degrees from horizontal (finite).
        #[arg(long, allow_hyphen_values = true, value_parser = finite)]
        stripe_angle: Option<f64>,
        /// Symmetric limit of a curvature map's colour scale (positive, finite); default:
        /// the 95th percentile of |value| over everything drawn.
        #[arg(long, value_parser = positive)]
        curvature_limit: Option<f64>,
        /// Override a parameter: NAME=VALUE (repeatable).
        #[arg(long = "set", value_name = "NAME=VALUE", allow_hyphen_values = true, value_parser = setting)]
        set: Vec<(String, f64)>,
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
        /// Longest time in seconds from a request's arrival to its answer, queueing
        /// included; a solve past it is cancelled.
        #[arg(long, default_value_t = crate::serve::SOLVE_LIMIT.as_secs_f64(), value_parser = positive_seconds)]
        time_limit: f64,
    },
}

/// A finite number (flags that take one).
fn finite(s: &str) -> Result<f64, String> {
    let x: f64 = s.trim().parse().map_err(|_| format!("`{}` is not a number", clip(s, 40)))?;
    if x.is_finite() { Ok(x) } else { Err(format!("{x} is not finite")) }
}

/// A B-spline degree for STEP faces: 3 or 5.
fn spline_degree(s: &str) -> Result<usize, String> {
    match s.trim() {
        "3" => Ok(3),
        "5" => Ok(5),
        _ => Err(format!("`{s}`: the faces are of degree 3 or 5")),
    }
}

/// A camera elevation in degrees.
fn elevation(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if (-90.0..=90.0).contains(&x) { Ok(x) } else { Err(format!("{x} is outside [-90, 90] degrees")) }
}

/// A surface view of `render --view`.
fn view(s: &str) -> Result<pdeshape_io::render::View, String> {
    s.parse()
}

/// A stripe count: 1 to 200.
fn stripes(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if (1.0..=200.0).contains(&x) { Ok(x) } else { Err(format!("{x} is outside [1, 200]")) }
}

/// A positive finite number.
fn positive(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if x > 0.0 { Ok(x) } else { Err(format!("{x} is not positive")) }
}

/// A time limit in seconds: positive, at most a day.
fn positive_seconds(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if x > 0.0 && x <= 86400.0 { Ok(x) } else { Err(format!("{x} is outside (0, 86400] seconds")) }
}

/// `NAME=VALUE` of `--set`, the value finite.
fn setting(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s.split_once('=').ok_or_else(|| format!("`{}`: expected NAME=VALUE", clip(s, 40)))?;
    let x = finite(v).map_err(|e| format!("`{}`: {e}", clip(k.trim(), 40)))?;
    Ok((k.trim().to_string(), x))
}

/// A `--limit CAP=VALUE` setting, checked as clap parses it.
fn limit(s: &str) -> Result<String, String> {
    Limits::default().apply(s).map(|()| s.to_string())
}

/// At most `n` characters of `s` (errors do not echo long arguments whole).
fn clip(s: &str, n: usize) -> String {
    match s.char_indices().nth(n) {
        Some((i, _)) => format!("{}…", &s[..i]),
        None => s.to_string(),
    }
}

/// Parses the arguments, runs, and returns the exit code: 0 ok, 1 a runtime or scene
/// error, 2 a usage error (flags, including a `--set` name the scene does not have).
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
        limits.apply(l).expect("checked by clap");
    }
    let result = execute(cli, limits);
    if std::env::var_os("PDESHAPE_SOLVE_COUNTS").is_some() {
        // a test hook: the solves of the whole command, and those done while loading
        let loaded = LOADED.get().copied().unwrap_or_default();
        eprintln!("solves: loaded {:?}, command {:?}", loaded.0, Solves::now().since(loaded).0);
    }
    match result {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("error: {e:#}");
            let usage = e
                .chain()
                .any(|c| c.downcast_ref::<pdeshape_io::scene::SceneError>().is_some_and(|s| s.key.starts_with("--")));
            if usage { 2 } else { 1 }
        }
    }
}

/// The solve counts right after the (last) scene was loaded; `PDESHAPE_SOLVE_COUNTS=1`
/// prints them and those of the rest of the command (in the order of
/// `pdeshape_core::solves::SolveKind::ALL`), so tests can check that a command solves each
/// patch once.
static LOADED: std::sync::OnceLock<Solves> = std::sync::OnceLock::new();

/// What a command loads a scene with: the caps, `--set` values, solver and sine-term
/// overrides.
pub struct Load<'a> {
    /// The caps in force (`--limit`).
    pub limits: Limits,
    /// `--set NAME=VALUE` overrides.
    pub set: &'a [(String, f64)],
    /// `--solver`.
    pub solver: Option<&'a str>,
    /// `--terms`.
    pub terms: Option<usize>,
}

impl Load<'_> {
    /// Loads the scene file at `path`.
    pub fn scene(&self, path: &Path) -> Result<Scene> {
        let text = pdeshape_io::scene::read_scene_file(path, &self.limits)?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
        let opts = LoadOptions {
            params: self.set.iter().cloned().collect::<HashMap<_, _>>(),
            solver: self.solver.map(str::to_string),
            terms: self.terms,
            limits: self.limits,
        };
        let scene = Scene::parse_with(&text, &path.display().to_string(), &name, &opts)?;
        let _ = LOADED.set(Solves::now());
        Ok(scene)
    }
}

/// The continuity line of a patch's report: the gaps at both trimlines, the class and
/// where the G1 angle is worst.
pub fn continuity_line(p: &PatchReport) -> Option<String> {
    let c = p.continuity.as_ref()?;
    let f = |x: Option<f64>| x.map(|v| format!("{v:.1e}")).unwrap_or_else(|| "-".into());
    let end =
        |e: &GapsReport| format!("C0 {} C1 {} G1 {} rad C2 {} G2 {}", f(e.c0), f(e.c1), f(e.g1), f(e.c2), f(e.g2));
    let mut line = format!("continuity {}:", c.class);
    if let Some(with) = c.with {
        line.push_str(&format!(" (with a {with})"));
    }
    for (e, u) in [(&c.start, 0), (&c.end, 1)] {
        if let Some(e) = e {
            line.push_str(&format!(" u={u} [{}] ", end(e)));
        }
    }
    let mut line = line.trim_end().to_string();
    if let Some(w) = &c.worst.g1 {
        line.push_str(&format!("; worst G1 angle {} rad at (u, v) = ({}, {:.4})", f(Some(w.value)), w.u, w.v));
    }
    Some(line)
}

fn write_png(path: &Path, img: &pdeshape_io::render::Image) -> Result<()> {
    write_atomic(path, |w| img.write_png(w)).with_context(|| format!("cannot write {}", path.display()))
}

/// Refuses a scene whose own condition check is not finite (an overflowing domain, data of
/// 1e300): its meshes would hold finite but meaningless numbers.
fn check_finite_report(d: &SceneReport) -> Result<()> {
    match d.first_not_finite() {
        Some(p) => bail!(not_finite(&p.name)),
        None => Ok(()),
    }
}

fn not_finite(patch: &str) -> String {
    format!(
        "patch `{patch}`: its condition check is not finite (the values overflow or are undefined): \
         the result is not usable; check the domain and the data's magnitude"
    )
}

fn execute(cli: Cli, limits: Limits) -> Result<()> {
    let quiet = cli.quiet;
    let loader = |set, solver, terms: Option<u64>| Load { limits, set, solver, terms: terms.map(|t| t as usize) };
    match cli.command {
        Command::Build { scene, out, set, tolerance, relative_tolerance, degree } => {
            let sc = loader(&set, None, None).scene(&scene)?;
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
                let d = model::scene_diagnostics(&sc);
                check_finite_report(&d)?;
                Some(d)
            };
            let ext = out.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
            if (tolerance.is_some() || relative_tolerance.is_some() || degree.is_some())
                && ext != "step"
                && ext != "stp"
            {
                bail!("--tolerance, --relative-tolerance and --degree apply to STEP output only (-o FILE.step)");
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
                let fitted = pdeshape_io::cad::fit_scene(&sc, &o).map_err(|e| anyhow!(e))?;
                pdeshape_io::cad::write_scene_step(&out, &sc, &fitted)
                    .with_context(|| format!("cannot write {}", out.display()))?;
                if !quiet {
                    for line in cad_lines(&fitted) {
                        eprintln!("{line}");
                    }
                    eprintln!(
                        "wrote {} ({} face{})",
                        out.display(),
                        fitted.len(),
                        if fitted.len() == 1 { "" } else { "s" }
                    );
                }
            } else if ext == "png" {
                let img = model::render_scene(&sc).map_err(|e| anyhow!(e))?;
                write_png(&out, &img)?;
                if !quiet {
                    eprintln!("wrote {}", out.display());
                }
            } else if let Some(fmt) = Format::from_extension(&ext) {
                let meshes = model::patch_meshes(&sc).map_err(|e| anyhow!(e))?;
                let refs: Vec<_> = meshes.iter().collect();
                write_meshes(&out, fmt, &refs).with_context(|| format!("cannot write {}", out.display()))?;
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
                bail!("unknown output format `.{ext}` (known: obj, ply, stl, glb, vtu, step, png, or a directory)");
            } else {
                let files = crate::build::build_into_dir(&sc, &out)?;
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
        Command::Check { scene, json, set, solver, cad, degree } => {
            let sc = loader(&set, solver.as_deref(), None).scene(&scene)?;
            let mut d = model::scene_diagnostics(&sc);
            let o = pdeshape_io::cad::CadOptions { degree: degree.unwrap_or(3), ..Default::default() };
            let fitted = if cad { Some(pdeshape_io::cad::fit_scene(&sc, &o).map_err(|e| anyhow!(e))?) } else { None };
            d.cad = fitted.as_deref().map(pdeshape_io::cad::CadReport::of);
            if json {
                println!("{}", serde_json::to_string_pretty(&d)?);
            } else {
                print_check(&sc, &d);
                if let Some(f) = &fitted {
                    println!("  CAD (STEP) faces:");
                    for line in cad_lines(f) {
                        println!("    {line}");
                    }
                }
            }
            check_finite_report(&d)
        }
        Command::Sample { scene, patch, time, set, solver, terms } => {
            let sc = loader(&set, solver.as_deref(), terms).scene(&scene)?;
            let p = match &patch {
                Some(n) => sc.patch(n).ok_or_else(|| {
                    anyhow!(
                        "no patch named `{}` in {} (patches: {})",
                        clip(n, 60),
                        sc.file,
                        sc.patches.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ")
                    )
                })?,
                None => sc.patches.first().ok_or_else(|| anyhow!("the scene {} has no patches", sc.file))?,
            };
            if let Some(t) = time
                && t != 0.0
                && p.dynamic.is_none()
                && !quiet
            {
                eprintln!("note: patch `{}` is not a dynamic blend: --time does not change it", p.name);
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
        Command::Render {
            scene,
            out,
            width,
            height,
            azimuth,
            elevation,
            wireframe,
            view,
            stripes,
            stripe_angle,
            curvature_limit,
            set,
        } => {
            let mut sc = loader(&set, None, None).scene(&scene)?;
            if let Some(w) = width {
                sc.render.size.0 = w;
            }
            if let Some(h) = height {
                sc.render.size.1 = h;
            }
            if let Some(a) = azimuth {
                sc.render.azimuth = a;
            }
            if let Some(e) = elevation {
                sc.render.elevation = e;
            }
            sc.render.wireframe |= wireframe;
            sc.render.view = view;
            sc.render.stripes = stripes.unwrap_or(sc.render.stripes);
            sc.render.stripe_angle = stripe_angle.unwrap_or(sc.render.stripe_angle);
            sc.render.curvature_limit = curvature_limit.or(sc.render.curvature_limit);
            let img = model::render_scene(&sc).map_err(|e| anyhow!(e))?;
            write_png(&out, &img)?;
            if !quiet {
                eprintln!("wrote {}", out.display());
            }
            Ok(())
        }
        Command::Gallery { dir } => crate::gallery::run(&dir, quiet, limits),
        Command::Bench { scaling: Some(dir), runs, max_side, .. } => {
            crate::bench::scaling(&dir, runs, max_side, quiet, limits)
        }
        Command::Bench { json, runs, out, .. } => crate::bench::run(runs, json, out.as_deref(), limits),
        Command::Serve { scene, port, host, open: _, time_limit } => crate::serve::run(crate::serve::ServeOptions {
            scene,
            host,
            port,
            limits,
            time_limit: std::time::Duration::from_secs_f64(time_limit),
        }),
    }
}

/// The text report of `check`.
fn print_check(sc: &Scene, d: &SceneReport) {
    println!("scene {}{}", sc.name, sc.title.as_ref().map(|t| format!(": {t}")).unwrap_or_default());
    for p in &d.patches {
        println!(
            "  patch {:<16} kind {:<10} solver {:<22} conditions {:>2}  max condition error {:.2e} abs, {:.2e} rel",
            p.name,
            p.kind.name(),
            p.solver,
            p.conditions.len(),
            p.condition_error.max_abs,
            p.condition_error.max_rel,
        );
        if let Some(sp) = &p.spectral {
            println!(
                "      order {}, M = {}, ω = {}, max mode condition {:.2e} ({} modes f64, {} multiprecision), Lebesgue {:.3}, truncated-part residual {:.1e} (relative)",
                sp.order,
                sp.modes,
                json_text(&sp.omega),
                sp.max_mode_condition_number,
                sp.modes_solved_in_f64,
                sp.modes_solved_in_multiprecision,
                sp.lebesgue_mode0,
                sp.truncated_residual_relative,
            );
        }
        if let Some(line) = continuity_line(p) {
            println!("      {line}");
        }
        if let Some(f) = &p.fill {
            println!(
                "      fill (order {}): {} edges, {} points: G1 angle ≤ {:.1e} rad, gap ≤ {:.1e}, curvature gap ≤ {:.1e} (relative); folds {}; pole {}",
                f.order,
                f.edges,
                f.edge_samples,
                f.g1_max_radians,
                f.gap_max_relative,
                f.g2_max_relative,
                f.folds,
                json_text(&f.pole),
            );
        }
        if let (Some(so), Some(mp)) = (&p.solid, &p.mass_properties) {
            println!(
                "      terms {}, condition {:.2e}, RMS residual {:.3e}; volume {:.6}, centroid {}, det J in [{:.3e}, {:.3e}]",
                json_text(&so.terms),
                so.condition_number,
                so.rms_residual,
                mp.volume,
                json_text(&mp.centroid),
                mp.min_jacobian,
                mp.max_jacobian,
            );
        }
        if let Some(b) = &p.blend {
            for c in &b.components {
                println!(
                    "      {}: order {}, solver {}, {} basis functions, condition {:.2e}{}",
                    c.component,
                    c.order,
                    c.solver,
                    c.basis.len(),
                    c.condition_number,
                    c.collocation_rms_residual
                        .map(|r| format!(", collocation RMS residual {r:.2e}"))
                        .unwrap_or_default()
                );
            }
            if let Some(x) = b.exact_vs_collocation_max_distance {
                println!("      max distance between the exact and the collocation solution: {x:.3e}");
            }
        }
        if let Some(x) = p.section_reference_distance {
            let lin = p.section_reference_distance_linear_s.unwrap_or(f64::NAN);
            println!(
                "      max distance to the section family at the fractional section index: {x:.4} \
                     (s linear in u between sections: {lin:.4})"
            );
        }
        for w in &p.warnings {
            println!("      warning: {w}");
        }
    }
}

/// A small array as compact JSON (`[1.0,2.0,3.0]`), the way the text report has always
/// printed points and term counts.
fn json_text<T: serde::Serialize>(x: &T) -> String {
    serde_json::to_string(x).unwrap_or_default()
}

/// The figures of a scene's CAD fit, one line each: faces (net, certified deviation,
/// holes) and seams (gap and normal angle after the fit).
fn cad_lines(fitted: &[pdeshape_io::cad::CadFace]) -> Vec<String> {
    let mut out = Vec::new();
    for f in fitted {
        let r = &f.report;
        out.push(format!(
            "face {}: B-spline {} × {} control points, certified deviation {:.3e} ≤ {:.3e}",
            f.name, r.points.0, r.points.1, r.max_deviation, r.tolerance
        ));
        for h in &f.holes {
            out.push(format!(
                "  hole {}: B-spline curve, {} control points, certified deviation {:.3e} from the face",
                h.name,
                h.curve.control.len(),
                h.deviation
            ));
        }
    }
    for s in pdeshape_io::cad::reported_seams(fitted) {
        let [(a, ua), (b, ub)] = s.faces;
        out.push(format!(
            "seam {} u={ua} | {} u={ub}: gap {:.2e}, normal angle {:.2e} rad, cross curvature gap {:.2e} ({} points, after export)",
            fitted[a].name, fitted[b].name, s.gap, s.angle, s.curvature_gap, s.samples
        ));
    }
    out
}

/// Reads CSV rows of `N` finite numbers from stdin and writes `header` then one line per
/// row from `f`; errors name the line. Blank lines and `#` comments are skipped, and so is
/// a first line that is literally the column names (`u,v` or `u,v,w`, spaces allowed); a
/// UTF-8 byte-order mark is dropped. Any other line that is not `N` numbers is an error.
fn sample_rows<const N: usize>(
    header: &str,
    mut f: impl FnMut(usize, [f64; N], &mut dyn Write) -> Result<()>,
) -> Result<()> {
    let names = header.split(',').take(N).collect::<Vec<_>>().join(",");
    let stdin = std::io::stdin();
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    writeln!(out, "{header}")?;
    let mut first = true;
    for (ln, line) in stdin.lock().lines().enumerate() {
        let line = line.with_context(|| format!("cannot read stdin line {}", ln + 1))?;
        let l = if ln == 0 { line.trim_start_matches('\u{feff}') } else { &line }.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cols: Vec<&str> = l.split(',').map(|c| c.trim()).collect();
        if std::mem::take(&mut first) && cols.join(",") == names {
            continue; // the header
        }
        if cols.len() != N {
            bail!("stdin line {}: expected {N} columns `{names}`, got {}: {:?}", ln + 1, cols.len(), clip(l, 80));
        }
        let mut vals = [0.0f64; N];
        for (k, c) in cols.iter().enumerate() {
            vals[k] = c.parse().map_err(|_| anyhow!("stdin line {}: `{}` is not a number", ln + 1, clip(c, 40)))?;
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
