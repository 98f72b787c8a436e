// The engine interface of the response-map material: what
// `sunbeam-play --export-shader glsl|hlsl|msl|spv` translates (with
// shaders/material.wgsl and shaders/response_map.wgsl prepended), documented
// in docs/ENGINES.md.
//
// Bindings (group 0): 0 the material's numbers, 1 the response map (3D texture,
// RGBA16F from NAME.response.ktx2), 2 its sampler (linear; repeat in x,
// clamp-to-edge in y and z).
// Bindings 3 to 9 are the environment's (shaders/export_env.wgsl), 10 and 11
// the scale maps' (shaders/export_scales.wgsl).
// Call sunbeam_shade(t, b, n, wi, wr) per light: linear sRGB for a light of
// intensity 1 (multiply by the light's colour and intensity, sum over lights,
// then expose and tone-map as the engine does); sb_frame(normal, orientation)
// gives (t, b, n) from the interpolated attributes as the player does, and
// sunbeam_scale_frame(normal, orientation, tangent, uv, scales) on a mesh
// with scale maps (sunbeam-bake --scales);
// sunbeam_shade_environment(t, b, n, wr) adds an environment without its
// sun, sunbeam_shade_sun(t, b, n, wi, wr) the sky's sun (shaders/export_env.wgsl;
// on a mesh with scale maps point by point: sunbeam_shade_sun_point). The entry point
// sunbeam_fragment shows the calls with the attributes and the two
// directions as varyings.

struct SunbeamMaterial {
    // xyz: the map's texels along angle, radius, s (grid.n_theta, n_rho, n_s); w: unused
    grid: vec4<f32>,
    // x: r0 (grid.r0), y: asinh(2 / r0), z: diffuse weight dw in [0, 1], w: unused
    warp: vec4<f32>,
    // rgb: linear sRGB base colour (the Lambert part), a: unused
    base: vec4<f32>,
    // the skin (PHYSICS.md 2): x: refractive index (1.5), y: what G is divided
    // by (1 for absolute reflectance, the default; F(0) = ((n - 1)/(n + 1))^2
    // for relative), zw: Smith masking's rms slopes along t and b (the pack's
    // rms_slope; (0, 0): no masking)
    skin: vec4<f32>,
    // the energy bound's table (PHYSICS.md 2b, docs/LIGHTING.md "Energy
    // bound"): b at t = sqrt(cos theta_r) = k / 15, k = 4 column + row: the
    // response map's info `energy.off` (or `energy.smith` with masking) in
    // column-major order for absolute reflectance; all 0 (no bound) for relative
    energy: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> sunbeam: SunbeamMaterial;
@group(0) @binding(1) var resp_tex: texture_3d<f32>;
@group(0) @binding(2) var resp_smp: sampler;

// CIE XYZ to linear sRGB (D65), sunbeam_optics::colour::XYZ_TO_SRGB.
fn sb_xyz_to_linear_srgb(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z,
        -0.969266 * c.x + 1.8760108 * c.y + 0.041556 * c.z,
        0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z,
    );
}

// One light of intensity 1, linear sRGB (docs/PLAY.md "Shading"):
// dw * base * cos(theta_i) (1 - F(theta_i)) + (1 - dw) * G G2 T, with G the
// skin's gain (exact Fresnel, absolute or relative), G2 Smith's masking and
// T the map. t: the surface's orientation (the mesh's _ORIENTATION, the
// patch's +x), n: the normal, b = n x t; wi towards the light, wr towards the
// viewer; all unit, any common space (world space in a forward pass).
fn sunbeam_shade(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let wi_l = vec3<f32>(dot(wi, t), dot(wi, b), dot(wi, n));
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    let gr = SbGrid(sunbeam.grid.xyz, sunbeam.warp.x, sunbeam.warp.y);
    let skin = SbSkin(sunbeam.skin.x, sunbeam.skin.y, sunbeam.skin.zw, sunbeam.energy);
    let dw = sunbeam.warp.z;
    var diff = vec3<f32>(0.0);
    if (wi_l.z > 0.0 && wr_l.z > 0.0) {
        let xyz = sb_diffraction_xyz(wi_l, wr_l, gr, skin) * sb_masking(wi_l, wr_l, skin.slope);
        diff = sb_xyz_to_linear_srgb(xyz);
    }
    let cos_i = max(wi_l.z, 0.0);
    return dw * sunbeam.base.rgb * cos_i * sb_base_transmission(cos_i, skin.ior, true) + (1.0 - dw) * diff;
}

struct SunbeamVaryings {
    // the interpolated normal and orientation (any length; sb_frame orthonormalises)
    @location(0) normal: vec3<f32>,
    @location(1) orientation: vec3<f32>,
    @location(2) wi: vec3<f32>,
    @location(3) wr: vec3<f32>,
    // a mesh with scale maps (shaders/export_scales.wgsl): the glTF TANGENT,
    // the maps' TEXCOORD, and `scales` (0: no maps; else 16 plus the wrap bits)
    @location(4) tangent: vec4<f32>,
    @location(5) uv: vec2<f32>,
    @location(6) @interpolate(flat) scales: u32,
};

@fragment
fn sunbeam_fragment(v: SunbeamVaryings) -> @location(0) vec4<f32> {
    let f = sunbeam_scale_frame(v.normal, v.orientation, v.tangent, v.uv, v.scales);
    let wr = normalize(v.wr);
    let c = sunbeam_shade(f[0], f[1], f[2], normalize(v.wi), wr) + sunbeam_shade_environment(f[0], f[1], f[2], wr)
        + sunbeam_shade_sun(f[0], f[1], f[2], sunbeam_env.sun_dir.xyz, wr);
    return vec4<f32>(c, 1.0);
}
