//! The scaling study (`pdeshape bench --scaling`): time and memory against grid
//! resolution, PDE order `2N`, Fourier modes `M` and collocation size, each on one and on
//! two rayon threads.
//!
//! Solve timings are cold: every run uses a slightly different shape parameter `a`
//! (`1 + k·10⁻⁹`), so the process-wide memo of cardinal functions cannot serve it.

use crate::tables::{Timing, time};
use pdeshape_core::mesh::{GridOptions, grid_mesh};
use pdeshape_io::render::Image;
use pdeshape_io::render::{Series, line_plot};
use pdeshape_io::scene::{LoadOptions, Scene};
use serde::Serialize;
use std::collections::HashMap;

/// One measurement.
#[derive(Clone, Debug, Serialize)]
pub struct ScalingRow {
    /// `"resolution"`, `"order"`, `"modes"` or `"collocation"`.
    pub study: &'static str,
    /// The size varied: vertices, `2N`, `M` or collocation rows.
    pub size: usize,
    /// Rayon threads.
    pub threads: usize,
    /// Solving the scene (parse, data analysis, cardinal functions), when it varies.
    pub solve: Option<Timing>,
    /// Meshing the patch (values and exact normals) at the study's resolution.
    pub mesh: Timing,
    /// Bytes of the mesh (positions, normals, UVs, quads).
    pub mesh_bytes: usize,
}

/// The study's settings.
#[derive(Clone, Copy, Debug)]
pub struct ScalingOptions {
    /// Timed runs of the cheap measurements (fewer for the big ones, at least 3).
    pub runs: usize,
    /// Largest grid side (the study goes 50, 100, 200, 500, 1000, 2000 up to it).
    pub max_side: usize,
    /// The caps every scene of the study is resolved under (`--limit`).
    pub limits: pdeshape_core::limits::Limits,
}

fn pool(threads: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())
}

/// Parses `text`, with the parameter `a` set when given.
fn parse(text: &str, a: Option<f64>, limits: pdeshape_core::limits::Limits) -> Result<Scene, String> {
    let opts = LoadOptions {
        params: a.map(|a| HashMap::from([("a".to_string(), a)])).unwrap_or_default(),
        limits,
        ..Default::default()
    };
    Scene::parse_with(text, "scaling.toml", "scaling", &opts).map_err(|e| e.to_string())
}

/// Times solving `text` (cold when `vary_a`: a new `a` every run) and meshing its first
/// patch at `side × side`.
fn solve_and_mesh(
    text: &str,
    vary_a: bool,
    side: usize,
    runs: usize,
    threads: usize,
    limits: pdeshape_core::limits::Limits,
) -> Result<(Timing, Timing, usize), String> {
    // one counter for the whole process: no two solves share an `a`, whatever the thread
    // count or study
    static RUN: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    pool(threads)?.install(|| {
        let mut err = None;
        let solve = time(runs, || {
            let k = RUN.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            if let Err(e) = parse(text, vary_a.then_some(1.0 + 1e-9 * k as f64), limits) {
                err = Some(e);
            }
        });
        if let Some(e) = err {
            return Err(e);
        }
        let scene = parse(text, None, limits)?;
        let s = scene.patches[0].surface.clone();
        let opts = GridOptions::new(side, side);
        let m = grid_mesh(s.as_ref(), &opts).map_err(|e| e.to_string())?;
        let mesh = time(runs, || {
            let _ = std::hint::black_box(grid_mesh(s.as_ref(), &opts));
        });
        Ok((solve, mesh, m.bytes()))
    })
}

/// The four-curve patch of `examples/four-curve-patch.toml` with `modes` Fourier modes.
fn four_curve(base: &str, modes: usize) -> String {
    base.replace("kind = \"pde\"", &format!("kind = \"pde\"\nmodes = {modes}"))
}

/// An open tube swept through `count` sections (PDE order `count`).
fn sections(count: usize) -> String {
    format!(
        r#"[parameters]
a = 1.0
[patches.tube]
kind = "pde"
a = "a"
modes = 6
[patches.tube.sections]
count = {count}
spacing = "chebyshev"
s = "pi*i/{last}"
expr = ["(3 + cos(v))*cos(s)", "(3 + cos(v))*sin(s)", "sin(v) + 0.5*s"]
"#,
        last = count - 1
    )
}

/// The 6th-order blend of `examples/blend-torus-hyperboloid.toml` solved by collocation on
/// an `l × 3l` grid (`3l²` rows).
fn collocation(base: &str, l: usize) -> String {
    let head = base.split("[patches.o2]").next().unwrap_or(base);
    format!(
        "{head}\n[patches.o6]\nkind = \"blend\"\norders = [6, 6, 6]\nsolver = \"collocation\"\ncollocation = [{l}, {}]\n\
         start = {{ surface = \"hyperboloid\", s = \"u0\", scale = \"k0\" }}\n\
         end = {{ surface = \"torus\", s = \"u1\", scale = \"k1\" }}\n",
        3 * l
    )
}

