//! The extended-light maps, the proposal and the CPU twin of the player's
//! estimator (docs/PACK_FORMAT.md "Extended-light maps"), each against a truth
//! the code under test does not produce: Parseval's theorem (the BRDF of a lobe
//! inside the disc integrates to the light's luminance), quadrature of the
//! proposal's density and a histogram of its samples, and the reference
//! renderer's Monte Carlo estimator (`sunbeam_raster::environment::EnvShader`,
//! the pack's own `R`, no map) at one shading point. With the reference
//! (above both crates it compares), not in sunbeam-response.

mod common;

use common::pack_of;
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};
use sunbeam_common::rng::SplitMix64;
use sunbeam_light::{daylight, sky::Sky, EnvMap, Environment};
use sunbeam_optics::colour;
use sunbeam_optics::gain::Material;
use sunbeam_optics::masking::Masking;
use sunbeam_pack::{Model, Pack};
use sunbeam_raster::environment::EnvShader;
use sunbeam_response::env::{build_env, EnvResponse, Frame};
use sunbeam_response::{Options, Proposal, Response};

/// Sinusoidal ridges of `period` along x, `amp` peak to peak, on an `n x n`
/// grid of `dx` (as the reference's tests build them).
fn ridges(n: usize, dx: f64, period: f64, amp: f64) -> Vec<f64> {
    (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            0.5 * amp * (1.0 + (2.0 * PI * (i * dx) / period + 0.3 * (0.7 * j).sin()).sin())
        })
        .collect()
}

/// The 3.2 um, 1.3 um period ridge patch of docs/LIGHTING.md "Noise".
fn ridge_pack() -> Arc<Pack> {
    static P: OnceLock<Arc<Pack>> = OnceLock::new();
    P.get_or_init(|| {
        pack_of(
            32,
            0.1e-6,
            &ridges(32, 0.1e-6, 1.3e-6, 0.3e-6),
            Model::Window,
        )
    })
    .clone()
}

fn sky() -> Environment {
    Environment::Sky(Box::new(Sky::new(40.0, 30.0, 3.0, 1.0)))
}

fn white() -> Environment {
    Environment::Map(EnvMap::constant([1.0; 3]))
}

/// A dim grey 512 x 256 map with two lamps of 2 x 2 texels (0.7 degrees,
/// smaller than the maps' texels): one at the mirror direction of the view
/// `(-0.2, 0.3, 0.8)`, one where the head-on view sees the ridges' first
/// order. What an HDR image's softboxes and bulbs are to the quadrature.
fn lamps() -> Environment {
    let (w, h) = (512, 256);
    let mut rgb = vec![[0.1f32, 0.1, 0.1]; w * h];
    for (i0, j0, c) in [
        (80, 34, [400.0, 300.0, 200.0]),
        (0, 35, [150.0, 250.0, 350.0]),
    ] {
        for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            rgb[(j0 + dj) * w + i0 + di] = c;
        }
    }
    Environment::Map(EnvMap::new(w, h, rgb, 0.0, 1.0).unwrap())
}

/// `int E_Y d(u, v)` of `maps` summed, at constant `w`, by a midpoint rule
/// over a fine polar grid (4 x 4 points per texel cell, `r dr dtheta`),
/// each point weighed by `f(r)`.
fn integral_y_with(maps: &[&Response], w: f64, f: impl Fn(f64) -> f64) -> f64 {
    let g = maps[0].info.grid;
    let (na, nr) = (4 * g.n_theta, 4 * (g.n_rho - 1));
    let mut sum = 0.0;
    for jr in 0..nr {
        let j = jr / 4;
        let (a, b) = (g.r_at(j), g.r_at(j + 1));
        let fr = (jr % 4) as f64;
        let (r_lo, r_hi) = (a + (b - a) * fr / 4.0, a + (b - a) * (fr + 1.0) / 4.0);
        let r = 0.5 * (r_lo + r_hi);
        let dr = r_hi - r_lo;
        let wr = f(r);
        for ia in 0..na {
            let th = 2.0 * PI * (ia as f64 + 0.5) / na as f64;
            let y: f64 = maps
                .iter()
                .map(|m| m.lookup(r * th.cos(), r * th.sin(), w)[1])
                .sum();
            sum += wr * y * r * dr * 2.0 * PI / na as f64;
        }
    }
    sum
}

