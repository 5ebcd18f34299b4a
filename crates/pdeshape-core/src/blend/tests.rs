use super::*;
use crate::Vec3;
use crate::data::{ExprField, FieldRef};
use crate::num::MaxNan;
use crate::patch::{Condition, Surface, VDomain, check_conditions};
use proptest::prelude::*;
use std::sync::Arc;

fn field(e: [&str; 3]) -> FieldRef {
    Arc::new(ExprField::parse(e, &["v", "t"], &|_| None).unwrap())
}

fn cond(u: f64, order: usize, e: [&str; 3]) -> Condition {
    Condition { u, order, data: field(e) }
}

/// Cone frustum to inclined elliptic cylinder (paper 001 eq. 13, orders 0-2 of the
/// trimline data with scale c = 1).
fn cone_cylinder() -> Vec<Condition> {
    vec![
        cond(0.0, 0, ["1.5*cos(v)", "1.0*sin(v)", "1.2"]),
        cond(0.0, 1, ["1.25*cos(v)", "0.833*sin(v)", "1.0"]),
        cond(0.0, 2, ["0", "0", "0"]),
        cond(
            1.0,
            0,
            ["0.3 + 0.8*cos(0.3)*cos(v) + 3*sin(0.3)", "0.6*sin(v)", "2.5 - 0.8*sin(0.3)*cos(v) + 3*cos(0.3)"],
        ),
        cond(1.0, 1, ["2*sin(0.3)", "0", "2*cos(0.3)"]),
        cond(1.0, 2, ["0", "0", "0"]),
    ]
}

fn ops(r: [usize; 3]) -> [Operator; 3] {
    r.map(Operator::laplacian_power)
}

fn max_residual(b: &StaticBlend) -> (f64, f64) {
    // |L X| against the size of its terms, at scattered points
    let mut worst: f64 = 0.0;
    let mut size: f64 = 0.0;
    for i in 0..40 {
        let (u, v) = ((i as f64 * 0.618).fract(), (i as f64 * 2.39).rem_euclid(std::f64::consts::TAU));
        let r = b.residual(u, v);
        worst = crate::num::max_nan(worst, r.norm());
        let d = b.derivatives(u, v, 6, 0);
        size = crate::num::max_nan(size, d.iter().map(|x| x.norm()).max_nan());
    }
    (worst, size)
}

fn condition_error(b: &StaticBlend, conds: &[Condition]) -> f64 {
    let mut worst: f64 = 0.0;
    for (t, op) in b.operators().iter().enumerate() {
        let used: Vec<Condition> = conds.iter().filter(|c| c.order < op.half_order()).cloned().collect();
        for c in &used {
            for i in 0..1000 {
                let v = std::f64::consts::TAU * (i as f64 + 0.3) / 1000.0;
                let x = b.u_derivative(c.u, v, c.order)[t];
                worst = crate::num::max_nan(worst, (x - c.data.eval(&[v, 0.0])[t]).abs());
            }
        }
    }
    worst
}

