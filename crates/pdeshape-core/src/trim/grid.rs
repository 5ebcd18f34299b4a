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
    /// Vertex moves of the local untangling that followed when Winslow's fixed point was
    /// still folded (0 when Winslow alone repaired the grid).
    pub untangle_moves: usize,
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
            moved = crate::num::max_nan(moved, crate::num::max_nan((new[0] - old[0]).abs(), (new[1] - old[1]).abs()));
            p[k] = new;
        }
    }
    moved
}

/// Winslow sweeps in blocks of ten while cells are folded or vertices inside trims, up to
/// `limit` sweeps in all or until the fold count has not dropped for `stall` sweeps.
/// Returns the folds and inside vertices left (`inside` is only recounted once no cell is
/// folded).
fn smooth(
    map: &LaplaceMap,
    p: &mut [Uv],
    (rings, cols): (usize, usize),
    (mut folds, mut inside): (usize, usize),
    sweeps: &mut usize,
    limit: usize,
    stall: usize,
) -> (usize, usize) {
    let (mut fewest, mut stalled) = (folds, 0);
    while (folds > 0 || inside > 0) && *sweeps < limit && stalled < stall {
        for _ in 0..10 {
            crate::cancel::checkpoint();
            winslow_sweep(p, rings, cols);
        }
        *sweeps += 10;
        folds = count_folds(p, rings, cols);
        inside = if folds == 0 { count_inside(map, p, rings, cols) } else { inside.max(1) };
        if folds > 0 && folds >= fewest {
            stalled += 10;
        } else {
            (fewest, stalled) = (folds.min(fewest), 0);
        }
    }
    (folds, inside)
}

/// Local untangling of the folded cells (after Freitag & Plassmann, "Local
/// optimization-based untangling algorithms for quadrilateral meshes", 2001).
///
/// Every corner Jacobian of a cell is the doubled signed area of a triangle of its
/// corners, `J = (b − a) × (c − a)`, so with all other vertices fixed it is an affine
/// function of any one free vertex `x`: written with `x` first in the cyclic order,
/// `J(x) = (b − x) × (c − x)` has gradient `(b_y − c_y, c_x − b_x)`. Moving `x` to maximise
/// the smallest Jacobian of the cells around it is then a linear programme in `(x, t)`
/// whose optimum is a vertex where three of the affine functions are equal; the functions
/// are few (≤ 12 corners and 4 box walls), so the vertices are enumerated. The box walls —
/// the distances to the bounding box of the eight neighbours, scaled to Jacobian units —
/// keep the programme bounded. A corner at a ring-0 vertex where the region is reflex
/// (the loop turns towards the hole) may stay non-positive, as [`is_folded`] allows; the
/// cell's signed area (the sum of its corners) must stay positive instead.
///
/// Passes sweep the free vertices of the folded cells until none is folded or a pass
/// moves nothing. Returns the number of moves.
fn untangle(p: &mut [Uv], rings: usize, cols: usize) -> usize {
    if rings < 3 {
        return 0;
    }
    let at = |p: &[Uv], a: usize, b: usize| p[a * cols + (b + cols) % cols];
    // the region turns reflex at ring-0 vertex j when the loop turns left there (the
    // region lies to the right of a positively oriented grid's ring 0); vertices on a
    // straight edge turn by round-off only, so the sine of the turn must exceed 1e-6
    let reflex: Vec<Option<Uv>> = (0..cols)
        .map(|j| {
            let (a, b) = (sub(at(p, 0, j), at(p, 0, j + cols - 1)), sub(at(p, 0, j + 1), at(p, 0, j)));
            let (la, lb) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
            // the outward bisector: away from both loop neighbours
            let n = [a[0] / la - b[0] / lb, a[1] / la - b[1] / lb];
            let ln = n[0].hypot(n[1]);
            (cross(a, b) > 1e-6 * la * lb && ln > 0.0).then(|| [n[0] / ln, n[1] / ln])
        })
        .collect();
    let mut moves = 0;
    for _pass in 0..64 {
        // first the free vertices at the folded cells' inverted corners, then the other free
        // vertices of those corners' triangles (moving a valid vertex before the inverted
        // one drags it towards where the inverted one is)
        let mut first: Vec<(usize, usize)> = Vec::new();
        let mut then: Vec<(usize, usize)> = Vec::new();
        for i in 0..rings - 1 {
            for j in 0..cols {
                if !is_folded(p, cols, i, j) {
                    continue;
                }
                let q = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)].map(|(a, b)| (a, b % cols));
                for (k, jac) in corner_jacobians(p, cols, i, j).into_iter().enumerate() {
                    if jac > 0.0 || (q[k].0 == 0 && reflex[q[k].1].is_some()) {
                        continue;
                    }
                    first.push(q[k]);
                    then.extend([q[(k + 1) % 4], q[(k + 3) % 4]]);
                }
            }
        }
        let mut free: Vec<(usize, usize)> = Vec::new();
        for v in first.into_iter().chain(then) {
            if v.0 > 0 && v.0 < rings - 1 && !free.contains(&v) {
                free.push(v);
            }
        }
        if free.is_empty() {
            break;
        }
        let mut moved = false;
        for (i, j) in free {
            if let Some(x) = best_position(p, cols, &reflex, i, j) {
                p[i * cols + j] = x;
                moved = true;
                moves += 1;
            }
        }
        if !moved {
            break;
        }
    }
    moves
}

