use super::*;
use proptest::prelude::*;
use std::f64::consts::TAU;

const UNIT: Rect = Rect { min: [0.0, 0.0], max: [1.0, 1.0] };

fn region(curves: Vec<(&str, TrimCurve)>) -> TrimRegion {
    TrimRegion::new(UNIT, curves.into_iter().map(|(n, c)| (n.to_string(), c)).collect()).unwrap()
}

fn on_border(p: Uv) -> bool {
    p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0
}

/// Everything the trimmed grid promises: boundary rings on the loop (1e-10) and on the
/// border (exactly), no fold, no interior vertex in a hole (fine polygonisation).
fn assert_valid(r: &TrimRegion, g: &TrimGrid) {
    assert_eq!(g.report.folds_after, 0);
    assert_eq!(count_folds(&g.points, g.rings, g.columns), 0);
    for j in 0..g.columns {
        let p = g.points[j];
        assert!(r.loop_distance(p) < 1e-10, "ring 0, column {j}: {p:?} is {} off", r.loop_distance(p));
        assert!(on_border(g.points[(g.rings - 1) * g.columns + j]));
    }
    let fine: Vec<Vec<Uv>> =
        r.curves.iter().map(|(_, c)| c.polygonize(512).into_iter().map(|x| x.1).collect()).collect();
    for p in &g.points[g.columns..] {
        for poly in &fine {
            assert!(!inside_polygon(*p, poly) || distance_to_polygon(*p, poly) < 1e-9, "{p:?} is inside a trim");
        }
    }
}

fn opts(rings: usize, columns: usize) -> TrimOptions {
    TrimOptions { rings, columns, ..Default::default() }
}

#[test]
fn circle_boundary_is_exact_at_any_phi() {
    let r = region(vec![("c", TrimCurve::ellipse([0.45, 0.55], [0.2, 0.2]))]);
    let map = LaplaceMap::new(r, 12, None);
    let mut rng = 0x1234_5678_u64;
    for _ in 0..1000 {
        rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let phi = (rng >> 11) as f64 / (1u64 << 53) as f64 * TAU;
        let (a, b) = (map.eval(0.0, phi), map.inner(phi));
        assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13);
        assert!((((a[0] - 0.45).hypot(a[1] - 0.55)) - 0.2).abs() < 1e-13);
        let (a, b) = (map.eval(1.0, phi), map.outer(phi));
        assert!((a[0] - b[0]).abs() < 1e-13 && (a[1] - b[1]).abs() < 1e-13);
        assert!(on_border(b));
    }
}

#[test]
fn grid_matches_pointwise_evaluation() {
    let r = region(vec![("c", TrimCurve::ellipse([0.5, 0.5], [0.25, 0.15]))]);
    let map = LaplaceMap::new(r, 10, Some(24));
    let g = map.grid(7, 24);
    for i in 0..7 {
        for j in 0..24 {
            let m = map.eval(i as f64 / 6.0, TAU * j as f64 / 24.0);
            let q = g[i * 24 + j];
            assert!((m[0] - q[0]).abs() < 1e-13 && (m[1] - q[1]).abs() < 1e-13);
        }
    }
}

#[test]
fn circular_trim_meshes_without_folds_and_keeps_the_corners() {
    let r = region(vec![("c", TrimCurve::ellipse([0.5, 0.5], [0.2, 0.2]))]);
    let map = LaplaceMap::new(r.clone(), 12, Some(40));
    let g = trim_grid(&map, &opts(20, 40)).unwrap();
    assert_valid(&r, &g);
    assert_eq!(g.report.folds_before, 0);
    assert_eq!(g.report.sweeps, 0);
    let last = &g.points[19 * 40..];
    for c in UNIT.corners() {
        assert!(last.contains(&c), "corner {c:?} is not a mesh vertex");
    }
    assert!((g.report.area_ratio - 1.0).abs() < 0.01, "{:?}", g.report);
}

