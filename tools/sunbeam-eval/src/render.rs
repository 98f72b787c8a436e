//! `sunbeam-eval render`: the CPU reference image of a scene, through
//! `sunbeam_raster::render` (the same scene loading and defaults as
//! `sunbeam-play`: a scene file, or `--mesh M --pack P` for
//! `Scene::default_for`). `--samples N` averages a stratified grid of sub-pixel
//! samples in linear light (the anti-aliased reference); `-o F.exr` writes the
//! linear frame (exposure applied, no tone curve) instead of display values.
//! A scene with an `environment` is lit by Monte Carlo (`--samples` per pixel,
//! `--seed S`; docs/LIGHTING.md).

use sunbeam_common::{Error, Result};
use sunbeam_scene::Scene;

pub fn run(a: &crate::args::RenderArgs) -> Result<()> {
    let mut scene = match (&a.scene, &a.mesh) {
        (Some(_), Some(_)) => {
            return Err(Error::usage(
                "give either SCENE.json or --mesh/--pack, not both",
            ))
        }
        (Some(s), None) => {
            if a.pack.is_some() {
                return Err(Error::usage(
                    "--pack goes with --mesh (a scene file names its own packs)",
                ));
            }
            Scene::load(s)?
        }
        (None, Some(m)) => sunbeam_raster::default_scene(m, a.pack.as_deref())?,
        (None, None) => {
            return Err(Error::usage(
                "nothing to render: give SCENE.json or --mesh M.glb --pack P.ktx2",
            ))
        }
    };
    if let Some(ev) = a.exposure {
        if !ev.is_finite() {
            return Err(Error::usage("--exposure must be finite"));
        }
        scene.exposure = ev;
    }
    if let Some((w, h)) = a.size {
        scene.size = [w as u32, h as u32];
        scene.validate()?;
    }
    let opts = sunbeam_raster::Options {
        samples: a.samples,
        seed: a.seed,
        ..Default::default()
    };
    sunbeam_raster::samples_side(a.samples)?;
    let exr = a
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
    if exr {
        sunbeam_raster::render_linear(&scene, &opts)?.write_exr(&a.output)
    } else {
        sunbeam_raster::render_with(&scene, &opts)?.write_png(&a.output)
    }
}
