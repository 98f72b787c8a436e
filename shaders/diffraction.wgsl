// Sunbeam diffraction shader (PHYSICS.md 1-3, docs/PLAY.md "Shading").
//
// Per fragment: local frame (t, b, n) with b = n x t (on a mesh with scale
// maps, the frame the maps give: shaders/scales.wgsl, frame_at), (u, v, w) = -wi - wr,
// for each wavelength sample that can reach a stored frequency:
//   t_l = 2 pi w H / lambda, c_n(t_l) (Chebyshev: i^n eps_n J_n by Miller's
//   backward recurrence; Taylor: (i t)^n / n!), only the terms |t_l| needs,
//   amplitude = sum over Kaiser-Bessel taps of weight * sum_n c_n F_n[tap]
//   (window model, squared after the sum; in the direct mode with the
//   window's exact grazing term, PHYSICS.md 2b: the amplitude's derivatives
//   along u and v from the kernel's derivative, R_U, as
//   sunbeam_pack::Pack::shading_reflectance) or power = sum of weight * |sum_n c_n F_n|^2
//   (tiled model), exactly as sunbeam_pack::Pack::reflectance;
// XYZ = G * G2 * sum_l R_l weight_l (the skin's gain and Smith masking:
// shaders/material.wgsl, prepended); linear sRGB; diffuse blend
// dw * base * cos_i * (1 - F(th_i)) + (1 - dw) * rgb (the base alone, cos_i,
// without a pack); exposure; tone curve; sRGB OETF.
//
// Modes: 0 = default: the same sum precomputed per pack, T(u, v, w) (XYZ
// without G), read from the response map (crates/sunbeam-response: a 3D texture
// over a polar grid, docs/PACK_FORMAT.md "Response map") with trilinear samples
// averaged over the pixel's footprint; or, without a map, from the Cartesian
// response table (crates/sunbeam-render/src/table.rs, `--mode table`); 3 = direct (the sum above per fragment);
// 1 = thesis (fixed term count, 5 nm samples, nearest texel, no interpolation);
// 2 = Lambert (base colour only). Under a scene environment the default mode
// adds shaders/environment.wgsl's estimate (group 2).

const MAX_TERMS: u32 = 64u;
const MAX_TAPS: u32 = 16u;
const TAU: f32 = SB_TAU;

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xyz: direction towards the light (unit), w: intensity
    lights: array<vec4<f32>, 4>,
    // rgb: the light's linear sRGB colour (scene lights[].color; it tints the
    // light's RGB contribution), w unused
    light_colors: array<vec4<f32>, 4>,
    // rows of the XYZ -> linear sRGB matrix
    xyz_to_rgb: array<vec4<f32>, 3>,
    background: vec4<f32>,
    n_lights: u32,
    mode: u32,
    curve: u32,
    // 0: write display values (UNORM/float target); 1: write their linear value (sRGB target);
    // 2: write linear light times the exposure (offscreen; the display transform follows on the CPU)
    output: u32,
    exposure_scale: f32,
    n_lambda: u32,
    // samples per pixel of the colour target (1 or 4)
    msaa: u32,
    _g0: u32,
};

