use super::*;
use crate::patch::test_shapes::{Paraboloid, Sphere};

/// A deterministic stream of points in `[0, 1) × [a, b)`.
fn points(n: usize, a: f64, b: f64) -> impl Iterator<Item = (f64, f64)> {
    let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
    (0..n).map(move |_| {
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        (next(), a + (b - a) * next())
    })
}

/// A polynomial patch of degree ≤ 3 in each parameter is reproduced by the first fit (the
/// interpolant of a cubic is itself), to round-off.
#[test]
fn a_paraboloid_is_reproduced_exactly() {
    let (b, r) = fit_surface(&Paraboloid, &FitOptions { tolerance: Some(1e-12), ..Default::default() }).unwrap();
    assert_eq!(r.rounds, 1);
    for (u, v) in points(500, -10.0, 10.0) {
        let d = (b.point(u, v) - Paraboloid.point(u, v)).norm();
        // values up to ~100 (v² on [−10, 10]): round-off ~1e-13
        assert!(d < 1e-12, "({u}, {v}): {d}");
    }
}

/// The unit sphere (poles at u = 0 and 1, periodic v): the measured maximum is within the
/// tolerance, and at 4000 random points — none of them a sample of the fit — the deviation
/// is at most the measured maximum. Corners and the seam are exact.
#[test]
fn the_sphere_is_fitted_within_the_tolerance() {
    let s = Sphere(1.0);
    for tol in [1e-4, 1e-6, 1e-8] {
        let (b, r) = fit_surface(&s, &FitOptions { tolerance: Some(tol), ..Default::default() }).unwrap();
        assert!(r.max_deviation <= tol, "{r:?}");
        let tau = std::f64::consts::TAU;
        let mut worst: f64 = 0.0;
        for (u, v) in points(4000, 0.0, tau) {
            worst = crate::num::max_nan(worst, (b.point(u, v) - s.point(u, v)).norm());
        }
        eprintln!(
            "sphere at {tol:e}: {:?} control points, measured {:.2e}, random {:.2e}, {} rounds",
            r.points, r.max_deviation, worst, r.rounds
        );
        assert!(worst <= tol, "random points: {worst} > {tol}");
        // a random point lies on some bump the measurement ascended to its top (to a step
        // of 1e-6 of the cell, so ~1e-12 relative in value)
        assert!(
            worst <= r.max_deviation * (1.0 + 1e-9),
            "random {worst} above the measured maximum {}",
            r.max_deviation
        );
        for (u, v) in [(0.0, 0.0), (1.0, 0.0), (0.0, tau), (1.0, tau), (0.5, 0.0)] {
            assert!((b.point(u, v) - s.point(u, v)).norm() < 1e-14, "({u}, {v})");
        }
        for u in [0.1, 0.37, 0.8] {
            assert!((b.point(u, 0.0) - b.point(u, tau)).norm() < 1e-14, "seam at u = {u}");
        }
    }
}

/// The cap is honoured: an impossible tolerance is an error naming the place.
#[test]
fn an_unreachable_tolerance_is_an_error() {
    let e = fit_surface(&Sphere(1.0), &FitOptions { tolerance: Some(1e-15), max_points: 20, ..Default::default() })
        .err()
        .unwrap();
    assert!(e.to_string().contains("was not reached with at most 20 control points"), "{e}");
}

