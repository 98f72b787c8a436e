// The environment in the engines' export (docs/ENGINES.md "Environment"):
// the data access shaders/env_cells.wgsl asks of its host, from textures
// (WebGL2 has no storage buffers), and sunbeam_shade_environment. The files
// come from `sunbeam-play --export-environment DIR` (sunbeam_render::env_export).
//
// Bindings (group 0, after the material's 0 to 2):
//   3 env_chain: the prefiltered coefficient table, 2D RGBA16F with its mip
//     levels (equirectangular: u = phi / 2 pi - chain.phase with phi =
//     atan2(z, x), v = theta / pi from +y; level m is w / 2^m x h / 2^m;
//     chain.ktx2);
//   4, 5 the irradiance tables without the sun, 2D RGBA16F, one level, the
//     same coordinates without the phase (u = phi / 2 pi): transmitted
//     through the skin (irradiance-skin.ktx2) and plain (irradiance.ktx2);
//   6 env_smp: linear, linear between mip levels, repeat in u, clamp in v;
//   7 env_cells_tex: the cells, 2D RGBA32UI, floats 4 i to 4 i + 3 of
//     Cells::gpu_data (their bits) at texel (i % width, i / width)
//     (cells-I.ktx2);
//   8 sunbeam_env: the numbers (environment.json);
//   9 env_sun_map: the sky's sun, Omega_sun E_sun over directions: a
//     response map of the sun's spectrum (sun-I.ktx2, read like the material's
//     map, with its sampler 2), for sunbeam_shade_sun;
//   12 env_lights_tex: a map's hot spots as lights (shaders/env_hotspots.wgsl),
//     2D RGBA32F, one row, two texels per tap: (2 i, 0) the tap's world
//     direction, (2 i + 1, 0) its basis power (environment.json hot_spots);
//   13, 14, 15 env_basis0..2: the mesh's extended-light maps E_k, one per
//     basis function of the environment (basis-I-K.ktx2, response maps read
//     like the sun's, with sampler 2), for the hot spots.

struct SunbeamEnvironment {
    // the mesh's cells: x the top cut (meshes[].n_top; 0: none), y the maps'
    // s layers (n_s), z every node (nodes); w unused
    cells: vec4<f32>,
    // x: the chain's level-0 height (chain.height), y: its levels
    // (chain.levels), z: where its columns start, turns after phi = 0
    // (chain.phase: a map's rotation by a fraction of a texel); w unused
    chain: vec4<f32>,
    // xyz: towards the sun's centre (world, unit); w: 1 when the sky's sun
    // is up (sun.direction), else 0
    sun_dir: vec4<f32>,
    // rgb: the sun's Omega L, linear sRGB (sun.rgb); a: unused
    sun_rgb: vec4<f32>,
    // the sun map's grid: n_theta, n_rho, n_s, r0 (meshes[].sun_grid)
    sun_grid: vec4<f32>,
    // x: the hot spots' taps (hot_spots.length; 0: none); yzw unused
    hot: vec4<f32>,
    // the basis maps' grid: n_theta, n_rho, n_s, r0 (meshes[].basis_grid)
    basis_grid: vec4<f32>,
};

@group(0) @binding(3) var env_chain: texture_2d<f32>;
@group(0) @binding(4) var env_irr_skin: texture_2d<f32>;
@group(0) @binding(5) var env_irr_plain: texture_2d<f32>;
@group(0) @binding(6) var env_smp: sampler;
@group(0) @binding(7) var env_cells_tex: texture_2d<u32>;
@group(0) @binding(8) var<uniform> sunbeam_env: SunbeamEnvironment;
@group(0) @binding(9) var env_sun_map: texture_3d<f32>;
@group(0) @binding(12) var env_lights_tex: texture_2d<f32>;
@group(0) @binding(13) var env_basis0: texture_3d<f32>;
@group(0) @binding(14) var env_basis1: texture_3d<f32>;
@group(0) @binding(15) var env_basis2: texture_3d<f32>;

// The grid of an environment's response map from its uniform
// (n_theta, n_rho, n_s, r0), as the material's (rho_scale = asinh(2 / r0)).
fn env_map_grid(g: vec4<f32>) -> SbGrid {
    return SbGrid(g.xyz, g.w, asinh(2.0 / g.w));
}

// shaders/env_hotspots.wgsl's data access
fn env_hot_count() -> u32 {
    return u32(sunbeam_env.hot.x);
}

fn env_hot_dir(i: u32) -> vec3<f32> {
    return textureLoad(env_lights_tex, vec2<i32>(i32(2u * i), 0), 0).xyz;
}

