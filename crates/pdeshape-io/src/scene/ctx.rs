//! What every part of a scene is built with: the source (for errors with file, line,
//! column and key), the resolved parameters, the command line's overrides and the caps;
//! numbers, vectors, expressions, domains and resolutions read from raw TOML values; the
//! check of condition data.

use crate::scene::error::{SceneError, Source};
use crate::scene::raw::*;
use crate::scene::{Param, SceneSurface};
use indexmap::IndexMap;
use pdeshape_core::Vec3;
use pdeshape_core::blend::Solver;
use pdeshape_core::data::{ExprField, FieldRef, curve_derivative};
use pdeshape_core::expr::{Expr, ExprError, Func};
use pdeshape_core::limits::{Cap, Limits};
use pdeshape_core::patch::VDomain;
use std::ops::Range;
use toml::Spanned;

/// Names that parameters, curves and surfaces may not take: variables, constants and
/// function names of the expression language.
pub const RESERVED: &[&str] = &["u", "v", "w", "s", "t", "pi", "e", "log"];

pub(in crate::scene) type R<T> = Result<T, SceneError>;

pub(in crate::scene) struct Ctx<'a> {
    pub(in crate::scene) src: Source<'a>,
    pub(in crate::scene) params: IndexMap<String, Param>,
    /// Solver override for patches that offer a choice.
    pub(in crate::scene) solver: Option<Solver>,
    /// Override of the sine-term count of dynamic blends.
    pub(in crate::scene) terms: Option<usize>,
    /// Caps on sizes.
    pub(in crate::scene) limits: Limits,
    /// The models of `[import.*]`, read.
    pub(in crate::scene) imports: Vec<crate::scene::SceneImport>,
}

pub(in crate::scene) fn span<T>(s: &Spanned<T>) -> Option<Range<usize>> {
    Some(s.span())
}

/// The surface `name` refers to; an unknown name is an error at `key` listing the defined
/// surfaces.
pub(in crate::scene) fn find_surface<'s>(
    ctx: &Ctx,
    surfaces: &'s [SceneSurface],
    name: &Spanned<String>,
    key: &str,
) -> R<&'s SceneSurface> {
    surfaces.iter().find(|s| s.name == *name.get_ref()).ok_or_else(|| {
        // a model's faces may number thousands: the first few, and how many more
        const SHOWN: usize = 24;
        let known: Vec<&str> = surfaces.iter().take(SHOWN).map(|s| s.name.as_str()).collect();
        let more = surfaces.len().saturating_sub(SHOWN);
        let list = match (known.is_empty(), more) {
            (true, _) => "none".to_string(),
            (false, 0) => known.join(", "),
            (false, m) => format!("{} and {m} more", known.join(", ")),
        };
        ctx.err(span(name), key, format!("unknown surface `{}` (defined: {list})", name.get_ref()))
    })
}

pub(in crate::scene) fn is_reserved(name: &str) -> bool {
    RESERVED.contains(&name) || Func::from_name(name).is_some()
}

