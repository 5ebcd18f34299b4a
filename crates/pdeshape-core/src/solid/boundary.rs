//! Meshes of a solid blend: hexahedral volume, closed boundary surface, cross sections.

use super::SolidBlend;
use crate::Vec3;
use crate::mesh::{HexMesh, Mesh, ScalarField};
use std::collections::HashMap;

/// The hexahedral volume mesh on an `(nu, nv, nw)`-vertex grid, with cell fields
/// `residual` (|PDE residual| at the cell centre) and `jacobian` (`det J` at the centre).
pub fn hex_mesh(s: &SolidBlend, res: (usize, usize, usize)) -> HexMesh {
    let (nu, nv, nw) = (res.0.max(2), res.1.max(2), res.2.max(2));
    let lin = |n: usize| -> Vec<f64> { (0..n).map(|i| i as f64 / (n - 1) as f64).collect() };
    let (us, vs, ws) = (lin(nu), lin(nv), lin(nw));
    let positions = s.grid(&us, &vs, &ws);
    let id = |i: usize, j: usize, k: usize| ((i * nv + j) * nw + k) as u32;
    let mut hexes = Vec::with_capacity((nu - 1) * (nv - 1) * (nw - 1));
    let mut centres = Vec::with_capacity(hexes.capacity());
    for i in 0..nu - 1 {
        for j in 0..nv - 1 {
            for k in 0..nw - 1 {
                // VTK hexahedron: bottom face (w = k) counter-clockwise, then the top face
                hexes.push([
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ]);
                centres.push(((us[i] + us[i + 1]) / 2.0, (vs[j] + vs[j + 1]) / 2.0, (ws[k] + ws[k + 1]) / 2.0));
            }
        }
    }
    use rayon::prelude::*;
    let (residual, jac): (Vec<f64>, Vec<f64>) = centres
        .par_iter()
        .map(|&(u, v, w)| {
            let [a, b, c] = s.jacobian(u, v, w);
            (s.residual(u, v, w).norm(), a.dot(b.cross(c)))
        })
        .unzip();
    HexMesh {
        name: String::new(),
        positions,
        hexes,
        point_fields: vec![],
        cell_fields: vec![
            ScalarField { name: "residual".into(), values: residual },
            ScalarField { name: "jacobian".into(), values: jac },
        ],
    }
}

/// Welds points closer than `tol` (grid hashing with a 27-cell neighbourhood).
struct Welder {
    tol: f64,
    cells: HashMap<[i64; 3], Vec<u32>>,
    points: Vec<Vec3>,
}

impl Welder {
    fn key(&self, p: Vec3) -> [i64; 3] {
        [(p.x / self.tol).floor() as i64, (p.y / self.tol).floor() as i64, (p.z / self.tol).floor() as i64]
    }

    fn insert(&mut self, p: Vec3) -> u32 {
        let k = self.key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        for &i in list {
                            if (self.points[i as usize] - p).norm() <= self.tol {
                                return i;
                            }
                        }
                    }
                }
            }
        }
        let i = self.points.len() as u32;
        self.points.push(p);
        self.cells.entry(k).or_default().push(i);
        i
    }
}

/// The boundary of the solid as a closed, consistently oriented triangle mesh (see
/// [`boundary_mesh_of`]).
pub fn boundary_mesh(s: &SolidBlend, res: (usize, usize, usize)) -> Mesh {
    boundary_mesh_of(&|u, v, w| s.point(u, v, w), res)
}

