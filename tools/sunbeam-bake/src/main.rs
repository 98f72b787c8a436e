//! sunbeam-bake: put the nanostructure orientation field on a mesh (docs/BAKE.md).

mod args;
mod run;

fn main() {
    sunbeam_common::cli::main("sunbeam-bake", run::run)
}
