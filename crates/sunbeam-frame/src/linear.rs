//! Linear-light frames: what a camera records before the display transform.
//!
//! A [`LinearImage`] holds linear sRGB (Rec. 709 primaries, D65 white) radiance
//! times `2^exposure`, so that `display_encode` with exposure 0 turns it into the
//! PNG a renderer writes. Comparisons between renderers are made on these values
//! (CIEDE2000 over lit pixels, [`compare_linear`]): they are not clipped by the
//! 8-bit display transform. Files are single-part RGB float32 OpenEXR,
//! uncompressed (written by `exr`; no attributes beyond the required ones, so the
//! bytes depend on the pixels only).

use std::path::Path;
use sunbeam_common::{Error, Result};
use sunbeam_optics::colour::{self, ToneCurve, ToneMap};

use crate::diff::{stats, ColourDiff};
use crate::Image;

/// Linear sRGB values (exposure applied), row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[f32; 3]>,
}

/// Luminance `Y` (white = 1) under which a pixel of the reference counts as unlit:
/// L* = 1.0, darker than the 8-bit display can show apart from black.
pub const LIT_Y: f64 = 0.0011;

impl LinearImage {
    pub fn new(width: u32, height: u32) -> LinearImage {
        LinearImage {
            width,
            height,
            rgb: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    /// Average `s x s` blocks (a box filter in linear light): the anti-aliased frame.
    pub fn downsample(&self, s: u32) -> LinearImage {
        if s <= 1 {
            return self.clone();
        }
        let (w, h) = (self.width / s, self.height / s);
        let mut out = LinearImage::new(w, h);
        let inv = 1.0 / (s * s) as f64;
        for y in 0..h {
            for x in 0..w {
                let mut acc = [0.0f64; 3];
                for j in 0..s {
                    let row = ((y * s + j) * self.width + x * s) as usize;
                    for p in &self.rgb[row..row + s as usize] {
                        for k in 0..3 {
                            acc[k] += p[k] as f64;
                        }
                    }
                }
                out.rgb[(y * w + x) as usize] = acc.map(|v| (v * inv) as f32);
            }
        }
        out
    }

    /// The display image (tone curve and sRGB OETF; the exposure is already applied).
    pub fn display(&self, curve: ToneCurve) -> Image {
        let tm = ToneMap {
            exposure_ev: 0.0,
            curve,
        };
        Image {
            width: self.width,
            height: self.height,
            rgb: self
                .rgb
                .iter()
                .map(|p| colour::display_encode(p.map(f64::from), &tm).map(|v| v as f32))
                .collect(),
        }
    }

    /// OpenEXR bytes: RGB float32, uncompressed, deterministic.
    pub fn exr_bytes(&self) -> Result<Vec<u8>> {
        use exr::prelude::{
            Encoding, Layer, LayerAttributes, SpecificChannels, Vec2, WritableImage,
        };
        let (w, h) = (self.width as usize, self.height as usize);
        let px = |p: Vec2<usize>| {
            let c = self.rgb[p.y() * w + p.x()];
            (c[0], c[1], c[2])
        };
        let channels = SpecificChannels::rgb(px);
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            Encoding::UNCOMPRESSED,
            channels,
        );
        let image = exr::image::Image::from_layer(layer);
        let mut out = std::io::Cursor::new(Vec::new());
        image
            .write()
            .non_parallel()
            .to_buffered(&mut out)
            .map_err(|e| Error::internal(format!("OpenEXR encoding: {e}")))?;
        Ok(out.into_inner())
    }

    /// Write atomically as OpenEXR.
    pub fn write_exr(&self, path: &Path) -> Result<()> {
        let bytes = self.exr_bytes()?;
        sunbeam_common::output::write_atomic(path, &bytes)
    }

    /// Read an RGB(A) OpenEXR (the first layer; channels R, G, B).
    pub fn read_exr(path: &Path) -> Result<LinearImage> {
        use exr::prelude::{read, ReadChannels, ReadLayers, Vec2};
        let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e.to_string()))?;
        let img = read()
            .no_deep_data()
            .largest_resolution_level()
            .rgb_channels(
                |res, _| LinearImage::new(res.width() as u32, res.height() as u32),
                |im: &mut LinearImage, p: Vec2<usize>, (r, g, b): (f32, f32, f32)| {
                    let w = im.width as usize;
                    im.rgb[p.y() * w + p.x()] = [r, g, b];
                },
            )
            .first_valid_layer()
            .all_attributes()
            .non_parallel()
            .from_buffered(std::io::Cursor::new(bytes))
            .map_err(|e| Error::input_file(path, format!("not an RGB OpenEXR image: {e}")))?;
        Ok(img.layer_data.channel_data.pixels)
    }
}

