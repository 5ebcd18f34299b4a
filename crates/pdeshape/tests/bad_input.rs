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
    // flags are usage errors (exit 2), like --limit's: a --set name the scene lacks too
    let (code, _, err) = run(&["build", p, "-o", dir.path().join("x.obj").to_str().unwrap(), "--set", "nope=1"], "");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("unknown parameter `nope`") && err.contains("the scene has no parameters"), "{err}");
    let (code, _, err) = run(&["build", p, "-o", "x.obj", "--set", "a=zero"], "");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is not a number"), "{err}");
    let (code, _, err) = run(&["build", p, "-o", "x.obj", "--set", "a=nan"], "");
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not finite"), "{err}");
    let (code, _, err) = run(&["sample", p, "--time", "inf"], "");
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = run(&["sample", p, "--terms", "0"], "");
    assert_eq!(code, 2, "{err}");
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
    // an output that names no known format is a usage error
    let (code, _, err) = run(&["build", p, "-o", dir.path().join("x.dwg").to_str().unwrap()], "");
    assert_eq!(code, 2);
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

/// The cases a hostile tester found against the CLI (issue "Trust"), each a regression
/// test: it failed on the code before the fix.
mod hostile {
    use super::*;

    fn scene_file(dir: &tempfile::TempDir, text: &str) -> String {
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    }

