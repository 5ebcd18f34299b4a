//! `kind = "dynamic"`: a time-dependent C1 blend (SPEC §5): operator, sine terms, time range.

use super::{PatchInput, conditions};
use crate::scene::ScenePatch;
use crate::scene::ctx::{Ctx, R, span};
use crate::scene::raw::*;
use pdeshape_core::blend::{DynBasis, DynamicBlend, DynamicOperator, DynamicOptions};
use pdeshape_core::limits::Cap;
use pdeshape_core::patch::{Condition, VDomain};
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;

/// The keys a `kind = "dynamic"` patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] = &[
    "v",
    "resolution",
    "conditions",
    "sections",
    "start",
    "end",
    "solver",
    "collocation",
    "basis",
    "beta",
    "gamma",
    "lambda",
    "rho",
    "eta",
    "terms",
    "joint",
    "time",
    "frames",
];

/// Keys it refuses, with the reason.
pub(super) const INSTEAD: &[(&str, &str)] =
    &[("trim", "trims apply to hermite, pde and blend patches (not to moving, solid or fill ones)")];

/// Reads the conditions and sets up the blend; the patch's surface is the frame at the
/// first time (solved now, kept for later).
pub(super) fn build(input: &PatchInput) -> R<ScenePatch> {
    let c = conditions::read(input)?;
    let setup = build_dynamic(input.ctx, &input.key, input.raw, &c.conditions, c.domain, c.span.clone())?;
    let f = setup
        .blend
        .frame(setup.times.0)
        .map_err(|e| input.ctx.err(c.span.clone().or(Some(input.raw.span())), &input.key, e.to_string()))?;
    let solver = f.report().solver.to_string();
    let mut p = conditions::finish(input, c, Arc::new(f), solver)?;
    p.dynamic = Some(setup);
    Ok(p)
}

/// The operator, options and basis of a dynamic blend (SPEC §5).
pub(in crate::scene) fn build_dynamic(
    ctx: &Ctx,
    key: &str,
    p: &Spanned<RawPatch>,
    conditions: &[Condition],
    domain: VDomain,
    conds_span: Option<Range<usize>>,
) -> R<crate::scene::DynamicSetup> {
    let rp = p.get_ref();
    let num = |x: &Option<Spanned<NumOrExpr>>, name: &str, default: f64| -> R<f64> {
        match x {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.{name}")),
            None => Ok(default),
        }
    };
    let op = DynamicOperator::new(
        num(&rp.beta, "beta", 1.0)?,
        num(&rp.gamma, "gamma", 2.0)?,
        num(&rp.lambda, "lambda", 1.0)?,
        num(&rp.rho, "rho", 0.0)?,
        num(&rp.eta, "eta", 0.0)?,
    )
    .map_err(|e| ctx.err(span(p), key, e.to_string()))?;
    let times = match &rp.time {
        None => (0.0, 1.0),
        Some(r) => ctx.range(r, &format!("{key}.time"))?,
    };
    let frames = match &rp.frames {
        None => 11,
        Some(f) => ctx.int(f, 2, 1000, &format!("{key}.frames"))? as usize,
    };
    let mut opts = DynamicOptions { times, limits: ctx.limits, ..Default::default() };
    if let Some(sv) = ctx.solver_choice(&rp.solver, key)? {
        opts.solver = sv;
    }
    if let Some(k) = &rp.terms {
        opts.terms = ctx.capped(k, 1, Cap::Modes, &format!("{key}.terms"))?;
    }
    if let Some(k) = ctx.terms {
        ctx.cap(Cap::Modes, k as u128, None, "--terms", "the sine terms K")?;
        opts.terms = k;
    }
    if let Some(c) = &rp.collocation {
        let [l, m] = *c.get_ref();
        if l < 2 || m < 1 {
            return Err(ctx.err(
                span(c),
                format!("{key}.collocation"),
                format!("[{l}, {m}] is too small (at least [2, 1])"),
            ));
        }
        let k = format!("{key}.collocation");
        ctx.cap(Cap::Collocation, l as u128 * m as u128, span(c), &k, &format!("the collocation grid [{l}, {m}]"))?;
        opts.collocation = (l as usize, m as usize);
    }
    opts.joint = rp.joint.as_ref().map(|j| *j.get_ref()).unwrap_or(false);
    if let Some(list) = &rp.basis {
        let exprs = ctx.basis_exprs(list, key, &["v", "t"])?;
        opts.basis = Some(exprs.into_iter().map(|(expr, text)| DynBasis::Expr { expr, text }).collect());
    }
    let blend = DynamicBlend::new(op, conditions, domain, &opts)
        .map_err(|e| ctx.err(conds_span.or(Some(p.span())), key, e.to_string()))?;
    Ok(crate::scene::DynamicSetup { blend: Arc::new(blend), times, frames })
}
