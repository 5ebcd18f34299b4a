//! `pdeshape serve`: the live editor. An axum server on loopback serving one embedded page
//! (WebGL2, no network access at run time) and a small API:
//!
//! - `GET /` the page; `GET /api/initial` the scene it opens with; `GET /api/examples`
//!   and `GET /api/example/NAME` the built-in examples (the gallery chooser);
//! - `POST /api/model` `{text, params, edits, time, diagnostics}` → the solved model as one
//!   binary message: a `u32` length, a JSON header (parameters, patches, handles, trims,
//!   diagnostics, the edited text) and little-endian `f32`/`u32` buffers it points into;
//!   invalid scenes and edits answer 422 with the error;
//! - `POST /api/export?format=obj|ply|stl|glb|vtu` the same request → the file's bytes
//!   (built in memory; no path is ever made from a request).
//!
//! Every request is treated as hostile (SPEC §14, SECURITY.md): any web page the user
//! visits can send requests to loopback. The server answers only requests whose `Host`
//! names the bound address or `localhost` with the bound port (DNS rebinding: 421), refuses
//! requests whose `Origin` is another site (403) and bodies that are not JSON (415) or
//! larger than 1 MiB (413), bounds the model's vertices and solver memory (the caps), the
//! queue (429 past [`MAX_QUEUED`] waiting requests) and the time: the limit ([`SOLVE_LIMIT`]
//! unless `--time-limit` says otherwise) counts
//! from the request's arrival, queueing included, and a solve past it is cancelled (the
//! solvers' checkpoints unwind it) and holds its slot until it has really stopped.

mod idle;
mod wire;

use crate::EXAMPLES;
use crate::clip::{clip, printable};
use anyhow::{Context, Result};
use axum::extract::{DefaultBodyLimit, Path as UrlPath, Query, Request, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::middleware::{self, Next};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use pdeshape_core::cancel;
use pdeshape_core::limits::Limits;
use pdeshape_core::mesh::Mesh;
use pdeshape_io::model;
use pdeshape_io::scene::edit;
use pdeshape_io::scene::{ImportRoot, LoadOptions, Scene};
use serde::Deserialize;
use serde_json::{Value, json};
use std::collections::HashMap;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};
use tokio::sync::Semaphore;

/// Largest request body.
pub const MAX_BODY: usize = 1 << 20;
/// Largest model (vertices over all patches) the editor solves.
pub const MAX_VERTICES: usize = 2_000_000;
/// Default longest time from a request's arrival to its answer (queueing and solve);
/// `serve --time-limit` changes it.
pub const SOLVE_LIMIT: Duration = Duration::from_secs(30);
/// Requests that may wait for a solve slot; more are refused with 429.
pub const MAX_QUEUED: usize = 8;
/// Downloads (`/api/export`) that may wait for the export slot; more are refused with 429.
pub const MAX_QUEUED_EXPORTS: usize = 4;
/// How long past the time limit a connection may stay silent (no byte read or written)
/// before it is closed: no request takes longer than the limit, so a connection silent
/// for longer is stalled.
pub const IDLE_GRACE: Duration = Duration::from_secs(5);

const PAGE: &str = include_str!("page.html");
/// The editor's ES modules, by path: `app.js` imports the others.
const SCRIPTS: [(&str, &str); 4] = [
    ("/app.js", include_str!("app.js")),
    ("/wire.js", include_str!("wire.js")),
    ("/camera.js", include_str!("camera.js")),
    ("/views.js", include_str!("views.js")),
];

/// Options of `pdeshape serve`.
pub struct ServeOptions {
    /// Scene to open (none: the gallery chooser).
    pub scene: Option<std::path::PathBuf>,
    /// Address to bind (loopback unless asked).
    pub host: String,
    /// Port (0: any free port).
    pub port: u16,
    /// The caps every request's scene is loaded under.
    pub limits: Limits,
    /// Longest time from a request's arrival to its answer.
    pub time_limit: Duration,
}

/// A kind of work with its own slots and queue: the editor's live requests, and the
/// downloads (a STEP fit can take seconds), so that downloads never hold the slots or fill
/// the queue that the sliders' requests need.
struct Lane {
    /// Work running at a time; a piece of work holds its permit until it has stopped.
    slots: Arc<Semaphore>,
    /// Requests waiting for a permit.
    queued: AtomicUsize,
    /// Most requests waiting; more are refused with 429.
    max_queued: usize,
    /// Worker threads of one piece of work.
    threads: usize,
    /// What the work is called in messages.
    what: &'static str,
}

