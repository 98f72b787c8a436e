//! False-colour PNG previews with a scale bar and the z range, drawn with a
//! tiny built-in 5x7 bitmap font. Deterministic bytes.

use crate::stats::Stats;
use crate::HeightField;
use sunbeam_common::units::format_length;
use sunbeam_common::{Error, Result};

/// Longest side of the image part of a preview, in pixels.
pub const MAX_PREVIEW: usize = 1024;

/// Viridis, 9 control points (sRGB), interpolated linearly.
const CMAP: [[f64; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

fn colour(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0) * (CMAP.len() - 1) as f64;
    let i = (t.floor() as usize).min(CMAP.len() - 2);
    let f = t - i as f64;
    let mut c = [0u8; 3];
    for k in 0..3 {
        c[k] = (CMAP[i][k] * (1.0 - f) + CMAP[i + 1][k] * f).round() as u8;
    }
    c
}

/// 5x7 glyphs, one byte per row (low 5 bits, bit 4 = leftmost).
fn glyph(ch: char) -> [u8; 7] {
    match ch {
        '0' => [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E],
        '1' => [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E],
        '2' => [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F],
        '3' => [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E],
        '4' => [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02],
        '5' => [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E],
        '6' => [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E],
        '7' => [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08],
        '8' => [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E],
        '9' => [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C],
        '.' => [0, 0, 0, 0, 0, 0x0C, 0x0C],
        '-' => [0, 0, 0, 0x1F, 0, 0, 0],
        'n' => [0, 0, 0x16, 0x19, 0x11, 0x11, 0x11],
        'm' => [0, 0, 0x1A, 0x15, 0x15, 0x11, 0x11],
        'u' => [0, 0, 0x11, 0x11, 0x11, 0x13, 0x0D],
        'p' => [0, 0, 0x1E, 0x11, 0x1E, 0x10, 0x10],
        'z' => [0, 0, 0x1F, 0x02, 0x04, 0x08, 0x1F],
        ':' => [0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0],
        _ => [0; 7],
    }
}

struct Canvas {
    w: usize,
    h: usize,
    px: Vec<u8>,
}

impl Canvas {
    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        if x < self.w && y < self.h {
            let o = 3 * (y * self.w + x);
            self.px[o..o + 3].copy_from_slice(&c);
        }
    }
    fn rect(&mut self, x: usize, y: usize, w: usize, h: usize, c: [u8; 3]) {
        for yy in y..y + h {
            for xx in x..x + w {
                self.set(xx, yy, c);
            }
        }
    }
    /// Text at (x, y) top-left, glyphs scaled by `s`; returns the width drawn.
    fn text(&mut self, x: usize, y: usize, s: usize, t: &str, c: [u8; 3]) -> usize {
        let mut cx = x;
        for ch in t.chars() {
            let g = glyph(ch);
            for (r, bits) in g.iter().enumerate() {
                for col in 0..5 {
                    if bits & (0x10 >> col) != 0 {
                        self.rect(cx + col * s, y + r * s, s, s, c);
                    }
                }
            }
            cx += 6 * s;
        }
        cx - x
    }
}

fn text_width(t: &str, s: usize) -> usize {
    t.chars().count() * 6 * s
}

/// A "nice" length (1, 2 or 5 x 10^k) no longer than `max`.
fn nice_length(max: f64) -> f64 {
    let e = max.log10().floor();
    let b = 10f64.powi(e as i32);
    for m in [5.0, 2.0, 1.0] {
        if m * b <= max {
            return m * b;
        }
    }
    b
}

/// The colour range: the 0.1 % and 99.9 % quantiles of the finite values, so
/// a few spikes or bad lines do not wash the picture out.
pub fn colour_range(f: &HeightField) -> (f64, f64) {
    let mut v: Vec<f64> = f.data.iter().copied().filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return (0.0, 1.0);
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    (q(0.001), q(0.999))
}

