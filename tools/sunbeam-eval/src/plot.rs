//! Plots as PNG through plotters' bitmap backend, with an embedded font
//! (DejaVu Sans, assets/DejaVuSans-LICENSE.txt) so no system fonts are needed,
//! and our own PNG encoder (png crate) and atomic write.

use plotters::prelude::*;
use std::path::Path;
use sunbeam_common::{output, Error, Result};

static FONT: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        for style in [
            FontStyle::Normal,
            FontStyle::Bold,
            FontStyle::Italic,
            FontStyle::Oblique,
        ] {
            let _ = plotters::style::register_font("sans-serif", style, FONT);
        }
    });
}

pub fn perr<E: std::fmt::Debug>(e: E) -> Error {
    Error::internal(format!("plot: {e:?}"))
}

/// Draw into an RGB buffer of `w` x `h` with `draw`, then write a PNG atomically.
pub fn png<F>(path: &Path, w: u32, h: u32, draw: F) -> Result<()>
where
    F: FnOnce(&DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>) -> Result<()>,
{
    register_font();
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(perr)?;
        draw(&root)?;
        root.present().map_err(perr)?;
    }
    write_rgb_png(path, w, h, &buf)
}

/// Encode an RGB8 buffer as PNG and write it atomically.
pub fn write_rgb_png(path: &Path, w: u32, h: u32, rgb: &[u8]) -> Result<()> {
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc
            .write_header()
            .map_err(|e| Error::output_file(path, e))?;
        wr.write_image_data(rgb)
            .map_err(|e| Error::output_file(path, e))?;
    }
    output::write_atomic(path, &bytes)
}

/// A perceptual-ish colour map (viridis, 5 stops) for t in [0, 1].
pub fn viridis(t: f64) -> RGBColor {
    const S: [(f64, f64, f64); 5] = [
        (68.0, 1.0, 84.0),
        (59.0, 82.0, 139.0),
        (33.0, 145.0, 140.0),
        (94.0, 201.0, 98.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    } * 4.0;
    let i = (t.floor() as usize).min(3);
    let f = t - i as f64;
    let (a, b) = (S[i], S[i + 1]);
    let l = |x: f64, y: f64| (x + f * (y - x)).round() as u8;
    RGBColor(l(a.0, b.0), l(a.1, b.1), l(a.2, b.2))
}
