//! Stage timings of the eq. 19 dynamic blend (medians of 51 runs, one thread).
//! Run: cargo run --release -p pdeshape-bench --example dynamic_timing
use pdeshape_bench::tables::{on_one_thread, time};
use pdeshape_core::blend::{DynamicBlend, DynamicOptions, Solver};
use pdeshape_core::mesh::{GridOptions, grid_mesh};
use pdeshape_core::patch::Surface;
use pdeshape_io::scene::Scene;

/// The allocator of the `pdeshape` binary, so that timings match it.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let scene = Scene::load(&root.join("dynamic-elliptic-cylinders.toml")).unwrap();
    let p = &scene.patches[0];
    let d = p.dynamic.as_ref().unwrap();
    on_one_thread(|| {
        for (label, solver) in [("closed form", Solver::Exact), ("K = 5", Solver::Collocation)] {
            let o = DynamicOptions { solver, terms: 5, collocation: (11, 11), times: d.times, ..Default::default() };
            let new = || DynamicBlend::new(d.blend.operator(), &p.conditions, p.surface.v_domain(), &o).unwrap();
            let b = new();
            let f = b.frame(0.0).unwrap();
            let t_new = time(51, || {
                std::hint::black_box(new());
            });
            let t_frame = time(51, || {
                std::hint::black_box(b.frame(0.0).unwrap());
            });
            let us: Vec<f64> = (0..100).map(|i| i as f64 / 99.0).collect();
            let vs: Vec<f64> = (0..100).map(|j| f.v_domain().at(j as f64 / 99.0)).collect();
            let t_grid = time(51, || {
                std::hint::black_box(f.grid(&us, &vs));
            });
            let t_mesh = time(51, || {
                std::hint::black_box(grid_mesh(&f, &GridOptions::new(100, 100)).unwrap());
            });
            println!(
                "{label}: new {:.3} ms, frame {:.3} ms, grid {:.3} ms, grid_mesh {:.3} ms",
                t_new.median_ms, t_frame.median_ms, t_grid.median_ms, t_mesh.median_ms
            );
        }
    })
    .unwrap();
}
