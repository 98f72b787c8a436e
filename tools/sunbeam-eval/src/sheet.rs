//! `sunbeam-eval sheet`: a contact sheet, one PNG with many PNGs on a grid
//! (height previews, BRDF pictures, rendered frames), row by row in the
//! order given. Each picture is scaled to fit a cell (area average when
//! shrinking, nearest when enlarging, aspect kept) and centred on a dark
//! grey background. Deterministic: same inputs, same bytes.

use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};

/// Cell size in pixels (each picture fits in CELL x CELL, plus the margin).
const CELL: usize = 256;
const MARGIN: usize = 8;
const BACKGROUND: [u8; 3] = [24, 24, 24];

/// An 8-bit RGB picture.
struct Rgb {
    w: usize,
    h: usize,
    px: Vec<u8>,
}

fn read_png(path: &Path) -> Result<Rgb> {
    let file = std::fs::File::open(path)
        .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    let mut dec = png::Decoder::new(std::io::BufReader::new(file));
    dec.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = dec
        .read_info()
        .map_err(|e| Error::input_file(path, format!("not a PNG: {e}")))?;
    let (w, h) = (reader.info().width as usize, reader.info().height as usize);
    if w == 0 || h == 0 || w.saturating_mul(h) > 64 << 20 {
        return Err(Error::input_file(
            path,
            format!("unusable PNG size {w}x{h}"),
        ));
    }
    let mut buf = vec![0; reader.output_buffer_size()];
    let frame = reader
        .next_frame(&mut buf)
        .map_err(|e| Error::input_file(path, format!("damaged PNG: {e}")))?;
    let ch = match frame.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => {
            return Err(Error::input_file(path, "indexed PNG not expanded"));
        }
    };
    let mut px = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        let row = &buf[y * frame.line_size..];
        for x in 0..w {
            let p = &row[x * ch..x * ch + ch];
            let (rgb, a) = match ch {
                1 => ([p[0]; 3], 255),
                2 => ([p[0]; 3], p[1]),
                3 => ([p[0], p[1], p[2]], 255),
                _ => ([p[0], p[1], p[2]], p[3]),
            };
            // Alpha over the sheet's background (integer, so deterministic).
            for (c, bg) in rgb.iter().zip(BACKGROUND) {
                let v = (*c as u32 * a as u32 + bg as u32 * (255 - a as u32) + 127) / 255;
                px.push(v as u8);
            }
        }
    }
    Ok(Rgb { w, h, px })
}

/// Scale `img` to fit `cell x cell`, keeping its aspect.
fn fit(img: &Rgb, cell: usize) -> Rgb {
    let s = (cell as f64 / img.w as f64).min(cell as f64 / img.h as f64);
    let w = ((img.w as f64 * s).round() as usize).clamp(1, cell);
    let h = ((img.h as f64 * s).round() as usize).clamp(1, cell);
    let mut px = vec![0u8; w * h * 3];
    for y in 0..h {
        // Source rows [y0, y1) covered by output row y (at least one).
        let y0 = y * img.h / h;
        let y1 = ((y + 1) * img.h / h).max(y0 + 1);
        for x in 0..w {
            let x0 = x * img.w / w;
            let x1 = ((x + 1) * img.w / w).max(x0 + 1);
            let mut acc = [0u64; 3];
            for sy in y0..y1 {
                for sx in x0..x1 {
                    let i = (sy * img.w + sx) * 3;
                    for (a, &v) in acc.iter_mut().zip(&img.px[i..i + 3]) {
                        *a += v as u64;
                    }
                }
            }
            let n = ((y1 - y0) * (x1 - x0)) as u64;
            for (d, a) in px[(y * w + x) * 3..(y * w + x) * 3 + 3].iter_mut().zip(acc) {
                *d = ((a + n / 2) / n) as u8;
            }
        }
    }
    Rgb { w, h, px }
}

