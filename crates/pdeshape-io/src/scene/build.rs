//! Resolution of a raw scene into core objects, with located errors.

use super::error::{SceneError, Source};
use super::raw::*;
use super::{Param, PatchKind, RenderSettings, Scene, ScenePatch, SceneSurface};
use indexmap::IndexMap;
use pdeshape_core::Vec3;
use pdeshape_core::blend::{
    BasisFn, BlendOptions, DynBasis, DynamicBlend, DynamicOperator, DynamicOptions, Operator, Solver, StaticBlend,
};
use pdeshape_core::data::{BSplineCurve, Combination, ExprField, FieldRef, PointField, Trimline, curve_derivative};
use pdeshape_core::expr::{BinOp, Expr, ExprError, Func, Node};
use pdeshape_core::limits::{Cap, Limits};
use pdeshape_core::patch::{Condition, HermitePatch, VDomain};
use pdeshape_core::spectral::{SpectralOptions, SpectralPatch};
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;

/// Names that parameters, curves and surfaces may not take: variables, constants and
/// function names of the expression language.
pub const RESERVED: &[&str] = &["u", "v", "w", "s", "t", "pi", "e", "log"];

/// Output formats a scene may list.
pub const FORMATS: &[&str] = &["obj", "ply", "stl", "glb", "vtu", "png"];

pub(super) type R<T> = Result<T, SceneError>;

pub(super) struct Ctx<'a> {
    src: Source<'a>,
    params: IndexMap<String, Param>,
    /// Solver override for patches that offer a choice.
    solver: Option<Solver>,
    /// Override of the sine-term count of dynamic blends.
    terms: Option<usize>,
    /// Caps on sizes.
    pub(super) limits: Limits,
}

pub(super) fn span<T>(s: &Spanned<T>) -> Option<Range<usize>> {
    Some(s.span())
}

/// The surface `name` refers to; an unknown name is an error at `key` listing the defined
/// surfaces.
pub(super) fn find_surface<'s>(
    ctx: &Ctx,
    surfaces: &'s [SceneSurface],
    name: &Spanned<String>,
    key: &str,
) -> R<&'s SceneSurface> {
    surfaces.iter().find(|s| s.name == *name.get_ref()).ok_or_else(|| {
        let known: Vec<&str> = surfaces.iter().map(|s| s.name.as_str()).collect();
        ctx.err(
            span(name),
            key,
            format!(
                "unknown surface `{}` (defined: {})",
                name.get_ref(),
                if known.is_empty() { "none".to_string() } else { known.join(", ") }
            ),
        )
    })
}

fn is_reserved(name: &str) -> bool {
    RESERVED.contains(&name) || Func::from_name(name).is_some()
}

fn toml_error(src: &Source, e: toml::de::Error) -> SceneError {
    let msg = e.message().trim().to_string();
    let msg = if msg.contains("untagged enum NumOrExpr") {
        "expected a number or an expression string".to_string()
    } else if msg.contains("untagged enum RawParam") {
        "expected a number, an expression string or a table { value, min, max, step }".to_string()
    } else if msg.contains("untagged enum RawDomain") {
        "expected \"periodic\" or a range [v0, v1]".to_string()
    } else {
        msg
    };
    src.error(e.span(), "", msg)
}

impl Ctx<'_> {
    /// An expression error located at its exact character: the expression text is looked
    /// up inside the TOML value it came from, and the error's offset added.
    fn expr_err(&self, sp: Option<Range<usize>>, key: impl Into<String>, text: &str, e: &ExprError) -> SceneError {
        let exact = sp.as_ref().and_then(|r| {
            let hay = self.src.text.get(r.clone())?;
            let at = hay.find(text)?;
            let start = r.start + at + e.span.start.min(text.len());
            Some(start..start + 1)
        });
        match exact {
            Some(r) => self.err(Some(r), key, format!("{} (in `{text}`)", e.message)),
            None => self.err(sp, key, e.with_source_ref(text).to_string()),
        }
    }

    pub(super) fn err(&self, span: Option<Range<usize>>, key: impl Into<String>, msg: impl Into<String>) -> SceneError {
        self.src.error(span, key, msg)
    }

    /// The solver of a blend: the command line's override, else the scene's `solver`.
    fn solver_choice(&self, raw: &Option<Spanned<String>>, key: &str) -> R<Option<Solver>> {
        let scene = match raw {
            None => None,
            Some(sv) => Some(Solver::parse(sv.get_ref()).ok_or_else(|| {
                self.err(
                    span(sv),
                    format!("{key}.solver"),
                    format!("unknown solver `{}` (known: auto, exact, collocation)", sv.get_ref()),
                )
            })?),
        };
        Ok(self.solver.or(scene))
    }

    /// Explicit basis functions: expressions in `vars`, with their source text.
    fn basis_exprs(&self, list: &Spanned<Vec<Spanned<String>>>, key: &str, vars: &[&str]) -> R<Vec<(Expr, String)>> {
        let mut out = Vec::new();
        for (j, t) in list.get_ref().iter().enumerate() {
            let text = t.get_ref();
            let bk = format!("{key}.basis[{j}]");
            let e = Expr::parse(text).map_err(|e| self.expr_err(span(t), &bk, text, &e))?;
            let e = e.bind(vars, &self.param_lookup()).map_err(|e| self.expr_err(span(t), &bk, text, &e))?;
            out.push((e, text.clone()));
        }
        Ok(out)
    }

    fn param_lookup(&self) -> impl Fn(&str) -> Option<f64> + '_ {
        |n: &str| self.params.get(n).map(|p| p.value)
    }

    /// A constant: a number or an expression in the parameters.
    pub(super) fn num(&self, x: &NumOrExpr, sp: Option<Range<usize>>, key: &str) -> R<f64> {
        let v = match x {
            NumOrExpr::Num(v) => *v,
            NumOrExpr::Expr(s) => {
                let e = Expr::parse(s).map_err(|e| self.expr_err(sp.clone(), key, s, &e))?;
                let b = e.bind(&[], &self.param_lookup()).map_err(|e| self.expr_err(sp.clone(), key, s, &e))?;
                b.eval(&[])
            }
        };
        if !v.is_finite() {
            return Err(self.err(sp, key, format!("the value is not finite ({v})")));
        }
        Ok(v)
    }

    pub(super) fn vec3(&self, x: &[NumOrExpr; 3], sp: Option<Range<usize>>, key: &str) -> R<Vec3> {
        Ok(Vec3::new(self.num(&x[0], sp.clone(), key)?, self.num(&x[1], sp.clone(), key)?, self.num(&x[2], sp, key)?))
    }

    fn field(&self, x: &Spanned<[NumOrExpr; 3]>, vars: &[&str], key: &str) -> R<ExprField> {
        let texts = x.get_ref().each_ref().map(NumOrExpr::text);
        ExprField::parse([&texts[0], &texts[1], &texts[2]], vars, &self.param_lookup())
            .map_err(|(i, e)| self.expr_err(span(x), format!("{key}[{i}]"), &texts[i], &e))
    }

    /// A plane curve: two expressions (the third component is 0).
    pub(super) fn field2(&self, x: &Spanned<[NumOrExpr; 2]>, vars: &[&str], key: &str) -> R<ExprField> {
        let texts = x.get_ref().each_ref().map(NumOrExpr::text);
        ExprField::parse([&texts[0], &texts[1], "0"], vars, &self.param_lookup())
            .map_err(|(i, e)| self.expr_err(span(x), format!("{key}[{i}]"), &texts[i.min(1)], &e))
    }

    pub(super) fn int(&self, x: &Spanned<i64>, lo: i64, hi: i64, key: &str) -> R<i64> {
        let v = *x.get_ref();
        if v < lo || v > hi {
            return Err(self.err(span(x), key, format!("{v} is out of range (expected {lo} … {hi})")));
        }
        Ok(v)
    }

    /// An integer `≥ lo` within `cap`.
    pub(super) fn capped(&self, x: &Spanned<i64>, lo: i64, cap: Cap, key: &str) -> R<usize> {
        let v = *x.get_ref();
        if v < lo {
            return Err(self.err(span(x), key, format!("{v} is too small (expected at least {lo})")));
        }
        self.cap(cap, v as u128, span(x), key, &format!("`{key}`"))?;
        Ok(v as usize)
    }

    /// `value` checked against `cap`; the error names the place, the cap and how to raise it.
    pub(super) fn cap(&self, cap: Cap, value: u128, sp: Option<Range<usize>>, key: &str, what: &str) -> R<()> {
        self.limits.check(cap, value, what).map_err(|e| self.err(sp, key, e.to_string()))
    }

    fn range(&self, x: &Spanned<[NumOrExpr; 2]>, key: &str) -> R<(f64, f64)> {
        let a = self.num(&x.get_ref()[0], span(x), key)?;
        let b = self.num(&x.get_ref()[1], span(x), key)?;
        if b <= a {
            return Err(self.err(span(x), key, format!("empty range [{a}, {b}] (expected start < end)")));
        }
        Ok((a, b))
    }

    fn domain(&self, x: &Option<Spanned<RawDomain>>, key: &str) -> R<VDomain> {
        let Some(x) = x else {
            return Ok(VDomain::PERIODIC);
        };
        match x.get_ref() {
            RawDomain::Word(w) if w == "periodic" => Ok(VDomain::PERIODIC),
            RawDomain::Word(w) => {
                Err(self.err(span(x), key, format!("unknown v domain `{w}` (expected \"periodic\" or [v0, v1])")))
            }
            RawDomain::Range(r) => {
                let a = self.num(&r[0], span(x), key)?;
                let b = self.num(&r[1], span(x), key)?;
                if b <= a {
                    return Err(self.err(span(x), key, format!("empty v range [{a}, {b}]")));
                }
                Ok(VDomain::open(a, b))
            }
        }
    }

    pub(super) fn resolution(
        &self,
        x: &Option<Spanned<[i64; 2]>>,
        default: (usize, usize),
        key: &str,
    ) -> R<(usize, usize)> {
        let Some(x) = x else { return Ok(default) };
        let [a, b] = *x.get_ref();
        if a < 2 || b < 2 {
            return Err(self.err(
                span(x),
                key,
                format!("resolution [{a}, {b}] is too small (at least 2 × 2 vertices)"),
            ));
        }
        self.cap(Cap::Vertices, a as u128 * b as u128, span(x), key, &format!("resolution [{a}, {b}] (vertices)"))?;
        Ok((a as usize, b as usize))
    }
}

