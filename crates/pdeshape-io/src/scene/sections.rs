//! `sections`: a patch given by a family of cross sections `C(v, t, s)` at section
//! parameters `s_i` placed at `u_i`, as position conditions (and the family, for the
//! report's distance to it).

use crate::scene::ctx::{Ctx, R, check_data, span};
use crate::scene::raw::*;
use pdeshape_core::data::{ExprField, FieldRef};
use pdeshape_core::expr::Expr;
use pdeshape_core::limits::Cap;
use pdeshape_core::patch::{Condition, VDomain};
use std::sync::Arc;
use toml::Spanned;

/// Expands `[patches.NAME.sections]` into position conditions.
pub(in crate::scene) fn build_sections(
    ctx: &Ctx,
    sec: &Spanned<RawSections>,
    domain: VDomain,
    key: &str,
) -> R<(Vec<Condition>, Option<super::SectionFamily>)> {
    let rs = sec.get_ref();
    let count = ctx.capped(&rs.count, 2, Cap::Order, &format!("{key}.count"))?;
    let us: Vec<f64> = match (&rs.u, &rs.spacing) {
        (Some(_), Some(sp)) => {
            return Err(ctx.err(span(sp), format!("{key}.spacing"), "give either `spacing` or explicit `u`, not both"));
        }
        (Some(list), None) => {
            if list.get_ref().len() != count {
                return Err(ctx.err(
                    span(list),
                    format!("{key}.u"),
                    format!("{} values for {count} sections", list.get_ref().len()),
                ));
            }
            for &u in list.get_ref() {
                if !(0.0..=1.0).contains(&u) {
                    return Err(ctx.err(span(list), format!("{key}.u"), format!("u = {u} is outside [0, 1]")));
                }
            }
            list.get_ref().clone()
        }
        (None, sp) => {
            let word = sp.as_ref().map(|s| s.get_ref().as_str()).unwrap_or("chebyshev");
            let m = (count - 1) as f64;
            match word {
                "uniform" => (0..count).map(|i| i as f64 / m).collect(),
                "chebyshev" => (0..count).map(|i| (1.0 - (std::f64::consts::PI * i as f64 / m).cos()) / 2.0).collect(),
                w => {
                    return Err(ctx.err(
                        sp.as_ref().and_then(span),
                        format!("{key}.spacing"),
                        format!("unknown spacing `{w}` (expected \"uniform\", \"chebyshev\" or explicit u = [...])"),
                    ));
                }
            }
        }
    };
    let s_text = rs.s.as_ref().map(|s| s.get_ref().clone()).unwrap_or_else(|| "i".into());
    let s_span = rs.s.as_ref().and_then(span);
    let s_expr = Expr::parse(&s_text).map_err(|e| ctx.expr_err(s_span.clone(), format!("{key}.s"), &s_text, &e))?;
    let texts = rs.expr.get_ref().each_ref().map(NumOrExpr::text);
    let parsed: Vec<Expr> = texts
        .iter()
        .enumerate()
        .map(|(k, t)| Expr::parse(t).map_err(|e| ctx.expr_err(span(&rs.expr), format!("{key}.expr[{k}]"), t, &e)))
        .collect::<R<_>>()?;
    let mut out = Vec::with_capacity(count);
    let mut ss = Vec::with_capacity(count);
    for (i, &u) in us.iter().enumerate() {
        let idx = i as f64;
        let lookup_i = |n: &str| {
            if n == "i" {
                Some(idx)
            } else if n == "count" {
                Some(count as f64)
            } else {
                ctx.params.get(n).map(|p| p.value)
            }
        };
        let s_i = s_expr
            .bind(&[], &lookup_i)
            .map_err(|e| ctx.expr_err(s_span.clone(), format!("{key}.s"), &s_text, &e))?
            .eval(&[]);
        if !s_i.is_finite() {
            return Err(ctx.err(s_span.clone(), format!("{key}.s"), format!("s is not finite for section {i}")));
        }
        let lookup = |n: &str| if n == "s" { Some(s_i) } else { lookup_i(n) };
        let comps: Vec<Expr> = parsed
            .iter()
            .enumerate()
            .map(|(k, e)| {
                e.bind(&["v", "t"], &lookup)
                    .map_err(|er| ctx.expr_err(span(&rs.expr), format!("{key}.expr[{k}]"), &texts[k], &er))
            })
            .collect::<R<_>>()?;
        let comps: [Expr; 3] =
            comps.try_into().map_err(|_| ctx.err(span(&rs.expr), key, "three components expected"))?;
        let data: FieldRef = Arc::new(ExprField::from_exprs(comps, &["v", "t"]));
        check_data(ctx, &data, domain, span(sec), &format!("{key} (section {i}, s = {s_i})"))?;
        out.push(Condition { u, order: 0, data });
        ss.push(s_i);
    }
    // The reference family C(v; s), when the curve depends on the index only through s.
    let spacing = match (&rs.u, rs.spacing.as_ref().map(|s| s.get_ref().as_str())) {
        (Some(_), _) => super::Spacing::Explicit,
        (None, Some("uniform")) => super::Spacing::Uniform,
        _ => super::Spacing::Chebyshev,
    };
    let s_of_index = s_expr
        .bind(&["i"], &|n| if n == "count" { Some(count as f64) } else { ctx.params.get(n).map(|p| p.value) })
        .ok();
    let family = parsed
        .iter()
        .map(|e| {
            e.bind(&["v", "t", "s"], &|n| {
                if n == "count" { Some(count as f64) } else { ctx.params.get(n).map(|p| p.value) }
            })
            .ok()
        })
        .collect::<Option<Vec<Expr>>>()
        .and_then(|v| <[Expr; 3]>::try_from(v).ok())
        .filter(|_| us.windows(2).all(|w| w[0] < w[1]))
        .zip(s_of_index)
        .map(|(comps, s_of_index)| super::SectionFamily {
            us: us.clone(),
            ss,
            spacing,
            s_of_index,
            curve: Arc::new(ExprField::from_exprs(comps, &["v", "t", "s"])),
        });
    Ok((out, family))
}