fn integral_y(maps: &[&Response], w: f64) -> f64 {
    integral_y_with(maps, w, |_| 1.0)
}

/// The extended-light maps of `pack` under `env` built with `R` instead of
/// `R_U` (`build::build_sets_r`, no grazing term), the basis spectra only.
fn r_maps(pack: &Pack, env: &Environment, o: &Options) -> Vec<Response> {
    let g = sunbeam_response::build::auto_grid(pack, o.budget_bytes);
    let ws = sunbeam_response::env::env_weights(pack, env, o.lambda_samples);
    sunbeam_response::build::build_sets_r(pack, &g, &ws)
        .iter()
        .take(3)
        .map(|e| sunbeam_response::build::to_response(pack, g, ws.lambdas.len(), e, false, "R"))
        .collect()
}

/// Parseval: for a lobe inside the disc, `int E_Y d(u, v)` of maps of `R` is
/// the Y of the basis spectrum (the BRDF `G R A / l^2` integrates to 1 over
/// `d^2 f`): 1 for D65 (the sum of a map's three bases), and the Y of S0, S1,
/// S2 from the daylight table (1 nm sums, not the map's 96 samples) for the
/// sky; for a flat patch and a shallow ridge patch (orders within `r < 1.6`,
/// where the slice `w = -1.2` is not clamped in `s`).
///
/// The maps hold `R_U` (PHYSICS.md 2b), which Parseval does not bound: for a
/// flat patch `R_U = (w^2 / |q|^2)^2 R`, so the `R_U` maps integrate to the `R`
/// maps weighed by that factor (within 0.3 %; the window is a Gaussian cut at
/// 3 sigma, for which the closed form is not exact), about 1 % below the
/// light at `w = -1.2` (measured 0.991); for the ridge patch within 2 % of the
/// `R` maps' integral (measured 0.990 of the light).
#[test]
fn parseval_the_maps_integrate_to_the_light() {
    let flat = pack_of(32, 0.2e-6, &[0.0; 32 * 32], Model::Window);
    let ridge = pack_of(
        48,
        0.125e-6,
        &ridges(48, 0.125e-6, 2.0e-6, 0.1e-6),
        Model::Window,
    );
    let want_sky = daylight::basis_xyz().map(|b| b[1]);
    let w = -1.2;
    for (name, pack) in [("flat", flat), ("ridge", ridge)] {
        let o = Options::default();
        let rm = r_maps(&pack, &white(), &o);
        let d65 = integral_y(&rm.iter().collect::<Vec<_>>(), w);
        let e = build_env(&pack, &white(), &o);
        assert!(e.sun.is_none());
        let d65_u = integral_y(&e.basis.iter().collect::<Vec<_>>(), w);
        eprintln!("{name}: D65 {d65:.5} (R), {d65_u:.5} (R_U)");
        assert!((d65 - 1.0).abs() < 0.01, "{name}: {d65}");
        if name == "flat" {
            let want = integral_y_with(&rm.iter().collect::<Vec<_>>(), w, |r| {
                (w * w / (w * w + r * r)).powi(2)
            });
            eprintln!("{name}: R maps weighed by (w^2/|q|^2)^2: {want:.5}");
            assert!(
                (d65_u / want - 1.0).abs() < 0.003,
                "{name}: {d65_u} vs {want}"
            );
        } else {
            assert!((d65_u / d65 - 1.0).abs() < 0.02, "{name}: {d65_u} vs {d65}");
        }
        let rm = r_maps(&pack, &sky(), &o);
        for k in 0..3 {
            let y = integral_y(&[&rm[k]], w);
            eprintln!("{name}: S{k} {y:.5} vs {:.5}", want_sky[k]);
            assert!(
                (y - want_sky[k]).abs() < 0.01 * want_sky[0],
                "{name} S{k}: {y} vs {}",
                want_sky[k]
            );
        }
    }
}

fn ridge_env(env: &Environment) -> EnvResponse {
    let e = build_env(&ridge_pack(), env, &Options::default());
    for m in e.basis.iter().chain(&e.sun) {
        m.validate().unwrap();
    }
    e
}

fn unit(v: [f64; 3]) -> [f64; 3] {
    let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|x| x / l)
}