fn check_name(
    src: &Source,
    name: &str,
    sp: Option<Range<usize>>,
    key: &str,
    taken: &mut HashMap<String, String>,
) -> R<()> {
    let valid = name.chars().next().is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !valid {
        return Err(src.error(
            sp,
            key,
            format!("`{name}` is not a valid name (letters, digits, `_`, `-`; starting with a letter)"),
        ));
    }
    if is_reserved(name) {
        return Err(src.error(sp, key, format!("`{name}` is reserved (a variable, constant or function name)")));
    }
    if let Some(prev) = taken.get(name) {
        return Err(src.error(sp, key, format!("the name `{name}` is already used by {prev}")));
    }
    taken.insert(name.to_string(), key.to_string());
    Ok(())
}

fn build_params(ctx: &mut Ctx, raw: &IndexMap<String, Spanned<RawParam>>, overrides: &HashMap<String, f64>) -> R<()> {
    for name in overrides.keys() {
        if !raw.contains_key(name) {
            let known = if raw.is_empty() {
                "the scene has no parameters".to_string()
            } else {
                format!("parameters: {}", raw.keys().map(String::as_str).collect::<Vec<_>>().join(", "))
            };
            return Err(ctx.err(None, "--set", format!("unknown parameter `{name}` ({known})")));
        }
    }
    #[derive(Clone, Copy, PartialEq)]
    enum St {
        Todo,
        Busy,
        Done,
    }
    let mut state: HashMap<&str, St> = raw.keys().map(|k| (k.as_str(), St::Todo)).collect();
    let mut values: HashMap<String, f64> = HashMap::new();

    fn visit<'r>(
        name: &'r str,
        raw: &'r IndexMap<String, Spanned<RawParam>>,
        overrides: &HashMap<String, f64>,
        state: &mut HashMap<&'r str, St>,
        values: &mut HashMap<String, f64>,
        stack: &mut Vec<&'r str>,
        src: &Source,
    ) -> R<()> {
        match state[name] {
            St::Done => return Ok(()),
            St::Busy => {
                let mut cyc: Vec<&str> = stack.clone();
                cyc.push(name);
                let start = cyc.iter().position(|n| *n == name).unwrap_or(0);
                return Err(src.error(
                    span(&raw[name]),
                    format!("parameters.{name}"),
                    format!("parameters depend on each other in a cycle: {}", cyc[start..].join(" → ")),
                ));
            }
            St::Todo => {}
        }
        let key = format!("parameters.{name}");
        let p = &raw[name];
        let value = match p.get_ref() {
            RawParam::Value(v) => v,
            RawParam::Full(t) => &t.value,
        };
        let x = if let Some(&o) = overrides.get(name) {
            o
        } else {
            match value {
                NumOrExpr::Num(x) => *x,
                NumOrExpr::Expr(text) => {
                    state.insert(name, St::Busy);
                    stack.push(name);
                    let e = Expr::parse(text).map_err(|e| src.error(span(p), &key, e.to_string()))?;
                    for id in e.identifiers() {
                        if raw.contains_key(&id) {
                            let id_ref = raw.get_key_value(&id).map(|(k, _)| k.as_str()).unwrap_or("");
                            visit(id_ref, raw, overrides, state, values, stack, src)?;
                        }
                    }
                    stack.pop();
                    let b = e
                        .bind(&[], &|n| values.get(n).copied())
                        .map_err(|e| src.error(span(p), &key, e.with_source(text).to_string()))?;
                    b.eval(&[])
                }
            }
        };
        if !x.is_finite() {
            return Err(src.error(span(p), &key, format!("the value is not finite ({x})")));
        }
        values.insert(name.to_string(), x);
        state.insert(name, St::Done);
        Ok(())
    }

    for name in raw.keys() {
        let mut stack = Vec::new();
        visit(name, raw, overrides, &mut state, &mut values, &mut stack, &ctx.src)?;
    }
    for (name, p) in raw {
        let (expr, min, max, step, description) = match p.get_ref() {
            RawParam::Value(NumOrExpr::Expr(e)) => (Some(e.clone()), None, None, None, None),
            RawParam::Value(_) => (None, None, None, None, None),
            RawParam::Full(t) => (
                match &t.value {
                    NumOrExpr::Expr(e) => Some(e.clone()),
                    _ => None,
                },
                t.min,
                t.max,
                t.step,
                t.description.clone(),
            ),
        };
        if let (Some(a), Some(b)) = (min, max)
            && !(a.is_finite() && b.is_finite() && a < b)
        {
            return Err(ctx.err(
                span(p),
                format!("parameters.{name}"),
                format!("slider range [{a}, {b}] is empty or not finite"),
            ));
        }
        ctx.params.insert(name.clone(), Param { value: values[name], expr, min, max, step, description });
    }
    Ok(())
}

