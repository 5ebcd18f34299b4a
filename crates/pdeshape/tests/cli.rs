//! The CLI end to end: sample round-trips, check, build into directories, gallery.

use assert_cmd::Command;
use std::path::PathBuf;

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

/// `sample` prints the Hermite blend of examples/hermite-blend.toml; compare with the
/// formula X = H00 C(z0) + H01 (−k0) ∂C/∂s + H10 P(r1) + H11 k1 ∂P/∂s, written out here.
#[test]
fn sample_round_trips_the_hermite_formula() {
    let (r, z0, r1, k0, k1) = (1.0f64, 1.5, 2.5, 1.5, 1.5);
    let mut input = String::from("u,v\n");
    let mut pts = Vec::new();
    for i in 0..=10 {
        for j in 0..=12 {
            let (u, v) = (i as f64 / 10.0, j as f64 * 0.51);
            pts.push((u, v));
            input.push_str(&format!("{u},{v}\n"));
        }
    }
    let out = Command::cargo_bin("pdeshape")
        .unwrap()
        .arg("sample")
        .arg(example("hermite-blend.toml"))
        .write_stdin(input)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("u,v,x,y,z"));
    let mut n = 0;
    for (line, (u, v)) in lines.zip(&pts) {
        let c: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        assert_eq!((c[0], c[1]), (*u, *v));
        let h00 = 1.0 - 3.0 * u * u + 2.0 * u * u * u;
        let h01 = u - 2.0 * u * u + u * u * u;
        let h10 = 3.0 * u * u - 2.0 * u * u * u;
        let h11 = u * u * u - u * u;
        let x = h00 * r * v.cos() + h10 * r1 * v.cos() + h11 * k1 * v.cos();
        let y = h00 * r * v.sin() + h10 * r1 * v.sin() + h11 * k1 * v.sin();
        let z = h00 * z0 - h01 * k0;
        for (got, want) in [(c[2], x), (c[3], y), (c[4], z)] {
            assert!((got - want).abs() <= 1e-14, "at ({u}, {v}): {got} vs {want}");
        }
        n += 1;
    }
    assert_eq!(n, pts.len());
}

#[test]
fn check_json_reports_exact_conditions() {
    let out = Command::cargo_bin("pdeshape")
        .unwrap()
        .arg("check")
        .arg("--json")
        .arg(example("hermite-blend.toml"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let d: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let p = &d["patches"][0];
    assert_eq!(p["kind"], "hermite");
    assert!(p["condition_error"]["max_rel"].as_f64().unwrap() < 1e-12);
    assert_eq!(p["condition_error"]["samples"], 1000);
}

#[test]
fn build_writes_every_format() {
    let dir = tempfile::tempdir().unwrap();
    for ext in ["obj", "ply", "stl", "glb", "vtu", "png"] {
        let out = dir.path().join(format!("m.{ext}"));
        Command::cargo_bin("pdeshape")
            .unwrap()
            .args(["build", "-q"])
            .arg(example("hermite-pole.toml"))
            .arg("-o")
            .arg(&out)
            .assert()
            .success();
        assert!(std::fs::metadata(&out).unwrap().len() > 100, "{ext}");
    }
    let sub = dir.path().join("outdir");
    Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["build", "-q"])
        .arg(example("hermite-pole.toml"))
        .arg("-o")
        .arg(&sub)
        .assert()
        .success();
    let mut names: Vec<String> =
        std::fs::read_dir(&sub).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, ["hermite-pole-cone.obj", "hermite-pole-strip.obj", "hermite-pole.png"]);
}

#[test]
fn set_overrides_a_parameter() {
    let run = |set: &[&str]| {
        let mut c = Command::cargo_bin("pdeshape").unwrap();
        c.arg("sample").arg(example("hermite-blend.toml"));
        for s in set {
            c.arg("--set").arg(s);
        }
        let o = c.write_stdin("0,0\n").output().unwrap();
        assert!(o.status.success());
        String::from_utf8(o.stdout).unwrap().lines().nth(1).unwrap().split(',').nth(2).unwrap().parse::<f64>().unwrap()
    };
    assert_eq!(run(&[]), 1.0);
    assert_eq!(run(&["r=1.75"]), 1.75);
}

#[test]
fn gallery_builds_an_index_with_pictures() {
    let dir = tempfile::tempdir().unwrap();
    Command::cargo_bin("pdeshape").unwrap().arg("gallery").arg(dir.path()).arg("-q").assert().success();
    let html = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
    let n_examples = std::fs::read_dir(example(""))
        .unwrap()
        .filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|x| x == "toml"))
        .count();
    assert_eq!(html.matches("<img src").count(), n_examples, "one picture per example");
    assert!(html.contains("four-curve-patch-sheet-convergence.png"), "the convergence plot of the four-curve patch");
    for img in html.split(" src=\"").skip(1) {
        let path = img.split('"').next().unwrap();
        let bytes = std::fs::read(dir.path().join(path)).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
    }
}

