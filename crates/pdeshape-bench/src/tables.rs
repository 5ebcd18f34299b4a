//! Reproductions of the papers' timing and accuracy tables (`pdeshape bench`).
//!
//! Timings are medians (with min–max) of repeated runs on one rayon thread, so that they
//! compare with SPEC §10's one-core targets; deviations are max distances over a 100 × 100
//! grid of `(u, v)`.

use pdeshape_core::blend::{DynamicBlend, DynamicOptions, Solver};
use pdeshape_core::mesh::{GridOptions, grid_mesh};
use pdeshape_core::patch::Surface;
use pdeshape_io::scene::{DynamicSetup, Scene, ScenePatch};
use serde::Serialize;
use std::time::Instant;

/// Median, minimum and maximum of a timing in milliseconds.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Timing {
    /// Median (ms).
    pub median_ms: f64,
    /// Fastest run (ms).
    pub min_ms: f64,
    /// Slowest run (ms).
    pub max_ms: f64,
    /// Number of runs.
    pub runs: usize,
}

/// Times `f` over `runs` runs (after one warm-up run).
pub fn time(runs: usize, mut f: impl FnMut()) -> Timing {
    f();
    let mut v: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    v.sort_by(f64::total_cmp);
    Timing { median_ms: v[v.len() / 2], min_ms: v[0], max_ms: v[v.len() - 1], runs: v.len() }
}

/// One row of paper 002's Table 1.
#[derive(Clone, Debug, Serialize)]
pub struct Table1Row {
    /// `"closed form"`, `"K = 5"`, `"K = 10"`.
    pub method: String,
    /// The paper's time in seconds (1.66 GHz laptop).
    pub paper_seconds: f64,
    /// Ours: solve and evaluate 100 × 100 points with normals.
    pub ours: Timing,
    /// Max |S − S_closed form| over 100 × 100 at t = 0.
    pub max_deviation: f64,
}

/// One entry of the accuracy study.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyRow {
    /// Time.
    pub t: f64,
    /// Sine terms.
    pub k: usize,
    /// Collocation grid (L = M).
    pub grid: usize,
    /// `"per-j"` or `"joint"`.
    pub fit: &'static str,
    /// Max |S − S_closed form| over 100 × 100.
    pub max_deviation: f64,
}

fn dynamic_patch(scene: &Scene) -> Result<(&ScenePatch, &DynamicSetup), String> {
    scene
        .patches
        .iter()
        .find_map(|p| p.dynamic.as_ref().map(|d| (p, d)))
        .ok_or_else(|| format!("scene `{}` has no dynamic patch", scene.name))
}

fn blend_with(
    p: &ScenePatch,
    d: &DynamicSetup,
    solver: Solver,
    k: usize,
    grid: usize,
    joint: bool,
) -> Result<DynamicBlend, String> {
    let o = DynamicOptions { solver, terms: k, collocation: (grid, grid), joint, times: d.times, ..Default::default() };
    DynamicBlend::new(d.blend.operator(), &p.conditions, p.surface.v_domain(), &o).map_err(|e| e.to_string())
}

fn max_distance(a: &dyn Surface, b: &dyn Surface) -> f64 {
    let dom = a.v_domain();
    let mut worst: f64 = 0.0;
    for i in 0..100 {
        for j in 0..100 {
            let (u, v) = (i as f64 / 99.0, dom.at(j as f64 / 99.0));
            worst = pdeshape_core::num::max_nan(worst, (a.point(u, v) - b.point(u, v)).norm());
        }
    }
    worst
}

/// Paper 002 Table 1 on the scene's dynamic patch (eq. 19): closed form, K = 5 and K = 10
/// on the paper's 11 × 11 collocation grid, each solved and evaluated at 100 × 100 points
/// with normals at t = 0.
pub fn dynamic_table1(scene: &Scene, runs: usize) -> Result<Vec<Table1Row>, String> {
    let (p, d) = dynamic_patch(scene)?;
    let exact = blend_with(p, d, Solver::Exact, 5, 11, false)?.frame(0.0).map_err(|e| e.to_string())?;
    let mut rows = Vec::new();
    for (method, paper, solver, k) in [
        ("closed form", 0.597, Solver::Exact, 5),
        ("K = 5", 0.077, Solver::Collocation, 5),
        ("K = 10", 0.111, Solver::Collocation, 10),
    ] {
        let mut err = None;
        let ours = time(runs, || {
            let r = blend_with(p, d, solver, k, 11, false)
                .and_then(|b| b.frame(0.0).map_err(|e| e.to_string()))
                .and_then(|f| grid_mesh(&f, &GridOptions::new(100, 100)));
            if let Err(e) = r {
                err = Some(e);
            }
        });
        if let Some(e) = err {
            return Err(e);
        }
        let f = blend_with(p, d, solver, k, 11, false)?.frame(0.0).map_err(|e| e.to_string())?;
        rows.push(Table1Row {
            method: method.into(),
            paper_seconds: paper,
            ours,
            max_deviation: max_distance(&f, &exact),
        });
    }
    Ok(rows)
}

