//! The typed diagnostics report of a scene: what `check` prints (text and `--json`), what
//! the gallery tabulates, what the editor marks and what Python receives as a dict.
//!
//! [`super::diagnose`] computes it once; printers read these fields, never JSON keys. A
//! field that was not computed is `None` and left out of the JSON; a computed value that is
//! NaN or infinite stays NaN in memory and is written as JSON `null` (serde_json's rule),
//! which the tests refuse.
//!
//! The JSON keys are those of the report before it was typed (the tests of `check --json`
//! read them); field order is the order below.

use crate::scene::PatchKind;
use indexmap::IndexMap;
use pdeshape_core::blend::Gaps;
use serde::Serialize;

/// The report of a whole scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneReport {
    /// The scene's name (its file stem).
    pub scene: String,
    /// Its title, `null` when it has none.
    pub title: Option<String>,
    /// Parameter values by name, in the scene's order.
    pub parameters: IndexMap<String, f64>,
    /// One report per patch, in the scene's order.
    pub patches: Vec<PatchReport>,
    /// The CAD fit (`check --cad`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cad: Option<crate::cad::CadReport>,
}

impl SceneReport {
    /// The first patch whose condition check is not finite (NaN or infinite).
    pub fn first_not_finite(&self) -> Option<&PatchReport> {
        self.patches.iter().find(|p| !(p.condition_error.max_abs.is_finite() && p.condition_error.max_rel.is_finite()))
    }

    /// The report as a JSON value (NaN as `null`).
    pub fn to_json(&self) -> serde_json::Value {
        // Serialising plain structs of numbers, strings and maps cannot fail.
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}

impl PatchReport {
    /// The report as a JSON value (NaN as `null`), as `check --json` writes it.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::to_value(self).unwrap_or(serde_json::Value::Null)
    }
}

/// The report of one patch. Sections that do not apply to the patch's kind are `None`.
#[derive(Clone, Debug, Serialize)]
pub struct PatchReport {
    /// Name.
    pub name: String,
    /// Kind, as in scene files.
    pub kind: PatchKind,
    /// The solve's path: `hermite-interpolation`, `spectral`, `exact`, `collocation`,
    /// `mixed (x: …, y: …, z: …)`, a dynamic blend's or a solid's method.
    pub solver: String,
    /// The conditions, as where and which derivative.
    pub conditions: Vec<ConditionKey>,
    /// The `v` domain (surfaces).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub v_domain: Option<VDomain>,
    /// Mesh resolution `[nu, nv]` (surfaces).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolution: Option<[usize; 2]>,
    /// How well the conditions are met.
    pub condition_error: ConditionError,
    /// What the user should know, in sentences.
    pub warnings: Vec<String>,
    /// Trimmed patches: the map and its grid's quality.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trim: Option<TrimReport>,
    /// Patches given by `sections`: the largest distance to the section family between
    /// sections (at the fractional section index).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section_reference_distance: Option<f64>,
    /// The same with `s` linear in `u` between sections.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section_reference_distance_linear_s: Option<f64>,
    /// Where the distance is largest.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub section_reference_worst: Option<SectionWorst>,
    /// Static blends: the components' solves.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blend: Option<BlendReport>,
    /// Blends and patches standing on other surfaces: the seams.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub continuity: Option<ContinuityReport>,
    /// Fills: edge continuity, corners, pole.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fill: Option<FillReport>,
    /// Dynamic blends: operator, solve and every frame's check.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dynamic: Option<DynamicReport>,
    /// PDE patches (and fills): modes, their solve paths and residuals.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spectral: Option<SpectralReport>,
    /// Solids: the solve.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub solid: Option<SolidReport>,
    /// Solids: volume, centroid, inertia, Jacobian range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mass_properties: Option<MassReport>,
}

/// Where a condition holds and which derivative it sets.
#[derive(Clone, Copy, Debug, Serialize)]
#[serde(untagged)]
pub enum ConditionKey {
    /// A surface's condition on the line `u`.
    Surface {
        /// The line.
        u: f64,
        /// The derivative `∂ᵏ/∂uᵏ`.
        order: usize,
    },
    /// A solid's condition on the face `w`.
    Solid {
        /// The face (0 or 1).
        w: u8,
        /// The derivative `∂ᵏ/∂wᵏ`.
        order: usize,
    },
}

/// The `v` domain of a surface.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct VDomain {
    /// Start.
    pub start: f64,
    /// End.
    pub end: f64,
    /// Whether the surface is periodic in `v`.
    pub periodic: bool,
}

/// How well a patch meets its conditions, at `samples` points per condition.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ConditionError {
    /// Points per condition (a solid: points per face).
    pub samples: usize,
    /// Largest `|X − data|`.
    pub max_abs: f64,
    /// `max_abs` over `patch_size`.
    pub max_rel: f64,
    /// The largest data value (the scale of the patch).
    pub patch_size: f64,
}

/// Where the distance to the section family is largest.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SectionWorst {
    /// Patch parameter.
    pub u: f64,
    /// Patch parameter.
    pub v: f64,
    /// Section parameter there.
    pub s: f64,
}