impl Lane {
    fn new(slots: usize, max_queued: usize, threads: usize, what: &'static str) -> Lane {
        Lane { slots: Arc::new(Semaphore::new(slots)), queued: AtomicUsize::new(0), max_queued, threads, what }
    }
}

struct AppState {
    initial: Option<(String, String)>,
    /// The models the starting scene imported: the only files requests may import (their
    /// text comes from a web page).
    imports: ImportRoot,
    /// Live requests (`/api/model`): one solve per core at a time, each parallel inside.
    solves: Lane,
    /// Downloads (`/api/export`): one at a time, on one thread.
    exports: Lane,
    /// `Host` values answered (lower case): the bound `host:port`, loopback names.
    hosts: Vec<String>,
    limits: Limits,
    time_limit: Duration,
}

/// A request for the solved model.
#[derive(Deserialize)]
pub struct ModelRequest {
    /// Scene text.
    pub text: String,
    /// Scene name (file stem).
    #[serde(default)]
    pub name: Option<String>,
    /// Parameter values.
    #[serde(default)]
    pub params: HashMap<String, f64>,
    /// Edits of the text, applied first.
    #[serde(default)]
    pub edits: Vec<edit::Edit>,
    /// Time, for dynamic blends.
    #[serde(default)]
    pub time: Option<f64>,
    /// Also compute `check`'s diagnostics (slower).
    #[serde(default)]
    pub diagnostics: bool,
    /// Curves with exact curvature to draw: a plane section, curvature combs.
    #[serde(default)]
    pub curves: Option<CurvesRequest>,
}

/// The editor's curve tools (untrimmed, static patches: their `(u, v)` grid is the mesh).
#[derive(Deserialize, Clone, Debug, Default)]
#[serde(deny_unknown_fields)]
pub struct CurvesRequest {
    /// The section plane `{axis: "x" | "y" | "z", offset}`: the points whose coordinate
    /// `axis` equals `offset`.
    #[serde(default)]
    pub section: Option<SectionPlane>,
    /// Curvature combs along each patch's position trimlines.
    #[serde(default)]
    pub combs: bool,
    /// A comb along the isoparameter `u` (in [0, 1]) of every patch.
    #[serde(default)]
    pub iso_u: Option<f64>,
}

/// A section plane normal to a coordinate axis.
#[derive(Deserialize, Clone, Debug)]
#[serde(deny_unknown_fields)]
pub struct SectionPlane {
    /// `x`, `y` or `z`.
    pub axis: String,
    /// The plane's coordinate on that axis.
    pub offset: f64,
}

impl CurvesRequest {
    /// Checks the request: a known axis, finite numbers, `iso_u` in [0, 1].
    fn check(&self) -> Result<(), String> {
        if let Some(s) = &self.section {
            if !["x", "y", "z"].contains(&s.axis.as_str()) {
                return Err(format!("curves.section.axis must be x, y or z, not `{}`", clip(&s.axis, 16)));
            }
            if !s.offset.is_finite() {
                return Err("curves.section.offset must be finite".into());
            }
        }
        if let Some(u) = self.iso_u
            && !(0.0..=1.0).contains(&u)
        {
            return Err(format!("curves.iso_u must be in [0, 1], not {u}"));
        }
        Ok(())
    }
}

