//! Structured grid meshes of patches with analytic normals.

use super::{Mesh, ScalarField};
use crate::Vec3;
use crate::patch::{CurvatureKind, Surface};
use rayon::prelude::*;

/// Options for [`grid_mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct GridOptions {
    /// Vertices along `u` (≥ 2).
    pub nu: usize,
    /// Vertices along `v` (≥ 2; a periodic patch repeats its seam column).
    pub nv: usize,
    /// Range of `u` to mesh (default `[0, 1]`).
    pub u_range: (f64, f64),
}

impl GridOptions {
    /// `nu × nv` vertices over `u ∈ [0, 1]`.
    pub fn new(nu: usize, nv: usize) -> Self {
        GridOptions { nu, nv, u_range: (0.0, 1.0) }
    }
}

/// The `u` and `v` parameter values of the grid vertices.
pub fn grid_params(s: &dyn Surface, o: &GridOptions) -> (Vec<f64>, Vec<f64>) {
    let d = s.v_domain();
    let us = (0..o.nu).map(|i| o.u_range.0 + (o.u_range.1 - o.u_range.0) * i as f64 / (o.nu - 1) as f64).collect();
    let vs = (0..o.nv).map(|j| d.at(j as f64 / (o.nv - 1) as f64)).collect();
    (us, vs)
}

/// The reference size of `|X_u||X_v|` for degeneracy tests (poles): the median over at
/// most 4097 evenly strided points of `(X_u, X_v)`.
fn area_scale<I: ExactSizeIterator<Item = (Vec3, Vec3)>>(d: I) -> f64 {
    let stride = (d.len() / 4096).max(1);
    let mut scales: Vec<f64> = d.step_by(stride).map(|(xu, xv)| xu.norm() * xv.norm()).collect();
    if scales.is_empty() {
        return f64::MIN_POSITIVE;
    }
    let mid = scales.len() / 2;
    scales.select_nth_unstable_by(mid, f64::total_cmp).1.max(f64::MIN_POSITIVE)
}

/// Meshes a patch on a structured `nu × nv` grid.
///
/// Normals are analytic: `n = X_u × X_v / |X_u × X_v|`. Where the cross product vanishes
/// (a pole: a boundary curve that degenerates to a point, `X_v = 0`), the limit
/// `X_u × X_v ≈ (u − u₀) X_u × X_uv` gives the normal `±X_u × X_uv` (sign from the side of
/// the domain the limit is taken from); likewise `±X_uv × X_v` where `X_u = 0`. A vertex
/// where even that vanishes takes the average of its neighbours' normals.
///
/// Fails (naming the parameters) when the patch evaluates to a non-finite point.
pub fn grid_mesh(s: &dyn Surface, o: &GridOptions) -> Result<Mesh, String> {
    // one entry into the thread pool for the whole mesh: each parallel step below, called
    // from outside the pool, would otherwise be a separate hand-over to the workers
    rayon::scope(|_| grid_mesh_in_pool(s, o))
}

fn grid_mesh_in_pool(s: &dyn Surface, o: &GridOptions) -> Result<Mesh, String> {
    assert!(o.nu >= 2 && o.nv >= 2, "a grid mesh needs at least 2 × 2 vertices");
    let (us, vs) = grid_params(s, o);
    let flat = s.grid(&us, &vs);
    assemble(s, o, &us, &vs, &flat, 3)
}

/// [`grid_mesh`] with the exact curvature fields `kinds`
/// ([`add_curvatures`](Mesh::add_curvatures)), the mesh and the curvatures from one
/// evaluation of second derivatives on the grid ([`Surface::grid2`]) where `grid_mesh` and
/// `add_curvatures` evaluate the grid twice. The same mesh and fields as those two calls
/// where a surface's `grid2` starts with its `grid`'s numbers (spectral patches, blends,
/// Hermite patches: bit for bit); to round-off elsewhere (on the examples, the dolphin's
/// fins by ≤ 8.9e-16 in position and the fills by ≤ 4.1e-15 in their normals).
pub fn grid_mesh_with_curvatures(s: &dyn Surface, o: &GridOptions, kinds: &[CurvatureKind]) -> Result<Mesh, String> {
    rayon::scope(|_| {
        assert!(o.nu >= 2 && o.nv >= 2, "a grid mesh needs at least 2 × 2 vertices");
        let (us, vs) = grid_params(s, o);
        let jets = s.grid2(&us, &vs);
        let mut m = assemble(s, o, &us, &vs, &jets, 4)?;
        m.fields.extend(curvature_fields(&jets, kinds));
        Ok(m)
    })
}

