//! Patch kinds in scene files, one file each: the keys a kind takes (`KEYS`), the keys it
//! refuses with a reason of its own (`INSTEAD`), and how it is built. [`KINDS`] registers
//! them; [`check_keys`] checks every patch's keys against its kind's, so no key is ignored.
//!
//! `hermite`, `pde`, `blend` and `dynamic` patches take conditions (curves, `sections`,
//! `start`/`end`, trim curves of earlier patches), read here once for all of them, and
//! differ in their solve; `solid` and `fill` patches are built from their own keys.

mod blend;
mod dynamic;
mod fill;
mod hermite;
mod pde;
mod solid;

use crate::scene::ctx::{Ctx, R, check_data, find_surface, span};
use crate::scene::raw::*;
use crate::scene::{PatchKind, ScenePatch, SceneSurface};
use indexmap::IndexMap;
use pdeshape_core::data::{FieldRef, PointField, Trimline};
use pdeshape_core::patch::{Condition, HermitePatch};
use std::sync::Arc;
use toml::Spanned;

/// A patch kind as scene files know it.
pub(in crate::scene) struct KindSpec {
    /// The kind.
    pub kind: PatchKind,
    /// The keys it takes besides [`COMMON`].
    pub keys: &'static [&'static str],
    /// Keys it refuses, each with the reason.
    pub instead: &'static [(&'static str, &'static str)],
}

/// Keys every patch takes.
const COMMON: &[&str] = &["kind", "color"];

/// Every patch kind, in the order error messages list them.
pub(in crate::scene) const KINDS: [KindSpec; 6] = [
    KindSpec { kind: PatchKind::Hermite, keys: hermite::KEYS, instead: &[] },
    KindSpec { kind: PatchKind::Pde, keys: pde::KEYS, instead: &[] },
    KindSpec { kind: PatchKind::Blend, keys: blend::KEYS, instead: &[] },
    KindSpec { kind: PatchKind::Dynamic, keys: dynamic::KEYS, instead: dynamic::INSTEAD },
    KindSpec { kind: PatchKind::Solid, keys: solid::KEYS, instead: solid::INSTEAD },
    KindSpec { kind: PatchKind::Fill, keys: fill::KEYS, instead: fill::INSTEAD },
];

/// The kind named by `kind = "…"`.
fn kind_of(ctx: &Ctx, key: &str, rp: &RawPatch) -> R<PatchKind> {
    let name = rp.kind.get_ref().as_str();
    KINDS.iter().map(|k| k.kind).find(|k| k.name() == name).ok_or_else(|| {
        let known: Vec<&str> = KINDS.iter().map(|k| k.kind.name()).collect();
        ctx.err(
            span(&rp.kind),
            format!("{key}.kind"),
            format!("unknown patch kind `{name}` (known: {})", known.join(", ")),
        )
    })
}

/// Every key of the patch is one its kind takes: a key of another kind is an error naming
/// the kinds it applies to, a refused key an error with its reason.
fn check_keys(ctx: &Ctx, key: &str, p: &Spanned<RawPatch>, kind: PatchKind) -> R<()> {
    let spec = KINDS.iter().find(|k| k.kind == kind).expect("every kind is registered");
    for name in p.get_ref().present_keys() {
        if COMMON.contains(&name) || spec.keys.contains(&name) {
            continue;
        }
        let msg = match spec.instead.iter().find(|(k, _)| *k == name) {
            Some((_, reason)) => reason.to_string(),
            None => {
                let takers: Vec<String> =
                    KINDS.iter().filter(|k| k.keys.contains(&name)).map(|k| format!("\"{}\"", k.kind.name())).collect();
                let list = match takers.split_last() {
                    Some((last, [])) => last.clone(),
                    Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
                    None => "no kind".into(),
                };
                format!("`{name}` only applies to kind = {list}")
            }
        };
        return Err(ctx.err(span(p), format!("{key}.{name}"), msg));
    }
    Ok(())
}

pub(in crate::scene) fn build_patch(
    ctx: &Ctx,
    pname: &str,
    p: &Spanned<RawPatch>,
    curves: &IndexMap<String, FieldRef>,
    surfaces: &[SceneSurface],
    done: &[ScenePatch],
) -> R<ScenePatch> {
    let key = format!("patches.{pname}");
    let rp = p.get_ref();
    let kind = kind_of(ctx, &key, rp)?;
    check_keys(ctx, &key, p, kind)?;
    if kind == PatchKind::Solid {
        return solid::build_solid(ctx, pname, &key, p);
    }
    if kind == PatchKind::Fill {
        return fill::build_fill(ctx, pname, &key, p, surfaces, done);
    }
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
    let mut spectral = None;
    let mut blend = None;
    let mut dynamic = None;
    let surface: Arc<dyn pdeshape_core::patch::Surface> = match kind {
        PatchKind::Hermite => Arc::new(
            HermitePatch::new(&conditions, domain)
                .map_err(|e| ctx.err(conds_span.clone(), format!("{key}.conditions"), e.to_string()))?,
        ),
        PatchKind::Pde => {
            let sp = Arc::new(pde::solve(ctx, &key, rp, &conditions, domain, conds_span.clone())?);
            spectral = Some(sp.clone());
            sp
        }
        PatchKind::Blend => {
            let setup = blend::build_blend(ctx, &key, p, &conditions, domain, conds_span.clone())?;
            let b = setup.blend.clone();
            blend = Some(setup);
            b
        }
        PatchKind::Dynamic => {
            let setup = dynamic::build_dynamic(ctx, &key, p, &conditions, domain, conds_span.clone())?;
            let f = setup
                .blend
                .frame(setup.times.0)
                .map_err(|e| ctx.err(conds_span.clone().or(Some(p.span())), &key, e.to_string()))?;
            dynamic = Some(setup);
            Arc::new(f)
        }
        PatchKind::Solid => unreachable!("solid patches are built by build_solid"),
        PatchKind::Fill => unreachable!("fills are built by fill::build_fill"),
    };
    let color = rp.color.as_ref().map(|c| *c.get_ref());
    let trim = rp.trim.as_ref().map(|t| crate::scene::trim::build_trim(ctx, &key, t, surface.as_ref())).transpose()?;
    Ok(ScenePatch {
        name: pname.to_string(),
        kind,
        surface,
        conditions,
        resolution,
        color,
        spectral,
        sections,
        blend,
        dynamic,
        solid: None,
        trim,
        fill: None,
    })
}
