//! A pack in memory and the CPU evaluator (the player's math, docs/PACK_FORMAT.md).

use crate::kernel;
use crate::manifest::{Manifest, Model};
use crate::series;
use sunbeam_common::{Error, Result};

/// A diffraction term pack: the manifest plus the complex terms.
#[derive(Debug, Clone, PartialEq)]
pub struct Pack {
    pub manifest: Manifest,
    /// Interleaved (re, im) float32: texel (n, ty, tx) at `2 * ((n * height + ty) * width + tx)`.
    pub terms: Vec<f32>,
}

/// Taps of one axis: texel index (None outside the crop) and weight.
struct Taps {
    idx: [i64; 64],
    w: [f64; 64],
    /// `d w / d kappa` (window model only).
    dw: [f64; 64],
    n: usize,
}

impl Pack {
    /// Checks shared by the readers: sizes and finiteness.
    /// A pack known by its manifest only (`Pack::read_manifest`), for a reader
    /// that needs no term data (the player's default mode reads a response map
    /// built from it). Its evaluators must not be called: [`Pack::has_terms`].
    pub fn manifest_only(manifest: Manifest) -> Pack {
        Pack {
            manifest,
            terms: Vec::new(),
        }
    }

    /// False for [`Pack::manifest_only`].
    pub fn has_terms(&self) -> bool {
        !self.terms.is_empty()
    }

    pub fn new(manifest: Manifest, terms: Vec<f32>) -> Result<Pack> {
        manifest.validate()?;
        let want = manifest
            .terms
            .checked_mul(manifest.layer_texels())
            .and_then(|v| v.checked_mul(2));
        if want != Some(terms.len()) {
            return Err(Error::input(format!(
                "pack holds {} values, manifest says {} terms of {}x{}",
                terms.len() / 2,
                manifest.terms,
                manifest.crop.width,
                manifest.crop.height
            )));
        }
        if terms.iter().any(|v| !v.is_finite()) {
            return Err(Error::input("pack holds NaN or Inf values"));
        }
        Ok(Pack { manifest, terms })
    }

    /// Term `n` at texel (tx, ty) as (re, im).
    #[inline]
    pub fn texel(&self, n: usize, tx: usize, ty: usize) -> [f32; 2] {
        let m = &self.manifest;
        let i = 2 * ((n * m.crop.height + ty) * m.crop.width + tx);
        [self.terms[i], self.terms[i + 1]]
    }

    /// `t = (2 pi / lambda) w H`.
    pub fn t(&self, w: f64, lambda_m: f64) -> f64 {
        2.0 * std::f64::consts::PI / lambda_m * w * self.manifest.height_half_range_m
    }

    fn taps(&self, kappa: f64, k_half: i64, axis: usize) -> Taps {
        let m = &self.manifest;
        let taps = m.kernel.taps;
        let k0 = kernel::first_tap(kappa, taps);
        let mut t = Taps {
            idx: [0; 64],
            w: [0.0; 64],
            dw: [0.0; 64],
            n: 0,
        };
        for j in 0..taps {
            let k = k0 + j as i64;
            if k < -k_half || k > k_half {
                continue; // outside the crop: contributes 0
            }
            let d = kappa - k as f64;
            let wt = match m.model {
                Model::Window => kernel::kb(d, taps, m.kernel.beta),
                Model::Tiled => kernel::gauss(d, m.kernel.sigma_bins[axis]),
            };
            t.idx[t.n] = k + k_half;
            t.w[t.n] = wt;
            if m.model == Model::Window {
                t.dw[t.n] = kernel::kb_derivative(d, taps, m.kernel.beta);
            }
            t.n += 1;
        }
        t
    }

    /// The series' coefficients and both axes' taps at a point (None for a
    /// non-finite point or one far outside any crop): what both evaluators need.
    fn point(&self, u: f64, v: f64, w: f64, lambda_m: f64) -> Option<(Vec<[f64; 2]>, Taps, Taps)> {
        let m = &self.manifest;
        if !(u.is_finite()
            && v.is_finite()
            && w.is_finite()
            && lambda_m.is_finite()
            && lambda_m > 0.0)
        {
            return None;
        }
        let kappa_x = -u / lambda_m * m.bin_scale_m[0];
        let kappa_y = -v / lambda_m * m.bin_scale_m[1];
        if kappa_x.abs() > 1e9 || kappa_y.abs() > 1e9 {
            return None;
        }
        let c = series::coefficients_f64(m.basis, self.t(w, lambda_m), m.terms);
        Some((
            c,
            self.taps(kappa_x, m.crop.kx, 0),
            self.taps(kappa_y, m.crop.ky, 1),
        ))
    }

