// The background pass of `"background": "environment"` (docs/PLAY.md
// "Background"): one full-screen triangle at the far plane, drawn after the
// meshes with depth test `LessEqual` and no depth write, so it covers exactly
// the samples no mesh covers. Each pixel looks up the environment along its
// view ray as the lighting does (shaders/environment.wgsl `env_coefficients`:
// the coefficient table's texel that contains the direction, no filtering,
// as `EnvMap::lookup`; the basis to linear sRGB; the sun's disc), then the
// display transform of shaders/diffraction.wgsl `display`.
//
// Each pixel averages 16 rays over its square, the box the reference's
// sub-pixel samples average, in every frame and with no sub-pixel jitter (so a
// running mean of frames is that box too): one ray per pixel drew the sky's
// horizon and a map's texel edges as steps a pixel high (the horizon's row of
// a sky 5 % off in a 96 x 48 frame at 4 x 4 supersampling; one frame of
// tests/background.rs' sky CIEDE2000 p99 34.6 within 1.5 degrees of the
// horizon, 0.75 with the box).

struct BgGlobals {
    // world view direction through NDC (x, y): o + x rx + y ry
    ray_o: vec4<f32>,
    ray_x: vec4<f32>,
    ray_y: vec4<f32>,
    basis_to_rgb: array<vec4<f32>, 3>,
    // xyz: towards the sun's centre; w: cos of its angular radius
    sun_dir: vec4<f32>,
    // xyz: the sun's radiance, linear sRGB
    sun_rgb: vec4<f32>,
    size: vec2<f32>,
    table_w: u32,
    table_h: u32,
    has_sun: u32,
    exposure_scale: f32,
    curve: u32,
    output: u32,
    // 1: keep negative linear values (a Monte Carlo frame of a running mean)
    keep_negative: u32,
    // where the table's columns start, turns after phi = 0
    table_phase: f32,
    _b1: u32,
    _b2: u32,
};

@group(0) @binding(0) var<uniform> bg: BgGlobals;
@group(0) @binding(1) var bg_table: texture_2d<f32>;


@vertex
fn vs_bg(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 1.0, 1.0);
}

fn bg_coefficients(d: vec3<f32>) -> vec3<f32> {
    return sb_env_texel(bg_table, bg.table_w, bg.table_h, bg.table_phase, d);
}

// The radiance along the ray through pixel coordinate `q` (pixels, y down),
// linear sRGB before the exposure.
fn bg_radiance(q: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(2.0 * q.x / bg.size.x - 1.0, 1.0 - 2.0 * q.y / bg.size.y);
    let d = normalize(bg.ray_o.xyz + ndc.x * bg.ray_x.xyz + ndc.y * bg.ray_y.xyz);
    let c = bg_coefficients(d);
    var rgb = vec3<f32>(dot(bg.basis_to_rgb[0].xyz, c), dot(bg.basis_to_rgb[1].xyz, c), dot(bg.basis_to_rgb[2].xyz, c));
    if (bg.has_sun == 1u && dot(d, bg.sun_dir.xyz) >= bg.sun_dir.w) {
        rgb = rgb + bg.sun_rgb.xyz;
    }
    return rgb;
}

// Offset (pixels, from the centre) of ray k of n = 16 over the pixel: the
// 16-point Hammersley set (x = (k + 1/2) / 16, y its 4-bit reversal plus
// 1/32), a (0, 4, 2)-net: one ray in every 1/16-wide row and column, so
// a horizontal or vertical edge (the horizon seen level) is resolved to
// 1/16 of the pixel.
fn bg_box_offset(k: u32) -> vec2<f32> {
    let r = ((k & 1u) << 3u) | ((k & 2u) << 1u) | ((k & 4u) >> 1u) | ((k & 8u) >> 3u);
    return (vec2<f32>(f32(k), f32(r)) + 0.5) / 16.0 - 0.5;
}

@fragment
fn fs_bg(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    var rgb = vec3<f32>(0.0);
    for (var k = 0u; k < 16u; k = k + 1u) {
        rgb = rgb + bg_radiance(p.xy + bg_box_offset(k));
    }
    var lin = rgb / 16.0 * bg.exposure_scale;
    lin = select(lin, vec3<f32>(0.0), lin != lin);
    // Offscreen (output 2) the alpha is the meshes' coverage: 0 here
    // (sunbeam_render::Offscreen).
    if (bg.output == 2u) {
        if (bg.keep_negative == 1u) {
            return vec4<f32>(lin, 0.0);
        }
        return vec4<f32>(max(lin, vec3<f32>(0.0)), 0.0);
    }
    var out = vec3<f32>(0.0);
    for (var k = 0; k < 3; k = k + 1) {
        out[k] = sb_display_channel(lin[k], bg.curve, bg.output);
    }
    return vec4<f32>(out, 1.0);
}