/// The requested curves of every patch: per patch its plane section (segments `[x, y, z,
/// kx, ky, kz, x′, y′, z′, k′…]`) and combs (`u`, points, curvature vectors, which point to
/// the centre of curvature; NaN becomes null where undefined). Trimmed, solid and moving
/// patches get none.
fn curves_answer(scene: &Scene, c: &CurvesRequest) -> Vec<wire::PatchCurves> {
    use pdeshape_core::patch::{CurvePoint, iso_u_curve, plane_section};
    let flat = |pts: &[CurvePoint]| -> (Vec<f64>, Vec<f64>) {
        let p = pts.iter().flat_map(|c| [c.point.x, c.point.y, c.point.z]).collect();
        let k = pts.iter().flat_map(|c| [c.curvature.x, c.curvature.y, c.curvature.z]).collect();
        (p, k)
    };
    scene
        .patches
        .iter()
        .map(|p| {
            if p.trim.is_some() || p.solid.is_some() || p.dynamic.is_some() {
                return wire::PatchCurves::None { name: p.name.clone() };
            }
            let s = p.surface.as_ref();
            let (nu, nv) = p.resolution;
            let (us, vs) = pdeshape_core::mesh::grid_params(s, &pdeshape_core::mesh::GridOptions::new(nu, nv));
            let section = c.section.as_ref().map(|sp| {
                let a = match sp.axis.as_str() {
                    "x" => pdeshape_core::Vec3::new(1.0, 0.0, 0.0),
                    "y" => pdeshape_core::Vec3::new(0.0, 1.0, 0.0),
                    _ => pdeshape_core::Vec3::new(0.0, 0.0, 1.0),
                };
                let segs = plane_section(s, &us, &vs, a * sp.offset, a);
                segs.iter()
                    .map(|[a, b]| {
                        let (pa, ka) = flat(&[*a, *b]);
                        [pa[..3].to_vec(), ka[..3].to_vec(), pa[3..].to_vec(), ka[3..].to_vec()].concat()
                    })
                    .collect::<Vec<_>>()
            });
            let mut comb_us: Vec<f64> = Vec::new();
            if c.combs {
                comb_us.extend(p.conditions.iter().filter(|k| k.order == 0).map(|k| k.u));
            }
            comb_us.extend(c.iso_u);
            let n = (4 * nv).clamp(64, 1024);
            let dom = s.v_domain();
            let cvs: Vec<f64> = (0..=n).map(|k| dom.at(k as f64 / n as f64)).collect();
            let combs = comb_us
                .iter()
                .map(|&u| {
                    let (points, curvature) = flat(&iso_u_curve(s, u, &cvs));
                    wire::Comb { u, points, curvature }
                })
                .collect();
            wire::PatchCurves::Some { name: p.name.clone(), section, combs }
        })
        .collect()
}

/// Runs the server until interrupted; prints the URL.
pub fn run(o: ServeOptions) -> Result<()> {
    let (initial, imports) = match &o.scene {
        Some(p) => {
            let text = if is_model(p) { model_scene(p) } else { pdeshape_io::scene::read_scene_file(p, &o.limits)? };
            let name = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
            // refuse a broken scene at start, with the scene error; its imports are read
            // once, here, and are all that requests may import
            let opts = LoadOptions {
                limits: o.limits,
                imports: ImportRoot::Dir(pdeshape_io::scene::scene_folder(p)),
                ..Default::default()
            };
            let scene = Scene::parse_with(&text, &p.display().to_string(), &name, &opts)?;
            (Some((name, text)), scene.imported())
        }
        None => (None, ImportRoot::Refused),
    };
    let rt = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    rt.block_on(async move {
        let listener = tokio::net::TcpListener::bind((o.host.as_str(), o.port))
            .await
            .with_context(|| format!("cannot listen on {}:{}", o.host, o.port))?;
        let addr = listener.local_addr()?;
        outln!("pdeshape editor: http://{addr}/");
        use std::io::Write as _;
        std::io::stdout().flush().ok();
        let listener = idle::IdleListener::new(listener, o.time_limit.saturating_add(IDLE_GRACE));
        axum::serve(listener, router(initial, imports, addr, o.limits, o.time_limit)).await.context("server stopped")
    })
}

/// The `Host` values a server bound to `addr` answers: `addr` itself and, on loopback,
/// `localhost`, `127.0.0.1` and `[::1]`, all with the bound port.
fn allowed_hosts(addr: std::net::SocketAddr) -> Vec<String> {
    let port = addr.port();
    let mut hosts = vec![addr.to_string().to_ascii_lowercase()];
    if addr.ip().is_loopback() {
        for h in ["localhost", "127.0.0.1", "[::1]"] {
            hosts.push(format!("{h}:{port}"));
        }
    }
    hosts
}

/// Whether `p` names a CAD model (`.step`, `.stp`) rather than a scene.
fn is_model(p: &std::path::Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("step") || e.eq_ignore_ascii_case("stp"))
}