struct Material {
    // rgb: linear base colour, w: diffuse weight
    base: vec4<f32>,
    has_pack: u32,
    basis: u32,   // 0 Chebyshev, 1 Taylor
    model: u32,   // 0 window (Kaiser-Bessel on amplitudes), 1 tiled (Gaussian on power)
    taps: u32,
    crop_w: u32,
    crop_h: u32,
    kx: i32,
    ky: i32,
    terms: u32,       // terms stored (capped at MAX_TERMS)
    fixed_terms: u32, // thesis mode: use exactly this many; 0 = per-fragment from the bound
    n_table: u32,     // entries in term_table
    // 1: the mesh's scale maps are bound (group 1, bindings 6 and 7) and
    // perturb the frame (shaders/scales.wgsl)
    scales_on: u32,
    // bins per (cycle per micrometre), x and y
    bin_scale_um: vec2<f32>,
    half_range_um: f32,
    beta: f32,
    sigma_bins: vec2<f32>,
    kb_norm: f32,      // beta / (W sinh beta)
    table_dt: f32,     // |t| step of term_table
    // response table: cells (nu, nv, nw), 1 when present
    tab_nu: u32,
    tab_nv: u32,
    tab_nw: u32,
    tab_on: u32,
    // u, v of cell 0 (= -2), their steps; w of cell 0 (= -2), its step
    tab_u0: f32,
    tab_du: f32,
    tab_dv: f32,
    tab_w0: f32,
    tab_dw: f32,
    // Smith masking (sunbeam_optics::masking): rms slopes along t and b; 0 = off
    mask_sx: f32,
    mask_sy: f32,
    // the skin (sunbeam_optics::gain::Material): refractive index, and what G
    // is divided by (1 absolute, F(0) relative; Material::norm)
    ior: f32,
    // response map (sunbeam-response): 1 when bound; texels (angle, radius, s);
    // radial warp rho = asinh(r / r0) / rho_scale; 1 = average over the footprint
    resp_on: u32,
    resp_n_theta: f32,
    resp_n_rho: f32,
    resp_n_s: f32,
    resp_r0: f32,
    resp_rho_scale: f32,
    resp_footprint: u32,
    norm: f32,
    // window model: the coherence window's sigma (manifest window_sigma_m) in
    // um, for R_U in the direct mode; 0 = plain R
    window_sigma_um: f32,
    // the scale maps' wraps (sb_scale_frame): bits 0-1 the normal map's
    // REPEAT along s and t, bits 2-3 the orientation map's
    scales_wrap: u32,
    _s1: f32,
    _s2: f32,
    // the energy bound's table (SbSkin.energy)
    energy: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
// xyz: colour weight of the sample, w: 1 / lambda in 1/um
@group(0) @binding(1) var<storage, read> spectrum: array<vec4<f32>>;

@group(1) @binding(0) var<uniform> mat: Material;
// texel (n, ty, tx) at (n * crop_h + ty) * crop_w + tx, (re, im)
@group(1) @binding(1) var<storage, read> terms: array<vec2<f32>>;
// term_table[i] = terms needed for |t| <= (i + 1) * table_dt
@group(1) @binding(2) var<storage, read> term_table: array<u32>;
// response table, (iw * nv + iv) * nu + iu, xyz
@group(1) @binding(3) var<storage, read> response: array<vec4<f32>>;
// response map: XYZ at texel (angle, radius, s); repeat in angle, clamp elsewhere
@group(1) @binding(4) var resp_tex: texture_3d<f32>;
@group(1) @binding(5) var resp_smp: sampler;
// scale maps (sunbeam-bake --scales): the normal map and the orientation map
// (RG ridge direction, B groove mask), RGBA8 unorm, read by textureLoad
// (shaders/scales.wgsl); 1 x 1 stand-ins when `mat.scales_on` is 0
@group(1) @binding(6) var scale_normal: texture_2d<f32>;
@group(1) @binding(7) var scale_orient: texture_2d<f32>;

struct VsIn {
    @location(0) pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec4<f32>,
    // TEXCOORD_0 and the glTF TANGENT (the UV frame, w = handedness) of a
    // mesh with scale maps (zero otherwise)
    @location(3) uv: vec2<f32>,
    @location(4) uv_tangent: vec4<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec3<f32>,
    @location(3) uv: vec2<f32>,
    @location(4) uv_tangent: vec4<f32>,
};

@vertex
fn vs_main(v: VsIn) -> VsOut {
    var o: VsOut;
    o.clip = g.view_proj * vec4<f32>(v.pos, 1.0);
    o.world = v.pos;
    o.normal = v.normal;
    o.tangent = v.tangent.xyz;
    o.uv = v.uv;
    o.uv_tangent = v.uv_tangent;
    return o;
}

// ---------------------------------------------------------------- series
var<private> coef: array<vec2<f32>, MAX_TERMS>;

// J_0..J_{n-1}(t) into coef[].x by Miller's backward recurrence, exactly as
// sunbeam_pack::series::bessel_j_f32.
fn bessel_j(t: f32, n: u32) {
    let a = abs(t);
    if (a < 1e-4) {
        let half = t / 2.0;
        var term = 1.0;
        for (var k = 0u; k < n; k = k + 1u) {
            if (k > 0u) {
                term = term * half / f32(k);
            }
            coef[k] = vec2<f32>(term, 0.0);
        }
        return;
    }
    for (var k = 0u; k < n; k = k + 1u) {
        coef[k] = vec2<f32>(0.0);
    }
    let mm = max(f32(n), a);
    let m = 2u * u32(ceil((mm + 16.0 + sqrt(40.0 * mm)) / 2.0));
    var jp1 = 0.0;
    var j = 1.0;
    var sum = 2.0; // m is even: 2 J_m
    var k = m;
    loop {
        if (k < 1u) {
            break;
        }
        let jm1 = (2.0 * f32(k) / a) * j - jp1;
        let idx = k - 1u;
        if (idx < n) {
            coef[idx].x = jm1;
        }
        if (idx == 0u) {
            sum = sum + jm1;
        } else if ((idx & 1u) == 0u) {
            sum = sum + 2.0 * jm1;
        }
        jp1 = j;
        j = jm1;
        if (abs(j) > 1e10) {
            j = j * 1e-10;
            jp1 = jp1 * 1e-10;
            sum = sum * 1e-10;
            for (var q = idx; q < n; q = q + 1u) {
                coef[q].x = coef[q].x * 1e-10;
            }
        }
        k = k - 1u;
    }
    let inv = 1.0 / sum;
    for (var q = 0u; q < n; q = q + 1u) {
        var v = coef[q].x * inv;
        if (t < 0.0 && (q & 1u) == 1u) {
            v = -v;
        }
        coef[q].x = v;
    }
}

// c_n(t), n = 0..count-1, into coef[].
fn coefficients(t: f32, count: u32) {
    if (mat.basis == 0u) {
        bessel_j(t, count);
        for (var k = 0u; k < count; k = k + 1u) {
            var e = coef[k].x;
            if (k > 0u) {
                e = 2.0 * e;
            }
            switch (k & 3u) {
                case 0u: { coef[k] = vec2<f32>(e, 0.0); }
                case 1u: { coef[k] = vec2<f32>(0.0, e); }
                case 2u: { coef[k] = vec2<f32>(-e, 0.0); }
                default: { coef[k] = vec2<f32>(0.0, -e); }
            }
        }
    } else {
        var c = vec2<f32>(1.0, 0.0);
        for (var k = 0u; k < count; k = k + 1u) {
            if (k > 0u) {
                let s = t / f32(k);
                c = vec2<f32>(-c.y * s, c.x * s);
            }
            coef[k] = c;
        }
    }
}

// Terms the bound asks for at |t| (never more than stored).
fn terms_needed(at: f32) -> u32 {
    if (mat.fixed_terms > 0u) {
        return min(mat.fixed_terms, mat.terms);
    }
    let i = min(u32(floor(at / mat.table_dt)), mat.n_table - 1u);
    return min(term_table[i], mat.terms);
}

// ---------------------------------------------------------------- kernel
fn bessel_i0(x: f32) -> f32 {
    let q = x * x / 4.0;
    var term = 1.0;
    var sum = 1.0;
    for (var k = 1; k < 60; k = k + 1) {
        let kk = f32(k);
        term = term * q / (kk * kk);
        sum = sum + term;
        if (term < 1e-8 * sum) {
            break;
        }
    }
    return sum;
}

fn tap_weight(d: f32, axis: u32) -> f32 {
    let w = f32(mat.taps);
    if (mat.model == 0u) {
        let r = 2.0 * d / w;
        if (abs(r) >= 1.0) {
            return 0.0;
        }
        return mat.kb_norm * bessel_i0(mat.beta * sqrt(1.0 - r * r));
    }
    let s = mat.sigma_bins[axis];
    return exp(-d * d / (2.0 * s * s));
}

// d tap_weight / d kappa of the window model (sunbeam_pack::kernel::kb_derivative):
// -kb_norm beta^2 (2 r / W) I1(z) / z with I1(z)/z = 1/2 sum_k (z^2/4)^k / (k! (k+1)!).
fn tap_dweight(d: f32) -> f32 {
    let w = f32(mat.taps);
    let r = 2.0 * d / w;
    if (abs(r) >= 1.0) {
        return 0.0;
    }
    let q = mat.beta * mat.beta * (1.0 - r * r) / 4.0;
    var term = 1.0;
    var sum = 1.0;
    for (var k = 1; k < 60; k = k + 1) {
        let kk = f32(k);
        term = term * q / (kk * (kk + 1.0));
        sum = sum + term;
        if (term < 1e-8 * sum) {
            break;
        }
    }
    return -mat.kb_norm * mat.beta * mat.beta * (2.0 * r / w) * 0.5 * sum;
}

var<private> wx: array<f32, MAX_TAPS>;
var<private> wy: array<f32, MAX_TAPS>;
var<private> dwx: array<f32, MAX_TAPS>;
var<private> dwy: array<f32, MAX_TAPS>;

fn term_at(n: u32, tx: u32, ty: u32) -> vec2<f32> {
    return terms[(n * mat.crop_h + ty) * mat.crop_w + tx];
}

fn cmul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

// R at fractional bin (kappa_x, kappa_y) with coef[0..count] set; with
// `grazing` (the window model's R_U, PHYSICS.md 2b) at (u, v, w) = uvw and
// 1 / lambda = inv_l (1/um): |P + (u dP/du + v dP/dv) / (sigma^2 k^2 |q|^2)|^2
// (sunbeam_optics::grazing::window_reflectance).
fn reflectance(kappa: vec2<f32>, count: u32, grazing: bool, uvw: vec3<f32>, inv_l: f32) -> f32 {
    let taps = i32(mat.taps);
    let k0x = i32(floor(kappa.x)) - taps / 2 + 1;
    let k0y = i32(floor(kappa.y)) - taps / 2 + 1;
    for (var j = 0; j < taps; j = j + 1) {
        let kx = k0x + j;
        if (kx < -mat.kx || kx > mat.kx) {
            wx[j] = 0.0;
            dwx[j] = 0.0;
        } else {
            wx[j] = tap_weight(kappa.x - f32(kx), 0u);
            dwx[j] = select(0.0, tap_dweight(kappa.x - f32(kx)), grazing);
        }
        let ky = k0y + j;
        if (ky < -mat.ky || ky > mat.ky) {
            wy[j] = 0.0;
            dwy[j] = 0.0;
        } else {
            wy[j] = tap_weight(kappa.y - f32(ky), 1u);
            dwy[j] = select(0.0, tap_dweight(kappa.y - f32(ky)), grazing);
        }
    }
    var amp = vec2<f32>(0.0);
    // d amp / d kappa_x, d kappa_y (R_U)
    var ampx = vec2<f32>(0.0);
    var ampy = vec2<f32>(0.0);
    var power = 0.0;
    for (var jy = 0; jy < taps; jy = jy + 1) {
        if (wy[jy] == 0.0 && dwy[jy] == 0.0) {
            continue;
        }
        let ty = u32(k0y + jy + mat.ky);
        for (var jx = 0; jx < taps; jx = jx + 1) {
            if (wx[jx] == 0.0 && dwx[jx] == 0.0) {
                continue;
            }
            let tx = u32(k0x + jx + mat.kx);
            var a = vec2<f32>(0.0);
            for (var n = 0u; n < count; n = n + 1u) {
                a = a + cmul(coef[n], term_at(n, tx, ty));
            }
            let wgt = wx[jx] * wy[jy];
            if (mat.model == 0u) {
                amp = amp + wgt * a;
                ampx = ampx + dwx[jx] * wy[jy] * a;
                ampy = ampy + wx[jx] * dwy[jy] * a;
            } else {
                power = power + wgt * dot(a, a);
            }
        }
    }
    if (mat.model == 0u) {
        if (grazing) {
            // d/du = (d kappa_x / du) d/dkappa_x = -(bin_scale_x / lambda) d/dkappa_x;
            // sigma and k in um, so the factors are dimensionless.
            let q2 = dot(uvw, uvw);
            let k = TAU * inv_l;
            let sk = mat.window_sigma_um * k;
            let c = 1.0 / (sk * sk * q2);
            let a = amp
                + (uvw.x * c * (-mat.bin_scale_um.x * inv_l)) * ampx
                + (uvw.y * c * (-mat.bin_scale_um.y * inv_l)) * ampy;
            return dot(a, a);
        }
        return dot(amp, amp);
    }
    return power;
}

// Thesis mode: the nearest stored texel, no interpolation.
fn reflectance_nearest(kappa: vec2<f32>, count: u32) -> f32 {
    let kx = i32(round(kappa.x));
    let ky = i32(round(kappa.y));
    if (kx < -mat.kx || kx > mat.kx || ky < -mat.ky || ky > mat.ky) {
        return 0.0;
    }
    let tx = u32(kx + mat.kx);
    let ty = u32(ky + mat.ky);
    var a = vec2<f32>(0.0);
    for (var n = 0u; n < count; n = n + 1u) {
        a = a + cmul(coef[n], term_at(n, tx, ty));
    }
    return dot(a, a);
}

// XYZ of the diffraction term (without G) for local directions wi, wr.
fn diffraction_xyz(wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let u = -wi.x - wr.x;
    let v = -wi.y - wr.y;
    let w = -wi.z - wr.z;
    // reachable kappa: within the crop plus half the kernel
    let reach = vec2<f32>(f32(mat.kx), f32(mat.ky)) + 0.5 * f32(mat.taps);
    var xyz = vec3<f32>(0.0);
    for (var l = 0u; l < g.n_lambda; l = l + 1u) {
        let s = spectrum[l];
        let kappa = -vec2<f32>(u, v) * s.w * mat.bin_scale_um;
        if (abs(kappa.x) > reach.x || abs(kappa.y) > reach.y) {
            continue;
        }
        let t = TAU * w * mat.half_range_um * s.w;
        let count = terms_needed(abs(t));
        coefficients(t, count);
        var r: f32;
        if (g.mode == 1u) {
            r = reflectance_nearest(kappa, count);
        } else {
            let grazing = mat.model == 0u && mat.window_sigma_um > 0.0;
            r = reflectance(kappa, count, grazing, vec3<f32>(u, v, w), s.w);
        }
        xyz = xyz + r * s.xyz;
    }
    return xyz;
}

fn response_xyz(wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let uvw = -wi - wr;
    let nmax = vec3<f32>(f32(mat.tab_nu - 1u), f32(mat.tab_nv - 1u), f32(mat.tab_nw - 1u));
    let p = clamp(
        (uvw - vec3<f32>(mat.tab_u0, mat.tab_u0, mat.tab_w0)) / vec3<f32>(mat.tab_du, mat.tab_dv, mat.tab_dw),
        vec3<f32>(0.0),
        nmax
    );
    let i = min(vec3<u32>(floor(p)), vec3<u32>(nmax) - vec3<u32>(1u));
    let f = p - vec3<f32>(i);
    let nu = mat.tab_nu;
    let nv = mat.tab_nv;
    let b00 = (i.z * nv + i.y) * nu + i.x;
    let b01 = b00 + nu;
    let b10 = b00 + nv * nu;
    let b11 = b10 + nu;
    let c00 = mix(response[b00].xyz, response[b00 + 1u].xyz, f.x);
    let c01 = mix(response[b01].xyz, response[b01 + 1u].xyz, f.x);
    let c10 = mix(response[b10].xyz, response[b10 + 1u].xyz, f.x);
    let c11 = mix(response[b11].xyz, response[b11 + 1u].xyz, f.x);
    return mix(mix(c00, c01, f.y), mix(c10, c11, f.y), f.z);
}

// ---------------------------------------------------------------- response map
// The material functions are in shaders/response_map.wgsl and
// shaders/material.wgsl (prepended to this file).
fn resp_grid() -> SbGrid {
    return SbGrid(vec3<f32>(mat.resp_n_theta, mat.resp_n_rho, mat.resp_n_s), mat.resp_r0, mat.resp_rho_scale);
}

// This mesh's skin (shaders/material.wgsl).
fn skin() -> SbSkin {
    return SbSkin(mat.ior, mat.norm, vec2<f32>(mat.mask_sx, mat.mask_sy), mat.energy);
}

fn response_map_xyz(wi: vec3<f32>, uvw: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, jx: vec3<f32>, jy: vec3<f32>) -> vec3<f32> {
    let gr = resp_grid();
    if (mat.resp_footprint == 1u) {
        return sb_diffraction_xyz_filtered(wi, uvw, dx, dy, jx, jy, gr, skin());
    }
    return sb_diffraction_xyz(wi, -uvw - wi, gr, skin());
}

// ---------------------------------------------------------------- colour
// The mesh's gain with its masking, G G2 (sunbeam_optics::masking::Masking::gain).
fn gain(wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    return sb_gain(wi, wr, skin()) * masking(wi, wr);
}

// The mesh's Smith masking G2 (1 when off).
fn masking(wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    return sb_masking(wi, wr, vec2<f32>(mat.mask_sx, mat.mask_sy));
}

// sunbeam_optics::colour::display_encode
fn display(rgb: vec3<f32>) -> vec4<f32> {
    if (g.output == 2u) {
        var lin = rgb * g.exposure_scale;
        lin = select(lin, vec3<f32>(0.0), lin != lin);
        // Under an environment the frame is one Monte Carlo estimate of a
        // running mean (shaders/accumulate.wgsl): negative values (a sample's
        // saturated colour outside the sRGB gamut, the maps' negative texels)
        // stay, or clamping each frame biases the mean upwards (+2.5 % red on
        // a ridge under a white map); the mean is clamped when displayed.
        if (envg.on == 1u) {
            return vec4<f32>(lin, 1.0);
        }
        return vec4<f32>(max(lin, vec3<f32>(0.0)), 1.0);
    }
    var out = vec3<f32>(0.0);
    for (var k = 0; k < 3; k = k + 1) {
        out[k] = sb_display_channel(rgb[k] * g.exposure_scale, g.curve, g.output);
    }
    return vec4<f32>(out, 1.0);
}

fn xyz_to_rgb(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(g.xyz_to_rgb[0].xyz, c), dot(g.xyz_to_rgb[1].xyz, c), dot(g.xyz_to_rgb[2].xyz, c));
}

