//! The band between a hole's loop and its fill: triangles on the collar whose apexes lie
//! over the loop's edges.
//!
//! **Why over the edges.** A small triangle inscribed in a smooth surface has about the
//! surface's normal at its circumcentre (exactly so on a sphere), so two triangles on an
//! edge crease by about the curvature times the distance between their circumcentres. A new triangle on a loop
//! edge creases against the mesh's triangle there no more than the mesh's own triangles
//! crease against each other when its circumcentre lies on or near the edge: its apex over
//! the edge's midpoint, about half the edge's length away (a right angle at the apex puts
//! the circumcentre on the edge). A band zipped from the loop to a smooth curve puts its
//! apexes wherever that curve's vertices happen to be: over a slanted edge they lie to one
//! side or far up, and the triangle creases.
//!
//! **The apexes.** Over loop edge `(x_i, x_{i+1})`, of length `ℓ`, midpoint `m` and
//! direction `t`, the apex is the collar point `C(s, w)` with
//!
//! ```text
//! (C(s, w) − m) · t = 0,    (C(s, w) − m) · q = H,
//! ```
//!
//! `q = t × N` (into the hole: the loop runs with the mesh on its left seen from the
//! collar's normal `N = C_w × C_s`) and `H = BAND_HEIGHT · ℓ`, solved by Newton's method
//! on `(s, w)` with the collar's exact first derivatives (the Jacobian's rows are
//! `(C_s · t, C_w · t)` and `(C_s · q, C_w · q)`). Its circumcentre lies
//! `(H² − ℓ²/4) / 2H ≈ 0.05 ℓ` beyond the edge.
//!
//! **Notches.** Where the loop turns towards the hole by a hole-side angle `α` below
//! `NOTCH`, the apexes over its two edges would run into each other; the two edges share
//! one, on the notch's bisector at `ℓ̄ cos(α/2)` from the vertex, where (for equal edges)
//! each edge sees it at a right angle. Sharpest notches first, an edge in one pair only.
//!
//! **Lengths.** The mesh's density asks for new edges within 2× of the local median edge
//! length `h_l` (the median of the mesh's edges at a loop vertex and at its neighbours):
//! no apex is nearer
//! than `SHORTEST · h_l` to a loop vertex of its triangles (its height is raised where a
//! short loop edge would put it nearer) or to the next apex.
//!
//! **Junctions.** Where two neighbouring apexes still come closer than `SHORTEST · h_l`, or the
//! triangle between them at their shared loop vertex turns over, their edges share one
//! apex (over their chord, high enough to clear the vertex between), at most
//! `MOST_MERGED` edges to an apex. At a loop vertex where the loop turns towards the mesh
//! (a peak into the hole), the fan between the two apexes beside it opens wide or past a
//! straight angle; past `WIDEST_FAN` it is split by a vertex over the loop vertex.
//!
//! The band is not used (the caller falls back to the loop zipped to the fill's boundary)
//! when a Newton solve fails, a triangle of it turns against the collar's normal, fewer
//! than 3 apexes remain or the apexes do not follow each other along the collar.

use super::collar::Collar;
use crate::Vec3;
use crate::data::Field;
use crate::jet::JetShape;
use crate::num::max_nan;
use std::f64::consts::PI;

/// The apex's height over its edge, as a fraction of the edge's length: just above 0.5,
/// where the apex angle is right and the circumcentre on the edge (below, the apex angle
/// is obtuse and the triangle a sliver).
const BAND_HEIGHT: f64 = 0.55;

/// The widest fan (radians between the two apexes seen from the loop vertex) left whole.
const WIDEST_FAN: f64 = 100.0 * PI / 180.0;

/// The largest hole-side angle at a loop vertex whose two edges share an apex from the
/// start (a notch of the loop).
const NOTCH: f64 = 135.0 * PI / 180.0;

/// The most loop edges that share one apex.
const MOST_MERGED: usize = 2;

/// The shortest edge from an apex (to a loop vertex or to another apex), as a fraction of
/// the local median edge length: the mesh's density asks for new edges within 2× of it,
/// and this keeps a margin above the half.
pub(super) const SHORTEST: f64 = 0.55;