/// The mesh of the grid `us × vs` from its points and derivatives `flat` (row-major in
/// `u`): entries 0, 1 and 2 of each are `X`, `X_u` and `X_v`, entry `at_uv` is `X_uv`.
fn assemble<const N: usize>(
    s: &dyn Surface,
    o: &GridOptions,
    us: &[f64],
    vs: &[f64],
    flat: &[[Vec3; N]],
    at_uv: usize,
) -> Result<Mesh, String> {
    let n = o.nu * o.nv;
    // reference size of |X_u||X_v| for the degeneracy test: the median over at most
    // 4097 evenly strided vertices
    let reference = area_scale(flat.iter().map(|d| (d[1], d[2])));
    // the first non-finite point in order: a plain scan (a parallel `position_first` shares
    // its best index through an atomic read at every vertex, which cost more than the test)
    if let Some(k) = flat.iter().position(|d| !d[0].is_finite()) {
        return Err(format!("the patch is not finite at (u, v) = ({}, {})", us[k / o.nv], vs[k % o.nv]));
    }
    let dom = s.v_domain();
    let u_mid = 0.5 * (o.u_range.0 + o.u_range.1);
    let v_mid = 0.5 * (dom.start + dom.end);
    // normals, positions and UVs in parallel by rows (row and column from the loops, not
    // from a division per vertex); the vertices where even the limit vanishes, in order
    let mut normals = vec![Vec3::ZERO; n];
    let mut positions = vec![Vec3::ZERO; n];
    let mut uvs = vec![[0.0; 2]; n];
    let (fu, fv) = (1.0 / (o.nu - 1) as f64, 1.0 / (o.nv - 1) as f64);
    let threshold = 1e-9 * reference;
    let missing: Vec<usize> = normals
        .par_chunks_mut(o.nv)
        .zip(positions.par_chunks_mut(o.nv))
        .zip(uvs.par_chunks_mut(o.nv))
        .zip(flat.par_chunks(o.nv))
        .enumerate()
        .flat_map_iter(|(i, (((dst, pos), uv), row))| {
            crate::cancel::checkpoint();
            let mut gone = Vec::new();
            let ui = i as f64 * fu;
            for (j, (((nm, p), t), d)) in dst.iter_mut().zip(pos.iter_mut()).zip(uv.iter_mut()).zip(row).enumerate() {
                let (x, pu, pv, puv) = (d[0], d[1], d[2], d[at_uv]);
                *p = x;
                *t = [ui, j as f64 * fv];
                let nrm = pu.cross(pv);
                // one square root a vertex: the length that tests for a pole also scales
                // the normal (`normalized` of a finite nonzero vector is `nrm / |nrm|`)
                let len = nrm.norm();
                if len > threshold && len.is_finite() {
                    *nm = nrm / len;
                    continue;
                }
                let nrm = if len <= threshold {
                    let side_u = if us[i] < u_mid { 1.0 } else { -1.0 };
                    let side_v = if vs[j] < v_mid { 1.0 } else { -1.0 };
                    if pv.norm() <= pu.norm() { pu.cross(puv) * side_u } else { puv.cross(pv) * side_v }
                } else {
                    nrm
                };
                match nrm.normalized() {
                    Some(unit) => *nm = unit,
                    None => gone.push(i * o.nv + j),
                }
            }
            gone
        })
        .collect();
    for &k in &missing {
        let (i, j) = (k / o.nv, k % o.nv);
        let mut acc = Vec3::ZERO;
        for (di, dj) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1), (-1, -1), (1, 1), (-1, 1), (1, -1)] {
            let (a, b) = (i as i64 + di, j as i64 + dj);
            if a >= 0 && b >= 0 && (a as usize) < o.nu && (b as usize) < o.nv {
                acc += normals[a as usize * o.nv + b as usize];
            }
        }
        normals[k] = acc.normalized().unwrap_or(Vec3::new(0.0, 0.0, 1.0));
    }
    // (u, v) → counter-clockwise about X_u × X_v
    let mut quads = vec![[0u32; 4]; (o.nu - 1) * (o.nv - 1)];
    quads.par_chunks_mut(o.nv - 1).enumerate().for_each(|(i, row)| {
        for (j, q) in row.iter_mut().enumerate() {
            let a = (i * o.nv + j) as u32;
            let b = ((i + 1) * o.nv + j) as u32;
            *q = [a, b, b + 1, a + 1];
        }
    });
    Ok(Mesh { positions, normals, uvs, quads, grid: Some((o.nu, o.nv)), ..Default::default() })
}

