//! The fills of one loop for every fullness scale `f` and pole height `h`, from a fixed
//! number of PDE solves.
//!
//! With every edge's fullness multiplied by `f`, the cross tangent along the loop is
//! `T = f T₁`: the edges' factors `c_k`, the corners' mean tangents `T_c`, their weights
//! `(a, b)` in each edge's frame and their normal parts are all linear in the fullnesses.
//! The second cross derivative is `Q = f² Q₁`: `α² S_ss + 2αβ S_sw + β² S_ww` is quadratic
//! in the weights, and the corners' corrections `(γ, δ, η)` solve linear equations whose
//! right-hand sides are differences of such terms. The loop's position and everything
//! the pole's frame is built from (centroid, normal, `e₁`, `e₂`) do not depend on `f`.
//!
//! The PDE solve is linear in its data, so with the pole's data `d` (pole, ring, `σ`)
//! the fill is `X = X_P + f X_T + f² X_Q + Σᵢ dᵢ Bᵢ`: `X_P`, `X_T`, `X_Q` the patches with
//! only the loop's position, cross tangent or second derivative as data, `Bᵢ` those with
//! only datum `i` at 1. Least bending minimises a quadratic form whose linear term is
//! `X_P + f X_T + f² X_Q`, so its choice is `d(f) = d_P + f d_T + f² d_Q`, three
//! least-squares solves with one matrix; `h` then scales the pole's offset from the loop's
//! centroid. One family therefore costs the solves of one [`Fill::new`] plus two, and each
//! member's grid is a sum of stored grids — what a search over `(f, h)` for the fairest
//! fill needs ([`crate::trimesh`]).

use super::{
    BendingRule, Fill, FillEdge, FillError, FillOptions, LoopSetup, PoleData, bending_solve, set_free, unit_poles,
};
use crate::Vec3;
use crate::patch::{Condition, Surface, VDomain};
use crate::spectral::SpectralPatch;

/// The fills of a loop for every fullness scale and pole height, on one grid.
pub struct FillFamily {
    edges: Vec<FillEdge>,
    o: FillOptions,
    centroid: Vec3,
    free: PoleData<bool, bool>,
    /// The free data's least-bending coefficients: column 0 constant, 1 of `f`, 2 of `f²`.
    coeffs: faer::Mat<f64>,
    /// `[X, X_u, X_v, X_uu, X_uv, X_vv]` on the grid of `X_P`, `X_T` (and `X_Q`).
    loop_grids: Vec<Vec<[Vec3; 6]>>,
    /// The same of each `Bᵢ`, in [`unit_poles`]' order.
    unit_grids: Vec<Vec<[Vec3; 6]>>,
}

impl FillFamily {
    /// The family of the loop `edges` (their fullnesses are those of `f = 1`), evaluated
    /// on the grid `us × vs`. The options must leave the pole's data to least bending
    /// (`pole`, `ring`, `pole_curvature` unset); their `height` is not used.
    pub fn new(edges: &[FillEdge], o: &FillOptions, us: &[f64], vs: &[f64]) -> Result<FillFamily, FillError> {
        if o.pole.is_some() || o.ring.is_some() || o.pole_curvature.is_some() {
            return Err(FillError::Loop(
                "a fill family chooses the pole's data itself: leave pole, ring and pole_curvature unset".into(),
            ));
        }
        let setup = LoopSetup::new(edges, o)?;
        let free = LoopSetup::free(o);
        let zero = PoleData { pole: Vec3::ZERO, ring: 0.0, sigma: 0.0 };
        let zero_loop = setup.zero_loop();
        let solve = |c: &[Condition]| SpectralPatch::new(c, VDomain::PERIODIC, o.spectral);
        let rule = BendingRule::new(setup.edges);
        // the loop's data one at a time, the pole's at zero
        let loop_patches = (0..setup.conds.len())
            .map(|k| {
                let mut c = zero_loop.clone();
                c[k] = setup.conds[k].clone();
                solve(&setup.with_pole(&zero, &c, o.order))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let unit_patches = unit_poles(&free)
            .iter()
            .map(|d| solve(&setup.with_pole(d, &zero_loop, o.order)))
            .collect::<Result<Vec<_>, _>>()?;
        // the members differ in their data alone: their cardinal functions evaluated once a
        // `u` of the rule and of the grid
        let all: Vec<&SpectralPatch> = loop_patches.iter().chain(&unit_patches).collect();
        SpectralPatch::share_rows(&all, &rule.us, 2);
        SpectralPatch::share_rows(&all, us, 2);
        let loop_rows: Vec<Vec<Vec3>> = loop_patches.iter().map(|p| rule.rows(p)).collect();
        let loop_grids = loop_patches.iter().map(|p| p.grid2(us, vs)).collect();
        let unit_rows: Vec<Vec<Vec3>> = unit_patches.iter().map(|p| rule.rows(p)).collect();
        let unit_grids = unit_patches.iter().map(|p| p.grid2(us, vs)).collect();
        let coeffs = bending_solve(&unit_rows, &loop_rows)?;
        Ok(FillFamily {
            edges: edges.to_vec(),
            o: o.clone(),
            centroid: setup.report.centroid,
            free,
            coeffs,
            loop_grids,
            unit_grids,
        })
    }

    /// The pole's data of the member `(f, h)`.
    fn pole_data(&self, f: f64, h: f64) -> PoleData {
        let powers = [1.0, f, f * f];
        let x = (0..self.coeffs.nrows())
            .map(|i| (0..self.coeffs.ncols()).map(|j| self.coeffs[(i, j)] * powers[j]).sum::<f64>());
        let mut d = PoleData { pole: Vec3::ZERO, ring: 0.0, sigma: 0.0 };
        set_free(&mut d, &self.free, x);
        d.pole = self.centroid + (d.pole - self.centroid) * h;
        d
    }

    /// `[X, X_u, X_v, X_uu, X_uv, X_vv]` on the family's grid of the fill whose edges'
    /// fullnesses are `f` times the given ones and whose pole height is `h`: the fill
    /// [`Fill::new`] builds with those, to round-off.
    pub fn grid2(&self, f: f64, h: f64) -> Vec<[Vec3; 6]> {
        let d = self.pole_data(f, h);
        let mut weights = vec![1.0, f, f * f];
        weights.truncate(self.loop_grids.len());
        let mut unit = Vec::new();
        if self.free.pole {
            unit.extend([d.pole.x, d.pole.y, d.pole.z]);
        }
        if self.free.ring {
            unit.push(d.ring);
        }
        if self.free.sigma {
            unit.push(d.sigma);
        }
        let terms: Vec<(f64, &Vec<[Vec3; 6]>)> =
            weights.into_iter().zip(&self.loop_grids).chain(unit.into_iter().zip(&self.unit_grids)).collect();
        let mut out = vec![[Vec3::ZERO; 6]; self.loop_grids[0].len()];
        for (w, g) in terms {
            for (o, x) in out.iter_mut().zip(g) {
                for (a, b) in o.iter_mut().zip(x) {
                    *a += *b * w;
                }
            }
        }
        out
    }

    /// The member `(f, h)` as a fill (one PDE solve).
    pub fn fill(&self, f: f64, h: f64) -> Result<Fill, FillError> {
        let edges: Vec<FillEdge> =
            self.edges.iter().map(|e| FillEdge { fullness: e.fullness * f, ..e.clone() }).collect();
        LoopSetup::new(&edges, &self.o)?.finish(&self.o, self.pole_data(f, h))
    }
}
