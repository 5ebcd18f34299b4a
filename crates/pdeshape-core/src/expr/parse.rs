//! Lexer, recursive-descent parser and name binding.

use super::{BinOp, Expr, Func, Node, Span};
use std::fmt;

/// A parse or name-resolution error with the position it refers to.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct ExprError {
    /// What went wrong.
    pub message: String,
    /// The source text.
    pub source_text: String,
    /// Where (byte range in `source_text`).
    pub span: Span,
}

impl ExprError {
    fn new(src: &str, span: Span, message: impl Into<String>) -> Self {
        ExprError { message: message.into(), source_text: src.to_string(), span }
    }

    /// Attaches the source text (name binding works on the tree, which does not keep it).
    pub fn with_source(mut self, src: &str) -> Self {
        self.source_text = src.to_string();
        self
    }

    /// A copy with the source text attached.
    pub fn with_source_ref(&self, src: &str) -> Self {
        self.clone().with_source(src)
    }

    /// The 1-based column (in characters) the error points at.
    pub fn column(&self) -> usize {
        self.source_text[..self.span.start.min(self.source_text.len())].chars().count() + 1
    }
}

/// Characters of the source an error shows around its column (a 1 MB expression is not
/// echoed whole).
const EXCERPT: usize = 100;

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let col = self.column();
        let chars: Vec<char> = self.source_text.chars().collect();
        let width = self.source_text
            [self.span.start.min(self.source_text.len())..self.span.end.min(self.source_text.len())]
            .chars()
            .count()
            .max(1);
        // a window of EXCERPT characters around the column, marked where it was cut
        let from = (col - 1).saturating_sub(EXCERPT / 2).min(chars.len().saturating_sub(EXCERPT));
        let to = (from + EXCERPT).min(chars.len());
        let mut excerpt: String = chars[from..to].iter().collect();
        let mut caret = col - 1 - from;
        if from > 0 {
            excerpt.insert(0, '…');
            caret += 1;
        }
        if to < chars.len() {
            excerpt.push('…');
        }
        let width = width.min(to.saturating_sub(col - 1).max(1));
        write!(f, "{} at column {}\n    {}\n    {}{}", self.message, col, excerpt, " ".repeat(caret), "^".repeat(width))
    }
}

#[derive(Clone, Debug, PartialEq)]
enum Tok {
    Num(f64),
    Ident(String),
    Op(char),
    End,
}

struct Lexer<'a> {
    src: &'a str,
    toks: Vec<(Tok, Span)>,
}

fn lex(src: &str) -> Result<Vec<(Tok, Span)>, ExprError> {
    let mut lx = Lexer { src, toks: Vec::new() };
    let b = src.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_digit() || (c == b'.' && i + 1 < b.len() && b[i + 1].is_ascii_digit()) {
            let start = i;
            while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                if j < b.len() && b[j].is_ascii_digit() {
                    while j < b.len() && b[j].is_ascii_digit() {
                        j += 1;
                    }
                    i = j;
                }
            }
            let text = &src[start..i];
            let span = Span { start, end: i };
            let x: f64 = text.parse().map_err(|_| ExprError::new(src, span, format!("malformed number `{text}`")))?;
            lx.toks.push((Tok::Num(x), span));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            lx.toks.push((Tok::Ident(src[start..i].to_string()), Span { start, end: i }));
        } else if b"+-*/^(),".contains(&c) {
            if c == b'*' && i + 1 < b.len() && b[i + 1] == b'*' {
                lx.toks.push((Tok::Op('^'), Span { start: i, end: i + 2 }));
                i += 2;
            } else {
                lx.toks.push((Tok::Op(c as char), Span { start: i, end: i + 1 }));
                i += 1;
            }
        } else {
            let ch = src[i..].chars().next().unwrap_or('?');
            return Err(ExprError::new(
                src,
                Span { start: i, end: i + ch.len_utf8() },
                format!("unexpected character `{ch}`"),
            ));
        }
    }
    lx.toks.push((Tok::End, Span { start: lx.src.len(), end: lx.src.len() }));
    Ok(lx.toks)
}

struct Parser<'a> {
    src: &'a str,
    toks: Vec<(Tok, Span)>,
    pos: usize,
    depth: usize,
}

/// Nesting limit of the parser's recursion (parentheses, unary signs, powers).
const MAX_DEPTH: usize = 200;

/// Limit on the depth of the expression *tree*. A chain `v+v+…+v` nests no parentheses but
/// is a tree as deep as it is long, and every later pass over the tree (binding, folding,
/// evaluation, expansion, even dropping it) recurses once per level; this keeps those
/// passes within a small stack whatever the input (a 1 MiB text could otherwise ask for a
/// tree 200 000 levels deep).
pub const MAX_TREE_DEPTH: usize = 500;