/// Runs the four studies. `four_curve_text` and `blend_text` are the example scenes.
pub fn run(
    four_curve_text: &str,
    blend_text: &str,
    o: ScalingOptions,
    mut progress: impl FnMut(&str),
) -> Result<Vec<ScalingRow>, String> {
    let mut rows = Vec::new();
    let base = parse(four_curve_text, None, o.limits)?;
    let surface = base.patches[0].surface.clone();
    for side in [50, 100, 200, 500, 1000, 2000].into_iter().filter(|&s| s <= o.max_side) {
        for threads in [1, 2] {
            progress(&format!("resolution {side}² on {threads} thread(s)"));
            let runs = (o.runs * 40_000 / (side * side)).clamp(3, o.runs.max(3));
            let opts = GridOptions::new(side, side);
            let (mesh, bytes) = pool(threads)?.install(|| {
                let m = grid_mesh(surface.as_ref(), &opts).map_err(|e| e.to_string())?;
                let t = time(runs, || {
                    let _ = std::hint::black_box(grid_mesh(surface.as_ref(), &opts));
                });
                Ok::<_, String>((t, m.bytes()))
            })?;
            rows.push(ScalingRow {
                study: "resolution",
                size: side * side,
                threads,
                solve: None,
                mesh,
                mesh_bytes: bytes,
            });
        }
    }
    for count in [2, 4, 6, 8, 10, 12, 16, 20, 24, 30] {
        for threads in [1, 2] {
            progress(&format!("order {count} on {threads} thread(s)"));
            let runs = if count > 10 { 3 } else { o.runs.min(7) };
            let (solve, mesh, bytes) = solve_and_mesh(&sections(count), true, 100, runs, threads, o.limits)?;
            rows.push(ScalingRow { study: "order", size: count, threads, solve: Some(solve), mesh, mesh_bytes: bytes });
        }
    }
    for modes in [2, 4, 8, 16, 32, 64, 128, 256] {
        for threads in [1, 2] {
            progress(&format!("modes {modes} on {threads} thread(s)"));
            let runs = o.runs.min(7);
            let (solve, mesh, bytes) =
                solve_and_mesh(&four_curve(four_curve_text, modes), true, 100, runs, threads, o.limits)?;
            rows.push(ScalingRow { study: "modes", size: modes, threads, solve: Some(solve), mesh, mesh_bytes: bytes });
        }
    }
    for l in [8, 16, 32, 64, 128] {
        for threads in [1, 2] {
            progress(&format!("collocation {l} × {} on {threads} thread(s)", 3 * l));
            let runs = if l >= 64 { 3 } else { o.runs.min(7) };
            let (solve, mesh, bytes) =
                solve_and_mesh(&collocation(blend_text, l), false, 100, runs, threads, o.limits)?;
            let size = 3 * l * l;
            rows.push(ScalingRow { study: "collocation", size, threads, solve: Some(solve), mesh, mesh_bytes: bytes });
        }
    }
    Ok(rows)
}

