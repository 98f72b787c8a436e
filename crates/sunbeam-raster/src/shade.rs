//! Per-pixel shading: the reference definition of what the player computes
//! (docs/PLAY.md "Shading"). For each light (directional, D65, `intensity`):
//!
//! ```text
//! n = normalize(N), t = normalize(T - n (n.T)), b = n x t
//! wi = light direction, wr = normalize(eye - p); local d' = (d.t, d.b, d.n)
//! diffraction XYZ = G(wi', wr') * sum_l R_U(u, v, w, l) weight(l)   (0 unless wi'.z > 0 and wr'.z > 0)
//! (l every 1 to 5 nm by where R varies: [`wavelength_step_nm`])
//! rgb += intensity * ( dw * base * max(wi'.z, 0) (1 - F(th_i)) + (1 - dw) * M_srgb XYZ )
//! ```
//! with `(u, v, w) = -wi' - wr'`, `G` the mesh's skin's (absolute by default,
//! `sunbeam_optics::gain`, with its energy bound: [`crate::bounded`]) times its masking, `R_U` the reflectance with the
//! window's exact grazing term (`Pack::shading_reflectance`, PHYSICS.md 2b),
//! `dw` the mesh's diffuse weight (1 and no `(1 - F)` for a mesh without a
//! pack: base colour only). The background is its linear colour, or under
//! `"background": "environment"` the environment's radiance along the
//! sample's view ray (`Environment::rgb`: rotation and intensity applied).
//! Display value = sRGB OETF(tone curve(2^exposure * rgb)).

use crate::raster::Fragment;
use crate::spectral::Samples;
use crate::{Options, Prepared};
use sunbeam_optics::cie;
use sunbeam_optics::colour::{self, ToneMap};
use sunbeam_scene::Background;

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
pub(crate) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
pub(crate) fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(a, a).sqrt();
    (l > 1e-20 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
}

/// The shading frame at a fragment: (t, b, n), or None when the normal is degenerate.
pub fn frame(normal: [f64; 3], tangent: [f64; 3]) -> Option<([f64; 3], [f64; 3], [f64; 3])> {
    let n = normalize(normal)?;
    let d = dot(n, tangent);
    let t = normalize([
        tangent[0] - d * n[0],
        tangent[1] - d * n[1],
        tangent[2] - d * n[2],
    ])
    .or_else(|| {
        // no usable orientation: any perpendicular (the mesh loader never gives this)
        let a = if n[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        };
        let d = dot(n, a);
        normalize([a[0] - d * n[0], a[1] - d * n[1], a[2] - d * n[2]])
    })?;
    Some((t, cross(n, t), n))
}

/// The reference's wavelength step at `(u, v, w)` (docs/EVAL.md "Wavelength
/// step"): the largest of 5, 4, 2 and 1 nm
/// over which R moves by at most half a cycle of its fastest variation at the
/// shortest wavelength. R is the power of an amplitude sampled on the pack's
/// frequency lattice at `kappa = u L / lambda` bins, whose window is one patch
/// wide, so R varies at most once per bin, and of `exp(i t h)` with `|h| <= 1`,
/// `t = 2 pi |w| H / lambda`, so at most once per `pi` of `t`. A step `dl`
/// moves them by `kappa dl / lambda` bins and `t dl / lambda`: half a cycle at
/// 380 nm is `dl = lmin^2 / (2 (max(|u| Lx, |v| Ly) + 2 |w| H))`. Real-size
/// packs (20 um and up) keep the 1 nm sum at large `|u|`; a 5 um patch's
/// first orders get 5 nm. The tiled model keeps 1 nm everywhere: its orders
/// are Gaussians as narrow as the coherence length is long (0.01 bins for
/// a 5 um patch at 65 um), far below 1 nm (5 nm moved one by CIEDE2000
/// 0.059).
pub fn wavelength_step_nm(m: &sunbeam_pack::manifest::Manifest, u: f64, v: f64, w: f64) -> u32 {
    if m.model != sunbeam_pack::manifest::Model::Window {
        return 1;
    }
    let lmin = cie::DEFAULT_RANGE_NM.0 as f64 * 1e-9;
    let len = (u.abs() * m.bin_scale_m[0]).max(v.abs() * m.bin_scale_m[1])
        + 2.0 * w.abs() * m.height_half_range_m;
    let step_nm = 0.5 * lmin * lmin / len / 1e-9;
    if !step_nm.is_finite() {
        return if len > 0.0 { 1 } else { WAVELENGTH_STEPS_NM[0] };
    }
    WAVELENGTH_STEPS_NM
        .into_iter()
        .find(|&s| s as f64 <= step_nm)
        .unwrap_or(1)
}