/// The proposal's density integrates to 1 over the disc `|(u, v)| < 2`
/// (midpoint rule on a polar grid not aligned with the cells), a histogram of
/// its samples over 64 coarse bins matches the same quadrature per bin
/// (chi-square within 5 sigma of its mean), and `sample`'s density equals
/// `pdf` at the sample.
#[test]
fn proposal_is_a_density_and_samples_follow_it() {
    let e = ridge_env(&sky());
    let p: &Proposal = &e.proposal;
    let wr = unit([-0.3, 0.2, 0.9]);
    let skin = Material::default();
    let redges = [0.0, 0.05, 0.1, 0.2, 0.4, 0.7, 1.0, 1.4, 2.0];
    let bin = |uv: [f64; 2]| {
        let r = uv[0].hypot(uv[1]);
        let rb = redges.iter().rposition(|&e| r >= e)?;
        if rb >= 8 {
            return None;
        }
        let th = uv[1].atan2(uv[0]).rem_euclid(2.0 * PI);
        Some(rb * 8 + ((th / (2.0 * PI) * 8.0) as usize).min(7))
    };
    let (na, nr) = (1000, 1400);
    let mut expect = [0.0f64; 64];
    let mut total = 0.0;
    for jr in 0..nr {
        let r = 2.0 * (jr as f64 + 0.5) / nr as f64;
        let dr = 2.0 / nr as f64;
        for ia in 0..na {
            let th = 2.0 * PI * (ia as f64 + 0.3) / na as f64;
            let uv = [r * th.cos(), r * th.sin()];
            let d = p.pdf(wr, skin, uv) * r * dr * 2.0 * PI / na as f64;
            total += d;
            if let Some(b) = bin(uv) {
                expect[b] += d;
            }
        }
    }
    eprintln!("integral of pdf: {total:.5}");
    assert!((total - 1.0).abs() < 0.01, "{total}");
    let n = 200_000;
    let mut hist = [0.0f64; 64];
    let mut rng = SplitMix64::new(3);
    for _ in 0..n {
        let (uv, pdf) = p
            .sample(wr, skin, [rng.unit(), rng.unit(), rng.unit()])
            .unwrap();
        let again = p.pdf(wr, skin, uv);
        assert!(
            (pdf - again).abs() <= 1e-9 * pdf,
            "{pdf} vs {again} at {uv:?}"
        );
        hist[bin(uv).unwrap()] += 1.0;
    }
    let (mut chi2, mut dof) = (0.0, 0);
    for b in 0..64 {
        let ex = expect[b] / total * n as f64;
        if ex > 20.0 {
            chi2 += (hist[b] - ex).powi(2) / ex;
            dof += 1;
        }
    }
    eprintln!("chi2 {chi2:.1} over {dof} bins");
    assert!(dof > 30);
    assert!(
        chi2 < dof as f64 + 5.0 * (2.0 * dof as f64).sqrt(),
        "{chi2} / {dof}"
    );
}

/// The mixture of the proposal and the defensive hemisphere technique
/// (`EnvResponse::draw`): the density it returns is `density` at the point,
/// and over the view's disc `|(u, v) + wr_xy| < 1` it integrates to
/// `DEFENSIVE + (1 - DEFENSIVE) * (the proposal's share inside the disc)`,
/// checked by a midpoint rule on a polar grid around the disc's centre.
#[test]
fn mixture_density_is_consistent() {
    let e = ridge_env(&sky());
    let wr = unit([-0.3, 0.2, 0.9]);
    let skin = Material::default();
    let mut rng = SplitMix64::new(11);
    for _ in 0..20_000 {
        let u = [rng.unit(), rng.unit(), rng.unit()];
        if let Some((uv, p)) = e.draw(wr, skin, u) {
            let again = e.density(wr, skin, uv);
            assert!((p - again).abs() <= 1e-9 * p, "{p} vs {again} at {uv:?}");
        }
    }
    // Integral over the disc (in wi_xy: r from 0 to 1 around -wr_xy).
    let (nr, nt) = (400, 720);
    let (mut mix, mut prop) = (0.0, 0.0);
    for a in 0..nr {
        // r = sin(x) spacing resolves the 1 / cos(theta_i) at the rim.
        let x0 = std::f64::consts::FRAC_PI_2 * a as f64 / nr as f64;
        let x1 = std::f64::consts::FRAC_PI_2 * (a + 1) as f64 / nr as f64;
        let (r0, r1) = (x0.sin(), x1.sin());
        let r = 0.5 * (r0 + r1);
        for b in 0..nt {
            let t = std::f64::consts::TAU * (b as f64 + 0.5) / nt as f64;
            let uv = [-r * t.cos() - wr[0], -r * t.sin() - wr[1]];
            let da = std::f64::consts::TAU / nt as f64 * (r1 * r1 - r0 * r0) / 2.0;
            mix += e.density(wr, skin, uv) * da;
            prop += e.proposal.pdf(wr, skin, uv) * da;
        }
    }
    let d = sunbeam_response::env::DEFENSIVE;
    let want = d + (1.0 - d) * prop;
    eprintln!("mixture over the disc {mix:.5}, expected {want:.5} (proposal share {prop:.5})");
    assert!((mix - want).abs() < 0.01, "{mix} vs {want}");
    assert!(prop > 0.9, "the proposal spends {prop} inside the disc");
}

