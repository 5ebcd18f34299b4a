//! Resolution of a raw scene into core objects, with located errors.

use super::ctx::{Ctx, R, find_surface, is_reserved, span, toml_error};
use super::error::Source;
use super::nurbs;
use super::raw::*;
use super::{Param, RenderSettings, Scene, SceneSurface};
use indexmap::IndexMap;
use pdeshape_core::Vec3;
use pdeshape_core::blend::Solver;
use pdeshape_core::data::{BSplineCurve, Combination, FieldRef, PointField, Trimline};
use pdeshape_core::expr::{BinOp, Expr, Node};
use pdeshape_core::limits::Cap;
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;
use toml::Spanned;

/// Output formats a scene may list.
pub const FORMATS: &[&str] = &["obj", "ply", "stl", "glb", "vtu", "png"];

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
        only_for(c.bspline.is_none() && c.knots.is_some(), "knots", "bspline")?;
        only_for(c.bspline.is_none() && c.weights.is_some(), "weights", "bspline")?;
        if c.closed == Some(true) && (c.knots.is_some() || c.weights.is_some()) {
            return Err(ctx.err(
                span(rc),
                key,
                "`knots` and `weights` apply to open B-splines (a closed one has uniform knots)",
            ));
        }
        if let (Some(k), Some(_)) = (&c.knots, &c.range) {
            return Err(ctx.err(span(k), key, "give `knots` or `range`, not both: the knots are the parameter"));
        }
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
            if c.knots.is_some() || c.weights.is_some() {
                let given = c.degree.as_ref().map(|_| degree);
                let range = c.range.as_ref().map(|_| range);
                let curve = nurbs::curve(ctx, key, c, (&points, span(pts)), given, range)?;
                return Ok(Arc::new(curve));
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
    let mut ctx = Ctx {
        src: src.clone(),
        params: IndexMap::new(),
        solver,
        terms: opts.terms,
        limits: opts.limits,
        imports: Vec::new(),
    };
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
    for (n, i) in &raw.import {
        check_name(&src, n, span(i), &format!("import.{n}"), &mut taken)?;
    }
    let mut patch_names: HashMap<String, String> = HashMap::new();
    for (n, p) in &raw.patches {
        check_name(&src, n, span(p), &format!("patches.{n}"), &mut patch_names)?;
    }
    build_params(&mut ctx, &raw.parameters, overrides)?;
    ctx.imports = super::import::read_imports(&ctx, &raw.import, &opts.imports)?;

    let mut surfaces = Vec::new();
    for (n, s) in &raw.surfaces {
        let key = format!("surfaces.{n}");
        let rs = s.get_ref();
        let (field, domain): (FieldRef, _) = match (&rs.expr, &rs.bspline) {
            (Some(x), None) => {
                for (given, what) in
                    [(rs.degree.is_some(), "degree"), (rs.knots.is_some(), "knots"), (rs.weights.is_some(), "weights")]
                {
                    if given {
                        return Err(ctx.err(span(s), &key, format!("`{what}` only applies to bspline surfaces")));
                    }
                }
                let field = Arc::new(ctx.field(x, &["s", "v", "t"], &format!("{key}.expr"))?);
                (field, ctx.domain(&rs.v, &format!("{key}.v"))?)
            }
            (None, Some(_)) => {
                if let Some(v) = &rs.v {
                    return Err(ctx.err(span(v), format!("{key}.v"), "a bspline surface's v domain is its knot range"));
                }
                let (surface, domain) = nurbs::surface(&ctx, &key, rs)?;
                (Arc::new(surface), domain)
            }
            (x, _) => {
                let msg = if x.is_some() {
                    "the surface has several definitions (expr, bspline); give exactly one"
                } else {
                    "the surface has no definition (expected one of: expr, bspline)"
                };
                return Err(ctx.err(span(s), &key, msg));
            }
        };
        let s_range = rs.s_range.as_ref().map(|r| ctx.range(r, &format!("{key}.s_range"))).transpose()?;
        let resolution = ctx.resolution(&rs.resolution, (17, 65), &format!("{key}.resolution"))?;
        surfaces.push(SceneSurface { name: n.clone(), field, s_range, domain, resolution });
    }
    surfaces.extend(super::import::import_surfaces(&ctx.imports));

    let mut cb =
        CurveBuilder { ctx: &ctx, raw: &raw.curves, surfaces: &surfaces, done: IndexMap::new(), busy: Vec::new() };
    for n in raw.curves.keys() {
        cb.get(n)?;
    }
    let curves: IndexMap<String, FieldRef> = raw.curves.keys().map(|n| (n.clone(), cb.done[n].clone())).collect();

    let mut patches = Vec::new();
    let mut bytes = 0u128;
    for (pname, p) in &raw.patches {
        let built = super::kinds::build_patch(&ctx, pname, p, &curves, &surfaces, &patches)?;
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
        imports: ctx.imports,
        curves,
        surfaces,
        patches,
        render,
        formats,
        studies,
        options: opts.clone(),
    })
}
