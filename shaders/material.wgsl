// Sunbeam's skin material (PHYSICS.md 2): the one WGSL version of the Fresnel
// reflectance, the gain G with its energy bound, Smith's shadowing-masking, the diffuse base's share
// and the shading frame. Every shader that shades calls these: the player's
// point lights (shaders/diffraction.wgsl) and environment (shaders/environment.wgsl),
// the response-map material (shaders/response_map.wgsl) and the engines' export
// (shaders/export.wgsl). It is prepended to each (crates/sunbeam-render:
// renderer::SHADER, export::SOURCE), and crates/sunbeam-render/tests/material.rs
// runs these functions in a compute pass against the float64 ones of
// sunbeam_optics (gain, masking) and sunbeam_raster::shade::frame.
//
// Directions are local unit vectors (d.t, d.b, d.n): wi towards the light, wr
// towards the viewer.

// The skin's interface.
struct SbSkin {
    // refractive index (from air), 1.5 by default (scene `meshes[].ior`)
    ior: f32,
    // what G is divided by: 1 (absolute reflectance, the default) or F(0)
    // (relative, the thesis'); from sunbeam_optics::gain::Material::norm
    norm: f32,
    // Smith masking: rms slopes of the height field along t and b; (0, 0) = off
    slope: vec2<f32>,
    // the energy bound's table (sunbeam_optics::energy::EnergyBound::columns):
    // b at t = sqrt(cos theta_r) = k / 15 in column k / 4, row k % 4; all 0 = no bound
    energy: mat4x4<f32>,
};

// sunbeam_optics::energy::EnergyBound::factor: the energy bound on G at view
// cosine cos_r, min(1, cos_r / b(cos_r)) with b linear in sqrt(cos_r)
// between the table's 16 knots (1 where b <= cos_r: the albedo is <= 1 there).
fn sb_energy(cos_r: f32, e: mat4x4<f32>) -> f32 {
    let c = clamp(cos_r, 0.0, 1.0);
    let t = sqrt(c) * 15.0;
    let k = min(u32(t), 14u);
    let f = t - f32(k);
    var m = e;
    let k1 = k + 1u;
    let b = m[k / 4u][k % 4u] * (1.0 - f) + m[k1 / 4u][k1 % 4u] * f;
    if (b <= c) {
        return 1.0;
    }
    return c / b;
}

// The exact unpolarised Fresnel power reflectance F = (r_s^2 + r_p^2) / 2 from
// air into index `ior` at incidence cos_theta (clamped to [0, 1]), and the
// transmittance 1 - F: (F, 1 - F). F is 1 at grazing and under total internal
// reflection. 1 - F is written as
// 2 n c c_t (1 / (c + n c_t)^2 + 1 / (n c + c_t)^2) (from 1 - r^2 = (1 - r)(1 + r)),
// so that each keeps its digits where it is small (F near normal incidence and
// n near 1, 1 - F at grazing), which 1 - the other would not in float32.
fn sb_fresnel_pair(cos_theta: f32, ior: f32) -> vec2<f32> {
    let c = clamp(cos_theta, 0.0, 1.0);
    // sin^2 of the refracted angle; (1 - c)(1 + c) keeps its digits near c = 1
    let s2t = (1.0 - c) * (1.0 + c) / (ior * ior);
    if (s2t >= 1.0) {
        return vec2<f32>(1.0, 0.0);
    }
    let ct = sqrt(1.0 - s2t);
    let ds = c + ior * ct;
    let dp = ior * c + ct;
    let rs = (c - ior * ct) / ds;
    let rp = (ior * c - ct) / dp;
    let t = 2.0 * ior * c * ct * (1.0 / (ds * ds) + 1.0 / (dp * dp));
    return vec2<f32>(0.5 * (rs * rs + rp * rp), t);
}

// sunbeam_optics::gain::fresnel: F(theta).
fn sb_fresnel(cos_theta: f32, ior: f32) -> f32 {
    return sb_fresnel_pair(cos_theta, ior).x;
}

// sunbeam_optics::gain::g: G = F(theta_d) (1 + wi.wr)^2 / ((cos th_i + cos th_r)^2 cos th_r) / norm,
// Fresnel taken once, times the skin's energy bound at wr (sb_energy). 0 unless both directions are above the horizon.
// The product of sb_gain_pair and sb_gain_view: a sum over many wi at one view
// (the environment's cells) computes the view's part once.
fn sb_gain(wi: vec3<f32>, wr: vec3<f32>, skin: SbSkin) -> f32 {
    return sb_gain_pair(wi, wr, skin.ior) * sb_gain_view(wr.z, skin);
}

// The part of G that depends on the view alone: the energy bound over
// norm cos theta_r (0 unless cos_r > 0).
fn sb_gain_view(cos_r: f32, skin: SbSkin) -> f32 {
    if (!(cos_r > 0.0)) {
        return 0.0;
    }
    return sb_energy(cos_r, skin.energy) / (skin.norm * cos_r);
}

