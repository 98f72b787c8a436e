//! sunbeam-pack: height field -> diffraction term pack (KTX2 / EXR). See docs/PACK.md.

mod args;
mod run;

fn main() {
    sunbeam_common::cli::main(args::TOOL, run::run)
}
