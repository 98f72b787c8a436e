//! Environment lighting in the reference renderer (docs/LIGHTING.md): the
//! oblique furnace (`F(theta)`, PHYSICS.md 5 item 11) at a point and through
//! the whole renderer (both estimators), the diffuse base's transmission, the
//! Monte Carlo estimator against a deterministic quadrature with a direct
//! float64 Kirchhoff sum (no pack code, no sampling), the maps' quadrature
//! against Monte Carlo over a whole frame, seed-to-seed noise, and rotation
//! of the environment against rotation of the scene.

mod common;

use common::{narrow_flat_pack, pack_of, Kirchhoff};
use std::f64::consts::PI;
use std::sync::Arc;
use sunbeam_light::{sky::Sky, EnvMap, Environment};
use sunbeam_optics::truth::{Params, Truth};
use sunbeam_optics::{cie, colour, gain};
use sunbeam_pack::Model;
use sunbeam_raster::environment::{EnvEstimator, EnvShader, Frame};
use sunbeam_raster::{compare_linear, fixtures, render_prepared_linear, LinearImage, Options};

/// A ridge field like snake skin, scaled down: sinusoidal ridges of `period`
/// along x, `amp` peak to peak, on an `n x n` grid of `dx`.
fn ridges(n: usize, dx: f64, period: f64, amp: f64) -> Vec<f64> {
    (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            0.5 * amp * (1.0 + (2.0 * PI * (i * dx) / period + 0.3 * (0.7 * j).sin()).sin())
        })
        .collect()
}

/// The estimator's mean XYZ over `m` samples at one shading point (frame `f`,
/// view `wr`), wavelengths stratified, no diffuse part.
fn estimate_xyz(es: &EnvShader, f: Frame, wr: [f64; 3], m: u64, seed: u64) -> [f64; 3] {
    common::estimator_xyz_sum(es, f, wr, seed, 0..m, m)
}

fn mean_y(img: &LinearImage, x0: u32, x1: u32) -> f64 {
    let mut s = 0.0;
    let mut n = 0.0;
    for y in x0..x1 {
        for x in x0..x1 {
            let p = img.rgb[(y * img.width + x) as usize];
            s += 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64;
            n += 1.0;
        }
    }
    s / n
}

/// The oblique furnace (PHYSICS.md 5 item 11): a flat patch under a constant
/// white environment of radiance 1, seen at 0, 60 and 80 degrees, returns
/// `F(theta)` (absolute, n = 1.5: 0.0400, 0.0892, 0.3877) within 1 %, at the
/// patch's centre through both of the reference's estimators: Monte Carlo
/// (200 000 samples) and the quadrature over the extended-light maps (every
/// texel); and the relative normalisation `F(theta) / F(0)` (1, 2.23, 9.69)
/// through the quadrature. Narrow lobes, both models ([`narrow_flat_pack`]),
/// and a 4 um window patch head-on (its lobe, 0.12 wide in `u`, is cut by
/// the horizon at oblique views).
#[test]
fn oblique_furnace_gives_fresnel() {
    use sunbeam_response::quadrature::EnvQuadrature;
    let env = Arc::new(Environment::Map(EnvMap::constant([1.0; 3])));
    let f = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let fresnel = [(0.0f64, 0.0400), (60.0, 0.0892), (80.0, 0.3877)];
    for (name, pack, views) in [
        (
            "4 um window",
            pack_of(40, 100e-9, &[0.0; 1600], Model::Window),
            1,
        ),
        ("256 um window", narrow_flat_pack(Model::Window), 3),
        ("6.4 um tiled", narrow_flat_pack(Model::Tiled), 3),
    ] {
        let es = EnvShader::new(env.clone(), &[Some(pack.clone())]);
        let quad = EnvQuadrature::build(&pack, &env, &EnvQuadrature::reference_options());
        for &(deg, want) in &fresnel[..views] {
            let th = deg.to_radians();
            assert!((gain::fresnel(th.cos(), 1.5) - want).abs() < 5e-5);
            let wr = [th.sin(), 0.0, th.cos()];
            let mc = estimate_xyz(&es, f, wr, 200_000, 11)[1];
            let q = |skin| quad.integrate(&env, f, wr, [0.5, 0.5], skin, (0, 1))[1];
            let (qa, qr) = (q(gain::Material::default()), q(gain::Material::RELATIVE));
            eprintln!(
                "furnace {name} at {deg} deg: Monte Carlo {mc:.5}, quadrature {qa:.5} (relative {qr:.4}), F {want}"
            );
            for (est, y) in [("Monte Carlo", mc), ("quadrature", qa)] {
                assert!(
                    (y / want - 1.0).abs() < 0.01,
                    "{name} {deg} deg {est}: Y = {y}, F = {want}"
                );
            }
            let rel = want / 0.04;
            assert!(
                (qr / rel - 1.0).abs() < 0.01,
                "{name} {deg} deg relative: {qr} vs {rel}"
            );
        }
    }
}