/// An expression with the depth of its tree.
type Sub = (Expr, usize);

impl<'a> Parser<'a> {
    fn peek(&self) -> &Tok {
        &self.toks[self.pos].0
    }
    fn span(&self) -> Span {
        self.toks[self.pos].1
    }
    fn next(&mut self) -> (Tok, Span) {
        let t = self.toks[self.pos].clone();
        if self.pos + 1 < self.toks.len() {
            self.pos += 1;
        }
        t
    }
    fn err(&self, msg: impl Into<String>) -> ExprError {
        ExprError::new(self.src, self.span(), msg)
    }
    fn describe(t: &Tok) -> String {
        match t {
            Tok::Num(x) => format!("number {x}"),
            Tok::Ident(n) => format!("`{n}`"),
            Tok::Op(c) => format!("`{c}`"),
            Tok::End => "end of input".into(),
        }
    }

    fn enter(&mut self) -> Result<(), ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(self.err(format!("expression nested deeper than {MAX_DEPTH} levels")));
        }
        Ok(())
    }

    /// A node over children of depths `depths`, refused past [`MAX_TREE_DEPTH`].
    fn node(&self, node: Node, span: Span, depth: usize) -> Result<Sub, ExprError> {
        if depth > MAX_TREE_DEPTH {
            return Err(ExprError::new(
                self.src,
                span,
                format!(
                    "expression too long or too deep: its tree would be more than {MAX_TREE_DEPTH} levels deep \
                     (split long sums into parameters, or use fewer terms)"
                ),
            ));
        }
        Ok((Expr { node, span }, depth))
    }

    fn bin(&self, op: BinOp, (a, da): Sub, (b, db): Sub) -> Result<Sub, ExprError> {
        let span = Span { start: a.span.start, end: b.span.end };
        self.node(Node::Bin(op, Box::new(a), Box::new(b)), span, 1 + da.max(db))
    }

    fn expr(&mut self) -> Result<Sub, ExprError> {
        self.enter()?;
        let mut lhs = self.term()?;
        while let Tok::Op(c @ ('+' | '-')) = *self.peek() {
            self.next();
            let rhs = self.term()?;
            let op = if c == '+' { BinOp::Add } else { BinOp::Sub };
            lhs = self.bin(op, lhs, rhs)?;
        }
        self.depth -= 1;
        Ok(lhs)
    }

    fn term(&mut self) -> Result<Sub, ExprError> {
        let mut lhs = self.unary()?;
        while let Tok::Op(c @ ('*' | '/')) = *self.peek() {
            self.next();
            let rhs = self.unary()?;
            let op = if c == '*' { BinOp::Mul } else { BinOp::Div };
            lhs = self.bin(op, lhs, rhs)?;
        }
        Ok(lhs)
    }

    fn unary(&mut self) -> Result<Sub, ExprError> {
        self.enter()?;
        let r = match *self.peek() {
            Tok::Op('-') => {
                let (_, s) = self.next();
                let (a, d) = self.unary()?;
                let span = Span { start: s.start, end: a.span.end };
                self.node(Node::Neg(Box::new(a)), span, d + 1)
            }
            Tok::Op('+') => {
                self.next();
                self.unary()
            }
            _ => self.power(),
        };
        self.depth -= 1;
        r
    }

    fn power(&mut self) -> Result<Sub, ExprError> {
        let base = self.primary()?;
        if let Tok::Op('^') = self.peek() {
            self.next();
            let exp = self.unary()?;
            return self.bin(BinOp::Pow, base, exp);
        }
        Ok(base)
    }

    fn primary(&mut self) -> Result<Sub, ExprError> {
        let (tok, span) = self.next();
        match tok {
            Tok::Num(x) => Ok((Expr { node: Node::Num(x), span }, 1)),
            Tok::Ident(name) => {
                if let Tok::Op('(') = self.peek() {
                    let func = Func::from_name(&name).ok_or_else(|| {
                        ExprError::new(
                            self.src,
                            span,
                            format!(
                                "unknown function `{name}` (known: {})",
                                Func::ALL.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(" ")
                            ),
                        )
                    })?;
                    self.next();
                    let mut args = Vec::new();
                    let mut depth = 0;
                    if !matches!(self.peek(), Tok::Op(')')) {
                        loop {
                            let (a, d) = self.expr()?;
                            args.push(a);
                            depth = depth.max(d);
                            match self.peek() {
                                Tok::Op(',') => {
                                    self.next();
                                }
                                Tok::Op(')') => break,
                                t => {
                                    return Err(self.err(format!(
                                        "expected `,` or `)` in the arguments of `{name}`, found {}",
                                        Self::describe(t)
                                    )));
                                }
                            }
                        }
                    }
                    let (_, close) = self.next();
                    let full = Span { start: span.start, end: close.end };
                    if args.len() != func.arity() {
                        return Err(ExprError::new(
                            self.src,
                            full,
                            format!(
                                "`{name}` takes {} argument{}, got {}",
                                func.arity(),
                                if func.arity() == 1 { "" } else { "s" },
                                args.len()
                            ),
                        ));
                    }
                    self.node(Node::Call(func, args), full, depth + 1)
                } else {
                    Ok((Expr { node: Node::Ident(name), span }, 1))
                }
            }
            Tok::Op('(') => {
                let (inner, d) = self.expr()?;
                match self.peek() {
                    Tok::Op(')') => {
                        let (_, close) = self.next();
                        Ok((Expr { node: inner.node, span: Span { start: span.start, end: close.end } }, d))
                    }
                    t => Err(self.err(format!("expected `)`, found {}", Self::describe(t)))),
                }
            }
            t => Err(ExprError::new(
                self.src,
                span,
                format!("expected a number, a name or `(`, found {}", Self::describe(&t)),
            )),
        }
    }
}

