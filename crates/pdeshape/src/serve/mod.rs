//! `pdeshape serve`: the live editor. An axum server on loopback serving one embedded page
//! (WebGL2, no network access at run time) and a small API:
//!
//! - `GET /` the page; `GET /api/initial` the scene it opens with; `GET /api/examples`
//!   and `GET /api/example/NAME` the built-in examples (the gallery chooser);
//! - `POST /api/model` `{text, params, edits, time, diagnostics}` → the solved model as one
//!   binary message: a `u32` length, a JSON header (parameters, patches, handles, trims,
//!   diagnostics, the edited text) and little-endian `f32`/`u32` buffers it points into;
//!   invalid scenes and edits answer 422 with the error;
//! - `POST /api/export?format=obj|ply|stl|glb|vtu` the same request → the file.
//!
//! Limits: request bodies (1 MiB), vertices per model, solve time, concurrent solves.

mod edit;

use crate::EXAMPLES;
use anyhow::{Context, Result};
use axum::extract::{DefaultBodyLimit, Path as UrlPath, Query, State};
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use pdeshape_core::mesh::Mesh;
use pdeshape_io::model;
use pdeshape_io::scene::{LoadOptions, Scene};
use serde::Deserialize;
use serde_json::{Value, json};
use std::collections::HashMap;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::sync::Semaphore;

/// Largest request body.
pub const MAX_BODY: usize = 1 << 20;
/// Largest model (vertices over all patches) the editor solves.
pub const MAX_VERTICES: usize = 2_000_000;
/// Longest solve before the request is answered with an error.
pub const SOLVE_LIMIT: Duration = Duration::from_secs(30);

const PAGE: &str = include_str!("page.html");
const APP: &str = include_str!("app.js");

/// Options of `pdeshape serve`.
pub struct ServeOptions {
    /// Scene to open (none: the gallery chooser).
    pub scene: Option<std::path::PathBuf>,
    /// Address to bind (loopback unless asked).
    pub host: String,
    /// Port (0: any free port).
    pub port: u16,
}

struct AppState {
    initial: Option<(String, String)>,
    solves: Semaphore,
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
}

/// Runs the server until interrupted; prints the URL.
pub fn run(o: ServeOptions) -> Result<()> {
    let initial = match &o.scene {
        Some(p) => {
            let text =
                std::fs::read_to_string(p).with_context(|| format!("cannot read the scene file {}", p.display()))?;
            let name = p.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
            // refuse a broken scene at start, with the scene error
            Scene::parse_with(
                &text,
                &p.display().to_string(),
                &name,
                &LoadOptions { limits: crate::cli::limits(), ..Default::default() },
            )?;
            Some((name, text))
        }
        None => None,
    };
    let rt = tokio::runtime::Builder::new_multi_thread().enable_all().build()?;
    rt.block_on(async move {
        let listener = tokio::net::TcpListener::bind((o.host.as_str(), o.port))
            .await
            .with_context(|| format!("cannot listen on {}:{}", o.host, o.port))?;
        let addr = listener.local_addr()?;
        println!("pdeshape editor: http://{addr}/");
        use std::io::Write as _;
        std::io::stdout().flush().ok();
        axum::serve(listener, router(initial)).await.context("server stopped")
    })
}

/// The application's routes.
pub fn router(initial: Option<(String, String)>) -> Router {
    // one solve per core at a time (each solve is parallel inside); the others queue, and
    // the time limit counts from the start of their solve
    let permits = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(2);
    let state = Arc::new(AppState { initial, solves: Semaphore::new(permits) });
    Router::new()
        .route("/", get(|| async { Html(PAGE) }))
        .route("/app.js", get(|| async { ([(header::CONTENT_TYPE, "text/javascript; charset=utf-8")], APP) }))
        .route("/api/initial", get(initial_scene))
        .route("/api/examples", get(|| async { Json(EXAMPLES.iter().map(|(n, _)| *n).collect::<Vec<_>>()) }))
        .route("/api/example/{name}", get(example))
        .route("/api/model", post(model_route))
        .route("/api/export", post(export_route))
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .with_state(state)
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
        None => (StatusCode::NOT_FOUND, Json(json!({"error": format!("no example `{name}`")}))).into_response(),
    }
}

fn fail(code: StatusCode, msg: impl Into<String>) -> Response {
    (code, Json(json!({"error": msg.into()}))).into_response()
}