/// The curvature fields `kinds` from the jets `[X, X_u, X_v, X_uu, X_uv, X_vv]` of each
/// vertex.
fn curvature_fields(jets: &[[Vec3; 6]], kinds: &[CurvatureKind]) -> Vec<ScalarField> {
    if kinds.is_empty() {
        return Vec::new();
    }
    // a pole (|X_u × X_v| below 1e-8 of the patch's typical |X_u||X_v|) has no
    // curvature: at a distance δ from it the formulas lose ~ε/δ relatively (N and G
    // are O(δ) and O(δ²) from O(1) data), so the cut keeps ~1e-8 relative accuracy
    let reference = area_scale(jets.iter().map(|j| (j[1], j[2])));
    let curv: Vec<Option<crate::patch::Curvature>> = jets
        .par_iter()
        .map(|j| if j[1].cross(j[2]).norm() > 1e-8 * reference { crate::patch::curvature(j) } else { None })
        .collect();
    kinds
        .iter()
        .map(|&k| ScalarField {
            name: k.field_name().into(),
            values: curv.iter().map(|c| c.as_ref().map_or(0.0, |c| k.of(c))).collect(),
        })
        .collect()
}

impl Mesh {
    /// Adds the exact curvatures ([`crate::patch::curvature`]) of `s` at every vertex, one
    /// field per kind ([`CurvatureKind::field_name`]): on the grid path (`Surface::grid2`)
    /// for a structured grid mesh over `u ∈ [0, 1]`, else at each vertex's `(u, v)` from its
    /// UV (`u = uv₀`, `v` the domain at `uv₁`). 0 where they are undefined: at poles, where
    /// `|X_u × X_v|` is below 1e-8 of the median `|X_u||X_v|`.
    pub fn add_curvatures(&mut self, s: &dyn Surface, kinds: &[CurvatureKind]) {
        if kinds.is_empty() {
            return;
        }
        let jets = match self.grid {
            Some((nu, nv)) if nu * nv == self.positions.len() => {
                let (us, vs) = grid_params(s, &GridOptions::new(nu, nv));
                s.grid2(&us, &vs)
            }
            _ => {
                let dom = s.v_domain();
                self.uvs.par_iter().map(|uv| s.jet2(uv[0], dom.at(uv[1]))).collect()
            }
        };
        self.fields.extend(curvature_fields(&jets, kinds));
    }

    /// Adds the exact mean curvature as the field `mean_curvature`
    /// ([`add_curvatures`](Self::add_curvatures) of [`CurvatureKind::Mean`]).
    pub fn add_mean_curvature(&mut self, s: &dyn Surface) {
        self.add_curvatures(s, &[CurvatureKind::Mean]);
    }

