//! Boundary basis functions `g_j(v)` and the decomposition of boundary data over them.

use super::BlendError;
use crate::Vec3;
use crate::data::FieldRef;
use crate::data::fourier::{FourierSeries, sample_count};
use crate::expr::Expr;
use crate::jet::{Jet, JetShape};
use crate::patch::{Condition, VDomain};
use std::f64::consts::TAU;

/// A scalar function `g(v)` with exact derivatives of every order.
#[derive(Clone, Debug)]
pub enum BasisFn {
    /// `g = 1` (`g″ = 0`).
    Constant,
    /// `cos(n θ)` or `sin(n θ)` with `θ = 2π (v − v₀)/P` on a periodic domain of period `P`;
    /// `g″ = −k² g`, `k = 2πn/P`.
    Trig {
        /// Mode number.
        n: usize,
        /// `sin` when true, `cos` otherwise.
        sine: bool,
        /// `k = 2πn/P`.
        k: f64,
        /// `v₀`.
        v0: f64,
    },
    /// An explicit expression in `v`.
    Expr {
        /// The expression (one variable, `v`).
        expr: Expr,
        /// Its source text.
        text: String,
    },
    /// One component of a boundary function, used whole.
    Data {
        /// The curve (slots `(v, t)`).
        field: FieldRef,
        /// The component (0, 1, 2).
        comp: usize,
        /// Which condition it came from.
        label: String,
    },
}

impl BasisFn {
    /// `out[j] = g^{(j)}(v)`, `j = 0 … kmax`.
    pub fn derivatives(&self, v: f64, kmax: usize) -> Vec<f64> {
        match self {
            BasisFn::Constant => (0..=kmax).map(|j| if j == 0 { 1.0 } else { 0.0 }).collect(),
            BasisFn::Trig { sine, k, v0, .. } => {
                let ph = k * (v - v0) + if *sine { -std::f64::consts::FRAC_PI_2 } else { 0.0 };
                (0..=kmax).map(|j| k.powi(j as i32) * (ph + j as f64 * std::f64::consts::FRAC_PI_2).cos()).collect()
            }
            BasisFn::Expr { expr, .. } => {
                let shape = JetShape::new(&[kmax]);
                let jet = expr.eval_jet(&[Jet::variable(shape, 0, v)]);
                (0..=kmax).map(|j| jet.derivative([j, 0, 0])).collect()
            }
            BasisFn::Data { field, comp, .. } => {
                let jet = field.jet(&[v, 0.0], JetShape::new(&[kmax]));
                (0..=kmax).map(|j| jet.0[*comp].derivative([j, 0, 0])).collect()
            }
        }
    }

    /// A short name for reports.
    pub fn name(&self) -> String {
        match self {
            BasisFn::Constant => "1".into(),
            BasisFn::Trig { n, sine, .. } => format!("{}({n}θ)", if *sine { "sin" } else { "cos" }),
            BasisFn::Expr { text, .. } => text.clone(),
            BasisFn::Data { label, comp, .. } => format!("{label}.{}", ["x", "y", "z"][*comp]),
        }
    }

    /// `μ` with `g″ = μ g` when `g` is an eigenfunction of `∂v²`: exact for the constant
    /// and trigonometric functions, otherwise detected numerically from exact derivatives
    /// at 41 points of the domain (`|g″ − μg| ≤ 1e-11 (|g″| + |μ g|)` everywhere).
    pub fn eigenvalue(&self, domain: VDomain) -> Option<f64> {
        match self {
            BasisFn::Constant => Some(0.0),
            BasisFn::Trig { k, .. } => Some(-k * k),
            _ => {
                let pts: Vec<[f64; 2]> = (0..41)
                    .map(|i| {
                        let d = self.derivatives(domain.at((i as f64 + 0.37) / 41.5), 2);
                        [d[0], d[2]]
                    })
                    .collect();
                let (num, den) = pts.iter().fold((0.0, 0.0), |(n, d), [g, g2]| (n + g * g2, d + g * g));
                if den == 0.0 || !den.is_finite() {
                    return None;
                }
                let mu = num / den;
                let scale = pts.iter().fold(0.0f64, |m, [g, g2]| m.max(g2.abs()).max((mu * g).abs()));
                pts.iter().all(|[g, g2]| (g2 - mu * g).abs() <= 1e-11 * scale).then_some(mu)
            }
        }
    }
}

/// The boundary data of one component over a basis: `f_c(v) = Σ_j coef[c][j] g_j(v)` for
/// every condition `c`.
#[derive(Clone, Debug)]
pub struct Decomposition {
    /// The basis `g_j`.
    pub basis: Vec<BasisFn>,
    /// `μ_j` when `g_j″ = μ_j g_j`.
    pub mu: Vec<Option<f64>>,
    /// `coef[c][j]`.
    pub coef: Vec<Vec<f64>>,
}

