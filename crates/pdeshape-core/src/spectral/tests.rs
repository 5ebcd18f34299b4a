//! Exactness and accuracy of the spectral solver.

use super::*;
use crate::data::FnField;
use crate::jet::Jet;
use crate::jet::JetShape;
use crate::patch::check_conditions;
use proptest::prelude::*;

/// An exact solution of (∂u² + a²∂θ²)² X = 0 with three Fourier modes: every term is
/// (mode-n function of ker (D² − a²n²)²) × (cos or sin nθ).
fn exact(a: f64) -> impl Fn(&Jet, &Jet) -> [Jet; 3] + Clone + Send + Sync + 'static {
    move |u: &Jet, th: &Jet| {
        let one = Jet::constant(u.shape(), 1.0);
        let c2 = 2.0 * a;
        let c3 = 3.0 * a;
        // mode 0: cubic; mode 2: u e^{-2au} + 0.3 e^{2a(u-1)}; mode 3: (1 - u) e^{3a(u-1)}
        let m0 = one.add(&u.scale(0.5)).sub(&u.powi(3).scale(0.8));
        let m2 = u.mul(&u.scale(-c2).exp()).add(&u.add_scalar(-1.0).scale(c2).exp().scale(0.3));
        let m3 = one.sub(u).mul(&u.add_scalar(-1.0).scale(c3).exp());
        let x = m0.add(&m2.mul(&th.scale(2.0).cos()));
        let y = m3.mul(&th.scale(3.0).sin()).add(&m2.mul(&th.scale(2.0).sin()).scale(-0.5));
        let z = m0.scale(0.3).add(&m3.mul(&th.scale(3.0).cos()));
        [x, y, z]
    }
}

fn data_of(f: impl Fn(&Jet, &Jet) -> [Jet; 3] + Send + Sync + 'static, u0: f64, d: usize) -> FieldRef {
    Arc::new(FnField::new(1, move |p: &[Jet]| {
        // jet in (u, θ) with order d in u and the requested θ-order, evaluated at (u0, θ)
        let kth = p[0].shape().orders()[0];
        let s = JetShape::new(&[d, kth]);
        let u = Jet::variable(s, 0, u0);
        let th = Jet::variable(s, 1, p[0].value());
        let full = f(&u, &th);
        let fact: f64 = (1..=d).map(|k| k as f64).product();
        let shape = p[0].shape();
        std::array::from_fn(|c| {
            let coeffs = shape.multi_indices().map(|[j, _, _]| full[c].coeff([d, j, 0]) * fact).collect();
            Jet::from_coeffs(shape, coeffs)
        })
    }))
}

/// The positions and slopes of [`exact`] at `u = 0` and `1`: the conditions of a
/// fourth-order patch that is [`exact`] itself.
fn end_conditions(a: f64) -> Vec<Condition> {
    [(0.0, 0), (0.0, 1), (1.0, 0), (1.0, 1)]
        .iter()
        .map(|&(u, d)| Condition { u, order: d, data: data_of(exact(a), u, d) })
        .collect()
}

#[test]
fn finite_fourier_data_reproduce_the_closed_form() {
    let a = 1.1;
    let f = exact(a);
    let conds = end_conditions(a);
    let p = SpectralPatch::new(&conds, VDomain::PERIODIC, SpectralOptions { a, modes: 4, omega: None }).unwrap();
    let mut worst: f64 = 0.0;
    for i in 0..=20 {
        for j in 0..30 {
            let (u, th) = (i as f64 / 20.0, j as f64 * 0.21);
            let s = JetShape::scalar();
            let want = f(&Jet::constant(s, u), &Jet::constant(s, th));
            let got = p.point(u, th);
            for c in 0..3 {
                worst = crate::num::max_nan(worst, (got[c] - want[c].value()).abs());
            }
        }
    }
    assert!(worst < 1e-12, "max deviation from the closed form {worst:e}");
    // the data have no modes above M: the tails vanish, R ≡ 0
    for t in p.tails(0.7, 1).iter().flatten() {
        assert!(t.norm() < 1e-13);
    }
}