#[test]
fn serve_refuses_a_broken_scene_before_listening() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("broken.toml");
    std::fs::write(&path, "[patches.p\n").unwrap();
    let o = Command::cargo_bin("pdeshape").unwrap().arg("serve").arg(&path).args(["--port", "0"]).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("broken.toml:1:"), "{err}");
    let o = Command::cargo_bin("pdeshape").unwrap().args(["serve", "--port", "not-a-port"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
}

/// `bench --json` reproduces paper 002's Table 1 beside the published figures and the
/// accuracy study; `--out` writes Markdown and JSON atomically.
#[test]
fn bench_prints_the_papers_tables() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bench");
    let o = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["bench", "--json", "--runs", "1", "--out"])
        .arg(&out)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let d: serde_json::Value = serde_json::from_slice(&o).unwrap();
    let t1 = d["paper_002_table_1"].as_array().unwrap();
    assert_eq!(t1.len(), 3);
    // our timings were measured: positive, finite, min ≤ median ≤ max, one run each
    for row in t1 {
        let o = &row["ours"];
        let (lo, med, hi) =
            (o["min_ms"].as_f64().unwrap(), o["median_ms"].as_f64().unwrap(), o["max_ms"].as_f64().unwrap());
        assert!(lo > 0.0 && lo <= med && med <= hi && hi.is_finite(), "{row}");
        assert_eq!(o["runs"], 1, "{row}");
    }
    let k5 = t1[1]["max_deviation"].as_f64().unwrap();
    assert!(k5 > 1e-4 && k5 < 1e-2, "K = 5 deviates from the closed form by {k5}");
    assert_eq!(d["paper_002_accuracy"].as_array().unwrap().len(), 48);
    assert!(out.with_extension("md").exists() && out.with_extension("json").exists());
}

/// `render --view`: every view draws a different picture than the shaded one (and than each
/// other); unknown views and bad stripe counts are usage errors that write nothing.
#[test]
fn render_views() {
    let dir = tempfile::tempdir().unwrap();
    let mut pictures = Vec::new();
    for view in ["shaded", "zebra", "isophotes", "gauss", "mean", "k1", "k2"] {
        let out = dir.path().join(format!("{view}.png"));
        Command::cargo_bin("pdeshape")
            .unwrap()
            .args(["render", "--width", "160", "--height", "120", "--view", view, "-o"])
            .arg(&out)
            .arg(example("bloor-wilson-blend.toml"))
            .assert()
            .success();
        pictures.push((view, std::fs::read(&out).unwrap()));
    }
    for (i, (a, pa)) in pictures.iter().enumerate() {
        for (b, pb) in &pictures[i + 1..] {
            assert_ne!(pa, pb, "{a} and {b} draw the same picture");
        }
    }
    for bad in [
        &["--view", "stripes"][..],
        &["--view", "zebra", "--stripes", "0"],
        &["--view", "mean", "--curvature-limit", "-1"],
    ] {
        let out = dir.path().join("bad.png");
        let o = Command::cargo_bin("pdeshape")
            .unwrap()
            .arg("render")
            .args(bad)
            .arg("-o")
            .arg(&out)
            .arg(example("bloor-wilson-blend.toml"))
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(!out.exists(), "{bad:?} wrote a file");
    }
    let o = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["render", "--view", "stripes", "-o", "x.png"])
        .arg(example("bloor-wilson-blend.toml"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("unknown view `stripes` (one of: shaded, zebra, isophotes, gauss, mean, k1, k2)"), "{err}");
}

/// `--limit` holds for the commands that load the built-in examples themselves (`bench`,
/// `gallery`): they resolved them with the default caps before, so a lowered cap let them
/// solve what it forbids.
#[test]
fn bench_keeps_the_limits_it_is_given() {
    let o =
        Command::cargo_bin("pdeshape").unwrap().args(["bench", "--limit", "order=2", "--runs", "1"]).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("over the `order` cap of 2") && !err.contains("panicked"), "{err}");
    assert!(o.stdout.is_empty(), "no table printed");
}

/// `sample --patch surface-NAME` evaluates the drawn part of a primary surface in the
/// parameters of its STEP face (`u` across `s_range`): hermite-blend's cylinder
/// `(r cos v, r sin v, s)` with `s = z0 + 1.5 u`, written out here.
#[test]
fn sample_evaluates_a_primary_surfaces_face() {
    let (r, z0) = (1.0f64, 1.5f64);
    let out = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["sample", "--patch", "surface-cylinder"])
        .arg(example("hermite-blend.toml"))
        .write_stdin("u,v\n0,0\n0.5,1\n1,2.5\n")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 3);
    for c in rows {
        let (u, v) = (c[0], c[1]);
        let want = [r * v.cos(), r * v.sin(), z0 + 1.5 * u];
        for (g, w) in c[2..].iter().zip(want) {
            // the expression evaluator's round-off on values of size ~3
            assert!((g - w).abs() <= 1e-15 * 4.0, "({u}, {v}): {g} vs {w}");
        }
    }
    // a surface that is not drawn (no s_range) or does not exist is named
    let o = Command::cargo_bin("pdeshape")
        .unwrap()
        .args(["sample", "--patch", "surface-nope"])
        .arg(example("hermite-blend.toml"))
        .write_stdin("u,v\n0,0\n")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("surface-nope"));
}

/// A reader that closes stdout before the report is written (`pdeshape holes … | head`)
/// ends the command quietly: exit 0, no panic on stderr. (The pipe's read end is closed
/// as soon as the process starts; reading the model takes it far longer than that.)
#[test]
fn a_closed_stdout_ends_the_command_quietly() {
    let model = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/step/third-party/as1-ug-theorem.stp");
    for args in [vec!["holes", model.to_str().unwrap()], vec!["check", example("dolphin.toml").to_str().unwrap()]] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("pdeshape"))
            .args(&args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}