/// The boundary of any map `x: [0, 1]³ → R³` as a closed, consistently oriented triangle
/// mesh: the six faces of the parameter cube at `res` vertices per direction. Coincident
/// vertices are welded, triangles that collapse (a face mapped onto an axis or a point) are
/// dropped, and pairs of triangles covering the same vertices with opposite orientation —
/// the two sides of a periodic seam, interior to the solid — are removed. The orientation
/// is made outward by the sign of the enclosed volume (divergence theorem).
pub fn boundary_mesh_of(x: &(dyn Fn(f64, f64, f64) -> Vec3 + Sync), res: (usize, usize, usize)) -> Mesh {
    let (nu, nv, nw) = (res.0.max(2), res.1.max(2), res.2.max(2));
    let probe: Vec<Vec3> =
        (0..27).map(|i| x((i % 3) as f64 / 2.0, ((i / 3) % 3) as f64 / 2.0, (i / 9) as f64 / 2.0)).collect();
    let (lo, hi) = probe.iter().fold((probe[0], probe[0]), |(lo, hi), p| {
        (Vec3::new(lo.x.min(p.x), lo.y.min(p.y), lo.z.min(p.z)), Vec3::new(hi.x.max(p.x), hi.y.max(p.y), hi.z.max(p.z)))
    });
    let size = (hi - lo).norm().max(1e-300);
    let mut weld = Welder { tol: 1e-9 * size, cells: HashMap::new(), points: Vec::new() };
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for (axis, value) in [(0usize, 0.0), (0, 1.0), (1, 0.0), (1, 1.0), (2, 0.0), (2, 1.0)] {
        let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
        let n = [nu, nv, nw];
        let (np, nq) = (n[p], n[q]);
        let mut ids = vec![0u32; np * nq];
        for i in 0..np {
            for j in 0..nq {
                let mut t = [0.0; 3];
                t[axis] = value;
                t[p] = i as f64 / (np - 1) as f64;
                t[q] = j as f64 / (nq - 1) as f64;
                ids[i * nq + j] = weld.insert(x(t[0], t[1], t[2]));
            }
        }
        // (p, q, axis) is cyclic: e_p × e_q = e_axis points outward at value = 1 in the
        // parameter cube; reversed at value = 0.
        let reverse = value == 0.0;
        for i in 0..np - 1 {
            for j in 0..nq - 1 {
                let (a, b, c, d) =
                    (ids[i * nq + j], ids[(i + 1) * nq + j], ids[(i + 1) * nq + j + 1], ids[i * nq + j + 1]);
                for t in [[a, b, c], [a, c, d]] {
                    tris.push(if reverse { [t[0], t[2], t[1]] } else { t });
                }
            }
        }
    }
    let pts = &weld.points;
    let area =
        |t: &[u32; 3]| (pts[t[1] as usize] - pts[t[0] as usize]).cross(pts[t[2] as usize] - pts[t[0] as usize]).norm();
    tris.retain(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2] && area(t) > 1e-14 * size * size);
    let mut count: HashMap<[u32; 3], usize> = HashMap::new();
    for t in &tris {
        let mut k = *t;
        k.sort_unstable();
        *count.entry(k).or_default() += 1;
    }
    tris.retain(|t| {
        let mut k = *t;
        k.sort_unstable();
        count[&k] == 1
    });
    let mut remap = vec![u32::MAX; pts.len()];
    let mut positions = Vec::new();
    for t in tris.iter_mut() {
        for i in t.iter_mut() {
            if remap[*i as usize] == u32::MAX {
                remap[*i as usize] = positions.len() as u32;
                positions.push(pts[*i as usize]);
            }
            *i = remap[*i as usize];
        }
    }
    // outward: a map with det J < 0 turns the parameter orientation inside out
    let signed: f64 = tris
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum();
    if signed < 0.0 {
        for t in tris.iter_mut() {
            t.swap(1, 2);
        }
    }
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for t in &tris {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            normals[i as usize] += n;
        }
    }
    let normals = normals.into_iter().map(|n| n.normalized().unwrap_or(Vec3::new(0.0, 0.0, 1.0))).collect();
    Mesh { positions, normals, triangles: tris, ..Default::default() }
}

/// The iso-parametric cross section `axis = value` (0: u, 1: v, 2: w) as a grid mesh of
/// `res × res` vertices with normals from the exact Jacobian.
pub fn cross_section(s: &SolidBlend, axis: usize, value: f64, res: usize) -> Mesh {
    let n = res.max(2);
    let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut positions = Vec::with_capacity(n * n);
    let mut normals = Vec::with_capacity(n * n);
    let mut uvs = Vec::with_capacity(n * n);
    for i in 0..n {
        for j in 0..n {
            let mut t = [0.0; 3];
            t[axis] = value;
            // stay inside the open cube where boundary derivatives may be singular
            t[p] = (i as f64 / (n - 1) as f64).clamp(1e-9, 1.0 - 1e-9);
            t[q] = (j as f64 / (n - 1) as f64).clamp(1e-9, 1.0 - 1e-9);
            positions.push(s.point(t[0], t[1], t[2]));
            let jac = s.jacobian(t[0], t[1], t[2]);
            normals.push(jac[p].cross(jac[q]).normalized().unwrap_or(Vec3::new(0.0, 0.0, 1.0)));
            uvs.push([i as f64 / (n - 1) as f64, j as f64 / (n - 1) as f64]);
        }
    }
    let mut quads = Vec::with_capacity((n - 1) * (n - 1));
    for i in 0..n - 1 {
        for j in 0..n - 1 {
            let a = (i * n + j) as u32;
            let b = ((i + 1) * n + j) as u32;
            quads.push([a, b, b + 1, a + 1]);
        }
    }
    Mesh { positions, normals, uvs, quads, grid: Some((n, n)), ..Default::default() }
}

#[cfg(test)]
mod tests {
    use super::super::blend::tests::{cubes, cylinders};
    use super::super::{SolidOperator, SolidOptions};
    use super::*;

    fn closed_and_oriented(m: &Mesh) -> Result<(), String> {
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a, b)).or_default() += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            if n != 1 || edges.get(&(b, a)) != Some(&1) {
                return Err(format!("edge ({a}, {b}) used {n} times, reverse {:?}", edges.get(&(b, a))));
            }
        }
        Ok(())
    }

    #[test]
    fn boundaries_are_closed_and_consistently_oriented() {
        let op = SolidOperator::new(1.0, 1.0, 1.0).unwrap();
        for f in [cubes(), cylinders()] {
            let s = SolidBlend::new(op, f, SolidOptions { terms: (4, 4, 4), ..Default::default() }).unwrap();
            let m = boundary_mesh(&s, (9, 17, 9));
            closed_and_oriented(&m).unwrap();
            // outward: the enclosed volume by the divergence theorem matches the quadrature
            let vol: f64 = m.enclosed_volume();
            let mp = s.mass_properties(12);
            assert!(vol > 0.0 && (vol - mp.volume).abs() < 0.05 * mp.volume, "{vol} vs {}", mp.volume);
        }
    }
}
