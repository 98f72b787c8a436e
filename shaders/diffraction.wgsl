// Sunbeam's player shading, shared by every technique (PHYSICS.md 1-3,
// docs/PLAY.md "Shading"): the uniforms, the vertex stage, and `shade`, the
// fragment's colour.
//
// Per fragment: local frame (t, b, n) with b = n x t (on a mesh with scale
// maps, the frame the maps give: shaders/scales.wgsl, frame_at), (u, v, w) =
// -wi - wr; per point light the diffraction term `point_xyz` (XYZ with the
// skin's gain G and Smith masking G2: shaders/material.wgsl, prepended);
// linear sRGB; diffuse blend dw * base * cos_i * (1 - F(th_i)) + (1 - dw) *
// rgb (the base alone, cos_i, without a pack); under a scene environment
// shaders/environment.wgsl's estimate (group 2); exposure; tone curve; sRGB
// OETF.
//
// `point_xyz` and the fragment entry point come from the technique's file,
// composed after this one (crates/sunbeam-render/src/renderer/mod.rs):
// shaders/default.wgsl (`fs_main`: the response map, T(u, v, w) precomputed
// per pack, crates/sunbeam-response) or shaders/baselines.wgsl
// (`fs_baseline`: table, direct, thesis; group 3). A mesh without a pack (and
// every mesh in the Lambert mode, whose material has no pack) shades its base
// colour alone through `fs_main`.

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
    // the rows of one band of the cells' walk targets laid out in bands
    // (shaders/default.wgsl band_point), for K > 1
    cells_band: u32,
    curve: u32,
    // 0: write display values (UNORM/float target); 1: write their linear value (sRGB target);
    // 2: write linear light times the exposure (offscreen; the display transform follows on the CPU)
    output: u32,
    exposure_scale: f32,
    n_lambda: u32,
    // samples per pixel of the colour target (1 or 4)
    msaa: u32,
    // the cells' rate (shaders/environment.wgsl env_cells_mixed,
    // env_cells_pixel): K >= 1 when the centre pass ran (after a coarse grid
    // of K x K pixels for K > 1), else 0
    cells_rate: u32,
    // 1: the cells' grid serves grazing views too (a tile of edge
    // refinement; shaders/environment.wgsl env_grid_serves), else 0
    cells_grazing: u32,
};

