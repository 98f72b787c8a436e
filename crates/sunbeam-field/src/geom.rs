//! Rotations by quarter turns, flips, crops and tiling. Pixel sizes follow the axes.

use crate::HeightField;
use sunbeam_common::{Error, Result};

/// Rotate counter-clockwise as the image is shown (row 0 at the top) by
/// `degrees` in {0, 90, 180, 270} (negative multiples of 90 are accepted too).
pub fn rotate(f: &HeightField, degrees: i32) -> Result<HeightField> {
    let (w, h) = (f.width, f.height);
    let turns = degrees.rem_euclid(360);
    if degrees % 90 != 0 {
        return Err(Error::usage(format!(
            "rotation {degrees} is not a multiple of 90 degrees"
        )));
    }
    let mut out = f.clone();
    match turns {
        0 => {}
        180 => out.data.reverse(),
        90 | 270 => {
            out.width = h;
            out.height = w;
            out.dx = f.dy;
            out.dy = f.dx;
            for r in 0..w {
                for c in 0..h {
                    // 90 CCW: new[r][c] = old[c][w-1-r]; 270: new[r][c] = old[h-1-c][r].
                    out.data[r * h + c] = if turns == 90 {
                        f.data[c * w + (w - 1 - r)]
                    } else {
                        f.data[(h - 1 - c) * w + r]
                    };
                }
            }
        }
        _ => unreachable!(),
    }
    Ok(out)
}

/// Mirror along x (left <-> right).
pub fn flip_x(f: &mut HeightField) {
    let w = f.width;
    for row in f.data.chunks_mut(w) {
        row.reverse();
    }
}

/// Mirror along y (top <-> bottom).
pub fn flip_y(f: &mut HeightField) {
    let (w, h) = (f.width, f.height);
    for i in 0..h / 2 {
        let (a, b) = f.data.split_at_mut((h - 1 - i) * w);
        a[i * w..(i + 1) * w].swap_with_slice(&mut b[..w]);
    }
}

/// Crop to columns `x..x+w`, rows `y..y+h` (row 0 at the top).
pub fn crop(f: &HeightField, x: usize, y: usize, w: usize, h: usize) -> Result<HeightField> {
    if w == 0
        || h == 0
        || x.checked_add(w).is_none_or(|e| e > f.width)
        || y.checked_add(h).is_none_or(|e| e > f.height)
    {
        return Err(Error::usage(format!(
            "crop {x},{y},{w},{h} (pixels) is empty or outside the {}x{} field",
            f.width, f.height
        )));
    }
    let mut data = Vec::with_capacity(w * h);
    for r in y..y + h {
        data.extend_from_slice(&f.data[r * f.width + x..r * f.width + x + w]);
    }
    let mut out = HeightField::new(w, h, f.dx, f.dy, data)?;
    out.provenance = f.provenance.clone();
    Ok(out)
}

/// A crop rectangle in pixels or physical units (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CropSpec {
    Pixels {
        x: usize,
        y: usize,
        w: usize,
        h: usize,
    },
    Metres {
        x: f64,
        y: f64,
        w: f64,
        h: f64,
    },
}

impl CropSpec {
    /// `X,Y,W,H`: four bare integers (pixels) or four lengths with units
    /// (`100nm,0nm,1um,1um`); mixing is refused.
    pub fn parse(s: &str) -> Result<CropSpec> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 4 {
            return Err(Error::usage("expected X,Y,W,H"));
        }
        if parts.iter().all(|p| p.parse::<usize>().is_ok()) {
            let v: Vec<usize> = parts.iter().map(|p| p.parse().unwrap_or(0)).collect();
            return Ok(CropSpec::Pixels {
                x: v[0],
                y: v[1],
                w: v[2],
                h: v[3],
            });
        }
        let mut v = [0.0; 4];
        for (k, p) in parts.iter().enumerate() {
            v[k] = sunbeam_common::units::parse_length(p).map_err(|e| {
                Error::usage(format!("{e} (give all four in pixels or all with units)"))
            })?;
            if v[k] < 0.0 {
                return Err(Error::usage("negative value"));
            }
        }
        Ok(CropSpec::Metres {
            x: v[0],
            y: v[1],
            w: v[2],
            h: v[3],
        })
    }

    /// The pixel rectangle for a field (physical values rounded to the nearest pixel).
    pub fn to_pixels(&self, f: &HeightField) -> (usize, usize, usize, usize) {
        match *self {
            CropSpec::Pixels { x, y, w, h } => (x, y, w, h),
            CropSpec::Metres { x, y, w, h } => {
                let px = |v: f64, d: f64| (v / d).round().min(u32::MAX as f64) as usize;
                (px(x, f.dx), px(y, f.dy), px(w, f.dx), px(h, f.dy))
            }
        }
    }
}

