//! `pdeshape serve` against hostile requests (SPEC §14, SECURITY.md): raw HTTP/1.1 over
//! loopback so that every header (Host, Origin, Content-Type) is the test's own.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::PathBuf;
use std::time::{Duration, Instant};

mod common;
use common::{Kill, example};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};

/// Starts `pdeshape serve --port 0` with extra arguments; returns the child and `host:port`.
fn start(args: &[&str]) -> (Kill, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(["serve", "--port", "0"])
        .args(args)
        .stdout(Stdio::piped())
        .spawn()
        .expect("pdeshape serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let addr = line.trim().rsplit(' ').next().unwrap().trim_start_matches("http://").trim_end_matches('/').to_string();
    assert!(addr.starts_with("127.0.0.1:"), "serve printed {line:?}");
    (Kill(child), addr)
}

struct Answer {
    status: u16,
    headers: String,
    body: Vec<u8>,
}

impl Answer {
    fn text(&self) -> String {
        String::from_utf8_lossy(&self.body).into_owned()
    }
}

/// Sends one request (`Connection: close`) and reads the whole answer.
fn request(addr: &str, method: &str, path: &str, headers: &[(&str, &str)], body: &[u8]) -> Answer {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
    let mut head = format!("{method} {path} HTTP/1.1\r\nConnection: close\r\nContent-Length: {}\r\n", body.len());
    for (k, v) in headers {
        head.push_str(&format!("{k}: {v}\r\n"));
    }
    head.push_str("\r\n");
    s.write_all(head.as_bytes()).unwrap();
    s.write_all(body).unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw.windows(4).position(|w| w == b"\r\n\r\n").expect("a complete answer");
    let headers = String::from_utf8_lossy(&raw[..split]).into_owned();
    let status = headers.split(' ').nth(1).unwrap().parse().unwrap();
    let mut body = raw[split + 4..].to_vec();
    if headers.to_ascii_lowercase().contains("transfer-encoding: chunked") {
        body = dechunk(&body);
    }
    Answer { status, headers, body }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let eol = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let n = usize::from_str_radix(std::str::from_utf8(&b[..eol]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[eol + 2..eol + 2 + n]);
        b = &b[eol + 2 + n + 2..];
    }
}

fn post_json(addr: &str, path: &str, body: &serde_json::Value) -> Answer {
    let host = addr.to_string();
    request(
        addr,
        "POST",
        path,
        &[("Host", &host), ("Content-Type", "application/json"), ("Origin", &format!("http://{addr}"))],
        body.to_string().as_bytes(),
    )
}

fn scene(name: &str) -> String {
    std::fs::read_to_string(example(name)).unwrap()
}

/// Regression (high): the export route joined the request's `name` to a directory, so
/// `../../../../tmp/x` wrote `/tmp/x.obj`. The bytes now come from memory; the download
/// name is sanitised; nothing is written anywhere.
#[test]
fn export_never_writes_a_path_from_the_request() {
    let (_k, addr) = start(&[]);
    let target = std::env::temp_dir().join(format!("pdeshape-escape-{}", std::process::id()));
    let _ = std::fs::remove_file(target.with_extension("obj"));
    for name in [format!("../../../../../..{}", target.display()), target.display().to_string()] {
        let a = post_json(
            &addr,
            "/api/export?format=obj",
            &serde_json::json!({"text": scene("hermite-ruled.toml"), "name": name}),
        );
        assert_eq!(a.status, 200, "{}", a.text());
        assert!(a.text().starts_with("# pdeshape") || a.text().contains("\nv "), "an OBJ: {}", &a.text()[..80]);
        let cd = a.headers.lines().find(|l| l.to_ascii_lowercase().starts_with("content-disposition")).unwrap();
        let file = cd.split("filename=\"").nth(1).unwrap().trim_end_matches('"');
        assert!(file.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)), "{cd}");
        assert!(!file.contains(".."), "{cd}");
        assert!(!target.with_extension("obj").exists(), "a file was written at {}", target.display());
    }
}