/// A linear form over curves: `Σ wₖ curveₖ + c` or a plain number.
enum Lin {
    Scalar(f64),
    Vector(Vec<(f64, String)>, Vec3),
}

fn linear(e: &Expr, is_curve: &dyn Fn(&str) -> bool, param: &dyn Fn(&str) -> Option<f64>) -> Result<Lin, String> {
    use Lin::*;
    Ok(match &e.node {
        Node::Num(x) => Scalar(*x),
        Node::Ident(n) if is_curve(n) => Vector(vec![(1.0, n.clone())], Vec3::ZERO),
        Node::Ident(n) => Scalar(
            param(n)
                .or(match n.as_str() {
                    "pi" => Some(std::f64::consts::PI),
                    "e" => Some(std::f64::consts::E),
                    _ => None,
                })
                .ok_or_else(|| format!("unknown name `{n}` (expected a curve or a parameter)"))?,
        ),
        Node::Neg(a) => match linear(a, is_curve, param)? {
            Scalar(x) => Scalar(-x),
            Vector(t, c) => Vector(t.into_iter().map(|(w, n)| (-w, n)).collect(), -c),
        },
        Node::Bin(op, a, b) => {
            let (x, y) = (linear(a, is_curve, param)?, linear(b, is_curve, param)?);
            match (op, x, y) {
                (BinOp::Add | BinOp::Sub, Scalar(x), Scalar(y)) => {
                    Scalar(if *op == BinOp::Add { x + y } else { x - y })
                }
                (BinOp::Add | BinOp::Sub, Vector(mut t, c), Vector(u, d)) => {
                    let s = if *op == BinOp::Add { 1.0 } else { -1.0 };
                    t.extend(u.into_iter().map(|(w, n)| (s * w, n)));
                    Vector(t, c + d * s)
                }
                (BinOp::Mul, Scalar(x), Vector(t, c)) | (BinOp::Mul, Vector(t, c), Scalar(x)) => {
                    Vector(t.into_iter().map(|(w, n)| (w * x, n)).collect(), c * x)
                }
                (BinOp::Div, Vector(t, c), Scalar(x)) => {
                    Vector(t.into_iter().map(|(w, n)| (w / x, n)).collect(), c / x)
                }
                (BinOp::Mul, Scalar(x), Scalar(y)) => Scalar(x * y),
                (BinOp::Div, Scalar(x), Scalar(y)) => Scalar(x / y),
                (BinOp::Pow, Scalar(x), Scalar(y)) => Scalar(x.powf(y)),
                _ => {
                    return Err(
                        "not a linear combination of curves (curves may be added, subtracted and scaled by numbers)"
                            .into(),
                    );
                }
            }
        }
        Node::Call(f, args) => {
            let mut xs = Vec::new();
            for a in args {
                match linear(a, is_curve, param)? {
                    Scalar(x) => xs.push(x),
                    _ => {
                        return Err(format!("`{}` of a curve is not a linear combination", f.name()));
                    }
                }
            }
            let e = Expr { node: Node::Call(*f, xs.into_iter().map(Expr::num).collect()), span: e.span };
            Scalar(e.bind(&[], &|_| None).map_err(|e| e.message)?.eval(&[]))
        }
        Node::Var(_) => return Err("unexpected variable".into()),
    })
}

struct CurveBuilder<'a, 'c> {
    ctx: &'a Ctx<'c>,
    raw: &'a IndexMap<String, Spanned<RawCurve>>,
    surfaces: &'a [SceneSurface],
    done: IndexMap<String, FieldRef>,
    busy: Vec<String>,
}

impl CurveBuilder<'_, '_> {
    fn get(&mut self, name: &str) -> R<FieldRef> {
        if let Some(f) = self.done.get(name) {
            return Ok(f.clone());
        }
        let rc = &self.raw[name];
        let key = format!("curves.{name}");
        if let Some(i) = self.busy.iter().position(|n| n == name) {
            let mut cyc = self.busy[i..].to_vec();
            cyc.push(name.to_string());
            return Err(self.ctx.err(
                span(rc),
                key,
                format!("curves depend on each other in a cycle: {}", cyc.join(" → ")),
            ));
        }
        self.busy.push(name.to_string());
        let f = self.make(name, rc, &key)?;
        self.busy.pop();
        self.done.insert(name.to_string(), f.clone());
        Ok(f)
    }

    fn make(&mut self, name: &str, rc: &Spanned<RawCurve>, key: &str) -> R<FieldRef> {
        let c = rc.get_ref();
        let ctx = self.ctx;
        let sources: Vec<&str> = [
            ("expr", c.expr.is_some()),
            ("bspline", c.bspline.is_some()),
            ("polyline", c.polyline.is_some()),
            ("point", c.point.is_some()),
            ("combine", c.combine.is_some()),
            ("surface", c.surface.is_some()),
        ]
        .iter()
        .filter(|(_, b)| *b)
        .map(|(n, _)| *n)
        .collect();
        if sources.len() != 1 {
            let msg = if sources.is_empty() {
                "the curve has no definition (expected one of: expr, bspline, polyline, point, combine, surface)"
                    .to_string()
            } else {
                format!("the curve has several definitions ({}); give exactly one", sources.join(", "))
            };
            return Err(ctx.err(span(rc), key, msg));
        }
        let only_for = |present: bool, what: &str, allowed: &str| -> R<()> {
            if present {
                return Err(ctx.err(span(rc), key, format!("`{what}` only applies to {allowed} curves")));
            }
            Ok(())
        };
        let spline_like = c.bspline.is_some() || c.polyline.is_some();
        only_for(!spline_like && c.closed.is_some(), "closed", "bspline and polyline")?;
        only_for(!spline_like && c.range.is_some(), "range", "bspline and polyline")?;
        only_for(c.bspline.is_none() && c.degree.is_some(), "degree", "bspline")?;
        let trim = c.surface.is_some();
        only_for(
            !trim && (c.s.is_some() || c.derivative.is_some() || c.scale.is_some()),
            "s/derivative/scale",
            "surface (trimline)",
        )?;

        if let Some(x) = &c.expr {
            return Ok(Arc::new(ctx.field(x, &["v", "t"], &format!("{key}.expr"))?));
        }
        if let Some(x) = &c.point {
            return Ok(Arc::new(PointField {
                point: ctx.vec3(x.get_ref(), span(x), &format!("{key}.point"))?,
                arity: 1,
            }));
        }
        if let Some(pts) = c.bspline.as_ref().or(c.polyline.as_ref()) {
            let is_poly = c.polyline.is_some();
            let k = format!("{key}.{}", if is_poly { "polyline" } else { "bspline" });
            let points = pts
                .get_ref()
                .iter()
                .enumerate()
                .map(|(i, p)| ctx.vec3(p, span(pts), &format!("{k}[{i}]")))
                .collect::<R<Vec<_>>>()?;
            let closed = c.closed.unwrap_or(false);
            let degree = match &c.degree {
                Some(d) => ctx.int(d, 1, 7, &format!("{key}.degree"))? as usize,
                None if is_poly => 1,
                None => 3,
            };
            let range = match &c.range {
                Some(r) => ctx.range(r, &format!("{key}.range"))?,
                None if closed => (0.0, 2.0 * std::f64::consts::PI),
                None => (0.0, 1.0),
            };
            if !closed && points.len() >= 2 && (points[0] - points[points.len() - 1]).norm() == 0.0 && points.len() > 2
            {
                // A repeated end point on an open curve is legitimate (a closed polygon as an
                // open spline); nothing to do.
            }
            let curve =
                BSplineCurve::new(points, degree, closed, range).map_err(|e| ctx.err(span(pts), &k, e.to_string()))?;
            return Ok(Arc::new(curve));
        }
        if let Some(text) = &c.combine {
            let k = format!("{key}.combine");
            let e = Expr::parse(text.get_ref()).map_err(|e| ctx.expr_err(span(text), &k, text.get_ref(), &e))?;
            let names: Vec<String> = self.raw.keys().cloned().collect();
            let is_curve = |n: &str| names.iter().any(|m| m == n);
            let lin = linear(&e, &is_curve, &ctx.param_lookup()).map_err(|m| ctx.err(span(text), &k, m))?;
            let Lin::Vector(terms, constant) = lin else {
                return Err(ctx.err(
                    span(text),
                    &k,
                    "the combination names no curve (expected e.g. \"alpha*(d1 - p2)\")",
                ));
            };
            let mut fields = Vec::new();
            for (w, n) in terms {
                if n == name {
                    return Err(ctx.err(span(text), &k, format!("the curve `{name}` refers to itself")));
                }
                if !w.is_finite() {
                    return Err(ctx.err(span(text), &k, format!("the weight of `{n}` is not finite")));
                }
                fields.push((w, self.get(&n)?));
            }
            return Ok(Arc::new(Combination::new(fields, constant)));
        }
        if let Some(sname) = &c.surface {
            let surf = find_surface(ctx, self.surfaces, sname, &format!("{key}.surface"))?;
            let s = c
                .s
                .as_ref()
                .ok_or_else(|| ctx.err(span(rc), key, "a trimline needs `s`, the surface parameter of the trimline"))?;
            let s0 = ctx.num(s.get_ref(), span(s), &format!("{key}.s"))?;
            let d = match &c.derivative {
                Some(d) => ctx.int(d, 0, 6, &format!("{key}.derivative"))? as usize,
                None => 0,
            };
            let scale = match &c.scale {
                Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.scale"))?,
                None => 1.0,
            };
            return Ok(Arc::new(Trimline::new(surf.field.clone(), s0, d, scale)));
        }
        unreachable!("one source is present")
    }
}