/// The position of free vertex `(i, j)` that maximises the smallest constrained Jacobian
/// of its four cells ([`untangle`]), or `None` when no position beats the current one.
fn best_position(p: &[Uv], cols: usize, reflex: &[Option<Uv>], i: usize, j: usize) -> Option<Uv> {
    let x0 = p[i * cols + j];
    let at = |a: usize, b: usize| p[a * cols + (b + cols) % cols];
    // affine functions f(d) = g·d + c of the displacement d = x − x0
    let mut f: Vec<(Uv, f64)> = Vec::with_capacity(16);
    for (ci, cj, m) in [(i - 1, j + cols - 1, 2), (i - 1, j, 1), (i, j + cols - 1, 3), (i, j, 0)] {
        // corners P00, P10, P11, P01 of cell (ci, cj); x is corner m
        let q = [(ci, cj), (ci + 1, cj), (ci + 1, cj + 1), (ci, cj + 1)];
        let mut sum: (Uv, f64) = ([0.0, 0.0], 0.0);
        let mut allowed = false;
        for k in 0..4 {
            let tri = [k, (k + 1) % 4, (k + 3) % 4];
            let Some(r) = tri.iter().position(|&t| t == m) else {
                let (a, b, c) = (at(q[k].0, q[k].1), at(q[tri[1]].0, q[tri[1]].1), at(q[tri[2]].0, q[tri[2]].1));
                sum.1 += cross(sub(b, a), sub(c, a));
                continue;
            };
            // x first in the cyclic order (x, b, c)
            let (b, c) =
                (at(q[tri[(r + 1) % 3]].0, q[tri[(r + 1) % 3]].1), at(q[tri[(r + 2) % 3]].0, q[tri[(r + 2) % 3]].1));
            let g = [b[1] - c[1], c[0] - b[0]];
            let v = cross(sub(b, x0), sub(c, x0));
            sum = ([sum.0[0] + g[0], sum.0[1] + g[1]], sum.1 + v);
            if q[k].0 == 0 && reflex[q[k].1 % cols].is_some() {
                allowed = true;
            } else {
                f.push((g, v));
            }
        }
        if allowed {
            f.push(sum);
        }
    }
    // box walls of the eight neighbours, in Jacobian units
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for a in i - 1..=i + 1 {
        for b in [j + cols - 1, j, j + 1] {
            if (a, b % cols) != (i, j) {
                let q = at(a, b);
                for d in 0..2 {
                    lo[d] = lo[d].min(q[d] - x0[d]);
                    hi[d] = hi[d].max(q[d] - x0[d]);
                }
            }
        }
    }
    let scale = f.iter().map(|(g, _)| g[0].abs() + g[1].abs()).fold(0.0, crate::num::max_nan);
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    f.push(([scale, 0.0], -scale * lo[0]));
    f.push(([-scale, 0.0], scale * hi[0]));
    f.push(([0.0, scale], -scale * lo[1]));
    f.push(([0.0, -scale], scale * hi[1]));
    // beside a reflex loop vertex T the two corners at T share the region's angle (< 360°),
    // so at most one of them is reflex — provided x stays on the outer side of the
    // half-plane through T normal to the outward bisector n (else both corners can turn
    // negative with the vertex inside the hole): (x − T)·n ≥ t, in Jacobian units
    if i == 1
        && let Some(n) = reflex[j]
    {
        let t = sub(x0, at(0, j));
        f.push(([scale * n[0], scale * n[1]], scale * (t[0] * n[0] + t[1] * n[1])));
    }
    let worst = |d: Uv| f.iter().map(|(g, c)| g[0] * d[0] + g[1] * d[1] + c).fold(f64::INFINITY, crate::num::min_nan);
    let (mut best, mut best_d) = (worst([0.0, 0.0]), [0.0, 0.0]);
    for a in 0..f.len() {
        for b in a + 1..f.len() {
            for c in b + 1..f.len() {
                // f_a = f_b = f_c: two linear equations in d
                let (r1, r2) = (sub(f[a].0, f[b].0), sub(f[a].0, f[c].0));
                let det = cross(r1, r2);
                if det == 0.0 {
                    continue;
                }
                let (s1, s2) = (f[b].1 - f[a].1, f[c].1 - f[a].1);
                let d = [(s1 * r2[1] - s2 * r1[1]) / det, (r1[0] * s2 - r2[0] * s1) / det];
                let w = worst(d);
                if w > best {
                    (best, best_d) = (w, d);
                }
            }
        }
    }
    (best > f64::NEG_INFINITY && best_d != [0.0, 0.0]).then(|| [x0[0] + best_d[0], x0[1] + best_d[1]])
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
    let mut sweeps = 0;
    // Winslow's equations have a folded fixed point near sharp convex trim corners (a
    // spike of the hole): stop sweeping once the fold count has not dropped for
    // `STALL` sweeps and untangle locally; if that does not finish, sweep on.
    const STALL: usize = 200;
    let (mut folds, mut inside) =
        smooth(map, &mut p, (rings, cols), (folds_before, inside_before), &mut sweeps, o.max_sweeps, STALL);
    let mut untangle_moves = 0;
    if folds > 0 {
        let mut q = p.clone();
        let moves = untangle(&mut q, rings, cols);
        if count_folds(&q, rings, cols) == 0 && count_inside(map, &q, rings, cols) == 0 {
            (p, folds, inside, untangle_moves) = (q, 0, 0, moves);
        } else {
            (folds, inside) =
                smooth(map, &mut p, (rings, cols), (folds, inside), &mut sweeps, o.max_sweeps, usize::MAX);
        }
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
    report.untangle_moves = untangle_moves;
    Ok(TrimGrid { rings, columns: cols, points: p, report })
}

/// Whether the angle `atan2(a.0, a.1)` is below `atan2(b.0, b.1)`, for sines `a.0, b.0 ≥ 0`
/// (angles in `[0, π]`): then `θ_a < θ_b` exactly when `(a.1, a.0) × (b.1, b.0) > 0`, two
/// products instead of two `atan2`. Where the products tie or are not finite, by `atan2`.
fn angle_below(a: (f64, f64), b: (f64, f64)) -> bool {
    let (l, r) = (a.1 * b.0, a.0 * b.1);
    if l.is_finite() && r.is_finite() && l != r { l > r } else { a.0.atan2(a.1) < b.0.atan2(b.1) }
}

fn quality(map: &LaplaceMap, p: &[Uv], rings: usize, cols: usize) -> TrimReport {
    // the corners' smallest and largest angles as (|sine|, cosine) pairs, in degrees at the
    // end (atan2 per corner was 13 % of the dolphin's cold build); NaN if any corner is
    let (mut lo, mut hi) = (None::<(f64, f64)>, None::<(f64, f64)>);
    let mut nan = false;
    let (mut cmin, mut cmax, mut total) = (f64::INFINITY, 0.0f64, 0.0);
    let at = |a: usize, b: usize| p[a * cols + (b % cols)];
    for i in 0..rings - 1 {
        for j in 0..cols {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let area = 0.5 * (cross(sub(q[2], q[0]), sub(q[3], q[1]))).abs();
            total += area;
            cmin = crate::num::min_nan(cmin, area);
            cmax = crate::num::max_nan(cmax, area);
            for k in 0..4 {
                let (a, b, c) = (q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
                let (x, y) = (sub(a, b), sub(c, b));
                if x != [0.0, 0.0] && y != [0.0, 0.0] {
                    let a = (cross(y, x).abs(), x[0] * y[0] + x[1] * y[1]);
                    nan |= a.0.is_nan() || a.1.is_nan();
                    if lo.is_none_or(|l| angle_below(a, l)) {
                        lo = Some(a);
                    }
                    if hi.is_none_or(|h| angle_below(h, a)) {
                        hi = Some(a);
                    }
                }
            }
        }
    }
    let degrees = |a: Option<(f64, f64)>, none: f64| match a {
        _ if nan => f64::NAN,
        Some((s, c)) => s.atan2(c).to_degrees(),
        None => none,
    };
    let (amin, amax) = (degrees(lo, f64::INFINITY), degrees(hi, 0.0));
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
    // the grid's points are scattered in `(u, v)` (no two rings share a `u`): in batches
    let mut evals = vec![[Vec3::ZERO; 3]; g.points.len()];
    g.points.par_chunks(512).zip(evals.par_chunks_mut(512)).for_each(|(uv, out)| s.firsts_at(uv, out));
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

#[cfg(test)]
mod untangle_tests {
    use super::*;
    use std::f64::consts::TAU;

    /// The products order angles as `atan2` does: on the axes (0, π/2, π), at equal angles
    /// of different lengths, at magnitudes whose products overflow or underflow, and at
    /// pseudo-random pairs; only pairs within 4 ulps of each other may be ordered either way.
    #[test]
    fn angles_ordered_by_products_as_by_atan2() {
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut pairs = vec![
            (0.0, 1.0),
            (0.0, -1.0),
            (0.0, 2.0),
            (1.0, 0.0),
            (2.0, 0.0),
            (3.0, 4.0),
            (6.0, 8.0),
            (1e-300, -1.0),
            (1e200, 1e200),
            (1e200, -1e200),
            (1e-200, 1e-200),
            (f64::MAX, 1.0),
        ];
        for k in 0..400 {
            let scale = [1.0, 1e-7, 1e9][k % 3];
            pairs.push((next().abs() * scale, next() * scale));
        }
        for a in &pairs {
            for b in &pairs {
                let (ta, tb) = (a.0.atan2(a.1), b.0.atan2(b.1));
                // NaN-free here (finite pairs), and a NaN would fail the comparison
                if (ta - tb).abs() > 4.0 * f64::EPSILON * crate::num::max_nan(ta.abs(), tb.abs()) {
                    assert_eq!(angle_below(*a, *b), ta < tb, "{a:?} against {b:?}");
                }
            }
        }
    }

    /// A polar grid about the origin (ring radii 1, 2, …), positively oriented.
    fn polar(rings: usize, cols: usize) -> Vec<Uv> {
        (0..rings)
            .flat_map(|i| {
                (0..cols).map(move |j| {
                    let (r, t) = (1.0 + i as f64, TAU * j as f64 / cols as f64);
                    [r * t.cos(), r * t.sin()]
                })
            })
            .collect()
    }

    #[test]
    fn a_vertex_dragged_across_its_neighbours_is_put_back_inside() {
        let (rings, cols) = (4, 12);
        let mut p = polar(rings, cols);
        assert_eq!(count_folds(&p, rings, cols), 0);
        // (2, 3) moved beyond ring 3: its cells fold
        let k = 2 * cols + 3;
        let home = p[k];
        p[k] = [home[0] * 1.8, home[1] * 1.8];
        assert!(count_folds(&p, rings, cols) >= 2);
        let moves = untangle(&mut p, rings, cols);
        assert_eq!(count_folds(&p, rings, cols), 0);
        assert!(moves >= 1);
        // the max–min position lies between rings 1 and 3 (radii 2 and 4)
        let r = p[k][0].hypot(p[k][1]);
        assert!(r > 2.0 && r < 4.0, "radius {r}");
        // vertices away from the fold stay put; its neighbours move less than a cell
        let q = polar(rings, cols);
        for m in 0..p.len() {
            let (i, j) = (m / cols, m % cols);
            let d = (p[m][0] - q[m][0]).hypot(p[m][1] - q[m][1]);
            if m != k {
                assert!(
                    if i.abs_diff(2) <= 1 && j.abs_diff(3) <= 1 { d < 0.5 } else { d == 0.0 },
                    "({i}, {j}) moved {d}"
                );
            }
        }
    }

    #[test]
    fn at_a_reflex_loop_vertex_the_ring_one_vertex_stays_outside_the_hole() {
        // ring 0: a square hole with one spike vertex at column 0 pointing along +x
        let (rings, cols) = (3, 8);
        let mut p = polar(rings, cols);
        p[0] = [2.5, 0.0]; // spike tip, between rings 1 and 2 in radius
        p[cols] = [1.0, 0.0]; // ring-1 vertex pulled back into the spike
        assert!(count_folds(&p, rings, cols) > 0);
        untangle(&mut p, rings, cols);
        assert_eq!(count_folds(&p, rings, cols), 0);
        // outward bisector at the tip is +x: the ring-1 vertex lies beyond the tip
        assert!(p[cols][0] > 2.5, "{:?}", p[cols]);
    }
}