/// The extended-light maps hold `R_U` (PHYSICS.md 2b), whose window lobe
/// falls to 0 as `w -> 0`: with too few `s` layers the quadrature over them
/// dimmed oblique views (a flat 40 um window patch under the white furnace at
/// 80 degrees: 3 % below Monte Carlo on the pack with 8 layers, 0.2 % with
/// `sunbeam_response::build::MIN_S_GRAZING` = 16). The two estimators agree
/// within 1 % at 60 and 80 degrees; both lie above `F(theta)` by what the
/// lobe's width adds (about +1.7 % at 80 degrees, [`narrow_flat_pack`]).
#[test]
fn furnace_maps_follow_the_grazing_term() {
    use sunbeam_response::quadrature::EnvQuadrature;
    let env = Arc::new(Environment::Map(EnvMap::constant([1.0; 3])));
    let f = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
    let pack = pack_of(400, 100e-9, &vec![0.0; 400 * 400], Model::Window);
    let es = EnvShader::new(env.clone(), &[Some(pack.clone())]);
    let quad = EnvQuadrature::build(&pack, &env, &EnvQuadrature::reference_options());
    assert!(quad.grid().n_s >= sunbeam_response::build::MIN_S_GRAZING);
    for deg in [60.0f64, 80.0] {
        let th = deg.to_radians();
        let wr = [th.sin(), 0.0, th.cos()];
        let mc = estimate_xyz(&es, f, wr, 200_000, 11)[1];
        let q = quad.integrate(&env, f, wr, [0.5, 0.5], gain::Material::default(), (0, 1))[1];
        let fr = gain::fresnel(th.cos(), 1.5);
        eprintln!(
            "40 um window at {deg} deg: Monte Carlo {mc:.5}, quadrature {q:.5} (ratio {:.4}), F {fr:.5}",
            q / mc
        );
        assert!((q / mc - 1.0).abs() < 0.01, "{deg} deg: {q} vs {mc}");
    }
}

/// Furnace through the whole renderer: a flat patch seen head-on under a
/// constant white environment of radiance 1 shows `F(0) = 0.04` (the
/// absolute specular gain at normal incidence, PHYSICS.md 2) over the frame,
/// for a small and a large patch and both models: by the quadrature (within
/// 1 %) and by Monte Carlo (within 3 %: fewer samples per pixel).
#[test]
fn furnace_through_the_renderer() {
    for (n, dx, model) in [
        (40usize, 100e-9, Model::Window),
        (400, 100e-9, Model::Window),
        (64, 100e-9, Model::Tiled),
    ] {
        let pack = pack_of(n, dx, &vec![0.0; n * n], model);
        let env = Arc::new(Environment::Map(EnvMap::constant([1.0; 3])));
        let (mut scene, mesh) = fixtures::quad_scene([16, 16]);
        scene.lights.clear();
        scene.meshes[0].diffuse_weight = 0.0;
        scene.camera.eye = [0.0, 0.0, 3.0];
        let mut p = fixtures::prepared(scene, mesh, Some(pack));
        p.environment = Some(env);
        let f0 = 0.04;
        // 4096 samples: 1024 interleaved classes of 4 samples each.
        for (estimator, tol, samples) in [
            (EnvEstimator::MonteCarlo, 0.03, 256),
            (EnvEstimator::Quadrature, 0.01, 256),
            (EnvEstimator::Quadrature, 0.01, 4096),
        ] {
            let img = render_prepared_linear(
                &p,
                &Options {
                    samples,
                    seed: 3,
                    estimator,
                    ..Default::default()
                },
            )
            .unwrap();
            // Every pixel that sees the patch (within 10 degrees of head-on, where
            // the Fresnel factor stays within 1e-3 of its normal value).
            let ys: Vec<f64> = img
                .rgb
                .iter()
                .map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64)
                .filter(|&y| y > 0.3 * f0)
                .collect();
            assert!(ys.len() > 30, "{} lit pixels", ys.len());
            let y = ys.iter().sum::<f64>() / ys.len() as f64;
            eprintln!(
                "furnace {n} x {dx:e} {model:?}: Y = {y:.5} over the frame ({estimator:?}, {samples} samples)"
            );
            assert!(
                (y / f0 - 1.0).abs() < tol,
                "{n} px {model:?} {estimator:?}: Y = {y}"
            );
        }
    }
}

