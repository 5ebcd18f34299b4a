//! Scene resolution: parameters, curve kinds, trimlines, overrides.

use super::*;
use pdeshape_core::Vec3;
use pdeshape_core::data::curve_derivative;
use pdeshape_core::jet::JetShape;

fn parse(text: &str) -> Scene {
    Scene::parse(text, "test.toml", "test", &HashMap::new()).unwrap_or_else(|e| panic!("{e}"))
}

const BASE: &str = r#"
[parameters]
r = 2.0
d = "3*r - 1"
h = { value = 0.5, min = 0, max = 1 }

[surfaces.cyl]
expr = ["r*cos(v)", "r*sin(v)", "s^2"]

[curves.c]
expr = ["d*cos(v)", "d*sin(v)", "h"]

[curves.p]
point = [0, 0, "h + 1"]

[curves.lin]
combine = "2*(c - p) + p/2"

[curves.tg]
surface = "cyl"
s = 1.5
derivative = 1
scale = -2

[patches.x]
kind = "hermite"
conditions = [{ u = 0, curve = "c" }, { u = 1, curve = "tg" }]
"#;

#[test]
fn derived_parameters_and_overrides() {
    let s = parse(BASE);
    assert_eq!(s.params["d"].value, 5.0);
    assert_eq!(s.params["d"].expr.as_deref(), Some("3*r - 1"));
    assert_eq!((s.params["h"].min, s.params["h"].max), (Some(0.0), Some(1.0)));
    let o = Scene::parse(BASE, "t", "t", &HashMap::from([("r".to_string(), 1.0)])).unwrap();
    assert_eq!(o.params["d"].value, 2.0, "derived parameters follow overrides");
}

#[test]
fn combinations_and_trimlines_evaluate_exactly() {
    let s = parse(BASE);
    let v = 0.7f64;
    let c = Vec3::new(5.0 * v.cos(), 5.0 * v.sin(), 0.5);
    let p = Vec3::new(0.0, 0.0, 1.5);
    let lin = s.curves["lin"].eval(&[v, 0.0]);
    assert!((lin - ((c - p) * 2.0 + p * 0.5)).norm() < 1e-14);
    // t = −2 ∂S/∂s at s = 1.5: (0, 0, −2·2s) = (0, 0, −6); its v-derivative is zero
    let t = s.curves["tg"].eval(&[v, 0.0]);
    assert!((t - Vec3::new(0.0, 0.0, -6.0)).norm() < 1e-14);
    assert!(curve_derivative(s.curves["tg"].as_ref(), v, 0.0, 2).norm() < 1e-14);
    // the position trimline keeps v-derivatives: d²/dv² of (r cos v, r sin v) = −(r cos v, r sin v)
    let j = s.curves["c"].jet(&[v, 0.0], JetShape::new(&[2]));
    assert!((j.derivative([2, 0, 0]) + Vec3::new(5.0 * v.cos(), 5.0 * v.sin(), 0.0)).norm() < 1e-13);
}

#[test]
fn parameters_keep_file_order() {
    let s = parse(BASE);
    assert_eq!(s.params.keys().collect::<Vec<_>>(), ["r", "d", "h"]);
}

/// A scene keeps the options it was resolved with, so that re-solves (parameter studies)
/// keep its caps, solver and terms.
#[test]
fn a_scene_carries_its_load_options() {
    let limits = pdeshape_core::limits::Limits { order: 12, ..Default::default() };
    let opts = LoadOptions { limits, solver: Some("collocation".into()), ..Default::default() };
    let sc = Scene::parse_with(BASE, "t", "t", &opts).unwrap();
    assert_eq!(sc.options.limits, limits);
    assert_eq!(sc.options.solver.as_deref(), Some("collocation"));
}

