//! The conditions of `hermite`, `pde`, `blend` and `dynamic` patches: the `v` domain and
//! resolution, `sections`, `start`/`end` trimlines and `conditions` (curves, expressions,
//! points, trimlines, trim curves of earlier patches), each checked on the domain; and the
//! patch assembled around the kind's solved surface, with its trim.

use super::PatchInput;
use crate::scene::ctx::{R, check_data, find_surface, span};
use crate::scene::{PatchKind, ScenePatch, SectionFamily};
use pdeshape_core::data::{FieldRef, PointField, Trimline};
use pdeshape_core::patch::{Condition, Surface, VDomain};
use std::ops::Range;
use std::sync::Arc;

/// A conditions patch's data, read and checked.
pub(super) struct Conditioned {
    /// The `v` domain.
    pub domain: VDomain,
    /// Mesh resolution.
    pub resolution: (usize, usize),
    /// The conditions, `sections` and `start`/`end` first.
    pub conditions: Vec<Condition>,
    /// The section family, when given by `sections`.
    pub sections: Option<SectionFamily>,
    /// Where errors about the conditions as a whole point.
    pub span: Option<Range<usize>>,
}

/// Reads the patch's conditions.
pub(super) fn read(input: &PatchInput) -> R<Conditioned> {
    let (ctx, key, p, kind) = (input.ctx, input.key.clone(), input.raw, input.kind);
    let (curves, surfaces, done) = (input.curves, input.surfaces, input.done);
    let rp = p.get_ref();
    let domain = ctx.domain(&rp.v, &format!("{key}.v"))?;
    let resolution = ctx.resolution(&rp.resolution, (33, 65), &format!("{key}.resolution"))?;
    if rp.conditions.is_none() && rp.sections.is_none() && rp.start.is_none() && rp.end.is_none() {
        return Err(ctx.err(span(p), &key, "the patch has no `conditions` (and no `sections`, `start` or `end`)"));
    }
    let no_conds = Vec::new();
    let rconds_list = rp.conditions.as_ref().map(|c| c.get_ref()).unwrap_or(&no_conds);
    let conds_span = rp.conditions.as_ref().map(|c| c.span()).or(Some(p.span()));
    let mut conditions = Vec::new();
    let mut sections = None;
    if let Some(sec) = &rp.sections {
        let (c, fam) = crate::scene::sections::build_sections(ctx, sec, domain, &format!("{key}.sections"))?;
        conditions.extend(c);
        sections = fam;
    }
    for (end_u, end, name) in [(0.0, &rp.start, "start"), (1.0, &rp.end, "end")] {
        let Some(e) = end else { continue };
        let ek = format!("{key}.{name}");
        let re = e.get_ref();
        let surf = find_surface(ctx, surfaces, &re.surface, &format!("{ek}.surface"))?;
        let s0 = ctx.num(re.s.get_ref(), span(&re.s), &format!("{ek}.s"))?;
        let scale = match &re.scale {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ek}.scale"))?,
            None => 1.0,
        };
        let top = if kind == PatchKind::Dynamic { 1 } else { 2 };
        for order in 0..=top {
            let data: FieldRef = Arc::new(Trimline::new(surf.field.clone(), s0, order, scale));
            check_data(ctx, &data, domain, span(e), &format!("{ek} (order {order})"))?;
            conditions.push(Condition { u: end_u, order, data });
        }
    }
    for (i, rc) in rconds_list.iter().enumerate() {
        let ck = format!("{key}.conditions[{i}]");
        let c = rc.get_ref();
        let u = ctx.num(c.u.get_ref(), span(&c.u), &format!("{ck}.u"))?;
        if !(0.0..=1.0).contains(&u) {
            return Err(ctx.err(span(&c.u), format!("{ck}.u"), format!("u = {u} is outside [0, 1]")));
        }
        let order = match &c.order {
            Some(o) => ctx.int(o, 0, 12, &format!("{ck}.order"))? as usize,
            None => 0,
        };
        let n_src = [c.curve.is_some(), c.expr.is_some(), c.point.is_some(), c.surface.is_some(), c.trim.is_some()]
            .iter()
            .filter(|b| **b)
            .count();
        if n_src != 1 {
            return Err(ctx.err(span(rc), &ck, "a condition needs exactly one of: curve, expr, point, surface, trim"));
        }
        if c.surface.is_none() && (c.s.is_some() || c.scale.is_some()) {
            return Err(ctx.err(span(rc), &ck, "`s` and `scale` only apply to trimline conditions (with `surface`)"));
        }
        let data: FieldRef = if let Some(n) = &c.curve {
            curves.get(n.get_ref()).cloned().ok_or_else(|| {
                ctx.err(
                    span(n),
                    format!("{ck}.curve"),
                    format!(
                        "unknown curve `{}` (defined: {})",
                        n.get_ref(),
                        if curves.is_empty() {
                            "none".to_string()
                        } else {
                            curves.keys().cloned().collect::<Vec<_>>().join(", ")
                        }
                    ),
                )
            })?
        } else if let Some(t) = &c.trim {
            crate::scene::trim::trim_condition(ctx, t, &format!("{ck}.trim"), done)?
        } else if let Some(x) = &c.expr {
            Arc::new(ctx.field(x, &["v", "t"], &format!("{ck}.expr"))?)
        } else if let Some(x) = &c.point {
            Arc::new(PointField { point: ctx.vec3(x.get_ref(), span(x), &format!("{ck}.point"))?, arity: 1 })
        } else {
            let sname = c.surface.as_ref().expect("counted above");
            let surf = find_surface(ctx, surfaces, sname, &format!("{ck}.surface"))?;
            let s = c.s.as_ref().ok_or_else(|| ctx.err(span(rc), &ck, "a trimline condition needs `s`"))?;
            let s0 = ctx.num(s.get_ref(), span(s), &format!("{ck}.s"))?;
            let scale = match &c.scale {
                Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ck}.scale"))?,
                None => 1.0,
            };
            Arc::new(Trimline::new(surf.field.clone(), s0, order, scale))
        };
        check_data(ctx, &data, domain, span(rc), &ck)?;
        if matches!(kind, PatchKind::Blend | PatchKind::Dynamic)
            && conditions.iter().any(|o| o.u == u && o.order == order)
        {
            return Err(ctx.err(
                span(rc),
                &ck,
                format!("∂^{order}X/∂u^{order} at u = {u} is already given (by `start`/`end` or another condition)"),
            ));
        }
        conditions.push(Condition { u, order, data });
    }
    Ok(Conditioned { domain, resolution, conditions, sections, span: conds_span })
}

/// The patch around its solved `surface` (a trim, when given, is cut on it); the kind
/// adds its own solved object (`spectral`, `blend`, `dynamic`).
pub(super) fn finish(input: &PatchInput, c: Conditioned, surface: Arc<dyn Surface>, solver: String) -> R<ScenePatch> {
    let rp = input.raw.get_ref();
    let trim = rp
        .trim
        .as_ref()
        .map(|t| crate::scene::trim::build_trim(input.ctx, &input.key, t, surface.as_ref()))
        .transpose()?;
    Ok(ScenePatch {
        name: input.name.to_string(),
        kind: input.kind,
        surface,
        conditions: c.conditions,
        solver,
        resolution: c.resolution,
        color: rp.color.as_ref().map(|c| *c.get_ref()),
        spectral: None,
        sections: c.sections,
        blend: None,
        dynamic: None,
        solid: None,
        trim,
        fill: None,
        hole: None,
    })
}
