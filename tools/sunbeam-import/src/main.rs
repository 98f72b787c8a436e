//! sunbeam-import: read an AFM/SPM scan, pick a channel, convert to metres,
//! optionally level / align rows / fill / remove scars / rotate / flip / crop /
//! resample, and write a height field (`.exr` or `.gsf`). See docs/IMPORT.md.

mod args;
mod run;

fn main() {
    sunbeam_common::cli::main("sunbeam-import", run::run)
}
