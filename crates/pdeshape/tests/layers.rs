//! No import circles between the workspace's source files.
//!
//! A file's module uses another when its code names a path into it (`crate::a::b::X`,
//! `super::x::f`, `child::g`, `use super::{x, y}`); the longest module with a file of its
//! own is the target. A module naming its own ancestors (`super::Type`: the types a folder's
//! `mod.rs` shares with its files) is how a folder holds together and does not count; every
//! other use does: between siblings (`scene/build.rs` ↔ `scene/trim.rs`), from a parent into
//! its children and across folders. A circle among those is a failure, listed file by file.
//! Crates depend on each other one way already (Cargo refuses circles between crates).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// `(crate, module path)`.
type Module = (String, Vec<String>);

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// The module a source file is: `src/a/b.rs` and `src/a/b/mod.rs` are `a::b`.
fn module_of(src: &Path, file: &Path) -> Vec<String> {
    let rel = file.strip_prefix(src).unwrap().with_extension("");
    let mut segs: Vec<String> = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
    if matches!(segs.last().map(String::as_str), Some("mod" | "lib" | "main")) {
        segs.pop();
    }
    segs
}

#[derive(Debug, PartialEq)]
enum Tok {
    Ident(String),
    Path, // ::
    Open,
    Close,
    Comma,
    Other,
}

/// The code's tokens, as far as paths go: comments dropped, and a file's inline
/// `#[cfg(test)] mod tests { … }` (its `super` is the file itself) cut off.
fn tokens(text: &str) -> Vec<Tok> {
    let text = match text.find("#[cfg(test)]\nmod tests {") {
        Some(i) => &text[..i],
        None => text,
    };
    let code: String = text.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n");
    let b = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_alphabetic() || c == b'_' {
            let s = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            out.push(Tok::Ident(code[s..i].to_string()));
            continue;
        }
        if c == b':' && b.get(i + 1) == Some(&b':') {
            out.push(Tok::Path);
            i += 2;
            continue;
        }
        if !c.is_ascii_whitespace() {
            out.push(match c {
                b'{' => Tok::Open,
                b'}' => Tok::Close,
                b',' => Tok::Comma,
                _ => Tok::Other,
            });
        }
        i += 1;
    }
    out
}

/// Every path the code names that starts at `crate`, `super`, `self` or a child module,
/// with a `use` group's items expanded one level (`a::{b, c::d}` gives `a::b`, `a::c`).
fn paths(toks: &[Tok], children: &BTreeSet<String>) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for i in 0..toks.len() {
        let Tok::Ident(first) = &toks[i] else { continue };
        if i > 0 && toks[i - 1] == Tok::Path {
            continue; // inside a path
        }
        let rooted = matches!(first.as_str(), "crate" | "super" | "self") || children.contains(first);
        if !rooted || toks.get(i + 1) != Some(&Tok::Path) {
            continue;
        }
        let mut path = vec![first.clone()];
        let mut j = i + 1;
        while toks.get(j) == Some(&Tok::Path) {
            match toks.get(j + 1) {
                Some(Tok::Ident(s)) => {
                    path.push(s.clone());
                    j += 2;
                }
                Some(Tok::Open) => {
                    // the group's items: the first name after `{` or a `,` at depth 1
                    let (mut k, mut depth, mut expect) = (j + 2, 1, true);
                    while k < toks.len() && depth > 0 {
                        match &toks[k] {
                            Tok::Open => depth += 1,
                            Tok::Close => depth -= 1,
                            Tok::Comma if depth == 1 => expect = true,
                            Tok::Ident(s) if depth == 1 && expect => {
                                let mut p = path.clone();
                                p.push(s.clone());
                                out.push(p);
                                expect = false;
                            }
                            _ => {}
                        }
                        k += 1;
                    }
                    break;
                }
                _ => break,
            }
        }
        out.push(path);
    }
    out
}

#[test]
fn no_import_circles_between_files() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files: BTreeMap<Module, PathBuf> = BTreeMap::new();
    for e in std::fs::read_dir(&root).unwrap() {
        let src = e.unwrap().path().join("src");
        if !src.is_dir() {
            continue;
        }
        let krate = src.parent().unwrap().file_name().unwrap().to_string_lossy().into_owned();
        let mut fs = Vec::new();
        rust_files(&src, &mut fs);
        for f in fs {
            files.insert((krate.clone(), module_of(&src, &f)), f);
        }
    }
    assert!(files.len() > 100, "found only {} source files under {}", files.len(), root.display());
    let mut edges: BTreeMap<&Module, BTreeSet<&Module>> = BTreeMap::new();
    for (m, f) in &files {
        let (krate, here) = m;
        let children: BTreeSet<String> = files
            .keys()
            .filter(|(k, p)| k == krate && p.len() == here.len() + 1 && p[..here.len()] == here[..])
            .map(|(_, p)| p[here.len()].clone())
            .collect();
        let text = std::fs::read_to_string(f).unwrap();
        let out = edges.entry(m).or_default();
        for path in paths(&tokens(&text), &children) {
            let mut segs = path.as_slice();
            let mut base: Vec<String> = here.clone();
            if segs[0] == "crate" {
                base.clear();
                segs = &segs[1..];
            }
            while let Some(s) = segs.first().filter(|s| *s == "super" || *s == "self") {
                if s == "super" {
                    base.pop();
                }
                segs = &segs[1..];
            }
            let full: Vec<String> = base.into_iter().chain(segs.iter().cloned()).collect();
            // the longest module with a file of its own
            let target = (0..=full.len()).rev().find_map(|k| files.get_key_value(&(krate.clone(), full[..k].to_vec())));
            let Some((t, _)) = target else { continue };
            let ancestor = t.1.len() < here.len() && here[..t.1.len()] == t.1[..];
            if t != m && !ancestor {
                out.insert(t);
            }
        }
    }
    // a circle is a back edge of a depth-first search
    let name = |m: &Module| files[m].strip_prefix(&root).unwrap().display().to_string();
    let mut state: BTreeMap<&Module, u8> = BTreeMap::new(); // 1: on the stack, 2: done
    let mut circles = Vec::new();
    fn visit<'a>(
        m: &'a Module,
        edges: &BTreeMap<&'a Module, BTreeSet<&'a Module>>,
        state: &mut BTreeMap<&'a Module, u8>,
        stack: &mut Vec<&'a Module>,
        circles: &mut Vec<Vec<&'a Module>>,
    ) {
        state.insert(m, 1);
        stack.push(m);
        for &t in edges.get(m).into_iter().flatten() {
            match state.get(t) {
                Some(1) => {
                    let from = stack.iter().position(|s| *s == t).unwrap();
                    circles.push(stack[from..].to_vec());
                }
                Some(_) => {}
                None => visit(t, edges, state, stack, circles),
            }
        }
        stack.pop();
        state.insert(m, 2);
    }
    for m in files.keys() {
        if !state.contains_key(m) {
            visit(m, &edges, &mut state, &mut Vec::new(), &mut circles);
        }
    }
    let shown: Vec<String> = circles
        .iter()
        .map(|c| c.iter().map(|m| name(m)).chain([name(c[0])]).collect::<Vec<_>>().join(" -> "))
        .collect();
    assert!(shown.is_empty(), "import circles:\n{}", shown.join("\n"));
}
