//! Where outputs go and what they may hold: an existing FIFO or device node is written into,
//! never replaced by a regular file; a full device is an error; a value that a format's
//! 32-bit floats cannot hold is an error naming the mesh and the format; outputs are checked
//! before long work starts; a failing study leaves no file.

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn example(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

fn pdeshape(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pdeshape")).args(args).output().unwrap()
}

fn path_str(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Makes a FIFO with `mkfifo` (coreutils).
fn mkfifo(p: &Path) {
    let s = Command::new("mkfifo").arg(p).status().unwrap();
    assert!(s.success());
}

/// A private character device node with the given major/minor numbers (root only); `None`
/// where the test cannot make one (not root).
fn mknod(p: &Path, major: u32, minor: u32) -> Option<()> {
    let s = Command::new("mknod").arg(p).arg("c").arg(major.to_string()).arg(minor.to_string()).output().unwrap();
    if s.status.success() {
        Some(())
    } else {
        // CI runs as root: there the device tests must run
        assert!(std::env::var_os("CI").is_none(), "mknod failed in CI: {}", String::from_utf8_lossy(&s.stderr));
        eprintln!("skipping the device-node part: {}", String::from_utf8_lossy(&s.stderr));
        None
    }
}

/// `build -o pipe.ply` and `render -o pipe.png` into a FIFO: its reader gets the whole file,
/// and the FIFO is still a FIFO afterwards (the atomic rename used to put a regular file in
/// its place, and the reader waited for ever).
#[test]
fn a_fifo_is_written_into_not_replaced() {
    let dir = tempfile::tempdir().unwrap();
    for (name, args, magic) in
        [("pipe.ply", vec!["build", "-q"], &b"ply\n"[..]), ("pipe.png", vec!["render"], &b"\x89PNG"[..])]
    {
        let fifo = dir.path().join(name);
        mkfifo(&fifo);
        // the reader reports through a channel: where the FIFO was replaced its open()
        // never returns, and the test fails after a time-out instead of hanging
        let (tx, rx) = std::sync::mpsc::channel();
        {
            let fifo = fifo.clone();
            std::thread::spawn(move || tx.send(std::fs::read(&fifo).unwrap()));
        }
        let mut a = args.clone();
        let scene = example("hermite-blend.toml");
        a.extend([path_str(&scene), "-o", path_str(&fifo)]);
        let o = pdeshape(&a);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        let bytes = rx.recv_timeout(std::time::Duration::from_secs(30)).expect("the FIFO's reader got nothing");
        assert!(
            bytes.starts_with(magic),
            "{name}: the reader got {} bytes: {:?}",
            bytes.len(),
            &bytes[..bytes.len().min(8)]
        );
        assert!(bytes.len() > 1000, "{name}: {} bytes", bytes.len());
        let t = std::fs::symlink_metadata(&fifo).unwrap().file_type();
        assert!(t.is_fifo(), "{name} is no longer a FIFO: {t:?}");
    }
    // nothing else was left in the directory (no temporary files)
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
}

/// A private null device (1, 3) takes the output and stays a device; a private full device
/// (1, 7) is a write error "no space left", exit 1, and stays a device.
#[test]
fn device_nodes_stay_devices_and_a_full_one_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let null = dir.path().join("null.obj");
    if mknod(&null, 1, 3).is_none() {
        return;
    }
    let scene = example("hermite-blend.toml");
    let o = pdeshape(&["build", "-q", path_str(&scene), "-o", path_str(&null)]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::symlink_metadata(&null).unwrap().file_type().is_char_device());

    let full = dir.path().join("full.stl");
    mknod(&full, 1, 7).unwrap();
    let o = pdeshape(&["build", "-q", path_str(&scene), "-o", path_str(&full)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.to_lowercase().contains("no space left"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(std::fs::symlink_metadata(&full).unwrap().file_type().is_char_device());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2, "stray files");
}

/// A directory given as a file output is refused with its name; nothing is created.
#[test]
fn a_directory_is_not_a_file_output() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("x.ply");
    std::fs::create_dir(&d).unwrap();
    let scene = example("hermite-blend.toml");
    let o = pdeshape(&["build", "-q", path_str(&scene), "-o", path_str(&d)]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("is a directory") && err.contains("x.ply"), "{err}");
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0);
}

/// `r = 1e39` fits an f64 but not the f32 of binary PLY, STL and glTF: each is an error
/// naming the mesh and the format (it wrote 1 915 infinities into the glTF and 10 958 into
/// the STL with exit 0); OBJ writes f64 and takes it.
#[test]
fn values_beyond_f32_are_refused_by_32_bit_formats() {
    let dir = tempfile::tempdir().unwrap();
    let scene = example("hermite-blend.toml");
    for ext in ["glb", "stl", "ply"] {
        let out = dir.path().join(format!("big.{ext}"));
        let o = pdeshape(&["build", "-q", path_str(&scene), "--set", "r=1e39", "-o", path_str(&out)]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{ext}: {err}");
        let format = match ext {
            "glb" => "glTF",
            e => &e.to_ascii_uppercase(),
        };
        assert!(
            err.contains("mesh `blend`") && err.contains(format) && err.contains("single-precision"),
            "{ext}: {err}"
        );
        assert!(!out.exists(), "{ext} written");
    }
    let out = dir.path().join("big.obj");
    let o = pdeshape(&["build", "-q", path_str(&scene), "--set", "r=1e39", "-o", path_str(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.lines().any(|l| l.starts_with("v ") && l.contains("e39")), "OBJ keeps f64 values");
}

/// `bench --out` into a path whose directory does not exist fails at once, before a table
/// is timed (it ran 20 s first); `bench --scaling DIR --max-side 0` is a usage error and
/// leaves no file; `bench --runs 0` is refused.
#[test]
fn bench_checks_its_outputs_first() {
    let dir = tempfile::tempdir().unwrap();
    let afile = dir.path().join("afile");
    std::fs::write(&afile, "x").unwrap();
    let t = std::time::Instant::now();
    let o = pdeshape(&["bench", "--runs", "1", "--out", path_str(&afile.join("x"))]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("afile") && err.contains("not a directory"), "{err}");
    // the tables take tens of seconds on this machine; the refusal, process start-up
    assert!(t.elapsed().as_secs_f64() < 5.0, "{:?}", t.elapsed());

    let study = dir.path().join("study");
    let o = pdeshape(&["bench", "--scaling", path_str(&study), "--max-side", "0", "--runs", "1"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("--max-side 0"), "{err}");
    assert!(!study.exists(), "the study's directory was created");

    let o = pdeshape(&["bench", "--runs", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `--degree` with a mesh output is a usage error: exit 2 (it was 1).
#[test]
fn step_options_with_a_mesh_output_are_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.obj");
    let scene = example("hermite-blend.toml");
    let o = pdeshape(&["build", "-q", path_str(&scene), "-o", path_str(&out), "--degree", "5"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("STEP output only"), "{err}");
    assert!(!out.exists());
}

/// A scene at 1e150 renders as the same scene at 1 (the picture was flat: unit normals of
/// cross products whose squares overflowed were dropped): at most 1 % of the pixels differ
/// by more than 8 of 255 in any channel (round-off moves a few edge pixels).
#[test]
fn a_scene_at_1e150_renders_like_the_same_scene_at_1() {
    use pdeshape_io::scene::Scene;
    let picture = |scale: &str| {
        let text = format!(
            "[curves.a]\nexpr = [\"{scale}*cos(v)\", \"{scale}*sin(v)\", \"0\"]\n\
             [curves.b]\nexpr = [\"{scale}*(1.5 + 0.2*cos(3*v))*cos(v)\", \"{scale}*1.5*sin(v)\", \"{scale}\"]\n\
             [patches.p]\nkind = \"hermite\"\nconditions = [{{ u = 0, curve = \"a\" }}, {{ u = 1, curve = \"b\" }}]\n"
        );
        let scene = Scene::parse(&text, "s.toml", "s", &Default::default()).unwrap();
        pdeshape_io::model::render_scene(&scene).unwrap()
    };
    let (a, b) = (picture("1"), picture("1e150"));
    assert_eq!((a.width, a.height), (b.width, b.height));
    let pixels = a.data.len() / 4;
    let differ = a
        .data
        .chunks(4)
        .zip(b.data.chunks(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 8))
        .count();
    assert!(differ * 100 <= pixels, "{differ} of {pixels} pixels differ");
}
