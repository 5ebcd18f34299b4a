//! Trimming of patches by closed curves in the `(u, v)` parameter domain (SPEC §7,
//! paper 003).
//!
//! A trim removes the insides of one or more closed curves ([`TrimCurve`]: ellipses,
//! closed cubic B-splines, polygons) from a patch. The remaining region is meshed without
//! triangulation:
//!
//! 1. [`TrimRegion`] validates the curves (inside the domain, simple, disjoint, not
//!    nested) and joins several of them into one closed loop `C₁` by bridge segments
//!    traversed both ways (paper 003, Fig. 7);
//! 2. [`LaplaceMap`] solves `(∂ρ² + ∂φ²) M = 0` between `C₁` (`ρ = 0`) and the domain
//!    border `C₂` (`ρ = 1`) by Fourier modes in a bounded exponential basis plus a
//!    remainder that meets both curves exactly;
//! 3. [`trim_grid`] maps a structured `(ρ, φ)` grid, detects folded cells (corner
//!    Jacobians) and repairs them by Winslow smoothing of the interior rings;
//! 4. [`trimmed_mesh`] maps the grid by the patch, with exact normals.
//!
//! ```
//! use pdeshape_core::trim::{LaplaceMap, Rect, TrimCurve, TrimOptions, TrimRegion, trim_grid};
//! let domain = Rect { min: [0.0, 0.0], max: [1.0, 1.0] };
//! let hole = TrimCurve::ellipse([0.5, 0.5], [0.2, 0.2]);
//! let region = TrimRegion::new(domain, vec![("hole".into(), hole)]).unwrap();
//! let map = LaplaceMap::new(region, 8, Some(32));
//! let g = trim_grid(&map, &TrimOptions { rings: 10, columns: 32, ..Default::default() }).unwrap();
//! assert_eq!(g.report.folds_after, 0);
//! // ring 0 lies on the circle
//! let p = g.points[5];
//! assert!(((p[0] - 0.5).hypot(p[1] - 0.5) - 0.2).abs() < 1e-12);
//! ```

mod curve;
mod grid;
mod laplace;
mod metric;
mod on_surface;
mod param;
mod region;
#[cfg(test)]
mod tests;

pub use curve::{TrimCurve, Uv, distance_to_polygon, inside_polygon, signed_area2};
pub use grid::{TrimGrid, TrimOptions, TrimReport, count_folds, is_folded, reflex_corner, trim_grid, trimmed_mesh};
pub use laplace::{FFT_SAMPLES, LaplaceMap};
pub use metric::{MetricTrim, metric_scale, trim_in_metric};
pub use on_surface::CurveOnSurface;
pub use param::{ARC_WEIGHT, ARC_WEIGHT_BRIDGED};
pub use region::{Piece, Rect, TrimRegion};

/// Invalid trims and meshing failures.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TrimError {
    /// No curves given.
    #[error("a trim needs at least one curve")]
    NoCurves,
    /// The domain rectangle is empty.
    #[error("the patch's parameter domain is empty")]
    BadDomain,
    /// A curve has non-finite points.
    #[error("trim curve `{curve}` is not finite")]
    NotFinite {
        /// Curve name.
        curve: String,
    },
    /// A curve leaves (or touches) the domain.
    #[error(
        "trim curve `{curve}` leaves the parameter domain [{}, {}] × [{}, {}] at (u, v) = ({:.6}, {:.6}) (t = {t:.4}); trim curves must lie strictly inside",
        domain.min[0], domain.max[0], domain.min[1], domain.max[1], at[0], at[1]
    )]
    LeavesDomain {
        /// Curve name.
        curve: String,
        /// Curve parameter.
        t: f64,
        /// The point outside.
        at: Uv,
        /// The domain.
        domain: Rect,
    },
    /// A curve encloses no area.
    #[error("trim curve `{curve}` encloses no area")]
    Degenerate {
        /// Curve name.
        curve: String,
    },
    /// A curve has a cusp or turns back along itself.
    #[error(
        "trim curve `{curve}` has a cusp or turns back on itself near (u, v) = ({:.6}, {:.6}); move the control points apart",
        at[0], at[1]
    )]
    Cusp {
        /// Curve name.
        curve: String,
        /// Near here.
        at: Uv,
    },
    /// A curve crosses itself.
    #[error("trim curve `{curve}` intersects itself near (u, v) = ({:.6}, {:.6})", at[0], at[1])]
    SelfIntersection {
        /// Curve name.
        curve: String,
        /// Near here.
        at: Uv,
    },
    /// Two curves cross.
    #[error("trim curves `{a}` and `{b}` intersect near (u, v) = ({:.6}, {:.6})", at[0], at[1])]
    CurvesIntersect {
        /// First curve.
        a: String,
        /// Second curve.
        b: String,
        /// Near here.
        at: Uv,
    },
    /// One curve lies inside another.
    #[error("trim curve `{inner}` lies inside trim curve `{outer}` (nested trims are not supported)")]
    Nested {
        /// The inner curve.
        inner: String,
        /// The outer curve.
        outer: String,
    },
    /// The straight bridge between two curves would cross something.
    #[error("the bridge joining trim curves `{a}` and `{b}` would cross {crossed}; move the curves apart")]
    BridgeCrosses {
        /// One end.
        a: String,
        /// Other end.
        b: String,
        /// What it crosses.
        crossed: String,
    },
    /// Too few rings or columns.
    #[error("a trimmed mesh needs at least 2 rings and 8 columns, got {rings} × {columns}")]
    Resolution {
        /// Rings.
        rings: usize,
        /// Columns.
        columns: usize,
    },
    /// Smoothing did not remove every fold.
    #[error(
        "{folds} folded cells and {inside} vertices inside trims remain after {sweeps} smoothing sweeps; raise the rings/columns or smooth the trim curve"
    )]
    CannotRepair {
        /// Folded cells left.
        folds: usize,
        /// Vertices inside holes left.
        inside: usize,
        /// Sweeps used.
        sweeps: usize,
    },
}
