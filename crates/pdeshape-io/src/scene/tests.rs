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