    /// `check /dev/zero` read until the kernel killed it: non-regular files are refused at
    /// once, and files over the `scene` cap (MiB) name the cap.
    #[test]
    fn scene_files_must_be_regular_and_small() {
        let t0 = std::time::Instant::now();
        let (code, _, err) = run(&["check", "/dev/zero"], "");
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("/dev/zero") && err.contains("not a regular file"), "{err}");
        assert!(t0.elapsed() < std::time::Duration::from_secs(5));
        let (code, _, err) = run(&["check", "/tmp"], "");
        assert_eq!(code, 1);
        assert!(err.contains("a directory"), "{err}");
        let dir = tempfile::tempdir().unwrap();
        let p = scene_file(&dir, &format!("{}\n# {}\n", good(), "x".repeat(3 << 20)));
        let (code, _, err) = run(&["--limit", "scene=2", "check", &p], "");
        assert_eq!(code, 1);
        assert!(err.contains("`scene` cap of 2 MiB") && err.contains("--limit scene=4"), "{err}");
        let (code, _, _) = run(&["check", &p], "");
        assert_eq!(code, 0, "under the default cap of 16 MiB");
    }

    /// `render --width 100000 --height 100000` aborted on a 40 GB allocation, `--width 0`
    /// became 16, `--azimuth nan` wrote a blank picture: flags are checked like `[render]`.
    #[test]
    fn render_flags_are_validated() {
        let dir = tempfile::tempdir().unwrap();
        let p = scene_file(&dir, &good());
        let out = dir.path().join("x.png");
        let o = out.to_str().unwrap();
        for args in [
            vec!["--width", "100000", "--height", "100000"],
            vec!["--width", "0"],
            vec!["--height", "15"],
            vec!["--azimuth", "nan"],
            vec!["--azimuth", "inf"],
            vec!["--elevation", "91"],
        ] {
            let mut a = vec!["render", p.as_str(), "-o", o];
            a.extend(args.iter());
            let (code, _, err) = run(&a, "");
            assert_eq!(code, 2, "{args:?}: {err}");
            assert!(!out.exists(), "{args:?} wrote a picture");
        }
        let (code, _, err) = run(&["render", &p, "-o", o, "--width", "64", "--height", "48", "--azimuth", "-30"], "");
        assert_eq!(code, 0, "{err}");
        assert!(out.exists());
    }

    /// `sample` took any unparsable first line for a header (a BOM, quoted numbers, tabs:
    /// exit 0 and no rows). Only the literal header is skipped (a BOM before it is fine).
    #[test]
    fn sample_accepts_only_a_literal_header() {
        let dir = tempfile::tempdir().unwrap();
        let p = scene_file(&dir, &good());
        for input in ["u,v\n0.5,0.25\n", "\u{feff}u,v\n0.5,0.25\n", " u , v \n0.5,0.25\n", "\u{feff}0.5,0.25\n"] {
            let (code, out, err) = run(&["sample", &p], input);
            assert_eq!(code, 0, "{input:?}: {err}");
            assert_eq!(out.lines().count(), 2, "{input:?}: {out}");
        }
        for (input, line) in [
            ("\"0.5\",\"0.25\"\n", 1),
            ("0.5\t0.25\n", 1),
            ("x,y\n0.5,0.25\n", 1),
            ("u,v\nu,v\n", 2),
            ("0.5,0.25\n0,1,2\n", 2),
        ] {
            let (code, out, err) = run(&["sample", &p], input);
            assert_eq!(code, 1, "{input:?}: {out}");
            assert!(err.contains(&format!("stdin line {line}")), "{input:?}: {err}");
        }
    }

    /// `build scene -o DIR` left the files it had written when a later one failed. Here
    /// the second format's target is taken by a directory: nothing new is left behind.
    #[test]
    fn a_directory_build_is_all_or_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let p = scene_file(&dir, &format!("{}\n[output]\nformats = [\"obj\", \"ply\"]\n", good()));
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("scene-p.ply/blocker")).unwrap();
        let (code, _, err) = run(&["build", &p, "-o", out.to_str().unwrap()], "");
        assert_eq!(code, 1, "{err}");
        let left: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left, vec![std::ffi::OsString::from("scene-p.ply")], "{err}");
        // and with the way clear, both files land
        std::fs::remove_dir_all(out.join("scene-p.ply")).unwrap();
        let (code, _, err) = run(&["build", &p, "-o", out.to_str().unwrap()], "");
        assert_eq!(code, 0, "{err}");
        let mut names: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name()).collect();
        names.sort();
        assert_eq!(names, ["scene-p.obj", "scene-p.ply"]);
    }

    /// `v = [0, 1e300]` exited 0 with "max condition error NaN" and vertices of 4.6e282: a
    /// result whose own check is not finite is an error, and nothing is written.
    #[test]
    fn a_result_whose_check_is_not_finite_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let text = "[curves.c0]\nexpr = [\"v\", \"0\", \"0\"]\n[curves.c1]\nexpr = [\"v\", \"0\", \"1\"]\n[patches.p]\n\
                    kind = \"pde\"\nv = [0, 1e300]\nconditions = [{ u = 0, curve = \"c0\" }, { u = 1, curve = \"c1\" }]\n";
        let p = scene_file(&dir, text);
        let out = dir.path().join("x.obj");
        let (code, _, err) = run(&["build", &p, "-o", out.to_str().unwrap()], "");
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("not finite"), "{err}");
        assert!(!out.exists());
        let (code, _, err) = run(&["check", &p], "");
        assert_eq!(code, 1, "{err}");
        // finite positions, but the residual figures over [0, 1e300] overflow: the report
        // has an inf, so `check` fails naming the figure (it printed a warning and exited 0
        // with `null` in the JSON)
        let p = scene_file(
            &dir,
            &text
                .replace("expr = [\"v\", \"0\", \"0\"]", "expr = [\"cos(v)\", \"sin(v)\", \"0\"]")
                .replace("expr = [\"v\", \"0\", \"1\"]", "expr = [\"cos(v)\", \"sin(v)\", \"1\"]"),
        );
        let (code, _, err) = run(&["check", &p], "");
        assert_eq!(code, 1, "{err}");
        assert!(err.contains("patch `p`") && err.contains("spectral.") && err.contains("not finite"), "{err}");
    }

    /// Small ones: an overflowing cap value, a 200 KB line echoed twice on stderr, an
    /// overflowing ω, Debug text in errors.
    #[test]
    fn errors_are_short_and_say_what_is_wrong() {
        let (code, _, err) = run(&["--limit", "vertices=18446744073709551616", "check", "x.toml"], "");
        assert_eq!(code, 2);
        assert!(err.contains("larger than the largest cap"), "{err}");
        let dir = tempfile::tempdir().unwrap();
        let long = format!("{}\n[parameters]\nq = \"{}\"\n", good(), "v+".repeat(100_000));
        let p = scene_file(&dir, &long);
        let (code, _, err) = run(&["check", &p], "");
        assert_eq!(code, 1);
        assert!(err.len() < 4000, "{} bytes of stderr", err.len());
        let text = format!(
            "{GOOD_CURVES}\n[parameters]\na = 1e308\n[patches.p]\nkind = \"pde\"\na = \"a\"\nconditions = [{{ u = 0, curve = \"c0\" }}, {{ u = 1, curve = \"c1\" }}]\n"
        );
        let p = scene_file(&dir, &text);
        let (code, _, err) = run(&["check", &p], "");
        assert_eq!(code, 1);
        assert!(err.contains("overflows") && !err.contains("ω = inf must be positive"), "{err}");
        let p = scene_file(&dir, &good().replace("\"0\"]", "\"1/(v - v)\"]"));
        let (code, _, err) = run(&["check", &p], "");
        assert_eq!(code, 1);
        assert!(!err.contains("Vec3 {"), "{err}");
    }
}

