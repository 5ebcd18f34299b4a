//! Trigonometric polynomials recognised in expressions: the degree of `g(θ)` as a finite
//! Fourier series `a₀ + Σ_{n ≤ d} (aₙ cos nθ + bₙ sin nθ)`, proved from the expression's
//! structure.
//!
//! The rules (θ the variable slot asked about; anything that does not depend on it is a
//! constant, degree 0):
//!
//! - `cos(kθ + c)`, `sin(kθ + c)` with `k` an integer (the argument affine in θ with a
//!   numeric integer slope): degree `|k|`;
//! - sums and differences: the larger degree; products: the sum (`cos aθ · cos bθ` is a
//!   combination of `cos(a ± b)θ`); division by a constant and negation keep it; a
//!   non-negative integer power `p` multiplies it by `p`;
//! - `select(x, a, b)` with `x` constant: the larger of the branches' degrees (one branch
//!   holds for every θ);
//! - anything else that depends on θ (θ itself, `exp(sin θ)`, `1/cos θ`, `abs`, …): not
//!   recognised (`None`) — not a claim that it is no trigonometric polynomial.
//!
//! A spectral patch whose every datum is recognised with degree at most its `M` has
//! Fourier tails `g − F_M[g]` that are identically zero, so its remainder term is zero
//! exactly and need not be evaluated (`spectral::batch`).

use super::{BinOp, Expr, Func, Node};

/// The largest degree reported: above it the expression is treated as not recognised.
const MAX_DEGREE: usize = 1 << 16;

/// What a sub-expression is as a function of θ.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    /// Free of θ.
    Const,
    /// A trigonometric polynomial of this degree (≥ 1 or 0 in a constant's place).
    Trig(usize),
    /// Not recognised.
    Other,
}

/// The degree in variable slot `var` of `e` as a trigonometric polynomial, when the rules
/// of the module docs prove it one. Linear in the size of `e` (one visit per node).
pub fn trig_degree(e: &Expr, var: usize) -> Option<usize> {
    match shape(e, var) {
        Shape::Const => Some(0),
        Shape::Trig(d) => Some(d),
        Shape::Other => None,
    }
}

fn degree(s: Shape) -> Option<usize> {
    match s {
        Shape::Const => Some(0),
        Shape::Trig(d) => Some(d),
        Shape::Other => None,
    }
}

fn trig(d: Option<usize>) -> Shape {
    match d {
        Some(d) if d <= MAX_DEGREE => Shape::Trig(d),
        _ => Shape::Other,
    }
}

fn shape(e: &Expr, var: usize) -> Shape {
    match &e.node {
        Node::Num(_) | Node::Ident(_) => Shape::Const,
        Node::Var(i) => {
            if *i == var {
                Shape::Other
            } else {
                Shape::Const
            }
        }
        Node::Neg(a) => shape(a, var),
        Node::Bin(op, a, b) => {
            let (sa, sb) = (shape(a, var), shape(b, var));
            if sa == Shape::Const && sb == Shape::Const {
                return Shape::Const;
            }
            match op {
                BinOp::Add | BinOp::Sub => trig(degree(sa).zip(degree(sb)).map(|(x, y)| x.max(y))),
                BinOp::Mul => trig(degree(sa).zip(degree(sb)).map(|(x, y)| x + y)),
                BinOp::Div if sb == Shape::Const => sa,
                BinOp::Div => Shape::Other,
                BinOp::Pow => power(sa, b),
            }
        }
        Node::Call(f, args) => match (f, args.as_slice()) {
            (Func::Sin | Func::Cos, [x]) => match affine(x, var) {
                Affine::Const => Shape::Const,
                Affine::Slope(k) if k.fract() == 0.0 && k.abs() <= MAX_DEGREE as f64 => Shape::Trig(k.abs() as usize),
                _ => Shape::Other,
            },
            (Func::Pow, [a, b]) => match (shape(a, var), shape(b, var)) {
                (Shape::Const, Shape::Const) => Shape::Const,
                (sa, _) => power(sa, b),
            },
            (Func::Select, [x, a, b]) => {
                let (sx, sa, sb) = (shape(x, var), shape(a, var), shape(b, var));
                match sx {
                    Shape::Const if sa == Shape::Const && sb == Shape::Const => Shape::Const,
                    Shape::Const => trig(degree(sa).zip(degree(sb)).map(|(x, y)| x.max(y))),
                    _ => Shape::Other,
                }
            }
            _ => {
                let mut all_const = true;
                for a in args {
                    all_const &= shape(a, var) == Shape::Const;
                }
                if all_const { Shape::Const } else { Shape::Other }
            }
        },
    }
}

/// `aᵇ` (`a` of shape `sa`) with `b` a non-negative integer number.
fn power(sa: Shape, b: &Expr) -> Shape {
    match b.node {
        Node::Num(p) if p >= 0.0 && p.fract() == 0.0 && p <= 64.0 => trig(degree(sa).map(|d| d * p as usize)),
        _ => Shape::Other,
    }
}

