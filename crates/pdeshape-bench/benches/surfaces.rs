//! SPEC §10 surface targets: 4th-order PDE surface (M = 6 plus remainder) at 100 × 100
//! points with normals; the Klein bottle (order 40) at 200 × 200; the dynamic blend of
//! paper 002 eq. 19 (closed form and K = 5) at 100 × 100; the solid blend of paper 000
//! example 2 (solve at L = M = N = 6, evaluation at 64³).
//!
//! One thread (the global rayon pool is built with one worker: the SPEC targets are for one
//! core; `PDESHAPE_BENCH_THREADS=2` for the two-thread tables), and nothing memoised
//! between iterations of a solve: each iteration changes a parameter by a hair (the dolphin
//! empties the memo), so the cardinal functions (memoised across solves by their rates) are
//! computed anew every time. Also issue 16's targets (four-curve M = 6 and M = 256, the
//! dolphin's cold build) and issue 21's fills.
//!
//! Run: cargo bench -p pdeshape-bench --bench surfaces
use criterion::{Criterion, criterion_group, criterion_main};
use pdeshape_core::blend::{DynamicBlend, DynamicOptions, Solver};
use pdeshape_core::mesh::{GridOptions, grid_mesh};
use pdeshape_core::solid::{SolidBlend, SolidOptions, Trial};
use pdeshape_core::trim::{LaplaceMap, TrimOptions, trim_grid};
use pdeshape_io::scene::Scene;
use std::path::PathBuf;

/// The allocator of the `pdeshape` binary, so that timings match it.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn load(name: &str) -> Scene {
    Scene::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).expect("example loads")
}

/// A new value every call: `base · (1 + 1e-9 k)` for the k-th call.
fn fresh(base: f64) -> impl FnMut() -> f64 {
    let mut k = 0u64;
    move || {
        k += 1;
        base * (1.0 + 1e-9 * k as f64)
    }
}

