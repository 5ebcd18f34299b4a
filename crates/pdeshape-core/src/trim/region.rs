//! The trimmed region: the domain rectangle minus the insides of the trim curves, its
//! validation, and the single closed inner boundary `C₁` that joins several trim curves by
//! bridge segments traversed both ways (paper 003, Fig. 7).

use super::TrimError;
use super::curve::{TrimCurve, Uv, cross, distance_to_segment, inside_polygon, segments_intersect, signed_area2, sub};
use crate::num::MaxNan;
use std::f64::consts::TAU;

/// The parameter rectangle `[u₀, u₁] × [v₀, v₁]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Lower corner `(u₀, v₀)`.
    pub min: Uv,
    /// Upper corner `(u₁, v₁)`.
    pub max: Uv,
}

impl Rect {
    /// Area.
    pub fn area(&self) -> f64 {
        (self.max[0] - self.min[0]) * (self.max[1] - self.min[1])
    }

    /// True when `p` lies strictly inside.
    pub fn contains(&self, p: Uv) -> bool {
        p[0] > self.min[0] && p[0] < self.max[0] && p[1] > self.min[1] && p[1] < self.max[1]
    }

    /// The corners counter-clockwise from `min`.
    pub fn corners(&self) -> [Uv; 4] {
        [self.min, [self.max[0], self.min[1]], self.max, [self.min[0], self.max[1]]]
    }
}

/// One piece of the inner boundary loop.
#[derive(Clone, Debug, PartialEq)]
pub enum Piece {
    /// Curve `curve` from parameter `from` to `to` (`to − from` may be negative when the
    /// curve is traversed against its parameter, to keep the region on the outside).
    Arc {
        /// Index into the trim curves.
        curve: usize,
        /// Start parameter.
        from: f64,
        /// End parameter.
        to: f64,
    },
    /// A bridge segment.
    Segment {
        /// Start.
        a: Uv,
        /// End.
        b: Uv,
    },
}

/// Samples of the loop per piece (and per knot interval of arcs) for the parameterisation
/// table and the point-in-trim tests.
const SAMPLES_PER_KNOT: usize = 32;

/// A validated trim: the curves, their polygonisations, the bridges and the joined loop.
#[derive(Clone, Debug)]
pub struct TrimRegion {
    /// The domain rectangle.
    pub domain: Rect,
    /// Curve names (for messages) and curves.
    pub curves: Vec<(String, TrimCurve)>,
    /// Fine polygonisations of each curve (counter-clockwise order not guaranteed).
    pub polygons: Vec<Vec<Uv>>,
    /// `+1` when the curve runs counter-clockwise in its parameter, `−1` otherwise.
    pub orientation: Vec<f64>,
    /// Per curve, twice the largest distance of the curve from its polygon's chords
    /// (sampled at the chords' parameter midpoints; 0 for a polygon, which is its own
    /// polygonisation): closer than this to the polygon, [`in_hole`](Self::in_hole)
    /// judges by the curve itself.
    pub sagitta: Vec<f64>,
    /// Per curve, the bounding box `[min, max]` of its polygon: a point farther than the
    /// sagitta (and the tolerance) from it is neither in the hole nor near it, which
    /// [`in_hole`](Self::in_hole) decides without walking the polygon.
    pub bounds: Vec<[Uv; 2]>,
    /// Bridges `(curve a, t_a, curve b, t_b)` joining the curves into one loop.
    pub bridges: Vec<(usize, f64, usize, f64)>,
    /// The loop: every curve once counter-clockwise, every bridge twice.
    pub pieces: Vec<Piece>,
    /// Area of the region (domain area minus the areas inside the curves).
    pub area: f64,
    /// A centre for the polar parameterisation: the area centroid of the trim curves.
    pub center: Uv,
}