#[test]
fn laplace_blend_matches_its_closed_form() {
    // ∂u² + ∂v²: data cos v at u = 0 and 0 at u = 1 → X = sinh(1 − u)/sinh 1 · cos v.
    let conds = vec![cond(0.0, 0, ["cos(v)", "0", "1"]), cond(1.0, 0, ["0", "0", "1"])];
    let b = StaticBlend::new(ops([1, 1, 1]), &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
    assert_eq!(b.reports()[0].solver, "exact");
    for (u, v) in [(0.2f64, 0.3f64), (0.5, 2.0), (0.9, 5.0)] {
        let want = (1.0f64 - u).sinh() / 1.0f64.sinh() * v.cos();
        assert!((b.point(u, v).x - want).abs() < 1e-14);
        assert!((b.point(u, v).z - 1.0).abs() < 1e-14);
    }
    // complex roots: ∂u⁴ + ∂u²∂v² + ∂v⁴ on cos v gives s⁴ − s² + 1 = 0
    let op = Operator::new(vec![1.0, 1.0, 1.0]).unwrap();
    let conds = cone_cylinder();
    let b =
        StaticBlend::new([op.clone(), op.clone(), op], &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
    let (res, size) = max_residual(&b);
    assert!(res < 1e-12 * size, "residual {res} of {size}");
    assert!(condition_error(&b, &conds) < 1e-13);
}

#[test]
fn every_order_combination_meets_its_conditions_and_the_pde() {
    let conds = cone_cylinder();
    for r in [[1, 1, 1], [1, 1, 2], [1, 1, 3], [2, 2, 2], [2, 2, 3], [3, 3, 3]] {
        let b = StaticBlend::new(ops(r), &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
        assert!(b.reports().iter().all(|rep| rep.solver == "exact"));
        assert!(condition_error(&b, &conds) < 1e-12, "{r:?}");
        let (res, size) = max_residual(&b);
        assert!(res < 1e-11 * size, "{r:?}: residual {res} of {size}");
    }
}

#[test]
fn continuity_follows_the_order() {
    let conds = cone_cylinder();
    let data = |u: f64| -> [Option<FieldRef>; 3] {
        std::array::from_fn(|k| conds.iter().find(|c| c.u == u && c.order == k).map(|c| c.data.clone()))
    };
    let gaps = |r: [usize; 3]| {
        let b = StaticBlend::new(ops(r), &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
        let d = data(0.0);
        continuity(&b, 0.0, [d[0].as_ref(), d[1].as_ref(), d[2].as_ref()], 200)
    };
    let g2 = gaps([1, 1, 1]);
    assert!(g2.c0.unwrap() < 1e-13 && g2.c1.unwrap() > 1e-2 && g2.g1.unwrap() > 1e-3, "{g2:?}");
    let g4 = gaps([2, 2, 2]);
    assert!(g4.c1.unwrap() < 1e-12 && g4.g1.unwrap() < 1e-8 && g4.c2.unwrap() > 1e-2, "{g4:?}");
    let g6 = gaps([3, 3, 3]);
    assert!(g6.c2.unwrap() < 1e-11 && g6.g2.unwrap() < 1e-9, "{g6:?}");
    let mixed = gaps([1, 1, 3]);
    assert!(mixed.g1.unwrap() > 1e-3, "a 2+2+6 blend is no better than C0: {mixed:?}");
}

/// The grid paths (`grid`, `grid2`) give the pointwise derivatives bit for bit, for the
/// exact and the collocation solvers.
#[test]
fn grid_paths_equal_pointwise_derivatives() {
    let conds = cone_cylinder();
    let us = [0.0, 0.13, 0.5, 0.77, 1.0];
    let vs = [0.0, 0.4, 2.1, 3.3, 6.0];
    for solver in [Solver::Exact, Solver::Collocation] {
        let o = BlendOptions { solver, bubbles: 4, ..Default::default() };
        let b = StaticBlend::new(ops([2, 2, 3]), &conds, VDomain::PERIODIC, &o).unwrap();
        let (g1, g2) = (b.grid(&us, &vs), b.grid2(&us, &vs));
        for (k, (a1, a2)) in g1.iter().zip(&g2).enumerate() {
            let (u, v) = (us[k / vs.len()], vs[k % vs.len()]);
            assert_eq!(*a2, b.jet2(u, v), "{solver:?} grid2 at ({u}, {v})");
            let d = b.derivatives(u, v, 1, 1);
            assert_eq!(*a1, [d[0], d[2], d[1], d[3]], "{solver:?} grid at ({u}, {v})");
        }
    }
}

#[test]
fn collocation_converges_to_the_exact_solution() {
    let conds = cone_cylinder();
    let exact = StaticBlend::new(ops([2, 2, 2]), &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
    let mut last = f64::INFINITY;
    for nb in [2, 4, 8, 12] {
        let o = BlendOptions { solver: Solver::Collocation, bubbles: nb, ..Default::default() };
        let b = StaticBlend::new(ops([2, 2, 2]), &conds, VDomain::PERIODIC, &o).unwrap();
        assert_eq!(b.reports()[0].solver, "collocation");
        assert!(condition_error(&b, &conds) < 1e-12, "collocation meets its conditions exactly");
        let mut d: f64 = 0.0;
        for i in 0..=20 {
            for j in 0..20 {
                let (u, v) = (i as f64 / 20.0, j as f64 * 0.314);
                d = crate::num::max_nan(d, (b.point(u, v) - exact.point(u, v)).norm());
            }
        }
        assert!(d < last, "B = {nb}: distance {d} did not shrink from {last}");
        last = d;
    }
    assert!(last < 1e-8, "B = 12 distance {last}");
}

#[test]
fn non_eigenfunction_data_fall_back_to_collocation() {
    let conds =
        vec![cond(0.0, 0, ["cos(v)", "sin(v)", "1/(1.02 + cos(v))"]), cond(1.0, 0, ["2*cos(v)", "2*sin(v)", "1"])];
    let b = StaticBlend::new(ops([1, 1, 1]), &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
    // 1/(1.02 + cos v) is no trigonometric polynomial of ≤ 64 modes: kept whole,
    // collocation for z only
    assert_eq!(b.reports()[0].solver, "exact");
    assert_eq!(b.reports()[2].solver, "collocation");
    assert!(!b.reports()[2].exact_available);
    assert!(check_conditions(&b, &conds, 0.0, 1000).max_abs < 1e-12);
    let o = BlendOptions { solver: Solver::Exact, ..Default::default() };
    let e = StaticBlend::new(ops([1, 1, 1]), &conds, VDomain::PERIODIC, &o).unwrap_err();
    assert!(e.to_string().contains("eigenfunctions"), "{e}");
}

#[test]
fn missing_conditions_and_degenerate_operators_are_named() {
    let conds = vec![cond(0.0, 0, ["cos(v)", "0", "0"]), cond(1.0, 0, ["0", "0", "0"])];
    let e = StaticBlend::new(ops([1, 1, 2]), &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap_err();
    assert!(e.to_string().contains("component z has order 4") && e.to_string().contains("u = 0"), "{e}");
    let e = Operator::new(vec![0.0, 1.0, 1.0]).unwrap_err();
    assert!(e.to_string().contains("∂u^4"), "{e}");
    // a hyperbolic operator is solved per mode where the mode systems are regular
    let wave = Operator::new(vec![1.0, -0.3]).unwrap();
    assert!(!wave.is_elliptic());
    let b = StaticBlend::new([wave.clone(), wave.clone(), wave], &conds, VDomain::PERIODIC, &BlendOptions::default())
        .unwrap();
    assert!(!b.reports()[0].elliptic);
    assert!(check_conditions(&b, &conds, 0.0, 100).max_abs < 1e-12);
}

fn arb_trig() -> impl Strategy<Value = String> {
    prop::collection::vec((0usize..=4, any::<bool>(), -2.0f64..2.0), 1..=3).prop_map(|terms| {
        terms
            .into_iter()
            .map(
                |(n, s, c)| {
                    if n == 0 { format!("({c})") } else { format!("({c})*{}({n}*v)", if s { "sin" } else { "cos" }) }
                },
            )
            .collect::<Vec<_>>()
            .join(" + ")
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Random elliptic coefficients, random orders and random eigenfunction data: the
    /// exact solver satisfies the PDE to round-off and every condition.
    #[test]
    fn exact_solver_is_exact_for_random_elliptic_operators(
        r in prop::array::uniform3(1usize..=3),
        seeds in prop::collection::vec(0.2f64..3.0, 12),
        data in prop::collection::vec(arb_trig(), 18),
    ) {
        let ops: [Operator; 3] = std::array::from_fn(|t| {
            // (a ∂u² + b ∂v²)(…) products of elliptic second-order factors stay elliptic
            let mut c = vec![1.0];
            for k in 0..r[t] {
                let (a, b) = (seeds[4 * t + k], seeds[4 * t + k + 1]);
                let mut next = vec![0.0; c.len() + 1];
                for (i, x) in c.iter().enumerate() {
                    next[i] += a * x;
                    next[i + 1] += b * x;
                }
                c = next;
            }
            Operator::new(c).unwrap()
        });
        for op in &ops {
            prop_assert!(op.is_elliptic());
        }
        let mut conds = Vec::new();
        for (e, u) in [(0usize, 0.0), (1, 1.0)] {
            for k in 0..3 {
                let i = 9 * e + 3 * k;
                conds.push(cond(u, k, [&data[i], &data[i + 1], &data[i + 2]]));
            }
        }
        let b = StaticBlend::new(ops, &conds, VDomain::PERIODIC, &BlendOptions::default()).unwrap();
        prop_assert!(b.reports().iter().all(|r| r.solver == "exact"));
        let err = condition_error(&b, &conds);
        let size = conds.iter().map(|c| (0..50).map(|i| c.data.eval(&[i as f64 * 0.13, 0.0]).norm()).max_nan()).fold(1.0, crate::num::max_nan);
        prop_assert!(err < 1e-10 * size, "condition error {}", err);
        let (res, rsize) = max_residual(&b);
        prop_assert!(res < 1e-10 * rsize.max(1.0), "PDE residual {} of {}", res, rsize);
    }
}

#[test]
fn vec3_index_sanity() {
    let mut v = Vec3::ZERO;
    v[2] = 1.0;
    assert_eq!(v.z, 1.0);
}