/// Every key of a patch is checked against its kind's declared keys: keys a kind used to
/// ignore without a word (`v` or `sections` on a solid or a fill) are errors naming the
/// kinds they apply to; keys with a reason of their own keep it.
#[test]
fn each_kind_takes_only_its_own_keys() {
    let solid = "[patches.q]\nkind = \"solid\"\nw0 = [\"u\", \"v\", \"0\"]\nw0_tangent = [\"0\", \"0\", \"1\"]\n\
                 w1 = [\"u\", \"v\", \"1\"]\nw1_tangent = [\"0\", \"0\", \"1\"]\n";
    let err = |text: &str| Scene::parse(text, "t.toml", "t", &HashMap::new()).err().map(|e| e.to_string());
    assert!(err(solid).is_none(), "{:?}", err(solid));
    let cases = [
        ("v = [0, 1]\n", "patches.q.v", "`v` only applies to kind = \"hermite\", \"pde\", \"blend\" or \"dynamic\""),
        ("modes = 3\n", "patches.q.modes", "`modes` only applies to kind = \"pde\" or \"fill\""),
        ("orders = [2, 2, 2]\n", "patches.q.orders", "`orders` only applies to kind = \"blend\""),
        (
            "conditions = []\n",
            "patches.q.conditions",
            "a solid blend takes w0, w0_tangent, w1, w1_tangent and cells instead of `conditions`",
        ),
    ];
    for (extra, key, msg) in cases {
        let e = err(&format!("{solid}{extra}")).unwrap_or_else(|| panic!("{extra}: accepted"));
        assert!(e.contains(key) && e.contains(msg), "{extra}: {e}");
    }
}

/// Every optional key of a raw patch is declared by some kind (or refused by one with a
/// reason), so the key check cannot send a valid key to "no kind".
#[test]
fn every_patch_key_belongs_to_a_kind() {
    let mut declared: Vec<&str> = vec!["kind", "color"];
    for k in kinds::KINDS {
        declared.extend(k.keys);
    }
    for name in raw::RawPatch::KEYS {
        assert!(declared.contains(name), "`{name}` is taken by no kind");
    }
}

/// A kind's name in scene files (its module's), in reports (`PatchKind`'s serialisation)
/// and in `kind = "…"` are one: every registered kind parses under its name and reports it.
#[test]
fn kind_names_agree() {
    for k in kinds::KINDS {
        assert_eq!(k.kind.name(), k.name);
        assert_eq!(serde_json::to_value(k.kind).unwrap(), serde_json::json!(k.name));
    }
    assert_eq!(kinds::KINDS.len(), 6);
}

/// The full unit circle as a rational quadratic B-spline of nine control points (the
/// square's corners weighted √2/2, The NURBS Book Ex. 7.2) with the knots
/// 0 0 0 ¼ ¼ ½ ½ ¾ ¾ 1 1 1: on the circle at every parameter, through (0, 1) at ¼, (−1, 0)
/// at ½ and (0, −1) at ¾, its tangent square to its radius, and its derivative at 0 the
/// closed form 2w(P₁ − P₀)/(h w₀) = (0, 4·√2/2·√2/2 … ) worked out below.
#[test]
fn a_rational_curve_with_given_knots_is_the_circle() {
    let s = parse(
        r#"
[curves.circle]
bspline = [[1, 0, 0], [1, 1, 0], [0, 1, 0], [-1, 1, 0], [-1, 0, 0], [-1, -1, 0], [0, -1, 0], [1, -1, 0], [1, 0, 0]]
knots = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
weights = [1, "sqrt(2)/2", 1, "sqrt(2)/2", 1, "sqrt(2)/2", 1, "sqrt(2)/2", 1]
degree = 2

[patches.x]
kind = "hermite"
v = [0, 1]
conditions = [{ u = 0, curve = "circle" }, { u = 1, point = [0, 0, 1] }]
"#,
    );
    let c = s.curves["circle"].as_ref();
    for (v, want) in [(0.25, [0.0, 1.0]), (0.5, [-1.0, 0.0]), (0.75, [0.0, -1.0]), (1.0, [1.0, 0.0])] {
        let p = c.eval(&[v, 0.0]);
        // a knot of multiplicity 2 = degree: the point is the control point, up to the
        // round-off of √2/2 in the weights' quotient
        assert!((p - Vec3::new(want[0], want[1], 0.0)).norm() < 1e-15, "v {v}: {p}");
    }
    for i in 0..=200 {
        let v = i as f64 / 200.0;
        let j = c.jet(&[v, 0.0], JetShape::new(&[1]));
        let (p, d) = (j.value(), j.derivative([1, 0, 0]));
        // |C| = 1 and C·C' = 0 (the radius is constant), to round-off of values ≤ 1 and
        // derivatives ≤ 8
        assert!((p.norm() - 1.0).abs() < 4e-16 && p.z == 0.0, "v {v}: |C| = {}", p.norm());
        assert!(p.dot(d).abs() < 4e-15, "v {v}: C·C' = {}", p.dot(d));
    }
    // C'(0) = p/(τ₃ − τ₁) · (w₁/w₀)(P₁ − P₀) = 2/0.25 · (√2/2) · (0, 1, 0) = (0, 4√2, 0)
    let d0 = curve_derivative(c, 0.0, 0.0, 1);
    assert!((d0 - Vec3::new(0.0, 4.0 * 2f64.sqrt(), 0.0)).norm() < 1e-14, "{d0}");
}