/// The editor's STEP download: measured B-spline faces of the model at the editor's
/// time (a dynamic blend's frame), with the scene's sanitised name; an unknown format is
/// refused.
#[test]
fn export_offers_step_at_the_editors_time() {
    let (_k, addr) = start(&[]);
    let text = scene("dynamic-elliptic-cylinders.toml");
    let mut bodies = Vec::new();
    for time in [0.0, 0.6] {
        let a = post_json(
            &addr,
            "/api/export?format=step",
            &serde_json::json!({"text": text, "name": "dyn", "time": time}),
        );
        assert_eq!(a.status, 200, "{}", a.text());
        let t = a.text();
        assert!(t.starts_with("ISO-10303-21;") && t.trim_end().ends_with("END-ISO-10303-21;"), "{}", &t[..80]);
        // the blend and the two drawn primary surfaces
        assert_eq!(t.matches("=ADVANCED_FACE(").count(), 3, "{t}");
        let cd = a.headers.lines().find(|l| l.to_ascii_lowercase().starts_with("content-disposition")).unwrap();
        assert!(cd.contains("filename=\"dyn.step\""), "{cd}");
        bodies.push(t.to_string());
    }
    assert_ne!(bodies[0], bodies[1], "the frame at t = 0.6 is not the first");
    let a = post_json(&addr, "/api/export?format=iges", &serde_json::json!({"text": text}));
    assert_eq!(a.status, 400);
    assert!(a.text().contains("known: obj, ply, stl, glb, vtu, step"), "{}", a.text());
}

/// DNS rebinding: a page on attacker.example resolving to 127.0.0.1 sends `Host:
/// attacker.example:PORT`; such requests are refused (421) before any work.
#[test]
fn requests_for_other_hosts_and_from_other_sites_are_refused() {
    let (_k, addr) = start(&[]);
    let port = addr.rsplit(':').next().unwrap();
    let ok = request(&addr, "GET", "/api/examples", &[("Host", &addr)], b"");
    assert_eq!(ok.status, 200);
    let local = format!("localhost:{port}");
    assert_eq!(request(&addr, "GET", "/api/examples", &[("Host", &local)], b"").status, 200);
    for host in [format!("attacker.example:{port}"), "attacker.example".into(), format!("127.0.0.1:{}1", port)] {
        let a = request(&addr, "GET", "/", &[("Host", &host)], b"");
        assert_eq!(a.status, 421, "Host {host}: {}", a.text());
        assert!(a.text().contains("answers only requests for"), "{}", a.text());
    }
    // a POST with a foreign Origin: 403 even with the right Host
    let body = serde_json::json!({"text": scene("hermite-ruled.toml")}).to_string();
    let a = request(
        &addr,
        "POST",
        "/api/model",
        &[("Host", &addr), ("Content-Type", "application/json"), ("Origin", "http://attacker.example")],
        body.as_bytes(),
    );
    assert_eq!(a.status, 403, "{}", a.text());
    let a = request(
        &addr,
        "POST",
        "/api/model",
        &[("Host", &addr), ("Content-Type", "application/json"), ("Sec-Fetch-Site", "cross-site")],
        body.as_bytes(),
    );
    assert_eq!(a.status, 403, "{}", a.text());
    // a cross-site "simple" request (a form post: text/plain, no preflight) is not JSON: 415
    let a = request(&addr, "POST", "/api/model", &[("Host", &addr), ("Content-Type", "text/plain")], body.as_bytes());
    assert_eq!(a.status, 415, "{}", a.text());
    // the API takes no GET
    assert_eq!(request(&addr, "GET", "/api/model", &[("Host", &addr)], b"").status, 405);
    // the same model request from the page's own origin works
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": scene("hermite-ruled.toml")}));
    assert_eq!(a.status, 200, "{}", a.text());
}

/// Regression (high): 3 500 terms `v+v+…+v` (18 KB) overflowed the worker's stack and
/// aborted the editor. Now a 422 naming the cap, and the server answers the next request.
#[test]
fn a_long_expression_is_an_error_not_an_abort() {
    let (mut k, addr) = start(&[]);
    let long = vec!["v"; 20_000].join("+");
    let text = scene("hermite-ruled.toml").replacen("[parameters]\n", &format!("[parameters]\nq = \"{long}\"\n"), 1);
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": text}));
    assert_eq!(a.status, 422, "{}", &a.text()[..a.text().len().min(300)]);
    assert!(a.text().contains("too long or too deep"), "{}", &a.text()[..300.min(a.text().len())]);
    assert!(a.text().len() < 4000, "the error echoes {} bytes", a.text().len());
    assert!(k.0.try_wait().unwrap().is_none(), "the server died");
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": scene("hermite-ruled.toml")}));
    assert_eq!(a.status, 200);
}

