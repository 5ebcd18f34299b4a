//! `kind = "hermite"`: ruled or Hermite interpolation in `u` of the conditions (no PDE).

use super::{PatchInput, conditions};
use crate::scene::ScenePatch;
use crate::scene::ctx::R;
use pdeshape_core::patch::HermitePatch;
use std::sync::Arc;

/// The keys a Hermite patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] = &["v", "resolution", "conditions", "sections", "trim"];

/// Keys it refuses, with the reason.
pub(super) const INSTEAD: &[(&str, &str)] = &[];

/// Interpolates the conditions in `u` (no solve).
pub(super) fn build(input: &PatchInput) -> R<ScenePatch> {
    let c = conditions::read(input)?;
    let h = HermitePatch::new(&c.conditions, c.domain)
        .map_err(|e| input.ctx.err(c.span.clone(), format!("{}.conditions", input.key), e.to_string()))?;
    conditions::finish(input, c, Arc::new(h), "hermite-interpolation".into())
}
