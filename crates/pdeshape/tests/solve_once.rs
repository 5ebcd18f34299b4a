//! Each command solves each patch once: when the scene is loaded. Meshes, the report,
//! pictures, strips, the CAD fit and the directory build reuse those solves. The only
//! solves after loading are the ones the report asks for on purpose (a blend that both
//! solvers apply to is solved once more with the other one, for
//! `exact_vs_collocation_max_distance`) and a dynamic blend's frames, each instant once.
//!
//! The binary prints its solve counts (`pdeshape_core::solves`) with
//! `PDESHAPE_SOLVE_COUNTS=1`: those done while loading and those of the rest of the command,
//! in the order spectral, static blend, dynamic frame, solid, Laplace map.

mod common;

use common::example;
use std::process::Command;

const SPECTRAL: usize = 0;
const STATIC_BLEND: usize = 1;
const DYNAMIC_FRAME: usize = 2;

/// Runs `pdeshape ARGS SCENE` and returns its (loaded, command) solve counts.
fn solves(args: &[&str], scene: &str) -> ([usize; 5], [usize; 5]) {
    let o = Command::new(env!("CARGO_BIN_EXE_pdeshape"))
        .args(args)
        .arg(example(scene))
        .env("PDESHAPE_SOLVE_COUNTS", "1")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{args:?} {scene}: {err}");
    let line = err.lines().find(|l| l.starts_with("solves: ")).unwrap_or_else(|| panic!("no counts: {err}"));
    let lists: Vec<[usize; 5]> = line
        .split('[')
        .skip(1)
        .map(|s| {
            let v: Vec<usize> = s[..s.find(']').unwrap()].split(", ").map(|x| x.parse().unwrap()).collect();
            v.try_into().unwrap()
        })
        .collect();
    (lists[0], lists[1])
}

/// The patches of `scene` as `check --json` reports them.
fn report(scene: &str) -> Vec<serde_json::Value> {
    let o =
        Command::new(env!("CARGO_BIN_EXE_pdeshape")).args(["check", "--json"]).arg(example(scene)).output().unwrap();
    let d: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    d["patches"].as_array().unwrap().clone()
}

#[test]
fn every_command_solves_each_patch_once() {
    let dir = tempfile::tempdir().unwrap();
    let out = |name: &str| dir.path().join(name).display().to_string();
    let (ply, png, step, sub) = (out("x.ply"), out("x.png"), out("x.step"), out("d"));
    for scene in [
        "blend-cone-cylinder.toml",
        "dynamic-sine.toml",
        "dolphin.toml",
        "solid-cubes.toml",
        "fill-sphere-hexagon.toml",
        "trim-circle.toml",
    ] {
        let patches = report(scene);
        // blends both solvers apply to: the report solves each once more, with the other solver
        let both = patches
            .iter()
            .filter(|p| {
                p["blend"]["components"].as_array().is_some_and(|c| c.iter().all(|c| c["exact_available"] == true))
            })
            .count();
        // a dynamic blend's instants: every frame time (the ends among them)
        let instants: usize = patches.iter().map(|p| p["dynamic"]["frames"].as_array().map_or(0, |f| f.len())).sum();
        let trims = patches.iter().filter(|p| p["trim"].is_object()).count();
        let runs: [(&[&str], bool); 8] = [
            (&["check"], true),
            (&["check", "--json"], true),
            (&["check", "--json", "--cad"], true),
            (&["build", "-o", &ply], true),
            (&["build", "-q", "-o", &ply], false),
            (&["build", "-o", &sub], true),
            (&["build", "-q", "-o", &step], false),
            (&["render", "-o", &png], false),
        ];
        for (args, with_report) in runs {
            let (loaded, command) = solves(args, scene);
            let what = format!("{scene} {args:?}: loaded {loaded:?}, then {command:?}");
            // every patch at load: one solve of its kind each (a dynamic blend: its first frame)
            // (and a trimmed patch its Laplace map)
            assert_eq!(loaded.iter().sum::<usize>(), patches.len() + trims, "{what}");
            for kind in [SPECTRAL, 3, 4] {
                assert_eq!(command[kind], 0, "{what}: solved again");
            }
            let extra = if with_report { both } else { 0 };
            assert_eq!(command[STATIC_BLEND], extra, "{what}");
            // a frame is solved when first asked for, each instant once; the condition check
            // (with or without the report) asks for all of them, a picture for some
            let frames = loaded[DYNAMIC_FRAME] + command[DYNAMIC_FRAME];
            assert!(frames <= instants.max(loaded[DYNAMIC_FRAME]), "{what}: {frames} frames for {instants} instants");
            if with_report || args.contains(&"-q") && args[0] == "build" {
                assert_eq!(frames, instants.max(loaded[DYNAMIC_FRAME]), "{what}");
            }
        }
    }
}
