//! The structured `(ρ, φ)` grid of a trimmed region: fold detection and repair, quality
//! figures, and the trimmed surface mesh.

use super::TrimError;
use super::curve::{Uv, cross, sub};
use super::laplace::LaplaceMap;
use crate::Vec3;
use crate::mesh::Mesh;
use crate::patch::Surface;
use rayon::prelude::*;

/// Options for [`trim_grid`].
#[derive(Clone, Debug, PartialEq)]
pub struct TrimOptions {
    /// Rings `ρ_i` (≥ 2): ring 0 is the trim loop, the last one the domain border.
    pub rings: usize,
    /// Columns `φ_j` around (≥ 8).
    pub columns: usize,
    /// Fourier modes `N` of the Laplace map.
    pub modes: usize,
    /// Winslow sweeps allowed to repair folds.
    pub max_sweeps: usize,
    /// Count grid vertices inside trim curves (point-in-polygon on the fine
    /// polygonisation) and compute the angle and area figures of the report; both cost more
    /// than the meshing itself.
    pub verify: bool,
}

impl Default for TrimOptions {
    fn default() -> Self {
        TrimOptions { rings: 20, columns: 64, modes: 12, max_sweeps: 4000, verify: true }
    }
}

/// Quality figures of a trimmed grid (all in the parameter domain).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrimReport {
    /// Rings × columns.
    pub rings: usize,
    /// Columns.
    pub columns: usize,
    /// Fourier modes and remainder rate of the map.
    pub modes: usize,
    /// `ω`.
    pub omega: f64,
    /// Folded cells ([`is_folded`]) in the Laplace map's grid.
    pub folds_before: usize,
    /// The same after repair (0 on success).
    pub folds_after: usize,
    /// Interior vertices inside a trim curve or outside the domain, before repair
    /// (counted when `verify`).
    pub inside_before: usize,
    /// The same after repair.
    pub inside_after: usize,
    /// Winslow sweeps used.
    pub sweeps: usize,
    /// Smallest and largest corner angle of any cell, degrees.
    pub min_angle: f64,
    /// Largest corner angle.
    pub max_angle: f64,
    /// Σ |cell area| / exact region area.
    pub area_ratio: f64,
    /// Largest / smallest cell area.
    pub cell_area_ratio: f64,
}

/// A trimmed region's structured grid: `rings × columns` points, row-major in `ρ`, with
/// `φ` periodic (cells wrap around).
#[derive(Clone, Debug)]
pub struct TrimGrid {
    /// Rings.
    pub rings: usize,
    /// Columns.
    pub columns: usize,
    /// Points `(u, v)`.
    pub points: Vec<Uv>,
    /// Quality report.
    pub report: TrimReport,
}

impl TrimGrid {
    /// Index of `(i, j)` with `j` wrapped.
    pub fn index(&self, i: usize, j: usize) -> usize {
        i * self.columns + j % self.columns
    }
}

/// The four corner Jacobians of cell `(i, j)`: corners `P₀₀ = (i, j)`, `P₁₀ = (i + 1, j)`,
/// `P₁₁`, `P₀₁`; all positive for a cell that is not folded.
fn corner_jacobians(p: &[Uv], cols: usize, i: usize, j: usize) -> [f64; 4] {
    let at = |a: usize, b: usize| p[a * cols + (b % cols)];
    let (p00, p10, p11, p01) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
    [
        cross(sub(p10, p00), sub(p01, p00)),
        cross(sub(p11, p10), sub(p00, p10)),
        cross(sub(p01, p11), sub(p10, p11)),
        cross(sub(p00, p01), sub(p11, p01)),
    ]
}

/// True when cell `(i, j)` is folded: inverted or self-overlapping. A cell is valid when it
/// is a simple, positively oriented quadrilateral: positive signed area and at most one
/// corner with a non-positive Jacobian (a reflex corner, as where the region has a
/// re-entrant corner; such a cell is split into triangles through that corner).
pub fn is_folded(p: &[Uv], cols: usize, i: usize, j: usize) -> bool {
    let jac = corner_jacobians(p, cols, i, j);
    let bad = jac.iter().filter(|&&d| d <= 0.0).count();
    bad > 1 || jac.iter().sum::<f64>() <= 0.0
}

/// The reflex corner (0 … 3, in the order `P₀₀, P₁₀, P₁₁, P₀₁`) of a valid cell, if any.
pub fn reflex_corner(p: &[Uv], cols: usize, i: usize, j: usize) -> Option<usize> {
    corner_jacobians(p, cols, i, j).iter().position(|&d| d <= 0.0)
}