/// Render the preview as RGB pixels: (width, height, rgb bytes).
pub fn render(f: &HeightField) -> (usize, usize, Vec<u8>) {
    let (lx, ly) = (f.size_x(), f.size_y());
    // Image part: physical aspect, longest side <= MAX_PREVIEW, at most 1 image
    // pixel per field pixel along the denser axis.
    let natural_w = f.width as f64 * (f.dx / f.dx.min(f.dy));
    let natural_h = f.height as f64 * (f.dy / f.dx.min(f.dy));
    let s = (MAX_PREVIEW as f64 / natural_w.max(natural_h)).min(1.0);
    let iw = ((natural_w * s).round() as usize).max(1);
    let ih = ((natural_h * s).round() as usize).max(1);
    let scale = if iw.max(ih) >= 400 { 2 } else { 1 };
    let strip = 14 * scale;
    let (w, h) = (
        iw.max(text_width("0000 nm  z: 000.0 nm", scale) + 8),
        ih + strip,
    );
    let mut cv = Canvas {
        w,
        h,
        px: vec![0u8; w * h * 3],
    };
    let st = Stats::of(f);
    let (lo, hi) = colour_range(f);
    let span = if hi > lo { hi - lo } else { 1.0 };
    for y in 0..ih {
        let r = ((y as f64 + 0.5) / ih as f64 * f.height as f64) as usize;
        for x in 0..iw {
            let c = ((x as f64 + 0.5) / iw as f64 * f.width as f64) as usize;
            let v = f.data[r.min(f.height - 1) * f.width + c.min(f.width - 1)];
            let col = if v.is_finite() {
                colour((v - lo) / span)
            } else {
                [255, 0, 255]
            };
            cv.set(x, y, col);
        }
    }
    // Scale bar: a nice length about a quarter of the width.
    let white = [255, 255, 255];
    let bar_m = nice_length(lx / 4.0);
    let bar_px = ((bar_m / lx * iw as f64).round() as usize).max(1);
    let y0 = ih + 3 * scale;
    cv.rect(2 * scale, y0 + 2 * scale, bar_px, 3 * scale, white);
    let label = format_length(bar_m);
    let tx = 2 * scale + bar_px + 4 * scale;
    let used = cv.text(tx, y0, scale, &label, white);
    // The colour span (0.1 %..99.9 % of the heights).
    let zlabel = if st.finite > 0 {
        format!("z: {}", format_length(hi - lo))
    } else {
        String::new()
    };
    let zx = (tx + used + 6 * scale).max(w.saturating_sub(text_width(&zlabel, scale) + 2 * scale));
    cv.text(zx, y0, scale, &zlabel, white);
    let _ = ly;
    (w, h, cv.px)
}

/// Encode the preview as a PNG (8-bit RGB).
pub fn encode_png(f: &HeightField) -> Result<Vec<u8>> {
    let (w, h, px) = render(f);
    let mut out = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut out, w as u32, h as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc
            .write_header()
            .map_err(|e| Error::internal(format!("PNG encoder: {e}")))?;
        wr.write_image_data(&px)
            .map_err(|e| Error::internal(format!("PNG encoder: {e}")))?;
    }
    Ok(out)
}

/// Write the preview PNG atomically.
pub fn write_png(path: &std::path::Path, f: &HeightField) -> Result<()> {
    sunbeam_common::output::write_atomic(path, &encode_png(f)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_deterministically() {
        let f = HeightField::new(
            64,
            32,
            10e-9,
            20e-9,
            (0..2048).map(|v| (v as f64 * 0.01).sin() * 1e-9).collect(),
        )
        .unwrap();
        let (w, h, px) = render(&f);
        assert!(w >= 64 && h == 64 + 14, "{w}x{h}");
        assert_eq!(px.len(), w * h * 3);
        assert_eq!(encode_png(&f).unwrap(), encode_png(&f).unwrap());
        assert_eq!(nice_length(160e-9), 100e-9);
        assert_eq!(nice_length(0.3e-6), 0.2e-6);
    }
}
