//! B-splines with given knots and weights in scene files, as core's exact NURBS fields:
//! open curves (`[curves.NAME] bspline` with `knots` and/or `weights`, a
//! [`NurbsCurve`]) and nets (`[surfaces.NAME] bspline`, a [`NurbsSurface`] in `s`, `v`).
//!
//! Knot vectors are written whole (`n + p + 1` non-decreasing values, end knots repeated as
//! the file wants them), as STEP and The NURBS Book write them; the parameter of the curve
//! (of the net: `s` and `v`) is the knot parameter itself. Without `knots` a curve gets the
//! clamped uniform knots over its `range` (default `[0, 1]`) and a net those over `[0, 1]²`.

use super::ctx::{Ctx, R, span};
use super::raw::{NumOrExpr, RawCurve, RawSurface};
use pdeshape_core::Vec3;
use pdeshape_core::data::{NurbsCurve, NurbsSurface};
use pdeshape_core::patch::VDomain;
use toml::Spanned;

/// The clamped uniform knot vector of `n` control points of degree `p` over `[a, b]`:
/// `p + 1` copies of `a`, the `n − p − 1` inner knots `a + (b − a) i/(n − p)`, `p + 1` of `b`.
pub(super) fn clamped_uniform(n: usize, p: usize, (a, b): (f64, f64)) -> Vec<f64> {
    let spans = n - p;
    let mut k = vec![a; p + 1];
    k.extend((1..spans).map(|i| a + (b - a) * (i as f64 / spans as f64)));
    k.extend(std::iter::repeat_n(b, p + 1));
    k
}

/// The degree `len − n − 1` a whole knot vector of `len` knots implies for `n` control
/// points (`dir` names the direction in the message when it implies none).
fn implied_degree(len: usize, n: usize, dir: &str) -> Result<usize, String> {
    match len.checked_sub(n + 1) {
        Some(p) if p >= 1 => Ok(p),
        _ => Err(format!("{dir}{len} knots for {n} control points imply no degree (degree p needs n + p + 1)")),
    }
}

fn numbers(ctx: &Ctx, x: &Spanned<Vec<NumOrExpr>>, key: &str) -> R<Vec<f64>> {
    x.get_ref().iter().enumerate().map(|(i, v)| ctx.num(v, span(x), &format!("{key}[{i}]"))).collect()
}

/// An open curve of `points` with the `knots` or `weights` the file gives. `degree` as the
/// file gives it, else what the knots imply, else 3 lowered to what the points allow;
/// `range` only without knots (the knots are the parameter).
pub(super) fn curve(
    ctx: &Ctx,
    key: &str,
    c: &RawCurve,
    (points, points_span): (&[Vec3], Option<std::ops::Range<usize>>),
    degree: Option<usize>,
    range: Option<(f64, f64)>,
) -> R<NurbsCurve> {
    let (knots, weights) = (c.knots.as_ref(), c.weights.as_ref());
    let n = points.len();
    let (p, knot_vector) = match knots {
        Some(k) => {
            let kv = numbers(ctx, k, &format!("{key}.knots"))?;
            let p = match degree {
                Some(p) => p,
                None => implied_degree(kv.len(), n, "").map_err(|m| ctx.err(span(k), format!("{key}.knots"), m))?,
            };
            (p, kv)
        }
        None => {
            if n < 2 {
                return Err(ctx.err(points_span, format!("{key}.bspline"), format!("{n} control points (at least 2)")));
            }
            let p = degree.unwrap_or(3).min(n - 1);
            (p, clamped_uniform(n, p, range.unwrap_or((0.0, 1.0))))
        }
    };
    let w = weights.map(|w| numbers(ctx, w, &format!("{key}.weights"))).transpose()?;
    if let (Some(w), Some(ws)) = (&w, weights)
        && w.len() != n
    {
        return Err(ctx.err(
            span(ws),
            format!("{key}.weights"),
            format!("{} weights for {n} control points (one each)", w.len()),
        ));
    }
    // the knots' or weights' place when the NURBS is refused: what its message names
    let at = knots.map(span).or_else(|| weights.map(span)).unwrap_or(points_span);
    let what = if knots.is_some() { "knots" } else { "weights" };
    NurbsCurve::new(p, knot_vector, points, w.as_deref())
        .map_err(|e| ctx.err(at, format!("{key}.{what}"), e.to_string()))
}

