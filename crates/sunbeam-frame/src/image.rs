//! Display images (sRGB-encoded floats, before 8-bit quantisation), PNG I/O and
//! the colour difference between two images (CIEDE2000, PHYSICS.md 4).

use std::path::Path;
use sunbeam_common::{Error, Result};
use sunbeam_optics::colour;

use crate::diff::ColourDiff;

/// An image of display values: sRGB-encoded, each channel in [0, 1], row 0 at the top.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<[f32; 3]>,
}

impl Image {
    pub fn new(width: u32, height: u32) -> Image {
        Image {
            width,
            height,
            rgb: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.rgb[(y * self.width + x) as usize]
    }

    /// 8-bit RGBA (alpha 255), quantised with `sunbeam_optics::colour::quantise8`.
    pub fn to_rgba8(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.rgb.len() * 4);
        for p in &self.rgb {
            for c in p {
                out.push(colour::quantise8(*c as f64));
            }
            out.push(255);
        }
        out
    }

    /// From 8-bit RGBA.
    pub fn from_rgba8(width: u32, height: u32, rgba: &[u8]) -> Image {
        let rgb = rgba
            .chunks_exact(4)
            .map(|p| [0, 1, 2].map(|k| p[k] as f32 / 255.0))
            .collect();
        Image { width, height, rgb }
    }

    /// PNG bytes (8-bit RGB, sRGB chunk; deterministic).
    pub fn png_bytes(&self) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            let mut wr = enc
                .write_header()
                .map_err(|e| Error::internal(format!("png: {e}")))?;
            let data: Vec<u8> = self
                .to_rgba8()
                .chunks_exact(4)
                .flat_map(|p| [p[0], p[1], p[2]])
                .collect();
            wr.write_image_data(&data)
                .map_err(|e| Error::internal(format!("png: {e}")))?;
        }
        Ok(out)
    }

    /// An animated PNG (APNG: 8-bit RGB, looping forever, `fps` frames per
    /// second) of equally sized frames; deterministic bytes. Viewers without
    /// APNG show the first frame.
    pub fn apng_bytes(frames: &[Image], fps: u16) -> Result<Vec<u8>> {
        let Some(first) = frames.first() else {
            return Err(Error::usage("an animation needs at least one frame"));
        };
        if frames
            .iter()
            .any(|f| f.width != first.width || f.height != first.height)
        {
            return Err(Error::internal("animation frames differ in size"));
        }
        let png_err = |e: png::EncodingError| Error::internal(format!("png: {e}"));
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, first.width, first.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
            enc.set_animated(frames.len() as u32, 0).map_err(png_err)?;
            enc.set_frame_delay(1, fps.max(1)).map_err(png_err)?;
            let mut wr = enc.write_header().map_err(png_err)?;
            for f in frames {
                let data: Vec<u8> = f
                    .to_rgba8()
                    .chunks_exact(4)
                    .flat_map(|p| [p[0], p[1], p[2]])
                    .collect();
                wr.write_image_data(&data).map_err(png_err)?;
            }
            wr.finish().map_err(png_err)?;
        }
        Ok(out)
    }

    /// Write a PNG atomically.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        sunbeam_common::output::write_atomic(path, &self.png_bytes()?)
    }

    /// Read an 8-bit RGB or RGBA PNG.
    pub fn read_png(path: &Path) -> Result<Image> {
        let f = std::fs::File::open(path).map_err(|e| Error::input_file(path, e))?;
        let mut dec = png::Decoder::new(std::io::BufReader::new(f));
        dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = dec.read_info().map_err(|e| Error::input_file(path, e))?;
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader
            .next_frame(&mut buf)
            .map_err(|e| Error::input_file(path, e))?;
        let ch = match info.color_type {
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            other => {
                return Err(Error::input_file(
                    path,
                    format!("unsupported PNG colour type {other:?}"),
                ))
            }
        };
        let rgb = buf[..info.buffer_size()]
            .chunks_exact(ch)
            .map(|p| {
                let g = |k: usize| p[if ch < 3 { 0 } else { k }] as f32 / 255.0;
                [g(0), g(1), g(2)]
            })
            .collect();
        Ok(Image {
            width: info.width,
            height: info.height,
            rgb,
        })
    }

    /// Mean and standard deviation of all channels (a blank-image check).
    pub fn mean_sd(&self) -> (f64, f64) {
        let n = (self.rgb.len() * 3).max(1) as f64;
        let mean = self.rgb.iter().flatten().map(|&v| v as f64).sum::<f64>() / n;
        let var = self
            .rgb
            .iter()
            .flatten()
            .map(|&v| (v as f64 - mean).powi(2))
            .sum::<f64>()
            / n;
        (mean, var.sqrt())
    }
}

/// Decode a display pixel to XYZ (sRGB EOTF, then the sRGB matrix).
pub fn display_to_xyz(p: [f32; 3]) -> [f64; 3] {
    colour::linear_srgb_to_xyz(p.map(|v| colour::srgb_eotf(v as f64)))
}

/// CIEDE2000 between the same pixels of two images (PHYSICS.md 4): mean, 99th percentile, max.
pub fn compare(a: &Image, b: &Image) -> Result<ColourDiff> {
    if a.width != b.width || a.height != b.height {
        return Err(Error::input(format!(
            "image sizes differ: {}x{} vs {}x{}",
            a.width, a.height, b.width, b.height
        )));
    }
    let mut d: Vec<f64> = a
        .rgb
        .iter()
        .zip(&b.rgb)
        .map(|(p, q)| colour::ciede2000_xyz(display_to_xyz(*p), display_to_xyz(*q)))
        .collect();
    Ok(crate::diff::stats(&mut d))
}
