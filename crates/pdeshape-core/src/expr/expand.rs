//! Algebraic expansion of an expression into a sum of (constant × product term).
//!
//! Used to extract the basis functions `F_j(v, t)` of dynamic blends (SPEC §5): an
//! expression is multiplied out over `+`, `−`, `·`, division by constants and small
//! non-negative integer powers; everything else (function calls, division by a
//! non-constant, other powers) is an opaque factor. Terms whose sorted factor lists print
//! the same are collected, so `(1 − t)·sin v + 2t·sin v` expands to `1·sin v + 1·t·sin v`.

use super::{BinOp, Expr, Node, Span};

/// One term `coef · Π factors` of an expanded expression.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    /// The numeric coefficient.
    pub coef: f64,
    /// The non-constant factors (empty for the constant term), sorted by their printed form.
    pub factors: Vec<Expr>,
}

impl Term {
    /// A canonical key: the printed factors joined by `*` (`"1"` for the constant term).
    pub fn key(&self) -> String {
        if self.factors.is_empty() {
            "1".into()
        } else {
            self.factors.iter().map(|f| f.to_string()).collect::<Vec<_>>().join("*")
        }
    }

    /// The product of the factors (without the coefficient) as an expression.
    pub fn product(&self) -> Expr {
        let mut it = self.factors.iter().cloned();
        let first = it.next().unwrap_or_else(|| Expr::num(1.0));
        it.fold(first, |acc, f| Expr {
            span: Span { start: 0, end: 0 },
            node: Node::Bin(BinOp::Mul, Box::new(acc), Box::new(f)),
        })
    }
}

/// Largest number of raw (uncollected) terms an expansion may produce: nested powers of
/// sums grow combinatorially, and past this size the expression is treated as opaque.
pub const MAX_TERMS: usize = 512;

/// Largest expression (in nodes) that is expanded at all: every term clones and prints its
/// factors, so the work grows with terms × size.
pub const MAX_NODES: usize = 2000;

/// The expansion outgrew [`MAX_TERMS`].
struct Overflow;

fn raw(e: &Expr) -> Result<Vec<Term>, Overflow> {
    match &e.node {
        Node::Num(c) => Ok(vec![Term { coef: *c, factors: vec![] }]),
        Node::Neg(a) => Ok(raw(a)?.into_iter().map(|t| Term { coef: -t.coef, ..t }).collect()),
        Node::Bin(BinOp::Add, a, b) => {
            let mut r = raw(a)?;
            r.extend(raw(b)?);
            if r.len() > MAX_TERMS { Err(Overflow) } else { Ok(r) }
        }
        Node::Bin(BinOp::Sub, a, b) => {
            let mut r = raw(a)?;
            r.extend(raw(b)?.into_iter().map(|t| Term { coef: -t.coef, ..t }));
            if r.len() > MAX_TERMS { Err(Overflow) } else { Ok(r) }
        }
        Node::Bin(BinOp::Mul, a, b) => product(&raw(a)?, &raw(b)?),
        Node::Bin(BinOp::Div, a, b) if b.as_constant().is_some() => {
            let c = b.as_constant().unwrap_or(1.0);
            Ok(raw(a)?.into_iter().map(|t| Term { coef: t.coef / c, ..t }).collect())
        }
        Node::Bin(BinOp::Pow, a, b) if matches!(b.as_constant(), Some(n) if n >= 0.0 && n == n.round() && n <= 8.0) => {
            let n = b.as_constant().unwrap_or(0.0) as usize;
            let base = raw(a)?;
            let mut acc = vec![Term { coef: 1.0, factors: vec![] }];
            for _ in 0..n {
                acc = product(&acc, &base)?;
            }
            Ok(acc)
        }
        _ => Ok(vec![Term { coef: 1.0, factors: vec![e.clone()] }]),
    }
}

fn product(a: &[Term], b: &[Term]) -> Result<Vec<Term>, Overflow> {
    if a.len() * b.len() > MAX_TERMS {
        return Err(Overflow);
    }
    let mut out = Vec::with_capacity(a.len() * b.len());
    for x in a {
        for y in b {
            let mut f = x.factors.clone();
            f.extend(y.factors.iter().cloned());
            out.push(Term { coef: x.coef * y.coef, factors: f });
        }
    }
    Ok(out)
}

/// Expands a (bound) expression into collected terms, in order of first appearance.
/// Terms whose coefficients cancel exactly are dropped. `None` when the expansion would
/// exceed [`MAX_TERMS`] raw terms (e.g. nested powers of sums) or the expression has more
/// than [`MAX_NODES`] nodes: callers then treat the
/// expression as one opaque function.
///
/// ```
/// use pdeshape_core::expr::{Expr, expand};
/// let e = Expr::parse("(1 - t)*(2*sin(v) + 3) + t*sin(v)").unwrap().bind(&["v", "t"], &|_| None).unwrap();
/// let terms = expand(&e).unwrap();
/// let keys: Vec<String> = terms.iter().map(|t| format!("{}:{}", t.coef, t.key())).collect();
/// assert_eq!(keys, ["2:sin(#0)", "3:1", "-1:#1*sin(#0)", "-3:#1"]);
/// ```
pub fn expand(e: &Expr) -> Option<Vec<Term>> {
    let mut nodes = 0usize;
    e.visit(&mut |_| nodes += 1);
    if nodes > MAX_NODES {
        return None;
    }
    let mut out: Vec<Term> = Vec::new();
    let mut index: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for mut t in raw(e).ok()? {
        t.factors.sort_by_key(|f| f.to_string());
        let k = t.key();
        match index.get(&k) {
            Some(&i) => out[i].coef += t.coef,
            None => {
                index.insert(k, out.len());
                out.push(t);
            }
        }
    }
    Some(out.into_iter().filter(|t| t.coef != 0.0).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expansion_reproduces_the_expression() {
        let src = "(1 - t)*(1.5*sinh(0.5*v + 0.1) + 2*sin(3*v))^2 / 4 - t*(v - 1)*cos(-v)";
        let e = Expr::parse(src).unwrap().bind(&["v", "t"], &|_| None).unwrap();
        let terms = expand(&e).unwrap();
        for &(v, t) in &[(0.3, 0.2), (-1.0, 0.7), (2.5, 0.0)] {
            let s: f64 = terms.iter().map(|tm| tm.coef * tm.product().eval(&[v, t])).sum();
            assert!((s - e.eval(&[v, t])).abs() < 1e-12);
        }
    }

    /// Found by fuzzing: nested powers of sums grow combinatorially; the expansion gives up
    /// instead of hanging.
    #[test]
    fn nested_powers_give_up_instead_of_exploding() {
        let src = "-u-(-(u)^8 + a-u-(u)^8 + u)^8 + a-u-(u)^8 + a";
        let e = Expr::parse(src).unwrap().bind(&["u"], &|n| (n == "a").then_some(1.5)).unwrap();
        assert!(expand(&e).is_none());
        let e = Expr::parse("(u + 1)^8").unwrap().bind(&["u"], &|_| None).unwrap();
        assert_eq!(expand(&e).unwrap().len(), 9);
        // and long expressions with many products are not expanded at all
        let long = include_str!("fuzz_regression_expand_long.txt").trim();
        let e = Expr::parse(long).unwrap().bind(&["u", "v", "t"], &|_| None).unwrap();
        assert!(expand(&e).is_none());
    }
}
