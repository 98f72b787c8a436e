//! `sunbeam-eval diff`: CIEDE2000 between a rendered linear frame (EXR) and a
//! reference frame, the way the tests compare renderers (PHYSICS.md 4: over
//! the pixels lit in the reference, in linear light before the display
//! transform), split into the interior of the lit area and its one-pixel
//! edge (silhouettes, where sub-pixel coverage dominates), with an optional
//! false-colour map of the per-pixel error to see *where* two renderers
//! disagree, and an optional mask (`--mask`: an object's pixels in front of a
//! drawn background).

use serde_json::json;
use std::path::Path;
use sunbeam_common::Result;
use sunbeam_raster::linear::{compare_regions_within, only_lit_in, per_pixel_de};
use sunbeam_raster::{Image, LinearImage};

/// Black (0) through red to yellow (at `scale` and above); unlit pixels dark blue.
fn heat(d: Option<f64>, scale: f64) -> [f32; 3] {
    match d {
        None => [0.0, 0.0, 0.15],
        Some(d) => {
            let t = (d / scale).clamp(0.0, 1.0) as f32;
            [(2.0 * t).min(1.0), (2.0 * t - 1.0).max(0.0), 0.0]
        }
    }
}

pub(crate) fn run(
    image: &Path,
    reference: &Path,
    heatmap: Option<&Path>,
    mask: Option<&Path>,
    scale: f64,
    json_out: bool,
) -> Result<()> {
    let a = LinearImage::read_exr(image)?;
    let r = LinearImage::read_exr(reference)?;
    if (a.width, a.height) != (r.width, r.height) {
        return Err(sunbeam_common::Error::input_file(
            image,
            format!(
                "size {}x{} differs from the reference's {}x{}",
                a.width, a.height, r.width, r.height
            ),
        ));
    }
    let mask = match mask {
        Some(m) => {
            let im = LinearImage::read_exr(m)?;
            if (im.width, im.height) != (r.width, r.height) {
                return Err(sunbeam_common::Error::input_file(
                    m,
                    format!(
                        "size {}x{} differs from the reference's {}x{}",
                        im.width, im.height, r.width, r.height
                    ),
                ));
            }
            Some(im)
        }
        None => None,
    };
    let regions = compare_regions_within(&a, &r, mask.as_ref())?;
    let (all, inner, edge) = (regions.all, regions.interior, regions.edge);
    if let Some(path) = heatmap {
        let mut d = per_pixel_de(&a, &r)?;
        if let Some(m) = &mask {
            only_lit_in(&mut d, m);
        }
        let mut im = Image::new(a.width, a.height);
        for (px, v) in im.rgb.iter_mut().zip(&d) {
            *px = heat(*v, scale);
        }
        sunbeam_common::output::write_atomic(path, &im.png_bytes()?)?;
    }
    if json_out {
        let s = |c: &sunbeam_raster::ColourDiff| json!({"mean": c.mean, "p99": c.p99, "max": c.max, "pixels": c.pixels});
        println!(
            "{}",
            serde_json::to_string_pretty(&json!({
                "all": s(&all), "interior": s(&inner), "edge": s(&edge),
            }))
            .expect("a JSON value serializes")
        );
    } else {
        println!("all lit:  {all}");
        println!("interior: {inner}");
        println!("edge:     {edge}");
    }
    Ok(())
}
