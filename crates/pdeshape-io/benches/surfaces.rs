//! SPEC §10 surface targets: 4th-order PDE surface (M = 6 plus remainder) at 100 × 100
//! points with normals; the Klein bottle (order 40) at 200 × 200.
//! Run: cargo bench -p pdeshape-io --bench surfaces

use criterion::{Criterion, criterion_group, criterion_main};
use pdeshape_core::mesh::{GridOptions, grid_mesh};
use pdeshape_io::scene::Scene;
use std::path::PathBuf;

fn load(name: &str) -> Scene {
    Scene::load(&PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).expect("example loads")
}

fn surfaces(c: &mut Criterion) {
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
    g.bench_function("bloor-wilson solve", |b| b.iter(|| Scene::parse(&text, "b", "b", &Default::default()).unwrap()));
    g.finish();
}

criterion_group! {
    name = benches;
    // no plots: criterion's plot backend needs system fonts
    config = Criterion::default().without_plots();
    targets = surfaces
}
criterion_main!(benches);
