//! The scene file as written: serde structures with source spans.

use indexmap::IndexMap;
use serde::Deserialize;
use toml::Spanned;

/// `[scene]`: free-text metadata.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawMeta {
    pub title: Option<String>,
    pub description: Option<String>,
    /// Paper / figure this example reproduces.
    pub reference: Option<String>,
}

/// A number or an expression text.
#[derive(Debug, Deserialize, Clone)]
#[serde(untagged)]
pub enum NumOrExpr {
    Num(f64),
    Expr(String),
}

impl NumOrExpr {
    /// The value as expression text (numbers printed exactly).
    pub fn text(&self) -> String {
        match self {
            NumOrExpr::Num(v) => format!("{v:?}"),
            NumOrExpr::Expr(s) => s.clone(),
        }
    }
}

/// `[parameters]` entry: `a = 1.5`, `b = "2*a"` or `c = { value = 1, min = 0, max = 2 }`.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub enum RawParam {
    Value(NumOrExpr),
    Full(RawParamTable),
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawParamTable {
    pub value: NumOrExpr,
    pub min: Option<f64>,
    pub max: Option<f64>,
    pub step: Option<f64>,
    pub description: Option<String>,
}

/// A v-domain: `"periodic"` or `[v0, v1]`.
#[derive(Debug, Deserialize, Clone)]
#[serde(untagged)]
pub enum RawDomain {
    Word(String),
    Range([NumOrExpr; 2]),
}

/// `[curves.NAME]`: exactly one of the source keys.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawCurve {
    /// Three expressions in `v` (and `t`).
    pub expr: Option<Spanned<[NumOrExpr; 3]>>,
    /// Cubic B-spline control points.
    pub bspline: Option<Spanned<Vec<[NumOrExpr; 3]>>>,
    /// Polyline vertices.
    pub polyline: Option<Spanned<Vec<[NumOrExpr; 3]>>>,
    /// A single point (a pole).
    pub point: Option<Spanned<[NumOrExpr; 3]>>,
    /// A linear combination of other curves, e.g. `"alpha*(d1 - p2)"`.
    pub combine: Option<Spanned<String>>,
    /// A trimline of a primary surface: its name.
    pub surface: Option<Spanned<String>>,
    /// Trimline parameter `s₀`.
    pub s: Option<Spanned<NumOrExpr>>,
    /// Trimline cross-derivative order.
    pub derivative: Option<Spanned<i64>>,
    /// Trimline reparameterisation factor `ds/du`.
    pub scale: Option<Spanned<NumOrExpr>>,
    /// B-spline/polyline: closed (periodic) curve.
    pub closed: Option<bool>,
    /// B-spline degree (default 3).
    pub degree: Option<Spanned<i64>>,
    /// Parameter range of a B-spline/polyline (default `[0, 2π]` closed, `[0, 1]` open).
    pub range: Option<Spanned<[NumOrExpr; 2]>>,
    /// An open B-spline's whole knot vector (`n + degree + 1` non-decreasing values); the
    /// curve's parameter is the knot parameter.
    pub knots: Option<Spanned<Vec<NumOrExpr>>>,
    /// An open B-spline's weights, one per control point (a rational curve).
    pub weights: Option<Spanned<Vec<NumOrExpr>>>,
}

/// `[surfaces.NAME]`: a primary parametric surface `S(s, v, t)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSurface {
    /// Three expressions in `s`, `v` (and `t`).
    pub expr: Option<Spanned<[NumOrExpr; 3]>>,
    /// A B-spline net: rows along `s`, each a list of points along `v`.
    pub bspline: Option<Spanned<Vec<Vec<[NumOrExpr; 3]>>>>,
    /// The net's degrees `[in s, in v]` (default: what the knots imply, else `[3, 3]` lowered
    /// to what the net allows).
    pub degree: Option<Spanned<[i64; 2]>>,
    /// The net's whole knot vectors `[in s, in v]` (default clamped uniform on `[0, 1]`).
    pub knots: Option<Spanned<[Vec<NumOrExpr>; 2]>>,
    /// The net's weights, rows like the points (a rational surface).
    pub weights: Option<Spanned<Vec<Vec<NumOrExpr>>>>,
    /// Range of `s` drawn in context (omit to hide the surface).
    pub s_range: Option<Spanned<[NumOrExpr; 2]>>,
    /// v domain (default periodic).
    pub v: Option<Spanned<RawDomain>>,
    /// Mesh resolution `[ns, nv]` for the context mesh.
    pub resolution: Option<Spanned<[i64; 2]>>,
}