#[test]
fn polygon_vertices_are_mesh_vertices() {
    let v = [[0.3, 0.3], [0.7, 0.35], [0.6, 0.7], [0.35, 0.6]];
    let r = region(vec![("p", TrimCurve::polygon(&v).unwrap())]);
    let map = LaplaceMap::new(r.clone(), 12, Some(48));
    let g = trim_grid(&map, &opts(16, 48)).unwrap();
    assert_valid(&r, &g);
    for q in v {
        assert!(g.points[..48].iter().any(|p| (p[0] - q[0]).abs() < 1e-12 && (p[1] - q[1]).abs() < 1e-12), "{q:?}");
    }
}

/// The paper's Fig. 6: a non-convex spline.
fn nonconvex() -> TrimCurve {
    TrimCurve::bspline(&[
        [0.25, 0.25],
        [0.5, 0.2],
        [0.75, 0.25],
        [0.8, 0.5],
        [0.75, 0.75],
        [0.55, 0.7],
        [0.5, 0.45],
        [0.45, 0.7],
        [0.25, 0.75],
        [0.2, 0.5],
    ])
    .unwrap()
}

#[test]
fn nonconvex_trim_is_repaired() {
    let r = region(vec![("n", nonconvex())]);
    let map = LaplaceMap::new(r.clone(), 12, Some(64));
    let g = trim_grid(&map, &opts(20, 64)).unwrap();
    assert_valid(&r, &g);
}

#[test]
fn disjoint_trims_are_bridged_into_one_loop() {
    // three curves side by side, as in paper 003 Fig. 7
    let r = region(vec![
        ("a", TrimCurve::ellipse([0.2, 0.45], [0.1, 0.15])),
        ("b", TrimCurve::bspline(&[[0.4, 0.4], [0.6, 0.35], [0.6, 0.6], [0.5, 0.7], [0.4, 0.6]]).unwrap()),
        ("c", TrimCurve::ellipse([0.8, 0.55], [0.1, 0.12])),
    ]);
    assert_eq!(r.bridges.len(), 2);
    let segments = r.pieces.iter().filter(|p| matches!(p, Piece::Segment { .. })).count();
    assert_eq!(segments, 4, "each bridge is traversed both ways");
    let map = LaplaceMap::new(r.clone(), 16, Some(96));
    let g = trim_grid(&map, &opts(24, 96)).unwrap();
    assert_valid(&r, &g);
}

#[test]
fn invalid_trims_are_refused() {
    let make = |c: Vec<(&str, TrimCurve)>| {
        TrimRegion::new(UNIT, c.into_iter().map(|(n, c)| (n.to_string(), c)).collect()).unwrap_err()
    };
    let e = make(vec![("big", TrimCurve::ellipse([0.5, 0.5], [0.6, 0.2]))]);
    assert!(matches!(e, TrimError::LeavesDomain { .. }), "{e}");
    assert!(e.to_string().contains("`big` leaves the parameter domain"), "{e}");
    // a bow tie crosses itself
    let bow = TrimCurve::polygon(&[[0.2, 0.2], [0.8, 0.8], [0.8, 0.2], [0.2, 0.8]]).unwrap();
    assert!(matches!(make(vec![("bow", bow)]), TrimError::SelfIntersection { .. }));
    let e = make(vec![
        ("a", TrimCurve::ellipse([0.4, 0.5], [0.2, 0.2])),
        ("b", TrimCurve::ellipse([0.6, 0.5], [0.2, 0.2])),
    ]);
    assert!(matches!(e, TrimError::CurvesIntersect { .. }), "{e}");
    let e = make(vec![
        ("out", TrimCurve::ellipse([0.5, 0.5], [0.3, 0.3])),
        ("in", TrimCurve::ellipse([0.5, 0.5], [0.1, 0.1])),
    ]);
    assert!(matches!(e, TrimError::Nested { .. }), "{e}");
    let flat = TrimCurve::polygon(&[[0.2, 0.5], [0.5, 0.5], [0.8, 0.5]]).unwrap();
    let e = make(vec![("flat", flat)]);
    assert!(matches!(e, TrimError::Degenerate { .. } | TrimError::Cusp { .. }), "{e}");
}

