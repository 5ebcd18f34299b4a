//! Process-wide counts of solves, by kind, so that callers (and tests) can check that work
//! is done once: a scene loaded and then meshed, checked and drawn solves each patch when
//! it is loaded and not again.
//!
//! A count is one relaxed atomic increment per solve; nothing else is recorded.

use std::sync::atomic::{AtomicUsize, Ordering};

/// What was solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolveKind {
    /// A spectral PDE patch ([`crate::spectral::SpectralPatch::new`]; fills too).
    Spectral,
    /// A static blend ([`crate::blend::StaticBlend::new`]).
    StaticBlend,
    /// One frame of a dynamic blend (solved on first request, then kept).
    DynamicFrame,
    /// A solid blend ([`crate::solid::SolidBlend::new`]).
    Solid,
    /// A trim's Laplace map ([`crate::trim::LaplaceMap::new`]).
    LaplaceMap,
}

impl SolveKind {
    /// Every kind, in the order of [`Solves`]' fields.
    pub const ALL: [SolveKind; 5] =
        [SolveKind::Spectral, SolveKind::StaticBlend, SolveKind::DynamicFrame, SolveKind::Solid, SolveKind::LaplaceMap];
}

static COUNTS: [AtomicUsize; 5] = [const { AtomicUsize::new(0) }; 5];

/// Counts one solve of `kind` (successful or not: the work was done).
pub fn record(kind: SolveKind) {
    COUNTS[kind as usize].fetch_add(1, Ordering::Relaxed);
}

/// The solves counted so far in this process, per kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Solves(pub [usize; 5]);

impl Solves {
    /// The counts now.
    pub fn now() -> Solves {
        Solves(std::array::from_fn(|k| COUNTS[k].load(Ordering::Relaxed)))
    }

    /// The solves of `kind`.
    pub fn of(&self, kind: SolveKind) -> usize {
        self.0[kind as usize]
    }

    /// The solves since `earlier`, per kind.
    pub fn since(&self, earlier: Solves) -> Solves {
        Solves(std::array::from_fn(|k| self.0[k] - earlier.0[k]))
    }

    /// All kinds together.
    pub fn total(&self) -> usize {
        self.0.iter().sum()
    }
}