/// The diffuse base under the skin gets `1 - F(theta_i)` of the light
/// (PHYSICS.md 2): a white Lambertian base (diffuse weight 1) under a white
/// furnace of radiance 1 has radiance `2 int_0^1 c (1 - F(c)) dc` (0.908 for
/// n = 1.5) with a pack, 1 without, over the frame (the quad fills it):
/// within 0.3 % by the quadrature (the tabulated irradiance), 2 % by Monte
/// Carlo (256 samples per pixel: 0.5 % noise over the frame).
#[test]
fn furnace_diffuse_base_gets_the_transmission() {
    let m = 100_000;
    let want_skin: f64 = (0..m)
        .map(|i| {
            let c = (i as f64 + 0.5) / m as f64;
            2.0 * c * (1.0 - gain::fresnel(c, 1.5)) / m as f64
        })
        .sum();
    for with_pack in [true, false] {
        let pack = with_pack.then(|| pack_of(16, 100e-9, &[0.0; 256], Model::Window));
        let (mut scene, mesh) = fixtures::quad_scene([16, 16]);
        scene.lights.clear();
        scene.meshes[0].diffuse_weight = 1.0;
        scene.meshes[0].base_color = [1.0; 3];
        let mut p = fixtures::prepared(scene, mesh, pack);
        p.environment = Some(Arc::new(Environment::Map(EnvMap::constant([1.0; 3]))));
        let want = if with_pack { want_skin } else { 1.0 };
        for (estimator, tol) in [
            (EnvEstimator::MonteCarlo, 0.02),
            (EnvEstimator::Quadrature, 0.003),
        ] {
            let img = render_prepared_linear(
                &p,
                &Options {
                    samples: 256,
                    seed: 5,
                    estimator,
                    ..Default::default()
                },
            )
            .unwrap();
            let y = mean_y(&img, 0, 16);
            eprintln!("diffuse base, pack {with_pack} ({estimator:?}): Y = {y:.4}, want {want:.4}");
            assert!(
                (y / want - 1.0).abs() < tol,
                "pack {with_pack} {estimator:?}: {y} vs {want}"
            );
        }
    }
}

