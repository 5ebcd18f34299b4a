//! `pdeshape`: the command-line tool. A thin layer over `pdeshape-core` (mathematics) and
//! `pdeshape-io` (scene files, exporters, pictures).

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