/// A net with non-uniform knots whose control points sit at the Greville abscissae
/// `(ξᵢ, ηⱼ, ξᵢ + 2ηⱼ)` is the plane `S(s, v) = (s, v, s + 2v)` exactly (linear
/// precision); a trimline of it at s = 0.3 is `(0.3, v, 0.3 + 2v)`, its cross derivative
/// `(1, 0, 1)`, its second zero, and the surface's v domain is its knot range.
#[test]
fn a_bspline_net_with_given_knots_is_exact_on_a_plane() {
    let ku = [0.0, 0.0, 0.0, 0.2, 0.7, 1.0, 1.0, 1.0];
    let kv = [-1.0, -1.0, -1.0, -1.0, 0.5, 2.0, 2.0, 2.0, 2.0];
    let greville = |k: &[f64], p: usize| -> Vec<f64> {
        (0..k.len() - p - 1).map(|i| k[i + 1..=i + p].iter().sum::<f64>() / p as f64).collect()
    };
    let (xi, eta) = (greville(&ku, 2), greville(&kv, 3));
    let rows: Vec<String> = xi
        .iter()
        .map(|x| {
            let row: Vec<String> = eta.iter().map(|y| format!("[{x:?}, {y:?}, {:?}]", x + 2.0 * y)).collect();
            format!("[{}]", row.join(", "))
        })
        .collect();
    let text = format!(
        r#"
[surfaces.plane]
bspline = [{}]
degree = [2, 3]
knots = [{ku:?}, {kv:?}]

[curves.edge]
surface = "plane"
s = 0.3

[curves.across]
surface = "plane"
s = 0.3
derivative = 1

[curves.bend]
surface = "plane"
s = 0.3
derivative = 2

[patches.x]
kind = "hermite"
v = [-1, 2]
conditions = [{{ u = 0, curve = "edge" }}, {{ u = 1, point = [0, 0, 1] }}]
"#,
        rows.join(", ")
    );
    let s = parse(&text);
    assert_eq!(s.surfaces[0].domain, VDomain::open(-1.0, 2.0));
    for i in 0..=60 {
        let v = -1.0 + 3.0 * i as f64 / 60.0;
        let e = s.curves["edge"].eval(&[v, 0.0]);
        // values ≤ 4.3: a few ulps
        assert!((e - Vec3::new(0.3, v, 0.3 + 2.0 * v)).norm() < 4e-15, "v {v}: {e}");
        let a = s.curves["across"].eval(&[v, 0.0]);
        assert!((a - Vec3::new(1.0, 0.0, 1.0)).norm() < 2e-14, "v {v}: {a}");
        assert!(s.curves["bend"].eval(&[v, 0.0]).norm() < 1e-13, "v {v}");
        // ∂/∂v of the edge: (0, 1, 2)
        let dv = curve_derivative(s.curves["edge"].as_ref(), v, 0.0, 1);
        assert!((dv - Vec3::new(0.0, 1.0, 2.0)).norm() < 2e-14, "v {v}: {dv}");
    }
}

