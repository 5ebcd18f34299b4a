//! Trims in scene files: `[patches.NAME.trim]` and conditions on trim curves of earlier
//! patches (`trim = "PATCH.CURVE"`).

use super::ctx::{Ctx, R, span};
use super::raw::{NumOrExpr, RawTrim, RawTrimCurve};
use super::{ScenePatch, TrimSetup};
use pdeshape_core::data::FieldRef;
use pdeshape_core::patch::Surface;
use pdeshape_core::trim::{CurveOnSurface, TrimCurve, TrimOptions, trim_in_metric};
use std::sync::Arc;
use toml::Spanned;

fn uv(ctx: &Ctx, p: &[NumOrExpr; 2], sp: Option<std::ops::Range<usize>>, key: &str) -> R<[f64; 2]> {
    Ok([ctx.num(&p[0], sp.clone(), key)?, ctx.num(&p[1], sp, key)?])
}

fn curve(ctx: &Ctx, rc: &Spanned<RawTrimCurve>, key: &str) -> R<TrimCurve> {
    let c = rc.get_ref();
    let given = [c.circle.is_some(), c.bspline.is_some(), c.polygon.is_some()].iter().filter(|b| **b).count();
    if given != 1 {
        return Err(ctx.err(span(rc), key, "a trim curve needs exactly one of: circle, bspline, polygon"));
    }
    if let Some(ci) = &c.circle {
        let k = format!("{key}.circle");
        let r = ci.get_ref();
        let center = uv(ctx, &r.center, span(ci), &format!("{k}.center"))?;
        let radii = match (&r.radius, &r.radii) {
            (Some(x), None) => {
                let v = ctx.num(x, span(ci), &format!("{k}.radius"))?;
                [v, v]
            }
            (None, Some(x)) => uv(ctx, x, span(ci), &format!("{k}.radii"))?,
            _ => return Err(ctx.err(span(ci), k, "give exactly one of `radius` and `radii`")),
        };
        if !(radii[0] > 0.0 && radii[1] > 0.0) {
            return Err(ctx.err(span(ci), k, format!("radii {radii:?} must be positive")));
        }
        return Ok(TrimCurve::ellipse(center, radii));
    }
    let (list, what) = match (&c.bspline, &c.polygon) {
        (Some(b), _) => (b, "bspline"),
        (_, Some(p)) => (p, "polygon"),
        _ => unreachable!("counted above"),
    };
    let k = format!("{key}.{what}");
    let pts: Vec<[f64; 2]> = list.get_ref().iter().map(|p| uv(ctx, p, span(list), &k)).collect::<R<_>>()?;
    let made = if what == "bspline" { TrimCurve::bspline(&pts) } else { TrimCurve::polygon(&pts) };
    made.map_err(|e| ctx.err(span(list), k, e.to_string()))
}

/// The trim of a patch: curves validated against the patch's domain, the Laplace map and
/// the repaired grid.
pub(super) fn build_trim(ctx: &Ctx, key: &str, raw: &Spanned<RawTrim>, surface: &dyn Surface) -> R<TrimSetup> {
    let key = format!("{key}.trim");
    let rt = raw.get_ref();
    let (rings, columns) = ctx.resolution(&rt.resolution, (20, 64), &format!("{key}.resolution"))?;
    if columns < 8 {
        return Err(ctx.err(
            span(raw),
            format!("{key}.resolution"),
            format!("[{rings}, {columns}] has too few columns (at least 8)"),
        ));
    }
    let modes = match &rt.modes {
        Some(m) => ctx.int(m, 1, (pdeshape_core::trim::FFT_SAMPLES / 2 - 1) as i64, &format!("{key}.modes"))? as usize,
        None => 12,
    };
    if rt.curves.is_empty() {
        return Err(ctx.err(span(raw), format!("{key}.curves"), "a trim needs at least one curve"));
    }
    let mut curves = Vec::new();
    for (name, rc) in &rt.curves {
        curves.push((name.clone(), curve(ctx, rc, &format!("{key}.curves.{name}"))?));
    }
    // validated in the patch's own parameters, meshed in the metric-scaled plane
    let o = TrimOptions { rings, columns, modes, ..Default::default() };
    let t = trim_in_metric(surface, &curves, &o).map_err(|e| ctx.err(span(raw), &key, e.to_string()))?;
    Ok(TrimSetup { map: Arc::new(t.map), grid: Arc::new(t.grid), curves, scale: t.scale })
}

/// The curve `X_P(C(t))` for `trim = "P.C"`: trim curve `C` of the earlier patch `P`.
pub(super) fn trim_condition(ctx: &Ctx, name: &Spanned<String>, key: &str, done: &[ScenePatch]) -> R<FieldRef> {
    let (surface, curve) = find_trim_curve(ctx, name, key, done)?;
    Ok(Arc::new(CurveOnSurface { surface, curve }))
}

/// The patch and trim curve named `"P.C"` (an earlier patch `P`, its curve `C`).
pub(super) fn find_trim_curve(
    ctx: &Ctx,
    name: &Spanned<String>,
    key: &str,
    done: &[ScenePatch],
) -> R<(Arc<dyn Surface>, TrimCurve)> {
    let text = name.get_ref();
    let Some((pname, cname)) = text.split_once('.') else {
        return Err(ctx.err(span(name), key, format!("`{text}` is not of the form \"PATCH.CURVE\"")));
    };
    let Some(p) = done.iter().find(|p| p.name == pname) else {
        let known: Vec<&str> = done.iter().map(|p| p.name.as_str()).collect();
        return Err(ctx.err(
            span(name),
            key,
            format!(
                "unknown patch `{pname}` (patches defined before this one: {})",
                if known.is_empty() { "none".to_string() } else { known.join(", ") }
            ),
        ));
    };
    let Some(t) = &p.trim else {
        return Err(ctx.err(span(name), key, format!("patch `{pname}` has no trim")));
    };
    let Some((_, c)) = t.curves.iter().find(|(n, _)| n == cname) else {
        let known: Vec<&str> = t.curves.iter().map(|(n, _)| n.as_str()).collect();
        return Err(ctx.err(
            span(name),
            key,
            format!("patch `{pname}` has no trim curve `{cname}` (its curves: {})", known.join(", ")),
        ));
    };
    let surface: Arc<dyn Surface> = p.surface.clone();
    Ok((surface, c.clone()))
}