/// What an argument of `sin`/`cos` is: free of θ, `kθ + c` with a numeric slope `k`, or
/// something else.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Affine {
    Const,
    Slope(f64),
    Other,
}

fn affine(x: &Expr, var: usize) -> Affine {
    use Affine::{Const, Other, Slope};
    let k = |a: Affine| match a {
        Const => Some(0.0),
        Slope(k) => Some(k),
        Other => None,
    };
    let both = |a: &Expr, b: &Expr, f: fn(f64, f64) -> f64| match (affine(a, var), affine(b, var)) {
        (Const, Const) => Const,
        (x, y) => k(x).zip(k(y)).map_or(Other, |(x, y)| Slope(f(x, y))),
    };
    match &x.node {
        Node::Num(_) | Node::Ident(_) => Const,
        Node::Var(i) => {
            if *i == var {
                Slope(1.0)
            } else {
                Const
            }
        }
        Node::Neg(a) => match affine(a, var) {
            Slope(k) => Slope(-k),
            other => other,
        },
        Node::Bin(BinOp::Add, a, b) => both(a, b, |x, y| x + y),
        Node::Bin(BinOp::Sub, a, b) => both(a, b, |x, y| x - y),
        Node::Bin(op @ (BinOp::Mul | BinOp::Div | BinOp::Pow), a, b) => {
            match (op, &a.node, &b.node, affine(a, var), affine(b, var)) {
                (_, _, _, Const, Const) => Const,
                (BinOp::Mul, Node::Num(c), _, _, Slope(k)) => Slope(c * k),
                (BinOp::Mul, _, Node::Num(c), Slope(k), _) => Slope(k * c),
                (BinOp::Div, _, Node::Num(c), Slope(k), _) if *c != 0.0 => Slope(k / c),
                _ => Other,
            }
        }
        Node::Call(_, args) => {
            let mut all_const = true;
            for a in args {
                all_const &= affine(a, var) == Const;
            }
            if all_const { Const } else { Other }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn deg(src: &str) -> Option<usize> {
        let e = Expr::parse(src).unwrap().bind(&["v", "t"], &|n| (n == "r").then_some(2.0)).unwrap();
        trig_degree(&e, 0)
    }

    #[test]
    fn degrees_are_proved_from_the_structure() {
        let cases: [(&str, Option<usize>); 23] = [
            ("3", Some(0)),
            ("r*t^2 + exp(t)", Some(0)),
            ("cos(v)", Some(1)),
            ("r*sin(v) - 4", Some(1)),
            ("cos(3*v + 0.5)", Some(3)),
            ("sin(-2*v)", Some(2)),
            ("cos(v/0.5)", Some(2)),
            ("cos(v)*sin(v)", Some(2)),
            ("cos(v)^3 + sin(2*v)", Some(3)),
            ("pow(cos(v), 2)", Some(2)),
            ("(1 + cos(v))/2", Some(1)),
            ("-(t*cos(v + t))", Some(1)),
            ("select(pi - 1, cos(v), cos(v + pi))", Some(1)),
            ("select(pi - 1, cos(2*v), 0)", Some(2)),
            // not recognised: not periodic, not a polynomial in cos and sin, or unknown
            ("v", None),
            ("cos(0.5*v)", None),
            ("cos(r*v)", Some(2)), // r = 2 is bound: a number
            ("cos(1.5*v)", None),
            ("cos(t*v)", None),
            ("exp(sin(v))", None),
            ("1/cos(v)", None),
            ("cos(v)^0.5", None),
            ("select(v - 1, cos(v), 0)", None),
        ];
        for (src, want) in cases {
            assert_eq!(deg(src), want, "{src}");
        }
    }

    /// The degree is an upper bound that holds: the expression sampled at 4d + 3 points
    /// has its discrete Fourier coefficients above d at round-off.
    #[test]
    fn a_recognised_expression_has_no_modes_above_its_degree() {
        for src in
            ["cos(v)^3*sin(2*v) + r*cos(5*v - 1)", "select(1, (1 + cos(v))^2, 0)*sin(v)", "cos(2*v)/3 - sin(v)*t"]
        {
            let e = Expr::parse(src).unwrap().bind(&["v", "t"], &|_| Some(2.0)).unwrap();
            let d = trig_degree(&e, 0).unwrap();
            let n = 4 * d + 3;
            let g: Vec<f64> = (0..n).map(|k| e.eval(&[std::f64::consts::TAU * k as f64 / n as f64, 0.7])).collect();
            let big = g.iter().fold(0.0f64, |a, x| crate::num::max_nan(a, x.abs()));
            for m in d + 1..=n / 2 {
                let (mut c, mut s) = (0.0, 0.0);
                for (k, x) in g.iter().enumerate() {
                    let th = std::f64::consts::TAU * (m * k) as f64 / n as f64;
                    c += x * th.cos();
                    s += x * th.sin();
                }
                // a sum of n terms of size ≤ big: n ulps
                assert!(c.hypot(s) <= 1e-13 * big * n as f64, "{src}: mode {m} is {}", c.hypot(s));
            }
        }
    }
}