/// Runs `f` on the blocking pool under the concurrency and time limits.
async fn limited<T: Send + 'static>(
    s: &AppState,
    f: impl FnOnce() -> Result<T, String> + Send + 'static,
) -> Result<T, Response> {
    let _permit = s.solves.acquire().await.map_err(|_| fail(StatusCode::SERVICE_UNAVAILABLE, "shutting down"))?;
    match tokio::time::timeout(SOLVE_LIMIT, tokio::task::spawn_blocking(f)).await {
        Err(_) => Err(fail(
            StatusCode::SERVICE_UNAVAILABLE,
            format!("the solve took longer than {} s (lower the resolution or order)", SOLVE_LIMIT.as_secs()),
        )),
        Ok(Err(e)) => Err(fail(StatusCode::INTERNAL_SERVER_ERROR, format!("the solve failed: {e}"))),
        Ok(Ok(Err(e))) => Err(fail(StatusCode::UNPROCESSABLE_ENTITY, e)),
        Ok(Ok(Ok(v))) => Ok(v),
    }
}

struct Solved {
    scene: Scene,
    text: String,
    meshes: Vec<Mesh>,
    solve_ms: f64,
}

/// Applies the edits, resolves the scene and meshes every patch (at `time` for dynamic
/// blends); errors are the scene's errors, ready to show.
pub fn solve(req: &ModelRequest) -> Result<(Scene, String, Vec<Mesh>), String> {
    let text = edit::apply(&req.text, &req.edits)?;
    let name = req.name.clone().unwrap_or_else(|| "scene".into());
    let opts = LoadOptions { params: req.params.clone(), limits: crate::cli::limits(), ..Default::default() };
    let scene = Scene::parse_with(&text, &format!("{name}.toml"), &name, &opts).map_err(|e| e.to_string())?;
    let estimate: usize = scene.patches.iter().map(|p| p.resolution.0 * p.resolution.1).sum();
    if estimate > MAX_VERTICES {
        return Err(format!(
            "the model would have {estimate} vertices; the editor's limit is {MAX_VERTICES} (lower the patches' `resolution`)"
        ));
    }
    let meshes = scene.patches.iter().map(|p| model::editor_mesh(p, req.time)).collect::<Result<Vec<_>, _>>()?;
    Ok((scene, text, meshes))
}

