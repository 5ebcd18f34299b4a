//! Expressions compiled to a flat instruction tape.
//!
//! A bound [`Expr`] (or several, sharing their common parts) is compiled once into a list
//! of instructions in static single assignment form: instruction `i` writes register `i`
//! and reads only earlier registers. Identical sub-expressions are compiled once (hash
//! consing), so `4*(1 - cos(s)/2)` written in three components of a field costs one
//! evaluation. The tape is evaluated over any [`TapeNum`]: plain `f64` (bit for bit the
//! same operations as [`Expr::eval`]), fixed-length univariate Taylor series
//! ([`Taylor`], no allocation) and multivariate [`Jet`]s (every mixed partial).
//!
//! ```
//! use pdeshape_core::expr::{Expr, Tape};
//! use pdeshape_core::taylor::Taylor;
//! let e = Expr::parse("sin(2*v) + v^2").unwrap().bind(&["v"], &|_| None).unwrap();
//! let tape = Tape::compile(&[&e]);
//! let mut regs = Vec::new();
//! assert_eq!(tape.eval(&[0.3], &0.0, &mut regs)[0], e.eval(&[0.3]));
//! let d = tape.eval(&[Taylor::<3>::variable(0.3)], &Taylor::constant(0.0), &mut Vec::new())[0];
//! assert!((d.derivative(2) - (-4.0 * 0.6f64.sin() + 2.0)).abs() < 1e-14);
//! ```

use super::eval::pow_f64;
use super::{BinOp, Expr, Func, Node};
use crate::jet::Jet;
use crate::taylor::Taylor;
use std::collections::HashMap;

/// One instruction; operands are registers (indices of earlier instructions).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Op {
    Num(f64),
    Var(u32),
    Neg(u32),
    Bin(BinOp, u32, u32),
    /// `a · c` for a number `c` known when compiling.
    MulC(u32, f64),
    /// `a / c` for a number `c` known when compiling.
    DivC(u32, f64),
    /// `aᶜ` for a number `c` known when compiling.
    PowC(u32, f64),
    Call1(Func, u32),
    Call2(Func, u32, u32),
    Select(u32, u32, u32),
}

impl Op {
    /// A hashable key: the variant, its operands and the bits of its number.
    fn key(&self) -> (u8, u8, [u32; 3], u64) {
        let bop = |b: BinOp| b as u8;
        let fc = |f: Func| f as u8;
        match *self {
            Op::Num(x) => (0, 0, [0; 3], x.to_bits()),
            Op::Var(i) => (1, 0, [i, 0, 0], 0),
            Op::Neg(a) => (2, 0, [a, 0, 0], 0),
            Op::Bin(o, a, b) => (3, bop(o), [a, b, 0], 0),
            Op::MulC(a, c) => (4, 0, [a, 0, 0], c.to_bits()),
            Op::DivC(a, c) => (5, 0, [a, 0, 0], c.to_bits()),
            Op::PowC(a, c) => (6, 0, [a, 0, 0], c.to_bits()),
            Op::Call1(f, a) => (7, fc(f), [a, 0, 0], 0),
            Op::Call2(f, a, b) => (8, fc(f), [a, b, 0], 0),
            Op::Select(x, a, b) => (9, 0, [x, a, b], 0),
        }
    }
}

/// A compiled list of bound expressions (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Tape {
    ops: Vec<Op>,
    outputs: Vec<u32>,
    vars: usize,
}

/// The arithmetic a tape needs from its number type.
pub trait TapeNum: Clone {
    /// The constant `x`, shaped like `like` (jets carry their truncation).
    fn constant(like: &Self, x: f64) -> Self;
    /// The value (the zeroth coefficient), which decides `select`, `abs`, `min`, `max`.
    fn value(&self) -> f64;
    /// `−a`
    fn neg(&self) -> Self;
    /// `a ∘ b`
    fn bin(&self, op: BinOp, b: &Self) -> Self;
    /// `a · c`
    fn mul_c(&self, c: f64) -> Self;
    /// `a / c`
    fn div_c(&self, c: f64) -> Self;
    /// `aᶜ`
    fn pow_c(&self, c: f64) -> Self;
    /// A function of one argument.
    fn call1(&self, f: Func) -> Self;
    /// A function of two arguments (`pow`, `atan2`, `min`, `max`).
    fn call2(&self, f: Func, b: &Self) -> Self;
}

