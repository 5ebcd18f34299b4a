//! `kind = "fill"`: an N-sided hole between `[surfaces.*]` filled with exact G1 (order 4)
//! or G2 (order 6) (`pdeshape_core::fill`).

use super::PatchInput;
use crate::scene::ctx::{Ctx, R, find_surface, span};
use crate::scene::import::{find_edge_use, find_hole};
use crate::scene::raw::{NumOrExpr, RawPatch};
use crate::scene::trim::find_trim_curve;
use crate::scene::{PatchHole, PatchKind, SceneImport, ScenePatch, SceneSurface};
use pdeshape_core::brep::{HoleKind, HoleUse, edge_pieces, pieces_per_edge};
use pdeshape_core::num::max_nan;
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
    "hole",
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

const EDGE_FORMS: &str = "{ surface, s, w } (an isoline), { surface, curve = [s(t), v(t)], t } (a curve in the surface's domain), { trim = \"PATCH.CURVE\", t } (an earlier patch's trim curve, t in [0, 2π]) or { edge = \"MODEL.edgeID\" } (an imported model's edge, with `face` when it bounds two)";

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
    if let (Some(h), Some(_)) = (&rp.hole, &rp.edges) {
        return Err(ctx.err(span(h), format!("{key}.hole"), "give `hole` or `edges`, not both: the hole is the loop"));
    }
    let loop_span = match (&rp.hole, &rp.edges) {
        (Some(h), _) => span(h),
        (_, Some(e)) => span(e),
        (None, None) => {
            return Err(ctx.err(
                span(p),
                format!("{key}.edges"),
                "a fill needs `edges` (the hole's boundary, in loop order) or `hole` (an imported model's hole)",
            ));
        }
    };
    let num = |x: &Option<Spanned<NumOrExpr>>, k: &str, default: f64| -> R<f64> {
        match x {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.{k}")),
            None => Ok(default),
        }
    };
    let fullness = num(&rp.fullness, "fullness", 1.0)?;
    let mut list = Vec::new();
    // the imported edges used, by import (to find the hole they close) and how far the
    // file's edges lie off their faces
    let mut imported: Vec<Option<(String, HoleUse)>> = Vec::new();
    let mut edge_offset: f64 = 0.0;
    if let Some(h) = &rp.hole {
        let hk = format!("{key}.hole");
        let (imp, hole) = find_hole(ctx, &ctx.imports, h, &hk)?;
        let cuts = pieces_per_edge(hole.uses.len());
        for u in &hole.uses {
            let p = edge_pieces(&imp.model.model.brep, u, cuts, 0.0).map_err(|e| ctx.err(span(h), &hk, e.to_string()))?;
            edge_offset = max_nan(edge_offset, p.offset);
            list.extend(p.edges.into_iter().map(|e| FillEdge { fullness, ..e }));
            imported.push(Some((imp.name.clone(), *u)));
        }
    }
    let no_edges = Vec::new();
    let edges = rp.edges.as_ref().map_or(&no_edges, |e| e.get_ref());
    // where the last imported edge ended (its model and vertex), to name a break in the chain
    let mut chain: Option<(String, usize, usize)> = None;
    for (i, e) in edges.iter().enumerate() {
        let ek = format!("{key}.edges[{i}]");
        let re = e.get_ref();
        if let Some(edge) = &re.edge {
            if re.surface.is_some() || re.curve.is_some() || re.trim.is_some() {
                return Err(ctx.err(span(e), ek, format!("`edge` takes no `surface`, `curve` or `trim`; an edge is {EDGE_FORMS}")));
            }
            if let Some(x) = re.s.as_ref().map(span).or(re.w.as_ref().map(span)).or(re.t.as_ref().map(span)) {
                return Err(ctx.err(x, ek, "an imported edge is taken whole, as its face runs it: it takes no `s`, `w` or `t`"));
            }
            let (imp, u) = find_edge_use(ctx, &ctx.imports, edge, re.face.as_ref(), &ek)?;
            let b = &imp.model.model.brep;
            let be = &b.edges[u.edge];
            let (start, end) = if u.forward { (be.vertices[0], be.vertices[1]) } else { (be.vertices[1], be.vertices[0]) };
            if let Some((m, at, prev)) = &chain
                && *m == imp.name
                && *at != start
            {
                return Err(ctx.err(
                    span(e),
                    ek,
                    format!(
                        "edge #{} does not start where the edge before it ({}) ends: as their faces run them, #{} ends at vertex #{} and #{} starts at vertex #{}",
                        be.id, b.edges[*prev].id, b.edges[*prev].id, b.vertices[*at].0, be.id, b.vertices[start].0
                    ),
                ));
            }
            chain = Some((imp.name.clone(), end, u.edge));
            let f = match &re.fullness {
                Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ek}.fullness"))?,
                None => fullness,
            };
            let p = edge_pieces(b, &u, pieces_per_edge(edges.len()), 0.0)
                .map_err(|err| ctx.err(span(e), &ek, err.to_string()))?;
            edge_offset = max_nan(edge_offset, p.offset);
            list.extend(p.edges.into_iter().map(|e| FillEdge { fullness: f, ..e }));
            imported.push(Some((imp.name.clone(), u)));
            continue;
        }
        chain = None;
        imported.push(None);
        if let Some(f) = &re.face {
            return Err(ctx.err(span(f), format!("{ek}.face"), "`face` names the face of an imported `edge`"));
        }
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
        list.push(FillEdge { surface, s0, w, fullness: f, side: None, smooth: false });
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
    let loop_key = if rp.hole.is_some() { "hole" } else { "edges" };
    let fill = Fill::new(&list, &opts).map_err(|e| ctx.err(loop_span, format!("{key}.{loop_key}"), e.to_string()))?;
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
        hole: closed_hole(&ctx.imports, &imported).map(|(import, hole)| PatchHole {
            import,
            hole,
            order: opts.order,
            edge_offset,
        }),
    })
}

/// The import and the number (from 1) of the hole whose loop is exactly the edges `used`
/// (each with the import's name; `None` for an edge not imported), if any.
fn closed_hole(imports: &[SceneImport], used: &[Option<(String, HoleUse)>]) -> Option<(String, usize)> {
    let used: Vec<&(String, HoleUse)> = used.iter().map(Option::as_ref).collect::<Option<Vec<_>>>()?;
    let name = &used.first()?.0;
    if used.iter().any(|(n, _)| n != name) {
        return None;
    }
    let imp = imports.iter().find(|i| i.name == *name)?;
    let mut mine: Vec<HoleUse> = used.iter().map(|(_, u)| *u).collect();
    mine.sort_by_key(|u| (u.edge, u.face));
    imp.model.holes.iter().position(|h| {
        let mut theirs = h.uses.clone();
        theirs.sort_by_key(|u| (u.edge, u.face));
        h.kind == HoleKind::Simple && theirs == mine
    })
    .map(|k| (name.clone(), k + 1))
}
