//! The sun's G over its disc as a plane (shaders/sun_gain.wgsl
//! `sb_sun_gain_plane`, `sb_sun_gain_at`: what the player's first frame and
//! the export's `sunbeam_shade_sun` take for the disc's 16 points wherever
//! the disc's centre is at least `SB_SUN_PLANE_COS` above the surface's
//! horizon), run in a compute pass on
//! the GPU (lavapipe in CI), against each point's own G with the masking in
//! float64 (`sunbeam_optics::gain::g`, `sunbeam_optics::masking`), with the
//! sky's disc (`sunbeam_light::sky::SUN_RADIUS_RAD`), random frames, views
//! (grazing ones included), indices and masking slopes, and the disc's
//! centre from just above the switch (6 degrees) to the zenith: the plane's
//! error isolated from the maps, the cells and the pixel, where the sky
//! tests against the reference only see it inside their bounds. The shader
//! is the player's and the export's own files (`renderer::SUN_GAIN_WGSL`
//! after `MATERIAL_WGSL` and `ENV_TABLE_WGSL`) plus an entry point.

mod gpu;

use gpu::{compute, gpu};
use sunbeam_common::rng::SplitMix64;
use sunbeam_optics::gain::{self, Material, Reflectance};
use sunbeam_optics::masking::Masking;
use sunbeam_render::renderer::{ENV_TABLE_WGSL, MATERIAL_WGSL, SUN_GAIN_WGSL};

/// Cases per height of the disc's centre.
const PER_HEIGHT: usize = 400;
/// Heights of the disc's centre above the surface's horizon (cosines): at
/// the switch (0.1) and above it, where the plane is taken.
const HEIGHTS: [f64; 9] = [0.1002, 0.101, 0.105, 0.12, 0.16, 0.25, 0.45, 0.75, 1.0];
/// Bounds of each point's G from the plane against its own, relative: at
/// most REL, at most SECOND times `(r / cos theta_i)^2` (second order in the
/// disc's radius r, [`second_order`]), the disc's mean at most MEAN.
/// Measured (2026-12-06, lavapipe; the worst at a grazing view, where G's
/// `1 / (cos theta_i + cos theta_r)^2` changes fastest): 1.27e-2 at the
/// switch, 2.0e-3 from 14 degrees, 8e-5 at the zenith; 5.9 `(r / cos
/// theta_i)^2` at every height; the mean 1.8e-3. A plane without its slopes
/// (the centre's G for every point) is off by 9 % at the switch. Plus 25 %.
const REL: f64 = 0.016;
const SECOND: f64 = 7.4;
const MEAN: f64 = 2.3e-3;

const ENTRY: &str = r#"
struct Case {
    // the disc's centre (world, unit); w: the cap's cosine
    c: vec4<f32>,
    // the disc's axes (unit, perpendicular to c and to each other)
    st: vec4<f32>,
    sb: vec4<f32>,
    // the surface's frame (orthonormal)
    t: vec4<f32>,
    b: vec4<f32>,
    n: vec4<f32>,
    // the local view
    wr: vec4<f32>,
    // ior, norm, slope x, slope y
    skin: vec4<f32>,
};

struct Out {
    plane: vec4<f32>,
    // G from the plane at the disc's 16 points (env_sun_disc's spiral)
    g: array<vec4<f32>, 4>,
    // the points' world directions (x, y, z; w unused), for the reference
    d: array<vec4<f32>, 16>,
};

fn run_case(c: Case) -> Out {
    let skin = SbSkin(c.skin.x, c.skin.y, c.skin.zw, mat4x4<f32>());
    var o: Out;
    o.plane = sb_sun_gain_plane(c.c.xyz, c.st.xyz, c.sb.xyz, c.c.w, c.t.xyz, c.b.xyz, c.n.xyz, c.wr.xyz, skin);
    for (var k = 0u; k < 16u; k = k + 1u) {
        let d = sb_sun_disc_dir(c.c.xyz, c.st.xyz, c.sb.xyz, c.c.w, (f32(k) + 0.5) / SB_SUN_POINTS, f32(k) * SB_GOLDEN);
        o.g[k / 4u][k % 4u] = sb_sun_gain_at(o.plane, d, c.st.xyz, c.sb.xyz);
        o.d[k] = vec4<f32>(d, 0.0);
    }
    return o;
}
"#;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Case {
    c: [f32; 4],
    st: [f32; 4],
    sb: [f32; 4],
    t: [f32; 4],
    b: [f32; 4],
    n: [f32; 4],
    wr: [f32; 4],
    skin: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Out {
    plane: [f32; 4],
    g: [[f32; 4]; 4],
    d: [[f32; 4]; 16],
}

type V = [f64; 3];

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn unit(a: V) -> V {
    let l = dot(a, a).sqrt();
    a.map(|x| x / l)
}