/// Luminance of a linear sRGB pixel (white = 1).
pub fn luminance(p: [f32; 3]) -> f64 {
    colour::linear_srgb_to_xyz(p.map(f64::from))[1]
}

/// The pixel-wise mean of frames of one size in linear light (e.g. several
/// seeds' frames of one scene): summed in order, then divided by their count.
pub fn mean_of(frames: &[LinearImage]) -> Result<LinearImage> {
    let Some((first, rest)) = frames.split_first() else {
        return Err(Error::usage("the mean of no frames"));
    };
    let mut mean = first.clone();
    for f in rest {
        if (f.width, f.height) != (mean.width, mean.height) {
            return Err(Error::input(format!(
                "image sizes differ: {}x{} vs {}x{}",
                f.width, f.height, mean.width, mean.height
            )));
        }
        for (m, p) in mean.rgb.iter_mut().zip(&f.rgb) {
            for c in 0..3 {
                m[c] += p[c];
            }
        }
    }
    let k = frames.len() as f32;
    for m in &mut mean.rgb {
        for v in m.iter_mut() {
            *v /= k;
        }
    }
    Ok(mean)
}

/// Indices of the pixels whose eight neighbours (and themselves) are lit
/// (`Y >= LIT_Y`) in every one of `frames` (one size): the interior of the
/// lit area, away from silhouettes, where a sub-pixel sample can fall on
/// either side of an edge.
pub fn interior_pixels(frames: &[&LinearImage]) -> Vec<usize> {
    let Some(f0) = frames.first() else {
        return Vec::new();
    };
    let w = f0.width as usize;
    let lit = |i: usize| frames.iter().all(|f| luminance(f.rgb[i]) >= LIT_Y);
    off_border(f0)
        .filter(|&i| (0..9).all(|k| lit(i + (k / 3) * w + k % 3 - w - 1)))
        .collect()
}

/// Indices of the pixels of `frame` with all eight neighbours in the image.
fn off_border(frame: &LinearImage) -> impl Iterator<Item = usize> {
    let (w, h) = (frame.width as usize, frame.height as usize);
    (0..w * h).filter(move |&i| {
        let (x, y) = (i % w, i / w);
        x > 0 && y > 0 && x + 1 < w && y + 1 < h
    })
}

/// Indices of the lit pixels (`Y > LIT_Y`) of `frame`, away from the
/// image's border, with an unlit pixel above, below, left or right: the
/// outline of the lit area, the pixels a silhouette crosses.
pub fn outline_pixels(frame: &LinearImage) -> Vec<usize> {
    let w = frame.width as usize;
    let lit = |i: usize| luminance(frame.rgb[i]) > LIT_Y;
    off_border(frame)
        .filter(|&i| lit(i) && [i - 1, i + 1, i - w, i + w].iter().any(|&j| !lit(j)))
        .collect()
}

/// CIEDE2000 of each pixel of `a` against `reference` (same size), `None`
/// where the reference is unlit (`Y < LIT_Y`).
pub fn per_pixel_de(a: &LinearImage, reference: &LinearImage) -> Result<Vec<Option<f64>>> {
    if a.width != reference.width || a.height != reference.height {
        return Err(Error::input(format!(
            "image sizes differ: {}x{} vs {}x{}",
            a.width, a.height, reference.width, reference.height
        )));
    }
    Ok(a.rgb
        .iter()
        .zip(&reference.rgb)
        .map(|(p, q)| {
            (luminance(*q) >= LIT_Y).then(|| {
                colour::ciede2000_xyz(
                    colour::linear_srgb_to_xyz(p.map(|v| f64::from(v).max(0.0))),
                    colour::linear_srgb_to_xyz(q.map(|v| f64::from(v).max(0.0))),
                )
            })
        })
        .collect())
}

