//! Environment lighting for Sunbeam: an equirectangular radiance map, its
//! lookup under a rotation about the up axis, and importance sampling of
//! directions proportional to radiance (2D CDF with the sin(theta) Jacobian).
//!
//! Conventions (world space, +y up):
//! - polar angle `theta = acos(y)` from +y, azimuth `phi = atan2(z, x)` in
//!   `[0, 2 pi)`, measured from +x towards +z;
//! - texel `(i, j)` (column `i` of `width`, row `j` of `height`, row 0 at the
//!   top) covers `phi` in `2 pi [i, i + 1) / width` and `theta` in
//!   `pi [j, j + 1) / height`;
//! - `rotation_deg = R` turns the environment by `R` degrees about +y in the
//!   sense of increasing `phi`: the radiance arriving from direction `d` is the
//!   map's radiance at `rot_y(-R) d`. An environment rotated by `R` therefore
//!   lights a scene exactly as the unrotated one lights the scene rotated by
//!   `-R` (tested below).
//!
//! Lookup is nearest texel (the map is treated as piecewise constant). The
//! sampler draws a texel with probability proportional to its luminance times
//! its exact solid angle `(2 pi / W)(cos theta_j - cos theta_(j+1))`, then a
//! direction uniformly over the texel's solid angle (uniform in `phi` and in
//! `cos theta`), so `pdf` is the exact density of `sample` and `L / pdf` is
//! constant inside a texel when `L` is proportional to luminance.

pub mod daylight;
pub mod environment;
pub mod hotspots;
pub mod io;
pub mod irradiance;
pub mod prefilter;
pub mod rgb_spectrum;
pub mod sky;

pub use environment::Environment;

use std::f64::consts::PI;

/// Why an environment map was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum EnvError {
    /// The map is not equirectangular: width must equal 2 * height, both > 0.
    NotEquirectangular { width: usize, height: usize },
    /// Pixel count does not match width * height.
    SizeMismatch { expected: usize, got: usize },
    /// A texel is NaN or infinite.
    BadTexel { index: usize },
    /// A channel value below zero by more than lossy-compression noise: more
    /// than [`NEGATIVE_TEXEL_LIMIT`] times the map's mean luminance.
    NegativeTexel {
        index: usize,
        value: f32,
        bound: f64,
    },
    /// Intensity negative, NaN or infinite.
    BadIntensity(f64),
}

impl std::fmt::Display for EnvError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EnvError::NotEquirectangular { width, height } => write!(
                f,
                "not an equirectangular map: {width}x{height}, width must be 2 * height"
            ),
            EnvError::SizeMismatch { expected, got } => {
                write!(f, "expected {expected} pixels, got {got}")
            }
            EnvError::BadTexel { index } => {
                write!(f, "pixel {index} is not finite")
            }
            EnvError::NegativeTexel {
                index,
                value,
                bound,
            } => write!(
                f,
                "pixel {index} has the value {value:.4e}, below -{bound:.4e} ({} times the \
                 map's mean luminance, what lossy compression leaves): not a radiance map",
                NEGATIVE_TEXEL_LIMIT
            ),
            EnvError::BadIntensity(v) => {
                write!(f, "intensity {v} must be finite and >= 0")
            }
        }
    }
}

impl std::error::Error for EnvError {}

/// The unit direction of polar angle `acos(cos_theta)` from +y and azimuth
/// `phi` from +x towards +z (the conventions above).
pub fn direction(cos_theta: f64, phi: f64) -> [f64; 3] {
    let sin_t = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    [sin_t * phi.cos(), cos_theta, sin_t * phi.sin()]
}

/// Rotate `d` about +y by `deg` degrees, in the sense of increasing `phi`
/// (from +x towards +z).
pub fn rot_y(d: [f64; 3], deg: f64) -> [f64; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    [c * d[0] - s * d[2], d[1], s * d[0] + c * d[2]]
}

