//! Subcommands and exit codes: 0 ok, 1 runtime error, 2 usage error.

use crate::clip::clip;
use anyhow::{Result, anyhow};
use clap::{Parser, Subcommand};
use pdeshape_core::limits::Limits;
use pdeshape_core::solves::Solves;
use pdeshape_io::model;
use pdeshape_io::scene::{LoadOptions, Scene};
use std::collections::HashMap;
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
    /// of one solve; 250000), vertices (per patch or hole fill; 4000000), memory (MiB of
    /// meshes; 4096), scene (MiB of a scene file; 16), model (MiB of a STEP model or mesh
    /// file; 256), entities (of a STEP model, or vertices and faces of a mesh; 4000000).
    #[arg(long = "limit", global = true, value_name = "CAP=VALUE", value_parser = limit)]
    limit: Vec<String>,
    /// Longest time in seconds: for build, check, sample and render the whole command
    /// (default 600; the solvers and meshing loops stop at their next checkpoint, nothing
    /// is written), for serve each request from its arrival, queueing included (default
    /// 30); gallery and bench have none unless given. 0: no limit.
    #[arg(long = "time-limit", global = true, value_name = "SECONDS", value_parser = max_time)]
    time_limit: Option<f64>,
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
        /// STEP only: the measured maximum deviation of every B-spline face from its patch
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
        /// Also fit the faces a STEP export would write and report each face's measured
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
    /// List the holes of a model: a STEP model's loops of free edges (with the faces
    /// around and whether they meet G1 at each corner) or a triangle mesh's boundary loops
    /// (OBJ, PLY, STL), with length and bounding box.
    Holes {
        /// The model (.step, .stp, .obj, .ply or .stl).
        model: PathBuf,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// STEP models: take these faces out first (their `#id`s, as `holes` names the
        /// faces around each hole), so that the loops they leave are holes — a face to be
        /// replaced by a fill.
        #[arg(long, value_delimiter = ',')]
        replace_faces: Vec<u64>,
    },
    /// Fill the holes of a model with fills of order 4 (G1) or 6 (G2) and write it back
    /// with the fills sewn in: a STEP model with new faces (every input face unchanged), a
    /// triangle mesh with new triangles stitched to each hole's own vertices (every input
    /// vertex and triangle kept).
    FillHoles {
        /// The model (.step, .stp, .obj, .ply or .stl).
        model: PathBuf,
        /// The output (.step or .stp for a STEP model; .obj, .ply or .stl for a mesh).
        #[arg(short, long)]
        out: PathBuf,
        /// 4: G1 to the faces around; 6: G2 (the new faces are of degree 5 at both).
        #[arg(long, default_value_t = 4, value_parser = fill_order)]
        order: usize,
        /// The holes to fill, by their numbers in `holes` (default: every hole).
        #[arg(long, value_delimiter = ',', conflicts_with = "max_edges")]
        holes: Option<Vec<usize>>,
        /// Leave holes of more edges open.
        #[arg(long)]
        max_edges: Option<usize>,
        /// The new faces' measured maximum deviation from their fills, relative to the
        /// model's size (default 1e-7).
        #[arg(long, value_parser = positive)]
        relative_tolerance: Option<f64>,
        /// STEP models: take these faces out first (their `#id`s, as `holes` names the
        /// faces around each hole), so that the loops they leave are holes — a face to be
        /// replaced by a fill.
        #[arg(long, value_delimiter = ',')]
        replace_faces: Vec<u64>,
    },
    /// Render a scene, or a triangle mesh (.obj, .ply, .stl), to PNG.
    Render {
        /// Scene file (TOML), or a mesh file (shaded, zebra or isophotes).
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
        /// Timed runs per measurement (medians are reported; 1 to 10000).
        #[arg(long, default_value_t = 21, value_parser = clap::value_parser!(u64).range(1..=10_000))]
        runs: u64,
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
        /// Scene to open (default: a chooser of the built-in examples), or a STEP model
        /// (.step, .stp): its faces drawn, a click on a hole's loop fills it.
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
    if (-90.0..=90.0).contains(&x) {
        Ok(x)
    } else {
        Err(format!("`{}` is outside [-90, 90] degrees", clip(s.trim(), 40)))
    }
}

/// A surface view of `render --view`.
fn view(s: &str) -> Result<pdeshape_io::render::View, String> {
    s.parse()
}

