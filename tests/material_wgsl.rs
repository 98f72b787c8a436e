//! The skin's WGSL functions (shaders/material.wgsl: `sb_fresnel`, `sb_gain`,
//! `sb_masking`, `sb_base_transmission`, `sb_frame`), run in a compute pass on
//! the GPU (lavapipe in CI), against the float64 ones they port
//! (`sunbeam_optics::gain`, `sunbeam_optics::masking`,
//! `sunbeam_raster::shade::frame`) over random direction pairs, grazing ones
//! included (cos down to 1e-4), random indices, both normalisations and random
//! (anisotropic, or off) slopes and random energy bounds (or none): relative error below 1e-4 wherever the value
//! is above 1e-6. The shader is the player's own module
//! (`renderer::MATERIAL_WGSL`, the file the player and the export begin with)
//! plus a small entry point, not a copy.

mod gpu;

use gpu::{compute, gpu};
use sunbeam_common::rng::SplitMix64;
use sunbeam_optics::energy::EnergyBound;
use sunbeam_optics::gain::{self, Material, Reflectance};
use sunbeam_optics::masking::Masking;
use sunbeam_render::renderer::MATERIAL_WGSL;
use sunbeam_render::Gpu;

/// Random cases besides the fixed ones.
const RANDOM: usize = 12_000;
/// Relative error bound, for values above [`FLOOR`] (absolute below it).
const REL: f64 = 1e-4;
const FLOOR: f64 = 1e-6;

const ENTRY: &str = r#"
struct Case {
    wi: vec4<f32>,
    wr: vec4<f32>,
    normal: vec4<f32>,
    tangent: vec4<f32>,
    // ior, norm, slope x, slope y
    skin: vec4<f32>,
    energy: mat4x4<f32>,
};

struct Out {
    // sb_fresnel(wi.z), sb_gain, sb_masking, sb_base_transmission(wi.z)
    vals: vec4<f32>,
    t: vec4<f32>,
    b: vec4<f32>,
    n: vec4<f32>,
};

fn run_case(c: Case) -> Out {
    let skin = SbSkin(c.skin.x, c.skin.y, c.skin.zw, c.energy);
    let f = sb_frame(c.normal.xyz, c.tangent.xyz);
    var o: Out;
    o.vals = vec4<f32>(
        sb_fresnel(c.wi.z, skin.ior),
        sb_gain(c.wi.xyz, c.wr.xyz, skin),
        sb_masking(c.wi.xyz, c.wr.xyz, skin.slope),
        sb_base_transmission(c.wi.z, skin.ior, true),
    );
    o.t = vec4<f32>(f[0], 0.0);
    o.b = vec4<f32>(f[1], 0.0);
    o.n = vec4<f32>(f[2], 0.0);
    return o;
}
"#;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Case {
    wi: [f32; 4],
    wr: [f32; 4],
    normal: [f32; 4],
    tangent: [f32; 4],
    skin: [f32; 4],
    /// The energy bound's table (`EnergyBound::columns`).
    energy: [[f32; 4]; 4],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Out {
    vals: [f32; 4],
    t: [f32; 4],
    b: [f32; 4],
    n: [f32; 4],
}

/// A unit direction at polar cosine `c` and azimuth `phi`.
fn dir(c: f64, phi: f64) -> [f64; 3] {
    let s = (1.0 - c * c).max(0.0).sqrt();
    [s * phi.cos(), s * phi.sin(), c]
}

/// A polar cosine: half the draws log-uniform over [1e-4, 1] (grazing), half uniform.
fn cosine(r: &mut SplitMix64) -> f64 {
    if r.unit() < 0.5 {
        10f64.powf(-4.0 * r.unit())
    } else {
        r.unit().max(1e-4)
    }
}

fn f32x3(v: [f64; 3]) -> [f32; 3] {
    v.map(|x| x as f32)
}