#[test]
fn truncated_part_solves_the_pde_and_the_remainder_residual_shrinks_with_m() {
    // Smooth data with infinitely many modes (analytic, so the tails decay geometrically).
    let c0: FieldRef = Arc::new(FnField::new(1, |p: &[Jet]| {
        let v = &p[0];
        [v.cos().exp(), v.sin().mul(&v.cos().scale(0.5).exp()), v.scale(2.0).sin().scale(0.3)]
    }));
    let c1: FieldRef = Arc::new(FnField::new(1, |p: &[Jet]| {
        let v = &p[0];
        [
            v.cos().scale(0.5),
            v.sin().scale(0.5).add(&v.scale(2.0).cos().scale(0.1)),
            v.sin().exp().scale(0.2).add_scalar(1.5),
        ]
    }));
    let zero: FieldRef = Arc::new(crate::data::PointField { point: Vec3::new(0.0, 0.0, 1.0), arity: 1 });
    let conds = vec![
        Condition { u: 0.0, order: 0, data: c0 },
        Condition { u: 0.0, order: 1, data: zero.clone() },
        Condition { u: 1.0, order: 0, data: c1 },
        Condition { u: 1.0, order: 1, data: zero },
    ];
    let mut prev = f64::INFINITY;
    for m in [4usize, 8, 12, 16] {
        let p =
            SpectralPatch::new(&conds, VDomain::PERIODIC, SpectralOptions { a: 1.0, modes: m, omega: None }).unwrap();
        let mut rms_t = 0.0;
        let mut rms_w = 0.0;
        let mut cnt = 0.0;
        for i in 1..10 {
            for j in 0..24 {
                let r = p.residual(i as f64 / 10.0, j as f64 * PI / 12.0);
                rms_t += r.truncated.unwrap().powi(2);
                rms_w += r.whole.unwrap().powi(2);
                cnt += 1.0;
            }
        }
        let (rt, rw) = ((rms_t / cnt).sqrt(), (rms_w / cnt).sqrt());
        assert!(rt < 1e-9, "M = {m}: residual of the truncated part {rt:e}");
        // decreases until it reaches the round-off floor
        assert!(rw < prev || rw < 1e-10, "M = {m}: residual {rw:e} did not decrease from {prev:e}");
        prev = rw;
        let rep = check_conditions(&p, &conds, 0.0, 1000);
        assert!(rep.max_rel < 1e-12, "M = {m}: condition error {:e}", rep.max_rel);
    }
}

#[test]
fn clashing_conditions_are_rejected_by_name() {
    let g: FieldRef = Arc::new(crate::data::PointField { point: Vec3::ZERO, arity: 1 });
    let conds: Vec<Condition> =
        [0.0, 0.5, 0.5, 1.0].iter().map(|&u| Condition { u, order: 0, data: g.clone() }).collect();
    let e = SpectralPatch::new(&conds, VDomain::PERIODIC, SpectralOptions::default()).unwrap_err();
    assert!(e.to_string().contains("conditions 1 and 2 are identical"), "{e}");
}

