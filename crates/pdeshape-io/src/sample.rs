//! Exact points of a scene's patch at many parameters: what `pdeshape sample` prints one
//! line at a time, and what the Python module's `Patch.evaluate` returns as an array.

use crate::scene::ScenePatch;
use pdeshape_core::patch::Surface;
use pdeshape_core::solid::SolidBlend;
use rayon::prelude::*;

/// What the parameters are evaluated on.
#[derive(Clone, Copy)]
pub enum Target<'a> {
    /// A surface at `(u, v)`.
    Surface(&'a dyn Surface),
    /// A solid at `(u, v, w)`.
    Solid(&'a SolidBlend),
}

impl<'a> Target<'a> {
    /// The patch's own target: its solid, else its surface (a dynamic blend's first frame).
    pub fn of(p: &'a ScenePatch) -> Target<'a> {
        match &p.solid {
            Some(sd) => Target::Solid(&sd.blend),
            None => Target::Surface(p.surface.as_ref()),
        }
    }

    /// Parameters per point: 2 for a surface, 3 for a solid.
    pub fn arity(&self) -> usize {
        match self {
            Target::Surface(_) => 2,
            Target::Solid(_) => 3,
        }
    }
}

/// Points at or above this count are spread over the current rayon pool.
pub const PARALLEL_FROM: usize = 4096;

/// `out[3k..3k+3]` = the point at parameters `params[a·k .. a·k + a]` (`a` =
/// [`Target::arity`]), computed by the same calls as `pdeshape sample`, so the results are
/// equal bit for bit. Ranges are the caller's to check.
pub fn points_into(target: Target<'_>, params: &[f64], out: &mut [f64]) {
    let a = target.arity();
    assert_eq!(params.len() / a * 3, out.len(), "three outputs per point");
    let one = |(dst, p): (&mut [f64], &[f64])| {
        let x = match target {
            Target::Surface(s) => s.point(p[0], p[1]),
            Target::Solid(b) => b.point(p[0], p[1], p[2]),
        };
        dst.copy_from_slice(&[x.x, x.y, x.z]);
    };
    if out.len() / 3 >= PARALLEL_FROM {
        out.par_chunks_mut(3).zip(params.par_chunks(a)).for_each(one);
    } else {
        out.chunks_mut(3).zip(params.chunks(a)).for_each(one);
    }
}
