//! The CPU reference renderer of a Sunbeam scene: what `sunbeam-play` must show,
//! pixel for pixel (docs/PLAY.md "The reference"). No GPU; float64 throughout.
//!
//! - Rasterisation follows the GPU's rules: vertices snapped to 1/256 pixel,
//!   coverage tested at pixel centres with the top-left rule, back faces culled
//!   (counter-clockwise fronts), depth test "less", attributes interpolated
//!   perspective-correctly, triangles clipped at the near plane.
//! - Shading per pixel (PHYSICS.md 1-2): local frame from the interpolated normal
//!   `n` and orientation `t` (made orthogonal to `n`), `b = n x t`;
//!   `R` from `sunbeam_pack::Pack::reflectance` (the pack's CPU evaluator, the
//!   player's math), the colour integral at 1 nm (`sunbeam_optics::cie`), the gain
//!   `G` (`sunbeam_optics::gain`), then linear sRGB, the diffuse blend, exposure,
//!   tone curve and sRGB encoding (`sunbeam_optics::colour`).
//!
//! - Under a scene `environment` (sky or map), the lighting integral by Monte
//!   Carlo with multiple importance sampling, spectral ([`environment`],
//!   docs/LIGHTING.md).
//!
//! `render(&Scene)` is what `sunbeam-eval render` calls. The scene it draws
//! (`Prepared`, `prepare`) and the images it draws into (`Image`,
//! `LinearImage`, their comparison) are `sunbeam_frame`'s, shared with the
//! player; they are re-exported here.

pub mod converge;
mod env_cache;
pub mod environment;
pub mod lobe_sampler;
pub mod raster;
pub mod shade;

pub use sunbeam_frame::{
    compare, compare_linear, default_scene, environment_clamped_warning, load_environment,
    load_mesh, load_mesh_with_scales, mesh_bounds, prepare, prepare_with, ColourDiff, Image,
    LinearImage, Material, Mesh, Prepared,
};
pub use sunbeam_frame::{diff, fixtures, image, linear, spectral};

use std::sync::Arc;
use sunbeam_common::{Error, Result};
use sunbeam_optics::colour::ToneCurve;
use sunbeam_optics::masking::Masking;
use sunbeam_scene::Scene;

/// How the reference renders (all defaults are the documented reference).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Options {
    /// Wavelength samples of the colour integral: None = the 1 nm reference sum
    /// of `sunbeam_optics::cie::integrate_xyz_1nm` over 380..=780 nm; Some(n) = the
    /// n midpoint samples the player uses (`spectral::Samples::uniform`).
    pub lambda_samples: Option<usize>,
    /// With `lambda_samples` None: the step of the reference sum in nm (1 = every
    /// row of the 1 nm tables); None = [`shade::wavelength_step_nm`]'s, from 1
    /// nm where R varies fast to 5 nm where it cannot (docs/EVAL.md
    /// "Wavelength step").
    pub lambda_step_nm: Option<u32>,
    /// Tone curve after exposure (the scene's `exposure`).
    pub curve: ToneCurve,
    /// Worker threads (0 = available parallelism). The image does not depend on it.
    pub threads: usize,
    /// Output size override (None: the scene's `size`).
    pub size: Option<[u32; 2]>,
    /// Samples per pixel (0 or 1: the pixel centre; else a perfect square `s * s`:
    /// a stratified `s x s` grid of sub-pixel positions, averaged in linear light:
    /// what a camera records, the anti-aliased reference). Under an environment
    /// the positions are jittered in their strata by the seed (also at 1
    /// sample: a point of the pixel), and each sub-pixel sample also draws
    /// wavelengths and directions
    /// ([`environment`], docs/LIGHTING.md).
    pub samples: u32,
    /// Seed of the environment's Monte Carlo sampling (frames with different
    /// seeds differ by the estimator's noise only).
    pub seed: u64,
    /// How an environment is integrated ([`environment::EnvEstimator`]).
    pub estimator: environment::EnvEstimator,
    /// The seed of the sub-pixel positions under an environment (None: `seed`'s).
    /// Holding it across seeds leaves the directions' noise alone.
    pub subpixel_seed: Option<u64>,
}

/// The grid side `s` of `samples = s * s` per pixel, or a usage error.
pub fn samples_side(samples: u32) -> Result<u32> {
    if samples <= 1 {
        return Ok(1);
    }
    let s = (samples as f64).sqrt().round() as u32;
    if s * s != samples || s > 128 {
        return Err(Error::usage(format!(
            "--samples {samples}: give a square number of samples per pixel (1, 4, 9, 16, ... 16384)"
        )));
    }
    Ok(s)
}

/// Render a scene with the reference settings (`Options::default()`).
pub fn render(scene: &Scene) -> Result<Image> {
    render_with(scene, &Options::default())
}