/// A stripe count: 1 to 200.
fn stripes(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if (1.0..=200.0).contains(&x) { Ok(x) } else { Err(format!("`{}` is outside [1, 200]", clip(s.trim(), 40))) }
}

/// A positive finite number.
fn positive(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if x > 0.0 { Ok(x) } else { Err(format!("`{}` is not positive", clip(s.trim(), 40))) }
}

/// `--time-limit`: 0 (no limit) or a positive time of at most a week.
fn max_time(s: &str) -> Result<f64, String> {
    let x = finite(s)?;
    if (0.0..=604_800.0).contains(&x) {
        Ok(x)
    } else {
        Err(format!("`{}` is outside [0, 604800] seconds", clip(s.trim(), 40)))
    }
}

/// The default `--time-limit` of the commands that load one scene.
pub const DEFAULT_MAX_TIME: f64 = 600.0;

/// `NAME=VALUE` of `--set`, the value finite.
fn setting(s: &str) -> Result<(String, f64), String> {
    let (k, v) = s.split_once('=').ok_or_else(|| format!("`{}`: expected NAME=VALUE", clip(s, 40)))?;
    let x = finite(v).map_err(|e| format!("`{}`: {e}", clip(k.trim(), 40)))?;
    Ok((k.trim().to_string(), x))
}

/// A fill's order: 4 or 6.
fn fill_order(s: &str) -> Result<usize, String> {
    match s {
        "4" => Ok(4),
        "6" => Ok(6),
        _ => Err(format!("`{}`: the order is 4 (G1) or 6 (G2)", clip(s, 20))),
    }
}

/// A `--limit CAP=VALUE` setting, checked as clap parses it.
fn limit(s: &str) -> Result<String, String> {
    Limits::default().apply(s).map(|()| s.to_string())
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
    let max_time = match (&cli.command, cli.time_limit) {
        // serve applies its limit to each request
        (Command::Serve { .. }, _) => 0.0,
        (_, Some(t)) => t,
        (
            Command::Build { .. }
            | Command::Check { .. }
            | Command::Sample { .. }
            | Command::Render { .. }
            | Command::Holes { .. }
            | Command::FillHoles { .. },
            None,
        ) => DEFAULT_MAX_TIME,
        _ => 0.0,
    };
    let result = if max_time > 0.0 { within(max_time, move || execute(cli, limits)) } else { execute(cli, limits) };
    if std::env::var_os("PDESHAPE_SOLVE_COUNTS").is_some() {
        // a test hook: the solves of the whole command, and those done while loading
        let loaded = LOADED.get().copied().unwrap_or_default();
        eprintln!("solves: loaded {:?}, command {:?}", loaded.0, Solves::now().since(loaded).0);
    }
    match result {
        Ok(()) => 0,
        // the reader of stdout closed it (`| head`): it wanted no more
        Err(e)
            if e.chain().any(|c| {
                c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            }) =>
        {
            0
        }
        Err(e) => {
            // hostile input echoed in the message is escaped and cut (a scene's keys can
            // hold escapes; a message is at most 4000 characters)
            eprintln!("error: {}", crate::clip::printable(&format!("{e:#}"), 4000));
            let usage = e.chain().any(|c| {
                c.is::<crate::usage::Usage>()
                    || c.downcast_ref::<pdeshape_io::scene::SceneError>().is_some_and(|s| s.key.starts_with("--"))
            });
            if usage { 2 } else { 1 }
        }
    }
}

/// Runs `f` under a deadline `seconds` from now: a watchdog raises the cancel flag then,
/// and the computation unwinds at its next checkpoint (`pdeshape_core::cancel`) into an
/// error naming the limit and the flag that raises it. Files are written atomically, so a
/// stopped command leaves none.
fn within(seconds: f64, f: impl FnOnce() -> Result<()> + Send) -> Result<()> {
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    match pdeshape_core::cancel::within(std::time::Duration::from_secs_f64(seconds), threads, f) {
        Ok(r) => r,
        Err(pdeshape_core::cancel::Cancelled) => Err(anyhow!(
            "the command ran past its time limit of {seconds} s and was stopped (nothing was written); raise it with `--time-limit SECONDS` (0: no limit), or lower the scene's resolution, modes or order"
        )),
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
            imports: pdeshape_io::scene::ImportRoot::Dir(pdeshape_io::scene::scene_folder(path)),
        };
        let scene = Scene::parse_with(&text, &path.display().to_string(), &name, &opts)?;
        let _ = LOADED.set(Solves::now());
        Ok(scene)
    }
}

