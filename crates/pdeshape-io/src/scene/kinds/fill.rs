//! `kind = "fill"`: an N-sided hole between `[surfaces.*]` filled with exact G1 (order 4)
//! or G2 (order 6) (`pdeshape_core::fill`).

use super::PatchInput;
use crate::scene::ctx::{Ctx, R, find_surface, span};
use crate::scene::raw::{NumOrExpr, RawPatch};
use crate::scene::trim::find_trim_curve;
use crate::scene::{PatchKind, ScenePatch, SceneSurface};
use pdeshape_core::data::FieldRef;
use pdeshape_core::fill::{AlongCurve, DomainCurve, Fill, FillEdge, FillOptions, Host};
use pdeshape_core::limits::Cap;
use pdeshape_core::spectral::SpectralOptions;
use std::sync::Arc;
use toml::Spanned;

/// The keys a `kind = "fill"` patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] = &[
    "resolution",
    "edges",
    "pole",
    "height",
    "ring",
    "corner_blend",
    "fullness",
    "order",
    "pole_curvature",
    "a",
    "modes",
    "omega",
];

/// Keys it refuses, with the reason.
pub(super) const INSTEAD: &[(&str, &str)] = &[
    ("conditions", "a fill takes `edges` instead of `conditions`"),
    ("trim", "trims apply to hermite, pde and blend patches (not to moving, solid or fill ones)"),
];

const EDGE_FORMS: &str = "{ surface, s, w } (an isoline), { surface, curve = [s(t), v(t)], t } (a curve in the surface's domain) or { trim = \"PATCH.CURVE\", t } (an earlier patch's trim curve, t in [0, 2π])";

/// Builds the fill from its own keys.
pub(super) fn build(input: &PatchInput) -> R<ScenePatch> {
    build_fill(input.ctx, input.name, &input.key, input.raw, input.surfaces, input.done)
}