struct Material {
    // rgb: linear base colour, w: diffuse weight
    base: vec4<f32>,
    // 1: the mesh has a pack and diffracts (0 in the Lambert mode)
    has_pack: u32,
    // 1: the mesh's scale maps are bound (group 1, bindings 6 and 7) and
    // perturb the frame (shaders/scales.wgsl)
    scales_on: u32,
    // Smith masking (sunbeam_optics::masking): rms slopes along t and b; 0 = off
    mask_sx: f32,
    mask_sy: f32,
    // the skin (sunbeam_optics::gain::Material): refractive index, and what G
    // is divided by (1 absolute, F(0) relative; Material::norm)
    ior: f32,
    norm: f32,
    // response map (sunbeam-response): 1 when bound; texels (angle, radius, s);
    // radial warp rho = asinh(r / r0) / rho_scale; 1 = average over the footprint
    resp_on: u32,
    resp_n_theta: f32,
    resp_n_rho: f32,
    resp_n_s: f32,
    resp_r0: f32,
    resp_rho_scale: f32,
    resp_footprint: u32,
    // the scale maps' wraps (sb_scale_frame): bits 0-1 the normal map's
    // REPEAT along s and t, bits 2-3 the orientation map's
    scales_wrap: u32,
    // 1: the frame's pass reads the cells' pre-passes at this mesh's
    // fragments and the pre-passes shade it (shaders/environment.wgsl
    // env_cells_read, shaders/default.wgsl cells_shaded_here); set by the
    // renderer, the one place that decides it (crates/sunbeam-render/src/
    // renderer/mod.rs `reads_centre`)
    reads_cells: u32,
    // the mesh's index + 1, which the cells' grid walk compares with the
    // grid point's (shaders/default.wgsl fs_cells_walk)
    cells_id: u32,
    // the energy bound's table (SbSkin.energy)
    energy: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
// Clip-space x and y shrink by this factor about the frame's centre: 1,
// except in the cells' grid pass, which widens its viewport to match, so
// that its grid points on the frame's right and bottom edges (exactly on
// the clip volume's border, outside by the rasteriser's rule) are drawn
// (crates/sunbeam-render/src/renderer/cells_rate.rs GRID_PAD).
override SB_CLIP_SCALE: f32 = 1.0;
// The cells' pre-passes (crates/sunbeam-render/src/renderer/cells_rate.rs):
// in the grid's walk (fs_cells_walk) the grid's raster targets (fs_cells:
// the view with the mark, the frame's normal with the distance to the eye,
// its tangent with the mesh); in the centre pass (fs_cells_centre, read by
// env_cells_mixed) the coarse grid at 1/K of the pixels: the walk's XYZ (w:
// 1 where shaded), the normal with the distance, the tangent; in the
// centre's walk (fs_cells_walk) the centre pass's view with the mark,
// normal with the distance and tangent with the mesh; in the frame's pass
// (read by env_cells_pixel) the centre's XYZ and normal with the distance,
// per pixel (binding 4 unused). 1 x 1 stand-ins where none ran.
@group(0) @binding(2) var cells_xyz: texture_2d<f32>;
@group(0) @binding(3) var cells_nd: texture_2d<f32>;
@group(0) @binding(4) var cells_t: texture_2d<f32>;
// In the grid's walk, the half grid's walks (fs_cells_walk_half); else a
// 1 x 1 stand-in.
@group(0) @binding(5) var cells_half: texture_2d<f32>;
// xyz: colour weight of the sample, w: 1 / lambda in 1/um (the per-fragment
// baselines' wavelengths)
@group(0) @binding(1) var<storage, read> spectrum: array<vec4<f32>>;

@group(1) @binding(0) var<uniform> mat: Material;
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
    o.clip = vec4<f32>(o.clip.xy * SB_CLIP_SCALE, o.clip.zw);
    o.world = v.pos;
    o.normal = v.normal;
    o.tangent = v.tangent.xyz;
    o.uv = v.uv;
    o.uv_tangent = v.uv_tangent;
    return o;
}

// ---------------------------------------------------------------- response map
// The map's grid, whose texel coordinates `shade` differentiates (the
// material functions are in shaders/response_map.wgsl and
// shaders/material.wgsl, prepended to this file).
fn resp_grid() -> SbGrid {
    return SbGrid(vec3<f32>(mat.resp_n_theta, mat.resp_n_rho, mat.resp_n_s), mat.resp_r0, mat.resp_rho_scale);
}

// This mesh's skin (shaders/material.wgsl).
fn skin() -> SbSkin {
    return SbSkin(mat.ior, mat.norm, vec2<f32>(mat.mask_sx, mat.mask_sy), mat.energy);
}