/// The trim of a patch.
#[derive(Clone, Debug, Serialize)]
pub struct TrimReport {
    /// The trim curves' names.
    pub curves: Vec<String>,
    /// Bridges cut to join the holes to the border.
    pub bridges: usize,
    /// The map works in `(u·k₀, v·k₁)`.
    pub metric_scale: [f64; 2],
    /// Grid rings.
    pub rings: usize,
    /// Grid columns.
    pub columns: usize,
    /// Fourier modes of the map.
    pub modes: usize,
    /// The map's `ω`.
    pub omega: f64,
    /// Folded cells before repair.
    pub folds_before: usize,
    /// Folded cells after repair.
    pub folds_after: usize,
    /// Grid points inside holes before repair.
    pub inside_before: usize,
    /// Grid points inside holes after repair.
    pub inside_after: usize,
    /// Winslow sweeps.
    pub repair_sweeps: usize,
    /// Local untangling moves.
    pub untangle_moves: usize,
    /// Smallest cell angle (degrees).
    pub min_angle_deg: f64,
    /// Largest cell angle (degrees).
    pub max_angle_deg: f64,
    /// Grid area over region area.
    pub area_ratio: f64,
    /// Largest over smallest cell area.
    pub cell_area_ratio: f64,
    /// Largest distance from the grid's boundary to the trim loop (parameter space).
    pub boundary_error: f64,
}

/// A static blend's solves.
#[derive(Clone, Debug, Serialize)]
pub struct BlendReport {
    /// `x`, `y`, `z`.
    pub components: Vec<ComponentReport>,
    /// When both solvers apply: how far apart their surfaces are.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exact_vs_collocation_max_distance: Option<f64>,
}

/// One component's solve.
#[derive(Clone, Debug, Serialize)]
pub struct ComponentReport {
    /// `x`, `y` or `z`.
    pub component: &'static str,
    /// Order of its operator.
    pub order: usize,
    /// The operator's coefficients.
    pub coefficients: Vec<f64>,
    /// Whether the operator is elliptic.
    pub elliptic: bool,
    /// `exact` or `collocation`.
    pub solver: &'static str,
    /// Whether the exact solver applies to these data.
    pub exact_available: bool,
    /// The basis functions by name.
    pub basis: Vec<String>,
    /// Condition number of the solve.
    pub condition_number: f64,
    /// Collocation: RMS PDE residual.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collocation_rms_residual: Option<f64>,
    /// Collocation: the grid and the bubbles.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collocation: Option<Collocation>,
}

/// A collocation grid.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Collocation {
    /// Points in `u`.
    pub u_points: usize,
    /// Points in `v`.
    pub v_points: usize,
    /// Bubble functions.
    pub bubbles: usize,
}

/// A patch's seams: the gaps at each end, the class, the worst places.
#[derive(Clone, Debug, Serialize)]
pub struct ContinuityReport {
    /// `C0`, `G1`, `C1`, `G2`, `C2` or `none` (`blend::ContinuityClass`).
    pub class: &'static str,
    /// Points per seam.
    pub samples: usize,
    /// What the seams join (a patch standing on other surfaces).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub with: Option<&'static str>,
    /// The seam at `u = 0`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub start: Option<GapsReport>,
    /// The seam at `u = 1`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end: Option<GapsReport>,
    /// Per measure, the worst place over both seams (the editor's markers).
    pub worst: WorstPlaces,
}

/// The largest gaps of one seam; a measure the data do not define is `None`.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct GapsReport {
    /// Position gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c0: Option<f64>,
    /// First-derivative gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c1: Option<f64>,
    /// Normal angle (radians).
    #[serde(rename = "g1_radians", skip_serializing_if = "Option::is_none")]
    pub g1: Option<f64>,
    /// Second-derivative gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c2: Option<f64>,
    /// Normal-curvature gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub g2: Option<f64>,
}

impl From<Gaps> for GapsReport {
    fn from(g: Gaps) -> Self {
        GapsReport { c0: g.c0, c1: g.c1, g1: g.g1, c2: g.c2, g2: g.g2 }
    }
}

/// Per measure, the worst place over a patch's seams.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct WorstPlaces {
    /// Position gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c0: Option<WorstPlace>,
    /// First-derivative gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c1: Option<WorstPlace>,
    /// Normal angle (radians).
    #[serde(rename = "g1_radians", skip_serializing_if = "Option::is_none")]
    pub g1: Option<WorstPlace>,
    /// Second-derivative gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub c2: Option<WorstPlace>,
    /// Normal-curvature gap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub g2: Option<WorstPlace>,
}

/// The worst place of one measure.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct WorstPlace {
    /// `start` (`u = 0`) or `end` (`u = 1`).
    pub end: &'static str,
    /// The seam's `u`.
    pub u: f64,
    /// Where along it.
    pub v: f64,
    /// The point there.
    pub point: [f64; 3],
    /// The measure's value there.
    pub value: f64,
}