/// Builds a fill from its edges (isolines or curves of named surfaces, trim curves of
/// earlier patches) and options.
pub(super) fn build_fill(
    ctx: &Ctx,
    pname: &str,
    key: &str,
    p: &Spanned<RawPatch>,
    surfaces: &[SceneSurface],
    done: &[ScenePatch],
) -> R<ScenePatch> {
    let rp = p.get_ref();
    if let Some(c) = &rp.conditions {
        return Err(ctx.err(span(c), format!("{key}.conditions"), "a fill takes `edges` instead of `conditions`"));
    }
    let Some(edges) = &rp.edges else {
        return Err(ctx.err(
            span(p),
            format!("{key}.edges"),
            "a fill needs `edges`: the hole's boundary, in loop order",
        ));
    };
    let num = |x: &Option<Spanned<NumOrExpr>>, k: &str, default: f64| -> R<f64> {
        match x {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.{k}")),
            None => Ok(default),
        }
    };
    let fullness = num(&rp.fullness, "fullness", 1.0)?;
    let mut list = Vec::new();
    for (i, e) in edges.get_ref().iter().enumerate() {
        let ek = format!("{key}.edges[{i}]");
        let re = e.get_ref();
        let range = |x: &Spanned<[NumOrExpr; 2]>, k: &str| -> R<(f64, f64)> {
            let [a, b] = x.get_ref();
            Ok((ctx.num(a, span(x), &format!("{ek}.{k}[0]"))?, ctx.num(b, span(x), &format!("{ek}.{k}[1]"))?))
        };
        let form = |what: &str| ctx.err(span(e), ek.clone(), format!("{what}; an edge is {EDGE_FORMS}"));
        let (surface, s0, w): (FieldRef, f64, (f64, f64)) = match (&re.surface, &re.curve, &re.trim) {
            (Some(name), None, None) => {
                let (Some(s), Some(w), None) = (&re.s, &re.w, &re.t) else {
                    return Err(form("an isoline edge takes `s` and `w` (not `t`)"));
                };
                let surf = find_surface(ctx, surfaces, name, &format!("{ek}.surface"))?;
                (surf.field.clone(), ctx.num(s.get_ref(), span(s), &format!("{ek}.s"))?, range(w, "w")?)
            }
            (Some(name), Some(curve), None) => {
                let (None, None, Some(t)) = (&re.s, &re.w, &re.t) else {
                    return Err(form("a curve edge takes `t` (not `s` or `w`)"));
                };
                let surf = find_surface(ctx, surfaces, name, &format!("{ek}.surface"))?;
                let c = ctx.field2(curve, &["t"], &format!("{ek}.curve"))?;
                let along =
                    AlongCurve { host: Host::Field(surf.field.clone()), curve: DomainCurve::Field(Arc::new(c)) };
                (Arc::new(along), 0.0, range(t, "t")?)
            }
            (None, None, Some(trim)) => {
                let (None, None, Some(t)) = (&re.s, &re.w, &re.t) else {
                    return Err(form("a trim edge takes `t` (not `s` or `w`)"));
                };
                let (patch, curve) = find_trim_curve(ctx, trim, &format!("{ek}.trim"), done)?;
                let along = AlongCurve { host: Host::Patch(patch), curve: DomainCurve::Trim(curve) };
                (Arc::new(along), 0.0, range(t, "t")?)
            }
            _ => return Err(form("`surface`, `curve` and `trim` do not combine so")),
        };
        let f = match &re.fullness {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ek}.fullness"))?,
            None => fullness,
        };
        list.push(FillEdge { surface, s0, w, fullness: f, side: None });
    }
    let a = num(&rp.a, "a", 1.0)?;
    let modes = match &rp.modes {
        Some(m) => ctx.capped(m, 0, Cap::Modes, &format!("{key}.modes"))?,
        None => 12,
    };
    let omega = rp.omega.as_ref().map(|x| ctx.num(x.get_ref(), span(x), &format!("{key}.omega"))).transpose()?;
    let pole = rp.pole.as_ref().map(|x| ctx.vec3(x.get_ref(), span(x), &format!("{key}.pole"))).transpose()?;
    let opts = FillOptions {
        corner_blend: num(&rp.corner_blend, "corner_blend", 0.25)?,
        pole,
        height: num(&rp.height, "height", 1.0)?,
        ring: rp.ring.as_ref().map(|x| ctx.num(x.get_ref(), span(x), &format!("{key}.ring"))).transpose()?,
        t: 0.0,
        order: match &rp.order {
            Some(o) => match *o.get_ref() {
                4 => 4,
                6 => 6,
                x => {
                    return Err(ctx.err(
                        span(o),
                        format!("{key}.order"),
                        format!("a fill's order is 4 (G1) or 6 (G2), not {x}"),
                    ));
                }
            },
            None => 4,
        },
        pole_curvature: rp
            .pole_curvature
            .as_ref()
            .map(|x| ctx.num(x.get_ref(), span(x), &format!("{key}.pole_curvature")))
            .transpose()?,
        spectral: SpectralOptions { a, modes, omega },
        split_creases: true,
    };
    let fill = Fill::new(&list, &opts).map_err(|e| ctx.err(span(edges), format!("{key}.edges"), e.to_string()))?;
    let resolution = ctx.resolution(&rp.resolution, (41, 201), &format!("{key}.resolution"))?;
    let patch = fill.patch().clone();
    Ok(ScenePatch {
        name: pname.to_string(),
        kind: PatchKind::Fill,
        surface: patch.clone(),
        conditions: fill.conditions().to_vec(),
        solver: "spectral".into(),
        resolution,
        color: rp.color.as_ref().map(|c| *c.get_ref()),
        spectral: Some(patch),
        sections: None,
        blend: None,
        dynamic: None,
        solid: None,
        trim: None,
        fill: Some(Arc::new(fill)),
    })
}