/// CIEDE2000 between two linear images over the pixels that are lit in the
/// reference `b` (`Y >= LIT_Y`): mean, 99th percentile, max (PHYSICS.md 4, with
/// Lab relative to the D65 white of Y = 1, so values above 1 are allowed).
pub fn compare_linear(a: &LinearImage, reference: &LinearImage) -> Result<ColourDiff> {
    let mut d: Vec<f64> = per_pixel_de(a, reference)?.into_iter().flatten().collect();
    Ok(stats(&mut d))
}

/// [`compare_linear`] over all lit pixels, and split into the interior of
/// the lit area ([`interior_pixels`] of the reference) and the rest, the
/// edge: the pixels next to a silhouette, where sub-pixel coverage and
/// grazing views dominate (`sunbeam-eval diff`, docs/EVAL.md "diff").
#[derive(Debug, Clone, PartialEq)]
pub struct RegionDiff {
    pub all: ColourDiff,
    pub interior: ColourDiff,
    pub edge: ColourDiff,
}

/// [`RegionDiff`] of `a` against `reference` (same size).
pub fn compare_regions(a: &LinearImage, reference: &LinearImage) -> Result<RegionDiff> {
    compare_regions_within(a, reference, None)
}

/// Per-pixel differences ([`per_pixel_de`]) kept only where `mask` (same
/// size) is lit.
pub fn only_lit_in(d: &mut [Option<f64>], mask: &LinearImage) {
    for (v, p) in d.iter_mut().zip(&mask.rgb) {
        if luminance(*p) < LIT_Y {
            *v = None;
        }
    }
}

