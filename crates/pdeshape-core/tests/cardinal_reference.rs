//! The cardinal functions of `ker (D² − c²)^N` at the 2N Chebyshev nodes
//! `u_i = (1 − cos(π i/(2N − 1)))/2`, values and first derivatives between the nodes,
//! against an independent table computed with mpmath at 160 digits
//! (`tests/data/cardinal-functions.csv`, a copy of `shared/reference/`): N = 2 … 32,
//! c = 0 … 30: the path the solver takes, and each path forced.

use pdeshape_core::num::max_nan;
use pdeshape_core::ode::{Cardinal, CardinalSet, ChebCardinal, CondSpec, ExpSpace, F64_COND_LIMIT, UltraCardinal};
use std::collections::BTreeMap;

struct Row {
    j: usize,
    u: f64,
    value: f64,
    derivative: f64,
}

fn table() -> BTreeMap<(usize, u64), Vec<Row>> {
    let text = include_str!("data/cardinal-functions.csv");
    let mut out: BTreeMap<(usize, u64), Vec<Row>> = BTreeMap::new();
    for line in text.lines().filter(|l| !l.starts_with('#') && !l.starts_with('N')) {
        let f: Vec<&str> = line.split(',').collect();
        assert_eq!(f.len(), 6, "{line}");
        let n: usize = f[0].parse().unwrap();
        let c: f64 = f[1].parse().unwrap();
        out.entry((n, c.to_bits())).or_default().push(Row {
            j: f[2].parse().unwrap(),
            u: f[3].parse().unwrap(),
            value: f[4].parse().unwrap(),
            derivative: f[5].parse().unwrap(),
        });
    }
    out
}

/// The largest value error (absolute) and derivative error (relative to the set's largest
/// |ℓ_j′|) of `eval` against the table, NaN-propagating.
fn errors(want: &[Row], eval: &dyn Fn(f64) -> Vec<Vec<f64>>) -> (f64, f64) {
    let dscale = want.iter().map(|r| r.derivative.abs()).fold(1.0, max_nan);
    let (mut ev, mut ed) = (0.0f64, 0.0f64);
    for r in want {
        let e = eval(r.u);
        ev = max_nan(ev, (e[0][r.j] - r.value).abs());
        ed = max_nan(ed, (e[1][r.j] - r.derivative).abs() / dscale);
    }
    (ev, ed)
}

fn nodes(n: usize) -> Vec<CondSpec> {
    let m = 2 * n;
    (0..m)
        .map(|i| CondSpec { u: (1.0 - (std::f64::consts::PI * i as f64 / (m - 1) as f64).cos()) / 2.0, order: 0 })
        .collect()
}

/// The path the solver chooses meets the table on every set.
#[test]
fn cardinal_functions_match_the_mpmath_table() {
    let t = table();
    assert!(t.len() >= 12, "{} (N, c) sets", t.len());
    let mut rows = 0;
    let mut report = Vec::new();
    for ((n, c), want) in &t {
        let c = f64::from_bits(*c);
        let set = CardinalSet::new(ExpSpace::symmetric(c, *n), &nodes(*n), 1).unwrap();
        let (ev, ed) = errors(want, &|u| set.eval(u, 1));
        rows += want.len();
        report.push(format!("N {n:2} c {c:4}: {} value {ev:.1e} derivative {ed:.1e}", set.method()));
        // values are O(1) (Lebesgue constants of Chebyshev nodes are small): 1e-12 absolute;
        // derivatives relative to their largest size in the set
        assert!(
            ev <= 1e-12 && ed <= 1e-12,
            "N = {n}, c = {c} ({}): value error {ev:e}, derivative error {ed:e}\n{}",
            set.method(),
            report.join("\n")
        );
    }
    assert!(rows > 11_000, "{rows} rows");
    println!("{}", report.join("\n"));
}

/// Each path forced on its own, so that a path the selector happens not to choose for
/// these sets is still held to the table: the f64 exponential basis wherever its condition
/// number is within [`F64_COND_LIMIT`] (the selector's rule), the ultraspherical solve
/// wherever it accepts the set, and multiple precision on every set. Each path must be
/// checked on at least three sets.
#[test]
fn every_path_meets_the_mpmath_table() {
    let t = table();
    let mut checked = [0usize; 3];
    for ((n, c), want) in &t {
        let c = f64::from_bits(*c);
        let space = ExpSpace::symmetric(c, *n);
        let conds = nodes(*n);
        let check = |name: &str, (ev, ed): (f64, f64)| {
            // as above: 1e-12 absolute in value, relative in derivative
            assert!(
                ev <= 1e-12 && ed <= 1e-12,
                "{name}, N = {n}, c = {c}: value error {ev:e}, derivative error {ed:e}"
            );
        };
        if let Ok(d) = Cardinal::new(space.clone(), &conds)
            && d.condition_number() <= F64_COND_LIMIT
        {
            check("f64", errors(want, &|u| d.eval(u, 1)));
            checked[0] += 1;
        }
        if let Ok(u) = UltraCardinal::new(&space, &conds, 1) {
            check("ultraspherical", errors(want, &|x| u.eval(x, 1)));
            checked[1] += 1;
        }
        let p = ChebCardinal::new(&space, &conds, 1).unwrap();
        check("multiple precision", errors(want, &|u| p.eval(u, 1)));
        checked[2] += 1;
    }
    eprintln!("sets checked per path (f64, ultraspherical, multiple precision): {checked:?}");
    assert!(checked.iter().all(|&k| k >= 3), "{checked:?}");
}
