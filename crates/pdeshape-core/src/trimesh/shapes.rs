//! Meshes of known surfaces, for tests and benchmarks: an icosphere, a height field on a
//! grid, and holes cut into them.

use super::TriMesh;
use crate::Vec3;
use std::collections::HashMap;

/// The unit icosphere subdivided `level` times (vertices on the sphere, triangles
/// counter-clockwise seen from outside).
pub fn icosphere(level: usize) -> TriMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalized().unwrap())
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<(u32, u32), u32> = HashMap::new();
        let mut get = |a: u32, b: u32, pos: &mut Vec<Vec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push(((pos[a as usize] + pos[b as usize]) * 0.5).normalized().unwrap());
                pos.len() as u32 - 1
            })
        };
        let mut next = Vec::new();
        for &[a, b, c] in &tris {
            let (ab, bc, ca) = (get(a, b, &mut pos), get(b, c, &mut pos), get(c, a, &mut pos));
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        tris = next;
    }
    TriMesh { positions: pos, triangles: tris }
}

/// `m` without the triangles whose centroid lies within angle `theta` of direction `d`.
pub fn cut_cap(m: &TriMesh, d: Vec3, theta: f64) -> TriMesh {
    let keep: Vec<[u32; 3]> = m
        .triangles
        .iter()
        .filter(|t| {
            let c = t.iter().fold(Vec3::ZERO, |a, &i| a + m.positions[i as usize]) * (1.0 / 3.0);
            c.normalized().unwrap().dot(d) < theta.cos()
        })
        .copied()
        .collect();
    TriMesh { positions: m.positions.clone(), triangles: keep }
}

/// A triangulated grid `z = f(x, y)` on `[-1, 1]²` with the triangles whose centroid lies
/// within `r` of the origin removed.
pub fn height_grid(k: usize, r: f64, f: impl Fn(f64, f64) -> f64) -> TriMesh {
    let mut positions = Vec::new();
    for i in 0..=k {
        for j in 0..=k {
            let (x, y) = (-1.0 + 2.0 * j as f64 / k as f64, -1.0 + 2.0 * i as f64 / k as f64);
            positions.push(Vec3::new(x, y, f(x, y)));
        }
    }
    let id = |i: usize, j: usize| (i * (k + 1) + j) as u32;
    let mut triangles = Vec::new();
    for i in 0..k {
        for j in 0..k {
            for t in [[id(i, j), id(i, j + 1), id(i + 1, j + 1)], [id(i, j), id(i + 1, j + 1), id(i + 1, j)]] {
                let c = t.iter().fold(Vec3::ZERO, |a, &v| a + positions[v as usize]) * (1.0 / 3.0);
                if c.x * c.x + c.y * c.y >= r * r {
                    triangles.push(t);
                }
            }
        }
    }
    TriMesh { positions, triangles }
}

/// The torus `((R + r cos φ) cos θ, (R + r cos φ) sin θ, r sin φ)` on an `nu × nv` grid of
/// quads, each split along one diagonal (the first halves, then the second), outward-facing,
/// without the triangles whose
/// centroid lies within `cut` of `hole`.
pub fn torus(nu: usize, nv: usize, big: f64, small: f64, hole: Vec3, cut: f64) -> TriMesh {
    use std::f64::consts::TAU;
    let mut positions = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (th, ph) = (TAU * i as f64 / nu as f64, TAU * j as f64 / nv as f64);
            let rr = big + small * ph.cos();
            positions.push(Vec3::new(rr * th.cos(), rr * th.sin(), small * ph.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % nu) * nv + j % nv) as u32;
    let mut triangles = Vec::with_capacity(2 * nu * nv);
    for half in 0..2 {
        for i in 0..nu {
            for j in 0..nv {
                let (a, b, c, d) = (id(i, j), id(i, j + 1), id(i + 1, j), id(i + 1, j + 1));
                let t = if half == 0 { [a, c, d] } else { [a, d, b] };
                let centroid = t.iter().fold(Vec3::ZERO, |s, &v| s + positions[v as usize]) * (1.0 / 3.0);
                if (centroid - hole).norm() > cut {
                    triangles.push(t);
                }
            }
        }
    }
    TriMesh { positions, triangles }
}
