//! `kind = "blend"`: a static blend of 2nd, 4th, 6th or mixed order (SPEC §4): operators per
//! component and the solver.

use super::{PatchInput, conditions};
use crate::scene::ScenePatch;
use crate::scene::ctx::{Ctx, R, span};
use crate::scene::raw::*;
use pdeshape_core::blend::{BasisFn, BlendOptions, Operator, StaticBlend};
use pdeshape_core::limits::Cap;
use pdeshape_core::patch::{Condition, VDomain};
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;

/// The keys a `kind = "blend"` patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] = &[
    "v",
    "resolution",
    "conditions",
    "trim",
    "orders",
    "coefficients",
    "solver",
    "bubbles",
    "collocation",
    "basis",
    "start",
    "end",
];

/// `"exact"`, `"collocation"` or the per-component mix.
fn solver_name(b: &StaticBlend) -> String {
    let r = b.reports();
    if r.iter().all(|c| c.solver == r[0].solver) {
        r[0].solver.to_string()
    } else {
        format!("mixed (x: {}, y: {}, z: {})", r[0].solver, r[1].solver, r[2].solver)
    }
}

/// Keys it refuses, with the reason.
pub(super) const INSTEAD: &[(&str, &str)] = &[];

/// Reads the conditions and solves the blend.
pub(super) fn build(input: &PatchInput) -> R<ScenePatch> {
    let c = conditions::read(input)?;
    let setup = build_blend(input.ctx, &input.key, input.raw, &c.conditions, c.domain, c.span.clone())?;
    let solver = solver_name(&setup.blend);
    let mut p = conditions::finish(input, c, setup.blend.clone(), solver)?;
    p.blend = Some(setup);
    Ok(p)
}

/// Operators, options and the solve of a static blend (SPEC §4).
pub(in crate::scene) fn build_blend(
    ctx: &Ctx,
    key: &str,
    p: &Spanned<RawPatch>,
    conditions: &[Condition],
    domain: VDomain,
    conds_span: Option<Range<usize>>,
) -> R<crate::scene::BlendSetup> {
    let rp = p.get_ref();
    let orders: [usize; 3] = match &rp.orders {
        None => [4, 4, 4],
        Some(o) => {
            let mut out = [0; 3];
            for (t, &x) in o.get_ref().iter().enumerate() {
                if ![2, 4, 6].contains(&x) {
                    return Err(ctx.err(
                        span(o),
                        format!("{key}.orders[{t}]"),
                        format!("order {x} is not available (static blends have order 2, 4 or 6 per component)"),
                    ));
                }
                out[t] = x as usize;
            }
            out
        }
    };
    let mut ops = Vec::with_capacity(3);
    for t in 0..3 {
        let r = orders[t] / 2;
        let op = match &rp.coefficients {
            None => Operator::laplacian_power(r),
            Some(c) => {
                let list = &c.get_ref()[t];
                let ck = format!("{key}.coefficients[{t}]");
                if list.len() != r + 1 {
                    return Err(ctx.err(
                        span(c),
                        &ck,
                        format!(
                            "component {} has order {}: it takes {} shape coefficients, {} given",
                            ["x", "y", "z"][t],
                            2 * r,
                            r + 1,
                            list.len()
                        ),
                    ));
                }
                let vals = list.iter().map(|x| ctx.num(x, span(c), &ck)).collect::<R<Vec<f64>>>()?;
                Operator::new(vals).map_err(|e| ctx.err(span(c), &ck, e.to_string()))?
            }
        };
        ops.push(op);
    }
    let ops: [Operator; 3] = ops.try_into().expect("three operators");
    let mut options = BlendOptions { limits: ctx.limits, ..Default::default() };
    if let Some(sv) = ctx.solver_choice(&rp.solver, key)? {
        options.solver = sv;
    }
    if let Some(b) = &rp.bubbles {
        options.bubbles = ctx.capped(b, 1, Cap::Modes, &format!("{key}.bubbles"))?;
    }
    if let Some(c) = &rp.collocation {
        let [l, q] = *c.get_ref();
        if l < 1 || q < 1 {
            return Err(ctx.err(
                span(c),
                format!("{key}.collocation"),
                format!("[{l}, {q}] is too small (at least 1 each)"),
            ));
        }
        let k = format!("{key}.collocation");
        ctx.cap(Cap::Collocation, l as u128 * q as u128, span(c), &k, &format!("the collocation grid [{l}, {q}]"))?;
        options.collocation = Some((l as usize, q as usize));
    }
    if let Some(list) = &rp.basis {
        let exprs = ctx.basis_exprs(list, key, &["v"])?;
        options.basis = Some(exprs.into_iter().map(|(expr, text)| BasisFn::Expr { expr, text }).collect());
    }
    let blend = StaticBlend::new(ops, conditions, domain, &options)
        .map_err(|e| ctx.err(conds_span.or(Some(p.span())), key, e.to_string()))?;
    Ok(crate::scene::BlendSetup { blend: Arc::new(blend), options })
}