/// The estimator at one shading point against a deterministic quadrature of
/// `integral L(wi, l) G R_U A / l^2 cmf(l) dw dl / sum D65 ybar` with `R_U`
/// from a direct float64 sum over the height field ([`Kirchhoff`], no pack
/// code; `A` the float64 truth's) on a fine grid of wi (and 10 nm
/// wavelengths), under the sky.
#[test]
fn estimator_matches_quadrature_under_the_sky() {
    use rayon::prelude::*;
    let (n, dx) = (32usize, 50e-9);
    let data = ridges(n, dx, 0.8e-6, 300e-9);
    let pack = pack_of(n, dx, &data, Model::Window);
    let kirchhoff = Kirchhoff::new(n, n, dx, dx, &data, Params::default().coherence_m);
    let field = sunbeam_field::HeightField::new(n, n, dx, dx, data).unwrap();
    let truth = Truth::new(&field, &Params::default()).unwrap();
    assert!((kirchhoff.sigma / truth.window_sigma_m() - 1.0).abs() < 1e-12);
    let sky = Sky::new(40.0, 30.0, 3.0, 1.0);
    let env = Arc::new(Environment::Sky(Box::new(sky.clone())));
    let es = EnvShader::new(env.clone(), &[Some(pack)]);
    // Shading frame: tilted so that sun, sky and ground all matter.
    let tilt: f64 = 0.5;
    let nrm = [0.0, tilt.cos(), tilt.sin()];
    let t = [1.0, 0.0, 0.0];
    // b = n x t
    let b = [
        nrm[1] * t[2] - nrm[2] * t[1],
        nrm[2] * t[0] - nrm[0] * t[2],
        nrm[0] * t[1] - nrm[1] * t[0],
    ];
    let wr_l = [0.2, -0.3, (1.0f64 - 0.04 - 0.09).sqrt()];
    let world = |d: [f64; 3]| [0, 1, 2].map(|k| d[0] * t[k] + d[1] * b[k] + d[2] * nrm[k]);
    let wr = world(wr_l);
    let mc = estimate_xyz(&es, (t, b, nrm), wr, 200_000, 7);
    // Midpoint quadrature over the hemisphere in (theta, phi): dw = sin(theta)
    // dtheta dphi, bounded integrand (in wi_t = (x, y) the 1 / cos(theta)
    // Jacobian is singular at the horizon, where this ridge field has orders).
    let a = truth.coherent_area_m2();
    let (nt, np) = (110usize, 240usize);
    let (dth, dph) = (PI / 2.0 / nt as f64, 2.0 * PI / np as f64);
    let norm = cie::d65_y_norm(cie::DEFAULT_RANGE_NM);
    let nms: Vec<u32> = (380..=780).step_by(10).collect();
    // Per theta row (w fixed per wavelength along it), in parallel.
    let rows: Vec<[f64; 3]> = (0..nt)
        .into_par_iter()
        .map(|it| {
            let th = (it as f64 + 0.5) * dth;
            let mut q = [0.0; 3];
            let w = -th.cos() - wr_l[2];
            for &nm in &nms {
                let l = nm as f64 * 1e-9;
                let p = kirchhoff.phasors(w, l);
                let wgt = if nm == 380 || nm == 780 { 5.0 } else { 10.0 };
                let c = cie::cmf_at(l);
                for ip in 0..np {
                    let ph = (ip as f64 + 0.5) * dph;
                    let wi = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
                    let cell = th.sin() * dth * dph;
                    let gg = gain::g(wi, wr_l, gain::Material::default());
                    let d = world(wi);
                    let r = kirchhoff
                        .r_u(&p, -wi[0] - wr_l[0], -wi[1] - wr_l[1], w, l)
                        .1;
                    // The sun's disc is far smaller than a grid cell: added below.
                    let sky_only = env.spectral(d, l)
                        - if sky.in_sun(d) {
                            sky.sun_spectral(l)
                        } else {
                            0.0
                        };
                    let v = sky_only * gg * r * a / (l * l) * cell * wgt / norm;
                    for i in 0..3 {
                        q[i] += v * c[i];
                    }
                }
            }
            q
        })
        .collect();
    let mut q = [0.0; 3];
    for r in &rows {
        for i in 0..3 {
            q[i] += r[i];
        }
    }
    // The sun: its disc's radiance times its solid angle, at its centre.
    let s = sky.sun_direction();
    let wi = [0, 1, 2]
        .map(|k| s[0] * [t, b, nrm][k][0] + s[1] * [t, b, nrm][k][1] + s[2] * [t, b, nrm][k][2]);
    if wi[2] > 0.0 {
        let gg = gain::g(wi, wr_l, gain::Material::default());
        let w = -wi[2] - wr_l[2];
        for &nm in &nms {
            let l = nm as f64 * 1e-9;
            let p = kirchhoff.phasors(w, l);
            let r = kirchhoff
                .r_u(&p, -wi[0] - wr_l[0], -wi[1] - wr_l[1], w, l)
                .1;
            let wgt = if nm == 380 || nm == 780 { 5.0 } else { 10.0 };
            let v = sky.sun_spectral(l) * sky.sun_solid_angle() * gg * r * a / (l * l) * wgt / norm;
            let c = cie::cmf_at(l);
            for i in 0..3 {
                q[i] += v * c[i];
            }
        }
    }
    eprintln!("MC {mc:?}\nquadrature {q:?}");
    for i in 0..3 {
        assert!(
            (mc[i] / q[i] - 1.0).abs() < 0.03,
            "channel {i}: MC {} vs quadrature {}",
            mc[i],
            q[i]
        );
    }
}

fn sphere_under(
    env: Environment,
    size: u32,
    eye: [f64; 3],
    samples: u32,
    seed: u64,
    estimator: EnvEstimator,
) -> LinearImage {
    let opts = Options {
        samples,
        seed,
        estimator,
        ..Default::default()
    };
    sphere_with(env, size, eye, &opts)
}

/// [`sphere_under`] with explicit options.
fn sphere_with(env: Environment, size: u32, eye: [f64; 3], opts: &Options) -> LinearImage {
    let (n, dx) = (64usize, 50e-9);
    let pack = pack_of(n, dx, &ridges(n, dx, 1.3e-6, 420e-9), Model::Window);
    let (mut scene, mesh) = fixtures::sphere_scene([size, size]);
    scene.lights.clear();
    scene.camera.eye = eye;
    scene.camera.target = [0.0, 0.0, 0.0];
    let mut p = fixtures::prepared(scene, mesh, Some(pack));
    p.environment = Some(Arc::new(env));
    render_prepared_linear(&p, opts).unwrap()
}

