// The baselines the default technique is measured against (docs/PLAY.md
// "Modes"), composed after shaders/diffraction.wgsl into the baseline
// pipelines only (crates/sunbeam-render/src/renderer/baselines.rs; the
// default pipeline has none of this code). Each gives a point light's
// diffraction term:
//
// - table (BASELINE 0): the Cartesian response table over (u, v, w), built on
//   the CPU at load (crates/sunbeam-render/src/table.rs), trilinear;
// - direct (BASELINE 1): PHYSICS.md 2 summed per fragment: for each wavelength
//   sample that can reach a stored frequency, t_l = 2 pi w H / lambda, c_n(t_l)
//   (Chebyshev: i^n eps_n J_n by Miller's backward recurrence; Taylor:
//   (i t)^n / n!), only the terms |t_l| needs, amplitude = sum over
//   Kaiser-Bessel taps of weight * sum_n c_n F_n[tap] (window model, squared
//   after the sum; with the window's exact grazing term, PHYSICS.md 2b: the
//   amplitude's derivatives along u and v from the kernel's derivative, R_U,
//   as sunbeam_pack::Pack::shading_reflectance) or power = sum of weight *
//   |sum_n c_n F_n|^2 (tiled model), exactly as sunbeam_pack::Pack::reflectance;
// - thesis (BASELINE 2): the thesis' shader: the same sum with a fixed term
//   count, 5 nm samples, the nearest texel, no interpolation;
//
// each times the skin's gain and masking (`gain`, shaders/diffraction.wgsl).
// BASELINE is a pipeline constant: each baseline's pipeline is specialised
// to its own term, with no branch on it at run time.

override BASELINE: u32;
const BASELINE_TABLE: u32 = 0u;
const BASELINE_DIRECT: u32 = 1u;
const BASELINE_THESIS: u32 = 2u;

const MAX_TERMS: u32 = 64u;
const MAX_TAPS: u32 = 16u;
const TAU: f32 = SB_TAU;

struct Baseline {
    basis: u32,   // 0 Chebyshev, 1 Taylor
    model: u32,   // 0 window (Kaiser-Bessel on amplitudes), 1 tiled (Gaussian on power)
    taps: u32,
    crop_w: u32,
    crop_h: u32,
    kx: i32,
    ky: i32,
    terms: u32,       // terms stored (capped at MAX_TERMS)
    fixed_terms: u32, // thesis: use exactly this many; 0 = per-fragment from the bound
    n_table: u32,     // entries in term_table
    // bins per (cycle per micrometre), x and y
    bin_scale_um: vec2<f32>,
    half_range_um: f32,
    beta: f32,
    sigma_bins: vec2<f32>,
    kb_norm: f32,      // beta / (W sinh beta)
    table_dt: f32,     // |t| step of term_table
    // response table: cells (nu, nv, nw)
    tab_nu: u32,
    tab_nv: u32,
    tab_nw: u32,
    // u, v of cell 0 (= -2), their steps; w of cell 0 (= -2), its step
    tab_u0: f32,
    tab_du: f32,
    tab_dv: f32,
    tab_w0: f32,
    tab_dw: f32,
    // window model: the coherence window's sigma (manifest window_sigma_m) in
    // um, for R_U in the direct baseline; 0 = plain R
    window_sigma_um: f32,
    _b0: u32,
};

@group(3) @binding(0) var<uniform> bl: Baseline;
// texel (n, ty, tx) at (n * crop_h + ty) * crop_w + tx, (re, im)
@group(3) @binding(1) var<storage, read> terms: array<vec2<f32>>;
// term_table[i] = terms needed for |t| <= (i + 1) * table_dt
@group(3) @binding(2) var<storage, read> term_table: array<u32>;
// response table, (iw * nv + iv) * nu + iu, xyz
@group(3) @binding(3) var<storage, read> response: array<vec4<f32>>;

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
    if (bl.basis == 0u) {
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
    if (bl.fixed_terms > 0u) {
        return min(bl.fixed_terms, bl.terms);
    }
    let i = min(u32(floor(at / bl.table_dt)), bl.n_table - 1u);
    return min(term_table[i], bl.terms);
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
    let w = f32(bl.taps);
    if (bl.model == 0u) {
        let r = 2.0 * d / w;
        if (abs(r) >= 1.0) {
            return 0.0;
        }
        return bl.kb_norm * bessel_i0(bl.beta * sqrt(1.0 - r * r));
    }
    let s = bl.sigma_bins[axis];
    return exp(-d * d / (2.0 * s * s));
}

// d tap_weight / d kappa of the window model (sunbeam_pack::kernel::kb_derivative):
// -kb_norm beta^2 (2 r / W) I1(z) / z with I1(z)/z = 1/2 sum_k (z^2/4)^k / (k! (k+1)!).
fn tap_dweight(d: f32) -> f32 {
    let w = f32(bl.taps);
    let r = 2.0 * d / w;
    if (abs(r) >= 1.0) {
        return 0.0;
    }
    let q = bl.beta * bl.beta * (1.0 - r * r) / 4.0;
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
    return -bl.kb_norm * bl.beta * bl.beta * (2.0 * r / w) * 0.5 * sum;
}

var<private> wx: array<f32, MAX_TAPS>;
var<private> wy: array<f32, MAX_TAPS>;
var<private> dwx: array<f32, MAX_TAPS>;
var<private> dwy: array<f32, MAX_TAPS>;

fn term_at(n: u32, tx: u32, ty: u32) -> vec2<f32> {
    return terms[(n * bl.crop_h + ty) * bl.crop_w + tx];
}