// Offset (pixels, from the centre) of covered sample number floor(u n) of the
// n covered samples of a pixel: the standard 4x MSAA positions (Vulkan, D3D,
// Metal alike). With u uniform the pick is uniform over the covered samples,
// so the resolved pixel (the shade times the coverage) has the mean of
// shading every covered sample; the frames' sub-pixel jitter moves the samples
// over the pixel.
fn covered_pick(covered: u32, u: f32) -> vec2<f32> {
    let n = countOneBits(covered & 15u);
    if (n == 0u) {
        return vec2<f32>(0.0);
    }
    var k = min(u32(u * f32(n)), n - 1u);
    for (var j = 0u; j < 4u; j = j + 1u) {
        if (((covered >> j) & 1u) == 1u) {
            if (k == 0u) {
                return msaa_position(j);
            }
            k = k - 1u;
        }
    }
    return vec2<f32>(0.0);
}

// One point light's radiance (linear RGB, before the exposure) at a point of
// the surface with frame fr (columns t, b, n) seen along wr (world); the
// response map's footprint from the screen derivatives of the pixel centre's
// (u, v, w) (duv_*, dw_*) and texel coordinates (jx, jy).
fn shade_light(i: u32, fr: mat3x3<f32>, wr: vec3<f32>, diffract: bool, dw: f32, duv_x: vec2<f32>, duv_y: vec2<f32>, dw_x: f32, dw_y: f32, jx: vec3<f32>, jy: vec3<f32>) -> vec3<f32> {
    let t = fr[0];
    let b = fr[1];
    let n = fr[2];
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    let wi = g.lights[i].xyz;
    let wi_l = vec3<f32>(dot(wi, t), dot(wi, b), dot(wi, n));
    let cos_i = max(wi_l.z, 0.0);
    // The base gets what the skin does not reflect (PHYSICS.md 2).
    let base_in = cos_i * sb_base_transmission(cos_i, mat.ior, diffract);
    let uvw = -wi_l - wr_l;
    var diff = vec3<f32>(0.0);
    if (diffract && dw < 1.0 && wi_l.z > 0.0 && wr_l.z > 0.0) {
        var xyz: vec3<f32>;
        if (g.mode == 0u && mat.resp_on == 1u) {
            // G is inside the footprint average; the masking, smooth over
            // the footprint, at its centre
            xyz = response_map_xyz(wi_l, uvw, vec3<f32>(duv_x, dw_x), vec3<f32>(duv_y, dw_y), jx, jy)
                * masking(wi_l, wr_l);
        } else if (g.mode == 0u && mat.tab_on == 1u) {
            xyz = response_xyz(wi_l, wr_l) * gain(wi_l, wr_l);
        } else {
            xyz = diffraction_xyz(wi_l, wr_l) * gain(wi_l, wr_l);
        }
        diff = xyz_to_rgb(xyz);
    }
    return g.lights[i].w * g.light_colors[i].rgb * (dw * mat.base.xyz * base_in + (1.0 - dw) * diff);
}

