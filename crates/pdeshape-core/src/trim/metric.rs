//! Trims meshed in the surface's metric: the parameter plane `(u, v)` stretched to
//! `(u, k v)` so that it is roughly isometric to the patch, before the Laplace map.

use super::{LaplaceMap, Rect, TrimCurve, TrimError, TrimGrid, TrimOptions, TrimRegion, trim_grid};
use crate::patch::Surface;

/// A trimmed patch's map and grid, meshed in the plane `(u, k v)`; the grid's points are
/// back in the patch's own `(u, v)`.
#[derive(Clone, Debug)]
pub struct MetricTrim {
    /// The Laplace map of the scaled region.
    pub map: LaplaceMap,
    /// The grid, in the patch's `(u, v)`.
    pub grid: TrimGrid,
    /// `[1, k]`: the factors on `u` and `v` of the plane the map lives in.
    pub scale: [f64; 2],
}

/// `k = mean |X_v| / mean |X_u|` over a 9 × 9 grid of cell centres: the factor on `v` that
/// makes the parameter plane roughly isometric to the patch, so the Laplace map and its
/// repair work on the shape the designer sees (a long body with small fin holes stays
/// meshable). 1 when either mean vanishes or the ratio is not finite.
pub fn metric_scale(s: &dyn Surface) -> f64 {
    let dom = s.v_domain();
    let (mut su, mut sv) = (0.0, 0.0);
    for i in 0..9 {
        for j in 0..9 {
            let d = s.derivatives((i as f64 + 0.5) / 9.0, dom.at((j as f64 + 0.5) / 9.0), 1, 1);
            su += d[2].norm();
            sv += d[1].norm();
        }
    }
    if su > 0.0 && sv > 0.0 && (sv / su).is_finite() { sv / su } else { 1.0 }
}

/// Validates `curves` in the patch's own parameters (errors quote its `u`, `v`), then
/// meshes the region in the metric-scaled plane. The scaling is a heuristic, so where its
/// map keeps folds after repair, the geometric mean of `k` and 1 and then the plain
/// parameter plane are tried before the first failure is returned.
pub fn trim_in_metric(
    s: &dyn Surface,
    curves: &[(String, TrimCurve)],
    o: &TrimOptions,
) -> Result<MetricTrim, TrimError> {
    let domain = s.v_domain();
    TrimRegion::new(Rect { min: [0.0, domain.start], max: [1.0, domain.end] }, curves.to_vec())?;
    let k = metric_scale(s);
    let mut first_error = None;
    for ks in [k, k.sqrt(), 1.0] {
        let scale = [1.0, ks];
        let rect = Rect { min: [0.0, domain.start * scale[1]], max: [1.0, domain.end * scale[1]] };
        let scaled: Vec<_> = curves.iter().map(|(n, c)| (n.clone(), c.scaled(scale))).collect();
        let map = LaplaceMap::new(TrimRegion::new(rect, scaled)?, o.modes, Some(o.columns));
        match trim_grid(&map, o) {
            Ok(mut grid) => {
                for p in &mut grid.points {
                    p[1] /= scale[1];
                }
                return Ok(MetricTrim { map, grid, scale });
            }
            Err(e) => {
                first_error.get_or_insert(e);
                if k == 1.0 {
                    break;
                }
            }
        }
    }
    Err(first_error.expect("at least one attempt"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Vec3;
    use crate::patch::VDomain;

    /// The plane `X = (A u, B v, 0)`: `|X_u| = A`, `|X_v| = B` everywhere.
    struct Plane(f64, f64);

    impl Surface for Plane {
        fn v_domain(&self) -> VDomain {
            VDomain::open(0.0, 1.0)
        }
        fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
            let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1)];
            out[0] = Vec3::new(self.0 * u, self.1 * v, 0.0);
            if dv >= 1 {
                out[1] = Vec3::new(0.0, self.1, 0.0);
            }
            if du >= 1 {
                out[dv + 1] = Vec3::new(self.0, 0.0, 0.0);
            }
            out
        }
    }

    #[test]
    fn a_stretched_plane_is_meshed_in_its_own_metric() {
        // k = B / A exactly (81 equal terms each; a power-of-two ratio is exact in f64)
        assert_eq!(metric_scale(&Plane(2.0, 8.0)), 4.0);
        assert_eq!(metric_scale(&Plane(0.0, 1.0)), 1.0, "a degenerate direction falls back to 1");
        let hole = vec![("c".to_string(), TrimCurve::ellipse([0.5, 0.5], [0.1, 0.025]))];
        let o = TrimOptions { rings: 12, columns: 48, modes: 8, ..Default::default() };
        let t = trim_in_metric(&Plane(1.0, 4.0), &hole, &o).unwrap();
        assert_eq!(t.scale, [1.0, 4.0]);
        // the grid is back in (u, v): its first ring lies on the ellipse to the polygon's
        // accuracy, and every point is inside the unit square
        for p in &t.grid.points[..o.columns] {
            let r = ((p[0] - 0.5) / 0.1).powi(2) + ((p[1] - 0.5) / 0.025).powi(2);
            assert!((r - 1.0).abs() < 1e-3, "{p:?}: {r}");
        }
        assert!(t.grid.points.iter().all(|p| (0.0..=1.0).contains(&p[0]) && (0.0..=1.0).contains(&p[1])));
        // a curve leaving the domain is refused in the patch's own parameters
        let out = vec![("c".to_string(), TrimCurve::ellipse([0.95, 0.5], [0.1, 0.1]))];
        assert!(matches!(trim_in_metric(&Plane(1.0, 4.0), &out, &o), Err(TrimError::LeavesDomain { .. })));
    }
}
