// The engine interface of the response-map material: what
// `sunbeam-play --export-shader glsl|hlsl|msl|spv` translates (with
// shaders/response_map.wgsl prepended), documented in docs/ENGINES.md.
//
// Bindings (group 0): 0 the material's numbers, 1 the response map (3D texture,
// RGBA16F from NAME.response.ktx2), 2 its sampler (linear; repeat in x,
// clamp-to-edge in y and z).
// Call sunbeam_shade(t, b, n, wi, wr) per light: linear sRGB for a light of
// intensity 1 (multiply by the light's colour and intensity, sum over lights,
// then expose and tone-map as the engine does). The entry point
// sunbeam_fragment shows the call with the five directions as varyings.

struct SunbeamMaterial {
    // xyz: the map's texels along angle, radius, s (grid.n_theta, n_rho, n_s);
    // w: Schlick F0 of the surface (0.04 for a refractive index of 1.5)
    grid: vec4<f32>,
    // x: r0 (grid.r0), y: asinh(2 / r0), z: diffuse weight dw in [0, 1], w: unused
    warp: vec4<f32>,
    // rgb: linear sRGB base colour (the Lambert part), a: unused
    base: vec4<f32>,
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

// One light of intensity 1, linear sRGB: dw * base * cos(theta_i) +
// (1 - dw) * diffraction (docs/PLAY.md "Shading"). t: the surface's
// orientation (the mesh's _ORIENTATION, the patch's +x), n: the normal,
// b = n x t; wi towards the light, wr towards the viewer; all unit, any common
// space (world space in a forward pass).
fn sunbeam_shade(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let wi_l = vec3<f32>(dot(wi, t), dot(wi, b), dot(wi, n));
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    let gr = SbGrid(sunbeam.grid.xyz, sunbeam.warp.x, sunbeam.warp.y, sunbeam.grid.w);
    let dw = sunbeam.warp.z;
    var diff = vec3<f32>(0.0);
    if (wi_l.z > 0.0 && wr_l.z > 0.0) {
        diff = sb_xyz_to_linear_srgb(sb_diffraction_xyz(wi_l, wr_l, gr));
    }
    return dw * sunbeam.base.rgb * max(wi_l.z, 0.0) + (1.0 - dw) * diff;
}

struct SunbeamVaryings {
    @location(0) t: vec3<f32>,
    @location(1) b: vec3<f32>,
    @location(2) n: vec3<f32>,
    @location(3) wi: vec3<f32>,
    @location(4) wr: vec3<f32>,
};

@fragment
fn sunbeam_fragment(v: SunbeamVaryings) -> @location(0) vec4<f32> {
    let c = sunbeam_shade(normalize(v.t), normalize(v.b), normalize(v.n), normalize(v.wi), normalize(v.wr));
    return vec4<f32>(c, 1.0);
}