/// A vertex of the band: its position, its collar parameters `(s, w)` and the local
/// median edge length `h` of the loop vertices it stands over.
#[derive(Clone, Copy, Debug)]
pub(super) struct BandVertex {
    pub p: Vec3,
    pub s: f64,
    pub w: f64,
    pub h: f64,
}

/// The band: its vertices in order along the loop and its triangles, on the loop's
/// vertex ids and `base + k` for band vertex `k`.
pub(super) struct Band {
    pub vertices: Vec<BandVertex>,
    pub triangles: Vec<[u32; 3]>,
}

/// What the band is built from: the loop's vertex ids, positions and collar parameters
/// (`w` increasing within one period), the collar and its period, `h` and the local
/// median edge length at each loop vertex.
pub(super) struct BandInput<'a> {
    pub ids: &'a [u32],
    pub pos: &'a [Vec3],
    pub params: &'a [(f64, f64)],
    pub collar: &'a Collar,
    pub period: f64,
    pub h: f64,
    pub local: &'a [f64],
}

/// `C`, `C_s`, `C_w` at `(s, w)`.
fn collar_first(c: &Collar, s: f64, w: f64) -> [Vec3; 3] {
    let j = c.jet(&[s, w], JetShape::new(&[1, 1]));
    [j.derivative([0, 0, 0]), j.derivative([1, 0, 0]), j.derivative([0, 1, 0])]
}

/// The collar's unit normal `C_w × C_s` at `(s, w)`.
fn collar_normal(c: &Collar, s: f64, w: f64) -> Option<Vec3> {
    let [_, cs, cw] = collar_first(c, s, w);
    cw.cross(cs).normalized()
}

/// The collar point `C(s, w)` on two planes `(C − p_k) · d_k = c_k`, by Newton's method
/// from `start` (the Jacobian's rows are `(C_s · d_k, C_w · d_k)`). `None` when the
/// Jacobian is singular, the iteration does not settle within 30 steps or strays farther
/// than `reach` in `(s, w)`.
fn point_on_collar(c: &Collar, planes: [(Vec3, Vec3, f64); 2], start: (f64, f64), reach: f64) -> Option<BandVertex> {
    let (mut s, mut w) = start;
    for _ in 0..30 {
        let [p, cs, cw] = collar_first(c, s, w);
        let f = planes.map(|(o, d, k)| (p - o).dot(d) - k);
        let [(_, d0, _), (_, d1, _)] = planes;
        let (a, b, cc, d) = (cs.dot(d0), cw.dot(d0), cs.dot(d1), cw.dot(d1));
        let det = a * d - b * cc;
        if det.is_nan() || det.abs() <= 1e-12 * (cs.norm() * cw.norm()) {
            return None;
        }
        let ds = (d * f[0] - b * f[1]) / det;
        let dw = (a * f[1] - cc * f[0]) / det;
        s -= ds;
        w -= dw;
        if !((s - start.0).abs() <= reach && (w - start.1).abs() <= reach) {
            return None;
        }
        // the residual is a length: done at round-off of the collar's size
        if f[0].abs().max(f[1].abs()) <= 1e-13 * (1.0 + p.max_abs()) {
            let p = c.eval(&[s, w]);
            return Some(BandVertex { p, s, w, h: 0.0 });
        }
    }
    None
}

/// The collar point over `m` at `height` along `q = t × N` (`N` the collar's normal at
/// `start`) and square to `t`: `(C − m)·t = 0`, `(C − m)·q = height`.
fn point_over(c: &Collar, m: Vec3, t: Vec3, height: f64, start: (f64, f64), reach: f64) -> Option<BandVertex> {
    let n = collar_normal(c, start.0, start.1)?;
    let q = t.cross(n).normalized()?;
    point_on_collar(c, [(m, t, 0.0), (m, q, height)], start, reach)
}