/// Random data with many modes: a sum of shifted exponentials of trigonometric terms.
fn random_curve(seed: &[f64]) -> FieldRef {
    let s = seed.to_vec();
    Arc::new(FnField::new(1, move |p: &[Jet]| {
        let v = &p[0];
        std::array::from_fn(|c| {
            let a = s[c % s.len()];
            let b = s[(c + 1) % s.len()];
            v.scale(1.0 + c as f64).add_scalar(a).sin().scale(b).exp().add(&v.cos().scale(a))
        })
    }))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, .. ProptestConfig::default() })]
    /// Random orders, random Hermite/interior condition mixes, random data: every
    /// condition holds to 1e-10 (relative) at 1000 v samples.
    #[test]
    fn every_condition_holds_for_random_problems(
        n in 2usize..=10,
        split in 0.0f64..1.0,
        frac_interior in 0.0f64..1.0,
        seeds in proptest::collection::vec(-1.0f64..1.0, 40),
        a in 0.5f64..2.0,
        m in 3usize..10,
    ) {
        let extra = 2 * n - 2;
        let interior = ((extra as f64) * frac_interior).round() as usize;
        let ders = extra - interior;
        let p0 = ((ders as f64) * split).round() as usize;
        let p1 = ders - p0;
        let mut specs = vec![(0.0, 0), (1.0, 0)];
        specs.extend((1..=p0).map(|d| (0.0, d)));
        specs.extend((1..=p1).map(|d| (1.0, d)));
        specs.extend((0..interior).map(|k| ((k as f64 + 0.5 + 0.3 * seeds[k]) / (interior as f64 + 0.5), 0)));
        let conds: Vec<Condition> = specs
            .iter()
            .enumerate()
            .map(|(i, &(u, d))| Condition { u, order: d, data: random_curve(&seeds[i..i + 3]) })
            .collect();
        let p = SpectralPatch::new(&conds, VDomain::PERIODIC, SpectralOptions { a, modes: m, omega: None }).unwrap();
        let rep = check_conditions(&p, &conds, 0.0, 1000);
        prop_assert!(rep.max_rel <= 1e-10, "N = {n}, conditions {specs:?}: error {:e}", rep.max_rel);
    }
}

#[test]
fn open_patches_use_the_even_extension() {
    let g0: FieldRef =
        Arc::new(FnField::new(1, |p: &[Jet]| [p[0].clone(), p[0].sin(), Jet::constant(p[0].shape(), 0.0)]));
    let g1: FieldRef =
        Arc::new(FnField::new(1, |p: &[Jet]| [p[0].clone(), p[0].scale(2.0).cos(), Jet::constant(p[0].shape(), 1.0)]));
    let conds = vec![Condition { u: 0.0, order: 0, data: g0 }, Condition { u: 1.0, order: 0, data: g1 }];
    let dom = VDomain::open(-1.0, 2.0);
    let p = SpectralPatch::new(&conds, dom, SpectralOptions { a: 1.0, modes: 5, omega: None }).unwrap();
    let rep = check_conditions(&p, &conds, 0.0, 1000);
    assert!(rep.max_rel < 1e-12, "{:e}", rep.max_rel);
    // The even extension: the data are mirrored about both ends of [−1, 2] before the
    // Fourier analysis; the conditions and their v-derivatives hold at the very ends, and
    // the patch is finite on a grid that includes them.
    for v in [-1.0, 2.0] {
        for (c, u) in [(&conds[0], 0.0), (&conds[1], 1.0)] {
            let d = p.derivatives(u, v, 0, 1);
            let g = c.data.eval(&[v, 0.0]);
            let gv = crate::data::curve_derivative(c.data.as_ref(), v, 0.0, 1);
            assert!((d[0] - g).norm() < 1e-12, "u = {u}, v = {v}: off the data by {:e}", (d[0] - g).norm());
            assert!((d[1] - gv).norm() < 1e-9, "u = {u}, v = {v}: X_v off g′ by {:e}", (d[1] - gv).norm());
        }
    }
    for i in 0..=20 {
        for j in 0..=30 {
            let (u, v) = (i as f64 / 20.0, dom.at(j as f64 / 30.0));
            assert!(p.point(u, v).is_finite(), "X({u}, {v})");
        }
    }
}