impl TrimRegion {
    /// Validates the curves against the domain and each other, and joins them.
    ///
    /// Errors: a curve that is not finite, leaves the (open) domain, is degenerate
    /// (zero area), has a cusp or doubles back on itself, crosses itself, crosses or lies
    /// inside another curve; bridges that
    /// would cross a curve or another bridge.
    pub fn new(domain: Rect, curves: Vec<(String, TrimCurve)>) -> Result<Self, TrimError> {
        if curves.is_empty() {
            return Err(TrimError::NoCurves);
        }
        if !(domain.max[0] > domain.min[0] && domain.max[1] > domain.min[1]) {
            return Err(TrimError::BadDomain);
        }
        let mut polygons = Vec::new();
        let mut orientation = Vec::new();
        let mut sagitta = Vec::new();
        let mut area = domain.area();
        let mut cx = [0.0; 2];
        let mut total = 0.0;
        for (name, c) in &curves {
            let pts = c.polygonize(SAMPLES_PER_KNOT);
            if let Some((t, p)) = pts.iter().find(|(_, p)| !domain.contains(*p)) {
                if !(p[0].is_finite() && p[1].is_finite()) {
                    return Err(TrimError::NotFinite { curve: name.clone() });
                }
                return Err(TrimError::LeavesDomain { curve: name.clone(), t: *t, at: *p, domain });
            }
            let poly: Vec<Uv> = pts.iter().map(|x| x.1).collect();
            let corners_allowed = matches!(c, TrimCurve::Spline(b) if b.degree() == 1);
            if let Some(at) = reversal(&poly, corners_allowed) {
                return Err(TrimError::Cusp { curve: name.clone(), at });
            }
            if let Some(at) = self_intersection(&poly) {
                return Err(TrimError::SelfIntersection { curve: name.clone(), at });
            }
            let sag = if corners_allowed { 0.0 } else { 2.0 * chord_deviation(c, &pts) };
            let a2 = signed_area2(&poly);
            if a2.abs() < 1e-12 * domain.area() {
                return Err(TrimError::Degenerate { curve: name.clone() });
            }
            area -= a2.abs() / 2.0;
            let c = centroid(&poly);
            cx[0] += c[0] * a2.abs();
            cx[1] += c[1] * a2.abs();
            total += a2.abs();
            orientation.push(a2.signum());
            sagitta.push(sag);
            polygons.push(poly);
        }
        for i in 0..polygons.len() {
            for j in i + 1..polygons.len() {
                if let Some(at) = crossing(&polygons[i], &polygons[j]) {
                    return Err(TrimError::CurvesIntersect { a: curves[i].0.clone(), b: curves[j].0.clone(), at });
                }
                for (inner, outer) in [(i, j), (j, i)] {
                    if inside_polygon(polygons[inner][0], &polygons[outer]) {
                        return Err(TrimError::Nested {
                            inner: curves[inner].0.clone(),
                            outer: curves[outer].0.clone(),
                        });
                    }
                }
            }
        }
        let center = [cx[0] / total, cx[1] / total];
        let bounds = polygons
            .iter()
            .map(|poly| {
                poly.iter().fold([[f64::INFINITY; 2], [f64::NEG_INFINITY; 2]], |[lo, hi], q| {
                    [[lo[0].min(q[0]), lo[1].min(q[1])], [hi[0].max(q[0]), hi[1].max(q[1])]]
                })
            })
            .collect();
        let mut region = TrimRegion {
            domain,
            curves,
            polygons,
            orientation,
            sagitta,
            bounds,
            bridges: vec![],
            pieces: vec![],
            area,
            center,
        };
        region.join()?;
        Ok(region)
    }

