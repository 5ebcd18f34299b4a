//! Patch kinds in scene files, one file each: the keys a kind takes (`KEYS`), the keys it
//! refuses with a reason of its own (`INSTEAD`), and how it is built. [`KINDS`] registers
//! them; [`check_keys`] checks every patch's keys against its kind's, so no key is ignored.
//!
//! `hermite`, `pde`, `blend` and `dynamic` patches take conditions (curves, `sections`,
//! `start`/`end`, trim curves of earlier patches), read by `conditions.rs` for all of them,
//! and differ in their solve; `solid` and `fill` patches are built from their own keys.
//!
//! A new kind: its file here (`KEYS`, `INSTEAD`, `build`), one line in [`kinds!`] below and
//! a `PatchKind` variant.

mod conditions;

use crate::scene::ctx::{Ctx, R, span};
use crate::scene::raw::*;
use crate::scene::{PatchKind, ScenePatch, SceneSurface};
use indexmap::IndexMap;
use pdeshape_core::data::FieldRef;
use toml::Spanned;

/// A patch kind as scene files know it.
pub(in crate::scene) struct KindSpec {
    /// The kind.
    pub kind: PatchKind,
    /// Its name in scene files (`kind = "…"`): its module's name.
    pub name: &'static str,
    /// The keys it takes besides [`COMMON`].
    pub keys: &'static [&'static str],
    /// Keys it refuses, each with the reason.
    pub instead: &'static [(&'static str, &'static str)],
    /// Builds (and solves) a patch of this kind.
    pub build: fn(&PatchInput) -> R<ScenePatch>,
}

/// What a kind's `build` gets: the scene so far and the raw patch, its keys checked.
pub(in crate::scene) struct PatchInput<'a, 'c> {
    /// Parameters, overrides, caps, located errors.
    pub ctx: &'a Ctx<'c>,
    /// The patch's name.
    pub name: &'a str,
    /// `patches.NAME`, the prefix of its keys in errors.
    pub key: String,
    /// The raw patch.
    pub raw: &'a Spanned<RawPatch>,
    /// Its kind.
    pub kind: PatchKind,
    /// The scene's curves.
    pub curves: &'a IndexMap<String, FieldRef>,
    /// The scene's primary surfaces.
    pub surfaces: &'a [SceneSurface],
    /// The patches built before it (trim curves of earlier patches).
    pub done: &'a [ScenePatch],
}

/// Registers the kinds: `module: Variant` declares the kind's file and lists it in
/// [`KINDS`] with the `KEYS`, `INSTEAD` and `build` that file defines.
macro_rules! kinds {
    ($($module:ident: $kind:ident),* $(,)?) => {
        $(mod $module;)*

        /// Every patch kind, in the order error messages list them.
        pub(in crate::scene) const KINDS: &[KindSpec] = &[$(KindSpec {
            kind: PatchKind::$kind,
            name: stringify!($module),
            keys: $module::KEYS,
            instead: $module::INSTEAD,
            build: $module::build,
        }),*];
    };
}

kinds! {
    hermite: Hermite,
    pde: Pde,
    blend: Blend,
    dynamic: Dynamic,
    solid: Solid,
    fill: Fill,
}

/// Keys every patch takes.
const COMMON: &[&str] = &["kind", "color"];

/// The kind named by `kind = "…"`.
fn kind_of(ctx: &Ctx, key: &str, rp: &RawPatch) -> R<PatchKind> {
    let name = rp.kind.get_ref().as_str();
    KINDS.iter().find(|k| k.name == name).map(|k| k.kind).ok_or_else(|| {
        let known: Vec<&str> = KINDS.iter().map(|k| k.name).collect();
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
                    KINDS.iter().filter(|k| k.keys.contains(&name)).map(|k| format!("\"{}\"", k.name)).collect();
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

/// Builds one patch: its kind, its keys checked against the kind's, then the kind's
/// `build`.
pub(in crate::scene) fn build_patch(
    ctx: &Ctx,
    name: &str,
    raw: &Spanned<RawPatch>,
    curves: &IndexMap<String, FieldRef>,
    surfaces: &[SceneSurface],
    done: &[ScenePatch],
) -> R<ScenePatch> {
    let key = format!("patches.{name}");
    let kind = kind_of(ctx, &key, raw.get_ref())?;
    check_keys(ctx, &key, raw, kind)?;
    let spec = KINDS.iter().find(|k| k.kind == kind).expect("every kind is registered");
    (spec.build)(&PatchInput { ctx, name, key, raw, kind, curves, surfaces, done })
}
