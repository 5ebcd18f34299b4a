//! Scene loader: any text loads or fails with a located error; never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;
use pdeshape_io::scene::Scene;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = Scene::parse(text, "fuzz.toml", "fuzz", &Default::default());
});
