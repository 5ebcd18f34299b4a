//! Helpers shared by the editor tests: a `pdeshape serve` child that dies with the test.
#![allow(dead_code)]

pub mod hermite_ode;

use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};

/// Kills and reaps the child when dropped (also when a test panics).
pub struct Kill(pub Child);
impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The path of a scene file under `examples/`.
pub fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

/// Starts `pdeshape serve [SCENE] --port 0` and returns it with the URL it printed. The
/// binary is the one under test, or `PDESHAPE_SERVE_BIN` when set (to measure the editor
/// against a release build).
pub fn serve(scene: Option<&str>) -> (Kill, String) {
    serve_file(scene.map(example).as_deref())
}

/// `pdeshape serve FILE --port 0` (a scene or a model file; none: the chooser); the child
/// and the URL it printed.
#[allow(dead_code)]
pub fn serve_file(file: Option<&std::path::Path>) -> (Kill, String) {
    let mut args: Vec<String> = file.map(|s| s.to_string_lossy().into_owned()).into_iter().collect();
    args.extend(["--port".into(), "0".into()]);
    let bin = std::env::var("PDESHAPE_SERVE_BIN").unwrap_or_else(|_| env!("CARGO_BIN_EXE_pdeshape").to_string());
    let mut child =
        Command::new(bin).arg("serve").args(&args).stdout(Stdio::piped()).spawn().expect("pdeshape serve starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let url = line.trim().rsplit(' ').next().unwrap_or_default().to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "serve printed {line:?}");
    (Kill(child), url)
}

/// `pdeshape build SCENE -o out.obj` on `scene` (a file in a temporary directory) fails with
/// exit code 1, without a panic, with every string of `expect` in its message, and writes
/// nothing.
pub fn build_fails(scene: &str, expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let out = dir.path().join("out.obj");
    let o = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .arg("build")
        .arg(&path)
        .arg("-o")
        .arg(&out)
        .arg("-q")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for e in expect {
        assert!(err.contains(e), "expected `{e}` in\n{err}");
    }
    assert!(!out.exists());
}

/// Every key path of a JSON value (`patches.[].spectral.order`), array indices as `[]`,
/// without the parameters' own names (they are the scenes').
pub fn key_paths(v: &serde_json::Value, at: &str, out: &mut std::collections::BTreeSet<String>) {
    let join = |k: &str| if at.is_empty() { k.to_string() } else { format!("{at}.{k}") };
    match v {
        serde_json::Value::Object(m) => {
            for (k, x) in m {
                let path = join(k);
                out.insert(path.clone());
                if path != "parameters" {
                    key_paths(x, &path, out);
                }
            }
        }
        serde_json::Value::Array(a) => {
            for x in a {
                let path = join("[]");
                out.insert(path.clone());
                key_paths(x, &path, out);
            }
        }
        _ => {}
    }
}
