//! The pack manifest: everything a reader needs to rebuild `c_n(t)`, `f` and `R`
//! from the stored terms. Documented field by field in docs/PACK_FORMAT.md.

use serde::{Deserialize, Serialize};
use sunbeam_common::{Error, Result};

/// Value of [`Manifest::format`].
pub const FORMAT_NAME: &str = "sunbeam-pack";
/// Value of [`Manifest::version`] written by this crate; readers accept this one only.
pub const FORMAT_VERSION: u32 = 1;
/// KTX2 key/value key and EXR header attribute holding the manifest JSON.
pub const MANIFEST_KEY: &str = "sunbeam.manifest";

/// What lies beyond the measured patch (PHYSICS.md 2): the ground truth's enum.
pub use sunbeam_optics::Model;

/// The basis of the height expansion (PHYSICS.md 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Basis {
    /// `B_n(s) = T_n(s)`, `c_n(t) = i^n eps_n J_n(t)`. Default.
    Chebyshev,
    /// `B_n(s) = s^n`, `c_n(t) = (i t)^n / n!`.
    Taylor,
}

/// Storage precision of the texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    F32,
    F16,
}

/// The interpolation kernel (one per axis, separable).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Kernel {
    /// "kaiser-bessel" (window model) or "gaussian" (tiled model).
    #[serde(rename = "type")]
    pub kind: String,
    /// Taps per axis W (even): the texels `k0 .. k0+W-1` with `k0 = floor(kappa) - W/2 + 1`.
    pub taps: usize,
    /// Kaiser-Bessel shape parameter beta (window model; 0 for the tiled model).
    pub beta: f64,
    /// Gaussian sigma in bins per axis [x, y] (tiled model; 0 for the window model).
    pub sigma_bins: [f64; 2],
}

/// Patch geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Patch {
    /// Columns Mx.
    pub width: usize,
    /// Rows My.
    pub height: usize,
    pub dx_m: f64,
    pub dy_m: f64,
    /// Lx = Mx dx.
    pub lx_m: f64,
    /// Ly = My dy.
    pub ly_m: f64,
}

/// The stored crop of the (padded) spectrum.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Crop {
    /// Bins each side along x: texel column `tx` holds bin `kx = tx - kx_half`.
    pub kx: i64,
    /// Bins each side along y: texel row `ty` holds bin `ky = ty - ky_half`.
    pub ky: i64,
    /// Texture width = 2 kx + 1.
    pub width: usize,
    /// Texture height = 2 ky + 1.
    pub height: usize,
}

/// What the term count rests on and what it guarantees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorInfo {
    /// The requested bound on max |dR| (--max-error), or None when --terms fixed the count.
    pub tolerance: Option<f64>,
    /// A-priori bound on max |dR| from truncating the series at `terms`, over |t| <= t_max.
    pub series_bound: f64,
    /// Estimate of the float32 rounding error of summing the series in a shader
    /// (largest partial sum magnitude times 2^-24, times 2 for R).
    pub f32_rounding_estimate: f64,
    /// True when the user fixed the term count (--terms).
    pub terms_fixed: bool,
}

/// Where the height field came from.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Source {
    /// File name only (no folders), so packs stay byte-identical across checkouts.
    pub file: String,
    pub format: String,
    pub channel: String,
    pub processing: Vec<String>,
}

/// The manifest: JSON in the KTX2 key/value data (`sunbeam.manifest`), in an EXR
/// header attribute of the same name, and optionally beside the pack.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// Always "sunbeam-pack".
    pub format: String,
    /// Format version (1).
    pub version: u32,
    /// Tool name and version that wrote the pack, e.g. "sunbeam-pack 0.1.0".
    pub generator: String,
    pub model: Model,
    pub basis: Basis,
    /// Number of stored terms N (layers); term n = 0 .. N-1.
    pub terms: usize,
    pub precision: Precision,
    pub patch: Patch,
    /// Height centre hc = (min + max) / 2, metres.
    pub height_centre_m: f64,
    /// Height half range H = (max - min) / 2, metres (0 for a flat field).
    pub height_half_range_m: f64,
    /// Wavelength range the pack was built for, metres.
    pub lambda_min_m: f64,
    pub lambda_max_m: f64,
    /// Largest |w| the pack was built for.
    pub max_w: f64,
    /// Largest |t| = 2 pi max_w H / lambda_min.
    pub t_max: f64,
    /// Coherence length, metres.
    pub coherence_m: f64,
    /// Window model: sigma of the Gaussian coherence window in metres, min(coherence/4, Lmin/6). 0 for tiled.
    pub window_sigma_m: f64,
    /// Tiled model: sigma_f = 1/(2 pi coherence/4) in cycles per metre. 0 for window.
    pub sigma_f_per_m: f64,
    /// Zero padding factor Z (2 for the window model, 1 for the tiled model).
    pub padding: usize,
    /// Padded DFT size [Nx, Ny] = [Z Mx, Z My].
    pub grid: [usize; 2],
    /// Bins per (cycle per metre) [Z Lx, Z Ly]: kappa = f * bin_scale.
    pub bin_scale_m: [f64; 2],
    /// Largest reachable |fx|, |fy| in cycles per metre the crop covers.
    pub freq_limit_per_m: [f64; 2],
    pub crop: Crop,
    pub kernel: Kernel,
    /// "sum_g" (window) or "mx_my" (tiled): what the terms were divided by.
    pub normalisation: String,
    /// Its value (sum of the window weights, or Mx My).
    pub normalisation_value: f64,
    pub error: ErrorInfo,
    pub source: Source,
    /// Notes from the build (e.g. what a --scene bound skipped).
    #[serde(default)]
    pub notes: Vec<String>,
    /// rms of the height field's slopes `[rms dh/dx, rms dh/dy]` (dimensionless,
    /// weighted like the terms: the coherence window, or uniform for the tiled
    /// model): what a scene's `"masking": "smith"` uses (sunbeam_optics::masking).
    /// Absent in packs written before it existed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_slope: Option<[f64; 2]>,
}