/// Bad knots, weights and nets name the key, and say what was expected.
#[test]
fn bspline_knots_weights_and_nets_are_checked() {
    let err = |body: &str| -> SceneError {
        Scene::parse(body, "t.toml", "t", &HashMap::new()).err().unwrap_or_else(|| panic!("accepted:\n{body}"))
    };
    let curve = |extra: &str| format!("[curves.c]\nbspline = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n{extra}\n");
    let cases: Vec<(String, &str, &str)> = vec![
        (curve("degree = 3\nknots = [0, 0, 0, 1, 1, 1]"), "curves.c.knots", "6 knots for 4 control points"),
        (curve("knots = [0, 0, 1, 1]"), "curves.c.knots", "4 knots for 4 control points imply no degree"),
        (curve("knots = [0, 0, 0, 0, 1, 0.5, 1, 1]"), "curves.c.knots", "knot 5 is less than knot 4"),
        (curve("knots = [0, 0, 0, 0, 1, 1, 1, \"1/0\"]"), "curves.c.knots[7]", "not finite"),
        (curve("weights = [1, 2, 0, 1]"), "curves.c.weights", "weight"),
        (curve("weights = [1, 2]"), "curves.c.weights", "2 weights for 4 control points"),
        (curve("closed = true\nknots = [0, 0, 0, 0, 1, 1, 1, 1]"), "curves.c", "open B-splines"),
        (curve("range = [0, 2]\nknots = [0, 0, 0, 0, 1, 1, 1, 1]"), "curves.c", "not both"),
        ("[curves.c]\npolyline = [[0, 0, 0], [1, 0, 0]]\nknots = [0, 0, 1, 1]\n".into(), "curves.c", "only applies"),
        (
            "[surfaces.net]\nbspline = [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0]]]\n".into(),
            "surfaces.net.bspline[1]",
            "1 points, row 0 has 2",
        ),
        (
            "[surfaces.net]\nbspline = [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]]\nv = [0, 1]\n".into(),
            "surfaces.net.v",
            "knot range",
        ),
        (
            "[surfaces.net]\nbspline = [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, \"nan\"]]]\n".into(),
            "surfaces.net.bspline[1][1]",
            "",
        ),
        (
            "[surfaces.net]\nbspline = [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]]\nknots = [[0, 0, 1, 1], [0, 0, 1]]\n"
                .into(),
            "surfaces.net.knots",
            "v: 3 knots for 2 control points imply no degree",
        ),
        (
            "[surfaces.net]\nbspline = [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]]\nweights = [[1, 1], [1]]\n".into(),
            "surfaces.net.weights",
            "2 × 2",
        ),
        (
            "[surfaces.net]\nbspline = [[[0, 0, 0], [1, 0, 0]], [[0, 1, 0], [1, 1, 0]]]\ndegree = [2, 1]\n".into(),
            "surfaces.net.degree",
            "more than 2 × 1",
        ),
        ("[surfaces.net]\nexpr = [\"s\", \"v\", \"0\"]\nknots = [[0, 1], [0, 1]]\n".into(), "surfaces.net", "only applies"),
        ("[surfaces.net]\ns_range = [0, 1]\n".into(), "surfaces.net", "no definition"),
    ];
    for (body, key, msg) in cases {
        let e = err(&body);
        assert_eq!(e.key, key, "{body}\n→ {e}");
        assert!(e.to_string().contains(msg), "{body}\n→ {e}");
        assert!(e.line.is_some(), "{body}\n→ {e}");
    }
}