#[test]
fn curve_on_surface_has_exact_derivatives() {
    use crate::Vec3;
    use crate::data::Field;
    use crate::jet::JetShape;
    use crate::patch::{Surface, VDomain};
    // X(u, v) = (u, v, u² v), C(t) = (0.5 + 0.2 cos t, 0.4 + 0.1 sin t)
    struct Paraboloid;
    impl Surface for Paraboloid {
        fn v_domain(&self) -> VDomain {
            VDomain::open(0.0, 1.0)
        }
        fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
            let mut out = Vec::new();
            for i in 0..=du {
                for j in 0..=dv {
                    let x = match i {
                        0 => u,
                        1 => 1.0,
                        _ => 0.0,
                    };
                    let y = match j {
                        0 => v,
                        1 => 1.0,
                        _ => 0.0,
                    };
                    let a = match i {
                        0 => u * u,
                        1 => 2.0 * u,
                        2 => 2.0,
                        _ => 0.0,
                    };
                    let b = match j {
                        0 => v,
                        1 => 1.0,
                        _ => 0.0,
                    };
                    out.push(Vec3::new(if j == 0 { x } else { 0.0 }, if i == 0 { y } else { 0.0 }, a * b));
                }
            }
            out
        }
    }
    let g =
        CurveOnSurface { surface: std::sync::Arc::new(Paraboloid), curve: TrimCurve::ellipse([0.5, 0.4], [0.2, 0.1]) };
    let t: f64 = 0.7;
    let j = g.jet(&[t, 0.0], JetShape::new(&[2]));
    let (u, v) = (0.5 + 0.2 * t.cos(), 0.4 + 0.1 * t.sin());
    let (du, dv) = (-0.2 * t.sin(), 0.1 * t.cos());
    let (ddu, ddv) = (-0.2 * t.cos(), -0.1 * t.sin());
    // z = u² v: z' = 2u u' v + u² v', z'' = 2u'² v + 2u u'' v + 4u u' v' + u² v''
    let z1 = 2.0 * u * du * v + u * u * dv;
    let z2 = 2.0 * du * du * v + 2.0 * u * ddu * v + 4.0 * u * du * dv + u * u * ddv;
    assert!((j.value().z - u * u * v).abs() < 1e-15);
    assert!((j.derivative([1, 0, 0]).z - z1).abs() < 1e-14);
    assert!((j.derivative([2, 0, 0]).z - z2).abs() < 1e-13);
    assert!((j.derivative([2, 0, 0]).x - ddu).abs() < 1e-14);

    // in a batch (`derivatives_in_many`, the path of condition checks and grid columns):
    // values (k = 1) and values with g′ (k = 2), by hand at 97 t, and the other counts and
    // slots through the jets, bit for bit
    let ts: Vec<f64> = (0..97).map(|i| -3.0 + 0.0713 * i as f64).collect();
    let at: Vec<f64> = ts.iter().flat_map(|&t| [t, 0.25]).collect();
    for k in 1..=3 {
        let mut out = vec![Vec3::new(f64::NAN, 0.0, 0.0); ts.len() * k];
        g.derivatives_in_many(&at, 2, 0, k, &mut out);
        for (i, &t) in ts.iter().enumerate() {
            let (u, v) = (0.5 + 0.2 * t.cos(), 0.4 + 0.1 * t.sin());
            let (du, dv) = (-0.2 * t.sin(), 0.1 * t.cos());
            // position and g′ = (u′, v′, 2u u′ v + u² v′), rounding of a few products
            let want = [Vec3::new(u, v, u * u * v), Vec3::new(du, dv, 2.0 * u * du * v + u * u * dv)];
            for (d, w) in want.iter().enumerate().take(k.min(2)) {
                let e = (out[i * k + d] - *w).norm();
                assert!(e < 4e-16, "k = {k}, t = {t}, derivative {d}: {e:e}");
            }
            if k == 3 {
                let mut one = [Vec3::ZERO; 3];
                g.derivatives_in(&at[2 * i..2 * i + 2], 0, &mut one);
                assert_eq!(&out[3 * i..3 * i + 3], &one[..], "k = 3 is the pointwise path");
            }
        }
    }

    // no derivatives asked: nothing written, no panic (as every field's default)
    g.derivatives_in_many(&at, 2, 0, 0, &mut []);

    // the host normal is the paraboloid's, X_u × X_v = (−2uv, −u², 1), at C(t)
    let h = g.host_normal(&[t]).unwrap();
    assert!((h - Vec3::new(-2.0 * u * v, -u * u, 1.0)).norm() < 1e-15, "{h:?}");
    // a vertical wall W(s, τ) = g(τ) + s (0, 0, 1) attached along g: no position gap, and
    // the angle between its normal line (0, 0, 1) × g′ and the host's, by hand
    struct Wall(CurveOnSurface);
    impl Surface for Wall {
        fn v_domain(&self) -> VDomain {
            VDomain::PERIODIC
        }
        fn derivatives(&self, s: f64, tau: f64, du: usize, dv: usize) -> Vec<Vec3> {
            let j = self.0.jet(&[tau], JetShape::new(&[dv]));
            let mut out = Vec::new();
            for i in 0..=du {
                for k in 0..=dv {
                    let c = j.derivative([k, 0, 0]);
                    out.push(match (i, k) {
                        (0, _) => c + if k == 0 { Vec3::new(0.0, 0.0, s) } else { Vec3::ZERO },
                        (1, 0) => Vec3::new(0.0, 0.0, 1.0),
                        _ => Vec3::ZERO,
                    });
                }
            }
            out
        }
    }
    let field: crate::data::FieldRef = std::sync::Arc::new(g.clone());
    let wall = Wall(g);
    let gaps = crate::blend::attached_gaps_at(&wall, 0.0, t, &field);
    assert_eq!(gaps.c0, Some(0.0));
    let nw = Vec3::new(-(0.1 * t.cos()), -0.2 * t.sin(), 0.0); // (0,0,1) × (u′, v′, ·)
    let nh = Vec3::new(-2.0 * u * v, -u * u, 1.0);
    let want = (nw.dot(nh).abs() / (nw.norm() * nh.norm())).acos();
    let got = gaps.g1.unwrap();
    assert!((got - want).abs() < 1e-14 && want > 0.5, "{got} vs {want}");
    assert!(gaps.c1.is_none() && gaps.c2.is_none() && gaps.g2.is_none());
}

