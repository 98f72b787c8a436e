//! Colour-difference statistics of an image comparison (PHYSICS.md 4:
//! CIEDE2000, mean, 99th percentile and max), shared by the display-value
//! comparison (`image::compare`) and the linear one (`linear::compare_linear`).

/// CIEDE2000 statistics between two images of the same size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColourDiff {
    pub mean: f64,
    pub p99: f64,
    pub max: f64,
    pub pixels: usize,
}

impl std::fmt::Display for ColourDiff {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "CIEDE2000 mean {:.3} p99 {:.3} max {:.3} over {} px",
            self.mean, self.p99, self.max, self.pixels
        )
    }
}

/// Mean, 99th percentile and max of a list of differences.
pub fn stats(d: &mut [f64]) -> ColourDiff {
    let n = d.len();
    if n == 0 {
        return ColourDiff {
            mean: 0.0,
            p99: 0.0,
            max: 0.0,
            pixels: 0,
        };
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    d.sort_by(|x, y| x.total_cmp(y));
    let p99 = d[((n as f64 * 0.99).ceil() as usize).clamp(1, n) - 1];
    ColourDiff {
        mean,
        p99,
        max: d[n - 1],
        pixels: n,
    }
}
