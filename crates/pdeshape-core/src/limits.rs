//! Caps on the size of a model built from outside input (scene files, the editor): the PDE
//! order, Fourier modes and sine terms, collocation/quadrature points of one solve, mesh
//! vertices per patch and the estimated memory of the meshes.
//!
//! The solvers themselves take any size; these caps stop a typo (`modes = 50000`) or a
//! hostile scene from taking the machine, and say which cap was hit and how to raise it.
//!
//! ```
//! use pdeshape_core::limits::{Cap, Limits};
//! let l = Limits::default();
//! assert!(l.check(Cap::Order, 40u32, "the PDE order").is_ok());
//! let e = l.check(Cap::Modes, 5000u32, "`modes`").unwrap_err();
//! assert!(e.to_string().contains("--limit modes=5000"));
//! ```

use std::fmt;
use std::str::FromStr;

/// One of the caps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cap {
    /// PDE order `2N` (number of conditions of a PDE patch).
    Order,
    /// Fourier modes, sine terms, bubbles, solid terms per direction.
    Modes,
    /// Collocation or quadrature points of one solve.
    Collocation,
    /// Mesh vertices (or solid cells) per patch.
    Vertices,
    /// Estimated memory of the model's meshes and of a solver's dense matrices, MiB.
    Memory,
    /// Size of a scene file, MiB.
    Scene,
    /// Size of an imported model file (STEP or mesh), MiB.
    Model,
    /// Entities of an imported STEP model; vertices plus faces of a mesh file.
    Entities,
}

impl Cap {
    /// Every cap, in the order of [`Cap::name`]'s list.
    pub const ALL: [Cap; 8] =
        [Cap::Order, Cap::Modes, Cap::Collocation, Cap::Vertices, Cap::Memory, Cap::Scene, Cap::Model, Cap::Entities];

    /// The name used by `--limit NAME=VALUE`.
    pub fn name(self) -> &'static str {
        match self {
            Cap::Order => "order",
            Cap::Modes => "modes",
            Cap::Collocation => "collocation",
            Cap::Vertices => "vertices",
            Cap::Memory => "memory",
            Cap::Scene => "scene",
            Cap::Model => "model",
            Cap::Entities => "entities",
        }
    }

    fn unit(self) -> &'static str {
        match self {
            Cap::Memory | Cap::Scene | Cap::Model => " MiB",
            _ => "",
        }
    }
}

/// A value over its cap.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "{what} is {value}{unit}, over the `{name}` cap of {limit}{unit}; raise the cap with `--limit {name}={value}` (library: `Limits::{name}`)",
    name = cap.name(), unit = cap.unit()
)]
pub struct LimitError {
    /// The cap that was hit.
    pub cap: Cap,
    /// What was measured against it.
    pub what: String,
    /// The value asked for.
    pub value: u128,
    /// The cap in force.
    pub limit: usize,
}

/// The caps in force. Defaults: order 64, modes 512, collocation 250 000 points,
/// vertices 4 000 000 per patch, memory 4096 MiB, scene files 16 MiB, model files 256 MiB
/// of at most 4 000 000 entities.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest PDE order `2N`.
    pub order: usize,
    /// Largest count of Fourier modes, sine terms, bubbles or solid terms in one direction.
    pub modes: usize,
    /// Largest number of collocation or quadrature points of one solve.
    pub collocation: usize,
    /// Largest number of mesh vertices (or solid cells) of one patch.
    pub vertices: usize,
    /// Largest estimated memory of all meshes of a model, and of one solver's dense
    /// matrices, MiB.
    pub memory: usize,
    /// Largest scene file, MiB.
    pub scene: usize,
    /// Largest imported model file (STEP), MiB.
    pub model: usize,
    /// Most entities of an imported model file.
    pub entities: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            order: 64,
            modes: 512,
            collocation: 250_000,
            vertices: 4_000_000,
            memory: 4096,
            scene: 16,
            model: 256,
            entities: 4_000_000,
        }
    }
}

