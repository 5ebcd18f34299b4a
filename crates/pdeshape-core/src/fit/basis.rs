//! Clamped B-spline knot vectors and their basis functions with derivatives (the NURBS
//! Book's `FindSpan`, and `DersBasisFuns` shared with `data`'s B-spline curves, Piegl &
//! Tiller §2.5).

/// A clamped knot vector of degree `p`: `p + 1` equal knots at each end.
#[derive(Clone, Debug, PartialEq)]
pub struct Knots {
    /// Degree.
    pub degree: usize,
    /// The full knot vector (length `n + p + 1` for `n` control points).
    pub knots: Vec<f64>,
}

impl Knots {
    /// Clamped knots on `[a, b]` with the given interior breakpoints (strictly increasing,
    /// inside `(a, b)`).
    pub fn clamped(degree: usize, a: f64, b: f64, interior: &[f64]) -> Knots {
        let mut knots = vec![a; degree + 1];
        knots.extend_from_slice(interior);
        knots.extend(std::iter::repeat_n(b, degree + 1));
        Knots { degree, knots }
    }

    /// Uniform clamped knots with `spans` spans on `[a, b]`.
    pub fn uniform(degree: usize, a: f64, b: f64, spans: usize) -> Knots {
        let interior: Vec<f64> = (1..spans).map(|i| a + (b - a) * i as f64 / spans as f64).collect();
        Knots::clamped(degree, a, b, &interior)
    }

    /// Number of control points.
    pub fn count(&self) -> usize {
        self.knots.len() - self.degree - 1
    }

    /// The distinct breakpoints `a = t₀ < t₁ < … < b`.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut b: Vec<f64> = Vec::new();
        for &t in &self.knots {
            if b.last() != Some(&t) {
                b.push(t);
            }
        }
        b
    }

    /// The distinct knots with their multiplicities (the form STEP and IGES write).
    pub fn multiplicities(&self) -> (Vec<f64>, Vec<usize>) {
        let (mut t, mut m): (Vec<f64>, Vec<usize>) = (Vec::new(), Vec::new());
        for &x in &self.knots {
            match t.last() {
                Some(&y) if y == x => *m.last_mut().expect("paired with t") += 1,
                _ => {
                    t.push(x);
                    m.push(1);
                }
            }
        }
        (t, m)
    }

    /// The Greville abscissae `(t_{j+1} + … + t_{j+p}) / p`, one per control point.
    pub fn greville(&self) -> Vec<f64> {
        let p = self.degree;
        (0..self.count()).map(|j| self.knots[j + 1..=j + p].iter().sum::<f64>() / p as f64).collect()
    }

    /// The knot span index `i` with `t_i ≤ x < t_{i+1}` (the last non-empty span at `b`).
    pub fn span(&self, x: f64) -> usize {
        let (p, n) = (self.degree, self.count());
        if x >= self.knots[n] {
            return n - 1;
        }
        if x <= self.knots[p] {
            return p;
        }
        // binary search in [p, n)
        let (mut lo, mut hi) = (p, n);
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if x < self.knots[mid] {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        lo
    }

    /// The `p + 1` non-zero basis functions' values at `x` into `out` (`p + 1` long), without
    /// allocating; returns the span. The recurrence and its operations are those of
    /// [`Knots::basis`] (The NURBS Book's A2.2 is A2.3's first table), so the values are
    /// the same bits.
    pub fn values_into(&self, x: f64, out: &mut [f64]) -> usize {
        let p = self.degree;
        let i = self.span(x);
        let u = &self.knots;
        let mut left: smallvec::SmallVec<[f64; 16]> = smallvec::smallvec![0.0; p + 1];
        let mut right: smallvec::SmallVec<[f64; 16]> = smallvec::smallvec![0.0; p + 1];
        out[0] = 1.0;
        for j in 1..=p {
            left[j] = x - u[i + 1 - j];
            right[j] = u[i + j] - x;
            let mut saved = 0.0;
            for r in 0..j {
                let temp = out[r] / (right[r + 1] + left[j - r]);
                out[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            out[j] = saved;
        }
        i
    }

    /// The `p + 1` non-zero basis functions at `x` and their derivatives up to order `nd`:
    /// `out[k][r]` is `dᵏ N_{span−p+r}/dxᵏ`; returns the span.
    pub fn basis(&self, x: f64, nd: usize) -> (usize, Vec<Vec<f64>>) {
        let p = self.degree;
        let i = self.span(x);
        let mut ders = crate::data::basis_derivatives(&self.knots, p, i, x, nd);
        ders.resize(nd + 1, vec![0.0; p + 1]); // zero above the degree
        (i, ders)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `values_into` gives the bits of `basis`' values, at knots, between them and at the
    /// ends, on clamped knots with a double interior knot, degrees 1 to 9.
    #[test]
    fn values_into_is_basis_bit_for_bit() {
        for p in 1..=9 {
            let k = Knots::clamped(p, -1.0, 2.5, &[-0.3, 0.1, 0.1, 0.7, 1.9]);
            let mut out = vec![f64::NAN; p + 1];
            for x in [-1.0, -0.7, -0.3, 0.0, 0.1, 0.45, 1.9, 2.2, 2.5] {
                let (span, d) = k.basis(x, 0);
                assert_eq!(k.values_into(x, &mut out), span, "degree {p} at {x}");
                assert_eq!(out, d[0], "degree {p} at {x}");
            }
        }
    }

    /// Partition of unity, derivatives summing to 0, and the cubic Bézier case by hand
    /// (one span: Bernstein polynomials `C(3, r) xʳ (1 − x)³⁻ʳ` and their derivatives).
    #[test]
    fn basis_against_bernstein_and_partition_of_unity() {
        let k = Knots::uniform(3, 0.0, 1.0, 1);
        for x in [0.0, 0.3, 0.77, 1.0] {
            let (span, d) = k.basis(x, 2);
            assert_eq!(span, 3);
            let b = [(1.0 - x).powi(3), 3.0 * x * (1.0 - x).powi(2), 3.0 * x * x * (1.0 - x), x.powi(3)];
            let db =
                [-3.0 * (1.0 - x).powi(2), 3.0 * (1.0 - x) * (1.0 - 3.0 * x), 3.0 * x * (2.0 - 3.0 * x), 3.0 * x * x];
            let ddb = [6.0 * (1.0 - x), 18.0 * x - 12.0, 6.0 - 18.0 * x, 6.0 * x];
            for r in 0..4 {
                assert!((d[0][r] - b[r]).abs() < 1e-15, "{x} {r}");
                assert!((d[1][r] - db[r]).abs() < 1e-13, "{x} {r}: {} {}", d[1][r], db[r]);
                assert!((d[2][r] - ddb[r]).abs() < 1e-12, "{x} {r}: {} {}", d[2][r], ddb[r]);
            }
        }
        let k = Knots::clamped(3, 0.0, 2.0, &[0.3, 0.9, 1.2, 1.7]);
        assert_eq!(k.count(), 8);
        for x in [0.0, 0.1, 0.3, 0.95, 1.5, 2.0] {
            let (_, d) = k.basis(x, 3);
            assert!((d[0].iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for row in &d[1..] {
                assert!(row.iter().sum::<f64>().abs() < 1e-11, "{x}: {row:?}");
            }
        }
        assert_eq!(k.span(0.3), 4);
        assert_eq!(k.span(2.0), 7);
        let g = k.greville();
        assert!((g[0] - 0.0).abs() < 1e-15 && (g[7] - 2.0).abs() < 1e-15 && (g[1] - 0.1).abs() < 1e-15);
    }
}