pub(super) fn build(src: Source, name: &str, opts: &super::LoadOptions) -> R<Scene> {
    let overrides = &opts.params;
    let raw: RawScene = toml::from_str(src.text).map_err(|e| toml_error(&src, e))?;
    let solver = match opts.solver.as_deref() {
        None => None,
        Some(w) => Some(Solver::parse(w).ok_or_else(|| {
            src.error(None, "--solver", format!("unknown solver `{w}` (known: auto, exact, collocation)"))
        })?),
    };
    let mut ctx = Ctx { src: src.clone(), params: IndexMap::new(), solver, terms: opts.terms, limits: opts.limits };
    let mut taken: HashMap<String, String> = HashMap::new();
    for (n, p) in &raw.parameters {
        check_name(&src, n, span(p), &format!("parameters.{n}"), &mut taken)?;
    }
    for (n, c) in &raw.curves {
        check_name(&src, n, span(c), &format!("curves.{n}"), &mut taken)?;
    }
    for (n, s) in &raw.surfaces {
        check_name(&src, n, span(s), &format!("surfaces.{n}"), &mut taken)?;
    }
    let mut patch_names: HashMap<String, String> = HashMap::new();
    for (n, p) in &raw.patches {
        check_name(&src, n, span(p), &format!("patches.{n}"), &mut patch_names)?;
    }
    build_params(&mut ctx, &raw.parameters, overrides)?;

    let mut surfaces = Vec::new();
    for (n, s) in &raw.surfaces {
        let key = format!("surfaces.{n}");
        let rs = s.get_ref();
        let field: FieldRef = Arc::new(ctx.field(&rs.expr, &["s", "v", "t"], &format!("{key}.expr"))?);
        let s_range = rs.s_range.as_ref().map(|r| ctx.range(r, &format!("{key}.s_range"))).transpose()?;
        let domain = ctx.domain(&rs.v, &format!("{key}.v"))?;
        let resolution = ctx.resolution(&rs.resolution, (17, 65), &format!("{key}.resolution"))?;
        surfaces.push(SceneSurface { name: n.clone(), field, s_range, domain, resolution });
    }

    let mut cb =
        CurveBuilder { ctx: &ctx, raw: &raw.curves, surfaces: &surfaces, done: IndexMap::new(), busy: Vec::new() };
    for n in raw.curves.keys() {
        cb.get(n)?;
    }
    let curves: IndexMap<String, FieldRef> = raw.curves.keys().map(|n| (n.clone(), cb.done[n].clone())).collect();

    let mut patches = Vec::new();
    let mut bytes = 0u128;
    for (pname, p) in &raw.patches {
        let built = build_patch(&ctx, pname, p, &curves, &surfaces, &patches)?;
        bytes += built.memory_estimate();
        let mib = bytes.div_ceil(1 << 20);
        ctx.cap(Cap::Memory, mib, span(p), &format!("patches.{pname}"), "the estimated memory of the meshes")?;
        patches.push(built);
    }

    let r = &raw.render;
    let mut render = RenderSettings::default();
    if let Some(a) = r.azimuth {
        render.azimuth = a;
    }
    if let Some(e) = r.elevation {
        if !(-90.0..=90.0).contains(&e) {
            return Err(ctx.err(None, "render.elevation", format!("{e} is out of range (expected -90 … 90 degrees)")));
        }
        render.elevation = e;
    }
    if let Some(sz) = &r.size {
        let [w, h] = *sz.get_ref();
        if !(16..=8192).contains(&w) || !(16..=8192).contains(&h) {
            return Err(ctx.err(span(sz), "render.size", format!("[{w}, {h}] is out of range (16 … 8192 pixels)")));
        }
        render.size = (w as u32, h as u32);
    }
    if let Some(z) = r.zoom {
        if !(z.is_finite() && z > 0.0) {
            return Err(ctx.err(None, "render.zoom", format!("{z} is not a positive number")));
        }
        render.zoom = z;
    }
    render.wireframe = r.wireframe.unwrap_or(false);
    render.field = r.field.clone();

    let formats = match &raw.output.formats {
        None => vec!["obj".to_string(), "png".to_string()],
        Some(list) => {
            let mut out = Vec::new();
            for f in list.get_ref() {
                if !FORMATS.contains(&f.get_ref().as_str()) {
                    return Err(ctx.err(
                        span(f),
                        "output.formats",
                        format!("unknown format `{}` (known: {})", f.get_ref(), FORMATS.join(", ")),
                    ));
                }
                out.push(f.get_ref().clone());
            }
            out
        }
    };

    let mut studies = Vec::new();
    for (i, st) in raw.studies.iter().enumerate() {
        let r = st.get_ref();
        let key = format!("studies[{i}]");
        for n in r.set.keys().chain(std::iter::once(&r.vary)) {
            if !ctx.params.contains_key(n) {
                return Err(ctx.err(span(st), &key, format!("unknown parameter `{n}`")));
            }
        }
        if r.values.is_empty() || r.values.len() > 12 || r.values.iter().chain(r.set.values()).any(|x| !x.is_finite()) {
            return Err(ctx.err(span(st), &key, "a study needs 1 … 12 finite values"));
        }
        studies.push(super::Study {
            title: r.title.clone(),
            set: r.set.iter().map(|(k, v)| (k.clone(), *v)).collect(),
            vary: r.vary.clone(),
            values: r.values.clone(),
        });
    }

    Ok(Scene {
        file: src.file.to_string(),
        name: name.to_string(),
        source: src.text.to_string(),
        title: raw.scene.title,
        description: raw.scene.description,
        reference: raw.scene.reference,
        params: ctx.params,
        curves,
        surfaces,
        patches,
        render,
        formats,
        studies,
        options: opts.clone(),
    })
}