/// The curve tools' request is checked before any work: unknown axes and keys, non-finite
/// offsets (a JSON number cannot be one, so a string) and `iso_u` outside [0, 1] are
/// refused with a message naming the field; a good one answers.
#[test]
fn bad_curve_requests_are_refused_by_name() {
    let (mut k, addr) = start(&[]);
    let text = scene("blend-torus-hyperboloid.toml");
    for (curves, status, says) in [
        (serde_json::json!({"section": {"axis": "w", "offset": 0.0}}), 422, "curves.section.axis must be x, y or z"),
        (serde_json::json!({"iso_u": 1.5}), 422, "curves.iso_u must be in [0, 1]"),
        (serde_json::json!({"section": {"axis": "x", "offset": "inf"}}), 422, "offset"),
        (serde_json::json!({"sections": 3}), 422, "unknown field `sections`"),
    ] {
        let a = post_json(&addr, "/api/model", &serde_json::json!({"text": text, "curves": curves}));
        assert_eq!(a.status, status, "{curves}: {}", a.text());
        assert!(a.text().contains(says), "{curves}: {}", a.text());
    }
    let good = serde_json::json!({"section": {"axis": "z", "offset": 0.2}, "combs": true, "iso_u": 0.5});
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": text, "curves": good}));
    assert_eq!(a.status, 200);
    assert!(k.0.try_wait().unwrap().is_none(), "the server died");
}

/// CPU seconds (user + system) the process has used, from /proc.
fn cpu_seconds(pid: u32) -> f64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap().split_whitespace().collect();
    // fields after the name: state is [0]; utime [11], stime [12] (clock ticks, 100 Hz)
    (fields[11].parse::<f64>().unwrap() + fields[12].parse::<f64>().unwrap()) / 100.0
}

/// A scene of many seconds at any foreseeable speed: the Klein bottle at order 64 with 65
/// modes (about 5 s of solve on this machine) meshed at 1400 × 1400 (just under the
/// editor's vertex limit). A term that is no trigonometric polynomial in the sections'
/// `z`: the bottle's own sections are of degree 1 and would leave modes 2 … 64 unsolved.
fn slow_scene() -> String {
    let s = scene("klein-bottle.toml")
        .replace("count = 40", "count = 64")
        .replace("modes = 6", "modes = 64")
        .replace("resolution = [161, 65]", "resolution = [1400, 1400]")
        .replace("\"4*(1 - cos(s)/2)*sin(v)\"", "\"4*(1 - cos(s)/2)*sin(v) + 0.01*exp(cos(v))\"");
    assert!(s.contains("modes = 64") && s.contains("exp(cos(v))"));
    s
}

/// Regression (high): a solve past the limit got its 503 but kept a core busy, and its
/// slot was released at once. Now it is cancelled: the CPU time stops growing and the next
/// request is served at once.
#[test]
fn a_solve_past_its_limit_is_cancelled_and_frees_its_core() {
    let (k, addr) = start(&["--time-limit", "2"]);
    let pid = k.0.id();
    let t0 = Instant::now();
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": slow_scene()}));
    let waited = t0.elapsed();
    assert_eq!(a.status, 503, "{}", a.text());
    assert!(a.text().contains("longer than the editor's limit of 2 s"), "{}", a.text());
    assert!(waited < Duration::from_secs(5), "the 503 came after {waited:?}");
    // the cancelled solve stops within a checkpoint's time
    std::thread::sleep(Duration::from_millis(1500));
    let c0 = cpu_seconds(pid);
    std::thread::sleep(Duration::from_secs(2));
    let burnt = cpu_seconds(pid) - c0;
    assert!(burnt < 0.3, "the server used {burnt} CPU seconds in 2 s after the cancelled solve");
    let t1 = Instant::now();
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": scene("hermite-ruled.toml")}));
    assert_eq!(a.status, 200, "{}", a.text());
    assert!(t1.elapsed() < Duration::from_secs(2), "the next request took {:?}", t1.elapsed());
}

