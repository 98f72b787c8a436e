//! sunbeam-play: render a scene with diffraction colour from term packs, in a
//! window (orbit camera, movable light, exposure) or headless to PNG. Docs: docs/PLAY.md.

mod args;
mod run;

fn main() {
    sunbeam_common::cli::main("sunbeam-play", run::run)
}