#[test]
fn grid_evaluation_matches_pointwise_derivatives() {
    let a = 0.9;
    let conds = end_conditions(a);
    for dom in [VDomain::PERIODIC, VDomain::open(0.5, 2.0)] {
        let p = SpectralPatch::new(&conds, dom, SpectralOptions { a, modes: 3, omega: None }).unwrap();
        let us = [0.0, 0.3, 0.77, 1.0];
        let vs = [dom.at(0.1), dom.at(0.45), dom.at(0.9)];
        let g = p.grid(&us, &vs);
        let g2 = p.grid2(&us, &vs);
        let values = p.grid_values(&us, &vs);
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                let d = p.derivatives(u, v, 1, 1);
                assert!((values[i * vs.len() + j] - d[0]).norm() < 1e-12, "({u}, {v}) value");
                let want = [d[0], d[2], d[1], d[3]];
                for k in 0..4 {
                    assert!((g[i * vs.len() + j][k] - want[k]).norm() < 1e-12, "({u}, {v}) entry {k}");
                }
                let d = p.derivatives(u, v, 2, 2);
                let want = [d[0], d[3], d[1], d[6], d[4], d[2]];
                for k in 0..6 {
                    let scale = 1.0 + want[k].norm();
                    assert!((g2[i * vs.len() + j][k] - want[k]).norm() < 1e-12 * scale, "({u}, {v}) jet {k}");
                }
            }
        }
    }
}