/// Least-squares slope of `log t` against `log size` over the rows of one study and thread
/// count with `size ≥ from`: 1 means linear scaling.
pub fn loglog_slope(rows: &[ScalingRow], study: &str, threads: usize, from: usize, solve: bool) -> Option<f64> {
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.study == study && r.threads == threads && r.size >= from)
        .filter_map(|r| {
            let t = if solve { r.solve?.median_ms } else { r.mesh.median_ms };
            Some(((r.size as f64).ln(), t.ln()))
        })
        .collect();
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// The study as Markdown tables.
pub fn markdown(rows: &[ScalingRow]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let ms = |t: &Option<Timing>| t.map(|t| format!("{:.3}", t.median_ms)).unwrap_or_else(|| "—".into());
    let heads = [
        ("resolution", "vertices", "mesh (ms)"),
        ("order", "order 2N", "mesh 100 × 100 (ms)"),
        ("modes", "modes M", "mesh 100 × 100 (ms)"),
        ("collocation", "collocation rows", "mesh 100 × 100 (ms)"),
    ];
    for (study, size, mesh) in heads {
        let _ = writeln!(s, "\n### {study}\n");
        let _ = writeln!(
            s,
            "| {size} | solve, 1 thread (ms) | solve, 2 threads (ms) | {mesh}, 1 thread | {mesh}, 2 threads | mesh bytes |"
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|");
        let sizes: Vec<usize> = {
            let mut v: Vec<usize> = rows.iter().filter(|r| r.study == study).map(|r| r.size).collect();
            v.dedup();
            v
        };
        for z in sizes {
            let get = |t: usize| rows.iter().find(|r| r.study == study && r.size == z && r.threads == t);
            let (Some(a), Some(b)) = (get(1), get(2)) else { continue };
            let _ = writeln!(
                s,
                "| {z} | {} | {} | {:.3} | {:.3} | {} |",
                ms(&a.solve),
                ms(&b.solve),
                a.mesh.median_ms,
                b.mesh.median_ms,
                a.mesh_bytes
            );
        }
    }
    for t in [1, 2] {
        if let Some(k) = loglog_slope(rows, "resolution", t, 40_000, false) {
            let _ = writeln!(s, "\nMeshing time ∝ vertices^{k:.3} from 200² up ({t} thread(s)); 1 is linear.");
        }
    }
    s
}

/// The study as four log-scale plots: `(file stem, picture)`.
pub fn plots(rows: &[ScalingRow]) -> Result<Vec<(String, Image)>, String> {
    let series = |study: &str, solve: bool, x: &dyn Fn(usize) -> f64| -> Vec<Series> {
        [1, 2]
            .into_iter()
            .map(|t| Series {
                label: format!("{} thread{}", t, if t > 1 { "s" } else { "" }),
                points: rows
                    .iter()
                    .filter(|r| r.study == study && r.threads == t)
                    .filter_map(|r| Some((x(r.size), if solve { r.solve?.median_ms } else { r.mesh.median_ms })))
                    .collect(),
            })
            .collect()
    };
    let size = (640, 400);
    let log10 = |z: usize| (z as f64).log10();
    let ident = |z: usize| z as f64;
    // a line of slope 1 through the largest one-thread point: linear scaling
    let mut res = series("resolution", false, &log10);
    if let Some(&(x1, y1)) = res[0].points.last() {
        let linear = res[0].points.iter().map(|&(x, _)| (x, y1 * 10f64.powf(x - x1))).collect();
        res.push(Series { label: "slope 1 (linear)".into(), points: linear });
    }
    Ok(vec![
        (
            "scaling-resolution".into(),
            line_plot(
                "Meshing the four-curve patch (values + exact normals)",
                "log10 vertices",
                "ms",
                &res,
                true,
                size,
            )?,
        ),
        (
            "scaling-order".into(),
            line_plot(
                "Solving a PDE patch through 2N sections",
                "order 2N",
                "ms",
                &series("order", true, &ident),
                true,
                size,
            )?,
        ),
        (
            "scaling-modes".into(),
            line_plot(
                "Solving the four-curve patch with M modes",
                "log10 M",
                "ms",
                &series("modes", true, &log10),
                true,
                size,
            )?,
        ),
        (
            "scaling-collocation".into(),
            line_plot(
                "Solving a 6th-order blend by collocation",
                "log10 collocation rows",
                "ms",
                &series("collocation", true, &log10),
                true,
                size,
            )?,
        ),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(size: usize, ms: f64) -> ScalingRow {
        let t = Timing { median_ms: ms, min_ms: ms, max_ms: ms, runs: 1 };
        ScalingRow { study: "resolution", size, threads: 1, solve: None, mesh: t, mesh_bytes: 0 }
    }

    #[test]
    fn slope_of_a_power_law_is_its_exponent() {
        let rows: Vec<ScalingRow> = [100, 1000, 10_000, 100_000].iter().map(|&n| row(n, 3e-4 * n as f64)).collect();
        assert!((loglog_slope(&rows, "resolution", 1, 0, false).unwrap() - 1.0).abs() < 1e-12);
        let rows: Vec<ScalingRow> = [100, 1000, 10_000].iter().map(|&n| row(n, (n as f64).powf(1.5))).collect();
        assert!((loglog_slope(&rows, "resolution", 1, 0, false).unwrap() - 1.5).abs() < 1e-12);
        assert_eq!(loglog_slope(&rows, "resolution", 2, 0, false), None);
        assert!(markdown(&rows).contains("### resolution"));
    }

    #[test]
    fn study_scenes_parse() {
        let four = include_str!("../../../examples/four-curve-patch.toml");
        let blend = include_str!("../../../examples/blend-torus-hyperboloid.toml");
        let s = parse(&four_curve(four, 3), Some(1.2), Default::default()).unwrap();
        assert_eq!(s.patches[0].spectral.as_ref().unwrap().options().modes, 3);
        let s = parse(&sections(6), Some(1.0), Default::default()).unwrap();
        assert_eq!(s.patches[0].conditions.len(), 6);
        let s = parse(&collocation(blend, 8), None, Default::default()).unwrap();
        assert_eq!(s.patches.len(), 1);
    }
}