fn build_patch(
    ctx: &Ctx,
    pname: &str,
    p: &Spanned<RawPatch>,
    curves: &IndexMap<String, FieldRef>,
    surfaces: &[SceneSurface],
    done: &[ScenePatch],
) -> R<ScenePatch> {
    let key = format!("patches.{pname}");
    let rp = p.get_ref();
    let kind = match rp.kind.get_ref().as_str() {
        "hermite" => PatchKind::Hermite,
        "pde" => PatchKind::Pde,
        "blend" => PatchKind::Blend,
        "dynamic" => PatchKind::Dynamic,
        "solid" => PatchKind::Solid,
        "fill" => PatchKind::Fill,
        k => {
            return Err(ctx.err(
                span(&rp.kind),
                format!("{key}.kind"),
                format!("unknown patch kind `{k}` (known: hermite, pde, blend, dynamic, solid, fill)"),
            ));
        }
    };
    let only = |present: bool, name: &str, for_kind: PatchKind| -> R<()> {
        // start/end, solver and the collocation grid serve both kinds of blend; β and γ
        // serve dynamic and solid blends
        let shared = matches!(name, "start" | "end" | "solver" | "collocation" | "basis")
            && matches!(kind, PatchKind::Blend | PatchKind::Dynamic)
            || matches!(name, "beta" | "gamma") && kind == PatchKind::Solid
            || matches!(name, "a" | "modes" | "omega") && kind == PatchKind::Fill;
        if present && kind != for_kind && !shared {
            return Err(ctx.err(
                span(p),
                format!("{key}.{name}"),
                format!("`{name}` only applies to kind = \"{}\"", for_kind.name()),
            ));
        }
        Ok(())
    };
    only(rp.a.is_some(), "a", PatchKind::Pde)?;
    only(rp.modes.is_some(), "modes", PatchKind::Pde)?;
    only(rp.omega.is_some(), "omega", PatchKind::Pde)?;
    only(rp.sections.is_some() && kind == PatchKind::Blend, "sections", PatchKind::Pde)?;
    only(rp.orders.is_some(), "orders", PatchKind::Blend)?;
    only(rp.coefficients.is_some(), "coefficients", PatchKind::Blend)?;
    only(rp.solver.is_some(), "solver", PatchKind::Blend)?;
    only(rp.bubbles.is_some(), "bubbles", PatchKind::Blend)?;
    only(rp.collocation.is_some(), "collocation", PatchKind::Blend)?;
    only(rp.basis.is_some(), "basis", PatchKind::Blend)?;
    only(rp.start.is_some(), "start", PatchKind::Blend)?;
    only(rp.end.is_some(), "end", PatchKind::Blend)?;
    for (present, name) in [
        (rp.beta.is_some(), "beta"),
        (rp.gamma.is_some(), "gamma"),
        (rp.lambda.is_some(), "lambda"),
        (rp.rho.is_some(), "rho"),
        (rp.eta.is_some(), "eta"),
        (rp.terms.is_some(), "terms"),
        (rp.joint.is_some(), "joint"),
        (rp.time.is_some(), "time"),
        (rp.frames.is_some(), "frames"),
    ] {
        only(present, name, PatchKind::Dynamic)?;
    }
    for (present, name) in [
        (rp.alpha.is_some(), "alpha"),
        (rp.trial.is_some(), "trial"),
        (rp.lmn.is_some(), "lmn"),
        (rp.w0.is_some(), "w0"),
        (rp.w0_tangent.is_some(), "w0_tangent"),
        (rp.w1.is_some(), "w1"),
        (rp.w1_tangent.is_some(), "w1_tangent"),
        (rp.cells.is_some(), "cells"),
        (rp.primary.is_some(), "primary"),
    ] {
        only(present, name, PatchKind::Solid)?;
    }
    for (present, name) in [
        (rp.edges.is_some(), "edges"),
        (rp.pole.is_some(), "pole"),
        (rp.height.is_some(), "height"),
        (rp.ring.is_some(), "ring"),
        (rp.corner_blend.is_some(), "corner_blend"),
        (rp.fullness.is_some(), "fullness"),
        (rp.order.is_some(), "order"),
        (rp.pole_curvature.is_some(), "pole_curvature"),
    ] {
        only(present, name, PatchKind::Fill)?;
    }
    if rp.trim.is_some() && matches!(kind, PatchKind::Dynamic | PatchKind::Solid | PatchKind::Fill) {
        return Err(ctx.err(
            span(p),
            format!("{key}.trim"),
            "trims apply to hermite, pde and blend patches (not to moving, solid or fill ones)",
        ));
    }
    if kind == PatchKind::Solid {
        for (present, name) in [(rp.conditions.is_some(), "conditions"), (rp.resolution.is_some(), "resolution")] {
            if present {
                return Err(ctx.err(
                    span(p),
                    format!("{key}.{name}"),
                    format!("a solid blend takes w0, w0_tangent, w1, w1_tangent and cells instead of `{name}`"),
                ));
            }
        }
        return build_solid(ctx, pname, &key, p);
    }
    if kind == PatchKind::Fill {
        return super::fill::build_fill(ctx, pname, &key, p, surfaces, done);
    }
    let domain = ctx.domain(&rp.v, &format!("{key}.v"))?;
    let resolution = ctx.resolution(&rp.resolution, (33, 65), &format!("{key}.resolution"))?;
    if rp.conditions.is_none() && rp.sections.is_none() && rp.start.is_none() && rp.end.is_none() {
        return Err(ctx.err(span(p), &key, "the patch has no `conditions` (and no `sections`, `start` or `end`)"));
    }
    let no_conds = Vec::new();
    let rconds_list = rp.conditions.as_ref().map(|c| c.get_ref()).unwrap_or(&no_conds);
    let conds_span = rp.conditions.as_ref().map(|c| c.span()).or(Some(p.span()));
    let mut conditions = Vec::new();
    let mut sections = None;
    if let Some(sec) = &rp.sections {
        let (c, fam) = build_sections(ctx, sec, domain, &format!("{key}.sections"))?;
        conditions.extend(c);
        sections = fam;
    }
    for (end_u, end, name) in [(0.0, &rp.start, "start"), (1.0, &rp.end, "end")] {
        let Some(e) = end else { continue };
        let ek = format!("{key}.{name}");
        let re = e.get_ref();
        let surf = find_surface(ctx, surfaces, &re.surface, &format!("{ek}.surface"))?;
        let s0 = ctx.num(re.s.get_ref(), span(&re.s), &format!("{ek}.s"))?;
        let scale = match &re.scale {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ek}.scale"))?,
            None => 1.0,
        };
        let top = if kind == PatchKind::Dynamic { 1 } else { 2 };
        for order in 0..=top {
            let data: FieldRef = Arc::new(Trimline::new(surf.field.clone(), s0, order, scale));
            check_data(ctx, &data, domain, span(e), &format!("{ek} (order {order})"))?;
            conditions.push(Condition { u: end_u, order, data });
        }
    }
    for (i, rc) in rconds_list.iter().enumerate() {
        let ck = format!("{key}.conditions[{i}]");
        let c = rc.get_ref();
        let u = ctx.num(c.u.get_ref(), span(&c.u), &format!("{ck}.u"))?;
        if !(0.0..=1.0).contains(&u) {
            return Err(ctx.err(span(&c.u), format!("{ck}.u"), format!("u = {u} is outside [0, 1]")));
        }
        let order = match &c.order {
            Some(o) => ctx.int(o, 0, 12, &format!("{ck}.order"))? as usize,
            None => 0,
        };
        let n_src = [c.curve.is_some(), c.expr.is_some(), c.point.is_some(), c.surface.is_some(), c.trim.is_some()]
            .iter()
            .filter(|b| **b)
            .count();
        if n_src != 1 {
            return Err(ctx.err(span(rc), &ck, "a condition needs exactly one of: curve, expr, point, surface, trim"));
        }
        if c.surface.is_none() && (c.s.is_some() || c.scale.is_some()) {
            return Err(ctx.err(span(rc), &ck, "`s` and `scale` only apply to trimline conditions (with `surface`)"));
        }
        let data: FieldRef = if let Some(n) = &c.curve {
            curves.get(n.get_ref()).cloned().ok_or_else(|| {
                ctx.err(
                    span(n),
                    format!("{ck}.curve"),
                    format!(
                        "unknown curve `{}` (defined: {})",
                        n.get_ref(),
                        if curves.is_empty() {
                            "none".to_string()
                        } else {
                            curves.keys().cloned().collect::<Vec<_>>().join(", ")
                        }
                    ),
                )
            })?
        } else if let Some(t) = &c.trim {
            super::trim::trim_condition(ctx, t, &format!("{ck}.trim"), done)?
        } else if let Some(x) = &c.expr {
            Arc::new(ctx.field(x, &["v", "t"], &format!("{ck}.expr"))?)
        } else if let Some(x) = &c.point {
            Arc::new(PointField { point: ctx.vec3(x.get_ref(), span(x), &format!("{ck}.point"))?, arity: 1 })
        } else {
            let sname = c.surface.as_ref().expect("counted above");
            let surf = find_surface(ctx, surfaces, sname, &format!("{ck}.surface"))?;
            let s = c.s.as_ref().ok_or_else(|| ctx.err(span(rc), &ck, "a trimline condition needs `s`"))?;
            let s0 = ctx.num(s.get_ref(), span(s), &format!("{ck}.s"))?;
            let scale = match &c.scale {
                Some(x) => ctx.num(x.get_ref(), span(x), &format!("{ck}.scale"))?,
                None => 1.0,
            };
            Arc::new(Trimline::new(surf.field.clone(), s0, order, scale))
        };
        check_data(ctx, &data, domain, span(rc), &ck)?;
        if matches!(kind, PatchKind::Blend | PatchKind::Dynamic)
            && conditions.iter().any(|o| o.u == u && o.order == order)
        {
            return Err(ctx.err(
                span(rc),
                &ck,
                format!("∂^{order}X/∂u^{order} at u = {u} is already given (by `start`/`end` or another condition)"),
            ));
        }
        conditions.push(Condition { u, order, data });
    }
    let mut spectral = None;
    let mut blend = None;
    let mut dynamic = None;
    let surface: Arc<dyn pdeshape_core::patch::Surface> = match kind {
        PatchKind::Hermite => Arc::new(
            HermitePatch::new(&conditions, domain)
                .map_err(|e| ctx.err(conds_span.clone(), format!("{key}.conditions"), e.to_string()))?,
        ),
        PatchKind::Pde => {
            let a = match &rp.a {
                Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.a"))?,
                None => 1.0,
            };
            let modes = match &rp.modes {
                Some(m) => ctx.capped(m, 0, Cap::Modes, &format!("{key}.modes"))?,
                None => 6,
            };
            let omega =
                rp.omega.as_ref().map(|x| ctx.num(x.get_ref(), span(x), &format!("{key}.omega"))).transpose()?;
            let what = format!("the PDE order (conditions of `{key}`)");
            ctx.cap(Cap::Order, conditions.len() as u128, conds_span.clone(), &format!("{key}.conditions"), &what)?;
            let sp = SpectralPatch::new(&conditions, domain, SpectralOptions { a, modes, omega })
                .map_err(|e| ctx.err(conds_span.clone(), format!("{key}.conditions"), e.to_string()))?;
            let sp = Arc::new(sp);
            spectral = Some(sp.clone());
            sp
        }
        PatchKind::Blend => {
            let setup = build_blend(ctx, &key, p, &conditions, domain, conds_span.clone())?;
            let b = setup.blend.clone();
            blend = Some(setup);
            b
        }
        PatchKind::Dynamic => {
            let setup = build_dynamic(ctx, &key, p, &conditions, domain, conds_span.clone())?;
            let f = setup
                .blend
                .frame(setup.times.0)
                .map_err(|e| ctx.err(conds_span.clone().or(Some(p.span())), &key, e.to_string()))?;
            dynamic = Some(setup);
            Arc::new(f)
        }
        PatchKind::Solid => unreachable!("solid patches are built by build_solid"),
        PatchKind::Fill => unreachable!("fills are built by fill::build_fill"),
    };
    let color = rp.color.as_ref().map(|c| *c.get_ref());
    let trim = rp.trim.as_ref().map(|t| super::trim::build_trim(ctx, &key, t, surface.as_ref())).transpose()?;
    Ok(ScenePatch {
        name: pname.to_string(),
        kind,
        surface,
        conditions,
        resolution,
        color,
        spectral,
        sections,
        blend,
        dynamic,
        solid: None,
        trim,
        fill: None,
    })
}