/// One condition of a patch.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCondition {
    pub u: Spanned<NumOrExpr>,
    #[serde(default)]
    pub order: Option<Spanned<i64>>,
    pub curve: Option<Spanned<String>>,
    pub expr: Option<Spanned<[NumOrExpr; 3]>>,
    pub point: Option<Spanned<[NumOrExpr; 3]>>,
    /// Trimline of a primary surface: the surface name; `s` and `scale` as for curves.
    pub surface: Option<Spanned<String>>,
    pub s: Option<Spanned<NumOrExpr>>,
    pub scale: Option<Spanned<NumOrExpr>>,
    /// A trim curve of an earlier patch carried onto that patch: `"PATCH.CURVE"`.
    pub trim: Option<Spanned<String>>,
}

/// `[patches.NAME]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawPatch {
    pub kind: Spanned<String>,
    /// v domain (default periodic).
    pub v: Option<Spanned<RawDomain>>,
    /// Mesh resolution `[nu, nv]` (vertices).
    pub resolution: Option<Spanned<[i64; 2]>>,
    pub conditions: Option<Spanned<Vec<Spanned<RawCondition>>>>,
    /// Display colour `[r, g, b]` in 0…1.
    pub color: Option<Spanned<[f64; 3]>>,
    /// PDE patches: the shape parameter `a`.
    pub a: Option<Spanned<NumOrExpr>>,
    /// PDE patches: Fourier modes `M`.
    pub modes: Option<Spanned<i64>>,
    /// PDE patches: remainder rate `ω` (default `a (M + 1)`).
    pub omega: Option<Spanned<NumOrExpr>>,
    /// A family of position conditions (cross sections).
    pub sections: Option<Spanned<RawSections>>,
    /// Blends: operator order per component `[x, y, z]` (2, 4 or 6).
    pub orders: Option<Spanned<[i64; 3]>>,
    /// Blends: shape coefficients per component (`r + 1` numbers for order `2r`).
    pub coefficients: Option<Spanned<[Vec<NumOrExpr>; 3]>>,
    /// Blends: `"auto"`, `"exact"` or `"collocation"`.
    pub solver: Option<Spanned<String>>,
    /// Blends: bubble functions per basis function (collocation).
    pub bubbles: Option<Spanned<i64>>,
    /// Blends: collocation grid `[L, Q]`.
    pub collocation: Option<Spanned<[i64; 2]>>,
    /// Blends: explicit boundary basis functions `g_j(v)`.
    pub basis: Option<Spanned<Vec<Spanned<String>>>>,
    /// Solid blends: α (∂u⁴); β and γ are shared with dynamic blends.
    pub alpha: Option<Spanned<NumOrExpr>>,
    /// Solid blends: `"complete"` (least squares), `"galerkin"` or `"paper"`.
    pub trial: Option<Spanned<String>>,
    /// Solid blends: terms `[L, M, N]` of the correction.
    pub lmn: Option<Spanned<[i64; 3]>>,
    /// Solid blends: boundary surfaces in `(u, v)`: `x(u, v, 0)`, `x_w(u, v, 0)`, `x(u, v, 1)`,
    /// `x_w(u, v, 1)`.
    pub w0: Option<Spanned<[NumOrExpr; 3]>>,
    pub w0_tangent: Option<Spanned<[NumOrExpr; 3]>>,
    pub w1: Option<Spanned<[NumOrExpr; 3]>>,
    pub w1_tangent: Option<Spanned<[NumOrExpr; 3]>>,
    /// Solid blends: mesh vertices `[nu, nv, nw]`.
    pub cells: Option<Spanned<[i64; 3]>>,
    /// Solid blends: how far the blended (primary) solids are drawn beyond the end faces,
    /// along the cross tangents (0 hides them).
    pub primary: Option<Spanned<f64>>,
    /// Dynamic blends: the shape parameters β, γ, λ, ρ, η.
    pub beta: Option<Spanned<NumOrExpr>>,
    pub gamma: Option<Spanned<NumOrExpr>>,
    pub lambda: Option<Spanned<NumOrExpr>>,
    pub rho: Option<Spanned<NumOrExpr>>,
    pub eta: Option<Spanned<NumOrExpr>>,
    /// Dynamic blends: sine terms `K` of the collocation solver.
    pub terms: Option<Spanned<i64>>,
    /// Dynamic blends: least squares jointly over all basis functions.
    pub joint: Option<Spanned<bool>>,
    /// Dynamic blends: the time range `[t0, t1]`.
    pub time: Option<Spanned<[NumOrExpr; 2]>>,
    /// Dynamic blends: the number of animation frames (≥ 2).
    pub frames: Option<Spanned<i64>>,
    /// Trims: closed curves in `(u, v)` whose insides are removed.
    pub trim: Option<Spanned<RawTrim>>,
    /// Fills: the hole's edges, in loop order.
    pub edges: Option<Spanned<Vec<Spanned<RawEdge>>>>,
    /// Fills: a hole of an imported model, `"MODEL.holeK"`, as the whole loop.
    pub hole: Option<Spanned<String>>,
    /// Fills: the pole (default above the loop's centroid).
    pub pole: Option<Spanned<[NumOrExpr; 3]>>,
    /// Fills: factor on the default pole height.
    pub height: Option<Spanned<NumOrExpr>>,
    /// Fills: length of the cross tangent at the pole.
    pub ring: Option<Spanned<NumOrExpr>>,
    /// Fills: half-width of the corner blends, as a fraction of an edge.
    pub corner_blend: Option<Spanned<NumOrExpr>>,
    /// Fills: PDE order, 4 (G1) or 6 (G2).
    pub order: Option<Spanned<i64>>,
    /// Fills, order 6: the cap's normal curvature at the pole.
    pub pole_curvature: Option<Spanned<NumOrExpr>>,
    /// Fills: cross-tangent length relative to the loop's radius, for every edge.
    pub fullness: Option<Spanned<NumOrExpr>>,
    /// Blends: the primary surface at `u = 0` (conditions of orders 0, 1, 2 from its trimline).
    pub start: Option<Spanned<RawEnd>>,
    /// Blends: the primary surface at `u = 1`.
    pub end: Option<Spanned<RawEnd>>,
}