    /// Relative reflectance R at `(u, v, w) = -wi - wr` and wavelength `lambda_m`
    /// (PHYSICS.md 2), with the interpolation the player uses.
    pub fn reflectance(&self, u: f64, v: f64, w: f64, lambda_m: f64) -> f64 {
        let m = &self.manifest;
        let Some((c, tx, ty)) = self.point(u, v, w, lambda_m) else {
            return 0.0;
        };
        let layer = m.layer_texels();
        let mut amp = [0.0f64; 2];
        let mut power = 0.0f64;
        for jy in 0..ty.n {
            for jx in 0..tx.n {
                let base = 2 * (ty.idx[jy] as usize * m.crop.width + tx.idx[jx] as usize);
                // Sum the terms as complex numbers at this tap.
                let mut a = [0.0f64; 2];
                for (n, cn) in c.iter().enumerate() {
                    let i = base + 2 * n * layer;
                    let (re, im) = (self.terms[i] as f64, self.terms[i + 1] as f64);
                    a[0] += cn[0] * re - cn[1] * im;
                    a[1] += cn[0] * im + cn[1] * re;
                }
                let wgt = tx.w[jx] * ty.w[jy];
                match m.model {
                    Model::Window => {
                        amp[0] += wgt * a[0];
                        amp[1] += wgt * a[1];
                    }
                    Model::Tiled => power += wgt * (a[0] * a[0] + a[1] * a[1]),
                }
            }
        }
        match m.model {
            Model::Window => amp[0] * amp[0] + amp[1] * amp[1],
            Model::Tiled => power,
        }
    }

    /// The reflectance that shading uses (PHYSICS.md 2b): for the window
    /// model `R_U` of [`sunbeam_optics::grazing::window_reflectance`], from the
    /// amplitude and its derivatives along `u` and `v` through the derivative
    /// of the pack's own interpolation kernel ([`kernel::kb_derivative`]); the
    /// tiled model keeps Beckmann's factor: [`Pack::reflectance`].
    pub fn shading_reflectance(&self, u: f64, v: f64, w: f64, lambda_m: f64) -> f64 {
        let m = &self.manifest;
        if m.model == Model::Tiled || m.window_sigma_m <= 0.0 {
            return self.reflectance(u, v, w, lambda_m);
        }
        let Some((c, tx, ty)) = self.point(u, v, w, lambda_m) else {
            return 0.0;
        };
        let layer = m.layer_texels();
        // amplitude, d/dkappa_x, d/dkappa_y
        let mut acc = [[0.0f64; 2]; 3];
        for jy in 0..ty.n {
            for jx in 0..tx.n {
                let base = 2 * (ty.idx[jy] as usize * m.crop.width + tx.idx[jx] as usize);
                let mut a = [0.0f64; 2];
                for (n, cn) in c.iter().enumerate() {
                    let i = base + 2 * n * layer;
                    let (re, im) = (self.terms[i] as f64, self.terms[i + 1] as f64);
                    a[0] += cn[0] * re - cn[1] * im;
                    a[1] += cn[0] * im + cn[1] * re;
                }
                let wts = [
                    tx.w[jx] * ty.w[jy],
                    tx.dw[jx] * ty.w[jy],
                    tx.w[jx] * ty.dw[jy],
                ];
                for (s, wt) in acc.iter_mut().zip(wts) {
                    s[0] += wt * a[0];
                    s[1] += wt * a[1];
                }
            }
        }
        // d/du = (d kappa_x / du) d/dkappa_x = -(bin_scale_x / lambda) d/dkappa_x
        let sx = -m.bin_scale_m[0] / lambda_m;
        let sy = -m.bin_scale_m[1] / lambda_m;
        let k = 2.0 * std::f64::consts::PI / lambda_m;
        let sg = m.window_sigma_m;
        sunbeam_optics::grazing::window_reflectance(
            [u, v, w],
            acc[0],
            acc[1].map(|d| d * sx),
            acc[2].map(|d| d * sy),
            k,
            [sg, sg],
        )
    }

