//! `kind = "hermite"`: ruled or Hermite interpolation in `u` of the conditions (no PDE).

/// The keys a Hermite patch takes besides `kind` and `color`.
pub(super) const KEYS: &[&str] = &["v", "resolution", "conditions", "sections", "trim"];