pub(super) fn parse(src: &str) -> Result<Expr, ExprError> {
    if src.trim().is_empty() {
        return Err(ExprError::new(src, Span { start: 0, end: 0 }, "empty expression"));
    }
    let toks = lex(src)?;
    let mut p = Parser { src, toks, pos: 0, depth: 0 };
    let (e, _) = p.expr()?;
    if !matches!(p.peek(), Tok::End) {
        let t = p.peek().clone();
        return Err(p.err(format!("unexpected {} after a complete expression", Parser::describe(&t))));
    }
    Ok(e)
}

/// Evaluates a constant-only operation for folding.
fn fold(e: &Expr) -> Option<f64> {
    match &e.node {
        Node::Num(x) => Some(*x),
        Node::Neg(a) => fold(a).map(|x| -x),
        Node::Bin(op, a, b) => {
            let (x, y) = (fold(a)?, fold(b)?);
            Some(match op {
                BinOp::Add => x + y,
                BinOp::Sub => x - y,
                BinOp::Mul => x * y,
                BinOp::Div => x / y,
                BinOp::Pow => x.powf(y),
            })
        }
        Node::Call(f, args) => {
            let v: Option<Vec<f64>> = args.iter().map(fold).collect();
            Some(super::eval::apply_f64(*f, &v?))
        }
        _ => None,
    }
}

