//! `sunbeam-eval render`: the CPU reference image of a scene, through
//! `sunbeam_raster::render` (written with the player). Until that crate is
//! wired in, the subcommand says so.

use sunbeam_common::{Error, Result};

pub fn run(_args: &crate::RenderArgs) -> Result<()> {
    Err(Error::internal(
        "render is not built yet: it calls sunbeam_raster::render, which this build of sunbeam-eval does not link",
    ))
}