impl Tape {
    /// Compiles bound expressions (all in the same variable slots) into one tape with one
    /// output per expression.
    pub fn compile(exprs: &[&Expr]) -> Tape {
        let mut c = Compiler { tape: Tape { ops: Vec::new(), outputs: Vec::new(), vars: 0 }, seen: HashMap::new() };
        for e in exprs {
            let r = c.node(e);
            c.tape.outputs.push(r);
        }
        c.tape.without_dead_code()
    }

    /// The tape without the instructions no output reads (the branches a constant
    /// `select` dropped, the operands of folded constants), registers renumbered in order.
    fn without_dead_code(self) -> Tape {
        let mut live = vec![false; self.ops.len()];
        for &o in &self.outputs {
            live[o as usize] = true;
        }
        for i in (0..self.ops.len()).rev() {
            if !live[i] {
                continue;
            }
            let mut mark = |r: u32| live[r as usize] = true;
            match self.ops[i] {
                Op::Num(_) | Op::Var(_) => {}
                Op::Neg(a) | Op::MulC(a, _) | Op::DivC(a, _) | Op::PowC(a, _) | Op::Call1(_, a) => mark(a),
                Op::Bin(_, a, b) | Op::Call2(_, a, b) => {
                    mark(a);
                    mark(b)
                }
                Op::Select(x, a, b) => {
                    mark(x);
                    mark(a);
                    mark(b)
                }
            }
        }
        let mut new = vec![u32::MAX; self.ops.len()];
        let mut ops = Vec::with_capacity(self.ops.len());
        for (i, op) in self.ops.iter().enumerate().filter(|(i, _)| live[*i]) {
            let m = |r: u32| new[r as usize];
            ops.push(match *op {
                Op::Num(x) => Op::Num(x),
                Op::Var(v) => Op::Var(v),
                Op::Neg(a) => Op::Neg(m(a)),
                Op::Bin(o, a, b) => Op::Bin(o, m(a), m(b)),
                Op::MulC(a, c) => Op::MulC(m(a), c),
                Op::DivC(a, c) => Op::DivC(m(a), c),
                Op::PowC(a, c) => Op::PowC(m(a), c),
                Op::Call1(f, a) => Op::Call1(f, m(a)),
                Op::Call2(f, a, b) => Op::Call2(f, m(a), m(b)),
                Op::Select(x, a, b) => Op::Select(m(x), m(a), m(b)),
            });
            new[i] = (ops.len() - 1) as u32;
        }
        let outputs = self.outputs.iter().map(|&o| new[o as usize]).collect();
        Tape { ops, outputs, vars: self.vars }
    }

    /// Number of instructions.
    pub fn len(&self) -> usize {
        self.ops.len()
    }

    /// True when the tape has no instructions.
    pub fn is_empty(&self) -> bool {
        self.ops.is_empty()
    }

    /// One more than the highest variable slot read.
    pub fn vars(&self) -> usize {
        self.vars
    }

    /// Evaluates the tape at `vars` (slot order of [`Expr::bind`]; at least
    /// [`vars()`](Self::vars) of them), with `like` shaping constants; `regs` is scratch
    /// space, reused across calls. Returns one value per compiled expression.
    pub fn eval<'r, T: TapeNum>(&self, vars: &[T], like: &T, regs: &'r mut Vec<T>) -> OutputIter<'r, '_, T> {
        assert!(vars.len() >= self.vars, "the tape reads {} variables, {} given", self.vars, vars.len());
        regs.clear();
        regs.reserve(self.ops.len());
        for op in &self.ops {
            let r = |i: u32| &regs[i as usize];
            let x = match *op {
                Op::Num(x) => T::constant(like, x),
                Op::Var(i) => vars[i as usize].clone(),
                Op::Neg(a) => r(a).neg(),
                Op::Bin(o, a, b) => r(a).bin(o, r(b)),
                Op::MulC(a, c) => r(a).mul_c(c),
                Op::DivC(a, c) => r(a).div_c(c),
                Op::PowC(a, c) => r(a).pow_c(c),
                Op::Call1(f, a) => r(a).call1(f),
                Op::Call2(f, a, b) => r(a).call2(f, r(b)),
                Op::Select(x, a, b) => {
                    if r(x).value() > 0.0 {
                        r(a).clone()
                    } else {
                        r(b).clone()
                    }
                }
            };
            regs.push(x);
        }
        OutputIter { regs, outputs: self.outputs.iter() }
    }
}

