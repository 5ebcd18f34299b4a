//! `kind = "solid"`: a solid blend (SPEC §6) from its four boundary surfaces.

use super::PatchInput;
use crate::scene::ctx::{Ctx, R, span};
use crate::scene::raw::*;
use crate::scene::{PatchKind, ScenePatch};
use pdeshape_core::data::FieldRef;
use pdeshape_core::limits::Cap;
use std::sync::Arc;
use toml::Spanned;

/// The keys a `kind = "solid"` patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] =
    &["alpha", "trial", "lmn", "w0", "w0_tangent", "w1", "w1_tangent", "cells", "primary", "beta", "gamma"];

/// Keys it refuses, with the reason.
pub(super) const INSTEAD: &[(&str, &str)] = &[
    ("conditions", "a solid blend takes w0, w0_tangent, w1, w1_tangent and cells instead of `conditions`"),
    ("resolution", "a solid blend takes w0, w0_tangent, w1, w1_tangent and cells instead of `resolution`"),
    ("trim", "trims apply to hermite, pde and blend patches (not to moving, solid or fill ones)"),
];

/// Builds the solid from its own keys.
pub(super) fn build(input: &PatchInput) -> R<ScenePatch> {
    build_solid(input.ctx, input.name, &input.key, input.raw)
}

/// A solid blend (SPEC §6) from its four boundary surfaces.
pub(in crate::scene) fn build_solid(ctx: &Ctx, pname: &str, key: &str, p: &Spanned<RawPatch>) -> R<ScenePatch> {
    use pdeshape_core::solid::{SolidBlend, SolidOperator, SolidOptions, Trial};
    let rp = p.get_ref();
    let num = |x: &Option<Spanned<NumOrExpr>>, name: &str| -> R<f64> {
        match x {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.{name}")),
            None => Ok(1.0),
        }
    };
    let op = SolidOperator::new(num(&rp.alpha, "alpha")?, num(&rp.beta, "beta")?, num(&rp.gamma, "gamma")?)
        .map_err(|e| ctx.err(span(p), key, e.to_string()))?;
    let mut faces = Vec::with_capacity(4);
    for (f, name) in [(&rp.w0, "w0"), (&rp.w0_tangent, "w0_tangent"), (&rp.w1, "w1"), (&rp.w1_tangent, "w1_tangent")] {
        let f = f.as_ref().ok_or_else(|| {
            ctx.err(
                span(p),
                format!("{key}.{name}"),
                format!("a solid blend needs `{name}` (three expressions in u, v)"),
            )
        })?;
        let field: FieldRef = Arc::new(ctx.field(f, &["u", "v"], &format!("{key}.{name}"))?);
        for i in 0..=8 {
            for j in 0..=8 {
                let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                if !field.eval(&[u, v]).is_finite() {
                    return Err(ctx.err(
                        span(f),
                        format!("{key}.{name}"),
                        format!("not finite at (u, v) = ({u}, {v})"),
                    ));
                }
            }
        }
        faces.push(field);
    }
    let faces: [FieldRef; 4] = faces.try_into().expect("four faces");
    let mut opts = SolidOptions::default();
    if let Some(t) = &rp.trial {
        opts.trial = match t.get_ref().as_str() {
            "complete" => Trial::Complete,
            "galerkin" => Trial::Galerkin,
            "collocation" => Trial::Collocation,
            "paper" => Trial::Paper,
            w => {
                return Err(ctx.err(
                    span(t),
                    format!("{key}.trial"),
                    format!("unknown trial space `{w}` (known: complete, galerkin, collocation, paper)"),
                ));
            }
        };
    }
    if let Some(l) = &rp.lmn {
        let [a, b, c] = *l.get_ref();
        if [a, b, c].iter().any(|x| *x < 1) {
            return Err(ctx.err(span(l), format!("{key}.lmn"), format!("[{a}, {b}, {c}]: every count must be ≥ 1")));
        }
        let k = format!("{key}.lmn");
        ctx.cap(Cap::Modes, a.max(b).max(c) as u128, span(l), &k, &format!("the largest of [{a}, {b}, {c}] (`{k}`)"))?;
        opts.terms = (a as usize, b as usize, c as usize);
        ctx.cap(Cap::Collocation, opts.points(), span(l), &k, &format!("the point set of [{a}, {b}, {c}]"))?;
    }
    let cells = match &rp.cells {
        None => (17, 33, 17),
        Some(c) => {
            let [a, b, d] = *c.get_ref();
            if [a, b, d].iter().any(|x| *x < 2) {
                return Err(ctx.err(span(c), format!("{key}.cells"), format!("[{a}, {b}, {d}]: at least 2 each")));
            }
            let cells = a as u128 * b as u128 * d as u128;
            ctx.cap(Cap::Vertices, cells, span(c), &format!("{key}.cells"), &format!("cells [{a}, {b}, {d}]"))?;
            (a as usize, b as usize, d as usize)
        }
    };
    let primary = rp.primary.as_ref().map(|x| *x.get_ref()).unwrap_or(0.5);
    if !(primary.is_finite() && primary >= 0.0) {
        return Err(ctx.err(None, format!("{key}.primary"), format!("{primary} is not a non-negative number")));
    }
    let blend = Arc::new(SolidBlend::new(op, faces.clone(), opts).map_err(|e| ctx.err(span(p), key, e.to_string()))?);
    let surface = Arc::new(pdeshape_core::solid::SolidFace::section(blend.clone(), 2, 0.5));
    Ok(ScenePatch {
        name: pname.to_string(),
        kind: PatchKind::Solid,
        surface,
        conditions: vec![],
        solver: blend.report().method.to_string(),
        resolution: (cells.0, cells.1),
        color: rp.color.as_ref().map(|c| *c.get_ref()),
        spectral: None,
        sections: None,
        blend: None,
        dynamic: None,
        solid: Some(crate::scene::SolidSetup { blend, faces, cells, primary }),
        trim: None,
        fill: None,
        hole: None,
    })
}
