use super::*;
use crate::data::ExprField;

/// Edges of the spherical N-gon hole in the unit sphere with vertices at polar angle θ:
/// great-circle arcs `S(s, w) = cos s (cos w A + sin w B) + sin s M` at `s = 0` from
/// `w = 0` (the vertex A) to `w = ∠(A, A′)`, `M = A × A′ / |·|`, `B = M × A`.
fn sphere_hole(n: usize, theta: f64) -> Vec<FillEdge> {
    let azimuths: Vec<f64> = (0..n).map(|i| TAU * i as f64 / n as f64).collect();
    sphere_loop(&azimuths, theta)
}

/// Great-circle arcs through the points at polar angle θ and the given azimuths, in order.
fn sphere_loop(azimuths: &[f64], theta: f64) -> Vec<FillEdge> {
    let n = azimuths.len();
    let vert = |i: usize| {
        let phi = azimuths[i % n];
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
            FillEdge {
                surface: Arc::new(f),
                s0: 0.0,
                w: (0.0, a.dot(a1).clamp(-1.0, 1.0).acos()),
                fullness: 1.0,
                side: None,
                smooth: false,
            }
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
        assert!(c.g1 <= 1e-13, "{n}-gon: G1 angle {}", c.g1);
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

/// Bad loops: too few edges, an open loop, a reversed edge, a loop crossing itself.
#[test]
fn bad_loops_are_named() {
    let e = sphere_hole(5, 0.7);
    let err = |edges: &[FillEdge]| Fill::new(edges, &FillOptions::default()).err().unwrap().to_string();
    assert!(err(&e[..2]).contains("at least 3 edges"), "{}", err(&e[..2]));
    let open: Vec<FillEdge> = e.iter().take(4).cloned().collect();
    assert!(err(&open).contains("edges 3 and 0 do not meet"), "{}", err(&open));
    let mut rev = e.clone();
    rev[2].w = (rev[2].w.1, rev[2].w.0);
    assert!(err(&rev).contains("edge 2 is reversed"), "{}", err(&rev));
    // the first edge reversed was "edges 0 and 1 do not meet"
    let mut rev0 = e.clone();
    rev0[0].w = (rev0[0].w.1, rev0[0].w.0);
    assert!(err(&rev0).contains("edge 0 is reversed"), "{}", err(&rev0));
    // a bow tie: the arcs 0 → π and π/2 → 3π/2 cross near the pole
    let pi = std::f64::consts::PI;
    let bow = sphere_loop(&[0.0, pi, 0.5 * pi, 1.5 * pi], 0.6);
    assert!(err(&bow).contains("the loop crosses itself: edge 0 comes within"), "{}", err(&bow));
    assert!(err(&bow).contains("of edge 2"), "{}", err(&bow));
}

/// Loops the self-crossing test refused although they are simple: 200 and 400 edges round
/// a circle (segments shorter than the test's distance; 150 passed), one edge of 1e-3 of
/// the loop, and a point-like edge, which is dropped and named in the report. The fills
/// are G1 to round-off as any other.
#[test]
fn long_loops_short_edges_and_point_edges_are_filled() {
    let theta = 0.7;
    for n in [200, 400] {
        let fill = Fill::new(&sphere_hole(n, theta), &FillOptions::default()).unwrap();
        let c = fill.edge_continuity(4 * n);
        assert_eq!(fill.report().corner_angles.len(), n);
        // G1 by construction; the same bound as the few-edge holes
        assert!(c.g1 <= 1e-13, "{n} edges: G1 {}", c.g1);
    }
    // a pentagon with one vertex split into two 1e-3 apart (an edge of 1e-3 of the radius)
    let pi2 = std::f64::consts::TAU;
    let az = [0.0, 1e-3, 0.2 * pi2, 0.4 * pi2, 0.6 * pi2, 0.8 * pi2];
    let fill = Fill::new(&sphere_loop(&az, theta), &FillOptions::default()).unwrap();
    let g1 = fill.edge_continuity(600).g1;
    // the short edge's tangent X_v is 1e-3 of the others', and the round-off of the normal
    // X_u × X_v grows by that ratio there (measured 4.5e-13)
    assert!(g1 <= 1e-11, "a 1e-3 edge: G1 {g1}");
    // an edge that is one point (w from 0 to 0) between edges 1 and 2 is dropped
    let mut e = sphere_hole(5, theta);
    let mut point = e[2].clone();
    point.w = (0.0, 0.0);
    e.insert(2, point);
    let fill = Fill::new(&e, &FillOptions::default()).unwrap();
    assert_eq!(fill.report().dropped_edges, vec![2]);
    assert_eq!(fill.report().corner_angles.len(), 5);
    let plain = Fill::new(&sphere_hole(5, theta), &FillOptions::default()).unwrap();
    // the same loop without it: the same fill, bit for bit
    assert_eq!(fill.patch().point(0.3, 1.0), plain.patch().point(0.3, 1.0));
    // a loop of point edges alone is named
    let points: Vec<FillEdge> = (0..3).map(|_| e[2].clone()).collect();
    let err = Fill::new(&points, &FillOptions::default()).err().unwrap().to_string();
    assert!(err.contains("no extent") || err.contains("no length"), "{err}");
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

/// Order 6 on the three sphere holes: G1 and G2 to round-off along every edge (the sphere
/// meets itself G2 at every corner, so no corner correction has a normal part), no fold.
/// The G1-only fill of the same hole misses the curvature, so the G2 measure can fail.
#[test]
fn sphere_holes_are_filled_with_exact_g2_at_order_6() {
    for (n, deg) in [(3, 50.0), (5, 40.0), (6, 60.0)] {
        let theta = f64::to_radians(deg);
        let o = FillOptions { order: 6, ..Default::default() };
        let fill = Fill::new(&sphere_hole(n, theta), &o).unwrap();
        assert_eq!(fill.patch().order(), 6);
        let c = fill.edge_continuity(400);
        // G1 and gap as at order 4; G2: second derivatives of data and patch carry
        // round-off ~1e-14 relative (the remainder's second-derivative cardinal function
        // and the data's jets), far below the 1e-8
        assert!(c.g1 <= 1e-13, "{n}-gon: G1 angle {}", c.g1);
        assert!(c.gap <= 1e-12, "{n}-gon: gap {}", c.gap);
        assert!(c.g2 <= 1e-8, "{n}-gon: G2 gap {}", c.g2);
        let r = fill.report();
        assert!(r.corner_curvature_gaps.iter().all(|g| *g < 1e-12), "{:?}", r.corner_curvature_gaps);
        // the least-bending cap bends like the sphere (−1 against the outward normal)
        let k = r.pole_curvature.unwrap();
        assert!(k < 0.0, "pole curvature {k}");
        assert_eq!(fill.folds(41, 200), 0, "{n}-gon folds");
        let dev = sphere_deviation(fill.patch());
        let g1_only = Fill::new(&sphere_hole(n, theta), &FillOptions::default()).unwrap().edge_continuity(100);
        eprintln!(
            "order 6, {n} sides, θ = {deg}°: G1 {:.1e} rad, gap {:.1e}, G2 {:.1e} (order 4: {:.1e}), max |r − 1| {dev:.2e}",
            c.g1, c.gap, c.g2, g1_only.g2
        );
        assert!(g1_only.g2 > 1e-3, "the order-4 fill matches the curvature: {}", g1_only.g2);
        assert!(dev < 0.2, "{n}-gon: the fill strays {dev} from the sphere");
    }
}

/// The second fundamental form in an orthonormal basis against a closed form: the unit
/// sphere `(cos v sin u, sin v sin u, cos u)` has `II = −I` against the outward normal in
/// every basis; a cylinder of radius 2 has `−1/2` around and 0 along its axis.
#[test]
fn second_form_of_sphere_and_cylinder() {
    let (u, v) = (0.7_f64, 1.9_f64);
    let (su, cu, sv, cv) = (u.sin(), u.cos(), v.sin(), v.cos());
    let x = Vec3::new(cv * su, sv * su, cu);
    let xu = Vec3::new(cv * cu, sv * cu, -su);
    let xv = Vec3::new(-sv * su, cv * su, 0.0);
    let xuu = x * -1.0;
    let xuv = Vec3::new(-sv * cu, cv * cu, 0.0);
    let xvv = Vec3::new(-cv * su, -sv * su, 0.0);
    let e1 = (xu * 0.6 + xv * 0.3).normalized().unwrap();
    let e2 = x.cross(e1);
    let b = second_form_in([xu, xv, xuu, xuv, xvv], x, e1, e2);
    for (got, want) in [(b[0][0], -1.0), (b[0][1], 0.0), (b[1][1], -1.0)] {
        assert!((got - want).abs() < 1e-14, "{b:?}");
    }
    // cylinder (2 cos v, 2 sin v, u): X_u = e_z, X_v = (−2 sin v, 2 cos v, 0)
    let n = Vec3::new(cv, sv, 0.0);
    let (xu, xv) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(-2.0 * sv, 2.0 * cv, 0.0));
    let xvv = Vec3::new(-2.0 * cv, -2.0 * sv, 0.0);
    let e1 = Vec3::new(-sv, cv, 0.0);
    let b = second_form_in([xu, xv, Vec3::ZERO, Vec3::ZERO, xvv], n, e1, n.cross(e1));
    for (got, want) in [(b[0][0], -0.5), (b[0][1], 0.0), (b[1][1], 0.0)] {
        assert!((got - want).abs() < 1e-15, "{b:?}");
    }
    assert_eq!(sym_norm([[-0.5, 0.0], [0.0, 0.0]]), 0.5);
    assert!(sym_norm([[f64::NAN, 0.0], [0.0, 0.0]]).is_nan());
}

/// Set pole data are met: `X(1, v) = P`, `X_u(1, v) = −ρ (cos v e₁ + sin v e₂)` (length ρ,
/// perpendicular to the loop normal) and, at order 6, `X_uu(1, v) = κ ρ² n̄`.
#[test]
fn set_pole_data_are_met() {
    let (p, rho, kappa) = (Vec3::new(0.01, -0.02, 1.05), 0.4, -1.3);
    let o = FillOptions { order: 6, pole: Some(p), ring: Some(rho), pole_curvature: Some(kappa), ..Default::default() };
    let fill = Fill::new(&sphere_hole(5, 0.7), &o).unwrap();
    let nbar = fill.report().normal;
    assert!((nbar.z - 1.0).abs() < 1e-12, "{nbar:?}");
    for v in [0.0, 0.9, 2.5, 4.4] {
        let d = fill.patch().derivatives(1.0, v, 2, 0);
        assert!((d[0] - p).norm() < 1e-13, "{:?}", d[0]);
        assert!((d[1].norm() - rho).abs() < 1e-13 && d[1].dot(nbar).abs() < 1e-13, "{:?}", d[1]);
        assert!((d[2] - nbar * (kappa * rho * rho)).norm() < 1e-12, "{:?}", d[2]);
    }
    assert!((fill.report().pole_curvature.unwrap() - kappa).abs() < 1e-14);
}

/// A ring turned inside out (negative length) turns the parametrisation over between the
/// loop and the pole: the fold count sees it, and so does the stricter turn-over count
/// (the normal reverses); the same fill with its ring the right way round has neither.
#[test]
fn an_inverted_ring_is_a_fold() {
    let o = FillOptions { pole: Some(Vec3::new(0.0, 0.0, 1.0)), ring: Some(-0.4), ..Default::default() };
    let fill = Fill::new(&sphere_hole(5, 0.7), &o).unwrap();
    assert!(fill.folds(41, 200) > 0);
    assert!(fill.turn_overs(41, 200) > 0);
    let o = FillOptions { ring: Some(0.4), ..o };
    let fill = Fill::new(&sphere_hole(5, 0.7), &o).unwrap();
    assert_eq!((fill.folds(41, 200), fill.turn_overs(41, 200)), (0, 0));
}

/// The ring's fast derivatives equal its jets: `ρ (e₁ cos(v + kπ/2) + e₂ sin(v + kπ/2))`.
#[test]
fn ring_fast_path_matches_its_jets() {
    let r =
        Ring { centre: Vec3::new(0.1, 0.2, 0.3), e1: Vec3::new(1.0, 0.0, 0.0), e2: Vec3::new(0.0, 0.6, 0.8), rho: 0.7 };
    for v in [0.0, 1.3, 5.0] {
        for slot in [0, 1] {
            let (mut fast, mut slow) = ([Vec3::ZERO; 4], [Vec3::ZERO; 4]);
            r.derivatives_in(&[v, 0.0], slot, &mut fast);
            crate::data::derivatives_by_jet(&r, &[v, 0.0], slot, &mut slow);
            for k in 0..4 {
                assert!((fast[k] - slow[k]).norm() < 1e-15, "{v} {slot} {k}: {} {}", fast[k], slow[k]);
            }
        }
    }
}

/// The square |x|, |y| ≤ 1 on the sheet z = ½|y − x/2|, which is only C0 along the line
/// y = x/2: edges 1 (x = 1) and 3 (x = −1) cross it at y = ±½, where the neighbour's cross
/// tangent and normal jump.
fn creased_square() -> Vec<FillEdge> {
    let edge = |e: [&str; 3]| {
        let f = ExprField::parse(e, &["s", "w", "t"], &|_| None).unwrap();
        FillEdge { surface: Arc::new(f), s0: 0.0, w: (-1.0, 1.0), fullness: 1.0, side: None, smooth: false }
    };
    vec![
        edge(["w", "-1 + s", "0.5*abs(-1 + s - 0.5*w)"]),
        edge(["1 - s", "w", "0.5*abs(w - 0.5*(1 - s))"]),
        edge(["-w", "1 - s", "0.5*abs(1 - s + 0.5*w)"]),
        edge(["-1 + s", "-w", "0.5*abs(-w + 0.5 - 0.5*s)"]),
    ]
}

/// Item 3 of the trust issue: data that jump inside an edge tore the fill, and nothing
/// measured it. The creases are found (to the last bit) and made corners; the fill is
/// continuous (tear ratio about 1), G1 to round-off along every edge outside the corner
/// blends, and at the two crease corners the neighbours' angle is reported. Filled across
/// the creases (`split_creases: false`), the same loop tears and the tear ratio shows it.
#[test]
fn creases_inside_edges_become_corners_and_the_tear_measure_sees_a_tear() {
    let fill = Fill::new(&creased_square(), &FillOptions::default()).unwrap();
    let r = fill.report();
    assert_eq!(r.split_edges.len(), 2, "{:?}", r.split_edges);
    for (&(k, w), want) in r.split_edges.iter().zip([(1, 0.5), (3, 0.5)]) {
        assert_eq!(k, want.0);
        assert!((w - want.1).abs() <= 2.0 * f64::EPSILON, "{w}");
    }
    assert_eq!(r.corner_angles.len(), 6);
    // the crease angle: the normals (−½·½, … ) of the two sides of z = ½|y − x/2|
    let crease = r.corner_angles.iter().copied().fold(0.0, crate::num::max_nan);
    assert!(crease > 0.5, "{:?}", r.corner_angles);
    let (tear, at) = fill.tear(41, 4000);
    // a smooth fill: 1 plus the spacing's term (see `Fill::tear`)
    assert!(tear <= 1.2, "tear {tear} at {at:?}");
    // G1 outside the corner blends (the middle half of each of the 6 edges): round-off
    let span = TAU / 6.0;
    for k in 0..6 {
        for i in 0..50 {
            let v = span * (k as f64 + 0.25 + 0.5 * i as f64 / 49.0);
            let g = fill.edge_gaps_at(v);
            assert!(g.g1 <= 1e-13 && g.gap <= 1e-14, "edge {k} at {v}: {g:?}");
        }
    }
    let torn = Fill::new(&creased_square(), &FillOptions { split_creases: false, ..Default::default() }).unwrap();
    assert!(torn.report().split_edges.is_empty());
    let (tear, at) = torn.tear(41, 4000);
    assert!(tear > 5.0, "the unsplit fill's tear ratio is only {tear} at {at:?}");
}

/// A fill's values-only grid (the fit's samples: the loop data's values through their
/// fast paths) against its full grid (the data with `v`-derivatives through jets), at
/// orders 4 and 6 on the sphere's pentagon hole: the same values to round-off.
#[test]
fn a_fills_value_grid_is_its_full_grids_first_entry() {
    for order in [4, 6] {
        let fill = Fill::new(&sphere_hole(5, 0.7), &FillOptions { order, ..Default::default() }).unwrap();
        let p = fill.patch();
        let us = [0.0, 0.2, 0.5, 0.93, 1.0];
        let vs: Vec<f64> = (0..23).map(|j| TAU * j as f64 / 23.0 + 0.01).collect();
        let (values, full) = (p.grid_values(&us, &vs), p.grid(&us, &vs));
        for (k, (a, b)) in values.iter().zip(&full).enumerate() {
            // points on the unit sphere's cap: a few roundings of the matrix products
            assert!((*a - b[0]).norm() < 1e-14, "order {order}, point {k}: {a} vs {}", b[0]);
        }
    }
}

/// A family member is the fill `Fill::new` builds with the same fullness and height: the
/// family's claim that the loop's cross data scale as `f` and `f²` and that least bending
/// is linear in them. Checked on an uneven spherical pentagon (G1 corners, tangential
/// corner corrections at order 6) and the creased square (split into six edges, corners
/// that are not G1, so the normal parts of the corner tangents enter), at both orders and
/// fullness scales and heights away from 1.
#[test]
fn a_family_member_is_the_fill_of_its_fullness_and_height() {
    let loops = [("pentagon", sphere_loop(&[0.0, 1.1, 2.0, 3.4, 4.9], 0.7)), ("creased square", creased_square())];
    let us: Vec<f64> = (0..9).map(|i| i as f64 / 8.0).collect();
    let vs: Vec<f64> = (0..24).map(|j| TAU * j as f64 / 24.0 + 0.1).collect();
    for (name, edges) in &loops {
        for order in [4, 6] {
            let o = FillOptions { order, ..FillOptions::default() };
            let family = FillFamily::new(edges, &o, &us, &vs).unwrap();
            for (f, h) in [(1.0, 1.0), (0.6, 2.5), (1.7, 0.3)] {
                let scaled: Vec<FillEdge> = edges.iter().map(|e| FillEdge { fullness: f, ..e.clone() }).collect();
                let direct = Fill::new(&scaled, &FillOptions { height: h, ..o.clone() }).unwrap();
                let want = direct.patch().grid2(&us, &vs);
                let member = family.fill(f, h).unwrap();
                let got = family.grid2(f, h);
                let again = member.patch().grid2(&us, &vs);
                // per derivative, against its largest size on the grid
                let mut worst = [0.0f64; 2];
                for d in 0..6 {
                    let scale = want.iter().map(|g| g[d].norm()).fold(0.0, crate::num::max_nan);
                    for ((w, g), a) in want.iter().zip(&got).zip(&again) {
                        worst[0] = crate::num::max_nan(worst[0], (g[d] - w[d]).norm() / scale);
                        worst[1] = crate::num::max_nan(worst[1], (a[d] - w[d]).norm() / scale);
                    }
                }
                eprintln!(
                    "{name}, order {order}, f {f}, h {h}: summed grid {:.1e}, member's fill {:.1e}",
                    worst[0], worst[1]
                );
                // sums of ~8 solved patches of size ~1 and a least-squares solve: 5e-15
                // seen, round-off of the solves and of the sum
                assert!(worst[0] < 5e-14 && worst[1] < 5e-14, "{name}, order {order}, ({f}, {h}): {worst:?}");
                let (a, b) = (member.report(), direct.report());
                assert!((a.pole - b.pole).norm() < 1e-12, "{name}: pole {} against {}", a.pole, b.pole);
                assert_eq!(a.split_edges, b.split_edges);
            }
        }
    }
}

/// `edge_continuity` reads the fill's side from one grid row, `edge_gaps_at` from the
/// pointwise derivatives: the same measures. Compared on the order-4 fill of an uneven
/// pentagon, whose curvature gap is of size 1 (order 4 does not match curvature).
#[test]
fn edge_continuity_on_a_grid_row_is_the_pointwise_measure() {
    let fill = Fill::new(&sphere_loop(&[0.0, 1.1, 2.0, 3.4, 4.9], 0.7), &FillOptions::default()).unwrap();
    let per = 40;
    let row = fill.edge_continuity(per);
    let mut g2 = 0.0;
    for k in 0..5 * per {
        g2 = crate::num::max_nan(g2, fill.edge_gaps_at(TAU * k as f64 / (5 * per) as f64).g2);
    }
    assert_eq!(row.samples, 5 * per);
    assert!(g2 > 0.1, "{g2}");
    // two exact evaluations of the same patch: round-off of ~1e-15 in second derivatives
    assert!((row.g2 - g2).abs() < 1e-12 * g2, "{} against {g2}", row.g2);
    assert!(row.g1 < 1e-13 && row.gap < 1e-13, "{row:?}");
}

/// The pole's ring is a trigonometric polynomial of degree 1 (0 without its circle) by
/// construction, so spectral patches skip its Fourier tails; a ring that is not finite is
/// not proved anything.
#[test]
fn the_pole_ring_is_a_trigonometric_polynomial() {
    let ring = |rho: f64, e1: Vec3| Ring { centre: Vec3::new(1.0, 2.0, 3.0), e1, e2: Vec3::new(0.0, 1.0, 0.0), rho };
    assert_eq!(ring(0.5, Vec3::new(1.0, 0.0, 0.0)).trig_degree(), Some(1));
    assert_eq!(ring(0.0, Vec3::new(1.0, 0.0, 0.0)).trig_degree(), Some(0));
    assert_eq!(zero_field().trig_degree(), Some(0));
    assert_eq!(ring(f64::NAN, Vec3::new(1.0, 0.0, 0.0)).trig_degree(), None);
    assert_eq!(ring(0.5, Vec3::new(f64::INFINITY, 0.0, 0.0)).trig_degree(), None);
}

/// The corner blends' ends reported by [`Fill::blend_joins`] are where the loop data stop
/// being smooth: at each, the cross derivatives' Taylor coefficients in `v` up to the third
/// agree from both sides (to the round-off of a step of 1e-9), and the fourth jumps
/// (sphere triangle, order 6: six joins). A sphere's latitude circle cut into three edges
/// (as a CAD model's single closed edge is), whose corners the two sides see alike,
/// reports none.
#[test]
fn blend_joins_are_where_the_fourth_derivative_jumps() {
    let o = FillOptions { order: 6, ..Default::default() };
    let fill = Fill::new(&sphere_hole(3, f64::to_radians(50.0)), &o).unwrap();
    let joins = fill.blend_joins();
    let span = TAU / 3.0;
    let h = o.corner_blend * span;
    let expected: Vec<f64> = (0..3).flat_map(|k| [k as f64 * span + h, (k + 1) as f64 * span - h]).collect();
    assert_eq!(joins.len(), 6, "{joins:?}");
    for ((v, k), e) in joins.iter().zip(&expected) {
        assert_eq!(*k, 3);
        assert!((v - e).abs() <= 1e-15 * TAU, "{v} against {e}");
    }
    // the loop's cross derivatives (not the pole's ring, at u = 1)
    for c in fill.conditions().iter().filter(|c| c.u == 0.0 && c.order >= 1) {
        for &(v, _) in &joins {
            let series = |v: f64| c.data.jet(&[v, 0.0], JetShape::new(&[4, 0]));
            let (left, right) = (series(v - 1e-9), series(v + 1e-9));
            let coeff = |j: &VecJet, i: usize, comp: usize| j.0[comp].coeff([i, 0, 0]);
            let jump = |i: usize| {
                (0..3).map(|comp| (coeff(&left, i, comp) - coeff(&right, i, comp)).abs()).fold(0.0, crate::num::max_nan)
            };
            // a C³ function moves its first four coefficients by O(1e-9 × its fourth)
            // across the step (measured ≤ 4e-7 against fourths of 1e1–1e2); the fourth
            // jumps by p⁗(1)/4! h⁻⁴ = 35/h⁴ times the blend's correction
            let top = jump(4);
            assert!(top > 1e-3, "order {}, v = {v}: the fourth coefficient does not jump ({top})", c.order);
            for i in 0..4 {
                assert!(jump(i) <= 1e-6 * top, "order {}, v = {v}: coefficient {i} jumps by {}", c.order, jump(i));
            }
        }
    }
    // a latitude circle: S(s, w) = (sin(θ+s) cos w, sin(θ+s) sin w, cos(θ+s)), three edges
    let f: FieldRef = Arc::new(
        ExprField::parse(["sin(0.8+s)*cos(w)", "sin(0.8+s)*sin(w)", "cos(0.8+s)"], &["s", "w", "t"], &|_| None)
            .unwrap(),
    );
    let edges: Vec<FillEdge> = (0..3)
        .map(|k| FillEdge {
            surface: f.clone(),
            s0: 0.0,
            w: (k as f64 * span, (k + 1) as f64 * span),
            fullness: 1.0,
            side: None,
            smooth: false,
        })
        .collect();
    let cap = Fill::new(&edges, &o).unwrap();
    assert_eq!(cap.blend_joins(), vec![], "a smooth closed loop");
}