    /// Adds a per-vertex field computed from `(u, v)` of a structured grid mesh.
    pub fn add_grid_field(&mut self, name: &str, s: &dyn Surface, f: impl Fn(&dyn Surface, f64, f64) -> f64 + Sync) {
        let Some((nu, nv)) = self.grid else { return };
        let (us, vs) = grid_params(s, &GridOptions::new(nu, nv));
        let values: Vec<f64> = (0..nu * nv).into_par_iter().map(|k| f(s, us[k / nv], vs[k % nv])).collect();
        self.fields.push(ScalarField { name: name.into(), values });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::Surface;
    use crate::patch::test_shapes::Sphere;

    /// The unit sphere: poles at u = 0 and 1.
    const SPHERE: Sphere = Sphere(1.0);

    #[test]
    fn mean_curvature_of_the_unit_sphere_is_one_and_undefined_at_the_poles() {
        let us = [0.0, 0.1, 0.37, 0.5, 0.81];
        let vs = [0.0, 1.0, 2.5, 4.0];
        let g = SPHERE.grid2(&us, &vs);
        for (k, j) in g.iter().enumerate() {
            let u = us[k / vs.len()];
            match crate::patch::mean_curvature(j) {
                Some(h) => assert!((h.abs() - 1.0).abs() < 1e-12, "u = {u}: H = {h}"),
                None => assert_eq!(u, 0.0, "H undefined away from the pole"),
            }
        }
    }

    #[test]
    fn curvature_fields_of_the_unit_sphere() {
        let mut m = grid_mesh(&SPHERE, &GridOptions::new(11, 9)).unwrap();
        m.add_curvatures(&SPHERE, &CurvatureKind::ALL);
        let f = |k: CurvatureKind| &m.field(k.field_name()).unwrap().values;
        for (i, uv) in m.uvs.iter().enumerate() {
            let pole = uv[0] == 0.0 || uv[0] == 1.0;
            let (g, h, k1, k2) = (
                f(CurvatureKind::Gauss)[i],
                f(CurvatureKind::Mean)[i],
                f(CurvatureKind::K1)[i],
                f(CurvatureKind::K2)[i],
            );
            if pole {
                assert_eq!((g, h, k1, k2), (0.0, 0.0, 0.0, 0.0), "undefined at the poles: 0");
            } else {
                // K = 1 and |H| = 1 to round-off; κ₁, κ₂ to √ε (an umbilic: see curvature.rs)
                assert!((g - 1.0).abs() < 1e-13 && (h.abs() - 1.0).abs() < 1e-13, "{uv:?}: {g} {h}");
                assert!((k1 - h).abs() < 1e-6 && (k2 - h).abs() < 1e-6 && k1 <= k2, "{uv:?}: {k1} {k2}");
            }
        }
    }

    /// One evaluation of second derivatives gives the mesh and the fields that `grid_mesh`
    /// and `add_curvatures` give from two: on the sphere, whose poles take the normal from
    /// `X_uv` (entry 4 of a `grid2` jet, entry 3 of a `grid` one).
    #[test]
    fn mesh_with_curvatures_is_the_mesh_then_its_curvatures() {
        let o = GridOptions::new(11, 9);
        let mut two = grid_mesh(&SPHERE, &o).unwrap();
        two.add_curvatures(&SPHERE, &CurvatureKind::ALL);
        let one = grid_mesh_with_curvatures(&SPHERE, &o, &CurvatureKind::ALL).unwrap();
        assert_eq!(one, two);
        // the poles' normals came from X_uv: radial there too
        for k in [0, 10 * 9 + 4] {
            assert!((one.positions[k].normalized().unwrap().dot(one.normals[k]).abs() - 1.0).abs() < 1e-9);
        }
    }

    #[test]
    fn sphere_normals_are_radial_including_poles() {
        let m = grid_mesh(&SPHERE, &GridOptions::new(9, 13)).unwrap();
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let r = p.normalized().unwrap();
            // X_u × X_v points inwards or outwards consistently; poles included.
            assert!((r.dot(*n).abs() - 1.0).abs() < 1e-9, "{p:?} {n:?}");
        }
        let s0 = m.positions[20].dot(m.normals[20]).signum();
        assert!(m.positions.iter().zip(&m.normals).all(|(p, n)| p.dot(*n).signum() == s0));
        assert_eq!(m.quads.len(), 8 * 12);
    }

    #[test]
    fn grid_bytes_bounds_the_bytes_of_a_grid_mesh() {
        let mut m = grid_mesh(&SPHERE, &GridOptions::new(30, 41)).unwrap();
        m.add_mean_curvature(&SPHERE);
        let (have, bound) = (m.bytes() as u128, Mesh::grid_bytes(30 * 41, 1, 0));
        assert!(have <= bound && have as f64 > 0.95 * bound as f64, "{have} vs {bound}");
    }
}
