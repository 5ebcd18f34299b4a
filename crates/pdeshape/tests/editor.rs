//! `pdeshape serve` end to end in a real headless Chromium (Debian's `chromium` and
//! `chromium-driver`): open the page, wait for the first frame, move a slider, drag a
//! boundary-curve handle and a trim control point, check that the mesh (hash) and the
//! picture change after each, that an invalid edit is shown and not applied, that the
//! diagnostics panel fills, and download an OBJ.
//!
//! `.ci/run` installs the browser and sets `PDESHAPE_REQUIRE_BROWSER=1`, which makes a
//! missing browser a failure; elsewhere the test says it is skipped.

use fantoccini::actions::{InputSource, MOUSE_BUTTON_LEFT, MouseActions, PointerAction};
use fantoccini::{Client, ClientBuilder, Locator};
use serde_json::{Value, json};
use std::time::{Duration, Instant};

mod common;
use common::{Kill, serve, serve_file};
use std::process::{Command, Stdio};

fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

async fn js(c: &Client, script: &str) -> Value {
    c.execute(script, vec![]).await.unwrap()
}

async fn wait_for(c: &Client, what: &str, script: &str) -> Value {
    let t0 = Instant::now();
    loop {
        let v = js(c, script).await;
        if !(v.is_null() || v == json!(false)) {
            return v;
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "timed out waiting for {what}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// Waits until the page's mesh hash differs from `old` and no request is pending.
async fn wait_changed(c: &Client, what: &str, old: &str) -> String {
    let script =
        format!("return !window.pdeshape.busy() && window.pdeshape.meshHash !== '{old}' && window.pdeshape.meshHash");
    let h = wait_for(c, what, &script).await;
    h.as_str().unwrap().to_string()
}

/// Presses at `from`, moves by `by` in `steps` moves, releases.
async fn drag(c: &Client, from: (f64, f64), by: (f64, f64), steps: usize) {
    let mut mouse = MouseActions::new("mouse".into())
        .then(PointerAction::MoveTo { duration: None, x: from.0, y: from.1 })
        .then(PointerAction::Down { button: MOUSE_BUTTON_LEFT });
    for _ in 0..steps {
        let (x, y) = (by.0 / steps as f64, by.1 / steps as f64);
        mouse = mouse.then(PointerAction::MoveBy { duration: Some(Duration::from_millis(60)), x, y });
    }
    c.perform_actions(mouse.then(PointerAction::Up { button: MOUSE_BUTTON_LEFT })).await.unwrap();
}

/// Clicks the STEP download and waits for it: its size in bytes.
async fn step_download(c: &Client) -> u64 {
    c.find(Locator::Css("button[data-format=step]")).await.unwrap().click().await.unwrap();
    let d = wait_for(
        c,
        "the STEP download",
        "const d = window.pdeshape.lastDownload; return d && d.name.endsWith('.step') && d.bytes",
    )
    .await;
    d.as_u64().unwrap()
}

fn pos(v: &Value) -> (f64, f64) {
    (v[0].as_f64().unwrap().round(), v[1].as_f64().unwrap().round())
}

/// Starts chromedriver and a headless Chromium (software WebGL); `None` when no driver is
/// installed and `PDESHAPE_REQUIRE_BROWSER` is not 1 (the test is then skipped).
async fn browser() -> Option<(Client, Kill)> {
    let required = std::env::var("PDESHAPE_REQUIRE_BROWSER").is_ok_and(|v| v == "1");
    let driver_bin = ["/usr/bin/chromedriver", "/usr/lib/chromium/chromedriver"]
        .into_iter()
        .find(|p| std::path::Path::new(p).exists());
    let Some(driver_bin) = driver_bin else {
        assert!(!required, "chromedriver not found: install Debian's chromium and chromium-driver");
        eprintln!("skipped: no chromedriver (install chromium and chromium-driver; .ci/run does)");
        return None;
    };
    let port = free_port();
    let driver = Kill(
        Command::new(driver_bin)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let mut caps = serde_json::Map::new();
    caps.insert(
        "goog:chromeOptions".into(),
        json!({"binary": "/usr/bin/chromium", "args": ["--headless=new", "--no-sandbox", "--window-size=1280,900",
               "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-dev-shm-usage"]}),
    );
    let t0 = Instant::now();
    let c = loop {
        match ClientBuilder::native().capabilities(caps.clone()).connect(&format!("http://127.0.0.1:{port}")).await {
            Ok(c) => break c,
            Err(e) => {
                assert!(t0.elapsed() < Duration::from_secs(30), "cannot start the browser: {e}");
                tokio::time::sleep(Duration::from_millis(200)).await;
            }
        }
    };
    Some((c, driver))
}

#[tokio::test(flavor = "multi_thread")]
async fn the_editor_follows_sliders_handles_and_trim_edits_in_chromium() {
    let Some((c, _driver)) = browser().await else { return };
    let (_server, url) = serve(Some("trim-spline.toml"));
    c.goto(&url).await.unwrap();

    // the first frame, with its diagnostics
    wait_for(&c, "the first frame", "return window.pdeshape.frames > 0 && window.pdeshape.vertexCount > 0").await;
    let h0 = js(&c, "return window.pdeshape.meshHash").await.as_str().unwrap().to_string();
    let diag = wait_for(
        &c,
        "diagnostics",
        "const t = document.getElementById('diag').textContent; return t.includes('trim: folds') && t",
    )
    .await;
    assert!(diag.as_str().unwrap().contains("max condition error"), "{diag}");
    let shot0 = c.screenshot().await.unwrap();

    // a slider, moved with the keyboard like a user
    let slider = c.find(Locator::Css("input[type=range][data-param='a']")).await.unwrap();
    slider.click().await.unwrap();
    slider.send_keys("\u{E014}\u{E014}\u{E014}\u{E014}\u{E014}").await.unwrap();
    let h1 = wait_changed(&c, "the slider", &h0).await;
    let a = js(&c, "return parseFloat(document.querySelector('[data-num=a]').value)").await;
    assert!((a.as_f64().unwrap() - 1.1).abs() > 1e-9, "the slider did not move: {a}");
    tokio::time::sleep(Duration::from_millis(300)).await;
    let shot1 = c.screenshot().await.unwrap();
    assert_ne!(shot0, shot1, "the picture did not change after the slider");

    // a boundary-curve handle, dragged in the view plane
    let n = js(&c, "return window.pdeshape.header.editables.handles.length").await;
    assert!(n.as_u64().unwrap() >= 4, "{n}");
    let at = js(&c, "return window.pdeshape.handleScreenPos(4)").await;
    drag(&c, pos(&at), (0.0, -40.0), 4).await;
    let h2 = wait_changed(&c, "the handle drag", &h1).await;
    let text = js(&c, "return window.pdeshape.header.text").await;
    assert!(!text.as_str().unwrap().contains("[-0.5, 1, 0.9]"), "the edited curve point is still in the scene text");
    let shot2 = c.screenshot().await.unwrap();
    assert_ne!(shot1, shot2);

    // a trim control point, dragged in the parameter-space panel
    let at = js(&c, "return window.pdeshape.trimPointScreenPos(0, 0)").await;
    drag(&c, pos(&at), (12.0, 6.0), 3).await;
    let h3 = wait_changed(&c, "the trim drag", &h2).await;
    assert_ne!(h3, h2);
    // an invalid edit (one jump out of the domain) is shown, and the model stays
    let at = js(&c, "return window.pdeshape.trimPointScreenPos(0, 0)").await;
    drag(&c, pos(&at), (-200.0, 0.0), 1).await;
    let err = wait_for(&c, "the error", "return !window.pdeshape.busy() && window.pdeshape.lastError").await;
    assert!(err.as_str().unwrap().contains("leaves the parameter domain"), "{err}");
    assert_eq!(js(&c, "return window.pdeshape.meshHash").await, json!(h3));
    assert_eq!(js(&c, "return getComputedStyle(document.getElementById('error')).display").await, json!("block"));

    // download an OBJ
    c.find(Locator::Css("button[data-format=obj]")).await.unwrap().click().await.unwrap();
    let d =
        wait_for(&c, "the download", "return window.pdeshape.lastDownload && window.pdeshape.lastDownloadText").await;
    assert!(d.as_str().unwrap().contains("o sheet"), "{d}");
    let bytes = js(&c, "return window.pdeshape.lastDownload.bytes").await;
    assert!(bytes.as_u64().unwrap() > 10_000, "{bytes}");
    // and the model as CAD geometry: measured B-spline faces in STEP
    let d = step_download(&c).await;
    assert!(d > 10_000, "{d}");
    c.close().await.unwrap();
}

/// `pdeshape serve MODEL.step`: the model's faces drawn from their loops, its holes as
/// orange loops; a click on a hole's loop adds a fill of it (order 6) to the scene, solved
/// and drawn; a drag that starts on a loop orbits and adds nothing.
#[tokio::test(flavor = "multi_thread")]
async fn the_editor_opens_a_step_model_and_fills_a_clicked_hole_in_chromium() {
    let Some((c, _driver)) = browser().await else { return };
    let model = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/step/rounded-box-corners.step");
    let (_server, url) = serve_file(Some(&model));
    c.goto(&url).await.unwrap();
    wait_for(&c, "the model", "return window.pdeshape.frames > 0 && window.pdeshape.contextFaces").await;
    let faces = js(&c, "return window.pdeshape.contextFaces").await;
    assert_eq!(faces.as_array().unwrap().len(), 18, "{faces}");
    assert!(faces.as_array().unwrap().contains(&json!("rounded_box_corners.face137")), "{faces}");
    let holes = js(&c, "return window.pdeshape.holes").await;
    assert_eq!(holes.as_array().unwrap().len(), 8, "{holes}");
    assert_eq!(js(&c, "return window.pdeshape.vertexCount").await, json!(0));
    let h0 = js(&c, "return window.pdeshape.meshHash").await.as_str().unwrap().to_string();
    let shot0 = c.screenshot().await.unwrap();

    // names under the mouse: a hole's loop, a face (the middle of the view is on the box)
    let at = js(&c, "return window.pdeshape.holeScreenPos('rounded_box_corners.hole1')").await;
    let (x, y) = pos(&at);
    c.perform_actions(MouseActions::new("mouse".into()).then(PointerAction::MoveTo { duration: None, x, y }))
        .await
        .unwrap();
    let name = wait_for(&c, "the hole's name", "return window.pdeshape.hoverName").await;
    assert_eq!(name, json!("rounded_box_corners.hole1"));
    // a point inside each face in turn: where the face is in sight, it is named
    let mut seen = Vec::new();
    for f in faces.as_array().unwrap() {
        let at = js(&c, &format!("return window.pdeshape.faceScreenPos({f})")).await;
        let (x, y) = pos(&at);
        c.perform_actions(MouseActions::new("mouse".into()).then(PointerAction::MoveTo { duration: None, x, y }))
            .await
            .unwrap();
        tokio::time::sleep(Duration::from_millis(150)).await;
        if js(&c, "return window.pdeshape.hoverName").await == *f {
            seen.push(f.clone());
        }
    }
    // three flat faces and three fillets face the camera; the test's point of three of them
    // is in sight (measured; the others' points are behind an edge of the box)
    assert!(seen.len() >= 3, "faces named under the mouse: {seen:?}");

    // a drag from a loop orbits the view; nothing is filled
    let at = js(&c, "return window.pdeshape.holeScreenPos('rounded_box_corners.hole1')").await;
    drag(&c, pos(&at), (40.0, 0.0), 3).await;
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(js(&c, "return window.pdeshape.lastFill || null").await, Value::Null);

    // a click on hole 1's loop
    let at = js(&c, "return window.pdeshape.holeScreenPos('rounded_box_corners.hole1')").await;
    drag(&c, pos(&at), (0.0, 0.0), 0).await;
    let h1 = wait_changed(&c, "the fill", &h0).await;
    assert_ne!(h1, h0);
    let text = js(&c, "return window.pdeshape.header.text").await;
    let text = text.as_str().unwrap();
    assert!(
        text.contains("[patches.fill_rounded_box_corners_hole1]")
            && text.contains("hole = \"rounded_box_corners.hole1\""),
        "{text}"
    );
    assert!(js(&c, "return window.pdeshape.vertexCount").await.as_u64().unwrap() > 1000);
    let shot1 = c.screenshot().await.unwrap();
    assert_ne!(shot0, shot1, "the picture did not change after the fill");

    // the STEP download is the model with the fill sewn in (the input is 49 929 bytes)
    let d = step_download(&c).await;
    assert!(d > 49_929, "{d}");
    c.close().await.unwrap();
}

/// The analysis views on the cone–cylinder blends: each view changes the picture, curvature
/// legends show finite numbers, the seams' worst-place markers are `check --json`'s, and
/// "show" flies the camera there. Prints how many model updates per second the page
/// received while a slider was moved continuously in the zebra view (a figure, not a
/// pass/fail timing).
#[tokio::test(flavor = "multi_thread")]
async fn the_editor_shows_zebra_curvature_and_seam_continuity_in_chromium() {
    let Some((c, _driver)) = browser().await else { return };
    let (_server, url) = serve(Some("blend-cone-cylinder.toml"));
    c.goto(&url).await.unwrap();
    wait_for(&c, "the first frame", "return window.pdeshape.frames > 0 && window.pdeshape.vertexCount > 0").await;
    wait_for(
        &c,
        "diagnostics and seam markers",
        "return window.pdeshape.seamMarkers && window.pdeshape.seamMarkers.length === 6",
    )
    .await;
    tokio::time::sleep(Duration::from_millis(300)).await;
    let mut shots = vec![("shading".to_string(), c.screenshot().await.unwrap())];
    for view in ["zebra", "isophotes", "gaussian_curvature", "mean_curvature", "k1", "k2"] {
        let frames = js(&c, "return window.pdeshape.frames").await.as_u64().unwrap();
        js(&c, &format!("const f = document.getElementById('field'); f.value = '{view}'; f.dispatchEvent(new Event('change')); return 0")).await;
        wait_for(&c, view, &format!("return window.pdeshape.frames > {frames} && window.pdeshape.view === '{view}'"))
            .await;
        tokio::time::sleep(Duration::from_millis(200)).await;
        let shot = c.screenshot().await.unwrap();
        for (other, s) in &shots {
            assert_ne!(&shot, s, "{view} looks like {other}");
        }
        let legend = js(&c, "return window.pdeshape.legend").await;
        let shown = js(&c, "return [...document.querySelectorAll('#legendnums span')].map((e) => e.textContent)").await;
        if view.contains("curvature") || view.starts_with('k') {
            let (lo, hi) = (legend["lo"].as_f64().unwrap(), legend["hi"].as_f64().unwrap());
            assert!(hi.is_finite() && hi > 0.0 && lo == -hi, "{view}: {legend}");
            let nums: Vec<f64> =
                shown.as_array().unwrap().iter().map(|x| x.as_str().unwrap().parse().unwrap()).collect();
            assert!(nums.iter().all(|x| x.is_finite()) && nums[1] == 0.0 && nums[2] > 0.0, "{view}: {shown}");
        } else {
            assert!(legend.is_null(), "{view}: no legend for stripes ({legend})");
        }
        shots.push((view.to_string(), shot));
    }
    // an edited limit is kept (and the automatic one switched off)
    js(
        &c,
        "const e = document.getElementById('climit'); e.value = '0.5'; e.dispatchEvent(new Event('input')); return 0",
    )
    .await;
    wait_for(&c, "the edited limit", "return window.pdeshape.legend && window.pdeshape.legend.hi === 0.5").await;

    // the seam markers are check's worst places, value and point
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(["check", "--json"])
        .arg(common::example("blend-cone-cylinder.toml"))
        .output()
        .unwrap();
    let check: Value = serde_json::from_slice(&out.stdout).unwrap();
    let markers = js(&c, "return window.pdeshape.seamMarkers").await;
    let markers = markers.as_array().unwrap();
    for (m, p) in markers.iter().zip(check["patches"].as_array().unwrap()) {
        let w = &p["continuity"]["worst"]["g1_radians"];
        assert_eq!(m["patch"], p["name"]);
        let nums = |x: &Value| -> Vec<f64> {
            let mut v = vec![x["value"].as_f64().unwrap(), x["u"].as_f64().unwrap(), x["v"].as_f64().unwrap()];
            v.extend(x["point"].as_array().unwrap().iter().map(|c| c.as_f64().unwrap()));
            v
        };
        // the same f64 bits: the page shows the numbers check prints
        assert_eq!(nums(m), nums(w), "{m} vs {w}");
    }
    let seams = js(&c, "return window.pdeshape.seams").await;
    assert_eq!(seams.as_array().unwrap().len(), 12, "two seams per blend: {seams}");
    // the C0 blend's seam is red where the C2 blend's is green (f32 of the per-vertex G1 angles)
    assert!(seams[0]["max"].as_f64().unwrap() > 0.1 && seams[10]["max"].as_f64().unwrap() < 1e-9, "{seams}");
    // "show" flies the camera to the worst place of o2
    c.find(Locator::Css("button[data-seam='0']")).await.unwrap().click().await.unwrap();
    wait_for(&c, "the flight", "return window.pdeshape.flying === false").await;
    let target = js(&c, "return window.pdeshape.cam.target").await;
    for k in 0..3 {
        let (a, b) = (target[k].as_f64().unwrap(), markers[0]["point"][k].as_f64().unwrap());
        assert!((a - b).abs() < 1e-12, "camera target {target} vs marker {}", markers[0]["point"]);
    }

    // a plane section at the middle of z: every cut point on the plane, with a curvature;
    // combs on both trimlines of the six blends
    js(&c, "document.getElementById('section').click(); return 0").await;
    wait_for(
        &c,
        "the section",
        "return !window.pdeshape.busy() && window.pdeshape.curves && window.pdeshape.curves.segments > 0",
    )
    .await;
    let cut =
        js(&c, "return [window.pdeshape.header.curves, parseFloat(document.getElementById('secval').textContent)]")
            .await;
    let mut points = 0;
    for p in cut[0].as_array().unwrap() {
        for seg in p["section"].as_array().unwrap() {
            for i in [2, 8] {
                let z = seg[i].as_f64().unwrap();
                // the offset shown with 3 decimals; the points are on the exact plane
                assert!((z - cut[1].as_f64().unwrap()).abs() < 6e-4, "{z} vs {}", cut[1]);
                assert!(seg[i + 1].as_f64().is_some_and(f64::is_finite), "a curvature at every cut point");
                points += 1;
            }
        }
    }
    assert!(points > 100, "{points} cut points");
    js(&c, "document.getElementById('combs').click(); return 0").await;
    wait_for(
        &c,
        "the combs",
        "return !window.pdeshape.busy() && window.pdeshape.curves && window.pdeshape.curves.combs === 12",
    )
    .await;

    // live: a slider moved continuously for 3 s in the zebra view
    js(
        &c,
        "const f = document.getElementById('field'); f.value = 'zebra'; f.dispatchEvent(new Event('change')); return 0",
    )
    .await;
    let u0 = js(&c, "return window.pdeshape.updates").await.as_u64().unwrap();
    let t0 = Instant::now();
    js(&c, "const s = document.querySelector('input[type=range][data-param=R]'); let k = 0;
            window.__sweep = setInterval(() => { s.value = 1.0 + 0.4 * Math.sin(k++ / 10); s.dispatchEvent(new Event('input')); }, 16);
            return 0").await;
    tokio::time::sleep(Duration::from_secs(3)).await;
    js(&c, "clearInterval(window.__sweep); return 0").await;
    let dt = t0.elapsed().as_secs_f64();
    let n = js(&c, "return window.pdeshape.updates").await.as_u64().unwrap() - u0;
    let t = js(
        &c,
        &format!(
            "const t = window.pdeshape.timings.slice({u0}); const med = (xs) => xs.sort((a, b) => a - b)[xs.length >> 1];
             return [med(t.map((x) => x.total)), med(t.map((x) => x.server))]"
        ),
    )
    .await;
    eprintln!(
        "live updates while dragging R in the zebra view (blend-cone-cylinder, 6 blends, section and combs on): \
         {n} in {dt:.1} s = {:.1}/s; median request-to-upload {:.0} ms, of it solve and mesh on the server {:.0} ms",
        n as f64 / dt,
        t[0].as_f64().unwrap_or(f64::NAN),
        t[1].as_f64().unwrap_or(f64::NAN)
    );
    assert!(n >= 3, "the view followed the slider {n} times in {dt:.1} s");
    c.close().await.unwrap();
}

/// How fast the editor follows a dragged slider, per example and view: a figure to quote,
/// not a pass/fail timing (run by hand, ideally against a release server:
/// `PDESHAPE_SERVE_BIN=target/release/pdeshape cargo test -p pdeshape --test editor
/// live_update_rates -- --ignored --nocapture`).
#[tokio::test(flavor = "multi_thread")]
#[ignore = "a measurement, printed; run by hand"]
async fn live_update_rates() {
    let Some((c, _driver)) = browser().await else { return };
    for (scene, param, lo, hi) in [
        ("klein-bottle.toml", "a", 0.8, 1.6),
        ("bloor-wilson-blend.toml", "r", 0.8, 1.4),
        ("four-curve-patch.toml", "", 0.0, 0.0),
        ("blend-torus-hyperboloid.toml", "", 0.0, 0.0),
        ("blend-cone-cylinder.toml", "R", 1.0, 1.4),
    ] {
        let (_server, url) = serve(Some(scene));
        c.goto(&url).await.unwrap();
        wait_for(&c, "the first frame", "return window.pdeshape.frames > 0 && window.pdeshape.vertexCount > 0").await;
        let param = if param.is_empty() {
            js(&c, "return document.querySelector('input[type=range][data-param]').dataset.param")
                .await
                .as_str()
                .unwrap()
                .to_string()
        } else {
            param.to_string()
        };
        for view in ["", "zebra", "mean_curvature"] {
            js(&c, &format!("const f = document.getElementById('field'); f.value = '{view}'; f.dispatchEvent(new Event('change')); return 0")).await;
            tokio::time::sleep(Duration::from_millis(500)).await;
            let u0 = js(&c, "return window.pdeshape.updates").await.as_u64().unwrap();
            let t0 = Instant::now();
            js(&c, &format!(
                "const s = document.querySelector('input[type=range][data-param={param}]'); let k = 0;
                 const lo = {lo} || parseFloat(s.min), hi = {hi} || parseFloat(s.max), m = (lo + hi) / 2, a = (hi - lo) / 4;
                 window.__sweep = setInterval(() => {{ s.value = m + a * Math.sin(k++ / 10); s.dispatchEvent(new Event('input')); }}, 16);
                 return 0"
            )).await;
            tokio::time::sleep(Duration::from_secs(3)).await;
            js(&c, "clearInterval(window.__sweep); return 0").await;
            let dt = t0.elapsed().as_secs_f64();
            wait_for(&c, "quiet", "return !window.pdeshape.busy()").await;
            let n = js(&c, "return window.pdeshape.updates").await.as_u64().unwrap() - u0;
            let t = js(
                &c,
                &format!(
                    "const t = window.pdeshape.timings.slice({u0}); const med = (xs) => xs.sort((a, b) => a - b)[xs.length >> 1];
                     return [med(t.map((x) => x.total)), med(t.map((x) => x.server)), window.pdeshape.vertexCount]"
                ),
            )
            .await;
            eprintln!(
                "{scene} {param} view {:<15} {:>5.1} updates/s, median request-to-upload {:>4.0} ms (server {:>4.0} ms), {} vertices",
                if view.is_empty() { "shading" } else { view },
                n as f64 / dt,
                t[0].as_f64().unwrap_or(f64::NAN),
                t[1].as_f64().unwrap_or(f64::NAN),
                t[2]
            );
        }
    }
    c.close().await.unwrap();
}
