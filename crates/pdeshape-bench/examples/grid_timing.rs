//! Stage timings of the 100 × 100 surface evaluation (medians of 200 runs).
//! Run: cargo run --release -p pdeshape-bench --example grid_timing
use pdeshape_core::mesh::{GridOptions, grid_mesh};
use pdeshape_io::scene::Scene;
use std::time::Instant;

/// The allocator of the `pdeshape` binary, so that timings match it.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for (name, n) in [("four-curve-patch.toml", 100), ("klein-bottle.toml", 200)] {
        let scene = Scene::load(&root.join(name)).unwrap();
        let s = scene.patches[0].surface.clone();
        let us: Vec<f64> = (0..n).map(|i| i as f64 / (n - 1) as f64).collect();
        let dom = s.v_domain();
        let vs: Vec<f64> = (0..n).map(|j| dom.at(j as f64 / (n - 1) as f64)).collect();
        let _ = s.grid(&us, &vs);
        let t_grid = median(
            (0..200)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(s.grid(&us, &vs));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        let t_mesh = median(
            (0..200)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(grid_mesh(s.as_ref(), &GridOptions::new(n, n)).unwrap());
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        let one = [0.5];
        let t_cols = median(
            (0..200)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(s.grid(&one, &vs));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        let onev = [0.5];
        let t_rows = median(
            (0..200)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(s.grid(&us, &onev));
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect(),
        );
        println!(
            "{name} {n}x{n}: grid {t_grid:.3} ms (one row, all columns {t_cols:.3}; all rows, one column {t_rows:.3}), grid_mesh {t_mesh:.3} ms"
        );
    }
}