/// The estimators' determinism and noise on a sky-lit ridge patch seen from
/// the front: the same seed gives the same frame whatever the thread count;
/// two seeds give frames whose mean luminance agrees to 3 % (under Monte
/// Carlo each pixel is still noisy at 256 samples: CIEDE2000 p99 ~ 8 between
/// seeds; docs/LIGHTING.md "Cost and noise").
#[test]
fn seeds_are_deterministic_and_agree_on_average() {
    for estimator in [EnvEstimator::MonteCarlo, EnvEstimator::Quadrature] {
        seeds_agree(estimator);
    }
}

fn seeds_agree(estimator: EnvEstimator) {
    let run = |seed, threads| {
        let (n, dx) = (64usize, 50e-9);
        let pack = pack_of(n, dx, &ridges(n, dx, 1.3e-6, 420e-9), Model::Window);
        let (mut scene, mesh) = fixtures::quad_scene([12, 12]);
        scene.lights.clear();
        scene.camera.eye = [0.0, 0.0, 2.0];
        let mut p = fixtures::prepared(scene, mesh, Some(pack));
        p.environment = Some(Arc::new(Environment::Sky(Box::new(Sky::new(
            35.0, 60.0, 3.0, 1.0,
        )))));
        render_prepared_linear(
            &p,
            &Options {
                samples: 256,
                seed,
                threads,
                estimator,
                ..Default::default()
            },
        )
        .unwrap()
    };
    let (a, b) = (run(1, 2), run(2, 2));
    assert_eq!(a, run(1, 1), "same seed, other thread count: another frame");
    let d = compare_linear(&a, &b).unwrap();
    let (ya, yb) = (mean_y(&a, 0, 12), mean_y(&b, 0, 12));
    eprintln!("{estimator:?}: seed 1 vs 2: {d}; mean Y {ya:.4} vs {yb:.4}");
    assert!(d.pixels > 50, "{d}");
    // Lit: 0.002 is 0.05 in the relative units this bound was set in (the
    // absolute gain is F(0) = 0.04 of the relative one); measured 0.0127.
    assert!(
        ya > 0.002 && (ya / yb - 1.0).abs() < 0.03,
        "mean Y {ya} vs {yb}"
    );
}

/// An environment rotated by R lights the scene as the unrotated one lights
/// the scene rotated by -R (the sphere and its orientation field are symmetric
/// under rotations about +y by multiples of its 3.75 degree segments, so the
/// scene's rotation is the camera's).
#[test]
fn rotating_the_environment_equals_rotating_the_scene_back() {
    let (w, h) = (64, 32);
    let px: Vec<[f32; 3]> = (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            [
                1.0 + (i % 7) as f32,
                0.5 + (j % 5) as f32,
                ((i * j) % 3) as f32 + 0.2,
            ]
        })
        .collect();
    let r = 90.0;
    let map = |rot: f64| Environment::Map(EnvMap::new(w, h, px.clone(), rot, 1.0).unwrap());
    let eye = [0.3, 0.8, 2.5];
    let rotated = sphere_under(map(r), 20, eye, 16, 5, EnvEstimator::MonteCarlo);
    let back = sunbeam_light::rot_y(eye, -r);
    let scene_rotated = sphere_under(map(0.0), 20, back, 16, 5, EnvEstimator::MonteCarlo);
    // Over the interior: the rotated scene's silhouette moves by rounding, and
    // a jittered sub-pixel sample can fall on either side of it.
    let xyz = |p: [f32; 3]| colour::linear_srgb_to_xyz(p.map(f64::from));
    let mut de: Vec<f64> = sunbeam_raster::linear::interior_pixels(&[&rotated, &scene_rotated])
        .into_iter()
        .map(|i| colour::ciede2000_xyz(xyz(rotated.rgb[i]), xyz(scene_rotated.rgb[i])))
        .collect();
    de.sort_by(f64::total_cmp);
    let (p99, max) = (de[(de.len() - 1) * 99 / 100], de[de.len() - 1]);
    eprintln!(
        "rotated environment vs rotated scene, {} interior pixels: p99 {p99:.4} max {max:.4}",
        de.len()
    );
    assert!(de.len() > 80, "{} interior pixels", de.len());
    assert!(p99 < 0.05 && max < 1.0, "p99 {p99} max {max}");
}

