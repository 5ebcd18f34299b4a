//! Measures the conditioning of the bounded f64 basis: condition numbers and the worst
//! cardinal-property error at the conditions, for orders 2N and mode constants c.
//! Run: cargo run --release -p pdeshape-core --example ode_conditioning
use pdeshape_core::ode::{Cardinal, CondSpec, ExpSpace};

fn main() {
    println!("{:>3} {:>7} {:>12} {:>12} {:>10}", "N", "c", "cond", "card. err", "Lebesgue");
    for n in [2usize, 4, 6, 8, 10, 12, 16, 20] {
        let m = 2 * n;
        let conds: Vec<CondSpec> = (0..m)
            .map(|i| CondSpec { u: (1.0 - (std::f64::consts::PI * i as f64 / (m - 1) as f64).cos()) / 2.0, order: 0 })
            .collect();
        for c in [0.0, 1.0, 5.0, 20.0, 64.0] {
            match Cardinal::new(ExpSpace::symmetric(c, n), &conds) {
                Ok(l) => {
                    let mut err: f64 = 0.0;
                    for (k, cd) in conds.iter().enumerate() {
                        let v = l.eval(cd.u, 0);
                        for (i, x) in v[0].iter().enumerate() {
                            err = err.max((x - if i == k { 1.0 } else { 0.0 }).abs());
                        }
                    }
                    println!("{n:>3} {c:>7} {:>12.3e} {:>12.3e} {:>10.3}", l.condition_number(), err, l.lebesgue(400));
                }
                Err(e) => println!("{n:>3} {c:>7} {e}"),
            }
        }
    }
}