/// [`compare_regions`] over the pixels lit in `mask` (same size) alone, the
/// interior and the edge taken from the mask's lit area: an object's pixels
/// when a background is drawn behind it (the mask: a frame of the same
/// camera with the background off), where the reference's lit area is the
/// whole frame. `None`: the reference's lit area.
pub fn compare_regions_within(
    a: &LinearImage,
    reference: &LinearImage,
    mask: Option<&LinearImage>,
) -> Result<RegionDiff> {
    let mut d = per_pixel_de(a, reference)?;
    let area = match mask {
        Some(m) => {
            if (m.width, m.height) != (reference.width, reference.height) {
                return Err(Error::input(format!(
                    "the mask's size {}x{} differs from the reference's {}x{}",
                    m.width, m.height, reference.width, reference.height
                )));
            }
            only_lit_in(&mut d, m);
            m
        }
        None => reference,
    };
    let mut inner = vec![false; d.len()];
    for i in interior_pixels(&[area]) {
        inner[i] = true;
    }
    let (mut all, mut interior, mut edge) = (Vec::new(), Vec::new(), Vec::new());
    for (v, &is_inner) in d.iter().zip(&inner) {
        if let Some(v) = *v {
            all.push(v);
            if is_inner {
                interior.push(v);
            } else {
                edge.push(v);
            }
        }
    }
    Ok(RegionDiff {
        all: stats(&mut all),
        interior: stats(&mut interior),
        edge: stats(&mut edge),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exr_round_trip_and_box_filter() {
        let mut im = LinearImage::new(4, 2);
        for (i, p) in im.rgb.iter_mut().enumerate() {
            *p = [i as f32, 0.5, 2.0 * i as f32];
        }
        let dir = std::env::temp_dir().join(format!("sunbeam-linear-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("a.exr");
        im.write_exr(&f).unwrap();
        let back = LinearImage::read_exr(&f).unwrap();
        assert_eq!(back, im);
        let d = im.downsample(2);
        assert_eq!((d.width, d.height), (2, 1));
        // (0 + 1 + 4 + 5) / 4 and (2 + 3 + 6 + 7) / 4
        assert_eq!(d.rgb[0][0], 2.5);
        assert_eq!(d.rgb[1][0], 4.5);
        std::fs::remove_dir_all(&dir).ok();
    }

    /// A lit square's outline is its ring of border pixels, not its inside
    /// or the dark around it.
    #[test]
    fn the_outline_is_the_lit_ring() {
        let mut f = LinearImage::new(8, 8);
        for y in 2..6 {
            for x in 2..6 {
                f.rgb[y * 8 + x] = [0.5; 3];
            }
        }
        let o = outline_pixels(&f);
        assert_eq!(o.len(), 12, "{o:?}");
        assert!(o.iter().all(|&i| {
            let (x, y) = (i % 8, i / 8);
            (2..6).contains(&x) && (2..6).contains(&y) && (x % 3 == 2 || y % 3 == 2)
        }));
    }

    #[test]
    fn regions_split_interior_and_edge() {
        // 4 x 3 lit reference: interior (1, 1) and (2, 1); `a` off by a
        // factor 2 at (1, 1) (interior) and at (0, 0) (edge) only.
        let mut r = LinearImage::new(4, 3);
        for p in &mut r.rgb {
            *p = [0.5, 0.5, 0.5];
        }
        let mut a = r.clone();
        a.rgb[5] = [1.0, 1.0, 1.0];
        a.rgb[0] = [1.0, 1.0, 1.0];
        let d = compare_regions(&a, &r).unwrap();
        assert_eq!(
            (d.all.pixels, d.interior.pixels, d.edge.pixels),
            (12, 2, 10)
        );
        assert!(d.interior.max > 10.0 && d.edge.max > 10.0, "{d:?}");
        assert_eq!(d.all.max, d.interior.max);
        let whole = compare_linear(&a, &r).unwrap();
        assert_eq!(whole, d.all);
        assert!((d.interior.mean - d.interior.max / 2.0).abs() < 1e-12);

        // A mask lit on the right 3 x 3 alone: (0, 0) is outside it, (2, 1)
        // its one interior pixel, and the interior error at (1, 1) now on
        // its edge.
        let mut m = r.clone();
        for y in 0..3 {
            m.rgb[y * 4] = [0.0; 3];
        }
        let d = compare_regions_within(&a, &r, Some(&m)).unwrap();
        assert_eq!((d.all.pixels, d.interior.pixels, d.edge.pixels), (9, 1, 8));
        assert_eq!(d.interior.max, 0.0);
        assert!(d.edge.max > 10.0, "{d:?}");
        assert!(compare_regions_within(&a, &r, Some(&LinearImage::new(3, 3))).is_err());
    }

    #[test]
    fn mean_and_interior() {
        let mut a = LinearImage::new(4, 3);
        let mut b = LinearImage::new(4, 3);
        for (i, (p, q)) in a.rgb.iter_mut().zip(b.rgb.iter_mut()).enumerate() {
            *p = [0.5, 0.5, 0.5];
            *q = [1.0 + i as f32, 0.5, 0.0];
        }
        let m = mean_of(&[a.clone(), b.clone()]).unwrap();
        assert_eq!(m.rgb[5], [(0.5 + 6.0) / 2.0, 0.5, 0.25]);
        assert!(mean_of(&[]).is_err());
        assert!(mean_of(&[a.clone(), LinearImage::new(3, 3)]).is_err());
        // 4 x 3, all lit: the interior is (1, 1) and (2, 1).
        assert_eq!(interior_pixels(&[&a, &b]), vec![5, 6]);
        // (3, 0) dark in b: (2, 1) has it as a neighbour.
        b.rgb[3] = [0.0; 3];
        assert_eq!(interior_pixels(&[&a, &b]), vec![5]);
        assert_eq!(interior_pixels(&[&a]), vec![5, 6]);
    }

    #[test]
    fn compare_counts_lit_pixels_only() {
        let mut a = LinearImage::new(2, 1);
        let mut b = LinearImage::new(2, 1);
        a.rgb = vec![[0.5, 0.5, 0.5], [0.0, 0.0, 0.0]];
        b.rgb = vec![[0.5, 0.5, 0.5], [1e-5, 0.0, 0.0]];
        let d = compare_linear(&a, &b).unwrap();
        assert_eq!(d.pixels, 1);
        assert!(d.max < 1e-9);
        b.rgb[0] = [0.6, 0.5, 0.5];
        assert!(compare_linear(&a, &b).unwrap().max > 1.0);
    }
}