/// The steps [`wavelength_step_nm`] picks from, largest first: each divides
/// the 400 nm of 380..=780, so every step sums rows that include both ends;
/// none above the CIE's own 5 nm tables, where D65's lines would shift the
/// white (10 nm moves a grazing mirror's colour by CIEDE2000 0.055).
const WAVELENGTH_STEPS_NM: [u32; 4] = [5, 4, 2, 1];

/// The reference shader of a prepared scene.
pub struct Shader<'a> {
    p: &'a Prepared,
    samples: Option<Samples>,
    lambda_step_nm: Option<u32>,
    tone: ToneMap,
}

impl<'a> Shader<'a> {
    pub fn new(p: &'a Prepared, opts: &Options) -> Shader<'a> {
        Shader {
            p,
            samples: opts
                .lambda_samples
                .map(|n| Samples::uniform(n, cie::DEFAULT_RANGE_NM)),
            lambda_step_nm: opts.lambda_step_nm,
            tone: ToneMap {
                exposure_ev: p.scene.exposure,
                curve: opts.curve,
            },
        }
    }

    /// Diffraction XYZ of mesh `mi` for local directions (before the light's intensity).
    pub fn diffraction_xyz(&self, mi: usize, wi: [f64; 3], wr: [f64; 3]) -> [f64; 3] {
        let Some(pack) = &self.p.meshes[mi].1.pack else {
            return [0.0; 3];
        };
        if !(wi[2] > 0.0 && wr[2] > 0.0) {
            return [0.0; 3];
        }
        let (u, v, w) = (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
        let r = |l: f64| pack.shading_reflectance(u, v, w, l);
        let xyz = match &self.samples {
            None => {
                let step = self
                    .lambda_step_nm
                    .unwrap_or_else(|| wavelength_step_nm(&pack.manifest, u, v, w));
                cie::integrate_xyz_nm_step(cie::DEFAULT_RANGE_NM, step, r)
            }
            Some(s) => s.integrate(r),
        };
        let mat = &self.p.meshes[mi].1;
        let g = mat.masking.gain(wi, wr, mat.skin);
        xyz.map(|c| c * g)
    }

    /// Linear sRGB radiance of a fragment (the background colour for none).
    pub fn linear(&self, f: &Fragment) -> [f64; 3] {
        let Some(mi) = f.mesh else {
            return match (self.p.scene.background, &self.p.environment) {
                (Background::Colour(c), _) => c,
                (Background::Environment, Some(env)) => {
                    let eye = self.p.scene.camera.eye;
                    normalize(std::array::from_fn(|k| f.pos[k] - eye[k]))
                        .map_or([0.0; 3], |d| env.rgb(d))
                }
                // refused by Scene::validate
                (Background::Environment, None) => [0.0; 3],
            };
        };
        let mi = mi as usize;
        let mat = &self.p.meshes[mi].1;
        let Some((t, b, n)) = frame(f.normal, f.tangent) else {
            return [0.0; 3];
        };
        let eye = self.p.scene.camera.eye;
        let Some(wr) = normalize([eye[0] - f.pos[0], eye[1] - f.pos[1], eye[2] - f.pos[2]]) else {
            return [0.0; 3];
        };
        let local = |d: [f64; 3]| [dot(d, t), dot(d, b), dot(d, n)];
        let wr_l = local(wr);
        let dw = if mat.pack.is_some() {
            mat.diffuse_weight
        } else {
            1.0
        };
        let mut rgb = [0.0; 3];
        for light in &self.p.scene.lights {
            let Some(wi) = normalize(light.direction) else {
                continue;
            };
            let wi_l = local(wi);
            let cos_i = wi_l[2].max(0.0);
            // The base gets what the interface does not reflect (PHYSICS.md 2).
            let base_in = if mat.pack.is_some() {
                cos_i * mat.skin.transmission(cos_i)
            } else {
                cos_i
            };
            let diff = if dw < 1.0 {
                colour::xyz_to_linear_srgb(self.diffraction_xyz(mi, wi_l, wr_l))
            } else {
                [0.0; 3]
            };
            // A coloured light tints its RGB contribution (docs/SCENE.md).
            for k in 0..3 {
                rgb[k] += light.intensity
                    * light.color[k]
                    * (dw * mat.base_color[k] * base_in + (1.0 - dw) * diff[k]);
            }
        }
        rgb
    }

    /// Display value (sRGB-encoded, [0, 1]) of a fragment.
    pub fn display(&self, f: &Fragment) -> [f64; 3] {
        colour::display_encode(self.linear(f), &self.tone)
    }
}
