//! Scene loader: any text loads or fails with a located error; never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| pdeshape_fuzz::scene(data));
