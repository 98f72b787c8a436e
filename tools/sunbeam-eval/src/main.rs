//! sunbeam-eval: ground truth, error and run-time benchmarks, the thesis'
//! grating check, and BRDF pictures (docs/EVAL.md).

mod args;
mod bench;
mod brdf;
mod commands;
mod diff;
mod grating_plot;
mod input;
mod plot;
mod probe;
mod render;
mod sheet;

fn main() {
    sunbeam_common::cli::main("sunbeam-eval", commands::run)
}