/// The lobe sampler's `pdf` is the density of its `sample`: over cells of equal
/// solid angle (uniform in cos(theta) and phi) the share of draws in each cell
/// matches the integral of `pdf` over it (a fine midpoint rule), within
/// 5 sigma of the counts' noise plus 3 % for the rule, and in total the
/// share of draws that are not evanescent matches the integral over the
/// hemisphere within 1 %; the density a draw reports (the product of its
/// descent's choices) is `pdf`'s. The window model (the tiled model's lobes
/// are far narrower than any cell's quadrature; its density is the sum of the
/// bins' Gaussians weighted by the same bin probabilities), views from head-on
/// to grazing, short and long wavelengths.
#[test]
fn lobe_sampler_pdf_is_the_density_of_its_samples() {
    use sunbeam_common::rng::SplitMix64;
    use sunbeam_raster::lobe_sampler::LobeSampler;
    let (n, dx) = (32usize, 50e-9);
    let data = ridges(n, dx, 0.8e-6, 300e-9);
    {
        let model = Model::Window;
        let ls = LobeSampler::new(pack_of(n, dx, &data, model));
        for (th, ph, nm) in [
            (0.0f64, 0.0f64, 450.0),
            (50.0, 120.0, 700.0),
            (82.0, 250.0, 550.0),
        ] {
            let (th, ph) = (th.to_radians(), ph.to_radians());
            let wr = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
            let l = nm * 1e-9;
            let q = ls.query(wr, l, gain::Material::default());
            let (nc, np) = (8usize, 16usize);
            let cell = |wi: [f64; 3]| {
                let c = ((wi[2] * nc as f64) as usize).min(nc - 1);
                let a = wi[1].atan2(wi[0]).rem_euclid(2.0 * PI);
                let p = ((a / (2.0 * PI) * np as f64) as usize).min(np - 1);
                c * np + p
            };
            let draws = 200_000usize;
            let mut counts = vec![0usize; nc * np];
            let mut rng = SplitMix64::new(77);
            for _ in 0..draws {
                let u = [rng.unit(), rng.unit(), rng.unit()];
                if let Some((wi, p)) = ls.sample_in(&q, u) {
                    let exact = ls.pdf_in(&q, wi);
                    assert!(
                        (p / exact - 1.0).abs() < 1e-6,
                        "{model:?}: the draw's density {p} vs pdf {exact}"
                    );
                    counts[cell(wi)] += 1;
                }
            }
            // The integral of pdf over each cell: dw = d(cos theta) d(phi).
            let k = 40usize;
            let (dc, dp) = (1.0 / (nc * k) as f64, 2.0 * PI / (np * k) as f64);
            let mut expect = vec![0.0f64; nc * np];
            for ic in 0..nc * k {
                let c = (ic as f64 + 0.5) * dc;
                let s = (1.0 - c * c).sqrt();
                for ip in 0..np * k {
                    let a = (ip as f64 + 0.5) * dp;
                    let wi = [s * a.cos(), s * a.sin(), c];
                    expect[(ic / k) * np + ip / k] += ls.pdf_in(&q, wi) * dc * dp;
                }
            }
            let total: f64 = expect.iter().sum();
            let hit = counts.iter().sum::<usize>() as f64 / draws as f64;
            eprintln!(
                "{model:?} th_r {:.0} {nm} nm: integral of pdf {total:.4}, share of draws {hit:.4}",
                th.to_degrees()
            );
            assert!((total / hit - 1.0).abs() < 0.01, "{total} vs {hit}");
            for (c, (&got, &e)) in counts.iter().zip(&expect).enumerate() {
                let e = e * draws as f64;
                let tol = 5.0 * e.sqrt() + 0.03 * e + 3.0;
                assert!(
                    (got as f64 - e).abs() < tol,
                    "{model:?} cell {c}: {got} draws, {e:.1} expected"
                );
            }
        }
    }
}

/// Seed-to-seed noise of the Monte Carlo estimator on a small sky-lit sphere
/// (silhouettes included: grazing views, the estimator's hardest case): two
/// seeds at 64 samples per pixel
/// differ by less than the bound measured when the estimator was last changed
/// (docs/LIGHTING.md "Cost and noise"), with a margin, so that a change that
/// makes the estimator noisier fails here.
#[test]
fn seed_to_seed_noise_of_a_sky_lit_sphere() {
    let sky = || Environment::Sky(Box::new(Sky::new(25.0, 120.0, 3.0, 1.0)));
    let eye = [0.0, 0.6, 2.6];
    let t0 = std::time::Instant::now();
    let a = sphere_under(sky(), 24, eye, 64, 1, EnvEstimator::MonteCarlo);
    let b = sphere_under(sky(), 24, eye, 64, 2, EnvEstimator::MonteCarlo);
    let d = compare_linear(&a, &b).unwrap();
    eprintln!(
        "sky-lit sphere, 24 x 24, 64 samples, seed 1 vs 2: {d} ({:.1} s)",
        t0.elapsed().as_secs_f64()
    );
    assert!(d.pixels > 150, "{d}");
    assert!(d.mean < MEAN_BOUND && d.p99 < P99_BOUND, "{d}");
}