/// How far below zero a channel value may lie, as a fraction of the map's
/// mean luminance (the plain mean over texels of `0.2126 R + 0.7152 G +
/// 0.0722 B`, negatives counted as 0): lossy OpenEXR compression (DWAA, DWAB,
/// PXR24, B44) leaves a few near-black texels slightly below zero (a public
/// library's HDRIs: up to about a thousand texels of 512 K, down to -0.003;
/// ../shared/data/hdri/night.exr: -0.0033 against a mean luminance of
/// 0.141, a ratio of 0.024, four times below this limit); those are set to 0 and counted
/// ([`Clamped`]). A value further below zero is not radiance: the map is
/// refused, naming the texel.
pub const NEGATIVE_TEXEL_LIMIT: f64 = 0.1;

/// Negative channel values [`EnvMap::new`] set to 0.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Clamped {
    /// Texels with at least one negative channel.
    pub texels: usize,
    /// Negative channel values (a texel counts once per negative channel).
    pub values: usize,
    /// The most negative channel value (0 when none).
    pub min: f32,
    /// The bound that applied: [`NEGATIVE_TEXEL_LIMIT`] times the map's mean
    /// luminance (before `intensity`).
    pub bound: f64,
}

/// An equirectangular RGB radiance map (linear, scaled by `intensity`),
/// rotated by `rotation_deg` about +y, with its importance sampler.
#[derive(Debug, Clone)]
pub struct EnvMap {
    width: usize,
    height: usize,
    rgb: Vec<[f32; 3]>,
    rotation_deg: f64,
    clamped: Clamped,
    /// Marginal CDF over rows (len height + 1), cumulative of row weights.
    marginal: Vec<f64>,
    /// Conditional CDF per row (height rows of width + 1).
    conditional: Vec<f64>,
    /// Sum of all texel weights (luminance * the row's cos theta span).
    total: f64,
}

fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

impl EnvMap {
    /// Build from row-major RGB texels (row 0 = theta near 0, i.e. up).
    pub fn new(
        width: usize,
        height: usize,
        rgb: Vec<[f32; 3]>,
        rotation_deg: f64,
        intensity: f64,
    ) -> Result<EnvMap, EnvError> {
        if height == 0 || width != 2 * height {
            return Err(EnvError::NotEquirectangular { width, height });
        }
        if rgb.len() != width * height {
            return Err(EnvError::SizeMismatch {
                expected: width * height,
                got: rgb.len(),
            });
        }
        if !(intensity.is_finite() && intensity >= 0.0) {
            return Err(EnvError::BadIntensity(intensity));
        }
        let mut rgb = rgb;
        let mut sum = 0.0f64;
        for (index, c) in rgb.iter().enumerate() {
            if c.iter().any(|v| !v.is_finite()) {
                return Err(EnvError::BadTexel { index });
            }
            sum += luminance(c.map(|v| v.max(0.0)));
        }
        let bound = NEGATIVE_TEXEL_LIMIT * sum / rgb.len() as f64;
        let mut clamped = Clamped {
            bound,
            ..Clamped::default()
        };
        for (index, c) in rgb.iter_mut().enumerate() {
            if c.iter().any(|v| *v < 0.0) {
                clamped.texels += 1;
            }
            for v in c.iter_mut() {
                if *v < 0.0 {
                    if -(*v as f64) > bound {
                        return Err(EnvError::NegativeTexel {
                            index,
                            value: *v,
                            bound,
                        });
                    }
                    clamped.values += 1;
                    clamped.min = clamped.min.min(*v);
                    *v = 0.0;
                }
                *v = (*v as f64 * intensity) as f32;
            }
        }
        let mut conditional = vec![0.0; height * (width + 1)];
        let mut marginal = vec![0.0; height + 1];
        for j in 0..height {
            let span = cos_span(j, height);
            let row = &mut conditional[j * (width + 1)..(j + 1) * (width + 1)];
            for i in 0..width {
                row[i + 1] = row[i] + luminance(rgb[j * width + i]) * span;
            }
            marginal[j + 1] = marginal[j] + row[width];
        }
        let total = marginal[height];
        Ok(EnvMap {
            width,
            height,
            rgb,
            rotation_deg,
            clamped,
            marginal,
            conditional,
            total,
        })
    }

