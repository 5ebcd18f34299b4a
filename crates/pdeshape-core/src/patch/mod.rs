//! Patches: maps `X(u, v)` from the parameter domain `[0, 1] × V` to R³ (SPEC §1).
//!
//! Every patch kind implements [`Surface`], which exposes exact partial derivatives, so
//! meshing (normals), condition checks and continuity diagnostics work the same way for
//! all of them. Conditions ([`Condition`]) prescribe `∂ᵈX/∂uᵈ (uᵢ, v) = gᵢ(v)`.

mod curvature;
mod curves;
mod hermite;
mod primary;
#[cfg(test)]
pub(crate) mod test_shapes;

pub use curvature::{Curvature, CurvatureKind, curvature};
pub use curves::{CurvePoint, iso_u_curve, plane_section, section_curvature};
pub use hermite::{HermiteBasis, HermitePatch, HermitePatchError, Poly, cubic_hermite};
pub use primary::PrimarySurface;

use crate::Vec3;
use crate::data::FieldRef;
use std::f64::consts::PI;

/// The transverse parameter domain `V`: an interval, periodic or not.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VDomain {
    /// Start of the interval.
    pub start: f64,
    /// End of the interval.
    pub end: f64,
    /// True when `X(u, start) = X(u, end)` with all derivatives (closed patches).
    pub periodic: bool,
}

impl VDomain {
    /// The closed-patch domain `[0, 2π)`.
    pub const PERIODIC: VDomain = VDomain { start: 0.0, end: 2.0 * PI, periodic: true };

    /// An open domain `[start, end]`.
    pub fn open(start: f64, end: f64) -> Self {
        VDomain { start, end, periodic: false }
    }

    /// The point `start + f (end − start)`.
    pub fn at(&self, f: f64) -> f64 {
        self.start + f * (self.end - self.start)
    }
}

/// A condition `∂ᵈX/∂uᵈ (u, v) = g(v, t)` (SPEC §1): position (`d = 0`), tangent (`d = 1`),
/// curvature-type (`d = 2`), …
#[derive(Clone, Debug)]
pub struct Condition {
    /// Where, in the blend direction.
    pub u: f64,
    /// Derivative order `d`.
    pub order: usize,
    /// The prescribed data `g`, slots `(v, t)`.
    pub data: FieldRef,
}

/// A patch `X: [0, 1] × V → R³` with exact partial derivatives.
pub trait Surface: Send + Sync {
    /// The transverse domain.
    fn v_domain(&self) -> VDomain;

    /// The partial derivatives `∂^{i+j}X/∂uⁱ∂vʲ (u, v)` for `i ≤ du`, `j ≤ dv`, stored at
    /// index `i (dv + 1) + j`.
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3>;

    /// `X(u, v)`.
    fn point(&self, u: f64, v: f64) -> Vec3 {
        self.derivatives(u, v, 0, 0)[0]
    }

    /// `out[p] = X(u, v)` at scattered parameters `uv[p] = [u, v]`, on the calling thread.
    /// Kinds override it to share work between the points (no per-point cache, lock or
    /// allocation); the result equals [`point`](Self::point)'s to round-off.
    fn points_at(&self, uv: &[[f64; 2]], out: &mut [Vec3]) {
        assert_eq!(uv.len(), out.len(), "one output per point");
        for (o, p) in out.iter_mut().zip(uv) {
            *o = self.point(p[0], p[1]);
        }
    }

    /// `out[p] = [X, X_u, X_v]` at scattered parameters `uv[p] = [u, v]`, on the calling
    /// thread; as [`points_at`](Self::points_at), with first derivatives.
    fn firsts_at(&self, uv: &[[f64; 2]], out: &mut [[Vec3; 3]]) {
        assert_eq!(uv.len(), out.len(), "one output per point");
        for (o, p) in out.iter_mut().zip(uv) {
            let d = self.derivatives(p[0], p[1], 1, 1);
            *o = [d[0], d[2], d[1]];
        }
    }

    /// `out[p] = [X, X_u, X_v, X_uu, X_uv, X_vv]` (the order of [`jet2`](Self::jet2)) at
    /// scattered parameters `uv[p] = [u, v]`, on the calling thread; as
    /// [`points_at`](Self::points_at), with first and second derivatives.
    fn seconds_at(&self, uv: &[[f64; 2]], out: &mut [[Vec3; 6]]) {
        assert_eq!(uv.len(), out.len(), "one output per point");
        for (o, p) in out.iter_mut().zip(uv) {
            *o = self.jet2(p[0], p[1]);
        }
    }

    /// Values `X` on the grid `us × vs` (row-major in `u`): the first of [`grid`](Self::grid)'s
    /// four, for callers that need no derivatives (the fit's samples); solvers whose grids
    /// are matrix products override it to form the values' product alone.
    fn grid_values(&self, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
        self.grid(us, vs).into_iter().map(|x| x[0]).collect()
    }

    /// Values and first derivatives `[X, X_u, X_v, X_uv]` on the grid `us × vs` (row-major
    /// in `u`). Solvers override this to share per-row and per-column work.
    fn grid(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 4]> {
        use rayon::prelude::*;
        us.par_iter()
            .flat_map_iter(|&u| {
                crate::cancel::checkpoint();
                vs.iter().map(move |&v| {
                    let d = self.derivatives(u, v, 1, 1);
                    [d[0], d[2], d[1], d[3]]
                })
            })
            .collect()
    }

