//! `pdeshape`: the command-line tool. A thin layer over `pdeshape-core` (mathematics) and
//! `pdeshape-io` (scene files, exporters, pictures).

/// `println!` that hands the write's error to the caller (`?`) instead of panicking: a
/// reader that closes the pipe early (`pdeshape holes … | head`) ends the command quietly
/// ([`cli::run`] exits 0 on a broken pipe, as `head` wanted no more).
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($t)*)?
    }};
}

mod bench;
mod build;
mod check;
mod cli;
mod clip;
mod gallery;
mod holes;
mod sample;
mod serve;
mod usage;

include!(concat!(env!("OUT_DIR"), "/examples.rs"));

/// mimalloc: glibc's allocator returns the mesh buffers to the kernel between solves and
/// faults them in again (a third of a 100 × 100 mesh's time in `perf`).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    std::process::exit(cli::run());
}