/// The GPU's input as float64 (what the reference evaluates), made unit in
/// float64: the float64 functions assume unit directions.
fn unit64(v: [f32; 3]) -> [f64; 3] {
    let d = v.map(f64::from);
    let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
    d.map(|x| x / l)
}

fn v4(v: [f32; 3], w: f32) -> [f32; 4] {
    [v[0], v[1], v[2], w]
}

/// The cases: fixed grazing ones (exact mirror pairs, nearly opposite, one
/// grazing direction, normal incidence) and random ones.
fn cases() -> Vec<Case> {
    let mut r = SplitMix64::new(0x5EED_F00D);
    let mut out = Vec::new();
    let mut push = |r: &mut SplitMix64, wi: [f64; 3], wr: [f64; 3]| {
        let ior = match (r.unit() * 4.0) as u32 {
            0 => 1.5,
            1 => 1.33,
            2 => 2.4,
            _ => 1.01 + 2.99 * r.unit(),
        };
        let mat = Material {
            ior,
            reflectance: if r.unit() < 0.5 {
                Reflectance::Absolute
            } else {
                Reflectance::Relative
            },
            ..Default::default()
        };
        let slope = match (r.unit() * 4.0) as u32 {
            0 => [0.0, 0.0],
            1 => [0.02 + r.unit(), 0.0],
            _ => [0.02 + r.unit(), 0.02 + r.unit()],
        };
        // A frame: any normal scaled (interpolated normals are not unit), an
        // orientation near its tangent plane (baked orientations are in it).
        let n = dir(2.0 * r.unit() - 1.0, std::f64::consts::TAU * r.unit());
        let a = dir(2.0 * r.unit() - 1.0, std::f64::consts::TAU * r.unit());
        let d = n[0] * a[0] + n[1] * a[1] + n[2] * a[2];
        let k = 0.5 * (2.0 * r.unit() - 1.0);
        let tangent = [0, 1, 2].map(|i| a[i] - d * n[i] + k * n[i]);
        let scale = 0.5 + 1.5 * r.unit();
        // Half the cases with an energy bound: b from 0.02 to 0.1 (the
        // factor is below 1 at cos(theta_r) below b).
        let mut energy = EnergyBound::OFF;
        if r.unit() < 0.5 {
            for b in energy.b.iter_mut() {
                *b = (0.02 + 0.08 * r.unit()) as f32;
            }
        }
        out.push(Case {
            wi: v4(f32x3(wi), 0.0),
            wr: v4(f32x3(wr), 0.0),
            normal: v4(f32x3(n.map(|x| x * scale)), 0.0),
            tangent: v4(f32x3(tangent), 0.0),
            skin: [
                mat.ior as f32,
                mat.norm() as f32,
                slope[0] as f32,
                slope[1] as f32,
            ],
            energy: energy.columns(),
        });
    };
    // Exact mirror pairs (specular; negating x and y is exact in float32) at
    // every cosine down to 1e-4, and nearly opposite grazing pairs.
    for k in 0..=40 {
        let c = 10f64.powf(-4.0 * k as f64 / 40.0);
        let phi = 0.37 * k as f64;
        let wi = dir(c, phi);
        push(&mut r, wi, [-wi[0], -wi[1], wi[2]]);
        push(&mut r, wi, dir(c, phi + std::f64::consts::PI + 0.01));
        push(&mut r, wi, dir(1e-4, phi + 1.0));
        push(&mut r, dir(1.0, 0.0), dir(c, phi));
        push(&mut r, wi, wi);
    }
    for _ in 0..RANDOM {
        let wi = dir(cosine(&mut r), std::f64::consts::TAU * r.unit());
        let wr = dir(cosine(&mut r), std::f64::consts::TAU * r.unit());
        push(&mut r, wi, wr);
    }
    out
}

fn run(gpu: &Gpu, cases: &[Case]) -> Vec<Out> {
    compute(
        gpu,
        "material test",
        &format!("{MATERIAL_WGSL}\n{ENTRY}"),
        cases,
    )
}