    /// Values with first and second derivatives `[X, X_u, X_v, X_uu, X_uv, X_vv]` on the
    /// grid `us × vs` (row-major in `u`), e.g. for exact curvature. Solvers override this
    /// to share per-row and per-column work.
    fn grid2(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 6]> {
        use rayon::prelude::*;
        us.par_iter()
            .flat_map_iter(|&u| {
                crate::cancel::checkpoint();
                vs.iter().map(move |&v| self.jet2(u, v))
            })
            .collect()
    }

    /// `[X, X_u, X_v, X_uu, X_uv, X_vv]` at one point (the order of [`grid2`](Self::grid2)).
    fn jet2(&self, u: f64, v: f64) -> [Vec3; 6] {
        // index i·3 + j of ∂ⁱ_u ∂ʲ_v
        let d = self.derivatives(u, v, 2, 2);
        [d[0], d[3], d[1], d[6], d[4], d[2]]
    }

    /// `∂ᵏX/∂uᵏ (u, v)`.
    fn u_derivative(&self, u: f64, v: f64, k: usize) -> Vec3 {
        self.derivatives(u, v, k, 0)[k]
    }
}

/// Mean curvature `H = (E N − 2 F M + G L) / (2 (E G − F²))` from the jets
/// `[X, X_u, X_v, X_uu, X_uv, X_vv]` (first fundamental form `E, F, G`, second `L, M, N`
/// against the unit normal `n = X_u × X_v / |X_u × X_v|`): positive where the surface bends
/// towards `n`. `None` where `X_u × X_v` vanishes (a pole).
///
/// ```
/// use pdeshape_core::{Vec3, patch::mean_curvature};
/// // the cylinder (cos v, sin v, u) at v = 0: n points to the axis, H = 1/(2R)
/// let j = [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 1.0, 0.0),
///          Vec3::ZERO, Vec3::ZERO, Vec3::new(-1.0, 0.0, 0.0)];
/// assert!((mean_curvature(&j).unwrap() - 0.5).abs() < 1e-15);
/// ```
pub fn mean_curvature(j: &[Vec3; 6]) -> Option<f64> {
    curvature(j).map(|c| c.mean)
}

/// Result of checking a patch against its conditions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConditionReport {
    /// Largest `|∂ᵈX/∂uᵈ(uᵢ, v) − gᵢ(v)|` over all conditions and samples.
    pub max_abs: f64,
    /// `max_abs` divided by the patch size (bounding-box diagonal of the samples).
    pub max_rel: f64,
    /// The patch size used.
    pub size: f64,
}

/// Checks every condition at `samples` equispaced `v` (plus pseudo-random jitter so no
/// grid is favoured) at time `t`.
pub fn check_conditions(s: &dyn Surface, conds: &[Condition], t: f64, samples: usize) -> ConditionReport {
    let dom = s.v_domain();
    let vs: Vec<f64> = (0..samples)
        .map(|k| {
            // a low-discrepancy jitter (golden ratio) keeps the samples off any solver grid
            let f = ((k as f64 + 0.5) / samples as f64 + 0.618_033_988_749_895 * 1e-3 * k as f64) % 1.0;
            dom.at(f)
        })
        .collect();
    // conditions of order 0 and 1 and the size samples at u = 0, ½, 1 on the grid path
    // (`Surface::grid`: the solvers share per-row and per-column work there); higher orders
    // pointwise
    let mut us: Vec<f64> = vec![0.0, 0.5, 1.0];
    for c in conds.iter().filter(|c| c.order <= 1) {
        if !us.contains(&c.u) {
            us.push(c.u);
        }
    }
    let g = s.grid(&us, &vs);
    let at = |u: f64, j: usize| &g[us.iter().position(|x| *x == u).expect("a grid row") * vs.len() + j];
    // each condition's data at every sample in one call (`Field::derivatives_in_many`:
    // data carried on another patch evaluate it in a batch)
    let vt: Vec<f64> = vs.iter().flat_map(|&v| [v, t]).collect();
    let data: Vec<Vec<Vec3>> = conds
        .iter()
        .map(|c| {
            let mut out = vec![Vec3::ZERO; vs.len()];
            c.data.derivatives_in_many(&vt, 2, 0, 1, &mut out);
            out
        })
        .collect();
    let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = -lo;
    let mut max_abs: f64 = 0.0;
    for (j, &v) in vs.iter().enumerate() {
        for (c, g) in conds.iter().zip(&data) {
            let x = match c.order {
                0 => at(c.u, j)[0],
                1 => at(c.u, j)[1],
                k => s.u_derivative(c.u, v, k),
            };
            let e = (x - g[j]).scaled_norm();
            max_abs = crate::num::max_nan(max_abs, e);
            if c.order == 0 {
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
        for u in [0.0, 0.5, 1.0] {
            let p = at(u, j)[0];
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    // NaN stays NaN (a NaN sample makes the box NaN); a zero size becomes the tiniest
    let size = crate::num::max_nan((hi - lo).scaled_norm(), f64::MIN_POSITIVE);
    ConditionReport { max_abs, max_rel: max_abs / size, size }
}