// The rest of G: F(theta_d) (1 + wi.wr)^2 / (cos th_i + cos th_r)^2, 0 unless
// both directions are above the horizon. For unit directions 1 + wi.wr =
// |wi + wr|^2 / 2 and cos theta_d = wi.h = |wi + wr| / 2: written so, G keeps
// its digits where wi and wr are nearly opposite (both grazing), where
// 1 + wi.wr cancels in float32.
fn sb_gain_pair(wi: vec3<f32>, wr: vec3<f32>, ior: f32) -> f32 {
    let ci = wi.z;
    let cr = wr.z;
    if (!(ci > 0.0 && cr > 0.0)) {
        return 0.0;
    }
    let s = wi + wr;
    let s2 = dot(s, s);
    let f = sb_fresnel(0.5 * sqrt(s2), ior);
    let c = ci + cr;
    return f * (0.25 * s2 * s2) / (c * c);
}

// erf by Abramowitz & Stegun 7.1.26 (sunbeam_optics::masking::erf).
fn sb_erf(x: f32) -> f32 {
    let a = abs(x);
    let t = 1.0 / (1.0 + 0.3275911 * a);
    let y = 1.0 - ((((1.061405429 * t - 1.453152027) * t + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-a * a);
    return select(y, -y, x < 0.0);
}

// Smith's Lambda for Beckmann slopes with rms slopes `slope` (sunbeam_optics::masking::lambda).
fn sb_smith_lambda(w: vec3<f32>, slope: vec2<f32>) -> f32 {
    // alpha_w^2 tan^2 = 2 (wx^2 sx^2 + wy^2 sy^2) / wz^2
    let at2 = 2.0 * (w.x * w.x * slope.x * slope.x + w.y * w.y * slope.y * slope.y);
    if (at2 <= 0.0) {
        return 0.0;
    }
    let a = w.z / sqrt(at2);
    if (a > 8.0) {
        return 0.0;
    }
    // erf by Abramowitz & Stegun 7.1.26 (a >= 0), as sunbeam_optics::masking::erf
    let t = 1.0 / (1.0 + 0.3275911 * a);
    let p = ((((1.061405429 * t - 1.453152027) * t + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t;
    let e = exp(-a * a);
    // (erf(a) - 1) / 2 = -p e / 2
    return -0.5 * p * e + e / (2.0 * a * 1.7724538509055159);
}

// sunbeam_optics::masking::Masking::factor: Smith's height-correlated
// shadowing-masking G2 = 1 / (1 + Lambda(wi) + Lambda(wr)); 1 when off
// (both slopes 0), 0 when either direction is at or below the horizon.
fn sb_masking(wi: vec3<f32>, wr: vec3<f32>, slope: vec2<f32>) -> f32 {
    return sb_masking_with(wi, wr.z, sb_smith_lambda(wr, slope), slope);
}

// G with the masking, G G2 (sunbeam_optics::masking::Masking::gain): what
// light from wi sends towards wr, before the response.
fn sb_gain_masked(wi: vec3<f32>, wr: vec3<f32>, skin: SbSkin) -> f32 {
    return sb_gain(wi, wr, skin) * sb_masking(wi, wr, skin.slope);
}

// sb_masking with the view's Lambda given (lambda_r = sb_smith_lambda(wr,
// slope)): a sum over many wi at one view computes it once.
fn sb_masking_with(wi: vec3<f32>, cos_r: f32, lambda_r: f32, slope: vec2<f32>) -> f32 {
    if (slope.x <= 0.0 && slope.y <= 0.0) {
        return 1.0;
    }
    if (wi.z <= 0.0 || cos_r <= 0.0) {
        return 0.0;
    }
    return 1.0 / (1.0 + sb_smith_lambda(wi, slope) + lambda_r);
}

// The diffuse base's share of the light arriving at cos_i
// (sunbeam_optics::gain::Material::transmission): 1 - F(theta_i) under the
// diffracting skin (`skin`: the mesh has a pack), 1 for a plain mesh. The
// base's radiance is base * cos_i * this (point lights) or the integral of
// L(d) cos(d) this over the hemisphere (environments).
fn sb_base_transmission(cos_i: f32, ior: f32, skin: bool) -> f32 {
    if (!skin) {
        return 1.0;
    }
    return sb_fresnel_pair(cos_i, ior).y;
}

// sunbeam_raster::shade::frame: the local frame (columns t, b, n) of an
// interpolated normal and orientation, t made orthogonal to n (any
// perpendicular when they are parallel), b = n x t.
fn sb_frame(normal: vec3<f32>, tangent: vec3<f32>) -> mat3x3<f32> {
    let n = normalize(normal);
    var t = tangent - n * dot(n, tangent);
    if (length(t) < 1e-12) {
        var a = vec3<f32>(1.0, 0.0, 0.0);
        if (abs(n.x) >= 0.9) {
            a = vec3<f32>(0.0, 1.0, 0.0);
        }
        t = a - n * dot(n, a);
    }
    t = normalize(t);
    return mat3x3<f32>(t, cross(n, t), n);
}