/// Frame with the normal up (+y), so the sky lights the patch.
const FRAME: Frame = ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]);

fn world(d: [f64; 3]) -> [f64; 3] {
    let (t, b, n) = FRAME;
    [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * n[k])
}

/// Mean XYZ and the per-sample relative standard deviation of Y of the twin.
fn twin(e: &EnvResponse, env: &Environment, wr: [f64; 3], n: usize) -> ([f64; 3], f64) {
    let mut rng = SplitMix64::new(17);
    let (mut sum, mut sy2) = ([0.0; 3], 0.0);
    for _ in 0..n {
        let u = [0; 5].map(|_| rng.unit());
        let xyz = colour::linear_srgb_to_xyz(e.sample(
            env,
            FRAME,
            wr,
            Masking::Off,
            Material::default(),
            u,
        ));
        for c in 0..3 {
            sum[c] += xyz[c];
        }
        sy2 += xyz[1] * xyz[1];
    }
    let mean = sum.map(|v| v / n as f64);
    let var = sy2 / n as f64 - mean[1] * mean[1];
    (mean, var.max(0.0).sqrt() / mean[1])
}

/// The reference's mean XYZ (no diffuse part), wavelengths stratified, under
/// the environment called `name` (`sky` or `white`). Sample k draws from its
/// own stream, so the sum is split over threads in fixed chunks (the same
/// bytes whatever the thread count); the result is kept for the other tests
/// of this binary, which ask for the same views (the Monte Carlo sums are
/// most of its time).
fn reference(name: &str, env: &Environment, wr: [f64; 3], n: u64) -> [f64; 3] {
    use rayon::prelude::*;
    use std::collections::HashMap;
    use std::sync::Mutex;
    type Key = (String, [u64; 3], u64);
    static DONE: OnceLock<Mutex<HashMap<Key, [f64; 3]>>> = OnceLock::new();
    let key = (name.to_string(), wr.map(f64::to_bits), n);
    let done = DONE.get_or_init(Default::default);
    if let Some(v) = done.lock().unwrap().get(&key) {
        return *v;
    }
    let es = EnvShader::new(Arc::new(env.clone()), &[Some(ridge_pack())]);
    let wr_w = world(wr);
    const CHUNK: u64 = 4096;
    let parts: Vec<[f64; 3]> = (0..n.div_ceil(CHUNK))
        .into_par_iter()
        .map(|c| {
            common::estimator_xyz_sum(&es, FRAME, wr_w, 5, c * CHUNK..((c + 1) * CHUNK).min(n), n)
        })
        .collect();
    let mut mc = [0.0; 3];
    for p in parts {
        for i in 0..3 {
            mc[i] += p[i];
        }
    }
    done.lock().unwrap().insert(key, mc);
    mc
}

/// The twin's expectation is the reference's: under the sky (with its sun)
/// and a constant white map, at two views of the ridge patch, Y within 2 %
/// and chromaticity within 0.005.
#[test]
fn twin_agrees_with_the_reference() {
    for (name, env) in [("sky", sky()), ("white", white())] {
        let e = ridge_env(&env);
        for wr in [unit([0.0, 0.0, 1.0]), unit([-0.2, 0.3, 0.8])] {
            let (t, rel) = twin(&e, &env, wr, 400_000);
            // 100 000 samples, as the other tests here ask at the same
            // views: the sums are shared (the binary's most costly part).
            let r = reference(name, &env, wr, 100_000);
            let xy = |v: [f64; 3]| {
                let s = v[0] + v[1] + v[2];
                [v[0] / s, v[1] / s]
            };
            let (a, b) = (xy(t), xy(r));
            eprintln!(
                "{name} wr {wr:.3?}: twin Y {:.5} xy {a:.4?} (per-sample rel std {rel:.2}), reference Y {:.5} xy {b:.4?}, ratio {:.4}",
                t[1], r[1], t[1] / r[1]
            );
            assert!((t[1] / r[1] - 1.0).abs() < 0.02, "{name}: {t:?} vs {r:?}");
            assert!((a[0] - b[0]).abs() < 0.005 && (a[1] - b[1]).abs() < 0.005);
        }
    }
}