/// Points at radius `r(θ_k)`, `θ_k = 2πk/n`, about `c`.
fn star_points(c: Uv, radii: &[f64]) -> Vec<Uv> {
    let n = radii.len();
    radii
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let th = TAU * k as f64 / n as f64;
            [c[0] + r * th.cos(), c[1] + r * th.sin()]
        })
        .collect()
}

/// A closed B-spline whose control points lie at radius `r(θ)` about `c`.
fn star(c: Uv, radii: &[f64]) -> TrimCurve {
    TrimCurve::bspline(&star_points(c, radii)).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random star-shaped spline trims: valid grids, usually without any repair.
    #[test]
    fn random_star_shaped_trims(
        cx in 0.35..0.65f64, cy in 0.35..0.65f64,
        radii in proptest::collection::vec(0.08..0.25f64, 5..12),
        rings in 6usize..24, columns in 16usize..96,
    ) {
        let r = region(vec![("s", star([cx, cy], &radii))]);
        let map = LaplaceMap::new(r.clone(), 12, Some(columns));
        let g = trim_grid(&map, &opts(rings, columns)).unwrap();
        assert_valid(&r, &g);
    }

    /// Random non-convex trims: alternating dents (inner/outer radius 0.4 … 0.7) as
    /// splines and as polygons, around a random centre.
    #[test]
    fn random_nonconvex_trims(
        cx in 0.4..0.6f64, cy in 0.4..0.6f64,
        outer in 0.2..0.3f64, ratio in 0.4..0.7f64, lobes in 3usize..6,
        jitter in proptest::collection::vec(0.85..1.0f64, 12),
        polygon in any::<bool>(),
    ) {
        let r = region(vec![("n", dented([cx, cy], outer, ratio, lobes, &jitter, polygon))]);
        let map = LaplaceMap::new(r.clone(), 16, Some(96));
        let g = trim_grid(&map, &opts(24, 96)).unwrap();
        assert_valid(&r, &g);
    }

    /// Deep spikes (ratio 0.15 … 0.4) can defeat the repair of a structured grid (a spike
    /// tip needs more than one grid line): then the result is an error, never a folded mesh.
    #[test]
    fn deep_spikes_give_a_valid_mesh_or_an_error(
        outer in 0.2..0.3f64, ratio in 0.15..0.4f64, lobes in 3usize..7,
        jitter in proptest::collection::vec(0.85..1.0f64, 12),
        polygon in any::<bool>(),
    ) {
        let r = region(vec![("n", dented([0.5, 0.5], outer, ratio, lobes, &jitter, polygon))]);
        let map = LaplaceMap::new(r.clone(), 16, Some(96));
        match trim_grid(&map, &TrimOptions { max_sweeps: 400, ..opts(24, 96) }) {
            Ok(g) => assert_valid(&r, &g),
            Err(e) => prop_assert!(matches!(e, TrimError::CannotRepair { .. }), "{}", e),
        }
    }
}