/// `RawPatch::KEYS` and `RawPatch::present_keys` from one list of the optional fields.
macro_rules! optional_keys {
    ($($field:ident),* $(,)?) => {
        impl RawPatch {
            /// Every optional key, in the order [`RawPatch::present_keys`] reports them.
            pub const KEYS: &'static [&'static str] = &[$(stringify!($field)),*];

            /// The optional keys given, in the order their checks report them (kind-specific
            /// keys first). `kinds::check_keys` checks each against the patch's kind, so no
            /// key is ignored.
            pub fn present_keys(&self) -> Vec<&'static str> {
                let given = [$(self.$field.is_some()),*];
                Self::KEYS.iter().zip(given).filter(|g| g.1).map(|g| *g.0).collect()
            }
        }
    };
}

optional_keys!(
    a,
    modes,
    omega,
    sections,
    orders,
    coefficients,
    solver,
    bubbles,
    collocation,
    basis,
    start,
    end,
    beta,
    gamma,
    lambda,
    rho,
    eta,
    terms,
    joint,
    time,
    frames,
    alpha,
    trial,
    lmn,
    w0,
    w0_tangent,
    w1,
    w1_tangent,
    cells,
    primary,
    edges,
    hole,
    pole,
    height,
    ring,
    corner_blend,
    fullness,
    order,
    pole_curvature,
    trim,
    conditions,
    resolution,
    v,
    color,
);

/// An edge of a fill's hole: the isoline `s` of a surface, `v` from `w[0]` to `w[1]`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEdge {
    /// The neighbouring surface (a `[surfaces.NAME]`).
    pub surface: Option<Spanned<String>>,
    /// The isoline `s = s₀`.
    pub s: Option<Spanned<NumOrExpr>>,
    /// The surface's `v` at the edge's start and end, in the loop's direction.
    pub w: Option<Spanned<[NumOrExpr; 2]>>,
    /// Or a curve `(s(t), v(t))` in the surface's domain.
    pub curve: Option<Spanned<[NumOrExpr; 2]>>,
    /// Or a trim curve `"PATCH.CURVE"` of an earlier patch.
    pub trim: Option<Spanned<String>>,
    /// Or an edge of an imported model, `"MODEL.edgeID"`, whole, run as its face runs it.
    pub edge: Option<Spanned<String>>,
    /// The face of an imported edge the fill meets, `"MODEL.faceID"` (needed when the
    /// edge bounds two faces).
    pub face: Option<Spanned<String>>,
    /// The curve's parameter at the edge's start and end (curve and trim edges).
    pub t: Option<Spanned<[NumOrExpr; 2]>>,
    /// This edge's fullness (overrides the patch's).
    pub fullness: Option<Spanned<NumOrExpr>>,
}