/// The reference's quadrature ([`EnvQuadrature`]) against the per-wavelength
/// Monte Carlo estimator (the pack's own `R`, no map) at views from head-on
/// to grazing, under the sky with its sun, a white map and a map with two
/// lamps smaller than the maps' texels ([`lamps`]; read at the texels'
/// centres the quadrature missed or multiplied them): Y within 2 % (6 % at 1
/// degree above the horizon, where the Monte Carlo estimate itself scatters
/// by a few per cent) and chromaticity within 0.005; each interleaved class
/// alone (what one sub-pixel sample of a pixel sums) within 20 % of the whole.
#[test]
fn quadrature_agrees_with_monte_carlo() {
    const CLASS_SPREAD: f64 = 0.2;
    use sunbeam_response::quadrature::EnvQuadrature;
    let xy = |v: [f64; 3]| {
        let s = v[0] + v[1] + v[2];
        [v[0] / s, v[1] / s]
    };
    for (name, env) in [("sky", sky()), ("white", white()), ("lamps", lamps())] {
        let q = EnvQuadrature::build(&ridge_pack(), &env, &EnvQuadrature::reference_options());
        for (wr, tol) in [
            (unit([0.0, 0.0, 1.0]), 0.02),
            (unit([-0.2, 0.3, 0.8]), 0.02),
            (unit([0.7, 0.1, 0.3]), 0.02),
            (unit([0.2, -0.9, 0.1]), 0.02),
            (unit([0.6, 0.8, 0.02]), 0.06),
        ] {
            // Every interleave class once (the quadrature is then complete),
            // the sun's disc point stratified.
            let parts = 16;
            let mut s = [0.0; 3];
            let mut class_y = Vec::new();
            for k in 0..parts {
                let u = [(k as f64 + 0.5) / parts as f64, (0.618 * k as f64) % 1.0];
                let x = q.integrate(&env, FRAME, wr, u, Material::default(), (k, parts));
                for c in 0..3 {
                    s[c] += x[c] / parts as f64;
                }
                class_y.push(x[1]);
            }
            let spread = class_y
                .iter()
                .map(|y| (y / s[1] - 1.0).abs())
                .fold(0.0f64, f64::max);
            eprintln!("{name} wr {wr:.3?}: one class alone within {spread:.3} of the whole");
            // What a pixel's noise comes from: each of its samples sums one
            // class. Measured at most 0.137 (head-on, whose mirror lobe lies
            // in few texels); lamps read at texels' centres gave up to 0.90.
            assert!(spread < CLASS_SPREAD, "{name} {wr:?}: classes {class_y:?}");
            let r = reference(name, &env, wr, 100_000);
            let (a, b) = (xy(s), xy(r));
            eprintln!(
                "{name} wr {wr:.3?}: quadrature {s:.5?}, Monte Carlo {r:.5?}, ratio Y {:.4}",
                s[1] / r[1]
            );
            assert!(
                (s[1] / r[1] - 1.0).abs() < tol,
                "{name} {wr:?}: {s:?} vs {r:?}"
            );
            assert!(
                (a[0] - b[0]).abs() < 0.005 && (a[1] - b[1]).abs() < 0.005,
                "{name} {wr:?}: chromaticity {a:?} vs {b:?}"
            );
        }
    }
}