    /// XYZ for local directions `wi` (to the light) and `wr` (to the viewer),
    /// PHYSICS.md 2: `G(wi, wr) * sum_i R(lambda_i) S(lambda_i) cmf(lambda_i) / sum_i S(lambda_i) ybar(lambda_i)`
    /// over `lambda_samples` midpoint samples of the pack's wavelength range
    /// (so a flat mirror at normal incidence gives Y = 1 exactly: the relative
    /// normalisation of plots and of the comparison with the truth).
    pub fn colour_xyz(
        &self,
        wi_local: [f64; 3],
        wr_local: [f64; 3],
        lambda_samples: usize,
    ) -> [f64; 3] {
        use sunbeam_optics::{cie, gain};
        let m = &self.manifest;
        let g = gain::g(wi_local, wr_local, gain::Material::RELATIVE);
        if !(g.is_finite() && g > 0.0) || lambda_samples == 0 {
            return [0.0; 3];
        }
        let (u, v, w) = (
            -wi_local[0] - wr_local[0],
            -wi_local[1] - wr_local[1],
            -wi_local[2] - wr_local[2],
        );
        let (l0, l1) = (m.lambda_min_m, m.lambda_max_m);
        let dl = (l1 - l0) / lambda_samples as f64;
        let mut xyz = [0.0; 3];
        let mut norm = 0.0;
        for i in 0..lambda_samples {
            let l = l0 + (i as f64 + 0.5) * dl;
            let s = cie::d65_at(l);
            let c = cie::cmf_at(l);
            let r = self.reflectance(u, v, w, l);
            for k in 0..3 {
                xyz[k] += r * s * c[k];
            }
            norm += s * c[1];
        }
        if norm <= 0.0 {
            return [0.0; 3];
        }
        xyz.map(|c| c * g / norm)
    }

    /// The evaluator in float32 arithmetic only, step for step as docs/PACK_FORMAT.md
    /// writes it (and as a WGSL port computes it): Miller's recurrence in f32, the
    /// Kaiser-Bessel weight with I0 by its power series in f32, complex sums per tap.
    /// For testing shader ports; [`Pack::reflectance`] is the float64 reference.
    pub fn reflectance_f32(&self, u: f32, v: f32, w: f32, lambda_m: f32) -> f32 {
        let m = &self.manifest;
        let n = m.terms;
        let t = 2.0 * std::f32::consts::PI / lambda_m * w * m.height_half_range_m as f32;
        let c = series::coefficients_f32(m.basis, t, n);
        let kappa = [
            -u / lambda_m * m.bin_scale_m[0] as f32,
            -v / lambda_m * m.bin_scale_m[1] as f32,
        ];
        if !(kappa[0].is_finite() && kappa[1].is_finite())
            || kappa[0].abs() > 1e7
            || kappa[1].abs() > 1e7
        {
            return 0.0;
        }
        let taps = m.kernel.taps as i32;
        let beta = m.kernel.beta as f32;
        let kb_scale = beta / (taps as f32 * beta.sinh());
        let weight = |d: f32, axis: usize| -> f32 {
            match m.model {
                Model::Window => {
                    let r = 2.0 * d / taps as f32;
                    if r.abs() >= 1.0 {
                        return 0.0;
                    }
                    let z = beta * (1.0 - r * r).sqrt();
                    let q = z * z / 4.0;
                    let (mut term, mut sum, mut k) = (1.0f32, 1.0f32, 1.0f32);
                    while term > 1e-7 * sum && k < 100.0 {
                        term *= q / (k * k);
                        sum += term;
                        k += 1.0;
                    }
                    kb_scale * sum
                }
                Model::Tiled => {
                    let sg = m.kernel.sigma_bins[axis] as f32;
                    (-d * d / (2.0 * sg * sg)).exp()
                }
            }
        };
        let (kx, ky) = (m.crop.kx as i32, m.crop.ky as i32);
        let k0 = [
            kappa[0].floor() as i32 - taps / 2 + 1,
            kappa[1].floor() as i32 - taps / 2 + 1,
        ];
        let layer = m.layer_texels();
        let (mut are, mut aim, mut power) = (0.0f32, 0.0f32, 0.0f32);
        for jy in 0..taps {
            let by = k0[1] + jy;
            if by < -ky || by > ky {
                continue;
            }
            let wy = weight(kappa[1] - by as f32, 1);
            for jx in 0..taps {
                let bx = k0[0] + jx;
                if bx < -kx || bx > kx {
                    continue;
                }
                let wt = wy * weight(kappa[0] - bx as f32, 0);
                let base = 2 * ((by + ky) as usize * m.crop.width + (bx + kx) as usize);
                let (mut re, mut im) = (0.0f32, 0.0f32);
                for (k, ck) in c.iter().enumerate() {
                    let i = base + 2 * k * layer;
                    let (dr, di) = (self.terms[i], self.terms[i + 1]);
                    re += ck[0] * dr - ck[1] * di;
                    im += ck[0] * di + ck[1] * dr;
                }
                match m.model {
                    Model::Window => {
                        are += wt * re;
                        aim += wt * im;
                    }
                    Model::Tiled => power += wt * (re * re + im * im),
                }
            }
        }
        match m.model {
            Model::Window => are * are + aim * aim,
            Model::Tiled => power,
        }
    }
}