/// The scene the editor opens for a model file: the model imported under its file stem
/// (letters, digits and `_`; `model` when that is not a name a scene may use).
fn model_scene(p: &std::path::Path) -> String {
    let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let mut name: String = stem.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    if !name.starts_with(|c: char| c.is_ascii_alphabetic())
        || pdeshape_io::scene::RESERVED.contains(&name.as_str())
        || name.len() > 40
    {
        name = "model".into();
    }
    let file = p.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    // the file name as a TOML string (quotes, backslashes and control characters escaped)
    let mut quoted = String::from("\"");
    for c in file.chars() {
        match c {
            '"' | '\\' => {
                quoted.push('\\');
                quoted.push(c);
            }
            c if c.is_control() => quoted.push_str(&format!("\\u{:04X}", c as u32)),
            c => quoted.push(c),
        }
    }
    quoted.push('"');
    format!("# the model's holes are drawn orange: click one to fill it\n[import.{name}]\nstep = {quoted}\n")
}

/// The application's routes for a server bound to `addr`.
pub fn router(
    initial: Option<(String, String)>,
    imports: ImportRoot,
    addr: std::net::SocketAddr,
    limits: Limits,
    time_limit: Duration,
) -> Router {
    // one solve per core at a time (each solve is parallel inside); the others queue, and
    // the time limit counts from their arrival
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(2);
    let state = Arc::new(AppState {
        initial,
        imports,
        solves: Lane::new(threads, MAX_QUEUED, threads, "solve"),
        exports: Lane::new(1, MAX_QUEUED_EXPORTS, 1, "export"),
        hosts: allowed_hosts(addr),
        limits,
        time_limit,
    });
    let mut router = Router::new().route("/", get(|| async { Html(PAGE) }));
    for (path, body) in SCRIPTS {
        router = router.route(
            path,
            get(move || async move { ([(header::CONTENT_TYPE, "text/javascript; charset=utf-8")], body) }),
        );
    }
    router
        .route("/api/initial", get(initial_scene))
        .route("/api/examples", get(|| async { Json(EXAMPLES.iter().map(|(n, _)| *n).collect::<Vec<_>>()) }))
        .route("/api/example/{name}", get(example))
        .route("/api/model", post(model_route))
        .route("/api/export", post(export_route))
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .layer(middleware::from_fn_with_state(state.clone(), guard))
        .with_state(state)
}

/// Refuses requests for another host (DNS rebinding) and requests from another site.
async fn guard(State(s): State<Arc<AppState>>, req: Request, next: Next) -> Response {
    match screen(&s.hosts, req.headers()) {
        Ok(()) => next.run(req).await,
        Err((code, msg)) => fail(code, msg),
    }
}

/// The header checks of [`guard`]: `Host` must be one of `hosts`; an `Origin` (sent by
/// browsers with every cross-origin request and every POST) must be `http://` one of
/// them; `Sec-Fetch-Site: cross-site` is refused.
fn screen(hosts: &[String], h: &HeaderMap) -> Result<(), (StatusCode, String)> {
    let host = h.get(header::HOST).and_then(|v| v.to_str().ok()).map(str::to_ascii_lowercase);
    match &host {
        Some(x) if hosts.contains(x) => {}
        _ => {
            return Err((
                StatusCode::MISDIRECTED_REQUEST,
                format!(
                    "this editor answers only requests for {} (Host was {})",
                    hosts.join(", "),
                    host.as_deref().map(|x| format!("`{}`", clip(x, 80))).unwrap_or_else(|| "missing".into())
                ),
            ));
        }
    }
    if let Some(origin) = h.get(header::ORIGIN) {
        let o = origin.to_str().unwrap_or("").to_ascii_lowercase();
        let same = o.strip_prefix("http://").is_some_and(|rest| hosts.iter().any(|x| x == rest));
        if !same {
            return Err((StatusCode::FORBIDDEN, format!("cross-site request from `{}` refused", clip(&o, 80))));
        }
    }
    if h.get("sec-fetch-site").and_then(|v| v.to_str().ok()) == Some("cross-site") {
        return Err((StatusCode::FORBIDDEN, "cross-site request refused".into()));
    }
    Ok(())
}

async fn initial_scene(State(s): State<Arc<AppState>>) -> Json<Value> {
    Json(match &s.initial {
        Some((name, text)) => json!({"name": name, "text": text}),
        None => Value::Null,
    })
}

async fn example(UrlPath(name): UrlPath<String>) -> Response {
    match EXAMPLES.iter().find(|(n, _)| *n == name) {
        Some((n, t)) => Json(json!({"name": n, "text": t})).into_response(),
        None => fail(StatusCode::NOT_FOUND, format!("no example `{}`", clip(&name, 64))),
    }
}