/// Max |S_collocation − S_closed form| over 100 × 100 for t ∈ {0, 0.1, 0.2, 0.3},
/// K ∈ {5, 7, 10}, on the paper's 11 × 11 grid and a 41 × 41 grid, per `j` and jointly.
pub fn dynamic_accuracy(scene: &Scene) -> Result<Vec<AccuracyRow>, String> {
    let (p, d) = dynamic_patch(scene)?;
    let exact = blend_with(p, d, Solver::Exact, 5, 11, false)?;
    let mut rows = Vec::new();
    for t in [0.0, 0.1, 0.2, 0.3] {
        let fe = exact.frame(t).map_err(|e| e.to_string())?;
        for grid in [11, 41] {
            for k in [5, 7, 10] {
                for (fit, joint) in [("per-j", false), ("joint", true)] {
                    let f =
                        blend_with(p, d, Solver::Collocation, k, grid, joint)?.frame(t).map_err(|e| e.to_string())?;
                    rows.push(AccuracyRow { t, k, grid, fit, max_deviation: max_distance(&f, &fe) });
                }
            }
        }
    }
    Ok(rows)
}

/// Runs `f` on a one-thread rayon pool (SPEC §10's targets are per core).
pub fn on_one_thread<T: Send>(f: impl FnOnce() -> T + Send) -> Result<T, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().map_err(|e| e.to_string())?;
    Ok(pool.install(f))
}

/// One row of paper 003's Table 1: meshing the region outside the Fig. 3 trim.
#[derive(Clone, Debug, Serialize)]
pub struct TrimTableRow {
    /// `(rings, columns)`: the paper's "mesh (u, v)".
    pub mesh: (usize, usize),
    /// Vertices of both meshes.
    pub vertices: usize,
    /// The paper's Laplace time (ms).
    pub paper_laplace_ms: f64,
    /// The paper's Delaunay time (ms).
    pub paper_delaunay_ms: f64,
    /// Ours: Laplace map solve + grid + fold check, in the parameter domain.
    pub laplace: Timing,
    /// `spade`'s constrained Delaunay triangulation of the same vertices, with the trim
    /// loop and the border as constraint edges.
    pub delaunay: Timing,
    /// Triangles of the Delaunay mesh that lie inside the trim (they must be removed after
    /// the triangulation; counted, not timed).
    pub delaunay_inside: usize,
}

/// Paper 003 Table 1 on the trim of `scene`'s first trimmed patch (the Fig. 3 circle):
/// for each resolution, the Laplace meshing and a constrained Delaunay triangulation of the
/// same points, medians of `runs` runs.
pub fn trim_table1(scene: &Scene, runs: usize) -> Result<Vec<TrimTableRow>, String> {
    use pdeshape_core::trim::{LaplaceMap, TrimOptions, trim_grid};
    use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
    let t = scene
        .patches
        .iter()
        .find_map(|p| p.trim.as_ref())
        .ok_or_else(|| format!("scene `{}` has no trimmed patch", scene.name))?;
    let region = t.map.region().clone();
    let modes = t.map.modes();
    let mut rows = Vec::new();
    for ((rings, columns), paper_l, paper_d) in [
        ((10, 20), 0.0313333, 0.1391),
        ((20, 30), 0.1561, 0.3333),
        ((40, 70), 0.3912, 0.89),
        ((140, 170), 4.2265, 7.10128),
    ] {
        let o = TrimOptions { rings, columns, modes, verify: false, ..Default::default() };
        let mut err = None;
        let laplace = time(runs, || {
            let map = LaplaceMap::new(region.clone(), modes, Some(columns));
            if let Err(e) = trim_grid(&map, &o) {
                err = Some(e.to_string());
            }
        });
        if let Some(e) = err {
            return Err(e);
        }
        let grid = trim_grid(&LaplaceMap::new(region.clone(), modes, Some(columns)), &o).map_err(|e| e.to_string())?;
        let pts: Vec<Point2<f64>> = grid.points.iter().map(|p| Point2::new(p[0], p[1])).collect();
        // constraint edges: ring 0 (the trim loop) and the last ring (the border)
        let mut edges = Vec::new();
        for ring in [0, rings - 1] {
            for j in 0..columns {
                edges.push([grid.index(ring, j), grid.index(ring, j + 1)]);
            }
        }
        let mut cdt_err = None;
        let delaunay = time(runs, || {
            match ConstrainedDelaunayTriangulation::<Point2<f64>>::bulk_load_cdt(pts.clone(), edges.clone()) {
                Ok(c) => {
                    std::hint::black_box(c.num_inner_faces());
                }
                Err(e) => cdt_err = Some(format!("{e:?}")),
            }
        });
        if let Some(e) = cdt_err {
            return Err(format!("spade: {e}"));
        }
        let cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::bulk_load_cdt(pts.clone(), edges.clone())
            .map_err(|e| format!("spade: {e:?}"))?;
        let delaunay_inside = cdt
            .inner_faces()
            .filter(|f| {
                let c = f.center();
                region.in_hole([c.x, c.y], 0.0)
            })
            .count();
        rows.push(TrimTableRow {
            mesh: (rings, columns),
            vertices: pts.len(),
            paper_laplace_ms: paper_l,
            paper_delaunay_ms: paper_d,
            laplace,
            delaunay,
            delaunay_inside,
        });
    }
    Ok(rows)
}