/// `check` on `scene` (written to a file) with `args`: exit 1, no panic, every string of
/// `expect` in the error; the time it took.
fn check_fails(scene: &str, args: &[&str], expect: &[&str]) -> std::time::Duration {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let t = std::time::Instant::now();
    let a = Command::cargo_bin("pdeshape").unwrap().arg("check").arg(&path).args(args).assert();
    let took = t.elapsed();
    let o = a.get_output();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "stderr: {err}");
    assert!(!err.contains("panicked"), "panic: {err}");
    for e in expect {
        assert!(err.contains(e), "expected `{e}` in\n{err}");
    }
    took
}

fn example_text(name: &str) -> String {
    std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).unwrap()
}

/// The Klein bottle at 100 modes (within every cap) ran `check` for 42 s, at 512 past 9
/// minutes: `--time-limit` stops it at its next checkpoint with an error naming the limit
/// and how to raise it.
#[test]
fn the_time_limit_stops_a_long_command() {
    // data not proved trigonometric polynomials (the bottle's sections are of degree 1,
    // which would leave modes 2 … 100 unsolved): 101 modes and the remainder at order 40
    let scene = example_text("klein-bottle.toml")
        .replace("modes = 6", "modes = 100")
        .replace("\"4*(1 - cos(s)/2)*sin(v)\"", "\"4*(1 - cos(s)/2)*sin(v) + 0.01*exp(cos(v))\"");
    assert!(scene.contains("modes = 100") && scene.contains("exp(cos(v))"));
    let took = check_fails(&scene, &["--time-limit", "1"], &["time limit of 1 s", "--time-limit"]);
    // the solve checks the flag between modes: well within seconds of the limit
    assert!(took.as_secs_f64() < 15.0, "{took:?}");
}

/// Fill and spectral settings whose results overflow or vanish (`check` exited 0 with NaN
/// and inf in its report, `omega = 1e100` STEP ran 64 s): refused up front, naming the
/// setting.
#[test]
fn fill_settings_that_overflow_are_refused() {
    let base = example_text("fill-sphere-triangle.toml");
    let cases: [(&str, &str, &[&str]); 5] = [
        ("corner_blend", "a = 2.0\ncorner_blend = 1e-300", &["corner_blend = 1e-300", "[1e-6, 0.5]"]),
        ("a", "a = 1e300", &["exponential rate", "lower a or ω"]),
        ("omega", "a = 2.0\nomega = 1e300", &["exponential rate"]),
        ("omega 1e100", "a = 2.0\nomega = 1e100", &["exponential rate"]),
        ("height", "a = 2.0\nheight = 1e400", &["height"]),
    ];
    for (what, with, expect) in cases {
        let scene = base.replacen("a = 2.0", with, 1);
        assert_ne!(scene, base, "{what}");
        check_fails(&scene, &[], expect);
    }
    let scene = base.replace("pole = [0, 0, \"pz\"]", "pole = [1e300, 0, 1]");
    assert_ne!(scene, base);
    check_fails(&scene, &[], &["the pole", "1e6 × the loop's mean radius"]);
}

/// Hostile text echoed in an error is escaped (an ANSI escape in a TOML key reached the
/// terminal raw) and cut.
#[test]
fn control_characters_in_errors_are_escaped() {
    let scene = format!("{}\n[patches.p.\"x\\u001b[31mred\"]\n", good());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let o = Command::cargo_bin("pdeshape").unwrap().arg("check").arg(&path).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains('\u{1b}'), "a raw escape: {err:?}");
    assert!(err.contains("\\u{1b}"), "{err:?}");
    // a numeric argument is echoed as given, cut, not printed with 300 digits
    let o = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["render", "x.toml", "-o", "x.png", "--stripes"])
        .arg(format!("1e-300{}", "0".repeat(1000)))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.len() < 1500, "{} bytes: {err}", err.len());
}