fn execute(cli: Cli, limits: Limits) -> Result<()> {
    let quiet = cli.quiet;
    let time_limit = cli.time_limit;
    let loader = |set, solver, terms: Option<u64>| Load { limits, set, solver, terms: terms.map(|t| t as usize) };
    match cli.command {
        Command::Build { scene, out, set, tolerance, relative_tolerance, degree } => {
            let sc = loader(&set, None, None).scene(&scene)?;
            let step = crate::build::StepOptions { tolerance, relative_tolerance, degree };
            crate::build::command(&sc, &out, &step, quiet)
        }
        Command::Check { scene, json, set, solver, cad, degree } => {
            let sc = loader(&set, solver.as_deref(), None).scene(&scene)?;
            crate::check::command(&sc, json, cad, degree)
        }
        Command::Sample { scene, patch, time, set, solver, terms } => {
            let sc = loader(&set, solver.as_deref(), terms).scene(&scene)?;
            crate::sample::command(&sc, patch.as_deref(), time, quiet)
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
            // the command line's choices over a scene's picture settings (or the defaults)
            let apply = |r: &mut pdeshape_io::scene::RenderSettings| {
                if let Some(w) = width {
                    r.size.0 = w;
                }
                if let Some(h) = height {
                    r.size.1 = h;
                }
                if let Some(a) = azimuth {
                    r.azimuth = a;
                }
                if let Some(e) = elevation {
                    r.elevation = e;
                }
                r.wireframe |= wireframe;
                r.view = view;
                r.stripes = stripes.unwrap_or(r.stripes);
                r.stripe_angle = stripe_angle.unwrap_or(r.stripe_angle);
                r.curvature_limit = curvature_limit.or(r.curvature_limit);
            };
            if pdeshape_io::import::mesh::MeshFormat::from_path(&scene).is_some() {
                if !set.is_empty() {
                    return Err(crate::usage::Usage(format!(
                        "{}: --set changes a scene's parameters; a mesh file has none",
                        scene.display()
                    ))
                    .into());
                }
                let mut r = pdeshape_io::scene::RenderSettings::default();
                apply(&mut r);
                let img = crate::holes::render_mesh(&scene, &r, &limits)?;
                crate::build::write_png(&out, &img)?;
                if !quiet {
                    eprintln!("wrote {}", out.display());
                }
                return Ok(());
            }
            let mut sc = loader(&set, None, None).scene(&scene)?;
            apply(&mut sc.render);
            let img = model::render_scene(&sc).map_err(|e| anyhow!(e))?;
            crate::build::write_png(&out, &img)?;
            if !quiet {
                eprintln!("wrote {}", out.display());
            }
            Ok(())
        }
        Command::Holes { model, json, replace_faces } => crate::holes::list(&model, json, &replace_faces, &limits),
        Command::FillHoles { model, out, order, holes, max_edges, relative_tolerance, replace_faces } => {
            let mut o = pdeshape_io::holes::FillHolesOptions { order, holes, max_edges, ..Default::default() };
            if let Some(r) = relative_tolerance {
                o.relative = r;
            }
            crate::holes::fill(&model, &out, &o, &replace_faces, &limits, quiet)
        }
        Command::Gallery { dir } => crate::gallery::run(&dir, quiet, limits),
        Command::Bench { scaling: Some(dir), runs, max_side, .. } => {
            crate::bench::scaling(&dir, runs as usize, max_side, quiet, limits)
        }
        Command::Bench { json, runs, out, .. } => crate::bench::run(runs as usize, json, out.as_deref(), limits),
        Command::Serve { scene, port, host, open: _ } => crate::serve::run(crate::serve::ServeOptions {
            scene,
            host,
            port,
            limits,
            // 0: no limit (a week, which no request waits for)
            time_limit: match time_limit {
                None => crate::serve::SOLVE_LIMIT,
                Some(t) if t > 0.0 => std::time::Duration::from_secs_f64(t),
                Some(_) => std::time::Duration::from_secs(604_800),
            },
        }),
    }
}