/// A star with `lobes` outer points at radius `outer` and dents at `outer·ratio`.
fn dented(c: Uv, outer: f64, ratio: f64, lobes: usize, jitter: &[f64], polygon: bool) -> TrimCurve {
    let n = 2 * lobes;
    let radii: Vec<f64> = (0..n).map(|k| if k % 2 == 0 { outer } else { outer * ratio } * jitter[k % 12]).collect();
    if polygon { TrimCurve::polygon(&star_points(c, &radii)).unwrap() } else { star(c, &radii) }
}

/// Found by the trim fuzz target: control points that make the spline run down a line and
/// back up it (a cusp; `closest` could not find the loop there) are refused.
#[test]
fn a_spline_that_turns_back_is_refused() {
    let pts: Vec<Uv> = [[5.0, 100.0], [100.0, 170.0], [100.0, 170.0], [100.0, 160.0], [100.0, 170.0]]
        .iter()
        .map(|p| [p[0] / 255.0, p[1] / 102.0])
        .collect();
    let dom = Rect { min: [0.0, 0.0], max: [1.0, 2.5] };
    let err = TrimRegion::new(dom, vec![("c".into(), TrimCurve::bspline(&pts).unwrap())]).unwrap_err();
    assert!(matches!(err, TrimError::Cusp { .. }), "{err}");
    assert!(err.to_string().contains("turns back"), "{err}");
    // a polygon that doubles back along an edge too, but a sharp corner is fine
    let back = TrimCurve::polygon(&[[0.2, 0.2], [0.6, 0.2], [0.4, 0.2], [0.4, 0.6]]).unwrap();
    assert!(matches!(TrimRegion::new(dom, vec![("p".into(), back)]), Err(TrimError::Cusp { .. })));
    let sharp = TrimCurve::polygon(&[[0.2, 0.2], [0.8, 0.25], [0.2, 0.3]]).unwrap();
    assert!(TrimRegion::new(dom, vec![("p".into(), sharp)]).is_ok());
}