/// Number of folded cells ([`is_folded`]).
pub fn count_folds(p: &[Uv], rings: usize, cols: usize) -> usize {
    (0..rings - 1).into_par_iter().map(|i| (0..cols).filter(|&j| is_folded(p, cols, i, j)).count()).sum()
}

fn count_inside(map: &LaplaceMap, p: &[Uv], rings: usize, cols: usize) -> usize {
    let r = map.region();
    let dom = r.domain;
    p[cols..(rings - 1) * cols]
        .par_iter()
        .filter(|q| {
            q[0] < dom.min[0] || q[0] > dom.max[0] || q[1] < dom.min[1] || q[1] > dom.max[1] || r.in_hole(**q, 0.0)
        })
        .count()
}

/// One Gauss–Seidel sweep of Winslow's equations `α x_ξξ − 2β x_ξη + γ x_ηη = 0` over the
/// interior rings (ξ = ring, η = column, periodic), with the boundary rings fixed.
/// Returns the largest move.
fn winslow_sweep(p: &mut [Uv], rings: usize, cols: usize) -> f64 {
    let mut moved: f64 = 0.0;
    for i in 1..rings - 1 {
        for j in 0..cols {
            let at = |p: &[Uv], a: usize, b: usize| p[a * cols + (b + cols) % cols];
            let (e, w) = (at(p, i + 1, j), at(p, i - 1, j));
            let (n, s) = (at(p, i, j + 1), at(p, i, j + cols - 1));
            let (ne, nw) = (at(p, i + 1, j + 1), at(p, i - 1, j + 1));
            let (se, sw) = (at(p, i + 1, j + cols - 1), at(p, i - 1, j + cols - 1));
            let x_xi = [(e[0] - w[0]) / 2.0, (e[1] - w[1]) / 2.0];
            let x_eta = [(n[0] - s[0]) / 2.0, (n[1] - s[1]) / 2.0];
            let alpha = x_eta[0] * x_eta[0] + x_eta[1] * x_eta[1];
            let beta = x_xi[0] * x_eta[0] + x_xi[1] * x_eta[1];
            let gamma = x_xi[0] * x_xi[0] + x_xi[1] * x_xi[1];
            let den = 2.0 * (alpha + gamma);
            if den <= 0.0 {
                continue;
            }
            let k = i * cols + j;
            let old = p[k];
            let mut new = [0.0; 2];
            for d in 0..2 {
                let mixed = ne[d] - se[d] - nw[d] + sw[d];
                new[d] = (alpha * (e[d] + w[d]) + gamma * (n[d] + s[d]) - 0.5 * beta * mixed) / den;
            }
            moved = moved.max((new[0] - old[0]).abs().max((new[1] - old[1]).abs()));
            p[k] = new;
        }
    }
    moved
}

/// Meshes the trimmed region: the Laplace map on the `(ρ, φ)` grid, then, if any cell is
/// folded (or, with `verify`, any interior vertex lies in a hole), Winslow smoothing of
/// the interior rings until none is. The boundary rings are never moved, so ring 0 stays
/// exactly on the trim loop and the last ring on the border.
pub fn trim_grid(map: &LaplaceMap, o: &TrimOptions) -> Result<TrimGrid, TrimError> {
    if o.rings < 2 || o.columns < 8 {
        return Err(TrimError::Resolution { rings: o.rings, columns: o.columns });
    }
    let (rings, cols) = (o.rings, o.columns);
    let mut p = map.grid(rings, cols);
    let folds_before = count_folds(&p, rings, cols);
    let inside_before = if o.verify || folds_before > 0 { count_inside(map, &p, rings, cols) } else { 0 };
    let mut folds = folds_before;
    let mut inside = inside_before;
    let mut sweeps = 0;
    while (folds > 0 || inside > 0) && sweeps < o.max_sweeps {
        for _ in 0..10 {
            crate::cancel::checkpoint();
            winslow_sweep(&mut p, rings, cols);
        }
        sweeps += 10;
        folds = count_folds(&p, rings, cols);
        inside = if folds == 0 { count_inside(map, &p, rings, cols) } else { inside.max(1) };
    }
    if folds > 0 || inside > 0 {
        // while folds remained, `inside` was not recounted: count it for the error
        let inside = if folds > 0 { count_inside(map, &p, rings, cols) } else { inside };
        return Err(TrimError::CannotRepair { folds, inside, sweeps });
    }
    let mut report = if o.verify {
        quality(map, &p, rings, cols)
    } else {
        TrimReport { rings, columns: cols, modes: map.modes(), omega: map.omega(), ..Default::default() }
    };
    report.folds_before = folds_before;
    report.inside_before = inside_before;
    report.sweeps = sweeps;
    Ok(TrimGrid { rings, columns: cols, points: p, report })
}