    /// A constant environment of radiance `rgb` (any even-sized grid works;
    /// a 2x1 grid keeps it cheap).
    pub fn constant(rgb: [f32; 3]) -> EnvMap {
        EnvMap::new(2, 1, vec![rgb; 2], 0.0, 1.0).expect("valid constant map")
    }

    pub fn width(&self) -> usize {
        self.width
    }

    /// The negative texels set to 0 when the map was built.
    pub fn clamped(&self) -> Clamped {
        self.clamped
    }

    pub fn height(&self) -> usize {
        self.height
    }

    /// Texel indices seen from world direction `d` (unit).
    fn texel(&self, d: [f64; 3]) -> (usize, usize) {
        let l = self.local(d);
        let theta = l[1].clamp(-1.0, 1.0).acos();
        let mut phi = l[2].atan2(l[0]);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        let i = ((phi / (2.0 * PI) * self.width as f64) as usize).min(self.width - 1);
        let j = ((theta / PI * self.height as f64) as usize).min(self.height - 1);
        (i, j)
    }

    /// The map's direction for world direction `d`: `d` turned by
    /// `-rotation_deg` (what [`EnvMap::lookup`] reads, and where
    /// [`EnvMap::prefiltered`]'s chain is read).
    pub fn local(&self, d: [f64; 3]) -> [f64; 3] {
        rot_y(d, -self.rotation_deg)
    }

    /// The map's texels (intensity applied, rotation not), row-major from
    /// the top: what [`EnvMap::lookup`] reads at [`EnvMap::local`] directions.
    pub fn texels(&self) -> &[[f32; 3]] {
        &self.rgb
    }

    /// World direction of map direction `l` (the inverse of [`EnvMap::local`]).
    pub fn world(&self, l: [f64; 3]) -> [f64; 3] {
        rot_y(l, self.rotation_deg)
    }

    /// Radiance arriving from world direction `d` (unit vector).
    pub fn lookup(&self, d: [f64; 3]) -> [f32; 3] {
        let (i, j) = self.texel(d);
        self.rgb[j * self.width + i]
    }

    /// Solid-angle density (1/sr) with which `sample` draws direction `d`.
    pub fn pdf(&self, d: [f64; 3]) -> f64 {
        if self.total <= 0.0 {
            return 0.0;
        }
        let (i, j) = self.texel(d);
        let span = cos_span(j, self.height);
        // The texel's probability over its exact solid angle (2 pi / W) span:
        // the weight carries the same span, so only the luminance remains.
        let texel_prob = luminance(self.rgb[j * self.width + i]) * span / self.total;
        texel_prob / ((2.0 * PI / self.width as f64) * span)
    }

    /// Draw a direction with density `pdf` from two uniform numbers in [0, 1).
    /// Returns `(direction, pdf)`; `None` for a black environment.
    pub fn sample(&self, u1: f64, u2: f64) -> Option<([f64; 3], f64)> {
        if self.total <= 0.0 {
            return None;
        }
        let j = find(&self.marginal, u1 * self.total);
        let row = &self.conditional[j * (self.width + 1)..(j + 1) * (self.width + 1)];
        let i = find(row, u2 * row[self.width]);
        // Position inside the texel: remaining fractions, uniform in (u, v).
        let fu = frac_in(&self.marginal, j, u1 * self.total);
        let fi = frac_in(row, i, u2 * row[self.width]);
        // Uniform in cos(theta) over the row: uniform over its solid angle.
        let c0 = (PI * j as f64 / self.height as f64).cos();
        let c1 = (PI * (j + 1) as f64 / self.height as f64).cos();
        let cos_t = (c0 + fu * (c1 - c0)).clamp(-1.0, 1.0);
        let phi = 2.0 * PI * (i as f64 + fi) / self.width as f64;
        let local = direction(cos_t, phi);
        let d = rot_y(local, self.rotation_deg);
        Some((d, self.pdf(d)))
    }
}

/// `cos(theta_j) - cos(theta_(j+1))` of row `j` of `height` (its solid angle is
/// this times `2 pi / width`).
fn cos_span(j: usize, height: usize) -> f64 {
    (PI * j as f64 / height as f64).cos() - (PI * (j + 1) as f64 / height as f64).cos()
}

