//! Evaluation in `f64` and in exact Taylor arithmetic.

use super::{BinOp, Expr, Func, Node};
use crate::jet::Jet;

pub(super) fn apply_f64(f: Func, a: &[f64]) -> f64 {
    match f {
        Func::Sin => a[0].sin(),
        Func::Cos => a[0].cos(),
        Func::Tan => a[0].tan(),
        Func::Sinh => a[0].sinh(),
        Func::Cosh => a[0].cosh(),
        Func::Tanh => a[0].tanh(),
        Func::Exp => a[0].exp(),
        Func::Ln => a[0].ln(),
        Func::Sqrt => a[0].sqrt(),
        Func::Abs => a[0].abs(),
        Func::Atan => a[0].atan(),
        Func::Pow => pow_f64(a[0], a[1]),
        Func::Atan2 => a[0].atan2(a[1]),
        Func::Min => {
            if a[1] < a[0] {
                a[1]
            } else {
                a[0]
            }
        }
        Func::Max => {
            if a[1] > a[0] {
                a[1]
            } else {
                a[0]
            }
        }
        Func::Select => {
            if a[0] > 0.0 {
                a[1]
            } else {
                a[2]
            }
        }
    }
}

pub(super) fn pow_f64(x: f64, y: f64) -> f64 {
    if y == y.round() && y.abs() <= 64.0 { x.powi(y as i32) } else { x.powf(y) }
}

pub(super) fn apply_jet(f: Func, a: &[Jet]) -> Jet {
    match f {
        Func::Sin => a[0].sin(),
        Func::Cos => a[0].cos(),
        Func::Tan => a[0].tan(),
        Func::Sinh => a[0].sinh(),
        Func::Cosh => a[0].cosh(),
        Func::Tanh => a[0].tanh(),
        Func::Exp => a[0].exp(),
        Func::Ln => a[0].ln(),
        Func::Sqrt => a[0].sqrt(),
        Func::Abs => a[0].abs(),
        Func::Atan => Jet::atan2(&a[0], &Jet::constant(a[0].shape(), 1.0)),
        Func::Pow => a[0].pow(&a[1]),
        Func::Atan2 => Jet::atan2(&a[0], &a[1]),
        Func::Min => a[0].min(&a[1]),
        Func::Max => a[0].max(&a[1]),
        Func::Select => {
            if a[0].value() > 0.0 {
                a[1].clone()
            } else {
                a[2].clone()
            }
        }
    }
}

impl Expr {
    /// Evaluates a bound expression at the variable values `vars` (slot order of
    /// [`Expr::bind`]). Panics on an unbound identifier, which `bind` rules out.
    pub fn eval(&self, vars: &[f64]) -> f64 {
        match &self.node {
            Node::Num(x) => *x,
            Node::Var(i) => vars[*i],
            Node::Neg(a) => -a.eval(vars),
            Node::Bin(op, a, b) => {
                let (x, y) = (a.eval(vars), b.eval(vars));
                match op {
                    BinOp::Add => x + y,
                    BinOp::Sub => x - y,
                    BinOp::Mul => x * y,
                    BinOp::Div => x / y,
                    BinOp::Pow => pow_f64(x, y),
                }
            }
            Node::Call(f, args) => match args.len() {
                1 => apply_f64(*f, &[args[0].eval(vars)]),
                2 => apply_f64(*f, &[args[0].eval(vars), args[1].eval(vars)]),
                _ => apply_f64(*f, &[args[0].eval(vars), args[1].eval(vars), args[2].eval(vars)]),
            },
            Node::Ident(n) => panic!("unbound identifier `{n}` evaluated"),
        }
    }

    /// Evaluates a bound expression on jets: `vars[i]` is the jet of variable slot `i`
    /// (usually [`Jet::variable`]); the result holds every partial derivative exactly.
    pub fn eval_jet(&self, vars: &[Jet]) -> Jet {
        let shape = vars.first().map(|j| j.shape()).unwrap_or(crate::jet::JetShape::scalar());
        match &self.node {
            Node::Num(x) => Jet::constant(shape, *x),
            Node::Var(i) => vars[*i].clone(),
            Node::Neg(a) => a.eval_jet(vars).neg(),
            Node::Bin(op, a, b) => {
                // Constant operands avoid a full jet product.
                match (op, a.as_constant(), b.as_constant()) {
                    (BinOp::Mul, Some(c), _) => return b.eval_jet(vars).scale(c),
                    (BinOp::Mul, _, Some(c)) => return a.eval_jet(vars).scale(c),
                    (BinOp::Div, _, Some(c)) => return a.eval_jet(vars).scale(1.0 / c),
                    (BinOp::Pow, _, Some(c)) => return a.eval_jet(vars).powf(c),
                    _ => {}
                }
                let (x, y) = (a.eval_jet(vars), b.eval_jet(vars));
                match op {
                    BinOp::Add => x.add(&y),
                    BinOp::Sub => x.sub(&y),
                    BinOp::Mul => x.mul(&y),
                    BinOp::Div => x.div(&y),
                    BinOp::Pow => x.pow(&y),
                }
            }
            Node::Call(f, args) => {
                let a: Vec<Jet> = args.iter().map(|a| a.eval_jet(vars)).collect();
                apply_jet(*f, &a)
            }
            Node::Ident(n) => panic!("unbound identifier `{n}` evaluated"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::JetShape;

    #[test]
    fn jets_match_f64_and_known_derivatives() {
        let e = Expr::parse("(1 - t)*(b1*sinh(a1*v + a2) + b2*sin(a3*v)) + b3*t*cos(-v)")
            .unwrap()
            .bind(&["v", "t"], &|p| match p {
                "a1" => Some(0.5),
                "a2" => Some(0.1),
                "a3" => Some(2.0),
                "b1" => Some(1.5),
                "b2" => Some(-0.7),
                "b3" => Some(0.3),
                _ => None,
            })
            .unwrap();
        let (v, t) = (0.9, 0.4);
        let shape = JetShape::new(&[6, 2]);
        let j = e.eval_jet(&[Jet::variable(shape, 0, v), Jet::variable(shape, 1, t)]);
        assert!((j.value() - e.eval(&[v, t])).abs() < 1e-14);
        // ∂v⁴∂t: -(b1 a1⁴ sinh(a1 v + a2) + b2 a3⁴ sin(a3 v)) + b3 cos(v)
        let expect = -(1.5 * 0.5f64.powi(4) * (0.5 * v + 0.1).sinh() + (-0.7) * 16.0 * (2.0 * v).sin()) + 0.3 * v.cos();
        assert!((j.derivative([4, 1, 0]) - expect).abs() < 1e-12, "{} vs {}", j.derivative([4, 1, 0]), expect);
        // ∂t² = 0
        assert!(j.derivative([3, 2, 0]).abs() < 1e-12);
    }
}