fn surfaces(c: &mut Criterion) {
    // one worker unless PDESHAPE_BENCH_THREADS asks for more (the two-thread tables)
    let threads = std::env::var("PDESHAPE_BENCH_THREADS").ok().and_then(|t| t.parse().ok()).unwrap_or(1);
    rayon::ThreadPoolBuilder::new().num_threads(threads).build_global().expect("the worker threads");
    let bw = load("bloor-wilson-blend.toml");
    let four = load("four-curve-patch.toml");
    let klein = load("klein-bottle.toml");
    let mut g = c.benchmark_group("surface evaluation with normals");
    for (label, scene, n) in [
        ("bloor-wilson M=6 100x100", &bw, 100),
        ("four-curve M=6 100x100", &four, 100),
        ("klein order 40 200x200", &klein, 200),
    ] {
        let p = scene.patches[0].spectral.clone().expect("a PDE patch");
        g.bench_function(format!("{label} (rows cached)"), |b| {
            b.iter(|| grid_mesh(p.as_ref(), &GridOptions::new(n, n)).expect("finite"))
        });
        g.bench_function(format!("{label} (fresh rows)"), |b| {
            b.iter(|| {
                p.clear_row_cache();
                grid_mesh(p.as_ref(), &GridOptions::new(n, n)).expect("finite")
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("solve");
    g.sample_size(10);
    let text = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/bloor-wilson-blend.toml"),
    )
    .unwrap();
    let mut a = fresh(1.0);
    g.bench_function("bloor-wilson solve (new a each time)", |b| {
        b.iter(|| {
            let params = std::collections::HashMap::from([("a".to_string(), a())]);
            Scene::parse(&text, "b", "b", &params).unwrap()
        })
    });
    // SPEC §10: the Klein bottle (order 40), cold solve for a new `a` + 200 × 200 with
    // normals (target 10 ms)
    let klein_text =
        std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/klein-bottle.toml"))
            .unwrap();
    let mut ka = fresh(1.0);
    g.bench_function("klein order 40: solve (new a) + 200x200 with normals", |b| {
        b.iter(|| {
            let params = std::collections::HashMap::from([("a".to_string(), ka())]);
            let s = Scene::parse(&klein_text, "k", "k", &params).unwrap();
            let p = s.patches[0].spectral.clone().expect("a PDE patch");
            grid_mesh(p.as_ref(), &GridOptions::new(200, 200)).expect("finite")
        })
    });
    // SPEC §10 / issue 16: the 4th-order four-curve patch (M = 6 + remainder) from its text,
    // solved for a new `a` and meshed at 100 × 100 with normals (target 0.3 ms), and the
    // same patch with M = 256 modes (target 50 ms)
    let four_text =
        std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/four-curve-patch.toml"))
            .unwrap();
    for (label, modes) in [("M=6", 6), ("M=256", 256)] {
        let text = four_text.replace("kind = \"pde\"", &format!("kind = \"pde\"\nmodes = {modes}"));
        assert_ne!(text, four_text);
        let mut fa = fresh(1.1);
        g.bench_function(format!("four-curve {label}: solve (new a) + 100x100 with normals"), |b| {
            b.iter(|| {
                let params = std::collections::HashMap::from([("a".to_string(), fa())]);
                let s = Scene::parse(&text, "f", "f", &params).unwrap();
                grid_mesh(s.patches[0].surface.as_ref(), &GridOptions::new(100, 100)).expect("finite")
            })
        });
    }
    // issue 16: the dolphin scene, cold (memo of cardinal functions emptied): parse, solve
    // every patch, every patch's mesh at its scene resolution (trimmed body included)
    let dolphin_text =
        std::fs::read_to_string(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples/dolphin.toml")).unwrap();
    g.bench_function("dolphin: cold build to meshes", |b| {
        b.iter(|| {
            pdeshape_core::spectral::clear_cardinal_memo();
            let s = Scene::parse(&dolphin_text, "d", "d", &Default::default()).unwrap();
            pdeshape_io::model::patch_meshes(&s).unwrap()
        })
    });
    // N-sided fills (issue 21 target: fill + 100 × 100 with normals ≤ 2 ms): the three
    // sphere holes, from the scene text (parse, expressions, fill, solve) for a new ring
    for hole in ["triangle", "pentagon", "hexagon"] {
        let fill_text = std::fs::read_to_string(
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../examples/fill-sphere-{hole}.toml")),
        )
        .unwrap();
        let ring0 = Scene::parse(&fill_text, "f", "f", &Default::default()).unwrap().params["ring"].value;
        let mut ring = fresh(ring0);
        g.bench_function(format!("fill sphere {hole}: scene + solve (new ring) + 100x100 with normals"), |b| {
            b.iter(|| {
                let params = std::collections::HashMap::from([("ring".to_string(), ring())]);
                let s = Scene::parse(&fill_text, "f", "f", &params).unwrap();
                grid_mesh(s.patches[0].surface.as_ref(), &GridOptions::new(100, 100)).expect("finite")
            })
        });
    }
    g.finish();

    // SPEC §10: paper 002 eq. 19 at one t, 100 × 100 points with normals: the closed form
    // (target 2 ms) and K = 5 on 11 × 11 collocation points (target 1 ms), solve included.
    let dynamic = load("dynamic-elliptic-cylinders.toml");
    let p = &dynamic.patches[0];
    let d = p.dynamic.as_ref().expect("a dynamic patch");
    let mut g = c.benchmark_group("dynamic blend eq. 19, solve + 100x100 with normals");
    for (label, solver) in [("closed form", Solver::Exact), ("K = 5, 11 x 11", Solver::Collocation)] {
        let o = DynamicOptions { solver, terms: 5, collocation: (11, 11), times: d.times, ..Default::default() };
        let mut gamma = fresh(d.blend.operator().gamma);
        g.bench_function(label, |b| {
            b.iter(|| {
                let op0 = d.blend.operator();
                let op = pdeshape_core::blend::DynamicOperator::new(op0.beta, gamma(), op0.lambda, op0.rho, op0.eta)
                    .unwrap();
                let blend = DynamicBlend::new(op, &p.conditions, p.surface.v_domain(), &o).unwrap();
                grid_mesh(&blend.frame(0.1).unwrap(), &GridOptions::new(100, 100)).expect("finite")
            })
        });
    }
    g.finish();

    // SPEC §10: solid blend L = M = N = 6 solve (target 20 ms), 64³ evaluation (50 ms).
    let solid = load("solid-cylinders.toml");
    let sd = solid.patches[0].solid.as_ref().expect("a solid patch");
    let mut g = c.benchmark_group("solid blend (elliptic to circular cylinder)");
    g.bench_function("solve L = M = N = 6", |b| {
        b.iter(|| {
            SolidBlend::new(
                sd.blend.operator(),
                sd.faces.clone(),
                SolidOptions { trial: Trial::Complete, terms: (6, 6, 6) },
            )
            .unwrap()
        })
    });
    let lin: Vec<f64> = (0..64).map(|i| i as f64 / 63.0).collect();
    g.bench_function("evaluate 64^3", |b| b.iter(|| sd.blend.grid(&lin, &lin, &lin)));
    g.finish();

    // SPEC §10: trimmed 140 × 170 Laplace mesh ≤ 0.5 ms and faster than spade's CDT (the
    // comparison with spade is `pdeshape bench`, paper 003 Table 1).
    let trim = load("trim-circle.toml");
    let t = trim.patches[0].trim.as_ref().expect("a trimmed patch");
    let region = t.map.region().clone();
    let o = TrimOptions { rings: 140, columns: 170, modes: t.map.modes(), verify: false, ..Default::default() };
    let mut g = c.benchmark_group("trim (paper 003 Fig. 3)");
    g.bench_function("Laplace map + 140x170 grid + fold check", |b| {
        b.iter(|| trim_grid(&LaplaceMap::new(region.clone(), o.modes, Some(170)), &o).unwrap())
    });
    g.finish();
}

/// The Rust side of the Python module's overhead figure (issue: ≤ 1.2 × through Python):
/// 10⁶ exact points of the Bloor–Wilson blend through `sample::points_into`, the call
/// `Patch.evaluate` makes (compare `crates/pdeshape-py/bench/evaluate.py`, same points).
fn evaluate_million(c: &mut Criterion) {
    let bw = load("bloor-wilson-blend.toml");
    let p = &bw.patches[0];
    let n = 1_000_000;
    // the same low-discrepancy points as the Python script: u = frac(k φ₁), v = 2π frac(k φ₂)
    let (g1, g2) = (0.7548776662466927, 0.5698402909980532);
    let params: Vec<f64> = (0..n)
        .flat_map(|k| {
            let k = k as f64;
            [(k * g1).fract(), 2.0 * std::f64::consts::PI * (k * g2).fract()]
        })
        .collect();
    let mut g = c.benchmark_group("evaluate");
    g.sample_size(10);
    g.bench_function("bloor-wilson 10^6 points (sample::points_into)", |b| {
        b.iter(|| {
            let mut out = vec![0.0; 3 * n];
            pdeshape_io::sample::points_into(pdeshape_io::sample::Target::of(p), &params, &mut out);
            out
        })
    });
    g.finish();
}

/// Issue 31: 10⁵ scattered points (the low-discrepancy points of the Python bench) on the
/// Klein bottle and the Bloor–Wilson blend, pointwise (`Surface::point`, `derivatives`:
/// per-row caches) and batched (`Surface::points_at`, `firsts_at`), on the calling thread.
/// The patch is solved once; its folded modes are built on the first batched call, as
/// part of the solved patch, and kept (the pointwise row cache is emptied every
/// iteration).
fn scattered(c: &mut Criterion) {
    use pdeshape_core::Vec3;
    let mut g = c.benchmark_group("scattered points (10^5)");
    g.sample_size(10);
    let n = 100_000;
    let (g1, g2) = (0.7548776662466927, 0.5698402909980532);
    for name in ["klein-bottle", "bloor-wilson-blend"] {
        let sc = load(&format!("{name}.toml"));
        let s = sc.patches[0].surface.clone();
        let dom = s.v_domain();
        let uv: Vec<[f64; 2]> = (0..n).map(|k| [(k as f64 * g1).fract(), dom.at((k as f64 * g2).fract())]).collect();
        let clear = || {
            if let Some(p) = &sc.patches[0].spectral {
                p.clear_row_cache()
            }
        };
        g.bench_function(format!("{name}: values, pointwise"), |b| {
            b.iter(|| {
                clear();
                uv.iter().map(|p| s.point(p[0], p[1]).x).sum::<f64>()
            })
        });
        g.bench_function(format!("{name}: values, batched"), |b| {
            let mut out = vec![Vec3::ZERO; n];
            b.iter(|| s.points_at(&uv, &mut out))
        });
        g.bench_function(format!("{name}: with first derivatives, pointwise"), |b| {
            b.iter(|| {
                clear();
                uv.iter().map(|p| s.derivatives(p[0], p[1], 1, 1)[1].x).sum::<f64>()
            })
        });
        g.bench_function(format!("{name}: with first derivatives, batched"), |b| {
            let mut out = vec![[Vec3::ZERO; 3]; n];
            b.iter(|| s.firsts_at(&uv, &mut out))
        });
    }
    g.finish();
}

/// Issue 18: measured B-spline fitting of a scene's faces (solved patches given; the fit
/// keeps nothing between iterations), at the default tolerance (1e-6 × each face's
/// bounding-box diagonal) and at 1e-8 ×.
fn cad_fit(c: &mut Criterion) {
    let mut g = c.benchmark_group("cad fit");
    g.sample_size(10);
    for name in ["dolphin", "bloor-wilson-blend", "fill-sphere-pentagon"] {
        let sc = load(&format!("{name}.toml"));
        g.bench_function(format!("{name}: every face at 1e-6 (measured maximum)"), |b| {
            b.iter(|| pdeshape_io::cad::fit_scene(&sc, &Default::default()).unwrap())
        });
    }
    g.finish();
}

/// The CAD issue's "a hole filled and exported" on one thread: the whole of `fill-holes
/// MODEL --holes 1` in memory — the STEP text parsed, the holes found, hole 1 filled, its
/// face fitted and measured, the model written back to bytes — for the OCCT suite's
/// models (`crates/pdeshape/tests/data/step`), nothing kept between iterations (the
/// cardinal memo emptied).
fn step_holes(c: &mut Criterion) {
    use pdeshape_io::holes::{FillHolesOptions, fill_holes, filled_bytes};
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../pdeshape/tests/data/step");
    let limits = pdeshape_core::limits::Limits::default();
    let mut g = c.benchmark_group("step fill-holes");
    g.sample_size(10);
    for (model, edges) in
        [("cylinder-open", 1), ("rounded-box-corners", 3), ("loft-open", 1), ("touching-parts", 2), ("loft-twelve", 12)]
    {
        let bytes = std::fs::read(dir.join(format!("{model}.step"))).expect("the model");
        for order in [4, 6] {
            let opts = FillHolesOptions { order, holes: Some(vec![1]), ..Default::default() };
            g.bench_function(
                format!("{model} hole 1 ({edges} edges), order {order}: read + fill + fit + write"),
                |b| {
                    b.iter(|| {
                        pdeshape_core::spectral::clear_cardinal_memo();
                        let m = pdeshape_io::import::step::parse_step(bytes.clone(), model, &limits).expect("read");
                        let holes = pdeshape_core::brep::holes(&m.brep);
                        let filled = fill_holes(&m, &holes, &opts).expect("filled");
                        filled_bytes(&m, &holes, &filled).expect("written")
                    })
                },
            );
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    // no plots: criterion's plot backend needs system fonts
    config = Criterion::default().without_plots();
    targets = surfaces, evaluate_million, scattered, cad_fit, step_holes
}
criterion_main!(benches);