/// A blend end: a trimline of a primary surface.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawEnd {
    /// The primary surface.
    pub surface: Spanned<String>,
    /// The trimline `s = s₀`.
    pub s: Spanned<NumOrExpr>,
    /// `ds/du` (default 1).
    pub scale: Option<Spanned<NumOrExpr>>,
}

/// `[patches.NAME.sections]`: `count` position conditions `X(u_i, v) = C(v; s_i)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawSections {
    pub count: Spanned<i64>,
    /// `"uniform"` (u_i = i/(count−1)) or `"chebyshev"` (u_i = (1 − cos(π i/(count−1)))/2).
    pub spacing: Option<Spanned<String>>,
    /// Explicit u_i instead of a spacing.
    pub u: Option<Spanned<Vec<f64>>>,
    /// The section parameter `s_i` as an expression in the index `i` (default `i`).
    pub s: Option<Spanned<String>>,
    /// The section curve: three expressions in `v`, `s` (and `i`, `t`).
    pub expr: Spanned<[NumOrExpr; 3]>,
}

/// `[render]`: the picture.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawRender {
    /// Camera azimuth in degrees (about +z).
    pub azimuth: Option<f64>,
    /// Camera elevation in degrees.
    pub elevation: Option<f64>,
    /// Image size in pixels.
    pub size: Option<Spanned<[i64; 2]>>,
    /// Draw the mesh lines.
    pub wireframe: Option<bool>,
    /// Colour the patches by this per-vertex field.
    pub field: Option<String>,
    /// Zoom factor (> 1 zooms in).
    pub zoom: Option<f64>,
}

/// `[output]`: what `build` writes into a directory and `gallery` shows.
#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RawOutput {
    pub formats: Option<Spanned<Vec<Spanned<String>>>>,
}

/// The whole file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawScene {
    #[serde(default)]
    pub scene: RawMeta,
    #[serde(default)]
    pub parameters: IndexMap<String, Spanned<RawParam>>,
    #[serde(default)]
    pub curves: IndexMap<String, Spanned<RawCurve>>,
    #[serde(default)]
    pub surfaces: IndexMap<String, Spanned<RawSurface>>,
    #[serde(default)]
    pub patches: IndexMap<String, Spanned<RawPatch>>,
    #[serde(default)]
    pub render: RawRender,
    #[serde(default)]
    pub output: RawOutput,
    /// Parameter studies drawn as image strips in the gallery.
    #[serde(default)]
    pub studies: Vec<Spanned<RawStudy>>,
    /// CAD models whose faces, edges and holes the scene uses.
    #[serde(default)]
    pub import: IndexMap<String, Spanned<RawImport>>,
}

/// `[import.NAME]`: a CAD model.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawImport {
    /// A STEP file, relative to the scene file's folder.
    pub step: Spanned<String>,
}

/// `[[studies]]`: one picture per value of a parameter, with other parameters fixed.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawStudy {
    pub title: String,
    /// Parameters fixed for the whole study.
    #[serde(default)]
    pub set: IndexMap<String, f64>,
    /// The parameter that varies.
    pub vary: String,
    pub values: Vec<f64>,
}

/// `[patches.NAME.trim]`: trim curves and the trimmed mesh.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTrim {
    /// `[rings, columns]` of the `(ρ, φ)` grid.
    pub resolution: Option<Spanned<[i64; 2]>>,
    /// Fourier modes of the Laplace map.
    pub modes: Option<Spanned<i64>>,
    /// The curves by name.
    pub curves: IndexMap<String, Spanned<RawTrimCurve>>,
}

/// One trim curve: exactly one of the keys.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawTrimCurve {
    /// `{ center = [u, v], radius = r }` or `{ center, radii = [r_u, r_v] }`.
    pub circle: Option<Spanned<RawCircle>>,
    /// Closed cubic B-spline control points `[u, v]`.
    pub bspline: Option<Spanned<Vec<[NumOrExpr; 2]>>>,
    /// Polygon vertices `[u, v]`.
    pub polygon: Option<Spanned<Vec<[NumOrExpr; 2]>>>,
}

/// A circle or axis-aligned ellipse in `(u, v)`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawCircle {
    pub center: [NumOrExpr; 2],
    pub radius: Option<NumOrExpr>,
    pub radii: Option<[NumOrExpr; 2]>,
}
