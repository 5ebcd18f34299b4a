//! The expression language of boundary data (SPEC §2.1).
//!
//! Expressions are real-valued formulas in named variables (`v`, `t`, `s`, `u`, `w`) and
//! named numeric parameters:
//!
//! ```text
//! (1 - t)*(b1*sinh(a1*v + a2) + b2*sin(a3*v)) + b3*t*cos(-v)
//! ```
//!
//! Operators `+ - * / ^` (`^` is right-associative and binds tighter than unary minus, so
//! `-v^2 = -(v²)`), functions `sin cos tan sinh cosh tanh exp ln sqrt abs atan pow atan2 min
//! max select`, constants `pi` and `e` (`select(x, a, b)` is `a` where `x > 0`, else `b`). Parsing yields an [`Expr`] whose identifiers are resolved
//! by [`Expr::bind`] into variable slots and parameter values; evaluation is available as
//! plain `f64` ([`Expr::eval`]) and as exact truncated Taylor series ([`Expr::eval_jet`]),
//! which gives every partial derivative up to any order exactly (see [`crate::jet`]).
//!
//! ```
//! use pdeshape_core::expr::Expr;
//! let e = Expr::parse("a*sin(2*v)").unwrap().bind(&["v"], &|p| (p == "a").then_some(3.0)).unwrap();
//! assert!((e.eval(&[0.25]) - 3.0 * 0.5f64.sin()).abs() < 1e-15);
//! ```

mod eval;
mod expand;
mod parse;
mod tape;
mod trig;

pub use expand::{Term, expand};
pub use parse::ExprError;
pub use tape::{OutputIter, Tape, TapeNum};
pub use trig::trig_degree;

use std::fmt;

/// A half-open byte range `[start, end)` of the source text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    /// First byte.
    pub start: usize,
    /// One past the last byte.
    pub end: usize,
}

/// A built-in function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Func {
    /// sin x
    Sin,
    /// cos x
    Cos,
    /// tan x
    Tan,
    /// sinh x
    Sinh,
    /// cosh x
    Cosh,
    /// tanh x
    Tanh,
    /// eˣ
    Exp,
    /// natural logarithm
    Ln,
    /// √x
    Sqrt,
    /// |x|
    Abs,
    /// arctan x
    Atan,
    /// pow(x, y) = xʸ
    Pow,
    /// atan2(y, x), the angle of (x, y)
    Atan2,
    /// min(x, y)
    Min,
    /// max(x, y)
    Max,
    /// select(x, a, b) = a where x > 0, else b (piecewise definitions)
    Select,
}

impl Func {
    /// All functions with their names (`log` is accepted as a synonym of `ln`).
    pub const ALL: [(&'static str, Func); 16] = [
        ("sin", Func::Sin),
        ("cos", Func::Cos),
        ("tan", Func::Tan),
        ("sinh", Func::Sinh),
        ("cosh", Func::Cosh),
        ("tanh", Func::Tanh),
        ("exp", Func::Exp),
        ("ln", Func::Ln),
        ("sqrt", Func::Sqrt),
        ("abs", Func::Abs),
        ("atan", Func::Atan),
        ("pow", Func::Pow),
        ("atan2", Func::Atan2),
        ("min", Func::Min),
        ("max", Func::Max),
        ("select", Func::Select),
    ];

    /// Looks a function up by name.
    pub fn from_name(name: &str) -> Option<Func> {
        if name == "log" {
            return Some(Func::Ln);
        }
        Func::ALL.iter().find(|(n, _)| *n == name).map(|(_, f)| *f)
    }

    /// The function's name.
    pub fn name(self) -> &'static str {
        Func::ALL.iter().find(|(_, f)| *f == self).map(|(n, _)| *n).unwrap_or("?")
    }

    /// Number of arguments.
    pub fn arity(self) -> usize {
        match self {
            Func::Pow | Func::Atan2 | Func::Min | Func::Max => 2,
            Func::Select => 3,
            _ => 1,
        }
    }
}

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BinOp {
    /// a + b
    Add,
    /// a − b
    Sub,
    /// a · b
    Mul,
    /// a / b
    Div,
    /// aᵇ
    Pow,
}

/// An expression node.
#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    /// A number literal (or a folded constant).
    Num(f64),
    /// An unresolved identifier (before [`Expr::bind`]).
    Ident(String),
    /// Variable slot `i` of the bound variable list.
    Var(usize),
    /// −a
    Neg(Box<Expr>),
    /// a ∘ b
    Bin(BinOp, Box<Expr>, Box<Expr>),
    /// f(a, …)
    Call(Func, Vec<Expr>),
}

/// A parsed expression: a tree of [`Node`]s, each with its source span.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    /// The node.
    pub node: Node,
    /// Where it stands in the source.
    pub span: Span,
}

impl Expr {
    /// Parses `src`. Errors carry the column and print a caret under it.
    pub fn parse(src: &str) -> Result<Expr, ExprError> {
        parse::parse(src)
    }

    /// A number.
    pub fn num(x: f64) -> Expr {
        Expr { node: Node::Num(x), span: Span { start: 0, end: 0 } }
    }

    /// Resolves identifiers: names in `vars` become variable slots (by position), other
    /// names are looked up with `param` (then the constants `pi`, `e`); anything else is an
    /// error naming the identifier and its column. Constant sub-expressions are folded.
    pub fn bind(&self, vars: &[&str], param: &dyn Fn(&str) -> Option<f64>) -> Result<Expr, ExprError> {
        parse::bind(self, vars, param)
    }

    /// The identifiers the expression uses, in order of first appearance.
    pub fn identifiers(&self) -> Vec<String> {
        let mut out = Vec::new();
        self.visit(&mut |e| {
            if let Node::Ident(n) = &e.node
                && !out.contains(n)
            {
                out.push(n.clone());
            }
        });
        out
    }

    /// Calls `f` on every node, parents first.
    pub fn visit(&self, f: &mut dyn FnMut(&Expr)) {
        f(self);
        match &self.node {
            Node::Neg(a) => a.visit(f),
            Node::Bin(_, a, b) => {
                a.visit(f);
                b.visit(f);
            }
            Node::Call(_, args) => args.iter().for_each(|a| a.visit(f)),
            _ => {}
        }
    }

    /// True when the expression is a constant number.
    pub fn as_constant(&self) -> Option<f64> {
        match self.node {
            Node::Num(x) => Some(x),
            _ => None,
        }
    }

    /// True when the (bound) expression depends on variable slot `i`.
    pub fn depends_on(&self, i: usize) -> bool {
        let mut found = false;
        self.visit(&mut |e| found |= matches!(e.node, Node::Var(j) if j == i));
        found
    }
}

impl fmt::Display for Expr {
    /// Prints the expression with full parentheses around every binary operation (bound
    /// variables print as `#i`), which is canonical enough to compare product terms.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.node {
            Node::Num(x) => write!(f, "{x:?}"),
            Node::Ident(n) => write!(f, "{n}"),
            Node::Var(i) => write!(f, "#{i}"),
            Node::Neg(a) => write!(f, "(-{a})"),
            Node::Bin(op, a, b) => {
                let o = match op {
                    BinOp::Add => "+",
                    BinOp::Sub => "-",
                    BinOp::Mul => "*",
                    BinOp::Div => "/",
                    BinOp::Pow => "^",
                };
                write!(f, "({a}{o}{b})")
            }
            Node::Call(func, args) => {
                write!(f, "{}(", func.name())?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        write!(f, ",")?;
                    }
                    write!(f, "{a}")?;
                }
                write!(f, ")")
            }
        }
    }
}