/// A creased sheet `(u, v, (1 + u) |v − c| + u³)` on `v ∈ [0, 1]`: the crease `v = c`
/// (not a knot of any uniform net) is found by the kink search and gets a knot of full
/// multiplicity, after which the sheet (bilinear on each side, cubic in `u`) is reproduced
/// with a few spans: 1e-12 is reached; the deviation at random points stays
/// within the measured maximum.
#[test]
fn a_crease_is_found_and_followed() {
    struct Crease(f64);
    impl Surface for Crease {
        fn v_domain(&self) -> crate::patch::VDomain {
            crate::patch::VDomain::open(0.0, 1.0)
        }
        fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
            let sg = (v - self.0).signum();
            let mut out = Vec::new();
            for i in 0..=du {
                for j in 0..=dv {
                    let x = [u, 1.0][..].get(i).copied().filter(|_| j == 0).unwrap_or(0.0);
                    let y = [v, 1.0][..].get(j).copied().filter(|_| i == 0).unwrap_or(0.0);
                    // (1 + u)|v − c| + u³
                    let cubic = match (i, j) {
                        (0, 0) => u * u * u,
                        (1, 0) => 3.0 * u * u,
                        (2, 0) => 6.0 * u,
                        (3, 0) => 6.0,
                        _ => 0.0,
                    };
                    let abs = match (i, j) {
                        (0, 0) => (1.0 + u) * (v - self.0).abs(),
                        (1, 0) => (v - self.0).abs(),
                        (0, 1) => (1.0 + u) * sg,
                        (1, 1) => sg,
                        _ => 0.0,
                    };
                    out.push(Vec3::new(x, y, abs + cubic));
                }
            }
            out
        }
    }
    let c = 0.3718;
    let s = Crease(c);
    let (b, r) = fit_surface(&s, &FitOptions { tolerance: Some(1e-12), ..Default::default() }).unwrap();
    let (t, m) = b.v.multiplicities();
    let at = t.iter().position(|&x| (x - c).abs() < 1e-12).expect("a knot at the crease");
    assert_eq!(m[at], 3, "{t:?} {m:?}");
    // (the spans next to the crease are halved too before it is found: the interpolant
    // rings there; without the knot 1e-12 is out of reach of any net within the cap)
    assert!(r.points.0 <= 8 && r.points.1 <= 48, "{r:?}");
    let mut worst: f64 = 0.0;
    for (u, v) in points(4000, 0.0, 1.0) {
        worst = crate::num::max_nan(worst, (b.point(u, v) - s.point(u, v)).norm());
    }
    assert!(worst <= r.max_deviation * (1.0 + 1e-9) && r.max_deviation <= 1e-12, "{worst} {r:?}");
}

/// Degree 5: the measured maximum holds as for degree 3 (random points within the measured
/// maximum), the net is smaller at a tight tolerance, and the edges interpolate the
/// patch's position, first and second cross derivatives exactly at the Greville points of
/// `v` — the second derivative only in degree 5.
#[test]
fn quintic_faces_meet_the_tolerance_and_interpolate_the_second_cross_derivative() {
    let s = Sphere(1.0);
    let tau = std::f64::consts::TAU;
    let tol = 1e-8;
    let (b3, r3) = fit_surface(&s, &FitOptions { tolerance: Some(tol), ..Default::default() }).unwrap();
    let (b5, r5) =
        fit_surface(&s, &FitOptions { tolerance: Some(tol), degrees: (5, 5), ..Default::default() }).unwrap();
    assert_eq!((b5.u.degree, b5.v.degree), (5, 5));
    assert!(r5.max_deviation <= tol);
    let worst =
        points(4000, 0.0, tau).map(|(u, v)| (b5.point(u, v) - s.point(u, v)).norm()).fold(0.0, crate::num::max_nan);
    assert!(worst <= r5.max_deviation * (1.0 + 1e-9), "random {worst} above the measured maximum {}", r5.max_deviation);
    assert!(r5.points.0 * r5.points.1 < r3.points.0 * r3.points.1, "{:?} vs {:?}", r5.points, r3.points);
    for (b, second) in [(&b3, false), (&b5, true)] {
        for v in b.v.greville() {
            for u in [0.0, 1.0] {
                let (d, e) = (b.derivatives(u, v, 2, 0), s.derivatives(u, v, 2, 0));
                assert!((d[0] - e[0]).norm() < 1e-13 && (d[1] - e[1]).norm() < 1e-12, "({u}, {v})");
                // X_uu of the sphere is of size π²: round-off 1e-11
                let err = (d[2] - e[2]).norm();
                assert_eq!(err < 1e-11, second, "degree {}: X_uu at ({u}, {v}) off by {err}", b.u.degree);
            }
        }
    }
}