/// Fairness: more slow requests than the queue holds get 429 at once; the queue clock
/// includes waiting, so none waits past the limit; afterwards a fast request is served.
#[test]
fn the_queue_is_bounded_and_waiting_counts_toward_the_limit() {
    let (_k, addr) = start(&["--time-limit", "3"]);
    let n = 16; // two cores solve, eight wait: at least six are refused
    let handles: Vec<_> = (0..n)
        .map(|_| {
            let addr = addr.clone();
            std::thread::spawn(move || {
                let t0 = Instant::now();
                let a = post_json(&addr, "/api/model", &serde_json::json!({"text": slow_scene()}));
                (a.status, t0.elapsed(), a.text())
            })
        })
        .collect();
    let answers: Vec<_> = handles.into_iter().map(|h| h.join().unwrap()).collect();
    let refused = answers.iter().filter(|a| a.0 == 429).count();
    let timed_out = answers.iter().filter(|a| a.0 == 503).count();
    assert_eq!(refused + timed_out, n, "{:?}", answers.iter().map(|a| (a.0, &a.2)).collect::<Vec<_>>());
    assert!(refused >= n - 8 - 2, "only {refused} refused");
    for (status, took, text) in &answers {
        if *status == 429 {
            assert!(text.contains("requests are waiting"), "{text}");
        }
        assert!(*took < Duration::from_secs(6), "an answer took {took:?}");
    }
    std::thread::sleep(Duration::from_secs(2));
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": scene("hermite-ruled.toml")}));
    assert_eq!(a.status, 200, "{}", a.text());
}

/// Caps bound the solver's memory: a static blend whose collocation system would need
/// gigabytes is refused before allocating, naming the cap.
#[test]
fn solver_memory_is_checked_against_the_cap() {
    let (_k, addr) = start(&[]);
    let big = heavy_blend(&scene("blend-cone-cylinder.toml"));
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": big}));
    assert_eq!(a.status, 422, "{}", a.text());
    assert!(a.text().contains("`memory` cap"), "{}", a.text());
}

/// The first blend patch of `text` with the largest collocation grid and bubble count.
fn heavy_blend(text: &str) -> String {
    let at = text.find("kind = \"blend\"").expect("a blend patch");
    let mut out = text.to_string();
    out.insert_str(at, "solver = \"collocation\"\ncollocation = [500, 500]\nbubbles = 512\n");
    out
}

/// Regression (medium): four slow downloads from one client made every light request of
/// another fail (20 × 429, 6 × 503). Downloads have their own slot and queue now: while four
/// clients keep the export lane busy with solves that run past the limit, 26 light
/// requests of a fifth client are all answered, each well within the limit.
#[test]
fn slow_downloads_do_not_starve_live_requests() {
    let (_k, addr) = start(&["--time-limit", "2"]);
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let exporters: Vec<_> = (0..4)
        .map(|_| {
            let (addr, stop) = (addr.clone(), stop.clone());
            std::thread::spawn(move || {
                let mut statuses = Vec::new();
                while !stop.load(std::sync::atomic::Ordering::SeqCst) {
                    let a = post_json(&addr, "/api/export?format=step", &serde_json::json!({"text": slow_scene()}));
                    statuses.push((a.status, a.text()));
                }
                statuses
            })
        })
        .collect();
    // let the exports fill their lane first
    std::thread::sleep(Duration::from_millis(500));
    let light = scene("hermite-ruled.toml");
    for k in 0..26 {
        let t = Instant::now();
        let a = post_json(&addr, "/api/model", &serde_json::json!({"text": light}));
        assert_eq!(a.status, 200, "light request {k}: {}", a.text());
        assert!(t.elapsed() < Duration::from_millis(1500), "light request {k} took {:?}", t.elapsed());
    }
    stop.store(true, std::sync::atomic::Ordering::SeqCst);
    for h in exporters {
        for (status, text) in h.join().unwrap() {
            // past the limit (503, worded as a stop or a queue time-out) or refused (429)
            assert!(status == 503 || status == 429, "{status}: {text}");
            if status == 503 {
                assert!(text.contains("was stopped") || text.contains("in the queue"), "{text}");
            }
        }
    }
}