/// Found by the trim fuzz target: `closest` stepped across an acute polygon vertex and
/// reported points of ring 0 next to it as 2e-3 off the loop; polygons are measured edge by
/// edge now.
#[test]
fn ring_zero_is_on_an_acute_polygon_next_to_an_ellipse() {
    let dom = Rect { min: [0.0, 0.0], max: [1.0, 1.5625] };
    let e = TrimCurve::ellipse([0.14118, 0.39216], [0.023529, 0.10980]);
    let p = TrimCurve::polygon(&[[0.17647, 0.27574], [0.29412, 0.018382], [0.37255, 0.39216]]).unwrap();
    let r = TrimRegion::new(dom, vec![("e".into(), e), ("p".into(), p)]).unwrap();
    let map = LaplaceMap::new(r, 8, Some(55));
    let g = trim_grid(&map, &TrimOptions { rings: 6, columns: 55, modes: 8, max_sweeps: 200, verify: true }).unwrap();
    for j in 0..55 {
        let q = g.points[g.index(0, j)];
        assert!(map.region().loop_distance(q) < 1e-12, "column {j}: {q:?}");
    }
}

/// Found by the trim fuzz target: a spline with a triple control point has a corner where
/// its speed vanishes; Newton stalled there and `closest` reported ring 0 off the loop.
#[test]
fn closest_finds_a_corner_of_a_spline() {
    let pts =
        [[0.70588, 0.020098], [0.0078431, 0.020098], [0.0078431, 0.020098], [0.0078431, 0.020098], [0.0078431, 1.0049]];
    let c = TrimCurve::bspline(&pts).unwrap();
    for k in 0..2000 {
        let t = TAU * k as f64 / 2000.0 - 0.3;
        let (s, d) = c.closest(c.point(t));
        assert!(d < 1e-12, "t = {t}: closest ({s}, {d:e})");
        assert!((0.0..TAU).contains(&s));
    }
    assert_eq!(c.point(-0.1), c.point(TAU - 0.1), "closed curves wrap");
}

/// Found by a longer run of `deep_spikes_give_a_valid_mesh_or_an_error`: a ring-1 vertex
/// at a spike tip lay between the curve and a chord of its polygonisation, inside the hole
/// but outside the polygon, so the repair never saw it. Between a chord and its arc the
/// curve itself decides.
#[test]
fn points_between_a_chord_and_its_arc_are_judged_by_the_curve() {
    let (c, r) = ([0.5, 0.5], 0.2);
    let reg = region(vec![("c", TrimCurve::ellipse(c, [r, r]))]);
    let n = reg.polygons[0].len();
    let sag = r * (1.0 - (std::f64::consts::PI / n as f64).cos());
    assert!(reg.sagitta[0] >= sag);
    let at = |t: f64, rho: f64| [c[0] + rho * t.cos(), c[1] + rho * t.sin()];
    for k in [0, 7, n / 3] {
        let t = TAU * (k as f64 + 0.5) / n as f64;
        let inner = at(t, r - 0.5 * sag);
        assert!(!inside_polygon(inner, &reg.polygons[0]) && reg.in_hole(inner, 0.0), "{inner:?}");
        assert!(!reg.in_hole(at(t, r + 1e-12), 0.0) && reg.in_hole(at(t, r - 1e-12), 0.0));
        assert!(!reg.in_hole(at(t, r + 2.0 * sag), 0.0) && reg.in_hole(at(t, r - 2.0 * sag), 0.0));
    }
}

/// A failing case of `random_nonconvex_trims` (a 34° spike of the hole polygon): Winslow's
/// fixed point keeps one folded cell beside the spike, which the local untangling repairs.
#[test]
fn spike_beside_a_polygon_dent_is_untangled() {
    let jitter = [
        0.9854522988377276,
        0.9093107148629781,
        0.9960210252240491,
        0.9761704196621998,
        0.85,
        0.9517210606510179,
        0.85,
        0.907273284889868,
        0.9750502074969778,
        0.85,
        0.85,
        0.85,
    ];
    let c = [0.528823337768761, 0.43599714116460886];
    let r = region(vec![("n", dented(c, 0.2984255953552473, 0.4, 5, &jitter, true))]);
    let map = LaplaceMap::new(r.clone(), 16, Some(96));
    let g = trim_grid(&map, &opts(24, 96)).unwrap();
    assert_valid(&r, &g);
    assert!(g.report.untangle_moves > 0 && g.report.sweeps < 1000, "{:?}", g.report);
}