/// The first-frame estimator's diffraction part (sunbeam_response::cells, the
/// twin of shaders/environment.wgsl `env_cells`) plus the sun at the point
/// `sun_u` of its disc as the player adds it (`G` times `Omega E_sun`), XYZ.
fn first_frame(
    e: &EnvResponse,
    cells: &sunbeam_response::cells::Cells,
    env: &Environment,
    frame: Frame,
    wr: [f64; 3],
    sun_u: [f64; 2],
) -> [f64; 3] {
    let (w, h, table) = env.coefficient_table(256);
    let pre = sunbeam_light::prefilter::Prefiltered::new(w, h, table);
    let skin = Material::default();
    let mut x = cells.estimate(frame, wr, Masking::Off, skin, &|d, om| pre.lookup(d, om));
    if let (Some(sky), Some(es)) = (env.sun(), &e.sun) {
        let (d, _) = sky.sample_sun(sun_u[0], sun_u[1]).unwrap();
        let (t, b, n) = frame;
        let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
        let wi = [dot(t), dot(b), dot(n)];
        if wi[2] > 0.0 {
            let g = sunbeam_optics::gain::g(wi, wr, skin);
            let m = es.lookup(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
            for a in 0..3 {
                x[a] += g * m[a];
            }
        }
    }
    x
}

/// The first-frame cells against the per-wavelength Monte Carlo reference
/// (the pack's own `R`, no map, no cells) on the ridge patch, under the sky
/// with its sun and a white map, from head-on to 6 degrees above the
/// horizon: Y within 3 % and chromaticity within 0.005 (measured: see the
/// printout; docs/LIGHTING.md "The first frame").
#[test]
fn first_frame_cells_agree_with_the_reference() {
    use sunbeam_response::cells::{Cells, DEFAULT_DEPTH, DEFAULT_TOP};
    let xy = |v: [f64; 3]| {
        let s = v[0] + v[1] + v[2];
        [v[0] / s, v[1] / s]
    };
    for (name, env) in [("sky", sky()), ("white", white())] {
        let e = ridge_env(&env);
        let cells = Cells::build(&e.basis, DEFAULT_TOP, DEFAULT_DEPTH);
        assert!(cells.n_top == DEFAULT_TOP && cells.nodes.len() > DEFAULT_TOP);
        for wr in [
            unit([0.0, 0.0, 1.0]),
            unit([-0.2, 0.3, 0.8]),
            unit([0.7, 0.1, 0.3]),
            unit([0.2, -0.9, 0.1]),
        ] {
            // the sun's disc averaged as the accumulated frames average it
            let n = 16;
            let mut c = [0.0; 3];
            for k in 0..n {
                let u = [(k as f64 + 0.5) / n as f64, (0.618 * k as f64) % 1.0];
                let x = first_frame(&e, &cells, &env, FRAME, wr, u);
                for a in 0..3 {
                    c[a] += x[a] / n as f64;
                }
            }
            let r = reference(name, &env, wr, 100_000);
            let (a, b) = (xy(c), xy(r));
            eprintln!(
                "{name} wr {wr:.3?}: cells Y {:.5} xy {a:.4?}, reference Y {:.5} xy {b:.4?}, ratio {:.4}",
                c[1],
                r[1],
                c[1] / r[1]
            );
            assert!(
                (c[1] / r[1] - 1.0).abs() < 0.03,
                "{name} {wr:?}: {c:?} vs {r:?}"
            );
            assert!(
                (a[0] - b[0]).abs() < 0.005 && (a[1] - b[1]).abs() < 0.005,
                "{name} {wr:?}: chromaticity {a:?} vs {b:?}"
            );
        }
    }
}

/// The furnace (PHYSICS.md 5 item 11) through the first-frame cells: a flat
/// patch with a narrow lobe (common::narrow_flat_pack, 256 um) under a
/// constant white environment returns the Fresnel reflectance of its view
/// (n = 1.5, absolute) at 0, 60 and 80 degrees within 1 %.
#[test]
fn furnace_through_the_first_frame_cells() {
    use sunbeam_response::cells::{Cells, DEFAULT_DEPTH, DEFAULT_TOP};
    let flat = common::narrow_flat_pack(sunbeam_pack::Model::Window);
    let env = white();
    let e = build_env(&flat, &env, &Options::default());
    let cells = Cells::build(&e.basis, DEFAULT_TOP, DEFAULT_DEPTH);
    for deg in [0.0f64, 60.0, 80.0] {
        let want = sunbeam_optics::gain::fresnel(deg.to_radians().cos(), 1.5);
        let t = deg.to_radians();
        let wr = [t.sin(), 0.0, t.cos()];
        let x = first_frame(&e, &cells, &env, FRAME, wr, [0.5, 0.5]);
        eprintln!("furnace at {deg} deg: Y {:.5} (F {want:.5})", x[1]);
        assert!(
            (x[1] / want - 1.0).abs() < 0.01,
            "{deg} deg: {} vs {want}",
            x[1]
        );
    }
}

/// The first-frame cells against the reference's quadrature (`EnvQuadrature`:
/// its own maps' texels, built with more wavelengths, the horizon band
/// integrated across each texel; no cells) over a grid of views,
/// 0 to 85 degrees from the normal at four azimuths, under a constant white
/// map and the sky with its sun, on the ridge patch: each view's Y within
/// [`CELLS_VIEW_TOL`], their mean ratio within [`CELLS_MEAN_TOL`] of 1. The
/// deterministic counterpart of [`first_frame_cells_agree_with_the_reference`]
/// (no Monte Carlo noise, so a bias of a per cent shows).
#[test]
fn first_frame_cells_agree_with_the_quadrature_over_views() {
    use sunbeam_response::cells::{Cells, FIRST_FRAME_TOP};
    use sunbeam_response::quadrature::EnvQuadrature;
    let pack = ridge_pack();
    for (name, env) in [("white", white()), ("sky", sky())] {
        let e = ridge_env(&env);
        let cells = Cells::build(
            &e.basis,
            FIRST_FRAME_TOP,
            sunbeam_response::cells::DEFAULT_DEPTH,
        );
        let q = EnvQuadrature::build(&pack, &env, &EnvQuadrature::reference_options());
        let mut ratios = Vec::new();
        for th in [0.0f64, 15.0, 30.0, 45.0, 60.0, 70.0, 80.0, 85.0] {
            for ph in [0.0f64, 30.0, 60.0, 90.0] {
                let (t, p) = (th.to_radians(), ph.to_radians());
                let wr = [t.sin() * p.cos(), t.sin() * p.sin(), t.cos()];
                // the sun's disc and the quadrature's classes, 16 each
                let parts = 16;
                let (mut c, mut r) = ([0.0; 3], [0.0; 3]);
                for k in 0..parts {
                    let u = [(k as f64 + 0.5) / parts as f64, (0.618 * k as f64) % 1.0];
                    let x = first_frame(&e, &cells, &env, FRAME, wr, u);
                    let y = q.integrate(&env, FRAME, wr, u, Material::default(), (k, parts));
                    for a in 0..3 {
                        c[a] += x[a] / parts as f64;
                        r[a] += y[a] / parts as f64;
                    }
                }
                let ratio = c[1] / r[1];
                eprintln!("{name} {th} deg, azimuth {ph}: cells Y {:.5}, quadrature Y {:.5}, ratio {ratio:.4}", c[1], r[1]);
                assert!(
                    (ratio - 1.0).abs() < CELLS_VIEW_TOL,
                    "{name} {th} deg, azimuth {ph}: {c:?} vs {r:?}"
                );
                ratios.push(ratio);
            }
        }
        let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
        eprintln!("{name}: mean ratio {mean:.4}");
        assert!(
            (mean - 1.0).abs() < CELLS_MEAN_TOL,
            "{name}: mean ratio {mean}"
        );
    }
}

/// Bound per view of [`first_frame_cells_agree_with_the_quadrature_over_views`]:
/// measured at worst -1.08 % (sky, 60 degrees, azimuth 0) and +0.87 % (white,
/// 80 degrees, azimuth 90) with the player's 512 cells (2026-11-30), plus
/// 25 %. Refining at `cells::REFINE` 2 spreads instead of 3 and reading the
/// environment over the spread's circle instead of the width's ellipse:
/// -1.45 % and +1.13 %; with the rim's mass as a Gaussian instead of a box
/// (`cells::rim_moments`) -2.0 % and +1.5 %; without the rim's integral
/// (`cells::rim_point`: `G / cos` at the centroid times a Gaussian share
/// inside) -3.7 % and +1.0 %, means 0.990 and 0.991, and more cells did not
/// lower it (docs/LIGHTING.md "Accuracy per view").
const CELLS_VIEW_TOL: f64 = 0.0135;
/// Bound on the mean ratio over the views: measured 1.0000 (white) and 0.9990
/// (sky), plus 25 % of the difference and 0.1 % for the measurement's own
/// spread (REFINE 2: 1.0008 and 0.9993; the Gaussian rim: 1.0020 and 1.0003).
const CELLS_MEAN_TOL: f64 = 0.0021;