fn cmul(a: vec2<f32>, b: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(a.x * b.x - a.y * b.y, a.x * b.y + a.y * b.x);
}

// R at fractional bin (kappa_x, kappa_y) with coef[0..count] set; with
// `grazing` (the window model's R_U, PHYSICS.md 2b) at (u, v, w) = uvw and
// 1 / lambda = inv_l (1/um): |P + (u dP/du + v dP/dv) / (sigma^2 k^2 |q|^2)|^2
// (sunbeam_optics::grazing::window_reflectance).
fn reflectance(kappa: vec2<f32>, count: u32, grazing: bool, uvw: vec3<f32>, inv_l: f32) -> f32 {
    let taps = i32(bl.taps);
    let k0x = i32(floor(kappa.x)) - taps / 2 + 1;
    let k0y = i32(floor(kappa.y)) - taps / 2 + 1;
    for (var j = 0; j < taps; j = j + 1) {
        let kx = k0x + j;
        if (kx < -bl.kx || kx > bl.kx) {
            wx[j] = 0.0;
            dwx[j] = 0.0;
        } else {
            wx[j] = tap_weight(kappa.x - f32(kx), 0u);
            dwx[j] = select(0.0, tap_dweight(kappa.x - f32(kx)), grazing);
        }
        let ky = k0y + j;
        if (ky < -bl.ky || ky > bl.ky) {
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
        let ty = u32(k0y + jy + bl.ky);
        for (var jx = 0; jx < taps; jx = jx + 1) {
            if (wx[jx] == 0.0 && dwx[jx] == 0.0) {
                continue;
            }
            let tx = u32(k0x + jx + bl.kx);
            var a = vec2<f32>(0.0);
            for (var n = 0u; n < count; n = n + 1u) {
                a = a + cmul(coef[n], term_at(n, tx, ty));
            }
            let wgt = wx[jx] * wy[jy];
            if (bl.model == 0u) {
                amp = amp + wgt * a;
                ampx = ampx + dwx[jx] * wy[jy] * a;
                ampy = ampy + wx[jx] * dwy[jy] * a;
            } else {
                power = power + wgt * dot(a, a);
            }
        }
    }
    if (bl.model == 0u) {
        if (grazing) {
            // d/du = (d kappa_x / du) d/dkappa_x = -(bin_scale_x / lambda) d/dkappa_x;
            // sigma and k in um, so the factors are dimensionless.
            let q2 = dot(uvw, uvw);
            let k = TAU * inv_l;
            let sk = bl.window_sigma_um * k;
            let c = 1.0 / (sk * sk * q2);
            let a = amp
                + (uvw.x * c * (-bl.bin_scale_um.x * inv_l)) * ampx
                + (uvw.y * c * (-bl.bin_scale_um.y * inv_l)) * ampy;
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
    if (kx < -bl.kx || kx > bl.kx || ky < -bl.ky || ky > bl.ky) {
        return 0.0;
    }
    let tx = u32(kx + bl.kx);
    let ty = u32(ky + bl.ky);
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
    let reach = vec2<f32>(f32(bl.kx), f32(bl.ky)) + 0.5 * f32(bl.taps);
    var xyz = vec3<f32>(0.0);
    for (var l = 0u; l < g.n_lambda; l = l + 1u) {
        let s = spectrum[l];
        let kappa = -vec2<f32>(u, v) * s.w * bl.bin_scale_um;
        if (abs(kappa.x) > reach.x || abs(kappa.y) > reach.y) {
            continue;
        }
        let t = TAU * w * bl.half_range_um * s.w;
        let count = terms_needed(abs(t));
        coefficients(t, count);
        var r: f32;
        if (BASELINE == BASELINE_THESIS) {
            r = reflectance_nearest(kappa, count);
        } else {
            let grazing = bl.model == 0u && bl.window_sigma_um > 0.0;
            r = reflectance(kappa, count, grazing, vec3<f32>(u, v, w), s.w);
        }
        xyz = xyz + r * s.xyz;
    }
    return xyz;
}

fn response_xyz(wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let uvw = -wi - wr;
    let nmax = vec3<f32>(f32(bl.tab_nu - 1u), f32(bl.tab_nv - 1u), f32(bl.tab_nw - 1u));
    let p = clamp(
        (uvw - vec3<f32>(bl.tab_u0, bl.tab_u0, bl.tab_w0)) / vec3<f32>(bl.tab_du, bl.tab_dv, bl.tab_dw),
        vec3<f32>(0.0),
        nmax
    );
    let i = min(vec3<u32>(floor(p)), vec3<u32>(nmax) - vec3<u32>(1u));
    let f = p - vec3<f32>(i);
    let nu = bl.tab_nu;
    let nv = bl.tab_nv;
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

// A point light's diffraction term (XYZ with G and the masking) for local
// directions wi, wr: this baseline's (the footprint arguments are the
// default technique's; the baselines shade at the pixel centre).
fn point_xyz(wi: vec3<f32>, wr: vec3<f32>, uvw: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, jx: vec3<f32>, jy: vec3<f32>) -> vec3<f32> {
    if (BASELINE == BASELINE_TABLE) {
        return response_xyz(wi, wr) * gain(wi, wr);
    }
    return diffraction_xyz(wi, wr) * gain(wi, wr);
}

@fragment
fn fs_baseline(in: VsOut, @builtin(sample_mask) covered: u32) -> @location(0) vec4<f32> {
    return shade(in, covered);
}