/// Largest mode number tried when splitting periodic data into Fourier modes.
pub const MAX_SPLIT_MODES: usize = 64;

fn scalar(c: &Condition, comp: usize, v: f64) -> f64 {
    c.data.eval(&[v, 0.0])[comp]
}

/// Decomposes component `comp` of the conditions' data.
///
/// - With an explicit basis: least-squares coefficients on 97 points; data outside the
///   span (residual > 1e-10 of the data size) is an error naming the condition.
/// - Automatically on a periodic domain: each function is analysed by FFT; when it is a
///   trigonometric polynomial of ≤ [`MAX_SPLIT_MODES`] modes (checked at off-grid points to
///   1e-12) it is split into constant, `cos nθ` and `sin nθ` terms (eigenfunctions), shared
///   across conditions; otherwise it becomes one basis function of its own.
/// - Automatically on an open domain: constants are detected, every other function is its
///   own basis function (the paper's fallback: one function per boundary function).
pub fn decompose(
    conds: &[&Condition],
    comp: usize,
    domain: VDomain,
    explicit: Option<&[BasisFn]>,
) -> Result<Decomposition, BlendError> {
    let label = |c: &Condition| format!("∂^{}X/∂u^{} at u = {}", c.order, c.order, c.u);
    let axis = ["x", "y", "z"][comp];
    if let Some(basis) = explicit {
        let vs: Vec<f64> = (0..97).map(|i| domain.at((i as f64 + 0.41) / 97.3)).collect();
        let g = faer::Mat::from_fn(vs.len(), basis.len(), |i, j| basis[j].derivatives(vs[i], 0)[0]);
        let f = faer::Mat::from_fn(vs.len(), conds.len(), |i, c| scalar(conds[c], comp, vs[i]));
        let (x, _) = crate::linalg::least_squares(&g, &f, 1e12).map_err(|e| {
            BlendError::Basis(format!("the explicit basis functions are not independent on the domain ({e})"))
        })?;
        let fit = crate::lanes::after(&g * &x);
        for (c, cond) in conds.iter().enumerate() {
            let size = (0..vs.len()).fold(0.0f64, |m, i| m.max(f[(i, c)].abs()));
            let err = (0..vs.len()).fold(0.0f64, |m, i| m.max((fit[(i, c)] - f[(i, c)]).abs()));
            if err > 1e-10 * size.max(1e-300) && err > 1e-14 {
                return Err(BlendError::Basis(format!(
                    "component {axis} of the condition {} is not in the span of the basis [{}] (max residual {err:.3e})",
                    label(cond),
                    basis.iter().map(|b| b.name()).collect::<Vec<_>>().join(", ")
                )));
            }
        }
        let coef = (0..conds.len()).map(|c| (0..basis.len()).map(|j| x[(j, c)]).collect()).collect();
        let mu = basis.iter().map(|b| b.eigenvalue(domain)).collect();
        return Ok(Decomposition { basis: basis.to_vec(), mu, coef });
    }
    let mut basis: Vec<BasisFn> = Vec::new();
    let mut keys: Vec<(usize, bool)> = Vec::new(); // (n, sine) of Trig/Constant entries; usize::MAX for data
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut index = |basis: &mut Vec<BasisFn>, key: (usize, bool), make: &dyn Fn() -> BasisFn| -> usize {
        if key.0 != usize::MAX
            && let Some(i) = keys.iter().position(|k| *k == key)
        {
            return i;
        }
        keys.push(key);
        basis.push(make());
        basis.len() - 1
    };
    let period = domain.end - domain.start;
    for cond in conds {
        let f = |v: f64| scalar(cond, comp, v);
        let probe: Vec<f64> = (0..53).map(|i| f(domain.at((i as f64 + 0.29) / 53.0))).collect();
        let size = probe.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut row = Vec::new();
        if size == 0.0 {
            rows.push(row);
            continue;
        }
        if probe.iter().all(|x| (x - probe[0]).abs() <= 1e-14 * size) {
            row.push((index(&mut basis, (0, false), &|| BasisFn::Constant), probe[0]));
            rows.push(row);
            continue;
        }
        if domain.periodic {
            let m = MAX_SPLIT_MODES;
            let fs = FourierSeries::analyse(
                |th| Vec3::new(f(domain.start + th * period / TAU), 0.0, 0.0),
                m,
                sample_count(m),
            );
            let ok = (0..53).all(|i| {
                let th = TAU * (i as f64 + 0.29) / 53.0;
                (fs.eval(th).x - probe[i]).abs() <= 1e-12 * size
            });
            if ok {
                for n in 0..=m {
                    for (sine, c) in [(false, fs.a[n].x), (true, fs.b[n].x)] {
                        if c.abs() <= 1e-15 * size || (n == 0 && sine) {
                            continue;
                        }
                        let k = TAU * n as f64 / period;
                        let v0 = domain.start;
                        let j = if n == 0 {
                            index(&mut basis, (0, false), &|| BasisFn::Constant)
                        } else {
                            index(&mut basis, (n, sine), &|| BasisFn::Trig { n, sine, k, v0 })
                        };
                        row.push((j, c));
                    }
                }
                rows.push(row);
                continue;
            }
        }
        let j = index(&mut basis, (usize::MAX, false), &|| BasisFn::Data {
            field: cond.data.clone(),
            comp,
            label: label(cond),
        });
        row.push((j, 1.0));
        rows.push(row);
    }
    let coef = rows
        .iter()
        .map(|row| {
            let mut c = vec![0.0; basis.len()];
            for &(j, x) in row {
                c[j] += x;
            }
            c
        })
        .collect();
    let mu = basis.iter().map(|b| b.eigenvalue(domain)).collect();
    Ok(Decomposition { basis, mu, coef })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ExprField;
    use std::sync::Arc;

    fn cond(u: f64, order: usize, e: [&str; 3]) -> Condition {
        Condition { u, order, data: Arc::new(ExprField::parse(e, &["v", "t"], &|_| None).unwrap()) }
    }

    #[test]
    fn periodic_data_split_into_fourier_eigenfunctions() {
        let c0 = cond(0.0, 0, ["2*cos(v) + 0.5", "sin(v)", "3"]);
        let c1 = cond(1.0, 0, ["cos(v)*cos(v)", "sin(2*v)", "0"]);
        let d = decompose(&[&c0, &c1], 0, VDomain::PERIODIC, None).unwrap();
        // 1, cos v, cos 2v (cos² v = (1 + cos 2v)/2)
        assert_eq!(d.basis.len(), 3, "{:?}", d.basis.iter().map(|b| b.name()).collect::<Vec<_>>());
        assert!(d.mu.iter().all(|m| m.is_some()));
        for (c, cond) in [&c0, &c1].iter().enumerate() {
            for v in [0.1, 1.7, 4.0] {
                let s: f64 = d.basis.iter().zip(&d.coef[c]).map(|(b, x)| b.derivatives(v, 0)[0] * x).sum();
                assert!((s - cond.data.eval(&[v, 0.0]).x).abs() < 1e-13);
            }
        }
        let d = decompose(&[&c0, &c1], 2, VDomain::PERIODIC, None).unwrap();
        assert_eq!(d.basis.len(), 1);
        assert_eq!(d.coef[1], vec![0.0]);
    }

    #[test]
    fn non_trigonometric_data_is_kept_whole_and_eigenfunctions_are_detected() {
        let c0 = cond(0.0, 0, ["cosh(v)", "v*v", "exp(-2*v)"]);
        let dom = VDomain::open(0.0, 1.0);
        for (comp, mu) in [(0, Some(1.0)), (1, None), (2, Some(4.0))] {
            let d = decompose(&[&c0], comp, dom, None).unwrap();
            assert_eq!(d.basis.len(), 1);
            match (d.mu[0], mu) {
                (Some(a), Some(b)) => assert!((a - b).abs() < 1e-12),
                (a, b) => assert_eq!(a, b),
            }
        }
    }

    #[test]
    fn explicit_basis_projection_and_span_errors() {
        let c0 = cond(0.0, 0, ["2*cos(v) + 1", "0", "0"]);
        let basis: Vec<BasisFn> = ["cos(v)", "1"]
            .iter()
            .map(|t| BasisFn::Expr {
                expr: Expr::parse(t).unwrap().bind(&["v"], &|_| None).unwrap(),
                text: t.to_string(),
            })
            .collect();
        let d = decompose(&[&c0], 0, VDomain::PERIODIC, Some(&basis)).unwrap();
        assert!((d.coef[0][0] - 2.0).abs() < 1e-13 && (d.coef[0][1] - 1.0).abs() < 1e-13);
        let c1 = cond(0.0, 0, ["sin(v)", "0", "0"]);
        let e = decompose(&[&c1], 0, VDomain::PERIODIC, Some(&basis)).unwrap_err();
        assert!(e.to_string().contains("not in the span"), "{e}");
    }
}