/// Render a scene with explicit options.
pub fn render_with(scene: &Scene, opts: &Options) -> Result<Image> {
    let p = prepare(scene)?;
    Ok(render_prepared(&p, opts))
}

/// Render a scene to linear light (exposure applied, no tone curve), with
/// `opts.samples` stratified samples per pixel.
pub fn render_linear(scene: &Scene, opts: &Options) -> Result<LinearImage> {
    let p = prepare(scene)?;
    render_prepared_linear(&p, opts)
}

/// Linear frame of an already prepared scene (see [`render_linear`]).
pub fn render_prepared_linear(p: &Prepared, opts: &Options) -> Result<LinearImage> {
    let p = &bounded(p);
    if let Some(env) = &p.environment {
        return render_environment_at(p, env.clone(), opts, None);
    }
    let s = samples_side(opts.samples)?;
    let [w, h] = opts.size.unwrap_or(p.scene.size);
    let (sw, sh) = (w * s, h * s);
    let gbuf = raster::rasterise(p, sw, sh);
    let shader = shade::Shader::new(p, opts);
    let scale = p.scene.exposure.exp2();
    let mut rgb = vec![[0.0f32; 3]; (sw as usize) * (sh as usize)];
    for_rows(&mut rgb, sw as usize, opts.threads, |j, row| {
        for (i, px) in row.iter_mut().enumerate() {
            let frag = &gbuf[j * sw as usize + i];
            *px = shader.linear(frag).map(|v| (v * scale) as f32);
        }
    });
    Ok(LinearImage {
        width: sw,
        height: sh,
        rgb,
    }
    .downsample(s))
}

/// Fragments per band of the environment path (about 100 bytes each).
const BAND_FRAGMENTS: usize = 4 << 20;

/// The environment path of [`render_prepared_linear`]: bands of output rows, each
/// rasterised at `s x s` per pixel, each sample at a point of its stratum drawn
/// from the seed (stratified jitter); every sub-pixel sample is shaded with the
/// point lights (as without an environment) plus one environment sample
/// ([`environment::EnvShader::sample`]). With `open`, only the pixels marked
/// there are rendered (the others are 0, and bands without one are skipped):
/// [`converge`]'s later rounds.
fn render_environment_at(
    p: &Prepared,
    env: Arc<sunbeam_light::Environment>,
    opts: &Options,
    open: Option<&[bool]>,
) -> Result<LinearImage> {
    let s = samples_side(opts.samples)?;
    let [w, h] = opts.size.unwrap_or(p.scene.size);
    let (sw, sh) = (w * s, h * s);
    let packs: Vec<_> = p.meshes.iter().map(|(_, m)| m.pack.clone()).collect();
    let masking: Vec<Masking> = p.meshes.iter().map(|(_, m)| m.masking).collect();
    let skins: Vec<_> = p.meshes.iter().map(|(_, m)| m.skin).collect();
    let es = env_cache::of(p).get(env, &packs, &masking, &skins, opts.estimator);
    let shader = shade::Shader::new(p, opts);
    let scale = p.scene.exposure.exp2();
    let eye = p.scene.camera.eye;
    let n = (s * s) as u64;
    // Each seed puts the sub-pixel samples at other points of their strata,
    // so the seeds' frames differ by the positions' noise too, and the mean
    // over seeds converges to the pixel's area average (a fixed grid's error
    // at a silhouette or a limb is the same in every seed).
    let positions = raster::Positions::Jittered(
        environment::EnvShader::rng(opts.subpixel_seed.unwrap_or(opts.seed), u64::MAX, u64::MAX)
            .next_u64(),
    );
    let mut out = LinearImage::new(w, h);
    let band = (BAND_FRAGMENTS / (sw as usize * s as usize).max(1)).max(1) as u32;
    let mut y0 = 0;
    while y0 < h {
        let y1 = (y0 + band).min(h);
        let band_open = |y: u32| {
            open.is_none_or(|o| o[(y * w) as usize..((y + 1) * w) as usize].contains(&true))
        };
        if !(y0..y1).any(band_open) {
            y0 = y1;
            continue;
        }
        // Later rounds of a converged frame rasterise their open pixels only.
        let gbuf = match open {
            None => raster::rasterise_rows_at(p, sw, sh, y0 * s..y1 * s, positions),
            Some(o) => {
                let keep = |i: i64, j: i64| {
                    o[(j / s as i64) as usize * w as usize + (i / s as i64) as usize]
                };
                raster::rasterise_rows_where(p, sw, sh, y0 * s..y1 * s, positions, Some(&keep))
            }
        };
        let rows = &mut out.rgb[(y0 * w) as usize..(y1 * w) as usize];
        for_rows(rows, w as usize, opts.threads, |jr, row| {
            let y = y0 as usize + jr;
            for (x, px) in row.iter_mut().enumerate() {
                let pixel = (y * w as usize + x) as u64;
                if open.is_some_and(|o| !o[pixel as usize]) {
                    continue;
                }
                let uniforms = environment::pixel_uniforms(opts.seed, pixel, n);
                let mut acc = [0.0; 3];
                // Under the quadrature, the covered samples are shaded
                // together (they share the maps' texels).
                let mut frags: Vec<environment::Fragment> = Vec::new();
                for k in 0..n {
                    let (sx, sy) = ((k % s as u64) as usize, (k / s as u64) as usize);
                    let f = &gbuf[(jr * s as usize + sy) * sw as usize + x * s as usize + sx];
                    let mut c = shader.linear(f);
                    if let Some(mi) = f.mesh {
                        let mi = mi as usize;
                        let mat = &p.meshes[mi].1;
                        let view = shade::normalize([
                            eye[0] - f.pos[0],
                            eye[1] - f.pos[1],
                            eye[2] - f.pos[2],
                        ]);
                        if let (Some(fr), Some(wr)) = (shade::frame(f.normal, f.tangent), view) {
                            let u = &uniforms[k as usize];
                            let dw = if mat.pack.is_some() {
                                mat.diffuse_weight
                            } else {
                                1.0
                            };
                            if es.is_quadrature() {
                                frags.push(environment::Fragment {
                                    mesh: mi,
                                    frame: fr,
                                    wr,
                                    base: mat.base_color,
                                    dw,
                                    sun_u: [u.lobe[0], u.env[1]],
                                });
                            } else {
                                let e = es.sample(mi, fr, wr, mat.base_color, dw, u);
                                for i in 0..3 {
                                    c[i] += e[i];
                                }
                            }
                        }
                    }
                    for i in 0..3 {
                        acc[i] += c[i];
                    }
                }
                if !frags.is_empty() {
                    let mut rng = environment::EnvShader::rng(opts.seed, pixel, u64::MAX - 1);
                    for e in es.shade_pixel(&frags, &mut rng) {
                        for i in 0..3 {
                            acc[i] += e[i];
                        }
                    }
                }
                *px = acc.map(|v| (v / n as f64 * scale) as f32);
            }
        });
        y0 = y1;
    }
    Ok(out)
}