pub(super) fn bind(e: &Expr, vars: &[&str], param: &dyn Fn(&str) -> Option<f64>) -> Result<Expr, ExprError> {
    // The source text is not kept in the tree; errors rebuild it from spans when the caller
    // re-parses. Here we report the name and rely on the span for the column.
    fn go(e: &Expr, vars: &[&str], param: &dyn Fn(&str) -> Option<f64>) -> Result<Expr, (Span, String)> {
        let node = match &e.node {
            Node::Ident(name) => {
                if let Some(i) = vars.iter().position(|v| v == name) {
                    Node::Var(i)
                } else if let Some(x) = param(name) {
                    Node::Num(x)
                } else if name == "pi" {
                    Node::Num(std::f64::consts::PI)
                } else if name == "e" {
                    Node::Num(std::f64::consts::E)
                } else {
                    let vs = if vars.is_empty() {
                        "no variables here".to_string()
                    } else {
                        format!("variables here: {}", vars.join(", "))
                    };
                    return Err((e.span, format!("unknown name `{name}` ({vs}; or a parameter, pi, e)")));
                }
            }
            Node::Neg(a) => Node::Neg(Box::new(go(a, vars, param)?)),
            Node::Bin(op, a, b) => Node::Bin(*op, Box::new(go(a, vars, param)?), Box::new(go(b, vars, param)?)),
            Node::Call(f, args) => Node::Call(*f, args.iter().map(|a| go(a, vars, param)).collect::<Result<_, _>>()?),
            n => n.clone(),
        };
        let out = Expr { node, span: e.span };
        Ok(match fold(&out) {
            Some(x) if !matches!(out.node, Node::Num(_)) => Expr { node: Node::Num(x), span: e.span },
            _ => out,
        })
    }
    go(e, vars, param).map_err(|(span, msg)| ExprError { message: msg, source_text: String::new(), span })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(s: &str) -> f64 {
        Expr::parse(s).unwrap().bind(&["v"], &|_| None).unwrap().eval(&[0.5])
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(p("1 + 2*3"), 7.0);
        assert_eq!(p("2^3^2"), 512.0);
        assert_eq!(p("-2^2"), -4.0);
        assert_eq!(p("2^-1"), 0.5);
        assert_eq!(p("(1+2)*3"), 9.0);
        assert_eq!(p("8/4/2"), 1.0);
        assert_eq!(p("2**3"), 8.0);
        assert_eq!(p("1e-3*1000"), 1.0);
        assert_eq!(p("v*4"), 2.0);
        assert!((p("pi") - std::f64::consts::PI).abs() < 1e-15);
        assert_eq!(p("min(3, max(1, 2))"), 2.0);
        assert_eq!(p("atan2(1, 1)*4"), std::f64::consts::PI);
    }

    #[test]
    fn errors_point_at_the_column() {
        let e = Expr::parse("sin(v + 2").unwrap_err();
        assert_eq!(e.column(), 10);
        assert!(e.to_string().contains("expected `,` or `)`"), "{e}");
        assert!(e.to_string().ends_with("         ^"), "{e}");
        let e = Expr::parse("foo(v)").unwrap_err();
        assert!(e.message.contains("unknown function `foo`"));
        assert_eq!(e.column(), 1);
        let e = Expr::parse("1 + $").unwrap_err();
        assert_eq!(e.column(), 5);
        let e = Expr::parse("pow(v)").unwrap_err();
        assert!(e.message.contains("takes 2 arguments, got 1"), "{e}");
        let e = Expr::parse("1 2").unwrap_err();
        assert_eq!(e.column(), 3);
        assert!(Expr::parse("").is_err());
        assert!(Expr::parse("(((").is_err());
        let deep = "(".repeat(5000) + "1" + &")".repeat(5000);
        assert!(Expr::parse(&deep).unwrap_err().message.contains("nested deeper"));
        let e = Expr::parse("v + q").unwrap().bind(&["v"], &|_| None).unwrap_err();
        assert!(e.message.contains("unknown name `q`"));
        assert_eq!(e.span.start, 4);
    }

    /// Regression: `v+v+…+v` of 3 500 terms (18 KB) overflowed the editor's stack; the
    /// parenthesis limit did not see it. Parsed on a thread with a small stack, long chains
    /// of every operator are refused with an error naming the cap; a tree at the cap binds,
    /// evaluates and drops within that stack.
    #[test]
    fn long_chains_are_refused_without_deep_recursion() {
        std::thread::Builder::new()
            .stack_size(1 << 20)
            .spawn(|| {
                for op in ["+", "-", "*", "/"] {
                    let long = vec!["v"; 20_000].join(op);
                    let e = Expr::parse(&long).unwrap_err();
                    assert!(e.message.contains("too long or too deep"), "{op}: {}", e.message);
                    assert!(e.message.contains(&MAX_TREE_DEPTH.to_string()), "{}", e.message);
                    // the error shows an excerpt, not the 80 KB input
                    assert!(e.to_string().len() < 600, "{op}: {} bytes", e.to_string().len());
                }
                // `^` is right-associative: the parser's own nesting limit refuses it first
                let e = Expr::parse(&vec!["v"; 20_000].join("^")).unwrap_err();
                assert!(e.message.contains("nested deeper"), "{}", e.message);
                let signs = "-".repeat(190) + "v"; // under the nesting limit, deep unary chain
                assert_eq!(p(&signs), 0.5);
                // exactly at the cap: MAX_TREE_DEPTH - 1 additions of leaves
                let at_cap = vec!["v"; MAX_TREE_DEPTH].join("+");
                let e = Expr::parse(&at_cap).unwrap().bind(&["v"], &|_| None).unwrap();
                assert_eq!(e.eval(&[0.5]), 0.5 * MAX_TREE_DEPTH as f64);
                let j = e.eval_jet(&[crate::jet::Jet::variable(crate::jet::JetShape::new(&[4]), 0, 0.5)]);
                assert_eq!(j.value(), 0.5 * MAX_TREE_DEPTH as f64);
                let over = vec!["v"; MAX_TREE_DEPTH + 1].join("+");
                assert!(Expr::parse(&over).is_err());
                // nested calls count too
                let calls = "sin(".repeat(60) + &vec!["v"; 450].join("+") + &")".repeat(60);
                assert!(Expr::parse(&calls).unwrap_err().message.contains("too long or too deep"));
            })
            .unwrap()
            .join()
            .unwrap();
    }
}