/// A solid blend (SPEC §6) from its four boundary surfaces.
fn build_solid(ctx: &Ctx, pname: &str, key: &str, p: &Spanned<RawPatch>) -> R<ScenePatch> {
    use pdeshape_core::solid::{SolidBlend, SolidOperator, SolidOptions, Trial};
    let rp = p.get_ref();
    let num = |x: &Option<Spanned<NumOrExpr>>, name: &str| -> R<f64> {
        match x {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.{name}")),
            None => Ok(1.0),
        }
    };
    let op = SolidOperator::new(num(&rp.alpha, "alpha")?, num(&rp.beta, "beta")?, num(&rp.gamma, "gamma")?)
        .map_err(|e| ctx.err(span(p), key, e.to_string()))?;
    let mut faces = Vec::with_capacity(4);
    for (f, name) in [(&rp.w0, "w0"), (&rp.w0_tangent, "w0_tangent"), (&rp.w1, "w1"), (&rp.w1_tangent, "w1_tangent")] {
        let f = f.as_ref().ok_or_else(|| {
            ctx.err(
                span(p),
                format!("{key}.{name}"),
                format!("a solid blend needs `{name}` (three expressions in u, v)"),
            )
        })?;
        let field: FieldRef = Arc::new(ctx.field(f, &["u", "v"], &format!("{key}.{name}"))?);
        for i in 0..=8 {
            for j in 0..=8 {
                let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                if !field.eval(&[u, v]).is_finite() {
                    return Err(ctx.err(
                        span(f),
                        format!("{key}.{name}"),
                        format!("not finite at (u, v) = ({u}, {v})"),
                    ));
                }
            }
        }
        faces.push(field);
    }
    let faces: [FieldRef; 4] = faces.try_into().expect("four faces");
    let mut opts = SolidOptions::default();
    if let Some(t) = &rp.trial {
        opts.trial = match t.get_ref().as_str() {
            "complete" => Trial::Complete,
            "galerkin" => Trial::Galerkin,
            "collocation" => Trial::Collocation,
            "paper" => Trial::Paper,
            w => {
                return Err(ctx.err(
                    span(t),
                    format!("{key}.trial"),
                    format!("unknown trial space `{w}` (known: complete, galerkin, collocation, paper)"),
                ));
            }
        };
    }
    if let Some(l) = &rp.lmn {
        let [a, b, c] = *l.get_ref();
        if [a, b, c].iter().any(|x| *x < 1) {
            return Err(ctx.err(span(l), format!("{key}.lmn"), format!("[{a}, {b}, {c}]: every count must be ≥ 1")));
        }
        let k = format!("{key}.lmn");
        ctx.cap(Cap::Modes, a.max(b).max(c) as u128, span(l), &k, &format!("the largest of [{a}, {b}, {c}] (`{k}`)"))?;
        opts.terms = (a as usize, b as usize, c as usize);
        ctx.cap(Cap::Collocation, opts.points(), span(l), &k, &format!("the point set of [{a}, {b}, {c}]"))?;
    }
    let cells = match &rp.cells {
        None => (17, 33, 17),
        Some(c) => {
            let [a, b, d] = *c.get_ref();
            if [a, b, d].iter().any(|x| *x < 2) {
                return Err(ctx.err(span(c), format!("{key}.cells"), format!("[{a}, {b}, {d}]: at least 2 each")));
            }
            let cells = a as u128 * b as u128 * d as u128;
            ctx.cap(Cap::Vertices, cells, span(c), &format!("{key}.cells"), &format!("cells [{a}, {b}, {d}]"))?;
            (a as usize, b as usize, d as usize)
        }
    };
    let primary = rp.primary.as_ref().map(|x| *x.get_ref()).unwrap_or(0.5);
    if !(primary.is_finite() && primary >= 0.0) {
        return Err(ctx.err(None, format!("{key}.primary"), format!("{primary} is not a non-negative number")));
    }
    let blend = Arc::new(SolidBlend::new(op, faces.clone(), opts).map_err(|e| ctx.err(span(p), key, e.to_string()))?);
    let surface = Arc::new(pdeshape_core::solid::SolidFace::section(blend.clone(), 2, 0.5));
    Ok(ScenePatch {
        name: pname.to_string(),
        kind: PatchKind::Solid,
        surface,
        conditions: vec![],
        resolution: (cells.0, cells.1),
        color: rp.color.as_ref().map(|c| *c.get_ref()),
        spectral: None,
        sections: None,
        blend: None,
        dynamic: None,
        solid: Some(super::SolidSetup { blend, faces, cells, primary }),
        trim: None,
        fill: None,
    })
}

