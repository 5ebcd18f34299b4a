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

/// Surface points per batch ([`Surface::points_at`]); blocks of this many go to the
/// rayon pool at or above [`PARALLEL_FROM`] points.
const BLOCK: usize = 1024;

/// `out[3k..3k+3]` = the point at parameters `params[a·k .. a·k + a]` (`a` =
/// [`Target::arity`]), computed by the same calls as `pdeshape sample` (a surface's
/// points in batches through [`Surface::points_at`], whose numbers do not depend on how
/// the points are grouped), so the results are equal bit for bit. Ranges are the
/// caller's to check.
pub fn points_into(target: Target<'_>, params: &[f64], out: &mut [f64]) {
    let a = target.arity();
    assert_eq!(params.len() / a * 3, out.len(), "three outputs per point");
    let block = |(dst, p): (&mut [f64], &[f64])| match target {
        Target::Surface(s) => {
            let uv: Vec<[f64; 2]> = p.chunks_exact(2).map(|q| [q[0], q[1]]).collect();
            let mut x = vec![pdeshape_core::Vec3::ZERO; uv.len()];
            s.points_at(&uv, &mut x);
            for (d, x) in dst.chunks_exact_mut(3).zip(x) {
                d.copy_from_slice(&[x.x, x.y, x.z]);
            }
        }
        Target::Solid(b) => {
            for (d, q) in dst.chunks_exact_mut(3).zip(p.chunks_exact(3)) {
                let x = b.point(q[0], q[1], q[2]);
                d.copy_from_slice(&[x.x, x.y, x.z]);
            }
        }
    };
    if out.len() / 3 >= PARALLEL_FROM {
        out.par_chunks_mut(3 * BLOCK).zip(params.par_chunks(a * BLOCK)).for_each(block);
    } else {
        out.chunks_mut(3 * BLOCK).zip(params.chunks(a * BLOCK)).for_each(block);
    }
}