impl Limits {
    /// The cap's value.
    pub fn get(&self, cap: Cap) -> usize {
        match cap {
            Cap::Order => self.order,
            Cap::Modes => self.modes,
            Cap::Collocation => self.collocation,
            Cap::Vertices => self.vertices,
            Cap::Memory => self.memory,
            Cap::Scene => self.scene,
            Cap::Model => self.model,
            Cap::Entities => self.entities,
        }
    }

    /// Sets the cap's value.
    pub fn set(&mut self, cap: Cap, value: usize) {
        match cap {
            Cap::Order => self.order = value,
            Cap::Modes => self.modes = value,
            Cap::Collocation => self.collocation = value,
            Cap::Vertices => self.vertices = value,
            Cap::Memory => self.memory = value,
            Cap::Scene => self.scene = value,
            Cap::Model => self.model = value,
            Cap::Entities => self.entities = value,
        }
    }

    /// `Ok` when `value ≤` the cap; otherwise an error naming `what`, the cap and how to
    /// raise it. Takes `u128` so products of sizes cannot overflow on the way here.
    pub fn check(&self, cap: Cap, value: impl Into<u128>, what: &str) -> Result<(), LimitError> {
        let value = value.into();
        let limit = self.get(cap);
        if value > limit as u128 { Err(LimitError { cap, what: what.to_string(), value, limit }) } else { Ok(()) }
    }

    /// `Ok` when a working set of `bytes` fits the `memory` cap (rounded up to whole MiB);
    /// the solvers call it with the size of their dense matrices before allocating them.
    pub fn check_bytes(&self, bytes: u128, what: &str) -> Result<(), LimitError> {
        self.check(Cap::Memory, bytes.div_ceil(1 << 20), what)
    }

    /// Applies one `NAME=VALUE` setting (`--limit`).
    pub fn apply(&mut self, setting: &str) -> Result<(), String> {
        let known = || Cap::ALL.iter().map(|c| c.name()).collect::<Vec<_>>().join(", ");
        let (name, value) =
            setting.split_once('=').ok_or_else(|| format!("`{setting}`: expected NAME=VALUE (names: {})", known()))?;
        let cap = Cap::from_str(name.trim())?;
        let digits = value.trim().replace('_', "");
        let value: usize = digits.parse().map_err(|e: std::num::ParseIntError| {
            use std::num::IntErrorKind::*;
            match e.kind() {
                PosOverflow => format!(
                    "`{setting}`: {digits} is larger than the largest cap this machine can hold ({})",
                    usize::MAX
                ),
                _ => format!("`{setting}`: {} is not a whole number", value.trim()),
            }
        })?;
        self.set(cap, value);
        Ok(())
    }
}

impl FromStr for Cap {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Cap::ALL.into_iter().find(|c| c.name() == s).ok_or_else(|| {
            format!("unknown cap `{s}` (known: {})", Cap::ALL.iter().map(|c| c.name()).collect::<Vec<_>>().join(", "))
        })
    }
}

impl fmt::Display for Cap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_apply_and_errors_say_how_to_raise() {
        let mut l = Limits::default();
        l.apply("order=80").unwrap();
        l.apply(" vertices = 9_000_000 ").unwrap();
        assert_eq!((l.order, l.vertices), (80, 9_000_000));
        assert!(l.apply("order").unwrap_err().contains("NAME=VALUE"));
        assert!(l.apply("colour=3").unwrap_err().contains("unknown cap `colour`"));
        assert!(l.apply("modes=-1").unwrap_err().contains("not a whole number"));
        // regression: an overflowing value was called "not a whole number"
        let e = l.apply("vertices=18446744073709551616").unwrap_err();
        assert!(e.contains("larger than the largest cap"), "{e}");
        l.apply("scene=2").unwrap();
        assert_eq!(l.scene, 2);
        let e = l.check(Cap::Memory, 5000u32, "the meshes' estimated memory").unwrap_err();
        assert_eq!(
            e.to_string(),
            "the meshes' estimated memory is 5000 MiB, over the `memory` cap of 4096 MiB; raise the cap with \
             `--limit memory=5000` (library: `Limits::memory`)"
        );
        assert!(l.check(Cap::Order, 80u32, "order").is_ok());
        assert!(l.check(Cap::Collocation, u128::MAX, "points").is_err());
    }
}