/// Bounds of [`seed_to_seed_noise_of_a_sky_lit_sphere`]: measured 2.84 and
/// 14.7 with the absolute gain, exact Fresnel once and `R_U` (10.3 and 54.4
/// before, 2026-11-25: the same estimator's noise is smaller in CIEDE2000 at
/// 1/25 of the luminance), with a margin of 25 %.
const MEAN_BOUND: f64 = 3.6;
const P99_BOUND: f64 = 18.4;

/// The quadrature on the sphere of [`seed_to_seed_noise_of_a_sky_lit_sphere`]:
/// two seeds at 64 samples per pixel and the same sub-pixel positions (their
/// only difference: the sun's disc points and the texels' classes) differ by less
/// than the bound measured when the quadrature was written, with a margin
/// (on this 24-pixel sphere most pixels span a sharp lobe or the sun's glint,
/// so 64 sub-pixel positions leave noise that the 64 x 64 sphere of
/// docs/BENCHMARKS.md does not have: p99 0.32 there at 64 samples); and the
/// quadrature's frame against the Monte Carlo frame (the mean of four seeds
/// at 256 samples: no code of the maps) over the pixels inside the
/// silhouette: summed luminance within 2 %, chromaticity of the sum within
/// 0.003, CIEDE2000 mean < 2.5 (mostly the Monte Carlo frame's noise).
#[test]
fn quadrature_is_quiet_and_agrees_with_monte_carlo() {
    let sky = || Environment::Sky(Box::new(Sky::new(25.0, 120.0, 3.0, 1.0)));
    let eye = [0.0, 0.6, 2.6];
    let q = EnvEstimator::Quadrature;
    // The same sub-pixel positions in both: the directions' noise alone (the
    // positions' is large on this small sphere, whose sun glint is a fraction
    // of a pixel).
    let at = |seed| Options {
        samples: 64,
        seed,
        estimator: q,
        subpixel_seed: Some(9),
        ..Default::default()
    };
    let a = sphere_with(sky(), 24, eye, &at(1));
    let b = sphere_with(sky(), 24, eye, &at(2));
    let d = compare_linear(&a, &b).unwrap();
    eprintln!("quadrature, 24 x 24, 64 samples, seed 1 vs 2: {d}");
    assert!(d.pixels > 150, "{d}");
    assert!(d.mean < Q_MEAN_BOUND && d.p99 < Q_P99_BOUND, "{d}");
    let mc: Vec<LinearImage> = (11..15)
        .map(|seed| sphere_under(sky(), 24, eye, 256, seed, EnvEstimator::MonteCarlo))
        .collect();
    let m = sunbeam_raster::linear::mean_of(&mc).unwrap();
    // Interior pixels (all eight neighbours lit): at the silhouette the Monte
    // Carlo estimate still has fireflies at 1024 samples (grazing views).
    let interior = sunbeam_raster::linear::interior_pixels(&[&m]);
    let xyz = |p: [f32; 3]| colour::linear_srgb_to_xyz(p.map(f64::from));
    let sums = |img: &LinearImage| {
        let mut s = [0.0; 3];
        for &i in &interior {
            let v = xyz(img.rgb[i]);
            for c in 0..3 {
                s[c] += v[c];
            }
        }
        s
    };
    let (sq, sm) = (sums(&a), sums(&m));
    let xy = |v: [f64; 3]| [v[0] / (v[0] + v[1] + v[2]), v[1] / (v[0] + v[1] + v[2])];
    let (cq, cm) = (xy(sq), xy(sm));
    let de: Vec<f64> = interior
        .iter()
        .map(|&i| colour::ciede2000_xyz(xyz(a.rgb[i]), xyz(m.rgb[i])))
        .collect();
    let mean_de = de.iter().sum::<f64>() / de.len() as f64;
    eprintln!(
        "quadrature vs Monte Carlo over {} interior pixels: Y ratio {:.4}, xy {cq:.4?} vs {cm:.4?}, CIEDE2000 mean {mean_de:.2}",
        interior.len(),
        sq[1] / sm[1],
    );
    assert!(interior.len() > 100, "{} interior pixels", interior.len());
    assert!(
        (sq[1] / sm[1] - 1.0).abs() < 0.02,
        "Y {} vs {}",
        sq[1],
        sm[1]
    );
    assert!((cq[0] - cm[0]).abs() < 0.003 && (cq[1] - cm[1]).abs() < 0.003);
    // The Monte Carlo frame's own noise is ~1.5 here.
    assert!(mean_de < 2.5, "{mean_de}");
}