/// Regression (medium): connections that send half a request and then nothing stayed open
/// for ever (40 still open after 65 s). With `--time-limit 1` a connection silent for
/// 1 + 5 s is closed; the server still answers afterwards.
#[test]
fn stalled_connections_are_closed() {
    let (_k, addr) = start(&["--time-limit", "1"]);
    let mut stalled: Vec<TcpStream> = (0..5)
        .map(|_| {
            let mut s = TcpStream::connect(&addr).unwrap();
            s.write_all(b"GET / HTTP/1.1\r\nHost: ").unwrap();
            s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
            s
        })
        .collect();
    let t = Instant::now();
    for s in &mut stalled {
        let mut buf = [0u8; 64];
        // closed by the server: end of stream (or a reset), not our read time-out
        match s.read(&mut buf) {
            Ok(n) => assert!(n == 0 || String::from_utf8_lossy(&buf[..n]).starts_with("HTTP/1.1 4"), "{n} bytes"),
            Err(e) => {
                assert!(matches!(e.kind(), std::io::ErrorKind::ConnectionReset | std::io::ErrorKind::BrokenPipe), "{e}")
            }
        }
    }
    let closed_after = t.elapsed();
    assert!(closed_after >= Duration::from_secs(5) && closed_after < Duration::from_secs(12), "{closed_after:?}");
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": scene("hermite-ruled.toml")}));
    assert_eq!(a.status, 200, "{}", a.text());
}

/// The limits that had no test: a body over 1 MiB is 413 before it is read as JSON; a model
/// over 2 000 000 vertices is 422 naming the editor's limit; `[::1]:PORT` is one of the
/// loopback names answered, `[::1]` without the port is not.
#[test]
fn body_size_vertex_count_and_loopback_names() {
    let (_k, addr) = start(&[]);
    let port = addr.rsplit(':').next().unwrap();
    let big = serde_json::json!({"text": format!("# {}\n{}", "x".repeat(1 << 20), scene("hermite-ruled.toml"))});
    let a = post_json(&addr, "/api/model", &big);
    assert_eq!(a.status, 413, "{}", a.text());
    let huge = scene("klein-bottle.toml").replace("resolution = [161, 65]", "resolution = [1500, 1500]");
    let a = post_json(&addr, "/api/model", &serde_json::json!({ "text": huge }));
    assert_eq!(a.status, 422, "{}", a.text());
    assert!(a.text().contains("2250000 vertices") && a.text().contains("limit is 2000000"), "{}", a.text());
    let v6 = format!("[::1]:{port}");
    assert_eq!(request(&addr, "GET", "/api/examples", &[("Host", &v6)], b"").status, 200);
    assert_eq!(request(&addr, "GET", "/api/examples", &[("Host", "[::1]")], b"").status, 421);
}

/// A request's scene text comes from a web page: its `[import.*]` may name only the models
/// the editor's own scene imported at start (by the path as that scene wrote it), never
/// another file, whose bytes (or whether it exists) would otherwise leak into the answer.
#[test]
fn requests_import_only_what_the_editors_scene_imported() {
    let dir = tempfile::tempdir().unwrap();
    let step = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/step/cylinder-open.step");
    std::fs::copy(&step, dir.path().join("part.step")).unwrap();
    let own = "[import.part]\nstep = \"part.step\"\n\n[patches.top]\nkind = \"fill\"\nhole = \"part.hole1\"\n";
    let scene_file = dir.path().join("top.toml");
    std::fs::write(&scene_file, own).unwrap();

    // no scene at start: nothing may be imported
    let (_k, addr) = start(&[]);
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": own}));
    assert_eq!(a.status, 422, "{}", a.text());
    assert!(a.text().contains("not read from a file"), "{}", a.text());

    // its own scene's import is served; any other path is refused without being read
    let (_k2, addr) = start(&[scene_file.to_str().unwrap()]);
    let a = post_json(&addr, "/api/model", &serde_json::json!({"text": own}));
    assert_eq!(a.status, 200, "{}", a.text());
    for path in ["/etc/passwd", "../part.step", step.to_str().unwrap()] {
        let text = own.replace("part.step", path);
        let a = post_json(&addr, "/api/model", &serde_json::json!({"text": text}));
        assert_eq!(a.status, 422, "{path}: {}", a.text());
        assert!(a.text().contains("only the models the scene imported"), "{path}: {}", a.text());
        assert!(!a.text().contains("root:"), "{path}: {}", a.text());
    }
}
