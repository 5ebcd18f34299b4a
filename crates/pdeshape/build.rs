//! Embeds the scene files of `examples/` into the binary, so `pdeshape gallery` works from
//! any directory.

use std::fmt::Write as _;
use std::path::Path;

fn main() {
    // read when the script runs, not when it is compiled: a script binary reused from a
    // build of another checkout would otherwise read that checkout's (possibly gone) examples
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = Path::new(&manifest).join("../../examples");
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok()).map(|e| e.path()).filter(|p| p.extension().is_some_and(|x| x == "toml")).collect()
        })
        .unwrap_or_else(|e| panic!("cannot read the examples in {}: {e}", dir.display()));
    files.sort();
    assert!(!files.is_empty(), "no scene files in {}", dir.display());
    let mut out =
        String::from("/// Built-in example scenes: (name, scene text).\npub const EXAMPLES: &[(&str, &str)] = &[\n");
    for f in &files {
        println!("cargo:rerun-if-changed={}", f.display());
        let name = f.file_stem().unwrap().to_string_lossy();
        let abs = f.canonicalize().unwrap();
        writeln!(out, "    ({name:?}, include_str!({:?})),", abs.display().to_string()).unwrap();
    }
    out.push_str("];\n");
    let dest = Path::new(&std::env::var("OUT_DIR").unwrap()).join("examples.rs");
    std::fs::write(dest, out).unwrap();
}
