//! Expression parser and evaluator: any text parses or fails with an error, and a parsed
//! expression evaluates (values and Taylor jets) without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| pdeshape_fuzz::expr(data));