impl Manifest {
    /// The pack's coherent area `A` (m^2), the factor of the BRDF for extended
    /// light (docs/LIGHTING.md "The factor"): window `(sum g)^2 / sum g^2 dx dy`,
    /// tiled `1 / (2 pi sigma_f^2)`. One definition for the reference and the
    /// player's maps.
    pub fn coherent_area_m2(&self) -> f64 {
        match self.model {
            Model::Window => sunbeam_optics::truth::window_coherent_area_m2(
                self.patch.width,
                self.patch.height,
                self.patch.dx_m,
                self.patch.dy_m,
                self.window_sigma_m,
            ),
            Model::Tiled => sunbeam_optics::truth::tiled_coherent_area_m2(self.sigma_f_per_m),
        }
    }

    /// Serialise as compact JSON (deterministic field order).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("manifest serialises")
    }

    /// Serialise as indented JSON (sidecar files).
    pub fn to_json_pretty(&self) -> String {
        let mut s = serde_json::to_string_pretty(self).expect("manifest serialises");
        s.push('\n');
        s
    }

    /// Parse and validate.
    pub fn from_json(text: &str) -> Result<Manifest> {
        let m: Manifest = serde_json::from_str(text)
            .map_err(|e| Error::input(format!("invalid manifest: {e}")))?;
        m.validate()?;
        Ok(m)
    }

    /// Internal consistency checks a reader relies on (no panics later).
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str| Err(Error::input(format!("invalid manifest: {what}")));
        if self.format != FORMAT_NAME {
            return bad(&format!(
                "format is '{}', expected '{FORMAT_NAME}'",
                self.format
            ));
        }
        if self.version != FORMAT_VERSION {
            return bad(&format!(
                "version {} is not supported (this reader knows {FORMAT_VERSION})",
                self.version
            ));
        }
        if self.terms == 0 || self.terms > 4096 {
            return bad("terms must be 1..4096");
        }
        if let Some(s) = self.rms_slope {
            if !s.iter().all(|v| v.is_finite() && *v >= 0.0) {
                return bad("rms_slope must be two finite values >= 0");
            }
        }
        let c = &self.crop;
        if c.kx < 0 || c.ky < 0 || c.kx > 1 << 20 || c.ky > 1 << 20 {
            return bad("crop.kx/crop.ky out of range");
        }
        if c.width as i64 != 2 * c.kx + 1 || c.height as i64 != 2 * c.ky + 1 {
            return bad("crop.width/height must be 2 kx + 1 / 2 ky + 1");
        }
        if self.kernel.taps == 0 || self.kernel.taps & 1 == 1 || self.kernel.taps > 64 {
            return bad("kernel.taps must be even, 2..64");
        }
        match (self.model, self.kernel.kind.as_str()) {
            (Model::Window, "kaiser-bessel") => {
                if !(self.kernel.beta.is_finite()
                    && self.kernel.beta > 0.0
                    && self.kernel.beta < 100.0)
                {
                    return bad("kernel.beta must be in (0, 100)");
                }
            }
            (Model::Tiled, "gaussian") => {
                if !self
                    .kernel
                    .sigma_bins
                    .iter()
                    .all(|s| s.is_finite() && *s > 0.0)
                {
                    return bad("kernel.sigma_bins must be positive");
                }
            }
            _ => {
                return bad(
                    "kernel.type must be kaiser-bessel (window model) or gaussian (tiled model)",
                )
            }
        }
        let finite_pos = |v: f64| v.is_finite() && v > 0.0;
        if !(finite_pos(self.lambda_min_m)
            && finite_pos(self.lambda_max_m)
            && self.lambda_max_m >= self.lambda_min_m)
        {
            return bad("lambda range");
        }
        if !(finite_pos(self.bin_scale_m[0]) && finite_pos(self.bin_scale_m[1])) {
            return bad("bin_scale_m must be positive");
        }
        if !(self.height_half_range_m.is_finite()
            && self.height_half_range_m >= 0.0
            && self.height_centre_m.is_finite())
        {
            return bad("height centre / half range");
        }
        if self.padding == 0 || self.padding > 16 {
            return bad("padding must be 1..16");
        }
        Ok(())
    }

    /// Texels per layer.
    pub fn layer_texels(&self) -> usize {
        self.crop.width * self.crop.height
    }
}
