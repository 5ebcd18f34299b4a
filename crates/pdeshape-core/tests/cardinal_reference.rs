//! The cardinal functions of `ker (D² − c²)^N` at the 2N Chebyshev nodes
//! `u_i = (1 − cos(π i/(2N − 1)))/2`, values and first derivatives between the nodes,
//! against an independent table computed with mpmath at 160 digits
//! (`tests/data/cardinal-functions.csv`, a copy of `shared/reference/`): N = 2 … 32,
//! c = 0 … 30, whichever path (f64 or multiple precision) the solver takes.

use pdeshape_core::ode::{CardinalSet, CondSpec, ExpSpace};
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

#[test]
fn cardinal_functions_match_the_mpmath_table() {
    let t = table();
    assert!(t.len() >= 12, "{} (N, c) sets", t.len());
    let mut rows = 0;
    let mut report = Vec::new();
    for ((n, c), want) in &t {
        let c = f64::from_bits(*c);
        let m = 2 * n;
        let nodes: Vec<CondSpec> = (0..m)
            .map(|i| CondSpec { u: (1.0 - (std::f64::consts::PI * i as f64 / (m - 1) as f64).cos()) / 2.0, order: 0 })
            .collect();
        let set = CardinalSet::new(ExpSpace::symmetric(c, *n), &nodes, 1).unwrap();
        // the derivative's scale: the largest |ℓ_j′| in the table for this set
        let dscale =
            want.iter().map(|r| r.derivative.abs()).fold(1.0, |a: f64, b| if b.is_nan() { f64::NAN } else { a.max(b) });
        let (mut ev, mut ed) = (0.0f64, 0.0f64);
        for r in want {
            let e = set.eval(r.u, 1);
            let (dv, dd) = ((e[0][r.j] - r.value).abs(), (e[1][r.j] - r.derivative).abs() / dscale);
            ev = if dv.is_nan() { f64::NAN } else { ev.max(dv) };
            ed = if dd.is_nan() { f64::NAN } else { ed.max(dd) };
            rows += 1;
        }
        report.push(format!("N {n:2} c {c:4}: {} value {ev:.1e} derivative {ed:.1e} (of {dscale:.1e})", set.method()));
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