/// The values of a tape's outputs, in compile order (indexable).
pub struct OutputIter<'r, 't, T> {
    regs: &'r [T],
    outputs: std::slice::Iter<'t, u32>,
}

impl<T> std::ops::Index<usize> for OutputIter<'_, '_, T> {
    type Output = T;
    fn index(&self, i: usize) -> &T {
        &self.regs[self.outputs.as_slice()[i] as usize]
    }
}

impl<'r, T> Iterator for OutputIter<'r, '_, T> {
    type Item = &'r T;
    fn next(&mut self) -> Option<&'r T> {
        self.outputs.next().map(|&i| &self.regs[i as usize])
    }
}

struct Compiler {
    tape: Tape,
    seen: HashMap<(u8, u8, [u32; 3], u64), u32>,
}

impl Compiler {
    fn push(&mut self, op: Op) -> u32 {
        *self.seen.entry(op.key()).or_insert_with(|| {
            self.tape.ops.push(op);
            (self.tape.ops.len() - 1) as u32
        })
    }

    /// The number register `r` holds when it is a constant.
    fn constant(&self, r: u32) -> Option<f64> {
        match self.tape.ops[r as usize] {
            Op::Num(x) => Some(x),
            _ => None,
        }
    }

    /// `op` evaluated now when every operand is a constant: the same `f64` operation the
    /// tape would run (so `f64` results do not change), its derivatives zero. `None` when
    /// an operand varies (`select` is decided elsewhere).
    fn fold(&self, op: &Op) -> Option<f64> {
        let c = |r: u32| self.constant(r);
        Some(match *op {
            Op::Neg(a) => c(a)?.neg(),
            Op::Bin(o, a, b) => c(a)?.bin(o, &c(b)?),
            Op::MulC(a, k) => c(a)?.mul_c(k),
            Op::DivC(a, k) => c(a)?.div_c(k),
            Op::PowC(a, k) => c(a)?.pow_c(k),
            Op::Call1(f, a) => c(a)?.call1(f),
            Op::Call2(f, a, b) => c(a)?.call2(f, &c(b)?),
            Op::Num(_) | Op::Var(_) | Op::Select(..) => return None,
        })
    }

    fn node(&mut self, e: &Expr) -> u32 {
        let op = self.op(e);
        // a `select` whose condition is a constant is the branch it picks; other
        // operations on constants are constants (`4*(1 - cos(s)/2)` for a section's bound
        // `s` costs nothing per point)
        if let Op::Select(x, a, b) = op
            && let Some(v) = self.constant(x)
        {
            return if v > 0.0 { a } else { b };
        }
        match self.fold(&op) {
            Some(v) => self.push(Op::Num(v)),
            None => self.push(op),
        }
    }

