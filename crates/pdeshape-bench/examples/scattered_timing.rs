//! Scattered-point evaluation: 10⁵ pseudo-random points on an example's first patch, one
//! thread, values then values with first derivatives; the pointwise `Surface::point` /
//! `derivatives` loop against the batched `Surface::points` / `firsts` (medians of 5).
//!
//! Run: cargo run --release -p pdeshape-bench --example scattered_timing [-- example.toml …]
//! (`PDESHAPE_BATCH_ONLY=1` skips the pointwise loops, `PDESHAPE_VALUES_ONLY=1` the batched
//! first derivatives: for a profile of one call.)
use pdeshape_io::scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    rayon::ThreadPoolBuilder::new().num_threads(1).build_global().expect("one worker");
    let mut names: Vec<String> = std::env::args().skip(1).collect();
    if names.is_empty() {
        names = vec!["klein-bottle.toml".into(), "bloor-wilson-blend.toml".into()];
    }
    let n = 100_000;
    for name in names {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(&name);
        let scene = Scene::load(&path).expect("example loads");
        let s = scene.patches[0].surface.as_ref();
        let dom = s.v_domain();
        // the low-discrepancy points of the Python bench: u = frac(k φ₁), v = frac(k φ₂) of V
        let (g1, g2) = (0.7548776662466927, 0.5698402909980532);
        let uv: Vec<[f64; 2]> = (0..n).map(|k| [(k as f64 * g1).fract(), dom.at((k as f64 * g2).fract())]).collect();
        let time = |f: &mut dyn FnMut()| {
            median(
                (0..5)
                    .map(|_| {
                        let t = Instant::now();
                        f();
                        t.elapsed().as_secs_f64() / n as f64 * 1e6
                    })
                    .collect(),
            )
        };
        let mut sink = 0.0;
        // PDESHAPE_BATCH_ONLY=1: the batched calls alone (for a profile of them)
        let only = std::env::var_os("PDESHAPE_BATCH_ONLY").is_some();
        let time_pointwise = |f: &mut dyn FnMut()| if only { f64::NAN } else { time(f) };
        let pv = time_pointwise(&mut || {
            for p in &uv {
                sink += s.point(p[0], p[1]).x;
            }
        });
        let pd = time_pointwise(&mut || {
            for p in &uv {
                sink += s.derivatives(p[0], p[1], 1, 1)[1].x;
            }
        });
        let mut vals = vec![pdeshape_core::Vec3::ZERO; n];
        let bv = time(&mut || s.points_at(&uv, &mut vals));
        let mut firsts = vec![[pdeshape_core::Vec3::ZERO; 3]; n];
        let bd = if std::env::var_os("PDESHAPE_VALUES_ONLY").is_some() {
            f64::NAN
        } else {
            time(&mut || s.firsts_at(&uv, &mut firsts))
        };
        sink += vals[n / 2].x + firsts[n / 3][1].y;
        println!(
            "{name}: values {pv:.3} → {bv:.3} µs a point, with first derivatives {pd:.3} → {bd:.3} \
             (pointwise → batched; {sink:.1e})"
        );
    }
}
