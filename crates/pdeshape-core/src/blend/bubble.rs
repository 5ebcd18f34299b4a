//! The bubble functions of the collocation solver.

use crate::jet::{Jet, JetShape};

/// `β_m(u) = uʳ (1 − u)ʳ P_m(2u − 1)` with the Legendre polynomial `P_m`: it vanishes with
/// its first `r − 1` derivatives at `u = 0` and `u = 1`, and `β_0 … β_{B−1}` span the same
/// space as the paper's `u^m` minus their Hermite interpolants (polynomials of degree
/// `< 2r + B` with those end conditions) without their ill-conditioning.
///
/// Returns `out[m][k] = β_m^{(k)}(u)` for `m < count`, `k ≤ kmax` (exact, by Taylor jets).
///
/// ```
/// use pdeshape_core::blend::bubbles;
/// let b = bubbles(2, 3, 0.0, 1);
/// assert!(b.iter().all(|d| d[0] == 0.0 && d[1] == 0.0));
/// ```
pub fn bubbles(r: usize, count: usize, u: f64, kmax: usize) -> Vec<Vec<f64>> {
    let shape = JetShape::new(&[kmax]);
    let x = Jet::variable(shape, 0, u);
    let w = x.powi(r as i32).mul(&x.neg().add_scalar(1.0).powi(r as i32));
    let t = x.scale(2.0).add_scalar(-1.0);
    let mut out = Vec::with_capacity(count);
    let (mut p0, mut p1) = (Jet::constant(shape, 1.0), t.clone());
    for m in 0..count {
        let p = if m == 0 { p0.clone() } else { p1.clone() };
        let b = w.mul(&p);
        out.push((0..=kmax).map(|k| b.derivative([k, 0, 0])).collect());
        if m >= 1 {
            // (m + 1) P_{m+1} = (2m + 1) t P_m − m P_{m−1}
            let mf = m as f64;
            let next = t.mul(&p1).scale((2.0 * mf + 1.0) / (mf + 1.0)).sub(&p0.scale(mf / (mf + 1.0)));
            p0 = p1;
            p1 = next;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bubbles_vanish_to_order_r_minus_one_at_both_ends() {
        for r in 1..=3 {
            for u in [0.0, 1.0] {
                for b in bubbles(r, 6, u, 2 * r) {
                    for (k, d) in b.iter().enumerate().take(r) {
                        assert!(d.abs() < 1e-13, "r {r} u {u} derivative {k}: {d}");
                    }
                    assert!(b[r].abs() > 0.0 || r == 0);
                }
            }
        }
        // P_2(t) = (3t² − 1)/2 at u = 0.3 (t = −0.4), r = 1: β = 0.21 · (−0.26)
        let b = bubbles(1, 3, 0.3, 0);
        assert!((b[2][0] - 0.21 * (3.0 * 0.16 - 1.0) / 2.0).abs() < 1e-15);
    }
}