    fn op(&mut self, e: &Expr) -> Op {
        match &e.node {
            Node::Num(x) => Op::Num(*x),
            Node::Var(i) => {
                self.tape.vars = self.tape.vars.max(i + 1);
                Op::Var(*i as u32)
            }
            Node::Neg(a) => Op::Neg(self.node(a)),
            Node::Bin(op, a, b) => match (op, a.as_constant(), b.as_constant()) {
                // The same special cases as the jet interpreter; in f64 they are the same
                // operation (`c·x = x·c`, `x/c`, `pow(x, c)`).
                (BinOp::Mul, Some(c), None) => Op::MulC(self.node(b), c),
                (BinOp::Mul, None, Some(c)) => Op::MulC(self.node(a), c),
                (BinOp::Div, None, Some(c)) => Op::DivC(self.node(a), c),
                (BinOp::Pow, None, Some(c)) => Op::PowC(self.node(a), c),
                _ => {
                    let (x, y) = (self.node(a), self.node(b));
                    Op::Bin(*op, x, y)
                }
            },
            Node::Call(f, args) => {
                let r: Vec<u32> = args.iter().map(|a| self.node(a)).collect();
                match r.len() {
                    1 => Op::Call1(*f, r[0]),
                    2 => Op::Call2(*f, r[0], r[1]),
                    _ => Op::Select(r[0], r[1], r[2]),
                }
            }
            Node::Ident(n) => panic!("unbound identifier `{n}` compiled"),
        }
    }
}

impl TapeNum for f64 {
    fn constant(_: &Self, x: f64) -> Self {
        x
    }
    fn value(&self) -> f64 {
        *self
    }
    fn neg(&self) -> Self {
        -self
    }
    fn bin(&self, op: BinOp, b: &Self) -> Self {
        match op {
            BinOp::Add => self + b,
            BinOp::Sub => self - b,
            BinOp::Mul => self * b,
            BinOp::Div => self / b,
            BinOp::Pow => pow_f64(*self, *b),
        }
    }
    fn mul_c(&self, c: f64) -> Self {
        self * c
    }
    fn div_c(&self, c: f64) -> Self {
        self / c
    }
    fn pow_c(&self, c: f64) -> Self {
        pow_f64(*self, c)
    }
    fn call1(&self, f: Func) -> Self {
        super::eval::apply_f64(f, &[*self])
    }
    fn call2(&self, f: Func, b: &Self) -> Self {
        super::eval::apply_f64(f, &[*self, *b])
    }
}

impl<const N: usize> TapeNum for Taylor<N> {
    fn constant(_: &Self, x: f64) -> Self {
        Taylor::constant(x)
    }
    fn value(&self) -> f64 {
        self.0[0]
    }
    fn neg(&self) -> Self {
        Taylor::neg(self)
    }
    fn bin(&self, op: BinOp, b: &Self) -> Self {
        match op {
            BinOp::Add => self.add(b),
            BinOp::Sub => self.sub(b),
            BinOp::Mul => self.mul(b),
            BinOp::Div => self.div(b),
            BinOp::Pow => self.pow(b),
        }
    }
    fn mul_c(&self, c: f64) -> Self {
        self.scale(c)
    }
    fn div_c(&self, c: f64) -> Self {
        self.div_scalar(c)
    }
    fn pow_c(&self, c: f64) -> Self {
        self.powf(c)
    }
    fn call1(&self, f: Func) -> Self {
        match f {
            Func::Sin => self.sin_cos().0,
            Func::Cos => self.sin_cos().1,
            Func::Tan => {
                let (s, c) = self.sin_cos();
                s.div(&c)
            }
            Func::Sinh => self.sinh_cosh().0,
            Func::Cosh => self.sinh_cosh().1,
            Func::Tanh => {
                let (s, c) = self.sinh_cosh();
                s.div(&c)
            }
            Func::Exp => self.exp(),
            Func::Ln => self.ln(),
            Func::Sqrt => self.sqrt(),
            Func::Abs => self.abs(),
            Func::Atan => Taylor::atan2(self, &Taylor::constant(1.0)),
            // two- and three-argument functions never reach here (the compiler routes them)
            Func::Pow | Func::Atan2 | Func::Min | Func::Max | Func::Select => Taylor::constant(f64::NAN),
        }
    }
    fn call2(&self, f: Func, b: &Self) -> Self {
        match f {
            Func::Pow => self.pow(b),
            Func::Atan2 => Taylor::atan2(self, b),
            Func::Min => {
                if b.0[0] < self.0[0] {
                    *b
                } else {
                    *self
                }
            }
            Func::Max => {
                if b.0[0] > self.0[0] {
                    *b
                } else {
                    *self
                }
            }
            _ => Taylor::constant(f64::NAN),
        }
    }
}

