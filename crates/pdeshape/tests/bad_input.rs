//! Malformed scenes, expressions and arguments: each gives a clear error naming the place
//! and the cause, exit code 1 or 2, no panic, and no output file.

use assert_cmd::Command;

const GOOD_CURVES: &str = r#"
[curves.c0]
expr = ["cos(v)", "sin(v)", "0"]
[curves.c1]
expr = ["cos(v)", "sin(v)", "1"]
"#;

fn patch(conds: &str) -> String {
    format!("{GOOD_CURVES}\n[patches.p]\nkind = \"hermite\"\nconditions = [{conds}]\n")
}

fn good() -> String {
    patch(r#"{ u = 0, curve = "c0" }, { u = 1, curve = "c1" }"#)
}

/// Runs `pdeshape build scene -o out.obj` and checks the failure.
fn fails(scene: &str, expect: &[&str]) {
    fails_with(scene, &[], expect)
}

/// [`fails`] with extra arguments.
fn fails_with(scene: &str, args: &[&str], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out.obj");
    let a = Command::cargo_bin("pdeshape")
        .unwrap()
        .arg("build")
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .arg("-q")
        .args(args)
        .assert();
    let o = a.get_output();
    let code = o.status.code().expect("exited normally, not by a signal");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(code == 1 || code == 2, "exit code {code} for\n{scene}\nstderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    for e in expect {
        assert!(err.contains(e), "expected `{e}` in the error for\n{scene}\ngot: {err}");
    }
    assert!(!out.exists(), "an output file was written");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "stray files left behind");
}

#[test]
fn the_good_scene_builds() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, good()).unwrap();
    let out = dir.path().join("out.obj");
    Command::cargo_bin("pdeshape").unwrap().arg("build").arg(&path).arg("-o").arg(&out).arg("-q").assert().success();
    assert!(out.exists());
}

#[test]
fn toml_syntax_error() {
    fails("[patches.p\nkind = 1", &["scene.toml:1:", "expected `]`"]);
}

#[test]
fn unknown_top_level_key() {
    fails(&format!("colour = 3\n{}", good()), &["scene.toml:1:", "unknown field `colour`"]);
}

#[test]
fn unknown_patch_key() {
    fails(
        &good().replace("kind = \"hermite\"", "kind = \"hermite\"\nordr = 4"),
        &["unknown field `ordr`", "expected one of"],
    );
}