fn env_hot_power(i: u32) -> vec3<f32> {
    return textureLoad(env_lights_tex, vec2<i32>(i32(2u * i + 1u), 0), 0).xyz;
}

fn env_hot_grid() -> SbGrid {
    return env_map_grid(sunbeam_env.basis_grid);
}

fn env_hot_maps(p: vec3<f32>, uvw: vec3<f32>) -> vec3<f32> {
    let gr = env_map_grid(sunbeam_env.basis_grid);
    let at = sb_resp_uvw(sb_resp_coords(uvw, gr), gr);
    return p.x * textureSampleLevel(env_basis0, resp_smp, at, 0.0).xyz
        + p.y * textureSampleLevel(env_basis1, resp_smp, at, 0.0).xyz
        + p.z * textureSampleLevel(env_basis2, resp_smp, at, 0.0).xyz;
}

// Floats 4 i to 4 i + 3: texel i (sunbeam-render's env_export.rs).
fn env_cell_v4(i: u32) -> vec4<f32> {
    let w = u32(textureDimensions(env_cells_tex, 0).x);
    return bitcast<vec4<f32>>(textureLoad(env_cells_tex, vec2<i32>(i32(i % w), i32(i / w)), 0));
}

fn env_cells_top() -> u32 {
    return u32(sunbeam_env.cells.x);
}

fn env_cells_nodes() -> u32 {
    return u32(sunbeam_env.cells.z);
}

fn env_cells_layers() -> u32 {
    return u32(sunbeam_env.cells.y);
}

fn env_cells_view(wr: vec3<f32>) -> vec2<f32> {
    let skin = SbSkin(sunbeam.skin.x, sunbeam.skin.y, sunbeam.skin.zw, sunbeam.energy);
    return vec2<f32>(sb_gain_view(wr.z, skin), sb_smith_lambda(wr, sunbeam.skin.zw));
}

fn env_cells_gain(wi: vec3<f32>, wr: vec3<f32>, view: vec2<f32>) -> f32 {
    return sb_gain_pair(wi, wr, sunbeam.skin.x) * view.x * sb_masking_with(wi, wr.z, view.y, sunbeam.skin.zw);
}

fn env_chain_height() -> u32 {
    return u32(sunbeam_env.chain.x);
}

fn env_chain_levels() -> u32 {
    return u32(sunbeam_env.chain.y);
}

fn env_chain_read(uv: vec2<f32>, level: f32) -> vec3<f32> {
    // (the sampler repeats in u)
    return textureSampleLevel(env_chain, env_smp, vec2<f32>(uv.x - sunbeam_env.chain.z, uv.y), level).xyz;
}

fn env_irradiance_read(skin: bool, uv: vec2<f32>) -> vec3<f32> {
    if (skin) {
        return textureSampleLevel(env_irr_skin, env_smp, uv, 0.0).xyz;
    }
    return textureSampleLevel(env_irr_plain, env_smp, uv, 0.0).xyz;
}

// The environment without its sun, linear sRGB leaving the surface towards
// wr (frame and directions as sunbeam_shade): the base lit by the
// transmitted irradiance, dw * base * E(n) / pi, plus (1 - dw) times the
// cells' diffraction (the player's `--env-estimator cells`, the same
// functions). The transmitted table is made for one index
// (environment.json `irradiance.ior`): the material's skin.x must be it.
fn sunbeam_shade_environment(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    return sunbeam_shade_environment_footprint(t, b, n, wr, env_no_footprint());
}

