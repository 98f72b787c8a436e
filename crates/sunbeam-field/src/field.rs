use sunbeam_common::{Error, Result};

/// Where a height field came from and what was done to it (written into EXR
/// headers and `--json` reports).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Provenance {
    /// The instrument file name (no directories, so outputs stay byte-identical across checkouts).
    pub source_file: String,
    /// e.g. "nanoscope", "gwy", "gsf", "ibw", "sxm", "park-tiff", "png", "ascii", "xyz".
    pub source_format: String,
    /// Channel name as the instrument file calls it.
    pub channel: String,
    /// Processing steps applied, in order, e.g. "level plane", "align-rows median".
    pub processing: Vec<String>,
}

/// A regular grid of heights in metres with its (possibly non-square) pixel size.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    /// Columns (Mx).
    pub width: usize,
    /// Rows (My).
    pub height: usize,
    /// Pixel size along x (columns), metres.
    pub dx: f64,
    /// Pixel size along y (rows), metres.
    pub dy: f64,
    /// Row-major heights in metres, row 0 at the top. May hold NaN only where
    /// the instrument file had no value; tools that need finite values check.
    pub data: Vec<f64>,
    pub provenance: Provenance,
}

/// Largest grid accepted anywhere (per side): a guard against absurd headers.
pub const MAX_SIDE: usize = 1 << 15;

impl HeightField {
    /// A validated height field: sizes match, pixel sizes finite and positive.
    pub fn new(width: usize, height: usize, dx: f64, dy: f64, data: Vec<f64>) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(Error::input(format!(
                "empty height field ({width}x{height})"
            )));
        }
        if width > MAX_SIDE || height > MAX_SIDE {
            return Err(Error::input(format!(
                "height field {width}x{height} exceeds the {MAX_SIDE} pixel limit per side"
            )));
        }
        if data.len() != width * height {
            return Err(Error::input(format!(
                "height field has {} values for {width}x{height} pixels",
                data.len()
            )));
        }
        if !(dx.is_finite() && dx > 0.0 && dy.is_finite() && dy > 0.0) {
            return Err(Error::input(format!(
                "pixel size must be finite and positive (dx={dx}, dy={dy})"
            )));
        }
        Ok(Self {
            width,
            height,
            dx,
            dy,
            data,
            provenance: Provenance::default(),
        })
    }

    /// Height at row `r` (0 = top), column `c`.
    #[inline]
    pub fn at(&self, r: usize, c: usize) -> f64 {
        self.data[r * self.width + c]
    }

    /// Physical size along x (Lx = Mx dx).
    pub fn size_x(&self) -> f64 {
        self.width as f64 * self.dx
    }

    /// Physical size along y (Ly = My dy).
    pub fn size_y(&self) -> f64 {
        self.height as f64 * self.dy
    }

    /// (min, max) over finite values; None if there are none.
    pub fn finite_range(&self) -> Option<(f64, f64)> {
        let mut it = self.data.iter().copied().filter(|v| v.is_finite());
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))))
    }

    /// Number of NaN/Inf values.
    pub fn count_nonfinite(&self) -> usize {
        self.data.iter().filter(|v| !v.is_finite()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn validates() {
        assert!(HeightField::new(2, 2, 1e-9, 1e-9, vec![0.0; 4]).is_ok());
        assert!(HeightField::new(2, 2, 1e-9, 1e-9, vec![0.0; 3]).is_err());
        assert!(HeightField::new(0, 2, 1e-9, 1e-9, vec![]).is_err());
        assert!(HeightField::new(1, 1, 0.0, 1e-9, vec![0.0]).is_err());
        let f = HeightField::new(2, 1, 1e-9, 2e-9, vec![1.0, f64::NAN]).unwrap();
        assert_eq!(f.finite_range(), Some((1.0, 1.0)));
        assert_eq!(f.count_nonfinite(), 1);
    }
}