#[test]
fn unknown_condition_key() {
    fails(&patch(r#"{ u = 0, curve = "c0", wieght = 1 }, { u = 1, curve = "c1" }"#), &["unknown field `wieght`"]);
}

#[test]
fn wrong_type() {
    fails(
        &good().replace("kind = \"hermite\"", "kind = \"hermite\"\nresolution = \"big\""),
        &["resolution", "invalid type"],
    );
}

#[test]
fn expression_syntax_error_shows_a_caret() {
    fails(&good().replace("\"sin(v)\", \"1\"", "\"sin(v\", \"1\""), &["curves.c1.expr[1]", "expected `,` or `)`", "^"]);
}

#[test]
fn unknown_function() {
    fails(&good().replace("cos(v)\", \"sin(v)\", \"1", "cosine(v)\", \"sin(v)\", \"1"), &["unknown function `cosine`"]);
}

#[test]
fn undefined_parameter() {
    fails(&good().replace("\"0\"]", "\"height\"]"), &["curves.c0.expr[2]", "unknown name `height`"]);
}

#[test]
fn nan_parameter() {
    fails(&format!("[parameters]\na = nan\n{}", good()), &["parameters.a", "not finite"]);
}

#[test]
fn infinite_parameter() {
    fails(&format!("[parameters]\na = -inf\n{}", good()), &["parameters.a", "not finite"]);
}

#[test]
fn parameter_expression_evaluates_to_nan() {
    fails(&format!("[parameters]\na = \"sqrt(-1)\"\n{}", good()), &["parameters.a", "not finite"]);
}

#[test]
fn parameter_cycle() {
    fails(&format!("[parameters]\na = \"2*b\"\nb = \"c + 1\"\nc = \"a\"\n{}", good()), &["cycle", "a → b → c → a"]);
}

#[test]
fn wrong_arity() {
    fails(&good().replace("\"0\"]", "\"pow(v)\"]"), &["`pow` takes 2 arguments, got 1"]);
}

#[test]
fn empty_expression() {
    fails(&good().replace("\"0\"]", "\"\"]"), &["empty expression"]);
}

#[test]
fn empty_bspline() {
    fails(&format!("[curves.b]\nbspline = []\nclosed = true\n{}", good()), &["curves.b.bspline", "at least"]);
}

#[test]
fn open_bspline_with_one_point() {
    fails(&format!("[curves.b]\nbspline = [[0, 0, 0]]\n{}", good()), &["open B-spline needs at least 2"]);
}

#[test]
fn closed_bspline_with_too_few_points() {
    fails(
        &format!("[curves.b]\nbspline = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\nclosed = true\n{}", good()),
        &["closed B-spline needs at least 4"],
    );
}

#[test]
fn open_curve_on_a_periodic_patch() {
    let s = format!(
        "[curves.b]\nbspline = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]\n{}",
        patch(r#"{ u = 0, curve = "b" }, { u = 1, curve = "c1" }"#)
    );
    fails(&s, &["patches.p.conditions[0]", "not periodic"]);
}

#[test]
fn duplicate_names_across_tables() {
    fails(&format!("[parameters]\nc0 = 1\n{}", good()), &["curves.c0", "already used by parameters.c0"]);
}

#[test]
fn duplicate_key_in_toml() {
    fails(&format!("[parameters]\na = 1\na = 2\n{}", good()), &["scene.toml:3:", "duplicate key"]);
}

#[test]
fn reserved_name() {
    fails(&format!("[parameters]\nv = 1\n{}", good()), &["parameters.v", "reserved"]);
}

#[test]
fn resolution_zero() {
    fails(
        &good().replace("kind = \"hermite\"", "kind = \"hermite\"\nresolution = [0, 10]"),
        &["patches.p.resolution", "too small"],
    );
}

#[test]
fn resolution_huge() {
    fails(
        &good().replace("kind = \"hermite\"", "kind = \"hermite\"\nresolution = [1000000000, 10]"),
        &["patches.p.resolution", "over the `vertices` cap of 4000000", "--limit vertices=10000000000"],
    );
}

#[test]
fn unknown_curve() {
    fails(
        &patch(r#"{ u = 0, curve = "c9" }, { u = 1, curve = "c1" }"#),
        &["conditions[0].curve", "unknown curve `c9`", "defined: c0, c1"],
    );
}

#[test]
fn unknown_surface() {
    fails(&patch(r#"{ u = 0, surface = "cyl", s = 1 }, { u = 1, curve = "c1" }"#), &["unknown surface `cyl`"]);
}

#[test]
fn condition_with_two_sources() {
    fails(&patch(r#"{ u = 0, curve = "c0", point = [0, 0, 0] }, { u = 1, curve = "c1" }"#), &["exactly one of"]);
}

#[test]
fn condition_without_source() {
    fails(&patch(r#"{ u = 0 }, { u = 1, curve = "c1" }"#), &["conditions[0]", "exactly one of"]);
}

#[test]
fn u_outside_the_domain() {
    fails(&patch(r#"{ u = 1.5, curve = "c0" }, { u = 1, curve = "c1" }"#), &["conditions[0].u", "outside [0, 1]"]);
}

#[test]
fn mismatched_hermite_conditions() {
    fails(
        &patch(r#"{ u = 0, curve = "c0" }, { u = 0, order = 1, curve = "c0" }, { u = 1, curve = "c1" }"#),
        &["patches.p.conditions", "same derivative orders"],
    );
}

#[test]
fn negative_order() {
    fails(&patch(r#"{ u = 0, order = -1, curve = "c0" }, { u = 1, curve = "c1" }"#), &["order", "out of range"]);
}

#[test]
fn unknown_patch_kind() {
    fails(&good().replace("\"hermite\"", "\"bezier\""), &["patches.p.kind", "unknown patch kind `bezier`"]);
}

#[test]
fn curve_cycle() {
    let s = format!("[curves.a]\ncombine = \"2*b\"\n[curves.b]\ncombine = \"a - c0\"\n{}", good());
    fails(&s, &["cycle", "a → b → a"]);
}

#[test]
fn nonlinear_combination() {
    fails(&format!("[curves.a]\ncombine = \"c0*c1\"\n{}", good()), &["curves.a.combine", "not a linear combination"]);
}

#[test]
fn trimline_without_s() {
    let s =
        format!("[surfaces.cyl]\nexpr = [\"cos(v)\", \"sin(v)\", \"s\"]\n[curves.a]\nsurface = \"cyl\"\n{}", good());
    fails(&s, &["curves.a", "needs `s`"]);
}

#[test]
fn degree_out_of_range() {
    fails(
        &format!("[curves.b]\nbspline = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\ndegree = 9\n{}", good()),
        &["curves.b.degree", "out of range"],
    );
}

#[test]
fn non_finite_data() {
    fails(&good().replace("\"0\"]", "\"1/(v - v)\"]"), &["conditions[0]", "not finite"]);
}

#[test]
fn curve_with_two_definitions() {
    fails(
        &format!("[curves.b]\npoint = [0,0,0]\nexpr = [\"v\", \"0\", \"0\"]\n{}", good()),
        &["curves.b", "several definitions"],
    );
}

#[test]
fn unknown_output_format() {
    fails(&format!("{}\n[output]\nformats = [\"dwg\"]\n", good()), &["output.formats", "unknown format `dwg`"]);
}

#[test]
fn render_size_out_of_range() {
    fails(&format!("{}\n[render]\nsize = [0, 10]\n", good()), &["render.size", "out of range"]);
}

#[test]
fn expression_nested_too_deep() {
    let deep = "(".repeat(400) + "v" + &")".repeat(400);
    fails(&good().replace("\"0\"]", &format!("\"{deep}\"]")), &["nested deeper"]);
}

fn run(args: &[&str], stdin: &str) -> (i32, String, String) {
    let o = Command::cargo_bin("pdeshape").unwrap().args(args).write_stdin(stdin).output().unwrap();
    (
        o.status.code().unwrap(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

#[test]
fn bad_arguments_and_stdin() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, good()).unwrap();
    let p = path.to_str().unwrap();
    let (code, _, err) = run(&["build", p, "-o", dir.path().join("x.obj").to_str().unwrap(), "--set", "nope=1"], "");
    assert_eq!(code, 1);
    assert!(err.contains("unknown parameter `nope`"), "{err}");
    let (code, _, err) = run(&["build", p, "-o", "x.obj", "--set", "a=zero"], "");
    assert_eq!(code, 1);
    assert!(err.contains("is not a number"), "{err}");
    let (code, _, err) = run(&["sample", p], "0.5,abc\n");
    assert_eq!(code, 1);
    assert!(err.contains("line 1") && err.contains("`abc` is not a number"), "{err}");
    let (code, _, err) = run(&["sample", p], "0.5\n");
    assert_eq!(code, 1);
    assert!(err.contains("expected 2 columns"), "{err}");
    let (code, _, err) = run(&["sample", p], "2.0,0.1\n");
    assert_eq!(code, 1);
    assert!(err.contains("outside [0, 1]"), "{err}");
    let (code, _, err) = run(&["sample", p, "--patch", "q"], "");
    assert_eq!(code, 1);
    assert!(err.contains("no patch named `q`"), "{err}");
    let (code, _, err) = run(&["build", "/nonexistent/scene.toml", "-o", "x.obj"], "");
    assert_eq!(code, 1);
    assert!(err.contains("cannot read the scene file"), "{err}");
    let (code, _, _) = run(&[], "");
    assert_eq!(code, 2);
    let (code, _, _) = run(&["build", p], "");
    assert_eq!(code, 2, "missing -o is a usage error");
    let (code, _, err) = run(&["build", p, "-o", dir.path().join("x.dwg").to_str().unwrap()], "");
    assert_eq!(code, 1);
    assert!(err.contains("unknown output format `.dwg`"), "{err}");
    assert!(!dir.path().join("x.dwg").exists());
}

fn blend(extra: &str) -> String {
    format!(
        "{GOOD_CURVES}\n[patches.p]\nkind = \"blend\"\n{extra}\nconditions = [{{ u = 0, curve = \"c0\" }}, {{ u = 1, curve = \"c1\" }}]\n"
    )
}

#[test]
fn blend_with_a_vanishing_u_coefficient() {
    fails(
        &blend("orders = [2, 2, 2]\ncoefficients = [[0, 1], [1, 1], [1, 1]]"),
        &["patches.p.coefficients[0]", "coefficient of ∂u^2 is zero"],
    );
}

#[test]
fn blend_with_an_unavailable_order_or_wrong_coefficient_count() {
    fails(&blend("orders = [2, 3, 2]"), &["patches.p.orders[1]", "order 3 is not available"]);
    fails(
        &blend("orders = [2, 2, 4]\ncoefficients = [[1, 1], [1, 1], [1, 1]]"),
        &["patches.p.coefficients[2]", "takes 3 shape coefficients, 2 given"],
    );
}

#[test]
fn blend_missing_the_conditions_its_order_needs() {
    fails(&blend("orders = [2, 2, 4]"), &["patches.p", "component z has order 4", "missing"]);
}

#[test]
fn blend_keys_on_other_kinds_and_unknown_solver() {
    fails(
        &patch(r#"{ u = 0, curve = "c0" }, { u = 1, curve = "c1" }"#)
            .replace("kind = \"hermite\"", "kind = \"hermite\"\norders = [2, 2, 2]"),
        &["patches.p.orders", "only applies to kind = \"blend\""],
    );
    fails(&blend("orders = [2, 2, 2]\nsolver = \"magic\""), &["patches.p.solver", "unknown solver `magic`"]);
}

#[test]
fn blend_exact_solver_on_data_it_cannot_take() {
    let s = "[curves.c0]\nexpr = [\"cos(v)\", \"sin(v)\", \"1/(1.02 + cos(v))\"]\n[curves.c1]\nexpr = [\"cos(v)\", \"sin(v)\", \"1\"]\n\
         [patches.p]\nkind = \"blend\"\norders = [2, 2, 2]\nsolver = \"exact\"\n\
         conditions = [{ u = 0, curve = \"c0\" }, { u = 1, curve = \"c1\" }]\n";
    fails(s, &["patches.p", "exact solver needs eigenfunctions", "component z"]);
}

/// The same scene as a PDE patch with `extra` keys.
fn pde(extra: &str) -> String {
    good().replace("kind = \"hermite\"", &format!("kind = \"pde\"\n{extra}"))
}

#[test]
fn caps_name_themselves_and_how_to_raise_them() {
    fails(&pde("modes = 600"), &["patches.p.modes", "over the `modes` cap of 512", "--limit modes=600"]);
    fails_with(&pde("modes = 4"), &["--limit", "modes=3"], &["`modes` cap of 3", "--limit modes=4"]);
    fails_with(&pde(""), &["--limit", "order=1"], &["patches.p.conditions", "the PDE order", "`order` cap of 1"]);
    fails_with(
        &pde("resolution = [400, 400]"),
        &["--limit", "memory=1"],
        &["patches.p", "estimated memory", "`memory` cap of 1 MiB", "--limit memory="],
    );
    // a solid's point set: the Gauss grid (3L + 24)(3M + 24)(2N + 24) = 84·84·64
    let solid = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/solid-cubes.toml"))
        .unwrap()
        .replace("lmn = [6, 6, 6]", "lmn = [20, 20, 20]");
    fails(&solid, &["lmn", "451584", "`collocation` cap of 250000", "--limit collocation=451584"]);
    fails_with(&good(), &["--limit", "colour=3"], &["unknown cap `colour`", "order, modes, collocation"]);
    fails_with(&good(), &["--limit", "order=many"], &["not a whole number"]);
}

#[test]
fn a_raised_cap_lets_the_scene_build() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, pde("modes = 600\nresolution = [5, 9]")).unwrap();
    let out = dir.path().join("out.obj");
    let mut c = Command::cargo_bin("pdeshape").unwrap();
    c.arg("build").arg(&path).arg("-o").arg(&out).args(["-q", "--limit", "modes=600"]).assert().success();
    assert!(out.exists());
}