/// Largest index k with cdf[k] <= x and cdf[k+1] > x (skipping empty bins).
fn find(cdf: &[f64], x: f64) -> usize {
    let n = cdf.len() - 1;
    let k = cdf.partition_point(|&c| c <= x);
    let mut k = k.saturating_sub(1).min(n - 1);
    while k + 1 < n && cdf[k + 1] <= cdf[k] {
        k += 1;
    }
    while k > 0 && cdf[k + 1] <= cdf[k] {
        k -= 1;
    }
    k
}

fn frac_in(cdf: &[f64], k: usize, x: f64) -> f64 {
    let w = cdf[k + 1] - cdf[k];
    if w > 0.0 {
        ((x - cdf[k]) / w).clamp(0.0, 1.0 - 1e-12)
    } else {
        0.5
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    fn norm(d: [f64; 3]) -> [f64; 3] {
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        [d[0] / n, d[1] / n, d[2] / n]
    }

    fn test_map(rot: f64) -> EnvMap {
        let (w, h) = (16, 8);
        let rgb = (0..w * h)
            .map(|k| {
                let (i, j) = (k % w, k / w);
                [(i + 1) as f32, (j + 1) as f32 * 0.5, ((i * j) % 5) as f32]
            })
            .collect();
        EnvMap::new(w, h, rgb, rot, 2.0).unwrap()
    }

    /// Compression noise below zero is set to 0, counted, and leaves the
    /// sampler's density exact for the map it keeps.
    #[test]
    fn sets_small_negatives_to_zero() {
        let mut px = vec![[2.0f32; 3]; 32];
        px[7] = [-0.003, 0.5, -1e-6];
        px[20][1] = -0.001;
        let m = EnvMap::new(8, 4, px, 0.0, 3.0).unwrap();
        // The mean luminance (negatives as 0): 30 white texels of 2, one of
        // G = 0.5 alone, one of R = B = 2.
        let mean = (30.0 * 2.0 + 0.7152 * 0.5 + (0.2126 + 0.0722) * 2.0) / 32.0;
        let c = m.clamped();
        assert_eq!((c.texels, c.values, c.min), (2, 3, -0.003));
        assert!((c.bound - 0.1 * mean).abs() < 1e-12, "{c:?}");
        // Texel 7 of the 8 x 4 map: column 7, row 0.
        let theta = PI * 0.5 / 4.0;
        let phi = 2.0 * PI * 7.5 / 8.0;
        assert_eq!(m.lookup(direction(theta.cos(), phi)), [0.0, 1.5, 0.0]);
        assert_eq!(m.clamped(), m.clone().clamped());
        let clean = EnvMap::new(8, 4, vec![[2.0f32; 3]; 32], 0.0, 3.0).unwrap();
        assert_eq!(clean.clamped().texels + clean.clamped().values, 0);
    }

    #[test]
    fn refuses_bad_maps() {
        assert!(matches!(
            EnvMap::new(3, 2, vec![[1.0; 3]; 6], 0.0, 1.0),
            Err(EnvError::NotEquirectangular { .. })
        ));
        assert!(matches!(
            EnvMap::new(4, 2, vec![[1.0; 3]; 8], 0.0, -1.0),
            Err(EnvError::BadIntensity(_))
        ));
        assert!(matches!(
            EnvMap::new(4, 2, vec![[1.0; 3]; 8], 0.0, f64::NAN),
            Err(EnvError::BadIntensity(_))
        ));
        let mut px = vec![[1.0; 3]; 8];
        px[3][1] = f32::NAN;
        assert_eq!(
            EnvMap::new(4, 2, px, 0.0, 1.0).unwrap_err(),
            EnvError::BadTexel { index: 3 }
        );
        let mut px = vec![[1.0; 3]; 8];
        px[5][2] = f32::INFINITY;
        assert_eq!(
            EnvMap::new(4, 2, px, 0.0, 1.0).unwrap_err(),
            EnvError::BadTexel { index: 5 }
        );
        // Negatives past a tenth of the mean luminance (7 white texels and
        // one of G = 1 alone: mean (7 + 0.7152) / 8 = 0.9644) name the texel;
        // one just inside is set to 0.
        let mean = (7.0 + 0.7152) / 8.0;
        let mut px = vec![[1.0; 3]; 8];
        px[2][0] = -0.1 * mean as f32 * 1.01;
        px[2][2] = -0.5;
        match EnvMap::new(4, 2, px, 0.0, 1.0).unwrap_err() {
            EnvError::NegativeTexel { index, .. } => assert_eq!(index, 2),
            e => panic!("{e}"),
        }
        let mut px = vec![[1.0; 3]; 8];
        px[2][0] = -0.1 * mean as f32 * 0.99;
        px[2][2] = 0.0;
        assert_eq!(EnvMap::new(4, 2, px, 0.0, 1.0).unwrap().clamped().values, 1);
    }

    /// Closed form: a constant map is sampled with density 1 / (4 pi)
    /// everywhere (the sin(theta) Jacobian makes it uniform on the sphere).
    #[test]
    fn constant_map_pdf_is_uniform_on_the_sphere() {
        let (w, h) = (64, 32);
        let m = EnvMap::new(w, h, vec![[1.0; 3]; w * h], 0.0, 1.0).unwrap();
        let mut s = 7;
        for _ in 0..1000 {
            let d = norm([lcg(&mut s) - 0.5, lcg(&mut s) - 0.5, lcg(&mut s) - 0.5]);
            let p = m.pdf(d);
            assert!((p * 4.0 * PI - 1.0).abs() < 1e-12, "pdf {p}");
        }
    }

    /// Monte Carlo estimate of the map's total power (integral of luminance
    /// over the sphere) with the sampler matches the texel sum.
    #[test]
    fn importance_sampling_is_unbiased() {
        let m = test_map(30.0);
        let truth: f64 = (0..m.height)
            .flat_map(|j| (0..m.width).map(move |i| (i, j)))
            .map(|(i, j)| {
                luminance(m.rgb[j * m.width + i])
                    * cos_span(j, m.height)
                    * (2.0 * PI / m.width as f64)
            })
            .sum();
        let mut s = 11;
        let n = 20000;
        let mut est = 0.0;
        for _ in 0..n {
            let (d, p) = m.sample(lcg(&mut s), lcg(&mut s)).unwrap();
            assert!((d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - 1.0).abs() < 1e-9);
            est += luminance(m.lookup(d)) / p;
        }
        est /= n as f64;
        // Luminance proportional to pdf: every sample has the same weight.
        assert!((est / truth - 1.0).abs() < 1e-9, "{est} vs {truth}");
    }

    /// An environment rotated by R lights direction d as the unrotated one
    /// lights the scene rotated by -R.
    #[test]
    fn rotation_equals_scene_rotated_back() {
        let r = 75.0;
        let rotated = test_map(r);
        let plain = test_map(0.0);
        let mut s = 3;
        for _ in 0..500 {
            let d = norm([lcg(&mut s) - 0.5, lcg(&mut s) - 0.5, lcg(&mut s) - 0.5]);
            assert_eq!(rotated.lookup(d), plain.lookup(rot_y(d, -r)));
        }
        // A map whose only bright column covers phi in [0, 45) deg on the
        // horizon shows it, after rotating by +90 deg, at phi in [90, 135).
        let (w, h) = (8, 4);
        let mut px = vec![[0.0; 3]; w * h];
        px[w] = [1.0; 3];
        px[2 * w] = [1.0; 3];
        let m = EnvMap::new(w, h, px, 90.0, 1.0).unwrap();
        let at = |deg: f64| {
            let (s, c) = deg.to_radians().sin_cos();
            [c, 0.0, s]
        };
        assert_eq!(m.lookup(at(110.0)), [1.0; 3]);
        assert_eq!(m.lookup(at(20.0)), [0.0; 3]);
        assert_eq!(m.lookup(at(-70.0)), [0.0; 3]);
    }
}
