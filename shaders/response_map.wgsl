// Sunbeam response-map material (docs/PACK_FORMAT.md "Response map", docs/ENGINES.md).
//
// The one source of the diffraction colour that sunbeam-play draws (it is
// prepended to shaders/diffraction.wgsl) and that `sunbeam-play --export-shader`
// translates for other engines (with shaders/export.wgsl). It follows
// shaders/material.wgsl (SbSkin, sb_gain: the skin's Fresnel and gain).
// Everything is in the local frame of the surface: t (the patch's +x, the
// baked orientation), b = n x t, n; wi towards the light, wr towards the
// viewer, both unit.
//
// The including module declares the map and its sampler:
//   var resp_tex: texture_3d<f32>;  RGBA16F, RGB = XYZ without the gain G
//   var resp_smp: sampler;          linear, repeat in x (angle), clamp in y, z

// The map's grid (from the map's KTX2 key `sunbeam.response`: grid.n_theta,
// n_rho, n_s, r0).
struct SbGrid {
    // texels along angle, radius, s
    n: vec3<f32>,
    // radial warp: rho = asinh(r / r0) / rho_scale, rho_scale = asinh(2 / r0)
    r0: f32,
    rho_scale: f32,
};

const SB_TAU: f32 = 6.283185307179586;

// Continuous texel coordinates (angle, radius, s) of (u, v, w) = -wi - wr,
// texel centres at integers (crates/sunbeam-response/src/grid.rs).
fn sb_resp_coords(uvw: vec3<f32>, gr: SbGrid) -> vec3<f32> {
    let r = length(uvw.xy);
    var th = atan2(uvw.y, uvw.x);
    if (th < 0.0) {
        th = th + SB_TAU;
    }
    let rho = clamp(asinh(r / gr.r0) / gr.rho_scale, 0.0, 1.0);
    let s = clamp(-uvw.z / sqrt(max(4.0 - r * r, 1e-12)), 0.0, 1.0);
    return vec3<f32>(th / SB_TAU * gr.n.x, rho * (gr.n.y - 1.0), s * (gr.n.z - 1.0));
}

// Derivative of the angle coordinate (texels) along a screen direction, from
// those of u and v (no jump where the angle wraps).
fn sb_resp_dtheta(uv: vec2<f32>, duv: vec2<f32>, gr: SbGrid) -> f32 {
    let r2 = max(dot(uv, uv), 1e-12);
    return (uv.x * duv.y - uv.y * duv.x) / r2 * gr.n.x / SB_TAU;
}

// Derivatives of the texel coordinates (sb_resp_coords, without its clamps)
// along a change duvw of (u, v, w): how many texels a footprint spans.
fn sb_resp_dcoords(uvw: vec3<f32>, duvw: vec3<f32>, gr: SbGrid) -> vec3<f32> {
    let r = length(uvw.xy);
    var dr = length(duvw.xy);
    if (r > 1e-6) {
        dr = dot(uvw.xy, duvw.xy) / r;
    }
    let drho = dr / sqrt(gr.r0 * gr.r0 + r * r) / gr.rho_scale;
    let q = sqrt(max(4.0 - r * r, 1e-12));
    let ds = -duvw.z / q - uvw.z * r * dr / (q * q * q);
    return vec3<f32>(sb_resp_dtheta(uvw.xy, duvw.xy, gr), drho * (gr.n.y - 1.0), ds * (gr.n.z - 1.0));
}

// Normalised texture coordinates of texel coordinates c in a map of grid gr
// (the angle wraps by the sampler's repeat; rho and s clamped to the grid):
// every reader of a response map (the material's, the environment's maps)
// samples there, trilinear at level 0.
fn sb_resp_uvw(c: vec3<f32>, gr: SbGrid) -> vec3<f32> {
    let n = gr.n;
    let cc = vec3<f32>(c.x, clamp(c.y, 0.0, n.y - 1.0), clamp(c.z, 0.0, n.z - 1.0));
    return (cc + 0.5) / n;
}

// Trilinear read of the map at texel coordinates c.
fn sb_resp_sample(c: vec3<f32>, gr: SbGrid) -> vec3<f32> {
    return textureSampleLevel(resp_tex, resp_smp, sb_resp_uvw(c, gr), 0.0).xyz;
}

// G T at one direction pair (XYZ, without the masking; D65 white at Y = F(0)
// (absolute) or 1 (relative) for a flat mirror seen head-on under a light of
// intensity 1).
fn sb_diffraction_xyz(wi: vec3<f32>, wr: vec3<f32>, gr: SbGrid, skin: SbSkin) -> vec3<f32> {
    let uvw = -wi - wr;
    return sb_resp_sample(sb_resp_coords(uvw, gr), gr) * sb_gain(wi, wr, skin);
}

// G T averaged over the pixel (XYZ): the footprint is the parallelogram spanned
// by the screen derivatives dx, dy of (u, v, w); jx, jy are those of the texel
// coordinates (angle from sb_resp_dtheta). Up to 4 x 4 stratified samples cover
// it (a box filter, as a camera pixel integrates), as many per axis as texels it
// spans, one when it is within a texel. Each sample has its own (u, v, w), so
// its own texel coordinates and gain G(wi, wr') with wr' = -(u, v, w)' - wi.
fn sb_diffraction_xyz_filtered(wi: vec3<f32>, uvw: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, jx: vec3<f32>, jy: vec3<f32>, gr: SbGrid, skin: SbSkin) -> vec3<f32> {
    let nx = u32(clamp(ceil(length(jx)), 1.0, 4.0));
    let ny = u32(clamp(ceil(length(jy)), 1.0, 4.0));
    if (nx * ny == 1u) {
        return sb_resp_sample(sb_resp_coords(uvw, gr), gr) * sb_gain(wi, -uvw - wi, skin);
    }
    var acc = vec3<f32>(0.0);
    for (var a = 0u; a < nx; a = a + 1u) {
        for (var b = 0u; b < ny; b = b + 1u) {
            let ox = (f32(a) + 0.5) / f32(nx) - 0.5;
            let oy = (f32(b) + 0.5) / f32(ny) - 0.5;
            let q = uvw + ox * dx + oy * dy;
            let wr = normalize(-q - wi);
            acc = acc + sb_resp_sample(sb_resp_coords(-wi - wr, gr), gr) * sb_gain(wi, wr, skin);
        }
    }
    return acc / f32(nx * ny);
}