fn quality(map: &LaplaceMap, p: &[Uv], rings: usize, cols: usize) -> TrimReport {
    let (mut amin, mut amax) = (f64::INFINITY, 0.0f64);
    let (mut cmin, mut cmax, mut total) = (f64::INFINITY, 0.0f64, 0.0);
    let at = |a: usize, b: usize| p[a * cols + (b % cols)];
    for i in 0..rings - 1 {
        for j in 0..cols {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let area = 0.5 * (cross(sub(q[2], q[0]), sub(q[3], q[1]))).abs();
            total += area;
            cmin = cmin.min(area);
            cmax = cmax.max(area);
            for k in 0..4 {
                let (a, b, c) = (q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
                let (x, y) = (sub(a, b), sub(c, b));
                let ang = cross(y, x).atan2(x[0] * y[0] + x[1] * y[1]).abs().to_degrees();
                if x != [0.0, 0.0] && y != [0.0, 0.0] {
                    amin = amin.min(ang);
                    amax = amax.max(ang);
                }
            }
        }
    }
    TrimReport {
        rings,
        columns: cols,
        modes: map.modes(),
        omega: map.omega(),
        min_angle: amin,
        max_angle: amax,
        area_ratio: total / map.region().area,
        cell_area_ratio: if cmin > 0.0 { cmax / cmin } else { f64::INFINITY },
        ..Default::default()
    }
}

/// The trimmed patch: the grid mapped by the patch, with exact normals `X_u × X_v`, UVs (the
/// patch parameters scaled to `[0, 1]`) and the trim loop drawn as a highlighted curve.
/// Quads are counter-clockwise about the normal (the grid is positively oriented in
/// `(u, v)`).
pub fn trimmed_mesh(s: &dyn Surface, g: &TrimGrid) -> Result<Mesh, String> {
    let dom = s.v_domain();
    let evals: Vec<[Vec3; 3]> = g
        .points
        .par_iter()
        .map(|q| {
            let d = s.derivatives(q[0], q[1], 1, 1);
            [d[0], d[2], d[1]]
        })
        .collect();
    let mut positions = Vec::with_capacity(evals.len());
    let mut normals = Vec::with_capacity(evals.len());
    for (k, [p, pu, pv]) in evals.iter().enumerate() {
        if !p.is_finite() {
            let q = g.points[k];
            return Err(format!("the patch is not finite at (u, v) = ({}, {})", q[0], q[1]));
        }
        positions.push(*p);
        normals.push(pu.cross(*pv).normalized().unwrap_or(Vec3::ZERO));
    }
    // vertices where X_u × X_v vanishes (poles) take their neighbours' normals
    for k in 0..normals.len() {
        if normals[k] == Vec3::ZERO {
            let (i, j) = (k / g.columns, k % g.columns);
            let mut acc = Vec3::ZERO;
            for (a, b) in [(i.saturating_sub(1), j), ((i + 1).min(g.rings - 1), j), (i, j + 1), (i, j + g.columns - 1)]
            {
                acc += normals[g.index(a, b)];
            }
            normals[k] = acc.normalized().unwrap_or(Vec3::new(0.0, 0.0, 1.0));
        }
    }
    let uvs = g.points.iter().map(|q| [q[0], (q[1] - dom.start) / (dom.end - dom.start)]).collect();
    let mut quads = Vec::with_capacity((g.rings - 1) * g.columns);
    let mut triangles = Vec::new();
    for i in 0..g.rings - 1 {
        for j in 0..g.columns {
            let q = [g.index(i, j), g.index(i + 1, j), g.index(i + 1, j + 1), g.index(i, j + 1)].map(|x| x as u32);
            match reflex_corner(&g.points, g.columns, i, j) {
                None => quads.push(q),
                Some(k) => {
                    triangles.push([q[k], q[(k + 1) % 4], q[(k + 2) % 4]]);
                    triangles.push([q[k], q[(k + 2) % 4], q[(k + 3) % 4]]);
                }
            }
        }
    }
    let mut ring0: Vec<Vec3> = (0..g.columns).map(|j| positions[j]).collect();
    ring0.push(positions[0]);
    Ok(Mesh { positions, normals, uvs, quads, triangles, curves: vec![ring0], ..Default::default() })
}