/// A wavy band `X = ((1 + u) cos v, (1 + u) sin v, 0.2 (1 + u) sin 5v + u² cos 3v)` (periodic
/// `v`; derivatives by hand: `∂ⱼ cos v = cos(v + jπ/2)`, `∂ⱼ sin 5v = 5ʲ sin(5v + jπ/2)`).
struct Band;

impl crate::patch::Surface for Band {
    fn v_domain(&self) -> crate::patch::VDomain {
        crate::patch::VDomain::PERIODIC
    }
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let h = std::f64::consts::FRAC_PI_2;
        let mut out = Vec::new();
        for i in 0..=du {
            for j in 0..=dv {
                let lin = [1.0 + u, 1.0, 0.0][i.min(2)];
                let sq = [u * u, 2.0 * u, 2.0, 0.0][i.min(3)];
                let jf = j as f64;
                let (c, s) = ((v + jf * h).cos(), (v + jf * h).sin());
                let z = 0.2 * lin * 5f64.powi(j as i32) * (5.0 * v + jf * h).sin()
                    + sq * 3f64.powi(j as i32) * (3.0 * v + jf * h).cos();
                out.push(Vec3::new(lin * c, lin * s, z));
            }
        }
        out
    }
}

/// The `u = 0` edge of a fit with [`EdgeTolerance`]: gap, normal angle and normal
/// curvature across the edge against the band's own, at 2000 points of the edge that are
/// not samples of the check, within the tolerances (the check samples 8 points a span; the
/// random points may land a little higher: 1.5×). The same fit without the edge tolerance
/// misses the angle by far (it only bounds positions), so the test can fail.
#[test]
fn the_edge_meets_its_own_gap_angle_and_curvature_tolerances() {
    let tol = EdgeTolerance { gap: 1e-12, angle: 1e-10, curvature: Some(1e-8), scale: 2.0 };
    let base = FitOptions { tolerance: Some(1e-6), degrees: (5, 5), ..Default::default() };
    let (plain, _) = fit_surface(&Band, &base).unwrap();
    let (tight, r) = fit_surface(&Band, &FitOptions { edge: Some(tol), max_points: 1000, ..base.clone() }).unwrap();
    assert!(r.max_deviation <= 1e-6, "{r:?}");
    let figures = |b: &BSplineSurface| {
        let (mut gap, mut angle, mut curv) = (0.0_f64, 0.0_f64, 0.0_f64);
        for (_, v) in points(2000, 0.0, std::f64::consts::TAU) {
            let d = b.derivatives(0.0, v, 2, 2); // index 3i + k: ∂uⁱ∂vᵏ
            let x = Band.derivatives(0.0, v, 2, 2);
            let along = x[1].normalized().unwrap();
            let across = x[3] - along * x[3].dot(along);
            let (ks, ns) = normal_curvature(d[3], d[1], d[6], d[4], d[2], across).unwrap();
            let (kx, nx) = normal_curvature(x[3], x[1], x[6], x[4], x[2], across).unwrap();
            gap = crate::num::max_nan(gap, (d[0] - x[0]).norm());
            angle = crate::num::max_nan(angle, ns.cross(nx).norm().atan2(ns.dot(nx)));
            curv = crate::num::max_nan(curv, (ks - kx).abs() / crate::num::max_nan(kx.abs(), 1.0 / tol.scale));
        }
        (gap, angle, curv)
    };
    let (gap, angle, curv) = figures(&tight);
    eprintln!("edge-fitted: {:?} points, gap {gap:.2e}, angle {angle:.2e}, curvature {curv:.2e}", r.points);
    assert!(gap <= 1.5 * tol.gap && angle <= 1.5 * tol.angle && curv <= 1.5 * 1e-8, "{gap} {angle} {curv}");
    let (pg, pa, pc) = figures(&plain);
    eprintln!("plain: gap {pg:.2e}, angle {pa:.2e}, curvature {pc:.2e}");
    assert!(pa > 100.0 * tol.angle && pc > 100.0 * 1e-8, "{pa} {pc}");
}

/// `(u, v, (1 + u) (v − c)₊⁴)` on `v ∈ [0, 1]`: C³ across `v = c`, its fourth `v`-derivative
/// jumps there (as an N-sided fill's cross derivatives do where its corner blends end).
struct Joined(f64);