/// The closed form of [`exact`] with its data written as expressions (numbers for the mode
/// functions' values and slopes at u = 0 and 1, times `cos nv`, `sin nv`): the data are
/// proved finite Fourier series (degree 3 ≤ M = 4), so the tails are taken as exactly zero
/// and the data are not evaluated; the patch still meets the closed form, and equals the
/// same data given as opaque fields (whose tails are summed) to round-off.
#[test]
fn data_proved_finite_series_have_no_remainder() {
    use crate::data::ExprField;
    let a = 1.1f64;
    let m = |u: f64| {
        let (e2, e2p, e3) = ((-2.0 * a * u).exp(), (2.0 * a * (u - 1.0)).exp(), (3.0 * a * (u - 1.0)).exp());
        let m0 = [1.0 + 0.5 * u - 0.8 * u.powi(3), 0.5 - 2.4 * u * u];
        let m2 = [u * e2 + 0.3 * e2p, e2 - 2.0 * a * u * e2 + 0.6 * a * e2p];
        let m3 = [(1.0 - u) * e3, -e3 + 3.0 * a * (1.0 - u) * e3];
        (m0, m2, m3)
    };
    let expr_data = |u: f64, d: usize| -> FieldRef {
        let (m0, m2, m3) = m(u);
        let x = format!("{:?} + {:?}*cos(2*v)", m0[d], m2[d]);
        let y = format!("{:?}*sin(3*v) - 0.5*{:?}*sin(2*v)", m3[d], m2[d]);
        let z = format!("0.3*{:?} + {:?}*cos(3*v)", m0[d], m3[d]);
        Arc::new(ExprField::parse([&x, &y, &z], &["v", "t"], &|_| None).unwrap())
    };
    let ends = [(0.0, 0), (0.0, 1), (1.0, 0), (1.0, 1)];
    let opts = SpectralOptions { a, modes: 4, omega: None };
    let conds: Vec<Condition> = ends.iter().map(|&(u, d)| Condition { u, order: d, data: expr_data(u, d) }).collect();
    let p = SpectralPatch::new(&conds, VDomain::PERIODIC, opts).unwrap();
    assert!(p.exact_series);
    assert!(p.tails(0.7, 2).is_empty(), "no tails to sum");
    let opaque: Vec<Condition> =
        ends.iter().map(|&(u, d)| Condition { u, order: d, data: data_of(exact(a), u, d) }).collect();
    let q = SpectralPatch::new(&opaque, VDomain::PERIODIC, opts).unwrap();
    assert!(!q.exact_series);
    let f = exact(a);
    let (mut worst, mut apart): (f64, f64) = (0.0, 0.0);
    for i in 0..=20 {
        for j in 0..30 {
            let (u, th) = (i as f64 / 20.0, j as f64 * 0.21);
            let s = JetShape::scalar();
            let want = f(&Jet::constant(s, u), &Jet::constant(s, th));
            let got = p.derivatives(u, th, 1, 1);
            for c in 0..3 {
                worst = crate::num::max_nan(worst, (got[0][c] - want[c].value()).abs());
            }
            let other = q.derivatives(u, th, 1, 1);
            for (x, y) in got.iter().zip(&other) {
                apart = crate::num::max_nan(apart, (*x - *y).norm());
            }
        }
    }
    // as the closed-form test above (values ≤ 2: 1e-12 leaves room for the solve's
    // conditioning), and the two data forms a few ulps apart in values and derivatives ≤ 10
    assert!(worst < 1e-12, "max deviation from the closed form {worst:e}");
    assert!(apart < 1e-13, "expression and opaque data differ by {apart:e}");

    // not proved: an open patch (even extension), degree above M, data in t, not a series
    let with = |x: &str| -> Vec<Condition> {
        ends.iter()
            .map(|&(u, d)| {
                let data: FieldRef = Arc::new(ExprField::parse([x, "sin(v)", "1"], &["v", "t"], &|_| None).unwrap());
                Condition { u, order: d, data }
            })
            .collect()
    };
    for (x, domain) in [
        ("cos(v)", VDomain::open(0.0, 2.0)),
        ("cos(5*v)", VDomain::PERIODIC),
        ("t*cos(v)", VDomain::PERIODIC),
        ("exp(sin(v))", VDomain::PERIODIC),
    ] {
        let r = SpectralPatch::new(&with(x), domain, opts).unwrap();
        assert!(!r.exact_series, "{x}");
    }
    assert!(SpectralPatch::new(&with("cos(4*v)"), VDomain::PERIODIC, opts).unwrap().exact_series);

    // proved data beside opaque ones: the proved data's tails are zero and not evaluated,
    // the others' summed, and the patch equals the all-opaque one to round-off
    let mixed: Vec<Condition> = ends
        .iter()
        .map(|&(u, d)| Condition { u, order: d, data: if d == 0 { expr_data(u, d) } else { data_of(exact(a), u, d) } })
        .collect();
    let r = SpectralPatch::new(&mixed, VDomain::PERIODIC, opts).unwrap();
    assert!(!r.exact_series);
    assert_eq!(r.exact, [true, false, true, false]);
    let mut apart: f64 = 0.0;
    for j in 0..30 {
        let th = j as f64 * 0.21;
        let tails = r.tails(th, 2);
        assert!(tails[0].iter().chain(&tails[2]).all(|t| *t == Vec3::ZERO), "θ = {th}");
        for i in 0..=20 {
            let u = i as f64 / 20.0;
            for (x, y) in r.derivatives(u, th, 1, 1).iter().zip(&q.derivatives(u, th, 1, 1)) {
                apart = crate::num::max_nan(apart, (*x - *y).norm());
            }
        }
    }
    // as above: a few ulps of values and derivatives ≤ 10
    assert!(apart < 1e-13, "mixed and opaque data differ by {apart:e}");

    // the data are of degree ≤ 3 < M = 4: mode 4 and the remainder are zero and not solved;
    // every way of evaluating (rows, grids of second derivatives, batches, the residual)
    // equals the opaque data's, which solve and sum them
    let rep = p.report();
    assert_eq!((rep.kept, rep.methods), (3, (4, 0)));
    assert_eq!(rep.mode_paths[4..], [NO_DATA, NO_DATA]);
    assert_eq!(rep.mode_residuals[4..], [0.0, 0.0]);
    assert_eq!((p.cards.len(), p.rem.is_none()), (4, true));
    let qr = q.report();
    assert_eq!((qr.kept, q.cards.len(), q.rem.is_some()), (4, 5, true));
    assert_eq!(p.remainder(0.3, 1.7), Vec3::ZERO);
    assert_eq!(p.residual(0.3, 1.7).remainder, Some(0.0));
    let us: Vec<f64> = (0..=12).map(|i| i as f64 / 12.0).collect();
    let vs: Vec<f64> = (0..17).map(|j| j as f64 * 0.37).collect();
    let uv: Vec<[f64; 2]> = us.iter().flat_map(|&u| vs.iter().map(move |&v| [u, v])).collect();
    let mut worst: f64 = 0.0;
    for other in [&q, &r] {
        for (x, y) in p.grid2(&us, &vs).iter().zip(other.grid2(&us, &vs)) {
            for (x, y) in x.iter().zip(y) {
                worst = crate::num::max_nan(worst, (*x - y).norm());
            }
        }
        let (mut fp, mut fq) = (vec![[Vec3::ZERO; 3]; uv.len()], vec![[Vec3::ZERO; 3]; uv.len()]);
        p.firsts_at(&uv, &mut fp);
        other.firsts_at(&uv, &mut fq);
        for (x, y) in fp.iter().flatten().zip(fq.iter().flatten()) {
            worst = crate::num::max_nan(worst, (*x - *y).norm());
        }
    }
    // second derivatives ≤ ~40 here: a few ulps of them
    assert!(worst < 1e-12, "grids and batches differ by {worst:e}");
}

