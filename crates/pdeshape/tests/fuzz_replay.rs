//! The fuzz targets' bodies (`fuzz/src/lib.rs`), compiled into this test and run on every
//! seed input and every crash input kept under `fuzz/regressions/`: the targets cannot
//! rot unbuilt, and a crash once found stays fixed. The long libFuzzer runs themselves
//! are in `fuzz/README.md`.

#[path = "../../../fuzz/src/lib.rs"]
mod bodies;

use std::path::PathBuf;

fn inputs(target: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut out = Vec::new();
    for dir in ["seeds", "regressions"] {
        // both folders are tracked (`regressions/TARGET/.keep`): a missing one is a broken
        // checkout or a renamed target, not "no inputs"
        let path = root.join(dir).join(target);
        let entries = std::fs::read_dir(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        for e in entries {
            let p = e.unwrap().path();
            if p.is_file() && !p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')) {
                out.push((p.clone(), std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

fn replay(target: &str, body: fn(&[u8]), at_least: usize) {
    let all = inputs(target);
    assert!(all.len() >= at_least, "{target}: {} inputs", all.len());
    for (path, data) in &all {
        if let Err(e) = std::panic::catch_unwind(|| body(data)) {
            let msg = e.downcast_ref::<String>().cloned().or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()));
            panic!("fuzz target {target} panics on {}: {msg:?}", path.display());
        }
    }
}

#[test]
fn expr_inputs_replay() {
    replay("expr", bodies::expr, 2);
}

#[test]
fn scene_inputs_replay() {
    replay("scene", bodies::scene, 10);
}

#[test]
fn bspline_inputs_replay() {
    replay("bspline", bodies::bspline, 1);
}

#[test]
fn trim_inputs_replay() {
    replay("trim", bodies::trim, 4);
}

#[test]
fn edit_inputs_replay() {
    replay("edit", bodies::edit, 5);
}
