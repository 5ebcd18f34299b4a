use super::*;
use crate::data::ExprField;

/// Edges of the spherical N-gon hole in the unit sphere with vertices at polar angle θ:
/// great-circle arcs `S(s, w) = cos s (cos w A + sin w B) + sin s M` at `s = 0` from
/// `w = 0` (the vertex A) to `w = ∠(A, A′)`, `M = A × A′ / |·|`, `B = M × A`.
fn sphere_hole(n: usize, theta: f64) -> Vec<FillEdge> {
    let vert = |i: usize| {
        let phi = TAU * i as f64 / n as f64;
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    };
    (0..n)
        .map(|i| {
            let (a, a1) = (vert(i), vert(i + 1));
            let m = a.cross(a1).normalized().unwrap();
            let b = m.cross(a);
            let c = |k: usize| {
                let (x, y, z) = ([a.x, a.y, a.z][k], [b.x, b.y, b.z][k], [m.x, m.y, m.z][k]);
                format!("cos(s)*(cos(w)*({x:?}) + sin(w)*({y:?})) + sin(s)*({z:?})")
            };
            let e = [c(0), c(1), c(2)];
            let f =
                ExprField::parse([e[0].as_str(), e[1].as_str(), e[2].as_str()], &["s", "w", "t"], &|_| None).unwrap();
            FillEdge { surface: Arc::new(f), s0: 0.0, w: (0.0, a.dot(a1).clamp(-1.0, 1.0).acos()), fullness: 1.0 }
        })
        .collect()
}

/// The largest |r − 1| of the fill on a 41 × 200 grid (NaN-propagating).
fn sphere_deviation(s: &SpectralPatch) -> f64 {
    let mut dev: f64 = 0.0;
    for i in 0..=40 {
        for j in 0..200 {
            let p = s.point(i as f64 / 40.0, TAU * j as f64 / 200.0);
            dev = crate::num::max_nan(dev, (p.norm() - 1.0).abs());
        }
    }
    dev
}

/// The three sphere holes: G1 to round-off along every edge (corners included),
/// no gap, no fold; the deviation from the sphere inside printed beside OCCT's figures.
#[test]
fn sphere_holes_are_filled_with_exact_g1() {
    for (n, deg) in [(3, 50.0), (5, 40.0), (6, 60.0)] {
        let theta = f64::to_radians(deg);
        let fill = Fill::new(&sphere_hole(n, theta), &FillOptions::default()).unwrap();
        let c = fill.edge_continuity(400);
        // G1: the normal is a cross product of exactly met conditions; round-off of the
        // data and the patch (~1e-15) over lengths ~ 1 gives angles of a few 1e-15
        assert!(c.g1 <= 1e-9, "{n}-gon: G1 angle {}", c.g1);
        assert!(c.gap <= 1e-12, "{n}-gon: gap {}", c.gap);
        assert!(fill.report().corner_angles.iter().all(|a| *a < 1e-12), "{:?}", fill.report().corner_angles);
        assert_eq!(fill.folds(41, 200), 0, "{n}-gon folds");
        let s = fill.patch();
        let dev = sphere_deviation(s);
        eprintln!(
            "{n} sides, θ = {deg}°: G1 {:.1e} rad, gap {:.1e}, max |r − 1| {dev:.2e}, pole {:?}",
            c.g1,
            c.gap,
            fill.report().pole
        );
        assert!(dev < 0.2, "{n}-gon: the fill strays {dev} from the sphere");
    }
}

/// Bad loops: too few edges, an open loop, a reversed edge.
#[test]
fn bad_loops_are_named() {
    let e = sphere_hole(5, 0.7);
    let err = |edges: &[FillEdge]| Fill::new(edges, &FillOptions::default()).err().unwrap().to_string();
    assert!(err(&e[..2]).contains("at least 3 edges"), "{}", err(&e[..2]));
    let open: Vec<FillEdge> = e.iter().take(4).cloned().collect();
    assert!(err(&open).contains("edges 3 and 0 do not meet"), "{}", err(&open));
    let mut rev = e.clone();
    rev[2].w = (rev[2].w.1, rev[2].w.0);
    assert!(err(&rev).contains("edge 2 runs the wrong way"), "{}", err(&rev));
}

/// A scan of fullness, ring length and shape parameter with the pole on the sphere, printing
/// the largest |r − 1| inside each hole (a figure for the issue, not a check; the defaults
/// do not yet choose these by least bending): `cargo test -p pdeshape-core --lib
/// sphere_fill_parameter_scan -- --ignored --nocapture`.
#[test]
#[ignore = "a parameter scan, printed"]
fn sphere_fill_parameter_scan() {
    for (n, deg) in [(3, 50.0), (5, 40.0), (6, 60.0)] {
        let theta = f64::to_radians(deg);
        for full in [0.8, 1.0, 1.2, 1.5] {
            for ring in [0.6, 1.0, 1.4] {
                for a in [0.5, 1.0, 2.0] {
                    let mut e = sphere_hole(n, theta);
                    for x in &mut e {
                        x.fullness = full;
                    }
                    let o = FillOptions {
                        pole: Some(Vec3::new(0.0, 0.0, 1.0)),
                        ring: Some(ring * theta.sin()),
                        spectral: SpectralOptions { a, modes: 12, omega: None },
                        ..Default::default()
                    };
                    let fill = Fill::new(&e, &o).unwrap();
                    let s = fill.patch();
                    let dev = sphere_deviation(s);
                    eprintln!("{n} {deg} full {full} ring {ring} a {a}: {dev:.2e} folds {}", fill.folds(21, 100));
                }
            }
        }
    }
}