// ---------------------------------------------------------------- colour
// The mesh's gain with its masking, G G2 (sunbeam_optics::masking::Masking::gain).
fn gain(wi: vec3<f32>, wr: vec3<f32>) -> f32 {
    return sb_gain_masked(wi, wr, skin());
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
        // the technique's term (shaders/default.wgsl, shaders/baselines.wgsl)
        let xyz = point_xyz(wi_l, wr_l, uvw, vec3<f32>(duv_x, dw_x), vec3<f32>(duv_y, dw_y), jx, jy);
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

// The centre of the quarter of the pixel that holds MSAA sample j (pixels
// from the centre): the part of the pixel the sample stands for. Points
// spread over a sample's part (env_sun_disc_carried) go over its quarter, so
// the four samples' points tile the pixel once. Half-pixel squares about
// the sample positions would overlap and reach 1/8 pixel past its sides, a
// kernel whose weight varies 2:1 across the pixel, which shows where the
// sun's orders are sharp within it: on the whole scaled snake with a 20 um
// pack, 8 x 8 under the sky, with 16 points a sample and the centre pass's
// cells, the squares read CIEDE2000 p99 6.56 where the quarters read 2.48
// (docs/bench/play.md "With a 20 um pack").
fn msaa_quarter(j: u32) -> vec2<f32> {
    return 0.5 * vec2<f32>(f32(j & 1u) - 0.5, f32(j >> 1u) - 0.5);
}

// The screen derivatives of a fragment's attributes (dpdx, dpdy), which
// carry them from the pixel centre to another point of the pixel.
struct AttrDerivs {
    world_x: vec3<f32>,
    world_y: vec3<f32>,
    normal_x: vec3<f32>,
    normal_y: vec3<f32>,
    tangent_x: vec3<f32>,
    tangent_y: vec3<f32>,
    uv_x: vec2<f32>,
    uv_y: vec2<f32>,
    uv_tangent_x: vec4<f32>,
    uv_tangent_y: vec4<f32>,
};

// The point and shading frame at offset o (pixels) from the centre, along the
// attributes' derivatives (the triangle's plane: it stays on the surface).
struct Carried {
    world: vec3<f32>,
    frame: mat3x3<f32>,
};

fn carried(in: VsOut, d: AttrDerivs, o: vec2<f32>) -> Carried {
    var c: Carried;
    c.world = in.world + d.world_x * o.x + d.world_y * o.y;
    c.frame = frame_at(
        in.normal + d.normal_x * o.x + d.normal_y * o.y,
        in.tangent + d.tangent_x * o.x + d.tangent_y * o.y,
        in.uv + d.uv_x * o.x + d.uv_y * o.y,
        in.uv_tangent + d.uv_tangent_x * o.x + d.uv_tangent_y * o.y
    );
    return c;
}

// What the environment needs at offset o (pixels) from the pixel centre:
// the frame carried there, the view in it and the distance to the eye.
struct CarriedView {
    frame: mat3x3<f32>,
    wr: vec3<f32>,
    dist: f32,
};

fn carried_view(in: VsOut, d: AttrDerivs, o: vec2<f32>) -> CarriedView {
    let c = carried(in, d, o);
    let fc = c.frame;
    let wr_c = normalize(g.eye.xyz - c.world);
    let wr_cl = vec3<f32>(dot(wr_c, fc[0]), dot(wr_c, fc[1]), dot(wr_c, fc[2]));
    return CarriedView(fc, wr_cl, length(g.eye.xyz - c.world));
}

// The environment (shaders/environment.wgsl env_shade) at offset o (pixels)
// from the pixel centre; `sun`: env_shade's (false where the caller adds
// env_sun_disc_carried).
fn env_shade_carried(in: VsOut, d: AttrDerivs, o: vec2<f32>, base: vec3<f32>, dw: f32, diffract: bool, fp: EnvFootprint, sun: bool) -> vec3<f32> {
    let v = carried_view(in, d, o);
    return env_shade(v.frame[0], v.frame[1], v.frame[2], v.wr, base, dw, diffract, in.clip.xy, v.dist, fp, true, sun);
}

// The environment at offset o (pixels) from the pixel centre without
// walking the cells (env_shade's `walk`): its colour in xyz, and in w 1
// where env_shade would have walked them (env_cells_walks), else 0.
fn env_shade_carried_nowalk(in: VsOut, d: AttrDerivs, o: vec2<f32>, base: vec3<f32>, dw: f32, diffract: bool, fp: EnvFootprint, sun: bool) -> vec4<f32> {
    let v = carried_view(in, d, o);
    let rgb = env_shade(v.frame[0], v.frame[1], v.frame[2], v.wr, base, dw, diffract, in.clip.xy, v.dist, fp, false, sun);
    let walks = env_cells_walks(v.frame[2], v.wr, dw, diffract, in.clip.xy, v.dist);
    return vec4<f32>(rgb, select(0.0, 1.0, walks));
}

// The cells' term (linear sRGB, dw applied) at offset o (pixels) from the
// pixel centre: one walk.
fn env_cells_carried(in: VsOut, d: AttrDerivs, o: vec2<f32>, dw: f32) -> vec3<f32> {
    let v = carried_view(in, d, o);
    if (v.wr.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return (1.0 - dw) * xyz_to_rgb(env_cells(v.frame[0], v.frame[1], v.frame[2], v.wr));
}

// The first-frame estimator's sun (linear sRGB, dw applied) on a mesh with
// scale maps, for a point at offset o (pixels) from the pixel centre that
// stands for `share` of the pixel along each axis: as env_sun_disc, each of
// the disc's SB_SUN_SAMPLE_POINTS points read at its own place in that part
// of the pixel (sb_sun_sample_offset), but with the frame and the view the scale
// maps give at that place (carried_view) instead of the footprint's linear
// model. A scale is about a pixel long at the scaled snake's size, its dome
// turns the sun's orders within it and its border turns them by the next
// scale's tilt and ridge angle: the screen derivatives of a 2 x 2 quad can
// not carry that, and each point's own read of the maps can
// (docs/LIGHTING.md "Scale borders").
fn env_sun_disc_carried(in: VsOut, d: AttrDerivs, o: vec2<f32>, share: f32, dw: f32) -> vec3<f32> {
    if (!(envg.on == 1u && env_by_cells() && envg.has_sun == 1u && envp.has_sun == 1u && envp.on == 1u && mat.has_pack == 1u && dw < 1.0)) {
        return vec3<f32>(0.0);
    }
    // this frame's share of the part of the pixel (env_shade's hot_fp); a
    // point under `--no-footprint`
    var k = 0.0;
    if (envg.hot_footprint == 1u) {
        k = share * envg.frame_share;
    }
    env_seed_at(vec2<u32>(in.clip.xy), envg.frame);
    let gr = env_grid();
    let r = SB_TAU * env_qmc(envg.frame + 1u, 19u);
    var xyz = vec3<f32>(0.0);
    for (var i = 0u; i < SB_SUN_SAMPLE_POINTS; i = i + 1u) {
        let v = carried_view(in, d, o + k * sb_sun_sample_offset(i));
        if (v.wr.z > 0.0) {
            xyz = xyz + env_sun_point_fp(v.frame[0], v.frame[1], v.frame[2], v.wr, gr, (f32(i) + 0.5) / f32(SB_SUN_SAMPLE_POINTS), r + f32(i) * SB_GOLDEN, vec2<f32>(0.0), env_no_footprint());
        }
    }
    return (1.0 - dw) * xyz_to_rgb(xyz / f32(SB_SUN_SAMPLE_POINTS));
}

// The colour of a fragment (`covered_px`: its sample mask), whichever the
// technique: each technique's entry point returns it.
fn shade(in: VsOut, covered_px: u32) -> vec4<f32> {
    // A frame of a running mean under MSAA is read at one sample
    // (EnvGlobals::frame_sample), which its jitter put where the pixel
    // centre is without MSAA: the fragment stands for that sample alone,
    // shaded there (the samples' loops below with one sample), and one that
    // does not cover it skips the environment (its value is not read).
    // Resolved, the four samples around each jittered centre widened the
    // sum's filter to 1.75 pixels (docs/PLAY.md "Environment").
    var covered = covered_px;
    let one_sample = envg.frame_sample < 4u;
    if (one_sample) {
        covered = covered_px & (1u << envg.frame_sample);
    }
    let fr = frame_at(in.normal, in.tangent, in.uv, in.uv_tangent);
    let t = fr[0];
    let b = fr[1];
    let n = fr[2];
    let wr = normalize(g.eye.xyz - in.world);
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    let base = mat.base.xyz;
    var dw = mat.base.w;
    let diffract = mat.has_pack == 1u;
    if (!diffract) {
        dw = 1.0;
    }
    // The attributes' screen derivatives, in uniform control flow: they carry
    // the attributes from the centre to a covered sample below.
    let da = AttrDerivs(
        dpdx(in.world), dpdy(in.world), dpdx(in.normal), dpdy(in.normal),
        dpdx(in.tangent), dpdy(in.tangent), dpdx(in.uv), dpdy(in.uv),
        dpdx(in.uv_tangent), dpdy(in.uv_tangent)
    );
    // The pixel's footprint for the environment's hot spots and the sun's
    // disc (the frame's and the view's derivatives at the centre). On a mesh
    // with scale maps (where the sun's disc reads the maps point by point
    // instead: env_sun_disc_carried) none where the 2 x 2 pixels whose
    // differences make the derivatives lie on more than one scale (as
    // three.js, sunbeam_scale_id): the frame jumps at a scale's border, and
    // a footprint across it smears both scales' orders together, a bias that
    // more samples do not remove (docs/LIGHTING.md "Scale borders"). The
    // scale id is read only on such meshes: `mat` is a uniform, so the
    // branch is uniform and its derivatives are defined.
    var env_fp = EnvFootprint(dpdx(t), dpdy(t), dpdx(b), dpdy(b), dpdx(n), dpdy(n), dpdx(wr_l), dpdy(wr_l));
    // In a frame of a running mean the footprint is the frame's share of the
    // pixel (env_shade's hot_fp): the differences across that share of the
    // frame carried half of it each way. The whole pixel's differences
    // scaled by the share misread a surface that turns tens of degrees
    // across a pixel (the baked snake at 96 x 48: 16 frames p99 3.5 inside
    // against 0.96 for the same 16 points in one 4 x 4 supersampled frame).
    // A share of 0 (the window's open-ended sum) reads a point.
    if (env_in_pipeline() && envg.on == 1u && envg.frame_share > 0.0 && envg.frame_share < 1.0) {
        let s = envg.frame_share;
        let x1 = carried_view(in, da, vec2<f32>(0.5 * s, 0.0));
        let x0 = carried_view(in, da, vec2<f32>(-0.5 * s, 0.0));
        let y1 = carried_view(in, da, vec2<f32>(0.0, 0.5 * s));
        let y0 = carried_view(in, da, vec2<f32>(0.0, -0.5 * s));
        env_fp = EnvFootprint(
            (x1.frame[0] - x0.frame[0]) / s, (y1.frame[0] - y0.frame[0]) / s,
            (x1.frame[1] - x0.frame[1]) / s, (y1.frame[1] - y0.frame[1]) / s,
            (x1.frame[2] - x0.frame[2]) / s, (y1.frame[2] - y0.frame[2]) / s,
            (x1.wr - x0.wr) / s, (y1.wr - y0.wr) / s
        );
    }
    if (mat.scales_on == 1u) {
        if (fwidth(sb_scale_id(scale_orient, in.uv, (mat.scales_wrap >> 2u) & 3u)) >= 0.5) {
            env_fp = env_no_footprint();
        }
    }
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
    // each sample's share of the pixel along each axis: a quarter of it
    // (half the footprint) when the samples make the pixel; the frame's share
    // when one sample is read (the frames' jitter spreads it over the pixel)
    var sample_share = 0.5;
    if (one_sample) {
        sample_share = envg.frame_share;
    }
    // the pixel centre's: the whole pixel, or in a frame of a running mean
    // the frame's share (its jitter spreads the frames over the pixel; the
    // whole footprint in each widened the sum's filter, as the environment's
    // hot spots: EnvGlobals::frame_share)
    var centre_share = 1.0;
    if (envg.on == 1u && envg.frame_share < 1.0) {
        centre_share = envg.frame_share;
    }
    // On a mesh with scale maps every pixel does so (with MSAA), each sample
    // reading the maps at its own uv: the frame varies at the maps' texels
    // and jumps at the scale borders, where the screen derivatives of
    // (u, v, w), the footprint filter's linear model, fail (across a border
    // they spread the response over both scales' lobes instead of mixing
    // the two); the samples resolve the variation (docs/PLAY.md "Scale maps").
    let at_samples = g.msaa >= 4u && n_cov > 0u && ((n_cov < 4u && dot(wr, n) <= ENV_GRAZING_COS) || mat.scales_on == 1u || one_sample);
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
                    let c = carried(in, da, msaa_position(j));
                    let wr_s = normalize(g.eye.xyz - c.world);
                    let k = sample_share;
                    acc = acc + shade_light(i, c.frame, wr_s, diffract, dw, k * duv_x, k * duv_y, k * dw_x, k * dw_y, k * jx, k * jy);
                }
            }
            rgb = rgb + acc / f32(n_cov);
        } else {
            let k = centre_share;
            rgb = rgb + shade_light(i, fr, wr, diffract, dw, k * duv_x, k * duv_y, k * dw_x, k * dw_y, k * jx, k * jy);
        }
    }
    // The scene's environment (shaders/environment.wgsl): one Monte Carlo
    // estimate per frame, accumulated by the caller, or the first-frame
    // estimator's cells.
    if (env_in_pipeline() && envg.on == 1u && !(one_sample && n_cov == 0u)) {
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
        //
        // The first-frame estimator (the cells) is one frame, not a running
        // mean, so it picks no sample: a partly covered pixel (a silhouette,
        // or an edge between triangles) shades every covered sample and
        // takes their mean, as the point lights do at silhouettes; every
        // other pixel its centre. The centre of a partly covered pixel may
        // lie past its triangle, where the attributes are extrapolated: on
        // the baked snake under the sky (96 x 48, 4 x 4 supersampled) the
        // first frame's interior p99 against the reference was 8.5 so, 1.4
        // at the samples, and 8.5 again when only the pixels whose centre
        // missed the surface took the samples: along the tapering tail the
        // triangles are smaller than a sub-pixel and turn fast
        // (docs/LIGHTING.md "The first frame"). The cells are walked once,
        // at the mean of the samples that would walk them (inside the
        // triangle: the mean of points of a convex set), for all of them:
        // Mesa's llvmpipe stops an invocation's loops after 65,535
        // iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS), and three walks
        // of 2048 cells were cut short, darkening the partly covered pixels
        // of grazing views (docs/LIGHTING.md "One walk per fragment").
        if (env_by_cells()) {
            // On a mesh with scale maps the sun's disc reads the maps at
            // each of its points (env_sun_disc_carried).
            let scaled = mat.scales_on == 1u;
            if (g.msaa >= 4u && (n_cov < 4u || scaled)) {
                // (a mesh with scale maps too, as the point lights: the
                // sun's orders jump at the scales' borders)
                var acc = vec3<f32>(0.0);
                var at = vec2<f32>(0.0);
                var k = 0.0;
                // each sample's share of the pixel (the frame's share is
                // applied in env_shade)
                var sample_fp = env_footprint_times(env_fp, 0.5);
                if (one_sample) {
                    sample_fp = env_fp;
                }
                for (var j = 0u; j < 4u; j = j + 1u) {
                    if (((covered >> j) & 1u) == 1u) {
                        let sj = env_shade_carried_nowalk(in, da, msaa_position(j), base, dw, diffract, sample_fp, !scaled);
                        acc = acc + sj.xyz;
                        if (scaled && one_sample) {
                            acc = acc + env_sun_disc_carried(in, da, msaa_position(j), 1.0, dw);
                        } else if (scaled) {
                            acc = acc + env_sun_disc_carried(in, da, msaa_quarter(j), 0.5, dw);
                        }
                        at = at + sj.w * msaa_position(j);
                        k = k + sj.w;
                    }
                }
                if (k > 0.0) {
                    acc = acc + k * env_cells_carried(in, da, at / k, dw);
                }
                rgb = rgb + acc / f32(n_cov);
            } else {
                rgb = rgb + env_shade_carried(in, da, vec2<f32>(0.0), base, dw, diffract, env_fp, !scaled);
                if (scaled) {
                    rgb = rgb + env_sun_disc_carried(in, da, vec2<f32>(0.0), 1.0, dw);
                }
            }
        } else {
            var off = vec2<f32>(0.0);
            if (g.msaa >= 4u && (one_sample || dot(wr, n) <= ENV_GRAZING_COS)) {
                env_seed_at(vec2<u32>(in.clip.xy), envg.frame);
                off = covered_pick(covered, env_qmc(envg.frame + 1u, 31u));
            }
            rgb = rgb + env_shade_carried(in, da, off, base, dw, diffract, env_fp, true);
        }
    }
    return display(rgb);
}