pub(in crate::scene) fn toml_error(src: &Source, e: toml::de::Error) -> SceneError {
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
    pub(in crate::scene) fn expr_err(
        &self,
        sp: Option<Range<usize>>,
        key: impl Into<String>,
        text: &str,
        e: &ExprError,
    ) -> SceneError {
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

    pub(in crate::scene) fn err(
        &self,
        span: Option<Range<usize>>,
        key: impl Into<String>,
        msg: impl Into<String>,
    ) -> SceneError {
        self.src.error(span, key, msg)
    }

    /// The solver of a blend: the command line's override, else the scene's `solver`.
    pub(in crate::scene) fn solver_choice(&self, raw: &Option<Spanned<String>>, key: &str) -> R<Option<Solver>> {
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
    pub(in crate::scene) fn basis_exprs(
        &self,
        list: &Spanned<Vec<Spanned<String>>>,
        key: &str,
        vars: &[&str],
    ) -> R<Vec<(Expr, String)>> {
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

    pub(in crate::scene) fn param_lookup(&self) -> impl Fn(&str) -> Option<f64> + '_ {
        |n: &str| self.params.get(n).map(|p| p.value)
    }

    /// A constant: a number or an expression in the parameters.
    pub(in crate::scene) fn num(&self, x: &NumOrExpr, sp: Option<Range<usize>>, key: &str) -> R<f64> {
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

    pub(in crate::scene) fn vec3(&self, x: &[NumOrExpr; 3], sp: Option<Range<usize>>, key: &str) -> R<Vec3> {
        Ok(Vec3::new(self.num(&x[0], sp.clone(), key)?, self.num(&x[1], sp.clone(), key)?, self.num(&x[2], sp, key)?))
    }

    pub(in crate::scene) fn field(&self, x: &Spanned<[NumOrExpr; 3]>, vars: &[&str], key: &str) -> R<ExprField> {
        let texts = x.get_ref().each_ref().map(NumOrExpr::text);
        ExprField::parse([&texts[0], &texts[1], &texts[2]], vars, &self.param_lookup())
            .map_err(|(i, e)| self.expr_err(span(x), format!("{key}[{i}]"), &texts[i], &e))
    }

    /// A plane curve: two expressions (the third component is 0).
    pub(in crate::scene) fn field2(&self, x: &Spanned<[NumOrExpr; 2]>, vars: &[&str], key: &str) -> R<ExprField> {
        let texts = x.get_ref().each_ref().map(NumOrExpr::text);
        ExprField::parse([&texts[0], &texts[1], "0"], vars, &self.param_lookup())
            .map_err(|(i, e)| self.expr_err(span(x), format!("{key}[{i}]"), &texts[i.min(1)], &e))
    }

    pub(in crate::scene) fn int(&self, x: &Spanned<i64>, lo: i64, hi: i64, key: &str) -> R<i64> {
        let v = *x.get_ref();
        if v < lo || v > hi {
            return Err(self.err(span(x), key, format!("{v} is out of range (expected {lo} … {hi})")));
        }
        Ok(v)
    }

    /// An integer `≥ lo` within `cap`.
    pub(in crate::scene) fn capped(&self, x: &Spanned<i64>, lo: i64, cap: Cap, key: &str) -> R<usize> {
        let v = *x.get_ref();
        if v < lo {
            return Err(self.err(span(x), key, format!("{v} is too small (expected at least {lo})")));
        }
        self.cap(cap, v as u128, span(x), key, &format!("`{key}`"))?;
        Ok(v as usize)
    }

    /// `value` checked against `cap`; the error names the place, the cap and how to raise it.
    pub(in crate::scene) fn cap(
        &self,
        cap: Cap,
        value: u128,
        sp: Option<Range<usize>>,
        key: &str,
        what: &str,
    ) -> R<()> {
        self.limits.check(cap, value, what).map_err(|e| self.err(sp, key, e.to_string()))
    }

    pub(in crate::scene) fn range(&self, x: &Spanned<[NumOrExpr; 2]>, key: &str) -> R<(f64, f64)> {
        let a = self.num(&x.get_ref()[0], span(x), key)?;
        let b = self.num(&x.get_ref()[1], span(x), key)?;
        if b <= a {
            return Err(self.err(span(x), key, format!("empty range [{a}, {b}] (expected start < end)")));
        }
        Ok((a, b))
    }

    pub(in crate::scene) fn domain(&self, x: &Option<Spanned<RawDomain>>, key: &str) -> R<VDomain> {
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

    pub(in crate::scene) fn resolution(
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

/// Checks that condition data are finite on the domain and, for a periodic patch, closed.
pub(in crate::scene) fn check_data(
    ctx: &Ctx,
    data: &FieldRef,
    domain: VDomain,
    sp: Option<Range<usize>>,
    key: &str,
) -> R<()> {
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
