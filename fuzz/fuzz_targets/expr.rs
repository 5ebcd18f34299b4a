//! Expression parser and evaluator: any text parses or fails with an error, and a parsed
//! expression evaluates (values and Taylor jets) without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;
use pdeshape_core::expr::Expr;
use pdeshape_core::jet::{Jet, JetShape};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(e) = Expr::parse(text) else { return };
    let Ok(b) = e.bind(&["u", "v", "t"], &|n| if n == "a" { Some(1.5) } else { None }) else { return };
    let _ = b.eval(&[0.3, -1.2, 2.0]);
    let shape = JetShape::new(&[3, 2, 1]);
    let vars = [Jet::variable(shape, 0, 0.3), Jet::variable(shape, 1, -1.2), Jet::variable(shape, 2, 2.0)];
    let _ = b.eval_jet(&vars);
    let _ = pdeshape_core::expr::expand(&b);
});