impl crate::patch::Surface for Joined {
    fn v_domain(&self) -> crate::patch::VDomain {
        crate::patch::VDomain::open(0.0, 1.0)
    }
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let x = (v - self.0).max(0.0);
        // d^j/dv^j x⁴ = 4!/(4−j)! x^(4−j)
        let g =
            |j: usize| if j > 4 { 0.0 } else { (0..j).map(|i| (4 - i) as f64).product::<f64>() * x.powi(4 - j as i32) };
        let mut out = Vec::new();
        for i in 0..=du {
            for j in 0..=dv {
                let lin = [1.0 + u, 1.0, 0.0][i.min(2)];
                let x = [u, 1.0, 0.0][i.min(2)] * [1.0, 0.0][j.min(1)];
                let y = [v, 1.0, 0.0][j.min(2)] * [1.0, 0.0][i.min(1)];
                out.push(Vec3::new(x, y, lin * g(j)));
            }
        }
        out
    }
}

/// A `C³` line given as a join gets a knot of multiplicity `degree − 3`, and then the
/// spline space holds the patch, `(v − c)₊⁴` times a linear function of `u`: the first fit
/// reproduces it to round-off at degrees 5 and 7. Given no join, the fit needs more rounds
/// (a simple knot at `c`, or none, cannot follow the jump of the fourth derivative).
#[test]
fn a_c3_join_gets_its_knots_and_the_patch_is_reproduced() {
    let c = 0.37;
    for q in [5, 7] {
        // values up to ~0.4 (0.63⁴ × 2): round-off ~1e-16; the tolerance leaves 100×
        let base = FitOptions { tolerance: Some(1e-14), degrees: (3, q), max_points: 200, ..Default::default() };
        let joined = FitOptions { v_joins: vec![(c, 3)], ..base.clone() };
        let (b, r) = fit_surface(&Joined(c), &joined).unwrap();
        assert_eq!(r.rounds, 1, "degree {q}: {r:?}");
        assert_eq!(b.v.knots.iter().filter(|&&k| k == c).count(), q - 3, "degree {q}: {:?}", b.v.knots);
        for (u, v) in points(2000, 0.0, 1.0) {
            let d = (b.point(u, v) - Joined(c).point(u, v)).norm();
            assert!(d < 1e-14, "degree {q}, ({u}, {v}): {d}");
        }
        match fit_surface(&Joined(c), &base) {
            Ok((_, r)) => assert!(r.rounds > 1, "degree {q} without the join: {r:?}"),
            Err(e) => assert!(e.to_string().contains("was not reached"), "{e}"),
        }
    }
}

/// A bump `X = (0, 0, F(q))`, `q = a du² + c du dv + b dv²` (`du = u − u*`, `dv = v − v*`),
/// `F(q) = e^{−q}` (Gaussian, `ln F` quadratic) or `1 / (1 + q)` (not), with its derivatives by hand:
/// `X_z,u = F′ q_u`, `X_z,uu = F″ q_u² + 2a F′`, `X_z,uv = F″ q_u q_v + c F′`, `X_z,vv = F″ q_v² + 2b F′`.
/// Against the zero spline its deviation `|S − X| = F(q)` is largest, 1, at `(u*, v*)`.
struct Bump {
    centre: (f64, f64),
    abc: (f64, f64, f64),
    gaussian: bool,
}

impl Bump {
    /// `[F, F′, F″, q_u, q_v]` at `(u, v)`.
    fn parts(&self, u: f64, v: f64) -> [f64; 5] {
        let (a, b, c) = self.abc;
        let (du, dv) = (u - self.centre.0, v - self.centre.1);
        let q = a * du * du + c * du * dv + b * dv * dv;
        let (f, f1, f2) = if self.gaussian {
            ((-q).exp(), -(-q).exp(), (-q).exp())
        } else {
            let r = 1.0 / (1.0 + q);
            (r, -r * r, 2.0 * r * r * r)
        };
        [f, f1, f2, 2.0 * a * du + c * dv, c * du + 2.0 * b * dv]
    }