/// An error answer; the message is escaped and cut (at most 2000 characters: errors
/// never echo a whole hostile input).
fn fail(code: StatusCode, msg: impl Into<String>) -> Response {
    (code, Json(json!({"error": printable(&msg.into(), 2000)}))).into_response()
}

/// Counts a waiting request while alive.
struct Queued<'a>(&'a AtomicUsize);
impl Drop for Queued<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Runs `f` on the blocking pool under `lane`'s queue and slots and the time limit; the
/// time counts from `arrived`. A request whose time runs out while it waits is refused as a
/// queue time-out (it never started); work past the limit is cancelled, and its permit is
/// released when it has stopped, not when the answer is sent.
async fn limited<T: Send + 'static>(
    s: &AppState,
    lane: &Lane,
    arrived: Instant,
    f: impl FnOnce() -> Result<T, String> + Send + 'static,
) -> Result<T, Response> {
    let deadline = tokio::time::Instant::from_std(arrived + s.time_limit);
    let limit = s.time_limit.as_secs_f64();
    let permit = {
        let waiting = lane.queued.fetch_add(1, Ordering::SeqCst);
        let _q = Queued(&lane.queued);
        if waiting >= lane.max_queued {
            return Err(fail(
                StatusCode::TOO_MANY_REQUESTS,
                format!("the editor is busy: {waiting} requests are waiting for a {}; try again shortly", lane.what),
            ));
        }
        match tokio::time::timeout_at(deadline, lane.slots.clone().acquire_owned()).await {
            Err(_) => {
                return Err(fail(
                    StatusCode::SERVICE_UNAVAILABLE,
                    format!(
                        "the request waited {limit} s in the queue for a free {} slot and was not started (the editor's time limit counts from arrival); try again shortly",
                        lane.what
                    ),
                ));
            }
            Ok(Err(_)) => return Err(fail(StatusCode::SERVICE_UNAVAILABLE, "shutting down")),
            Ok(Ok(p)) => p,
        }
    };
    let too_slow = || {
        fail(
            StatusCode::SERVICE_UNAVAILABLE,
            format!(
                "the {} took longer than the editor's limit of {limit} s and was stopped (lower the resolution, modes or order)",
                lane.what
            ),
        )
    };
    let flag = Arc::new(AtomicBool::new(false));
    let worker_flag = flag.clone();
    let threads = lane.threads;
    let mut task = tokio::task::spawn_blocking(move || {
        let _permit = permit; // held until the work has stopped
        cancel::run(&worker_flag, threads, f)
    });
    match tokio::time::timeout_at(deadline, &mut task).await {
        Err(_) => {
            // raise the flag: the solve unwinds at its next checkpoint and frees its core
            flag.store(true, Ordering::SeqCst);
            Err(too_slow())
        }
        Ok(Err(e)) => Err(fail(StatusCode::INTERNAL_SERVER_ERROR, format!("the {} failed: {e}", lane.what))),
        Ok(Ok(Err(cancel::Cancelled))) => Err(too_slow()),
        Ok(Ok(Ok(Err(e)))) => Err(fail(StatusCode::UNPROCESSABLE_ENTITY, e)),
        Ok(Ok(Ok(Ok(v)))) => Ok(v),
    }
}

struct Solved {
    scene: Scene,
    text: String,
    meshes: Vec<Mesh>,
    context: Vec<Mesh>,
    solve_ms: f64,
}

/// The scene name of a request as used in answers and download names: letters, digits,
/// `-` and `_` only (anything else becomes `_`), at most 64 characters, `scene` when empty.
pub fn safe_name(name: Option<&str>) -> String {
    let n: String = name
        .unwrap_or("")
        .chars()
        .take(64)
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' })
        .collect();
    if n.trim_matches('_').is_empty() { "scene".into() } else { n }
}

/// Applies the edits, resolves the scene and meshes every patch (at `time` for dynamic
/// blends); errors are the scene's errors, ready to show.
pub fn solve(req: &ModelRequest, limits: &Limits, imports: &ImportRoot) -> Result<(Scene, String, Vec<Mesh>), String> {
    let text = edit::apply(&req.text, &req.edits)?;
    let name = safe_name(req.name.as_deref());
    let opts =
        LoadOptions { params: req.params.clone(), limits: *limits, imports: imports.clone(), ..Default::default() };
    let scene = Scene::parse_with(&text, &format!("{name}.toml"), &name, &opts).map_err(|e| e.to_string())?;
    let estimate: usize = scene.patches.iter().map(|p| p.vertices()).sum();
    if estimate > MAX_VERTICES {
        return Err(format!(
            "the model would have {estimate} vertices; the editor's limit is {MAX_VERTICES} (lower the patches' `resolution` or `trim.resolution`)"
        ));
    }
    let meshes = scene.patches.iter().map(|p| model::editor_mesh(p, req.time)).collect::<Result<Vec<_>, _>>()?;
    Ok((scene, text, meshes))
}

