//! `pdeshape`: the command-line tool. A thin layer over `pdeshape-core` (mathematics) and
//! `pdeshape-io` (scene files, exporters, pictures).

mod bench;
mod cli;
mod gallery;
mod serve;

include!(concat!(env!("OUT_DIR"), "/examples.rs"));

fn main() {
    std::process::exit(cli::run());
}