/// A unit direction at polar cosine `c` and azimuth `phi`.
fn dir(c: f64, phi: f64) -> V {
    let s = (1.0 - c * c).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), c]
}

/// `x t + y b + z n`.
fn world(l: V, f: [V; 3]) -> V {
    [0, 1, 2].map(|i| l[0] * f[0][i] + l[1] * f[1][i] + l[2] * f[2][i])
}

fn v4(v: V) -> [f32; 4] {
    [v[0] as f32, v[1] as f32, v[2] as f32, 0.0]
}

/// An orthonormal frame about unit `n`, turned by `a` about it.
fn frame_about(n: V, a: f64) -> [V; 3] {
    let up = if n[1].abs() > 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let t0 = unit(cross(up, n));
    let b0 = cross(n, t0);
    let t = [0, 1, 2].map(|i| a.cos() * t0[i] + a.sin() * b0[i]);
    [t, cross(n, t), n]
}

/// The cases: per height of the disc's centre, random surface frames,
/// azimuths of the sun, views (half grazing: cos log-uniform down to 1e-3),
/// indices, normalisations and masking slopes (a quarter off).
fn cases(cos_cap: f32) -> Vec<(f64, Case)> {
    let mut r = SplitMix64::new(0x5_0B_1A_7E);
    let mut out = Vec::new();
    for &h in &HEIGHTS {
        for _ in 0..PER_HEIGHT {
            let tau = std::f64::consts::TAU;
            let n = dir(2.0 * r.unit() - 1.0, tau * r.unit());
            let f = frame_about(n, tau * r.unit());
            let c = world(dir(h, tau * r.unit()), f);
            let disc = frame_about(c, tau * r.unit());
            let cr = if r.unit() < 0.5 {
                10f64.powf(-3.0 * r.unit())
            } else {
                r.unit().max(1e-3)
            };
            let wr = dir(cr, tau * r.unit());
            let ior = [1.5, 1.33, 2.4, 1.01 + 2.99 * r.unit()][(r.unit() * 4.0) as usize];
            let norm = if r.unit() < 0.5 { 1.0 } else { gain::f0(ior) };
            let slope = match (r.unit() * 4.0) as u32 {
                0 => [0.0, 0.0],
                1 => [0.02 + r.unit(), 0.0],
                _ => [0.02 + r.unit(), 0.02 + r.unit()],
            };
            let skin = [ior as f32, norm as f32, slope[0] as f32, slope[1] as f32];
            out.push((h, case(c, cos_cap, disc, f, wr, skin)));
        }
    }
    out
}

/// A case: the disc about `c` (cap cosine `cos_cap`, axes the first two of
/// `disc`), the surface's frame `f`, the local view `wr` and the skin (ior,
/// norm, slopes).
fn case(c: V, cos_cap: f32, disc: [V; 3], f: [V; 3], wr: V, skin: [f32; 4]) -> Case {
    let mut cc = v4(c);
    cc[3] = cos_cap;
    Case {
        c: cc,
        st: v4(disc[0]),
        sb: v4(disc[1]),
        t: v4(f[0]),
        b: v4(f[1]),
        n: v4(f[2]),
        wr: v4(wr),
        skin,
    }
}

/// G with the masking in float64 at the world direction `d` for a case.
fn gain64(c: &Case, d: V) -> f64 {
    let f = |v: [f32; 4]| [v[0], v[1], v[2]].map(f64::from);
    let d = unit(d);
    let wi = unit([dot(d, f(c.t)), dot(d, f(c.b)), dot(d, f(c.n))]);
    let wr = unit(f(c.wr));
    let mat = Material {
        ior: f64::from(c.skin[0]),
        reflectance: if c.skin[1] == 1.0 {
            Reflectance::Absolute
        } else {
            Reflectance::Relative
        },
        ..Default::default()
    };
    let slope = [f64::from(c.skin[2]), f64::from(c.skin[3])];
    gain::g(wi, wr, mat) * Masking::smith(slope).factor(wi, wr)
}

