//! `kind = "fill"`: an N-sided hole between `[surfaces.*]` filled with exact G1 (order 4)
//! or G2 (order 6) (`pdeshape_core::fill`).

use super::build::{Ctx, R, find_surface, span};
use super::raw::{NumOrExpr, RawPatch};
use super::{PatchKind, ScenePatch, SceneSurface};
use pdeshape_core::fill::{Fill, FillEdge, FillOptions};
use pdeshape_core::limits::Cap;
use pdeshape_core::spectral::SpectralOptions;
use std::sync::Arc;
use toml::Spanned;

/// Builds a fill from its edges (each an isoline of a named surface) and options.
pub(super) fn build_fill(
    ctx: &Ctx,
    pname: &str,
    key: &str,
    p: &Spanned<RawPatch>,
    surfaces: &[SceneSurface],
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
        let surf = find_surface(ctx, surfaces, &re.surface, &format!("{ek}.surface"))?;
        let s0 = ctx.num(re.s.get_ref(), span(&re.s), &format!("{ek}.s"))?;
        let [w0, w1] = re.w.get_ref();
        let w = (ctx.num(w0, span(&re.w), &format!("{ek}.w[0]"))?, ctx.num(w1, span(&re.w), &format!("{ek}.w[1]"))?);
        let f = match &re.fullness {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ek}.fullness"))?,
            None => fullness,
        };
        list.push(FillEdge { surface: surf.field.clone(), s0, w, fullness: f });
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
    };
    let fill = Fill::new(&list, &opts).map_err(|e| ctx.err(span(edges), format!("{key}.edges"), e.to_string()))?;
    let resolution = ctx.resolution(&rp.resolution, (41, 201), &format!("{key}.resolution"))?;
    let patch = fill.patch().clone();
    Ok(ScenePatch {
        name: pname.to_string(),
        kind: PatchKind::Fill,
        surface: patch.clone(),
        conditions: fill.conditions().to_vec(),
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