    /// Joins the curves by a minimum spanning tree of shortest bridges and builds the loop.
    fn join(&mut self) -> Result<(), TrimError> {
        let n = self.curves.len();
        // Bridge ends avoid polygon vertices: a bridge from a corner leaves a re-entrant
        // corner that a single grid line cannot split into two convex cells.
        let samples: Vec<Vec<(f64, Uv)>> = self
            .curves
            .iter()
            .map(|(_, c)| {
                let pts = c.polygonize(SAMPLES_PER_KNOT);
                match c {
                    TrimCurve::Spline(b) if b.degree() == 1 => {
                        pts.into_iter().enumerate().filter(|(k, _)| k % SAMPLES_PER_KNOT != 0).map(|x| x.1).collect()
                    }
                    _ => pts,
                }
            })
            .collect();
        // closest sample pair between every two curves
        let mut best = vec![vec![(f64::INFINITY, 0.0, 0.0); n]; n];
        for i in 0..n {
            for j in i + 1..n {
                let mut b = (f64::INFINITY, 0.0, 0.0);
                for (ti, pi) in &samples[i] {
                    for (tj, pj) in &samples[j] {
                        let d = (pi[0] - pj[0]).hypot(pi[1] - pj[1]);
                        if d < b.0 {
                            b = (d, *ti, *tj);
                        }
                    }
                }
                best[i][j] = b;
                best[j][i] = (b.0, b.2, b.1);
            }
        }
        // Prim's algorithm from curve 0.
        let mut in_tree = vec![false; n];
        in_tree[0] = true;
        let mut bridges = Vec::new();
        for _ in 1..n {
            let mut pick = (f64::INFINITY, 0, 0);
            for i in (0..n).filter(|&i| in_tree[i]) {
                for j in (0..n).filter(|&j| !in_tree[j]) {
                    if best[i][j].0 < pick.0 {
                        pick = (best[i][j].0, i, j);
                    }
                }
            }
            let (_, i, j) = pick;
            in_tree[j] = true;
            bridges.push((i, best[i][j].1, j, best[i][j].2));
        }
        // bridges must not cross any curve (away from their ends) or each other
        for (k, &(i, ti, j, tj)) in bridges.iter().enumerate() {
            let (a, b) = (self.curves[i].1.point(ti), self.curves[j].1.point(tj));
            for (c, poly) in self.polygons.iter().enumerate() {
                let m = poly.len();
                for e in 0..m {
                    let (p, q) = (poly[e], poly[(e + 1) % m]);
                    let near_end = |x: Uv| distance_to_segment(x, p, q) < 1e-12;
                    if (c == i && near_end(a)) || (c == j && near_end(b)) {
                        continue;
                    }
                    if segments_intersect(a, b, p, q) {
                        return Err(TrimError::BridgeCrosses {
                            a: self.curves[i].0.clone(),
                            b: self.curves[j].0.clone(),
                            crossed: self.curves[c].0.clone(),
                        });
                    }
                }
            }
            for &(i2, ti2, j2, tj2) in &bridges[..k] {
                let (c, d) = (self.curves[i2].1.point(ti2), self.curves[j2].1.point(tj2));
                let shares = [a, b].iter().any(|x| [c, d].iter().any(|y| x == y));
                if !shares && segments_intersect(a, b, c, d) {
                    return Err(TrimError::BridgeCrosses {
                        a: self.curves[i].0.clone(),
                        b: self.curves[j].0.clone(),
                        crossed: format!("the bridge {} – {}", self.curves[i2].0, self.curves[j2].0),
                    });
                }
            }
        }
        self.bridges = bridges;
        let start = self.curves[0].1.knots()[0];
        let mut pieces = Vec::new();
        self.visit(0, start, None, &mut pieces);
        self.pieces = pieces;
        Ok(())
    }