impl TapeNum for Jet {
    fn constant(like: &Self, x: f64) -> Self {
        Jet::constant(like.shape(), x)
    }
    fn value(&self) -> f64 {
        Jet::value(self)
    }
    fn neg(&self) -> Self {
        Jet::neg(self)
    }
    fn bin(&self, op: BinOp, b: &Self) -> Self {
        match op {
            BinOp::Add => self.add(b),
            BinOp::Sub => self.sub(b),
            BinOp::Mul => self.mul(b),
            BinOp::Div => self.div(b),
            BinOp::Pow => self.pow(b),
        }
    }
    fn mul_c(&self, c: f64) -> Self {
        self.scale(c)
    }
    fn div_c(&self, c: f64) -> Self {
        self.scale(1.0 / c)
    }
    fn pow_c(&self, c: f64) -> Self {
        self.powf(c)
    }
    fn call1(&self, f: Func) -> Self {
        super::eval::apply_jet(f, std::slice::from_ref(self))
    }
    fn call2(&self, f: Func, b: &Self) -> Self {
        super::eval::apply_jet(f, &[self.clone(), b.clone()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jet::JetShape;
    use proptest::prelude::*;

    const VARS: [&str; 2] = ["v", "t"];

    /// Operations on constants are done when compiling, a `select` on a constant keeps
    /// only its branch, and nothing dead stays: the Klein bottle's section at a bound `s`
    /// keeps `cos(v)` and `cos(v + π)` behind a constant factor — and the values are those
    /// of the expression, bit for bit, values and derivatives.
    #[test]
    fn constants_are_folded_and_dead_branches_dropped() {
        let src = "1.3*cos(s)*(1 + sin(s)) + 4*(1 - cos(s)/2)*select(pi - s, cos(s)*cos(v), cos(v + pi))";
        // s < π: [c₀, v, cos v, ·cos s, ·c₁, +]; s > π: [c₀, v, π, v + π, cos, ·c₁, +]
        for (s, ops) in [(0.5, 6), (4.0, 7)] {
            let e = Expr::parse(src).unwrap().bind(&VARS, &|p| (p == "s").then_some(s)).unwrap();
            let tape = Tape::compile(&[&e]);
            // no trig of s, no other branch
            let trig = tape.ops.iter().filter(|o| matches!(o, Op::Call1(..))).count();
            assert_eq!(trig, 1, "s = {s}: {:?}", tape.ops);
            assert_eq!(tape.len(), ops, "s = {s}: {:?}", tape.ops);
            let mut regs = Vec::new();
            for k in 0..50 {
                let v = -3.0 + 0.13 * k as f64;
                assert_eq!(tape.eval(&[v, 0.0], &0.0, &mut regs)[0].to_bits(), e.eval(&[v, 0.0]).to_bits());
                // the derivative against the hand-derived one (s < π: c₁ cos(s) cos v,
                // s > π: c₁ cos(v + π); c₁ = 4(1 − cos(s)/2))
                let d = tape.eval(
                    &[Taylor::<2>::variable(v), Taylor::constant(0.0)],
                    &Taylor::constant(0.0),
                    &mut Vec::new(),
                )[0]
                .derivative(1);
                let c1 = 4.0 * (1.0 - s.cos() / 2.0);
                let want = if s < std::f64::consts::PI {
                    -c1 * s.cos() * v.sin()
                } else {
                    -c1 * (v + std::f64::consts::PI).sin()
                };
                assert!((d - want).abs() < 1e-14, "s = {s}, v = {v}: {d} vs {want}");
            }
        }
    }

    fn bound(src: &str) -> Expr {
        Expr::parse(src).unwrap().bind(&VARS, &|p| (p == "a").then_some(1.7)).unwrap()
    }

    /// Random expressions in `v`, `t` and the parameter `a` over every operator and
    /// function, with arguments kept where each function is smooth.
    fn expr_src() -> impl Strategy<Value = String> {
        let leaf = prop_oneof![
            Just("v".to_string()),
            Just("t".to_string()),
            Just("a".to_string()),
            (-3.0f64..3.0).prop_map(|x| format!("{x:.3}")),
        ];
        leaf.prop_recursive(5, 40, 3, |inner| {
            prop_oneof![
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} + {b})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} - {b})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} * {b})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("({a} / (2 + sin({b})))")),
                inner.clone().prop_map(|a| format!("(-{a})")),
                inner.clone().prop_map(|a| format!("({a})^2")),
                inner.clone().prop_map(|a| format!("sqrt(1.5 + cos({a}))")),
                inner.clone().prop_map(|a| format!("(2 + sin({a}))^1.5")),
                inner.clone().prop_map(|a| format!("pow(2 + sin({a}), v)")),
                inner.clone().prop_map(|a| format!("ln(2 + cos({a}))")),
                inner.clone().prop_map(|a| format!("exp(sin({a}))")),
                inner.clone().prop_map(|a| format!("tan(0.5*sin({a}))")),
                inner.clone().prop_map(|a| format!("sinh(sin({a})) + cosh(cos({a})) + tanh({a})")),
                inner.clone().prop_map(|a| format!("atan({a})")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("atan2(2 + sin({a}), 2 + cos({b}))")),
                (inner.clone(), inner.clone()).prop_map(|(a, b)| format!("min({a}, {b}) + max({a}, {b})")),
                (inner.clone(), inner.clone(), inner.clone())
                    .prop_map(|(x, a, b)| format!("select({x}, {a}, {b}) + abs({x})")),
            ]
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

        /// The tape in f64 is the tree interpreter bit for bit; in Taylor series it gives the
        /// jet interpreter's v-derivatives; in jets, the same mixed partials.
        #[test]
        fn tape_agrees_with_the_interpreters(src in expr_src(), v in -2.0f64..2.0, t in -2.0f64..2.0) {
            let e = bound(&src);
            let tape = Tape::compile(&[&e, &e]);
            let want = e.eval(&[v, t]);
            let got = tape.eval(&[v, t], &0.0, &mut Vec::new())[1];
            prop_assert!(got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()), "{got} vs {want}");

            let shape = JetShape::new(&[3, 2]);
            let jv = [Jet::variable(shape, 0, v), Jet::variable(shape, 1, t)];
            let tree = e.eval_jet(&jv);
            let taped = tape.eval(&jv, &jv[0], &mut Vec::new())[0].clone();
            let tv = [Taylor::<4>::variable(v), Taylor::constant(t)];
            let taylor = tape.eval(&tv, &tv[0], &mut Vec::new())[0];
            for m in shape.multi_indices() {
                let w = tree.derivative(m);
                // Same operations in the same order, except the hash-consed sharing: equal
                // to round-off of the size of the derivative.
                let tol = 1e-12 * w.abs().max(1.0);
                prop_assert!((taped.derivative(m) - w).abs() <= tol || !w.is_finite(), "jet {m:?}: {} vs {w}", taped.derivative(m));
                if m[1] == 0 {
                    // independent recurrences vs composition with Taylor polynomials
                    let g = taylor.derivative(m[0]);
                    prop_assert!((g - w).abs() <= 1e-10 * w.abs().max(1.0) || !w.is_finite(), "taylor {m:?}: {g} vs {w}");
                }
            }
        }
    }

    #[test]
    fn shared_subexpressions_compile_once() {
        let a = bound("4*(1 - cos(v)/2)*sin(t)");
        let b = bound("4*(1 - cos(v)/2)*cos(t)");
        let tape = Tape::compile(&[&a, &b]);
        // v, cos v, /2, 1, 1 − ·, 4·, t, sin t, ·, cos t, ·  → 11 instructions, not 16
        assert_eq!(tape.len(), 11, "{tape:?}");
        let mut regs = Vec::new();
        let out: Vec<f64> = tape.eval(&[0.4, 1.1], &0.0, &mut regs).copied().collect();
        assert_eq!(out, [a.eval(&[0.4, 1.1]), b.eval(&[0.4, 1.1])]);
    }
}