async fn model_route(State(s): State<Arc<AppState>>, Json(req): Json<ModelRequest>) -> Response {
    let diag = req.diagnostics;
    let r = limited(&s, move || {
        let t0 = Instant::now();
        let (scene, text, meshes) = solve(&req)?;
        Ok(Solved { scene, text, meshes, solve_ms: t0.elapsed().as_secs_f64() * 1e3 })
    })
    .await;
    match r {
        Ok(solved) => {
            let body = encode(&solved, diag);
            ([(header::CONTENT_TYPE, "application/octet-stream")], body).into_response()
        }
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
    let Some(format) = pdeshape_io::export::Format::from_extension(&q.format) else {
        return fail(
            StatusCode::BAD_REQUEST,
            format!("unknown format `{}` (known: obj, ply, stl, glb, vtu)", q.format),
        );
    };
    let r = limited(&s, move || {
        let (scene, _, meshes) = solve(&req)?;
        let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
        let path = dir.path().join(format!("{}.{}", scene.name, format.extension()));
        let refs: Vec<&Mesh> = meshes.iter().collect();
        pdeshape_io::export::write_meshes(&path, format, &refs).map_err(|e| e.to_string())?;
        let bytes = std::fs::read(&path).map_err(|e| e.to_string())?;
        Ok((scene.name, bytes))
    })
    .await;
    match r {
        Ok((name, bytes)) => (
            [
                (header::CONTENT_TYPE, "application/octet-stream".to_string()),
                (header::CONTENT_DISPOSITION, format!("attachment; filename=\"{name}.{}\"", format.extension())),
            ],
            bytes,
        )
            .into_response(),
        Err(resp) => resp,
    }
}

/// The binary answer: `u32` header length, JSON header (padded to 4 bytes), buffers.
fn encode(s: &Solved, diagnostics: bool) -> Vec<u8> {
    let mut buf: Vec<u8> = Vec::new();
    let put_f32 = |buf: &mut Vec<u8>, xs: &mut dyn Iterator<Item = f32>| -> Value {
        let offset = buf.len();
        let mut n = 0;
        for x in xs {
            buf.extend_from_slice(&x.to_le_bytes());
            n += 1;
        }
        json!({"offset": offset, "count": n})
    };
    let mut patches = Vec::new();
    for (m, p) in s.meshes.iter().zip(&s.scene.patches) {
        let positions = put_f32(&mut buf, &mut m.positions.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]));
        let normals = put_f32(&mut buf, &mut m.normals.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32]));
        let tris = m.all_triangles();
        let offset = buf.len();
        for t in &tris {
            for i in t {
                buf.extend_from_slice(&i.to_le_bytes());
            }
        }
        let indices = json!({"offset": offset, "count": tris.len() * 3});
        // wireframe: quad edges (and triangle edges)
        let offset = buf.len();
        let mut n = 0;
        for q in &m.quads {
            for k in 0..4 {
                buf.extend_from_slice(&q[k].to_le_bytes());
                buf.extend_from_slice(&q[(k + 1) % 4].to_le_bytes());
                n += 2;
            }
        }
        for t in &m.triangles {
            for k in 0..3 {
                buf.extend_from_slice(&t[k].to_le_bytes());
                buf.extend_from_slice(&t[(k + 1) % 3].to_le_bytes());
                n += 2;
            }
        }
        let lines = json!({"offset": offset, "count": n});
        let curves: Vec<Value> = m
            .curves
            .iter()
            .map(|c| put_f32(&mut buf, &mut c.iter().flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])))
            .collect();
        let fields: Vec<Value> = m
            .fields
            .iter()
            .map(|f| {
                let mut v = put_f32(&mut buf, &mut f.values.iter().map(|x| *x as f32));
                v["name"] = json!(f.name);
                v
            })
            .collect();
        let trim = p.trim.as_ref().map(|t| {
            let g = &t.grid;
            let ring0: Vec<[f64; 2]> = (0..=g.columns).map(|j| g.points[g.index(0, j)]).collect();
            let step = (g.columns / 48).max(1);
            let spokes: Vec<Vec<[f64; 2]>> =
                (0..g.columns).step_by(step).map(|j| (0..g.rings).map(|i| g.points[g.index(i, j)]).collect()).collect();
            let rings: Vec<Vec<[f64; 2]>> = (0..g.rings)
                .step_by((g.rings / 12).max(1))
                .map(|i| (0..=g.columns).map(|j| g.points[g.index(i, j)]).collect())
                .collect();
            let dom = p.surface.v_domain();
            json!({"domain": [[0.0, dom.start], [1.0, dom.end]], "loop": ring0, "spokes": spokes, "rings": rings,
                   "folds_before": g.report.folds_before, "folds_after": g.report.folds_after})
        });
        patches.push(json!({
            "name": m.name,
            "kind": p.kind.name(),
            "color": p.color,
            "vertices": m.positions.len(),
            "positions": positions, "normals": normals, "indices": indices, "lines": lines,
            "curves": curves, "fields": fields, "trim": trim,
        }));
    }
    let params: Vec<Value> = s
        .scene
        .params
        .iter()
        .map(|(k, p)| {
            json!({"name": k, "value": p.value, "min": p.min, "max": p.max, "step": p.step,
                             "derived": p.expr.is_some(), "description": p.description})
        })
        .collect();
    let time = s.scene.patches.iter().find_map(|p| p.dynamic.as_ref()).map(|d| json!([d.times.0, d.times.1]));
    let header = json!({
        "name": s.scene.name,
        "title": s.scene.title,
        "text": s.text,
        "params": params,
        "time_range": time,
        "view": {"azimuth": s.scene.render.azimuth, "elevation": s.scene.render.elevation},
        "patches": patches,
        "editables": edit::editables(&s.text),
        "hash": model::mesh_hash(&s.meshes),
        "solve_ms": s.solve_ms,
        "diagnostics": if diagnostics { model::scene_diagnostics(&s.scene) } else { Value::Null },
    });
    let mut h = serde_json::to_vec(&header).expect("JSON of plain values");
    while !h.len().is_multiple_of(4) {
        h.push(b' ');
    }
    let mut out = Vec::with_capacity(4 + h.len() + buf.len());
    out.extend_from_slice(&(h.len() as u32).to_le_bytes());
    out.extend_from_slice(&h);
    out.extend_from_slice(&buf);
    out
}