/// A fill's edges, corners and pole.
#[derive(Clone, Debug, Serialize)]
pub struct FillReport {
    /// Edges (sides of the hole).
    pub edges: usize,
    /// Points checked along all edges.
    pub edge_samples: usize,
    /// Largest normal angle to the neighbours (radians).
    pub g1_max_radians: f64,
    /// Largest position gap over the loop's mean radius.
    pub gap_max_relative: f64,
    /// Largest normal-curvature gap (relative).
    pub g2_max_relative: f64,
    /// The patch's order.
    pub order: usize,
    /// At each corner, the angle between the two neighbours' normals.
    pub corner_normal_angles_radians: Vec<f64>,
    /// Folded cells of a 41 × 400 grid.
    pub folds: usize,
    /// The fill's own continuity on a 41 × 4000 grid: the largest step between
    /// neighbouring points over the spacing times the larger derivative at its ends
    /// (`Fill::tear`): about 1 where the fill is smooth, far above where it jumps.
    pub tear_ratio_max: f64,
    /// The pole.
    pub pole: [f64; 3],
    /// The loop's mean radius.
    pub loop_radius: f64,
    /// G2 fills: the pole's curvature.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pole_curvature: Option<f64>,
    /// G2 fills: per corner, the neighbours' normal-curvature gap across it (relative).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub corner_curvature_gaps_relative: Option<Vec<f64>>,
}

/// A dynamic blend's operator, solve and frames.
#[derive(Clone, Debug, Serialize)]
pub struct DynamicReport {
    /// `β, γ, λ, ρ, η`.
    pub operator: DynamicOperator,
    /// The first solved frame's solver.
    pub solver: String,
    /// Whether the closed form applies.
    pub exact_available: bool,
    /// The basis functions by name.
    pub basis: Vec<String>,
    /// Condition number of the first solved frame.
    pub condition_number: f64,
    /// `[t0, t1]`.
    pub time: [f64; 2],
    /// Every frame's check.
    pub frames: Vec<FrameCheck>,
}

/// The dynamic operator's coefficients.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct DynamicOperator {
    /// `β`.
    pub beta: f64,
    /// `γ`.
    pub gamma: f64,
    /// `λ`.
    pub lambda: f64,
    /// `ρ`.
    pub rho: f64,
    /// `η`.
    pub eta: f64,
}

/// One frame's condition check, or why it could not be solved.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum FrameCheck {
    /// Solved and checked.
    Checked {
        /// The frame's time.
        t: f64,
        /// Largest `|X − data|`.
        max_abs: f64,
        /// Relative.
        max_rel: f64,
    },
    /// Not solved.
    Failed {
        /// The frame's time.
        t: f64,
        /// Why.
        error: String,
    },
}

/// A spectral patch's modes, solve paths and residuals.
#[derive(Clone, Debug, Serialize)]
pub struct SpectralReport {
    /// PDE order `2N`.
    pub order: usize,
    /// Fourier modes `M`.
    pub modes: usize,
    /// The modes solved and summed (`0 … modes_kept`): `M`, or the largest degree of the
    /// data when every datum is proved a trigonometric polynomial (the modes above, and the
    /// remainder, are then identically zero: their paths read "none: no data of this degree").
    pub modes_kept: usize,
    /// The remainder's `ω`.
    pub omega: f64,
    /// The worst mode's condition number.
    pub max_mode_condition_number: f64,
    /// Modes solved in f64.
    pub modes_solved_in_f64: usize,
    /// Modes solved in multiple precision.
    pub modes_solved_in_multiprecision: usize,
    /// Each mode's solve path.
    pub mode_paths: Vec<&'static str>,
    /// The truncated part's PDE residual per mode, relative, from the modes' Chebyshev
    /// coefficients (every order; the last entry is the remainder's functions).
    pub mode_residuals_relative: Vec<f64>,
    /// The largest of the modes' residuals.
    pub truncated_residual_relative: f64,
    /// Lebesgue constant of the condition set, mode 0.
    pub lebesgue_mode0: f64,
    /// The same for modes ≥ 1 when it differs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lebesgue_mode1: Option<f64>,
    /// RMS PDE residual of the truncated part on an interior grid (orders ≤ 20).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_residual_truncated: Option<f64>,
    /// The same for the remainder.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_residual_remainder: Option<f64>,
    /// The same for the whole patch.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rms_residual_whole: Option<f64>,
}

/// A solid's solve.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SolidReport {
    /// Terms `[L, M, N]`.
    pub terms: [usize; 3],
    /// Condition number of the solve.
    pub condition_number: f64,
    /// The largest coefficient.
    pub max_coefficient: f64,
    /// RMS PDE residual at interior points.
    pub rms_residual: f64,
    /// Mesh cells `[nu, nv, nw]`.
    pub cells: [usize; 3],
}

/// A solid's mass properties.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct MassReport {
    /// Volume.
    pub volume: f64,
    /// Centroid.
    pub centroid: [f64; 3],
    /// Inertia tensor about the centroid.
    pub inertia: [[f64; 3]; 3],
    /// Smallest `det J`.
    pub min_jacobian: f64,
    /// Largest `det J`.
    pub max_jacobian: f64,
    /// Whether `det J` changes sign.
    pub folds: bool,
}
