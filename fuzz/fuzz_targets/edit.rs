//! Whole scenes through the editor's edit path: a JSON array of edits, then the scene text;
//! the edits are applied, the scene loaded under small caps and meshed. Never a panic.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| pdeshape_fuzz::edit(data));