/// The operator, options and basis of a dynamic blend (SPEC §5).
fn build_dynamic(
    ctx: &Ctx,
    key: &str,
    p: &Spanned<RawPatch>,
    conditions: &[Condition],
    domain: VDomain,
    conds_span: Option<Range<usize>>,
) -> R<super::DynamicSetup> {
    let rp = p.get_ref();
    let num = |x: &Option<Spanned<NumOrExpr>>, name: &str, default: f64| -> R<f64> {
        match x {
            Some(x) => ctx.num(x.get_ref(), span(x), &format!("{key}.{name}")),
            None => Ok(default),
        }
    };
    let op = DynamicOperator::new(
        num(&rp.beta, "beta", 1.0)?,
        num(&rp.gamma, "gamma", 2.0)?,
        num(&rp.lambda, "lambda", 1.0)?,
        num(&rp.rho, "rho", 0.0)?,
        num(&rp.eta, "eta", 0.0)?,
    )
    .map_err(|e| ctx.err(span(p), key, e.to_string()))?;
    let times = match &rp.time {
        None => (0.0, 1.0),
        Some(r) => ctx.range(r, &format!("{key}.time"))?,
    };
    let frames = match &rp.frames {
        None => 11,
        Some(f) => ctx.int(f, 2, 1000, &format!("{key}.frames"))? as usize,
    };
    let mut opts = DynamicOptions { times, limits: ctx.limits, ..Default::default() };
    if let Some(sv) = ctx.solver_choice(&rp.solver, key)? {
        opts.solver = sv;
    }
    if let Some(k) = &rp.terms {
        opts.terms = ctx.capped(k, 1, Cap::Modes, &format!("{key}.terms"))?;
    }
    if let Some(k) = ctx.terms {
        ctx.cap(Cap::Modes, k as u128, None, "--terms", "the sine terms K")?;
        opts.terms = k;
    }
    if let Some(c) = &rp.collocation {
        let [l, m] = *c.get_ref();
        if l < 2 || m < 1 {
            return Err(ctx.err(
                span(c),
                format!("{key}.collocation"),
                format!("[{l}, {m}] is too small (at least [2, 1])"),
            ));
        }
        let k = format!("{key}.collocation");
        ctx.cap(Cap::Collocation, l as u128 * m as u128, span(c), &k, &format!("the collocation grid [{l}, {m}]"))?;
        opts.collocation = (l as usize, m as usize);
    }
    opts.joint = rp.joint.as_ref().map(|j| *j.get_ref()).unwrap_or(false);
    if let Some(list) = &rp.basis {
        let exprs = ctx.basis_exprs(list, key, &["v", "t"])?;
        opts.basis = Some(exprs.into_iter().map(|(expr, text)| DynBasis::Expr { expr, text }).collect());
    }
    let blend = DynamicBlend::new(op, conditions, domain, &opts)
        .map_err(|e| ctx.err(conds_span.or(Some(p.span())), key, e.to_string()))?;
    Ok(super::DynamicSetup { blend: Arc::new(blend), times, frames })
}

/// Operators, options and the solve of a static blend (SPEC §4).
fn build_blend(
    ctx: &Ctx,
    key: &str,
    p: &Spanned<RawPatch>,
    conditions: &[Condition],
    domain: VDomain,
    conds_span: Option<Range<usize>>,
) -> R<super::BlendSetup> {
    let rp = p.get_ref();
    let orders: [usize; 3] = match &rp.orders {
        None => [4, 4, 4],
        Some(o) => {
            let mut out = [0; 3];
            for (t, &x) in o.get_ref().iter().enumerate() {
                if ![2, 4, 6].contains(&x) {
                    return Err(ctx.err(
                        span(o),
                        format!("{key}.orders[{t}]"),
                        format!("order {x} is not available (static blends have order 2, 4 or 6 per component)"),
                    ));
                }
                out[t] = x as usize;
            }
            out
        }
    };
    let mut ops = Vec::with_capacity(3);
    for t in 0..3 {
        let r = orders[t] / 2;
        let op = match &rp.coefficients {
            None => Operator::laplacian_power(r),
            Some(c) => {
                let list = &c.get_ref()[t];
                let ck = format!("{key}.coefficients[{t}]");
                if list.len() != r + 1 {
                    return Err(ctx.err(
                        span(c),
                        &ck,
                        format!(
                            "component {} has order {}: it takes {} shape coefficients, {} given",
                            ["x", "y", "z"][t],
                            2 * r,
                            r + 1,
                            list.len()
                        ),
                    ));
                }
                let vals = list.iter().map(|x| ctx.num(x, span(c), &ck)).collect::<R<Vec<f64>>>()?;
                Operator::new(vals).map_err(|e| ctx.err(span(c), &ck, e.to_string()))?
            }
        };
        ops.push(op);
    }
    let ops: [Operator; 3] = ops.try_into().expect("three operators");
    let mut options = BlendOptions { limits: ctx.limits, ..Default::default() };
    if let Some(sv) = ctx.solver_choice(&rp.solver, key)? {
        options.solver = sv;
    }
    if let Some(b) = &rp.bubbles {
        options.bubbles = ctx.capped(b, 1, Cap::Modes, &format!("{key}.bubbles"))?;
    }
    if let Some(c) = &rp.collocation {
        let [l, q] = *c.get_ref();
        if l < 1 || q < 1 {
            return Err(ctx.err(
                span(c),
                format!("{key}.collocation"),
                format!("[{l}, {q}] is too small (at least 1 each)"),
            ));
        }
        let k = format!("{key}.collocation");
        ctx.cap(Cap::Collocation, l as u128 * q as u128, span(c), &k, &format!("the collocation grid [{l}, {q}]"))?;
        options.collocation = Some((l as usize, q as usize));
    }
    if let Some(list) = &rp.basis {
        let exprs = ctx.basis_exprs(list, key, &["v"])?;
        options.basis = Some(exprs.into_iter().map(|(expr, text)| BasisFn::Expr { expr, text }).collect());
    }
    let blend = StaticBlend::new(ops, conditions, domain, &options)
        .map_err(|e| ctx.err(conds_span.or(Some(p.span())), key, e.to_string()))?;
    Ok(super::BlendSetup { blend: Arc::new(blend), options })
}