/// The worst relative error of one quantity, and how many values it checked.
#[derive(Default)]
struct Worst {
    rel: f64,
    at: String,
    checked: usize,
}

impl Worst {
    fn add(&mut self, gpu: f64, reference: f64, what: impl Fn() -> String) {
        let err = (gpu - reference).abs() / reference.abs().max(FLOOR);
        if reference.abs() > FLOOR {
            self.checked += 1;
        }
        // A NaN stays the worst.
        if err > self.rel || err.is_nan() {
            self.rel = err;
            self.at = format!("{}: gpu {gpu:e} vs float64 {reference:e}", what());
        }
    }
}

#[test]
fn material_functions_match_float64() {
    let Some(gpu) = gpu() else { return };
    let cases = cases();
    let outs = run(&gpu, &cases);
    let names = [
        "sb_fresnel",
        "sb_gain",
        "sb_masking",
        "sb_base_transmission",
        "sb_frame",
    ];
    let mut worst: Vec<Worst> = names.iter().map(|_| Worst::default()).collect();
    for (i, (c, o)) in cases.iter().zip(&outs).enumerate() {
        let wi32 = [c.wi[0], c.wi[1], c.wi[2]];
        let wr32 = [c.wr[0], c.wr[1], c.wr[2]];
        let (wi, wr) = (unit64(wi32), unit64(wr32));
        let ior = f64::from(c.skin[0]);
        let mat = Material {
            ior,
            reflectance: if c.skin[1] == 1.0 {
                Reflectance::Absolute
            } else {
                Reflectance::Relative
            },
            energy: EnergyBound {
                b: std::array::from_fn(|k| c.energy[k / 4][k % 4]),
            },
        };
        let slope = [f64::from(c.skin[2]), f64::from(c.skin[3])];
        let what = || format!("case {i}: wi {wi32:?} wr {wr32:?} skin {:?}", c.skin);
        // Fresnel and the transmission at the float32 cosine itself.
        let ci = f64::from(c.wi[2]);
        worst[0].add(o.vals[0].into(), gain::fresnel(ci, ior), what);
        worst[1].add(o.vals[1].into(), gain::g(wi, wr, mat), what);
        worst[2].add(o.vals[2].into(), Masking::smith(slope).factor(wi, wr), what);
        worst[3].add(o.vals[3].into(), mat.transmission(ci), what);
        // The frame: each vector's error relative to its length (1).
        let normal = [c.normal[0], c.normal[1], c.normal[2]].map(f64::from);
        let tangent = [c.tangent[0], c.tangent[1], c.tangent[2]].map(f64::from);
        let (t, b, n) = sunbeam_raster::shade::frame(normal, tangent).expect("a frame");
        for (g, r) in [(o.t, t), (o.b, b), (o.n, n)] {
            let e = (0..3)
                .map(|k| (f64::from(g[k]) - r[k]).powi(2))
                .sum::<f64>()
                .sqrt();
            worst[4].add(1.0 + e, 1.0, what);
        }
    }
    let mut failed = Vec::new();
    for (name, w) in names.iter().zip(&worst) {
        eprintln!(
            "{name}: worst relative error {:.2e} over {} values above {FLOOR:e} ({})",
            w.rel, w.checked, w.at
        );
        if w.rel >= REL || w.rel.is_nan() {
            failed.push(format!("{name}: {:.2e} at {}", w.rel, w.at));
        }
    }
    assert!(cases.len() >= 10_000);
    assert!(worst[1].checked > 9_000, "G checked at too few pairs");
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The player's shader and the export begin with the module tested above.
#[test]
fn the_player_and_the_export_use_this_module() {
    assert!(sunbeam_render::renderer::SHADER.starts_with(MATERIAL_WGSL));
    assert!(sunbeam_render::export::SOURCE.starts_with(MATERIAL_WGSL));
}