    /// Appends the traversal of curve `c` entered at parameter `entry` (once around,
    /// counter-clockwise), with detours along every bridge to curves not yet visited.
    fn visit(&self, c: usize, entry: f64, parent: Option<usize>, out: &mut Vec<Piece>) {
        let dir = self.orientation[c];
        // attachments: (parameter on c, child curve, parameter on child)
        let mut att: Vec<(f64, usize, f64)> = Vec::new();
        for &(i, ti, j, tj) in &self.bridges {
            if i == c && Some(j) != parent {
                att.push((ti, j, tj));
            } else if j == c && Some(i) != parent {
                att.push((tj, i, ti));
            }
        }
        // order by the distance travelled from the entry in the direction of traversal
        let offset = |t: f64| ((t - entry) * dir).rem_euclid(TAU);
        att.sort_by(|a, b| offset(a.0).total_cmp(&offset(b.0)));
        let mut at = entry;
        for (t, child, tc) in att {
            let to = entry + dir * offset(t);
            if to != at {
                out.push(Piece::Arc { curve: c, from: at, to });
            }
            let (a, b) = (self.curves[c].1.point(t), self.curves[child].1.point(tc));
            out.push(Piece::Segment { a, b });
            self.visit(child, tc, Some(c), out);
            out.push(Piece::Segment { a: b, b: a });
            at = to;
        }
        out.push(Piece::Arc { curve: c, from: at, to: entry + dir * TAU });
    }

    /// `(curve, t)` of an exact point on piece `k` at local fraction `s ∈ [0, 1]`, or the
    /// bridge point.
    pub fn piece_point(&self, k: usize, s: f64) -> Uv {
        match &self.pieces[k] {
            Piece::Arc { curve, from, to } => self.curves[*curve].1.point(from + s * (to - from)),
            Piece::Segment { a, b } => [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])],
        }
    }

    /// True when the loop has a corner at fraction `s` of piece `k` (a polygon vertex).
    pub fn is_corner(&self, k: usize, s: f64) -> bool {
        let Piece::Arc { curve, from, to } = &self.pieces[k] else { return false };
        let TrimCurve::Spline(b) = &self.curves[*curve].1 else { return false };
        if b.degree() != 1 {
            return false;
        }
        let t = from + s * (to - from);
        let n = b.points().len() as f64;
        let x = t / TAU * n;
        (x - x.round()).abs() < 1e-9
    }

    /// Number of samples used on piece `k` by [`Self::samples`].
    fn piece_samples(&self, k: usize) -> usize {
        match &self.pieces[k] {
            Piece::Arc { curve, from, to } => {
                let knots = self.curves[*curve].1.knots().len();
                ((to - from).abs() / TAU * (knots * SAMPLES_PER_KNOT) as f64).ceil().max(4.0) as usize
            }
            Piece::Segment { .. } => 16,
        }
    }

    /// The loop sampled densely: `(piece, fraction, point)`, ends of pieces included once,
    /// the loop's start not repeated at the end.
    pub fn samples(&self) -> Vec<(usize, f64, Uv)> {
        let mut out = Vec::new();
        for k in 0..self.pieces.len() {
            let m = self.piece_samples(k);
            for i in 0..m {
                let s = i as f64 / m as f64;
                out.push((k, s, self.piece_point(k, s)));
            }
        }
        out
    }

    /// Distance from `p` to the loop: exact on the curves ([`TrimCurve::closest`]), and to
    /// the bridge segments.
    pub fn loop_distance(&self, p: Uv) -> f64 {
        let mut d = self.curves.iter().map(|(_, c)| c.closest(p).1).fold(f64::INFINITY, f64::min);
        for piece in &self.pieces {
            if let Piece::Segment { a, b } = piece {
                d = d.min(distance_to_segment(p, *a, *b));
            }
        }
        d
    }

    /// True when `p` lies inside (or within `tol` of) some trim curve. Judged on the
    /// polygonisations, except between a polygon and its curve (closer to the polygon than
    /// the curve's [`sagitta`](Self::sagitta)), where a chord cuts off or adds a sliver:
    /// there the side of the curve's tangent at the closest point decides.
    pub fn in_hole(&self, p: Uv, tol: f64) -> bool {
        (0..self.polygons.len()).any(|i| {
            // outside the box grown by the margin: farther than it from the polygon, and
            // outside the polygon (a NaN point fails these tests and is judged below)
            let [lo, hi] = self.bounds[i];
            let m = self.sagitta[i].max(tol);
            if p[0] < lo[0] - m || p[0] > hi[0] + m || p[1] < lo[1] - m || p[1] > hi[1] + m {
                return false;
            }
            let poly = &self.polygons[i];
            let d = super::curve::distance_to_polygon(p, poly);
            if tol > 0.0 && d < tol {
                return true;
            }
            if d >= self.sagitta[i] {
                return inside_polygon(p, poly);
            }
            let curve = &self.curves[i].1;
            let (t, _) = curve.closest(p);
            let c = curve.derivatives(t, 1);
            let side = cross(c[1], sub(p, c[0])) * self.orientation[i];
            if side == 0.0 || c[1] == [0.0, 0.0] { inside_polygon(p, poly) } else { side > 0.0 }
        })
    }
}