/// Expands `[patches.NAME.sections]` into position conditions.
fn build_sections(
    ctx: &Ctx,
    sec: &Spanned<RawSections>,
    domain: VDomain,
    key: &str,
) -> R<(Vec<Condition>, Option<super::SectionFamily>)> {
    let rs = sec.get_ref();
    let count = ctx.capped(&rs.count, 2, Cap::Order, &format!("{key}.count"))?;
    let us: Vec<f64> = match (&rs.u, &rs.spacing) {
        (Some(_), Some(sp)) => {
            return Err(ctx.err(span(sp), format!("{key}.spacing"), "give either `spacing` or explicit `u`, not both"));
        }
        (Some(list), None) => {
            if list.get_ref().len() != count {
                return Err(ctx.err(
                    span(list),
                    format!("{key}.u"),
                    format!("{} values for {count} sections", list.get_ref().len()),
                ));
            }
            for &u in list.get_ref() {
                if !(0.0..=1.0).contains(&u) {
                    return Err(ctx.err(span(list), format!("{key}.u"), format!("u = {u} is outside [0, 1]")));
                }
            }
            list.get_ref().clone()
        }
        (None, sp) => {
            let word = sp.as_ref().map(|s| s.get_ref().as_str()).unwrap_or("chebyshev");
            let m = (count - 1) as f64;
            match word {
                "uniform" => (0..count).map(|i| i as f64 / m).collect(),
                "chebyshev" => (0..count).map(|i| (1.0 - (std::f64::consts::PI * i as f64 / m).cos()) / 2.0).collect(),
                w => {
                    return Err(ctx.err(
                        sp.as_ref().and_then(span),
                        format!("{key}.spacing"),
                        format!("unknown spacing `{w}` (expected \"uniform\", \"chebyshev\" or explicit u = [...])"),
                    ));
                }
            }
        }
    };
    let s_text = rs.s.as_ref().map(|s| s.get_ref().clone()).unwrap_or_else(|| "i".into());
    let s_span = rs.s.as_ref().and_then(span);
    let s_expr = Expr::parse(&s_text).map_err(|e| ctx.expr_err(s_span.clone(), format!("{key}.s"), &s_text, &e))?;
    let texts = rs.expr.get_ref().each_ref().map(NumOrExpr::text);
    let parsed: Vec<Expr> = texts
        .iter()
        .enumerate()
        .map(|(k, t)| Expr::parse(t).map_err(|e| ctx.expr_err(span(&rs.expr), format!("{key}.expr[{k}]"), t, &e)))
        .collect::<R<_>>()?;
    let mut out = Vec::with_capacity(count);
    let mut ss = Vec::with_capacity(count);
    for (i, &u) in us.iter().enumerate() {
        let idx = i as f64;
        let lookup_i = |n: &str| {
            if n == "i" {
                Some(idx)
            } else if n == "count" {
                Some(count as f64)
            } else {
                ctx.params.get(n).map(|p| p.value)
            }
        };
        let s_i = s_expr
            .bind(&[], &lookup_i)
            .map_err(|e| ctx.expr_err(s_span.clone(), format!("{key}.s"), &s_text, &e))?
            .eval(&[]);
        if !s_i.is_finite() {
            return Err(ctx.err(s_span.clone(), format!("{key}.s"), format!("s is not finite for section {i}")));
        }
        let lookup = |n: &str| if n == "s" { Some(s_i) } else { lookup_i(n) };
        let comps: Vec<Expr> = parsed
            .iter()
            .enumerate()
            .map(|(k, e)| {
                e.bind(&["v", "t"], &lookup)
                    .map_err(|er| ctx.expr_err(span(&rs.expr), format!("{key}.expr[{k}]"), &texts[k], &er))
            })
            .collect::<R<_>>()?;
        let comps: [Expr; 3] =
            comps.try_into().map_err(|_| ctx.err(span(&rs.expr), key, "three components expected"))?;
        let data: FieldRef = Arc::new(ExprField::from_exprs(comps, &["v", "t"]));
        check_data(ctx, &data, domain, span(sec), &format!("{key} (section {i}, s = {s_i})"))?;
        out.push(Condition { u, order: 0, data });
        ss.push(s_i);
    }
    // The reference family C(v; s), when the curve depends on the index only through s.
    let spacing = match (&rs.u, rs.spacing.as_ref().map(|s| s.get_ref().as_str())) {
        (Some(_), _) => super::Spacing::Explicit,
        (None, Some("uniform")) => super::Spacing::Uniform,
        _ => super::Spacing::Chebyshev,
    };
    let s_of_index = s_expr
        .bind(&["i"], &|n| if n == "count" { Some(count as f64) } else { ctx.params.get(n).map(|p| p.value) })
        .ok();
    let family = parsed
        .iter()
        .map(|e| {
            e.bind(&["v", "t", "s"], &|n| {
                if n == "count" { Some(count as f64) } else { ctx.params.get(n).map(|p| p.value) }
            })
            .ok()
        })
        .collect::<Option<Vec<Expr>>>()
        .and_then(|v| <[Expr; 3]>::try_from(v).ok())
        .filter(|_| us.windows(2).all(|w| w[0] < w[1]))
        .zip(s_of_index)
        .map(|(comps, s_of_index)| super::SectionFamily {
            us: us.clone(),
            ss,
            spacing,
            s_of_index,
            curve: Arc::new(ExprField::from_exprs(comps, &["v", "t", "s"])),
        });
    Ok((out, family))
}

/// Checks that condition data are finite on the domain and, for a periodic patch, closed.
fn check_data(ctx: &Ctx, data: &FieldRef, domain: VDomain, sp: Option<Range<usize>>, key: &str) -> R<()> {
    for k in 0..=64 {
        let v = domain.at(k as f64 / 64.0);
        let g = data.eval(&[v, 0.0]);
        if !g.is_finite() {
            return Err(ctx.err(
                sp,
                key,
                format!(
                    "the data are not finite at v = {} (value {g})",
                    if v.abs() < 1e6 { format!("{v:.6}") } else { format!("{v:.6e}") }
                ),
            ));
        }
    }
    if domain.periodic {
        let (a, b) = (data.eval(&[domain.start, 0.0]), data.eval(&[domain.end, 0.0]));
        let (da, db) = (
            curve_derivative(data.as_ref(), domain.start, 0.0, 1),
            curve_derivative(data.as_ref(), domain.end, 0.0, 1),
        );
        let scale = 1.0 + a.norm().max(b.norm());
        let dscale = 1.0 + da.norm().max(db.norm());
        if (a - b).norm() > 1e-9 * scale || (da - db).norm() > 1e-7 * dscale {
            return Err(ctx.err(
                sp,
                key,
                format!(
                    "the data are not periodic on [{:.6}, {:.6}] (value gap {:.3e}, slope gap {:.3e}) but the patch is: \
                     use a closed curve, or make the patch open with v = [v0, v1]",
                    domain.start,
                    domain.end,
                    (a - b).norm(),
                    (da - db).norm()
                ),
            ));
        }
    }
    Ok(())
}