#[test]
fn the_suns_gain_plane_matches_each_points_gain() {
    let Some(gpu) = gpu() else { return };
    let cos_cap = sunbeam_light::sky::SUN_RADIUS_RAD.cos() as f32;
    let cases = cases(cos_cap);
    let input: Vec<Case> = cases.iter().map(|c| c.1).collect();
    let src = format!("{MATERIAL_WGSL}\n{ENV_TABLE_WGSL}\n{SUN_GAIN_WGSL}\n{ENTRY}");
    let outs: Vec<Out> = compute(&gpu, "sun gain test", &src, &input);
    // per height: worst relative error of a point's G, of the disc's mean,
    // of the centre's G alone (what a plane without its slopes gives), and
    // of a point's G over the plane's second order (r / cos theta_i)^2
    let mut worst = vec![[0.0f64; 4]; HEIGHTS.len()];
    let mut at = vec![String::new(); HEIGHTS.len()];
    let mut checked = 0;
    for (i, ((h, c), o)) in cases.iter().zip(&outs).enumerate() {
        let k = HEIGHTS.iter().position(|x| x == h).unwrap();
        assert_eq!(o.plane[3], 1.0, "case {i} at height {h}: no plane");
        let q = second_order(c);
        let (mut mean, mut mean64) = (0.0, 0.0);
        for p in 0..16 {
            let d = [0, 1, 2].map(|a| f64::from(o.d[p][a]));
            let want = gain64(c, d);
            let got = f64::from(o.g[p / 4][p % 4]);
            mean += got / 16.0;
            mean64 += want / 16.0;
            if want < 1e-6 {
                continue;
            }
            checked += 1;
            let e = (got - want).abs() / want;
            if e > worst[k][0] || e.is_nan() {
                worst[k][0] = e;
                at[k] = format!("case {i} point {p}: plane {got:e} vs float64 {want:e} ({c:?})");
            }
            worst[k][3] = worst[k][3].max(e / q);
            let e0 = (f64::from(o.plane[0]) - want).abs() / want;
            worst[k][2] = worst[k][2].max(e0);
        }
        if mean64 > 1e-6 {
            worst[k][1] = worst[k][1].max((mean - mean64).abs() / mean64);
        }
    }
    let mut failed = Vec::new();
    for (k, h) in HEIGHTS.iter().enumerate() {
        let deg = h.asin().to_degrees();
        eprintln!(
            "centre {deg:.2} deg above the horizon: worst relative error of a point's G {:.2e} ({:.3} (r / cos theta_i)^2), of the disc's mean {:.2e}; the centre's G alone {:.2e} ({})",
            worst[k][0], worst[k][3], worst[k][1], worst[k][2], at[k]
        );
        if !(worst[k][0] < REL && worst[k][3] < SECOND && worst[k][1] < MEAN) {
            failed.push(format!(
                "height {h}: {:.2e} ({:.3} q^2, mean {:.2e}) at {}",
                worst[k][0], worst[k][3], worst[k][1], at[k]
            ));
        }
    }
    // The cases reach where the disc's G changes: a plane without its
    // slopes (the centre's G for every point) would fail.
    assert!(
        worst[0][2] > 3.0 * REL,
        "the cases at the switch do not tell a plane from a constant: {:.2e}",
        worst[0][2]
    );
    assert!(
        checked > 9 * PER_HEIGHT * 16 / 2,
        "too few points checked: {checked}"
    );
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The plane's error is second order in the disc's radius r over the
/// centre's height above the surface's horizon, `cos theta_i`: G changes on
/// that scale (its `1 / (cos theta_i + cos theta_r)^2` where the view is
/// grazing, the masking's `Lambda(wi)`). `(r / cos theta_i)^2` for a case.
fn second_order(c: &Case) -> f64 {
    let f = |v: [f32; 4]| [v[0], v[1], v[2]].map(f64::from);
    let ci = dot(unit(f(c.c)), f(c.n));
    (sunbeam_light::sky::SUN_RADIUS_RAD / ci).powi(2)
}

/// Below the switch (and at and below the horizon) the plane is off (w 0:
/// each point takes its own G, environment.wgsl env_sun_disc).
#[test]
fn below_the_switch_each_point_takes_its_own_gain() {
    let Some(gpu) = gpu() else { return };
    let cos_cap = sunbeam_light::sky::SUN_RADIUS_RAD.cos() as f32;
    let n: V = [0.0, 0.0, 1.0];
    let f = frame_about(n, 0.3);
    let mut input = Vec::new();
    let heights = [-0.2, 0.0, 0.02, 0.06, 0.0995, 0.1005, 0.3];
    for &h in &heights {
        let c = world(dir(h, 0.7), f);
        let disc = frame_about(c, 1.1);
        input.push(case(
            c,
            cos_cap,
            disc,
            f,
            dir(0.5, 2.0),
            [1.5, 1.0, 0.3, 0.3],
        ));
    }
    let src = format!("{MATERIAL_WGSL}\n{ENV_TABLE_WGSL}\n{SUN_GAIN_WGSL}\n{ENTRY}");
    let outs: Vec<Out> = compute(&gpu, "sun gain switch", &src, &input);
    for (h, o) in heights.iter().zip(&outs) {
        let want = if *h >= 0.1 { 1.0 } else { 0.0 };
        assert_eq!(o.plane[3], want, "height {h}: {:?}", o.plane);
    }
}

/// The player's shader and the export hold these files as tested here.
#[test]
fn the_player_and_the_export_use_these_files() {
    for s in [
        sunbeam_render::renderer::SHADER,
        sunbeam_render::export::SOURCE,
    ] {
        assert!(s.contains(ENV_TABLE_WGSL) && s.contains(SUN_GAIN_WGSL));
    }
}