/// The largest distance of the curve's points at the parameter midpoints of the
/// polygonisation `pts` from the chords.
fn chord_deviation(c: &TrimCurve, pts: &[(f64, Uv)]) -> f64 {
    let n = pts.len();
    (0..n)
        .map(|i| {
            let ((ta, a), (tb, b)) = (pts[i], pts[(i + 1) % n]);
            let tb = if i + 1 == n { tb + TAU } else { tb };
            distance_to_segment(c.point(0.5 * (ta + tb)), a, b)
        })
        .max_nan()
}

fn centroid(p: &[Uv]) -> Uv {
    let n = p.len();
    let (mut a, mut x, mut y) = (0.0, 0.0, 0.0);
    for i in 0..n {
        let (q, r) = (p[i], p[(i + 1) % n]);
        let c = cross(q, r);
        a += c;
        x += (q[0] + r[0]) * c;
        y += (q[1] + r[1]) * c;
    }
    [x / (3.0 * a), y / (3.0 * a)]
}

/// The first crossing between non-adjacent edges of a closed polygon.
/// A point where the closed polygonisation `p` turns back on itself: consecutive
/// (non-zero) edges pointing against each other. For a smooth curve sampled finely that is
/// a cusp (its tangent reverses within one sample); for a polygon (`corners_allowed`) only a
/// vertex where it doubles back along its own edge (a turn of 180°) counts.
fn reversal(p: &[Uv], corners_allowed: bool) -> Option<Uv> {
    let n = p.len();
    let edges: Vec<(Uv, Uv)> =
        (0..n).map(|i| (sub(p[(i + 1) % n], p[i]), p[(i + 1) % n])).filter(|(e, _)| *e != [0.0, 0.0]).collect();
    let m = edges.len();
    (0..m).find_map(|i| {
        let ((a, at), (b, _)) = (edges[i], edges[(i + 1) % m]);
        let dot = a[0] * b[0] + a[1] * b[1];
        let len = (a[0].hypot(a[1])) * (b[0].hypot(b[1]));
        let reverses = dot < 0.0 && (!corners_allowed || cross(a, b).abs() <= 1e-9 * len);
        reverses.then_some(at)
    })
}

fn self_intersection(p: &[Uv]) -> Option<Uv> {
    let n = p.len();
    let bbox = |i: usize| {
        let (a, b) = (p[i], p[(i + 1) % n]);
        [a[0].min(b[0]), a[1].min(b[1]), a[0].max(b[0]), a[1].max(b[1])]
    };
    let boxes: Vec<[f64; 4]> = (0..n).map(bbox).collect();
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue;
            }
            let (bi, bj) = (boxes[i], boxes[j]);
            if bi[2] < bj[0] || bj[2] < bi[0] || bi[3] < bj[1] || bj[3] < bi[1] {
                continue;
            }
            if segments_intersect(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]) {
                return Some(p[j]);
            }
        }
    }
    None
}

/// A point where two closed polygons cross.
fn crossing(a: &[Uv], b: &[Uv]) -> Option<Uv> {
    let (n, m) = (a.len(), b.len());
    for i in 0..n {
        let (p, q) = (a[i], a[(i + 1) % n]);
        for j in 0..m {
            if segments_intersect(p, q, b[j], b[(j + 1) % m]) {
                return Some(p);
            }
        }
    }
    None
}
