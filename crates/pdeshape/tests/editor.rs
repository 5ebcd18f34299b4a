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
use common::{Kill, serve};
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

fn pos(v: &Value) -> (f64, f64) {
    (v[0].as_f64().unwrap().round(), v[1].as_f64().unwrap().round())
}

#[tokio::test(flavor = "multi_thread")]
async fn the_editor_follows_sliders_handles_and_trim_edits_in_chromium() {
    let required = std::env::var("PDESHAPE_REQUIRE_BROWSER").is_ok_and(|v| v == "1");
    let driver_bin = ["/usr/bin/chromedriver", "/usr/lib/chromium/chromedriver"]
        .into_iter()
        .find(|p| std::path::Path::new(p).exists());
    let Some(driver_bin) = driver_bin else {
        assert!(!required, "chromedriver not found: install Debian's chromium and chromium-driver");
        eprintln!("skipped: no chromedriver (install chromium and chromium-driver; .ci/run does)");
        return;
    };
    let (_server, url) = serve(Some("trim-spline.toml"));
    let port = free_port();
    let _driver = Kill(
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
    c.close().await.unwrap();
}