    /// The largest `F(q)` along `u = w` and where it is: at `dv = −c du / 2b`, where
    /// `q = (a − c²/4b) du²`.
    fn on_side(&self, w: f64) -> (f64, f64, f64) {
        let (a, b, c) = self.abc;
        let du = w - self.centre.0;
        let q = (a - c * c / (4.0 * b)) * du * du;
        (if self.gaussian { (-q).exp() } else { 1.0 / (1.0 + q) }, w, self.centre.1 - c * du / (2.0 * b))
    }
}

impl crate::patch::Surface for Bump {
    fn v_domain(&self) -> crate::patch::VDomain {
        crate::patch::VDomain::open(0.0, 1.0)
    }
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        assert!(du <= 1 && dv <= 1, "the test asks for seconds through jet2");
        let [f, f1, f2, qu, qv] = self.parts(u, v);
        let c = self.abc.2;
        let all = [f, f1 * qv, f1 * qu, f2 * qu * qv + c * f1]; // [X, X_v, X_u, X_uv] in z
        let idx: Vec<usize> = (0..=du).flat_map(|i| (0..=dv).map(move |j| 2 * i + j)).collect();
        idx.into_iter().map(|k| Vec3::new(0.0, 0.0, all[k])).collect()
    }
    fn jet2(&self, u: f64, v: f64) -> [Vec3; 6] {
        let [f, f1, f2, qu, qv] = self.parts(u, v);
        let (a, b, c) = self.abc;
        [f, f1 * qu, f1 * qv, f2 * qu * qu + 2.0 * a * f1, f2 * qu * qv + c * f1, f2 * qv * qv + 2.0 * b * f1]
            .map(|z| Vec3::new(0.0, 0.0, z))
    }
}

/// `local_max` finds a narrow, skewed bump's maximum (`a = 400`, `b = 4`, `c = 30`: level
/// lines 10 : 1), Gaussian and rational, from starts 0.03 and 0.1 off: inside the cell, on a
/// side of the cell where the bump's centre lies outside it, and from a start where
/// `ln|e|` is convex (gradient steps first). The value is within 1e-9 of the closed form:
/// the maximisation stops when `|e|` would grow by less than 5e-10 of itself. The bounds
/// on the evaluations are those measured plus one or two; the gradient ascent that
/// preceded the Newton steps stopped at 0.989 inside the Gaussian, after 54 evaluations.
#[test]
fn the_local_maximum_of_a_skewed_bump() {
    let zero = BSplineSurface {
        u: Knots::clamped(3, 0.0, 1.0, &[]),
        v: Knots::clamped(3, 0.0, 1.0, &[]),
        control: vec![Vec3::ZERO; 16],
        periodic_v: false,
    };
    for gaussian in [true, false] {
        let bump = Bump { centre: (0.43, 0.61), abc: (400.0, 4.0, 30.0), gaussian };
        let top = (1.0, 0.43, 0.61);
        // evaluations measured: Gaussian 2, 3, 2 (ψ quadratic: one Newton step, one more
        // to see it converged; on the side a gradient step first), rational 6, 4, 8
        let cases = [
            ("inside", (0.46, 0.51), (0.0, 1.0), top, if gaussian { 3 } else { 8 }),
            ("on a side", (0.37, 0.7), (0.0, 0.4), bump.on_side(0.4), if gaussian { 4 } else { 6 }),
            ("from the convex tail", (0.53, 0.81), (0.0, 1.0), top, if gaussian { 3 } else { 10 }),
        ];
        for (name, (u0, v0), ru, (m, um, vm), most) in cases {
            let (f, u, v, evals) = local_max(&bump, &zero, u0, v0, ru, (0.0, 1.0));
            assert!((f - m).abs() <= 1e-9, "{name}: {f} against {m}");
            // |e| is flat at its maximum: 5e-10 of it is a step of ~1e-5 along the bump
            assert!((u - um).abs() <= 1e-5 && (v - vm).abs() <= 1e-5, "{name}: ({u}, {v}) against ({um}, {vm})");
            assert!(evals <= most, "{name}: {evals} evaluations");
        }
    }
}