/// Write the contact sheet of `inputs` (PNGs) to `output`, `columns` per row.
pub fn run(output: &Path, inputs: &[PathBuf], columns: usize) -> Result<()> {
    if inputs.is_empty() {
        return Err(Error::usage("sheet: give at least one input PNG"));
    }
    if columns == 0 {
        return Err(Error::usage("sheet: --columns must be at least 1"));
    }
    let ok = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !ok {
        return Err(Error::usage(format!(
            "{}: the sheet is a .png",
            output.display()
        )));
    }
    let pics = inputs
        .iter()
        .map(|p| read_png(p).map(|i| fit(&i, CELL)))
        .collect::<Result<Vec<_>>>()?;
    let cols = columns.min(pics.len());
    let rows = pics.len().div_ceil(cols);
    let step = CELL + MARGIN;
    let (w, h) = (cols * step + MARGIN, rows * step + MARGIN);
    let mut sheet: Vec<u8> = BACKGROUND.iter().copied().cycle().take(w * h * 3).collect();
    for (i, p) in pics.iter().enumerate() {
        let (cx, cy) = (MARGIN + (i % cols) * step, MARGIN + (i / cols) * step);
        let (ox, oy) = (cx + (CELL - p.w) / 2, cy + (CELL - p.h) / 2);
        for y in 0..p.h {
            let dst = ((oy + y) * w + ox) * 3;
            sheet[dst..dst + p.w * 3].copy_from_slice(&p.px[y * p.w * 3..(y + 1) * p.w * 3]);
        }
    }
    let mut bytes = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut bytes, w as u32, h as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Default);
        let mut wr = enc
            .write_header()
            .map_err(|e| Error::internal(format!("PNG header: {e}")))?;
        wr.write_image_data(&sheet)
            .map_err(|e| Error::internal(format!("PNG data: {e}")))?;
    }
    sunbeam_common::output::write_atomic(output, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_png(path: &Path, w: u32, h: u32, ct: png::ColorType, data: &[u8]) {
        let f = std::fs::File::create(path).unwrap();
        let mut e = png::Encoder::new(f, w, h);
        e.set_color(ct);
        e.set_depth(png::BitDepth::Eight);
        e.write_header().unwrap().write_image_data(data).unwrap();
    }

    #[test]
    fn grid_placement_scaling_and_determinism() {
        let d = std::env::temp_dir().join(format!("sunbeam-sheet-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        // A 512x256 red picture (shrinks to 256x128) and a 2x2 grey one (enlarges to 256x256).
        let a = d.join("a.png");
        let b = d.join("b.png");
        write_png(
            &a,
            512,
            256,
            png::ColorType::Rgb,
            &[200, 0, 0].repeat(512 * 256),
        );
        write_png(&b, 2, 2, png::ColorType::Grayscale, &[100; 4]);
        let out = d.join("s.png");
        run(&out, &[a.clone(), b.clone(), a.clone()], 2).unwrap();
        let s = read_png(&out).unwrap();
        assert_eq!(
            (s.w, s.h),
            (2 * (CELL + MARGIN) + MARGIN, 2 * (CELL + MARGIN) + MARGIN)
        );
        let at = |x: usize, y: usize| &s.px[(y * s.w + x) * 3..(y * s.w + x) * 3 + 3];
        // Cell 0: red band centred vertically, background above it.
        assert_eq!(at(MARGIN + 10, MARGIN + CELL / 2), &[200, 0, 0]);
        assert_eq!(at(MARGIN + 10, MARGIN + 10), &BACKGROUND);
        // Cell 1: grey fills the cell.
        assert_eq!(at(2 * MARGIN + CELL + 1, MARGIN + 1), &[100, 100, 100]);
        // Cell 3 (row 1, column 1) is empty.
        assert_eq!(
            at(2 * MARGIN + CELL + 100, 2 * MARGIN + CELL + 100),
            &BACKGROUND
        );
        let first = std::fs::read(&out).unwrap();
        run(&out, &[a.clone(), b.clone(), a.clone()], 2).unwrap();
        assert_eq!(first, std::fs::read(&out).unwrap());
        // Errors: no inputs, zero columns, a missing input (names it), not a PNG output.
        assert_eq!(run(&out, &[], 2).unwrap_err().exit_code(), 1);
        assert_eq!(
            run(&out, std::slice::from_ref(&a), 0)
                .unwrap_err()
                .exit_code(),
            1
        );
        let e = run(&out, &[d.join("missing.png")], 1).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("missing.png"));
        assert_eq!(run(&d.join("s.jpg"), &[a], 1).unwrap_err().exit_code(), 1);
        let _ = std::fs::remove_dir_all(&d);
    }
}