/// Replicate a height field `nx` x `ny` times (a periodic patch seen by a
/// window larger than one period); `nx = ny = 1` is a copy.
pub fn tile(f: &HeightField, nx: usize, ny: usize) -> Result<HeightField> {
    if nx == 1 && ny == 1 {
        return Ok(f.clone());
    }
    let (w, h) = (f.width * nx, f.height * ny);
    let mut data = Vec::with_capacity(w * h);
    for r in 0..h {
        for c in 0..w {
            data.push(f.at(r % f.height, c % f.width));
        }
    }
    let mut t = HeightField::new(w, h, f.dx, f.dy, data)?;
    t.provenance = f.provenance.clone();
    t.provenance.processing.push(format!("tiled {nx}x{ny}"));
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f32x2() -> HeightField {
        // 3 wide, 2 high: [0 1 2; 3 4 5]
        HeightField::new(3, 2, 1.0, 2.0, (0..6).map(|v| v as f64).collect()).unwrap()
    }

    #[test]
    fn rotations() {
        let f = f32x2();
        let r90 = rotate(&f, 90).unwrap();
        assert_eq!((r90.width, r90.height, r90.dx, r90.dy), (2, 3, 2.0, 1.0));
        assert_eq!(r90.data, vec![2.0, 5.0, 1.0, 4.0, 0.0, 3.0]);
        let r270 = rotate(&f, 270).unwrap();
        assert_eq!(r270.data, vec![3.0, 0.0, 4.0, 1.0, 5.0, 2.0]);
        assert_eq!(
            rotate(&f, 180).unwrap().data,
            vec![5.0, 4.0, 3.0, 2.0, 1.0, 0.0]
        );
        assert_eq!(rotate(&rotate(&f, 90).unwrap(), -90).unwrap(), f);
        assert!(rotate(&f, 45).is_err());
    }

    #[test]
    fn flips_and_crop() {
        let mut f = f32x2();
        flip_x(&mut f);
        assert_eq!(f.data, vec![2.0, 1.0, 0.0, 5.0, 4.0, 3.0]);
        flip_y(&mut f);
        assert_eq!(f.data, vec![5.0, 4.0, 3.0, 2.0, 1.0, 0.0]);
        let c = crop(&f32x2(), 1, 1, 2, 1).unwrap();
        assert_eq!((c.width, c.height, c.data.clone()), (2, 1, vec![4.0, 5.0]));
        assert!(crop(&f32x2(), 2, 0, 2, 1).is_err());
        assert_eq!(
            CropSpec::parse("1,2,3,4").unwrap(),
            CropSpec::Pixels {
                x: 1,
                y: 2,
                w: 3,
                h: 4
            }
        );
        let m = CropSpec::parse("1nm,2nm,3nm,4nm").unwrap();
        assert_eq!(
            m.to_pixels(&HeightField::new(9, 9, 1e-9, 2e-9, vec![0.0; 81]).unwrap()),
            (1, 1, 3, 2)
        );
        assert!(CropSpec::parse("1,2nm,3,4").is_err());
    }

    #[test]
    fn tiling() {
        let t = tile(&f32x2(), 2, 2).unwrap();
        assert_eq!((t.width, t.height, t.dx, t.dy), (6, 4, 1.0, 2.0));
        #[rustfmt::skip]
        let want = vec![
            0.0, 1.0, 2.0, 0.0, 1.0, 2.0,
            3.0, 4.0, 5.0, 3.0, 4.0, 5.0,
            0.0, 1.0, 2.0, 0.0, 1.0, 2.0,
            3.0, 4.0, 5.0, 3.0, 4.0, 5.0,
        ];
        assert_eq!(t.data, want);
        assert_eq!(t.provenance.processing.last().unwrap(), "tiled 2x2");
        assert_eq!(tile(&f32x2(), 1, 1).unwrap(), f32x2());
        let row = tile(&f32x2(), 1, 3).unwrap();
        assert_eq!((row.width, row.height), (3, 6));
        assert_eq!(&row.data[12..], &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    }
}