/// A net `[surfaces.NAME] bspline = [[P₀₀, P₀₁, …], [P₁₀, …], …]` (rows along `s`): the
/// surface `S(s, v)` and its `v` domain (the knot range in `v`).
pub(super) fn surface(ctx: &Ctx, key: &str, rs: &RawSurface) -> R<(NurbsSurface, VDomain)> {
    let net = rs.bspline.as_ref().expect("called for bspline surfaces");
    let k = format!("{key}.bspline");
    let rows = net.get_ref();
    let nu = rows.len();
    let nv = rows.first().map_or(0, Vec::len);
    if nu < 2 || nv < 2 {
        return Err(ctx.err(span(net), &k, format!("a {nu} × {nv} net (at least 2 × 2 points)")));
    }
    let mut points = Vec::with_capacity(nu * nv);
    for (i, row) in rows.iter().enumerate() {
        if row.len() != nv {
            return Err(ctx.err(span(net), format!("{k}[{i}]"), format!("{} points, row 0 has {nv}", row.len())));
        }
        for (j, p) in row.iter().enumerate() {
            points.push(ctx.vec3(p, span(net), &format!("{k}[{i}][{j}]"))?);
        }
    }
    let (pu, pv) = match &rs.degree {
        Some(d) => {
            let [a, b] = *d.get_ref();
            let dk = format!("{key}.degree");
            for x in [a, b] {
                if !(1..=7).contains(&x) {
                    return Err(ctx.err(span(d), &dk, format!("{x} is out of range (expected 1 … 7)")));
                }
            }
            (a as usize, b as usize)
        }
        None => match &rs.knots {
            Some(k) => {
                let [a, b] = k.get_ref();
                let implied =
                    implied_degree(a.len(), nu, "u: ").and_then(|pu| Ok((pu, implied_degree(b.len(), nv, "v: ")?)));
                implied.map_err(|m| ctx.err(span(k), format!("{key}.knots"), m))?
            }
            None => (3.min(nu - 1), 3.min(nv - 1)),
        },
    };
    let (ku, kv) = match &rs.knots {
        Some(kn) => {
            let kk = format!("{key}.knots");
            let [a, b] = kn.get_ref();
            let num = |x: &[NumOrExpr], d: usize| -> R<Vec<f64>> {
                x.iter().enumerate().map(|(i, v)| ctx.num(v, span(kn), &format!("{kk}[{d}][{i}]"))).collect()
            };
            (num(a, 0)?, num(b, 1)?)
        }
        None => {
            let dk = format!("{key}.degree");
            if pu >= nu || pv >= nv {
                let sp = rs.degree.as_ref().map(span).unwrap_or(span(net));
                return Err(ctx.err(sp, dk, format!("degree [{pu}, {pv}] needs a net of more than {pu} × {pv}")));
            }
            (clamped_uniform(nu, pu, (0.0, 1.0)), clamped_uniform(nv, pv, (0.0, 1.0)))
        }
    };
    let weights = match &rs.weights {
        None => None,
        Some(w) => {
            let wk = format!("{key}.weights");
            let wr = w.get_ref();
            if wr.len() != nu || wr.iter().any(|r| r.len() != nv) {
                return Err(ctx.err(span(w), &wk, format!("the weights must be a {nu} × {nv} array, as the net")));
            }
            let mut out = Vec::with_capacity(nu * nv);
            for (i, r) in wr.iter().enumerate() {
                for (j, x) in r.iter().enumerate() {
                    out.push(ctx.num(x, span(w), &format!("{wk}[{i}][{j}]"))?);
                }
            }
            Some(out)
        }
    };
    let at = rs.knots.as_ref().map(span).or_else(|| rs.weights.as_ref().map(span)).unwrap_or(span(net));
    let what = if rs.knots.is_some() {
        "knots"
    } else if rs.weights.is_some() {
        "weights"
    } else {
        "bspline"
    };
    let s = NurbsSurface::new((pu, pv), ku, kv, (nu, nv), &points, weights.as_deref())
        .map_err(|e| ctx.err(at, format!("{key}.{what}"), e.to_string()))?;
    let (_, (v0, v1)) = s.domain();
    Ok((s, VDomain::open(v0, v1)))
}