/// Run `f(row index, row)` over the rows of `buf` on `threads` workers (0: all
/// cores, on rayon). Each row is one task; the result does not depend on the count.
fn for_rows<T: Send>(
    buf: &mut [T],
    width: usize,
    threads: usize,
    f: impl Fn(usize, &mut [T]) + Sync + Send,
) {
    use rayon::prelude::*;
    let mut run = || {
        buf.par_chunks_mut(width.max(1))
            .enumerate()
            .for_each(|(j, row)| f(j, row))
    };
    match threads {
        0 => run(),
        n => match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
            Ok(pool) => pool.install(run),
            Err(_) => run(),
        },
    }
}

/// Render an already prepared scene (display values). With `opts.samples > 1`
/// the sub-pixel samples are averaged in linear light before the display transform.
pub fn render_prepared(p: &Prepared, opts: &Options) -> Image {
    let p = &bounded(p);
    if opts.samples > 1 || p.environment.is_some() {
        if let Ok(lin) = render_prepared_linear(p, opts) {
            return lin.display(opts.curve);
        }
    }
    let [w, h] = opts.size.unwrap_or(p.scene.size);
    let gbuf = raster::rasterise(p, w, h);
    let shader = shade::Shader::new(p, opts);
    let mut rgb = vec![[0.0f32; 3]; (w as usize) * (h as usize)];
    for_rows(&mut rgb, w as usize, opts.threads, |j, row| {
        for (i, px) in row.iter_mut().enumerate() {
            *px = shader.display(&gbuf[j * w as usize + i]).map(|v| v as f32);
        }
    });
    Image {
        width: w,
        height: h,
        rgb,
    }
}

/// `p` with every skin's energy bound filled (sunbeam_optics::energy): the
/// tables of its pack (built once per prepared scene, as `sunbeam-pack
/// --response` builds them), the masked one for a masked mesh; OFF for
/// relative reflectance and meshes without a pack. Idempotent.
pub fn bounded(p: &Prepared) -> Prepared {
    let cache = env_cache::of(p);
    let mut q = p.clone();
    for (_, m) in q.meshes.iter_mut() {
        m.skin.energy = match &m.pack {
            Some(pack) if m.skin.reflectance == sunbeam_optics::gain::Reflectance::Absolute => {
                cache
                    .energy(pack)
                    .bound(m.skin, m.masking != sunbeam_optics::masking::Masking::Off)
            }
            _ => sunbeam_optics::energy::EnergyBound::OFF,
        };
    }
    q
}