async fn model_route(State(s): State<Arc<AppState>>, Json(req): Json<ModelRequest>) -> Response {
    let arrived = Instant::now();
    let limits = s.limits;
    let imports = s.imports.clone();
    // diagnostics and encoding run inside the limits too
    let r = limited(&s, &s.solves, arrived, move || {
        let t0 = Instant::now();
        if let Some(c) = &req.curves {
            c.check()?;
        }
        let (scene, text, meshes) = solve(&req, &limits, &imports)?;
        // the answer's buffers are f32: a value that does not fit is an error, not an inf
        for m in &meshes {
            m.check_fits_f32("the editor's buffers")?;
        }
        let curves = req.curves.as_ref().map(|c| curves_answer(&scene, c));
        let context = model::import_meshes(&scene);
        let solved = Solved { scene, text, meshes, context, solve_ms: t0.elapsed().as_secs_f64() * 1e3 };
        Ok(wire::encode(
            &wire::Model {
                scene: &solved.scene,
                text: &solved.text,
                meshes: &solved.meshes,
                context: &solved.context,
                solve_ms: solved.solve_ms,
            },
            req.diagnostics,
            curves,
        ))
    })
    .await;
    match r {
        Ok(body) => ([(header::CONTENT_TYPE, "application/octet-stream")], body).into_response(),
        Err(resp) => resp,
    }
}

#[derive(Deserialize)]
struct ExportQuery {
    format: String,
}

async fn export_route(
    State(s): State<Arc<AppState>>,
    Query(q): Query<ExportQuery>,
    Json(req): Json<ModelRequest>,
) -> Response {
    let arrived = Instant::now();
    let step = q.format.eq_ignore_ascii_case("step") || q.format.eq_ignore_ascii_case("stp");
    let format = pdeshape_io::export::Format::from_extension(&q.format);
    if format.is_none() && !step {
        return fail(
            StatusCode::BAD_REQUEST,
            format!("unknown format `{}` (known: obj, ply, stl, glb, vtu, step)", clip(&q.format, 16)),
        );
    }
    let extension = format.map_or("step", |f| f.extension());
    let limits = s.limits;
    let imports = s.imports.clone();
    let r = limited(&s, &s.exports, arrived, move || {
        let (scene, _, meshes) = solve(&req, &limits, &imports)?;
        let bytes = match format {
            Some(format) => {
                let refs: Vec<&Mesh> = meshes.iter().collect();
                pdeshape_io::export::to_bytes(format, &refs).map_err(|e| e.to_string())?
            }
            // measured B-spline faces at the editor's time (inside the time limit: the
            // fit checks the cancel flag)
            // a scene that imports a model: that model with the scene's fills of its
            // holes sewn in, as `build -o OUT.step` writes it
            None if !scene.imports.is_empty() => {
                let relative = pdeshape_io::holes::FillHolesOptions::default().relative;
                let (m, filled) = pdeshape_io::holes::scene_fills(&scene, relative)?;
                pdeshape_io::holes::filled_bytes(&m.model, &m.holes, &filled)?
            }
            None => {
                let faces = pdeshape_io::cad::fit_scene(
                    &scene,
                    &pdeshape_io::cad::CadOptions { time: req.time, ..Default::default() },
                )?;
                pdeshape_io::cad::step_bytes(&scene, &faces).map_err(|e| e.to_string())?
            }
        };
        Ok((scene.name, bytes))
    })
    .await;
    match r {
        Ok((name, bytes)) => (
            [
                (header::CONTENT_TYPE, "application/octet-stream".to_string()),
                // `name` went through safe_name: no quote, slash or control character
                (header::CONTENT_DISPOSITION, format!("attachment; filename=\"{name}.{extension}\"")),
            ],
            bytes,
        )
            .into_response(),
        Err(resp) => resp,
    }
}