/// A case the property test above found with a random seed: position and derivatives
/// 1–9 at `u = 0`, position and slope at `u = 1`, `a = 1.74`. The remainder's cardinal functions (`ω = 7`, solved in f64) summed `φ^{(9)}(0) C` with
/// `|φ^{(9)}| ≈ 4e7`: the ninth- and eighth-derivative conditions held to 3.3e-10 and
/// 1.1e-10 only. At a condition's own place and order the rows are now the cardinal
/// property's unit vectors.
#[test]
fn ninth_derivative_conditions_hold() {
    let mut seeds = vec![0.0; 40];
    seeds[5] = -0.4026662318415399;
    let mut specs = vec![(0.0, 0), (1.0, 0)];
    specs.extend((1..=9).map(|d| (0.0, d)));
    specs.push((1.0, 1));
    let conds: Vec<Condition> = specs
        .iter()
        .enumerate()
        .map(|(i, &(u, d))| Condition { u, order: d, data: random_curve(&seeds[i..i + 3]) })
        .collect();
    let opts = SpectralOptions { a: 1.7404181942342378, modes: 3, omega: None };
    let p = SpectralPatch::new(&conds, VDomain::PERIODIC, opts).expect("solves");
    let rep = check_conditions(&p, &conds, 0.0, 1000);
    // each condition is then its datum's Fourier sum and tail added back: a few ulps (0 seen)
    assert!(rep.max_rel <= 1e-14, "error {:e}", rep.max_rel);
}

/// The grid's products go through faer's GEMM, whose kernels on a CPU with AVX leave the
/// vector registers' upper lanes in use; the grid clears them on the thread that ran the
/// product. Left in use, every scalar instruction after it (the normals, the fold check,
/// the CAD fit on that worker) carries a false dependency on them: a 200 × 200 mesh's
/// normal pass ran 4× slower ([`crate::lanes`]).
#[test]
fn grid_products_leave_the_upper_lanes_clear() {
    let a = 0.9;
    let conds = end_conditions(a);
    let p = SpectralPatch::new(&conds, VDomain::PERIODIC, SpectralOptions { a, modes: 3, omega: None }).unwrap();
    let us: Vec<f64> = (0..60).map(|i| i as f64 / 59.0).collect();
    let vs: Vec<f64> = (0..60).map(|j| VDomain::PERIODIC.at(j as f64 / 59.0)).collect();
    // one worker: the products and this check run on the same thread
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let (g, state) = pool.install(|| {
        let g = p.grid(&us, &vs);
        (g, crate::lanes::upper_in_use())
    });
    let d = p.derivatives(us[17], vs[40], 1, 1);
    assert!((g[17 * 60 + 40][0] - d[0]).norm() < 1e-12);
    assert_ne!(state, Some(true), "the upper lanes were left in use");
}