// As sunbeam_shade_environment, the hot spots' taps read over the pixel's
// footprint fp (EnvFootprint: the screen derivatives of t, b, n and of the
// local view (dot(wr, t), dot(wr, b), dot(wr, n)), dFdx / dFdy), as the
// player does: a hot spot's orders are sharp within a pixel.
fn sunbeam_shade_environment_footprint(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, fp: EnvFootprint) -> vec3<f32> {
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    if (wr_l.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let dw = sunbeam.warp.z;
    let base = dw * sunbeam.base.rgb * env_irradiance(true, n) / ENV_PI;
    if (dw >= 1.0 || env_cells_top() == 0u) {
        return base;
    }
    let xyz = env_cells(t, b, n, wr_l) + env_hotspots_footprint(t, b, n, wr_l, fp);
    return base + (1.0 - dw) * sb_xyz_to_linear_srgb(xyz);
}


// The sky's sun about direction wi (towards its centre, sun_dir; an
// engine's directional light, with its shadows), linear sRGB towards wr: as
// the player's sun, (1 - dw) G G2 Omega E_sun read from the sun's own map
// (the sun's spectrum: a white light tinted by its RGB would not do, a
// diffraction colour is nearly monochromatic), averaged over SB_SUN_POINTS
// points of the disc of solid angle sun_rgb.w about wi as the player's first
// frame does, G from its plane over the disc where the disc is at least
// SB_SUN_PLANE_COS above the horizon (0: the point wi alone), plus the base
// lit by the disc, dw * base * Omega L cos (1 - F) / pi at wi. 0 without a
// sun.
fn sunbeam_shade_sun(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    return sunbeam_shade_sun_footprint(t, b, n, wi, wr, env_no_footprint());
}

// As sunbeam_shade_sun, each point of the disc read at its own place in the
// pixel's footprint fp (as sunbeam_shade_environment_footprint;
// sb_sun_pixel_offset): the points integrate the disc and the pixel
// together, as the player's first frame does, where the sun's orders are
// sharp within a pixel (domed scales, packs of real size).
fn sunbeam_shade_sun_footprint(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>, fp: EnvFootprint) -> vec3<f32> {
    if (sunbeam_env.sun_dir.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    let skin = SbSkin(sunbeam.skin.x, sunbeam.skin.y, sunbeam.skin.zw, sunbeam.energy);
    let dw = sunbeam.warp.z;
    var diff = vec3<f32>(0.0);
    if (wr_l.z > 0.0 && sunbeam_env.sun_grid.x > 0.0) {
        let gr = env_map_grid(sunbeam_env.sun_grid);
        if (sunbeam_env.sun_rgb.w > 0.0) {
            let df = sunbeam_sun_disc_frame(wi);
            // G from its plane over the disc well above the horizon, as the
            // player's first frame (sun_gain.wgsl)
            let cos_cap = 1.0 - sunbeam_env.sun_rgb.w / SB_TAU;
            let gp = sb_sun_gain_plane(wi, df[0], df[1], cos_cap, t, b, n, wr_l, skin);
            for (var i = 0u; i < u32(SB_SUN_POINTS); i = i + 1u) {
                let d = sunbeam_sun_point_in(df, i);
                let o = sb_sun_pixel_offset(i);
                let shift = o.x * env_footprint_dx(d, fp) + o.y * env_footprint_dy(d, fp);
                let wi_l = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
                if (gp.w > 0.5) {
                    diff = diff + env_sun_map_at(wi_l, wr_l, gr, shift) * sb_sun_gain_at(gp, d, df[0], df[1]);
                } else {
                    diff = diff + env_sun_at(wi_l, wr_l, skin, gr, shift);
                }
            }
            diff = diff / SB_SUN_POINTS;
        } else {
            diff = env_sun_at(vec3<f32>(dot(wi, t), dot(wi, b), dot(wi, n)), wr_l, skin, gr, vec3<f32>(0.0));
        }
        diff = sb_xyz_to_linear_srgb(diff);
    }
    return sunbeam_shade_sun_base(t, b, n, wi) + (1.0 - dw) * diff;
}

// The base's part of sunbeam_shade_sun: dw * base * Omega L cos (1 - F) / pi
// at wi (linear sRGB; 0 without a sun).
fn sunbeam_shade_sun_base(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>) -> vec3<f32> {
    if (sunbeam_env.sun_dir.w <= 0.0) {
        return vec3<f32>(0.0);
    }
    let cos_i = max(dot(wi, n), 0.0);
    let lit = sunbeam_env.sun_rgb.rgb * cos_i * sb_base_transmission(cos_i, sunbeam.skin.x, true) / ENV_PI;
    return sunbeam.warp.z * sunbeam.base.rgb * lit;
}

// Point i (0 <= i < SB_SUN_POINTS, 16) of the sun's disc about wi (towards
// its centre): a Vogel spiral of equal solid angles over the cap of solid
// angle sun_rgb.w; wi itself for a sun without a disc (sun_rgb.w 0).
fn sunbeam_sun_point_dir(wi: vec3<f32>, i: u32) -> vec3<f32> {
    return sunbeam_sun_point_in(sunbeam_sun_disc_frame(wi), i);
}

// A frame about the disc's centre wi: columns dt, db and wi (made once for
// all of the disc's points).
fn sunbeam_sun_disc_frame(wi: vec3<f32>) -> mat3x3<f32> {
    let up = select(vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(1.0, 0.0, 0.0), abs(wi.y) > 0.9);
    let dt = normalize(cross(up, wi));
    return mat3x3<f32>(dt, cross(wi, dt), wi);
}

// sunbeam_sun_point_dir in the disc's frame f (sunbeam_sun_disc_frame).
fn sunbeam_sun_point_in(f: mat3x3<f32>, i: u32) -> vec3<f32> {
    return env_sun_point_of(f, i, SB_SUN_POINTS);
}

// Point i of a Vogel spiral of `count` points over the disc, in the disc's
// frame f.
fn env_sun_point_of(f: mat3x3<f32>, i: u32, count: f32) -> vec3<f32> {
    let omega = sunbeam_env.sun_rgb.w;
    if (omega <= 0.0) {
        return f[2];
    }
    return sb_sun_disc_dir(f[2], f[0], f[1], 1.0 - omega / SB_TAU, (f32(i) + 0.5) / count, f32(i) * SB_GOLDEN);
}

// Where in the pixel disc point i is read: offset (pixels, in [-1/2, 1/2)
// along x and y) from the pixel centre (sb_sun_pixel_offset).
fn sunbeam_sun_pixel_offset(i: u32) -> vec2<f32> {
    return sb_sun_pixel_offset(i);
}

// The diffraction of disc point i alone, (1 - dw) G G2 Omega E_sun in
// linear sRGB, for a host that reads each point with its own frame and view:
// on a mesh with scale maps, the frame the maps give at the point's place in
// the pixel (sunbeam_sun_pixel_offset(i), the attributes carried there along
// their screen derivatives) and the view from there, as the player's first
// frame does (docs/ENGINES.md "Scale maps under an environment"). The mean
// over i of this plus sunbeam_shade_sun_base is sunbeam_shade_sun at one
// frame.
fn sunbeam_shade_sun_point(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>, i: u32) -> vec3<f32> {
    return env_sun_point_diffraction(t, b, n, sunbeam_sun_point_dir(wi, i), wr);
}

// Where in the host's part of the pixel (its sub-pixel) point i of
// SB_SUN_SAMPLE_POINTS (64) is read: offset in [-1/2, 1/2) of that part
// along x and y from its centre (sb_sun_sample_offset).
fn sunbeam_sun_sample_offset(i: u32) -> vec2<f32> {
    return sb_sun_sample_offset(i);
}

// As sunbeam_shade_sun_point for point i of SB_SUN_SAMPLE_POINTS (64) of
// the disc, read at sunbeam_sun_sample_offset(i): what the player's first
// frame reads on a mesh with scale maps, where a domed scale's glint at a
// pack of real size is smaller than a sub-pixel and as narrow as the disc
// (docs/ENGINES.md "Scale maps under an environment"). The mean over i of
// this plus sunbeam_shade_sun_base is again sunbeam_shade_sun at one frame,
// over 64 points of the disc.
fn sunbeam_shade_sun_sample_point(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>, i: u32) -> vec3<f32> {
    let d = env_sun_point_of(sunbeam_sun_disc_frame(wi), i, f32(SB_SUN_SAMPLE_POINTS));
    return env_sun_point_diffraction(t, b, n, d, wr);
}

// The diffraction of the sun's disc point d (a world direction towards it),
// (1 - dw) G G2 Omega E_sun in linear sRGB towards wr, in the frame (t, b, n).
fn env_sun_point_diffraction(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, d: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let wr_l = vec3<f32>(dot(wr, t), dot(wr, b), dot(wr, n));
    if (sunbeam_env.sun_dir.w <= 0.0 || sunbeam_env.sun_grid.x <= 0.0 || wr_l.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let skin = SbSkin(sunbeam.skin.x, sunbeam.skin.y, sunbeam.skin.zw, sunbeam.energy);
    let gr = env_map_grid(sunbeam_env.sun_grid);
    let xyz = env_sun_at(vec3<f32>(dot(d, t), dot(d, b), dot(d, n)), wr_l, skin, gr, vec3<f32>(0.0));
    return (1.0 - sunbeam.warp.z) * sb_xyz_to_linear_srgb(xyz);
}

// The sun's map at local incidence wi and view wr, its (u, v, w) moved by
// `shift` (a place in the pixel's footprint), times G and the masking (XYZ;
// 0 for a direction below the horizon).
fn env_sun_at(wi: vec3<f32>, wr: vec3<f32>, skin: SbSkin, gr: SbGrid, shift: vec3<f32>) -> vec3<f32> {
    return env_sun_map_at(wi, wr, gr, shift) * sb_gain_masked(wi, wr, skin);
}

// The sun's map alone at local wi, wr and shift (env_sun_at without G; 0 for
// a direction below the horizon).
fn env_sun_map_at(wi: vec3<f32>, wr: vec3<f32>, gr: SbGrid, shift: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let at = sb_resp_uvw(sb_resp_coords(-wi - wr + shift, gr), gr);
    return textureSampleLevel(env_sun_map, resp_smp, at, 0.0).xyz;
}