// The shading frame (columns t, b, n) of interpolated attributes: sb_frame of
// the normal and the orientation, or, on a mesh with scale maps, the frame the
// maps give at `uv` (shaders/scales.wgsl, as the reference's
// sunbeam_frame::MeshScales::perturb).
fn frame_at(normal: vec3<f32>, tangent: vec3<f32>, uv: vec2<f32>, uv_tangent: vec4<f32>) -> mat3x3<f32> {
    let fr = sb_frame(normal, tangent);
    if (mat.scales_on == 0u) {
        return fr;
    }
    return sb_scale_frame(scale_normal, scale_orient, mat.scales_wrap, normal, uv_tangent, uv, fr);
}

// The standard 4x MSAA sample positions (pixels from the centre; Vulkan,
// D3D, Metal alike).
fn msaa_position(j: u32) -> vec2<f32> {
    let pos = array<vec2<f32>, 4>(vec2<f32>(-0.125, -0.375), vec2<f32>(0.375, -0.125), vec2<f32>(-0.375, 0.125), vec2<f32>(0.125, 0.375));
    return pos[j];
}

@fragment
fn fs_main(in: VsOut, @builtin(sample_mask) covered: u32) -> @location(0) vec4<f32> {
    let fr = frame_at(in.normal, in.tangent, in.uv, in.uv_tangent);
    let t = fr[0];
    let b = fr[1];
    let n = fr[2];
    let wr = normalize(g.eye.xyz - in.world);
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    let base = mat.base.xyz;
    var dw = mat.base.w;
    let diffract = mat.has_pack == 1u && g.mode != 2u;
    if (!diffract) {
        dw = 1.0;
    }
    // The attributes' screen derivatives, in uniform control flow: they carry
    // the attributes from the centre to a covered sample below.
    let dworld_x = dpdx(in.world);
    let dworld_y = dpdy(in.world);
    let dnormal_x = dpdx(in.normal);
    let dnormal_y = dpdy(in.normal);
    let dtangent_x = dpdx(in.tangent);
    let dtangent_y = dpdy(in.tangent);
    let duv_tex_x = dpdx(in.uv);
    let duv_tex_y = dpdy(in.uv);
    let duv_tangent_x = dpdx(in.uv_tangent);
    let duv_tangent_y = dpdy(in.uv_tangent);
    // A partly covered pixel whose centre sees the surface at a grazing angle
    // or from below (a silhouette, with MSAA) shades the point lights at each
    // of its covered samples and takes their mean: the centre lies past the
    // triangle there, where the attributes extrapolated along their
    // derivatives tilt the normal beyond the limb (the base's cos(theta_i)
    // too small, G's 1 / cos(theta_r) too large or the view below the
    // horizon), while the resolve weighs the pixel by its covered samples and
    // the reference shades each covered sub-pixel position (docs/PLAY.md
    // "Where a pixel shades"; crates/sunbeam-render/tests/silhouette.rs).
    let n_cov = countOneBits(covered & 15u);
    // On a mesh with scale maps every pixel does so (with MSAA), each sample
    // reading the maps at its own uv: the frame varies at the maps' texels
    // and jumps at the scale borders, where the screen derivatives of
    // (u, v, w), the footprint filter's linear model, fail (across a border
    // they spread the response over both scales' lobes instead of mixing
    // the two); the samples resolve the variation (docs/PLAY.md "Scale maps").
    let at_samples = g.msaa >= 4u && n_cov > 0u && ((n_cov < 4u && dot(wr, n) <= ENV_GRAZING_COS) || mat.scales_on == 1u);
    var rgb = vec3<f32>(0.0);
    for (var i = 0u; i < g.n_lights; i = i + 1u) {
        let wi = g.lights[i].xyz;
        let wi_l = vec3<f32>(dot(wi, t), dot(wi, b), dot(wi, n));
        // Response-map coordinates and their screen derivatives at the
        // centre, here in uniform control flow (derivatives are undefined
        // inside the branches of shade_light).
        let uvw = -wi_l - wr_l;
        let gr = resp_grid();
        let rc = sb_resp_coords(uvw, gr);
        let duv_x = dpdx(uvw.xy);
        let duv_y = dpdy(uvw.xy);
        let dw_x = dpdx(uvw.z);
        let dw_y = dpdy(uvw.z);
        let jx = vec3<f32>(sb_resp_dtheta(uvw.xy, duv_x, gr), dpdx(rc.y), dpdx(rc.z));
        let jy = vec3<f32>(sb_resp_dtheta(uvw.xy, duv_y, gr), dpdy(rc.y), dpdy(rc.z));
        if (at_samples) {
            var acc = vec3<f32>(0.0);
            for (var j = 0u; j < 4u; j = j + 1u) {
                if (((covered >> j) & 1u) == 1u) {
                    let o = msaa_position(j);
                    let world_s = in.world + dworld_x * o.x + dworld_y * o.y;
                    let fs = frame_at(
                        in.normal + dnormal_x * o.x + dnormal_y * o.y,
                        in.tangent + dtangent_x * o.x + dtangent_y * o.y,
                        in.uv + duv_tex_x * o.x + duv_tex_y * o.y,
                        in.uv_tangent + duv_tangent_x * o.x + duv_tangent_y * o.y
                    );
                    let wr_s = normalize(g.eye.xyz - world_s);
                    // each sample stands for a quarter of the pixel: half the
                    // footprint along each axis
                    acc = acc + shade_light(i, fs, wr_s, diffract, dw, 0.5 * duv_x, 0.5 * duv_y, 0.5 * dw_x, 0.5 * dw_y, 0.5 * jx, 0.5 * jy);
                }
            }
            rgb = rgb + acc / f32(n_cov);
        } else {
            rgb = rgb + shade_light(i, fr, wr, diffract, dw, duv_x, duv_y, dw_x, dw_y, jx, jy);
        }
    }
    // The scene's environment (shaders/environment.wgsl): one Monte Carlo
    // estimate per frame, accumulated by the caller.
    if (envg.on == 1u) {
        // Where the environment's Monte Carlo estimate shades: the pixel centre,
        // except in a partly covered pixel whose centre sees the surface at a
        // grazing angle or from below (a silhouette): there the centre
        // extrapolates the attributes past the triangle, where the view falls
        // below the horizon (black pixels), and the pixel's light changes
        // fastest across it (G, the masking), so it shades at one covered
        // sample, a new one each frame (covered_pick, stratified over the
        // frames by env_qmc's base 31): the accumulated pixel is then the
        // mean over the covered part of the pixel, as the reference takes it.
        // The point is reached along the attributes' screen derivatives (the
        // triangle's plane: it stays on the surface). Not
        // `@interpolate(centroid)`: that may be any covered sample, and Mesa's
        // llvmpipe takes one, 0.4 px off the centre of every pixel that an edge
        // between triangles crosses, which shifted every sharp feature of the
        // environment frame (the sun's glint: CIEDE2000 p99 4.6 against the
        // reference at the centroid, 0.3 at the centre). The point lights shade
        // at the centre, whose derivatives the footprint filter needs.
        // Elsewhere (edges between triangles) the centre too: with the jitter
        // it is an unbiased point of the pixel, and the sun's glint on the
        // benchmark sphere is sharper that way (p99 0.3 against 0.9 with the
        // covered samples' mean everywhere). Without masking a silhouette's
        // samples have infinite variance (docs/LIGHTING.md "Grazing views").
        // (Derivatives here: envg is uniform, so this is uniform control flow;
        // the pick only moves the point along them.)
        var off = vec2<f32>(0.0);
        if (g.msaa >= 4u && dot(wr, n) <= ENV_GRAZING_COS) {
            env_seed_at(vec2<u32>(in.clip.xy), envg.frame);
            off = covered_pick(covered, env_qmc(envg.frame + 1u, 31u));
        }
        let world_c = in.world + dworld_x * off.x + dworld_y * off.y;
        let normal_c = in.normal + dnormal_x * off.x + dnormal_y * off.y;
        let tangent_c = in.tangent + dtangent_x * off.x + dtangent_y * off.y;
        let uv_c = in.uv + duv_tex_x * off.x + duv_tex_y * off.y;
        let uv_tangent_c = in.uv_tangent + duv_tangent_x * off.x + duv_tangent_y * off.y;
        let fc = frame_at(normal_c, tangent_c, uv_c, uv_tangent_c);
        let wr_c = normalize(g.eye.xyz - world_c);
        let wr_cl = vec3<f32>(dot(wr_c, fc[0]), dot(wr_c, fc[1]), dot(wr_c, fc[2]));
        rgb = rgb + env_shade(fc[0], fc[1], fc[2], wr_cl, base, dw, diffract, vec2<u32>(in.clip.xy));
    }
    return display(rgb);
}