/// The band of `inp` (see the module's documentation), or `None` where it does not apply.
pub(super) fn apex_band(inp: &BandInput, base: u32) -> Option<Band> {
    let n = inp.ids.len();
    let h = inp.h;
    // loop vertex k's (s, w), `w` unwrapped past the period for k ≥ n
    let param = |k: usize| {
        let (s, w) = inp.params[k % n];
        (s, w + inp.period * (k / n) as f64)
    };
    let x = |k: usize| inp.pos[k % n];
    let hl = |k: usize| inp.local[k % n];
    // the collar's unit normal at each loop vertex, once
    let normals: Vec<Option<Vec3>> = inp.params.iter().map(|&(s, w)| collar_normal(inp.collar, s, w)).collect();
    let vn = |k: usize| normals[k % n];
    // `s` and `w` are lengths: an apex lies within a few edges of where its search starts
    let reach = 8.0 * h;
    // the apex over loop vertices a..=b (b > a, unwrapped)
    let apex = |a: usize, b: usize| -> Option<BandVertex> {
        let chord = x(b) - x(a);
        let t = chord.normalized()?;
        let m = (x(a) + x(b)) * 0.5;
        let mean = (a..b).map(|k| (x(k + 1) - x(k)).norm()).sum::<f64>() / (b - a) as f64;
        let (pa, pb) = (param(a), param(b));
        let mid = (0.5 * (pa.0 + pb.0), 0.5 * (pa.1 + pb.1));
        let n0 = collar_normal(inp.collar, mid.0, mid.1)?;
        let q = t.cross(n0).normalized()?;
        // over the highest loop vertex between, by 0.4 of an edge and `SHORTEST` of the
        // local median
        let floor = SHORTEST * max_nan(hl(a), hl(b));
        let above = (a + 1..b).map(|k| (x(k) - m).dot(q) + max_nan(0.4 * mean, floor)).fold(0.0, max_nan);
        // the legs from x(a) and x(b), √((c/2)² + H²), no shorter than `floor`
        let half = 0.5 * chord.norm();
        let legs = max_nan(floor * floor - half * half, 0.0).sqrt();
        let height = max_nan(max_nan(BAND_HEIGHT * mean, above), legs);
        let [_, cs, _] = collar_first(inp.collar, mid.0, mid.1);
        let start = (mid.0 - height / cs.norm().max(1e-300), mid.1);
        point_over(inp.collar, m, t, height, start, reach).map(|v| BandVertex { h: max_nan(hl(a), hl(b)), ..v })
    };
    // the shared apex of edges a and a + 1 at a notch of hole-side angle α at x = x(a+1):
    // on the notch's bisector `b` (in the plane of `b` and the normal) at `ℓ̄ cos(α/2)`
    // from x, where each edge sees it at a right angle (for equal edges): the triangles'
    // circumcentres then lie on the edges, as for the single apexes
    let notch_apex = |a: usize| -> Option<BandVertex> {
        let xv = x(a + 1);
        let (u0, u1) = ((x(a) - xv).normalized()?, (x(a + 2) - xv).normalized()?);
        let pv = param(a + 1);
        let nrm = vn(a + 1)?;
        let b = (u0 + u1).normalized()?;
        let side = b.cross(nrm).normalized()?;
        let half = 0.5 * u0.cross(u1).norm().atan2(u0.dot(u1));
        let (l0, l1) = ((x(a + 1) - x(a)).norm(), (x(a + 2) - x(a + 1)).norm());
        // no nearer any of the three vertices than `SHORTEST` of the local median `F`: at a
        // wide notch (α → 135°) ℓ̄ cos(α/2) falls to 0.38 ℓ̄ (the circumcentres then lie
        // 0.06 ℓ̄ beyond the edges instead of on them), and beside a short edge of length
        // ℓ its far vertex lies √(ℓ² + r² − 2ℓr cos(α/2)) from the apex, at least `F` for
        // r ≥ ℓ cos(α/2) + √(F² − ℓ² sin²(α/2))
        let f = SHORTEST * max_nan(max_nan(hl(a), hl(a + 1)), hl(a + 2));
        let (c, sn) = (half.cos(), half.sin());
        let clear = |l: f64| l * c + max_nan(f * f - l * l * sn * sn, 0.0).sqrt();
        let r = [f, clear(l0), clear(l1)].into_iter().fold(0.5 * (l0 + l1) * c, max_nan);
        let cs = collar_first(inp.collar, pv.0, pv.1)[1].norm().max(1e-300);
        point_on_collar(inp.collar, [(xv, side, 0.0), (xv, b, r)], (pv.0 - r / cs, pv.1), reach)
            .map(|b| BandVertex { h: hl(a + 1), ..b })
    };
    // does the triangle (p, q, r) face the collar's normal at loop vertex `v`?
    let faces = |p: Vec3, q: Vec3, r: Vec3, v: usize| -> bool {
        let nn = (q - p).cross(r - p);
        vn(v).is_some_and(|c| nn.dot(c) > 0.2 * nn.norm())
    };
    // groups of loop edges (first vertex, edge count), cyclic, each with its apex
    // the angle at loop vertex v from p to q, counter-clockwise about the collar's normal,
    // in (0, 2π]
    let fan = |v: usize, p: Vec3, q: Vec3| -> f64 {
        let (d0, d1) = (p - x(v), q - x(v));
        let nrm = vn(v).unwrap_or(Vec3::ZERO);
        let a = d0.cross(d1).dot(nrm).atan2(d0.dot(d1));
        if a <= 0.0 { a + 2.0 * PI } else { a }
    };
    // does the loop turn left at v (towards the mesh: a peak into the hole)?
    let peak = |v: usize| {
        let nrm = vn(v).unwrap_or(Vec3::ZERO);
        (x(v) - x(v + n - 1)).cross(x(v + 1) - x(v)).dot(nrm) > 0.0
    };
    // first the notches (the loop turning right, towards the hole, by a hole-side angle
    // below `NOTCH`), sharpest first: their two edges share the apex square over both
    let mut notches: Vec<(f64, usize)> = (0..n)
        .filter_map(|v| {
            let (e1, e2) = (x(v + n - 1) - x(v), x(v + 1) - x(v));
            let nrm = vn(v)?;
            let right = (x(v) - x(v + n - 1)).cross(x(v + 1) - x(v)).dot(nrm) < 0.0;
            let angle = e1.cross(e2).norm().atan2(e1.dot(e2));
            (right && angle < NOTCH).then_some((angle, v))
        })
        .collect();
    notches.sort_by(|a, b| a.0.total_cmp(&b.0));
    // pair[e]: edge e starts a pair (Some(apex)); taken[e]: edge e is in one
    let mut pair: Vec<Option<BandVertex>> = vec![None; n];
    let mut taken = vec![false; n];
    for &(_, v) in &notches {
        let (e0, e1) = ((v + n - 1) % n, v);
        if taken[e0] || taken[e1] {
            continue;
        }
        if let Some(b) = notch_apex(e0).filter(|b| (0..2).all(|e| faces(x(e0 + e + 1), x(e0 + e), b.p, e0 + e))) {
            pair[e0] = Some(b);
            taken[e0] = true;
            taken[e1] = true;
        }
    }
    // the groups in loop order, from an edge that is not a pair's second
    let first = (0..n).find(|&e| pair[(e + n - 1) % n].is_none())?;
    let mut groups: Vec<(usize, usize, BandVertex)> = Vec::with_capacity(n);
    let mut e = first;
    while e < first + n {
        match pair[e % n] {
            Some(b) => {
                groups.push((e % n, 2, b));
                e += 2;
            }
            None => {
                groups.push((e % n, 1, apex(e % n, e % n + 1)?));
                e += 1;
            }
        }
    }
    // merge the worst junction first; a junction between two apexes too close is left as
    // it is when merging would pass `MOST_MERGED` edges, one whose fan turns over is not
    let mut kept = vec![false; n];
    loop {
        let g = groups.len();
        if g < 3 {
            return None;
        }
        // the worst junction: the fan at the loop vertex between groups j and j + 1
        let mut worst: Option<(usize, f64)> = None;
        for j in 0..g {
            let (a, b) = (&groups[j], &groups[(j + 1) % g]);
            let v = b.0;
            let d = (a.2.p - b.2.p).norm();
            let phi = fan(v, a.2.p, b.2.p);
            // a reflex fan at a peak of the loop is split below; elsewhere it has turned over
            let open = faces(x(v), a.2.p, b.2.p, v) || (peak(v) && (PI - 0.35..=1.6 * PI).contains(&phi));
            let bad = if open { d } else { -1.0 };
            if bad < SHORTEST * hl(v) && !(bad >= 0.0 && kept[v]) && worst.is_none_or(|w| bad < w.1) {
                worst = Some((j, bad));
            }
        }
        let Some((j, bad)) = worst else { break };
        let k = (j + 1) % g;
        let (start, len) = (groups[j].0, groups[j].1 + groups[k].1);
        if len > MOST_MERGED {
            if bad < 0.0 {
                return None;
            }
            kept[groups[k].0] = true;
            continue;
        }
        let pair = if len == 2 && !peak(start + 1) { notch_apex(start) } else { None };
        let ap = match pair {
            Some(b) if (0..2).all(|e| faces(x(start + e + 1), x(start + e), b.p, start + e)) => b,
            _ => apex(start, start + len)?,
        };
        groups[j] = (start, len, ap);
        groups.remove(k);
    }
    // every edge's triangle faces the collar's normal
    for &(a, len, ap) in &groups {
        for e in a..a + len {
            if !faces(x(e + 1), x(e), ap.p, e) {
                return None;
            }
        }
    }
    // the vertices in order, a split vertex before each group whose fan is wide
    let g = groups.len();
    let mut vertices = Vec::with_capacity(g + g / 2);
    let mut triangles = Vec::with_capacity(n + 2 * g);
    let mut apex_id = Vec::with_capacity(g);
    let mut split_id: Vec<Option<u32>> = vec![None; g];
    for j in 0..g {
        let prev = groups[(j + g - 1) % g].2;
        let (v, _, ap) = groups[j];
        let (xv, e0, e1) = (x(v), (x(v) - x(v + n - 1)).norm(), (x(v + 1) - x(v)).norm());
        let phi = fan(v, prev.p, ap.p);
        if phi > WIDEST_FAN {
            let t = (x(v + 1) - x(v + n - 1)).normalized();
            let pv = param(v);
            let split = t.and_then(|t| {
                let cs = collar_first(inp.collar, pv.0, pv.1)[1].norm().max(1e-300);
                let height = max_nan(BAND_HEIGHT * 0.5 * (e0 + e1), SHORTEST * hl(v));
                point_over(inp.collar, xv, t, height, (pv.0 - height / cs, pv.1), reach)
                    .map(|b| BandVertex { h: hl(v), ..b })
            });
            if let Some(b) = split.filter(|b| {
                faces(xv, prev.p, b.p, v)
                    && faces(xv, b.p, ap.p, v)
                    && (b.p - prev.p).norm() >= SHORTEST * hl(v)
                    && (b.p - ap.p).norm() >= SHORTEST * hl(v)
            }) {
                vertices.push(b);
                split_id[j] = Some(base + vertices.len() as u32 - 1);
            } else if phi >= PI - 0.35 || !faces(xv, prev.p, ap.p, v) {
                return None;
            }
        }
        vertices.push(ap);
        apex_id.push(base + vertices.len() as u32 - 1);
    }
    let id = |k: usize| inp.ids[k % n];
    for j in 0..g {
        let (v, len, _) = groups[j];
        let (a, prev) = (apex_id[j], apex_id[(j + g - 1) % g]);
        for e in v..v + len {
            triangles.push([id(e + 1), id(e), a]);
        }
        match split_id[j] {
            Some(b) => {
                triangles.push([id(v), prev, b]);
                triangles.push([id(v), b, a]);
            }
            None => triangles.push([id(v), prev, a]),
        }
    }
    Some(Band { vertices, triangles })
}
