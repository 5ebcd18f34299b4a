//! `kind = "pde"`: `(∂u² + a²∂v²)^N X = 0` by the spectral method (SPEC §3), `N` from the
//! number of conditions.

use super::{PatchInput, conditions};
use crate::scene::ScenePatch;
use crate::scene::ctx::{Ctx, R, span};
use std::sync::Arc;
use crate::scene::raw::RawPatch;
use pdeshape_core::limits::Cap;
use pdeshape_core::patch::{Condition, VDomain};
use pdeshape_core::spectral::{SpectralOptions, SpectralPatch};
use std::ops::Range;

/// The keys a PDE patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] = &["v", "resolution", "conditions", "sections", "trim", "a", "modes", "omega"];

/// Keys it refuses, with the reason.
pub(super) const INSTEAD: &[(&str, &str)] = &[];

/// Reads the conditions and solves the patch.
pub(super) fn build(input: &PatchInput) -> R<ScenePatch> {
    let c = conditions::read(input)?;
    let sp = Arc::new(solve(input.ctx, &input.key, input.raw.get_ref(), &c.conditions, c.domain, c.span.clone())?);
    let mut p = conditions::finish(input, c, sp.clone(), "spectral".into())?;
    p.spectral = Some(sp);
    Ok(p)
}

/// Solves the patch: `a` (default 1), `modes` (default 6, capped), `omega`; the order is
/// capped too.
pub(super) fn solve(
    ctx: &Ctx,
    key: &str,
    rp: &RawPatch,
    conditions: &[Condition],
    domain: VDomain,
    conds_span: Option<Range<usize>>,
) -> R<SpectralPatch> {
    let a = match &rp.a {
        Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.a"))?,
        None => 1.0,
    };
    let modes = match &rp.modes {
        Some(m) => ctx.capped(m, 0, Cap::Modes, &format!("{key}.modes"))?,
        None => 6,
    };
    let omega = rp.omega.as_ref().map(|x| ctx.num(x.get_ref(), span(x), &format!("{key}.omega"))).transpose()?;
    let what = format!("the PDE order (conditions of `{key}`)");
    ctx.cap(Cap::Order, conditions.len() as u128, conds_span.clone(), &format!("{key}.conditions"), &what)?;
    SpectralPatch::new(conditions, domain, SpectralOptions { a, modes, omega })
        .map_err(|e| ctx.err(conds_span, format!("{key}.conditions"), e.to_string()))
}