/// Bounds of [`quadrature_is_quiet_and_agrees_with_monte_carlo`]'s seed-to-seed
/// noise at held sub-pixel positions: measured 0.120 and 0.435 with the
/// absolute gain, exact Fresnel once and `R_U` (0.49 and 2.28 before,
/// 2026-11-25, at 25 times the luminance), with a margin of 25 %.
const Q_MEAN_BOUND: f64 = 0.15;
const Q_P99_BOUND: f64 = 0.55;

/// `converge::render_converged` (docs/EVAL.md "A converged reference") on
/// the sky-lit sphere of [`seed_to_seed_noise_of_a_sky_lit_sphere`] under the
/// quadrature: two seeds' converged frames agree far better than two plain
/// frames of 256 samples, and each agrees with the brute-force frame (the
/// mean of two seeds at 1024 samples, no adaptivity) to about its target;
/// the interior closes at the first level (fewer samples than the edge).
#[test]
fn converged_frames_agree_across_seeds() {
    use sunbeam_raster::converge::{render_converged, Converge};
    let sky = || Environment::Sky(Box::new(Sky::new(25.0, 120.0, 3.0, 1.0)));
    let eye = [0.0, 0.6, 2.6];
    let (n, dx) = (64usize, 50e-9);
    let pack = pack_of(n, dx, &ridges(n, dx, 1.3e-6, 420e-9), Model::Window);
    let (mut scene, mesh) = fixtures::sphere_scene([24, 24]);
    scene.lights.clear();
    scene.camera.eye = eye;
    scene.camera.target = [0.0, 0.0, 0.0];
    let mut p = fixtures::prepared(scene, mesh, Some(pack));
    p.environment = Some(Arc::new(sky()));
    let t0 = std::time::Instant::now();
    let c = Converge {
        de: 0.3,
        max_samples: 1024,
        max_seeds: 6,
        ..Default::default()
    };
    let conv = |seed| {
        let o = Options {
            samples: 16,
            seed,
            ..Default::default()
        };
        render_converged(&p, &o, c).unwrap()
    };
    let (a, b) = (conv(1), conv(2));
    let t_conv = t0.elapsed().as_secs_f64();
    let plain = |seed, samples| {
        let o = Options {
            samples,
            seed,
            ..Default::default()
        };
        render_prepared_linear(&p, &o).unwrap()
    };
    let t1 = std::time::Instant::now();
    let (p1, p2) = (plain(1, 256), plain(2, 256));
    let t_plain = t1.elapsed().as_secs_f64();
    let truth =
        sunbeam_raster::linear::mean_of(&(11..13).map(|s| plain(s, 1024)).collect::<Vec<_>>())
            .unwrap();
    let d_conv = compare_linear(&a.image, &b.image).unwrap();
    let d_plain = compare_linear(&p1, &p2).unwrap();
    let (da, db) = (
        compare_linear(&a.image, &truth).unwrap(),
        compare_linear(&b.image, &truth).unwrap(),
    );
    eprintln!(
        "converged seeds 1 vs 2: {d_conv} ({t_conv:.1} s; samples mean {:.0} / {:.0}, max {}, open {} / {}, estimate p99 {:.3})\n\
         plain 256 seeds 1 vs 2: {d_plain} ({t_plain:.1} s)\nconverged vs 2 x 1024: {da}; {db}",
        a.samples_mean, b.samples_mean, a.samples_max, a.open, b.open, a.estimate_p99
    );
    assert!(d_conv.pixels > 150, "{d_conv}");
    assert!(
        d_conv.p99 < 0.5 * d_plain.p99,
        "converged {d_conv} vs plain {d_plain}"
    );
    assert!(
        a.samples_mean < 0.5 * a.samples_max as f64,
        "samples mean {} max {}",
        a.samples_mean,
        a.samples_max
    );
    for d in [da, db] {
        assert!(d.p99 < CONVERGED_P99, "against the brute-force frame: {d}");
    }
}

/// Bound of [`converged_frames_agree_across_seeds`] against the brute-force
/// frame (whose own two seeds leave it some noise): measured 0.261 and 0.423
/// (2026-12-02), plus 25 %.
const CONVERGED_P99: f64 = 0.53;
