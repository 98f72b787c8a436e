// Sunbeam environment lighting in the player (docs/PLAY.md "Environment";
// contract: docs/LIGHTING.md, crates/sunbeam-response/src/env.rs).
//
// Appended to shaders/material.wgsl + shaders/response_map.wgsl +
// shaders/diffraction.wgsl (it uses their Globals `g`, Material `mat`, SbGrid,
// sb_resp_coords, the mesh's gain with its masking `gain` and
// sb_base_transmission). Per pixel and frame, for a surface with local frame
// (t, b, n) and view wr (local):
//
// - diffraction: `samples` draws (u, v), each from the proposal pyramid
//   (hierarchical sample warping over the dual cells of the polar grid, the
//   same cell weights and density as sunbeam_response::Proposal) or, with
//   probability ENV_DEFENSIVE, uniform over the hemisphere, weighed by the
//   mixture's density (EnvResponse::draw / density); wi = (-u - wr_x, -v - wr_y, sqrt(..)),
//   XYZ += [G G2 / wi_z] sum_k c_k(wi) E_k(u, v, w) / pdf(u, v), with c_k from the
//   coefficient table and E_k the extended-light response maps (same coordinates
//   and sampler as the point-light map);
// - the sun (sky only): one direction uniform on its disc,
//   XYZ += G G2(wi, wr) [Omega_sun E_sun](u, v, w) (the map holds the product);
// - diffuse: one cosine-weighted direction d, base * L_rgb(d) (1 - F(theta_d))
//   (the estimate of the transmitted irradiance, the integral of
//   L (1 - F) cos over the hemisphere, pi L (1 - F) over pi: the skin's
//   Fresnel per sampled direction), plus the sun's
//   base / pi * Omega cos(theta_sun) (1 - F(theta_sun)) rgb_sun (F at the
//   disc's centre); 1 - F only under a skin (a mesh with a pack).
//
// Random numbers: the PCG hash (Jarzynski and Olano 2020, "Hash functions for
// GPU rendering") of the pixel, the frame index (frames accumulated since the
// last reset) and the sample's dimension: env_rand(k) = pcg(seed ^ pcg(k)),
// seed = pcg(x ^ pcg(y ^ pcg(frame))).

struct EnvGlobals {
    // rows of the matrix basis coefficients -> linear sRGB (L_rgb(d) = M c(d))
    basis_to_rgb: array<vec4<f32>, 3>,
    // xyz: towards the sun's centre (world, unit); w: cos of its angular radius
    sun_dir: vec4<f32>,
    // rgb: linear sRGB radiance of the disc; w: its solid angle (sr)
    sun_rgb: vec4<f32>,
    // an orthonormal pair perpendicular to sun_dir (disc sampling)
    sun_t: vec4<f32>,
    sun_b: vec4<f32>,
    // coefficient table size (texels, width = 2 height)
    table_w: u32,
    table_h: u32,
    // frames accumulated since the last reset (the random numbers' seed)
    frame: u32,
    // 1: the scene has an environment
    on: u32,
    // 1: a sky with the sun up
    has_sun: u32,
    // proposal samples per pixel per frame
    samples: u32,
    // 0: the cells (first-frame estimator), 1: Monte Carlo; the shaders
    // read SB_ENV_ESTIMATOR, which equals it
    estimator: u32,
    // levels of the prefiltered chain env_chain
    chain_levels: u32,
    // the skin index of the transmitted irradiance table
    irr_ior: f32,
    // where the table's (and the chain's) columns start, turns after phi = 0
    // (Environment::table_phase)
    table_phase: f32,
    // 1: the hot spots' taps read the maps over the pixel's footprint
    // (env_hotspots_footprint), 0: at one point
    hot_footprint: u32,
    // the part of the pixel along each axis one frame of a running mean
    // stands for: the footprint's scale (EnvGlobals::frame_share)
    frame_share: f32,
    // under MSAA, the one sample of each pixel a frame of a running mean is
    // read at (EnvGlobals::frame_sample); 4: the resolved pixel
    frame_sample: u32,
};

struct EnvProposal {
    // offset of level l in `pyramid` at offsets[l / 4][l % 4] (levels 0..=top)
    offsets: array<vec4<u32>, 4>,
    // padded cell counts of level 0 (angle, radius), top level index, s layers
    pw: u32,
    ph: u32,
    top: u32,
    n_s: u32,
    // the maps' grid: texels along angle, radius, s; radial warp
    n_theta: f32,
    n_rho: f32,
    n_s_f: f32,
    r0: f32,
    rho_scale: f32,
    // 1: this mesh has a pack and maps (diffraction under the environment)
    on: u32,
    // 1: E_sun is bound
    has_sun: u32,
    // cells of the top cut in env_cells (0: none)
    n_cells: u32,
};

@group(2) @binding(0) var<uniform> envg: EnvGlobals;
@group(2) @binding(1) var<uniform> envp: EnvProposal;
// level l, layer k, cell (x, y) at offsets[l] + (k * H_l + y) * W_l + x
@group(2) @binding(2) var<storage, read> pyramid: array<f32>;
// E_0, E_1, E_2 and E_sun: XYZ per basis spectrum, as the point map's texels
@group(2) @binding(3) var env_e0: texture_3d<f32>;
@group(2) @binding(4) var env_e1: texture_3d<f32>;
@group(2) @binding(5) var env_e2: texture_3d<f32>;
@group(2) @binding(6) var env_esun: texture_3d<f32>;
@group(2) @binding(7) var env_smp: sampler;
// coefficients c_0..c_2 per texel (equirectangular, theta from +y, phi = atan2(z, x))
@group(2) @binding(8) var env_table: texture_2d<f32>;
// the table prefiltered by solid angle (sunbeam_light::prefilter, f16, mips)
@group(2) @binding(9) var env_chain: texture_2d<f32>;
// irradiance per normal without the sun (sunbeam_light::irradiance, linear
// sRGB): transmitted through the skin (weight cos (1 - F)), and plain
@group(2) @binding(10) var env_irr_skin: texture_2d<f32>;
@group(2) @binding(11) var env_irr_plain: texture_2d<f32>;
// the maps' cells (sunbeam_response::cells::Cells::gpu_data), four floats an element
@group(2) @binding(12) var<storage, read> cells: array<vec4<f32>>;
// the hot spots' taps (shaders/env_hotspots.wgsl), two vec4 per tap:
// (world direction, 0) and (the light's basis power times the tap's weight, 0)
@group(2) @binding(13) var<storage, read> env_lights: array<vec4<f32>>;

// The environment's estimator as a pipeline constant (0: the cells, 1:
// Monte Carlo, as envg.estimator; 2: a pipeline that never shades an
// environment, envg.on 0): the driver then compiles only the path a scene
// takes. With every path behind the uniforms, llvmpipe took 20-29 s to
// compile the default pipeline on its first use (docs/bench/play.md
// "Shader compile time and unused paths").
override SB_ENV_ESTIMATOR: u32 = 0u;

// Whether the first-frame estimator (the cells) shades the environment.
fn env_by_cells() -> bool {
    return SB_ENV_ESTIMATOR == 0u;
}

// Whether this pipeline shades an environment at all (where envg.on may be 1).
fn env_in_pipeline() -> bool {
    return SB_ENV_ESTIMATOR < 2u;
}

// shaders/env_hotspots.wgsl's data access
fn env_hot_count() -> u32 {
    return arrayLength(&env_lights) / 2u;
}

fn env_hot_dir(i: u32) -> vec3<f32> {
    return env_lights[2u * i].xyz;
}

fn env_hot_power(i: u32) -> vec3<f32> {
    return env_lights[2u * i + 1u].xyz;
}

fn env_hot_grid() -> SbGrid {
    return env_grid();
}

fn env_hot_maps(p: vec3<f32>, uvw: vec3<f32>) -> vec3<f32> {
    let gr = env_grid();
    let rc = sb_resp_coords(uvw, gr);
    return p.x * env_map(env_e0, rc, gr) + p.y * env_map(env_e1, rc, gr) + p.z * env_map(env_e2, rc, gr);
}

// ---------------------------------------------------------------- random numbers
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

var<private> env_seed: u32;

fn env_seed_at(px: vec2<u32>, frame: u32) {
    env_seed = pcg(px.x ^ pcg(px.y ^ pcg(frame)));
    env_pixel = pcg(px.x ^ pcg(px.y ^ 0x9e3779b9u));
}

// Uniform in [0, 1) for dimension k of this pixel and frame.
fn env_rand(k: u32) -> f32 {
    return f32(pcg(env_seed ^ pcg(k)) >> 8u) * (1.0 / 16777216.0);
}

// The pixel's own hash, the same in every frame (the shifts of env_qmc).
var<private> env_pixel: u32;

// Point `i` (from 1) of the Halton sequence in prime `base`, shifted by a
// uniform of this pixel (Cranley-Patterson rotation): over the frames a
// pixel's points fill [0, 1) evenly (the error of the running mean falls
// nearly as 1 / frames where the integrand allows, not 1 / sqrt(frames));
// each frame alone is still uniform, and neighbouring pixels are
// independent. The bases 2 and 3 are the sub-pixel jitter's
// (renderer::subpixel_jitter), so the sampling takes 5 and up.
fn env_qmc(i: u32, base: u32) -> f32 {
    var f = 1.0;
    var r = 0.0;
    var n = i;
    let b = f32(base);
    while (n > 0u) {
        f = f / b;
        r = r + f * f32(n % base);
        n = n / base;
    }
    let shift = f32(pcg(env_pixel ^ pcg(base)) >> 8u) * (1.0 / 16777216.0);
    return fract(r + shift);
}

// ---------------------------------------------------------------- lookups
fn env_grid() -> SbGrid {
    return SbGrid(vec3<f32>(envp.n_theta, envp.n_rho, envp.n_s_f), envp.r0, envp.rho_scale);
}

// Trilinear read of one map at texel coordinates c (as sb_resp_sample).
fn env_map(tex: texture_3d<f32>, c: vec3<f32>, gr: SbGrid) -> vec3<f32> {
    return textureSampleLevel(tex, env_smp, sb_resp_uvw(c, gr), 0.0).xyz;
}

// Coefficients c_k of the radiance from world direction d: the texel that
// contains it (no filtering, as EnvMap::lookup).
fn env_coefficients(d: vec3<f32>) -> vec3<f32> {
    return sb_env_texel(env_table, envg.table_w, envg.table_h, envg.table_phase, d);
}

fn env_basis_rgb(c: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(envg.basis_to_rgb[0].xyz, c), dot(envg.basis_to_rgb[1].xyz, c), dot(envg.basis_to_rgb[2].xyz, c));
}

// ---------------------------------------------------------------- the proposal
fn env_r_at(rho: f32) -> f32 {
    return min(envp.r0 * sinh(rho * envp.rho_scale), 2.0);
}

// The largest radius of the visible disc (|(u, v) - p| < 1, p = -wr_xy, |p| < 1)
// along angle th.
fn env_r_max(p: vec2<f32>, th: f32) -> f32 {
    let pe = dot(p, vec2<f32>(cos(th), sin(th)));
    return pe + sqrt(max(1.0 - dot(p, p) + pe * pe, 0.0));
}

fn env_w(l: u32) -> u32 {
    return max(envp.pw >> l, 1u);
}

fn env_h(l: u32) -> u32 {
    return max(envp.ph >> l, 1u);
}

fn env_offset(l: u32) -> u32 {
    return envp.offsets[l / 4u][l % 4u];
}

// True when level-l cell with real extent [x0, x1] x [y0, y1] (level-0 cell
// units) meets the view's disc |(u, v) + wr_xy| < 1: exact distance from the
// disc's centre p = -wr_xy to the cell's annular sector
// (Proposal::reaches_disc).
fn env_reaches_disc(x0: f32, x1: f32, y0: f32, y1: f32, wr: vec3<f32>) -> bool {
    let n1 = envp.n_rho - 1.0;
    let ra = env_r_at(y0 / n1);
    let rb = env_r_at(y1 / n1);
    let ta = SB_TAU * x0 / envp.n_theta;
    let tb = SB_TAU * x1 / envp.n_theta;
    let p = -wr.xy;
    let rp = length(p);
    var tp = atan2(p.y, p.x);
    if (tp < 0.0) {
        tp = tp + SB_TAU;
    }
    var d = 0.0;
    if (rp == 0.0 || (tp >= ta && tp <= tb)) {
        d = max(max(ra - rp, rp - rb), 0.0);
    } else {
        let ea = vec2<f32>(cos(ta), sin(ta));
        let eb = vec2<f32>(cos(tb), sin(tb));
        let sa = clamp(dot(p, ea), ra, rb);
        let sb = clamp(dot(p, eb), ra, rb);
        d = min(length(p - sa * ea), length(p - sb * eb));
    }
    return d < 1.0;
}

// e(c) of cell (x, y) of level l for view wr (Proposal::weight): 0 when the
// cell holds no real cell or misses the view's disc; else the mean, over its
// four sub-points (fractions 0.25 / 0.75 of its real extent) inside the disc,
// of the stored value interpolated between the two s layers of that point
// times G / max(wi_z, 0.05) (the mesh's skin; unmasked); 0.05 * max(v G) when
// no sub-point is inside.
// Sub-points, not the centre: across a coarse cell G / cos, s and the rim
// change, and centre weights starved the lit cells by factors of 30-400.
fn env_cell_weight(l: u32, x: u32, y: u32, wr: vec3<f32>) -> f32 {
    let wl = env_w(l);
    let hl = env_h(l);
    let sx = envp.pw / wl;
    let sy = envp.ph / hl;
    let x0 = f32(x * sx);
    let x1 = min(f32((x + 1u) * sx), envp.n_theta);
    let y0 = f32(y * sy);
    let y1 = min(f32((y + 1u) * sy), envp.n_rho - 1.0);
    if (!(x0 < x1 && y0 < y1)) {
        return 0.0;
    }
    if (!env_reaches_disc(x0, x1, y0, y1, wr)) {
        return 0.0;
    }
    let o = env_offset(l);
    let n1 = envp.n_rho - 1.0;
    var sum = 0.0;
    var n_in = 0u;
    var fallback = 0.0;
    for (var q = 0u; q < 4u; q = q + 1u) {
        let fx = select(0.25, 0.75, (q & 1u) == 1u);
        let fy = select(0.25, 0.75, (q >> 1u) == 1u);
        let theta = SB_TAU * (x0 + fx * (x1 - x0)) / envp.n_theta;
        let r = env_r_at((y0 + fy * (y1 - y0)) / n1);
        var wxy = -r * vec2<f32>(cos(theta), sin(theta)) - wr.xy;
        let len = length(wxy);
        let inside = len < 1.0;
        if (len > 0.999) {
            wxy = wxy * (0.999 / len);
        }
        let wz = sqrt(max(1.0 - dot(wxy, wxy), 0.0));
        let wi = vec3<f32>(wxy, wz);
        let s = clamp((wz + wr.z) / sqrt(max(4.0 - r * r, 1e-12)), 0.0, 1.0);
        let sc = s * f32(envp.n_s - 1u);
        let k0 = min(u32(floor(sc)), max(envp.n_s, 2u) - 2u);
        let k1 = min(k0 + 1u, envp.n_s - 1u);
        let f = sc - f32(k0);
        let v = mix(pyramid[o + (k0 * hl + y) * wl + x], pyramid[o + (k1 * hl + y) * wl + x], f);
        let gn = sb_gain(wi, wr, skin());
        if (inside) {
            sum = sum + v * gn / max(wz, 0.05);
            n_in = n_in + 1u;
        } else {
            fallback = max(fallback, v * gn);
        }
    }
    if (n_in > 0u) {
        return sum / f32(n_in);
    }
    return fallback * 0.05;
}

// The children at level l - 1 of cell (x, y) of level l, in the order y
// outer, x inner (slot 2 cy + cx; 0 where a side did not halve), and their
// weights for view wr: what the draw (env_descend) and the density of a
// given point (env_pdf) both weigh.
struct EnvChildren {
    x0: u32,
    y0: u32,
    e: array<f32, 4>,
    total: f32,
};

fn env_children(l: u32, x: u32, y: u32, wr: vec3<f32>) -> EnvChildren {
    let lc = l - 1u;
    var nx = 1u;
    if (env_w(lc) > env_w(l)) {
        nx = 2u;
    }
    var ny = 1u;
    if (env_h(lc) > env_h(l)) {
        ny = 2u;
    }
    var out: EnvChildren;
    out.x0 = x * nx;
    out.y0 = y * ny;
    out.e = array<f32, 4>(0.0, 0.0, 0.0, 0.0);
    out.total = 0.0;
    for (var c = 0u; c < 4u; c = c + 1u) {
        let cx = c & 1u;
        let cy = c >> 1u;
        if (cx < nx && cy < ny) {
            out.e[c] = env_cell_weight(lc, out.x0 + cx, out.y0 + cy, wr);
            out.total = out.total + out.e[c];
        }
    }
    return out;
}

// Density per unit (u, v) with which env_descend draws uv for view wr
// (Proposal::pdf): the descent repeated along the level-0 cell holding uv.
fn env_pdf(wr: vec3<f32>, uv: vec2<f32>) -> f32 {
    let r = length(uv);
    if (!(r < 2.0)) {
        return 0.0;
    }
    var th = atan2(uv.y, uv.x);
    if (th < 0.0) {
        th = th + SB_TAU;
    }
    let i = min(u32(th / SB_TAU * envp.n_theta), u32(envp.n_theta) - 1u);
    let nr = u32(envp.n_rho);
    var j = min(u32(asinh(r / envp.r0) / envp.rho_scale * (envp.n_rho - 1.0)), nr - 2u);
    // The cell's radii are r_at(j), r_at(j + 1): settle rounding at the edges.
    if (j > 0u && r < env_r_at(f32(j) / (envp.n_rho - 1.0))) {
        j = j - 1u;
    }
    if (j + 2u < nr && r >= env_r_at(f32(j + 1u) / (envp.n_rho - 1.0))) {
        j = j + 1u;
    }
    var p = 1.0;
    var x = 0u;
    var y = 0u;
    for (var l = envp.top; l > 0u; l = l - 1u) {
        let lc = l - 1u;
        var ch = env_children(l, x, y, wr);
        let want = vec2<u32>(i / (envp.pw / env_w(lc)), j / (envp.ph / env_h(lc)));
        let total = ch.total;
        let mine = ch.e[(want.y - ch.y0) * 2u + (want.x - ch.x0)];
        if (!(total > 0.0 && mine > 0.0)) {
            return 0.0;
        }
        p = p * mine / total;
        x = want.x;
        y = want.y;
    }
    let rj = env_r_at(f32(j) / (envp.n_rho - 1.0));
    let rj1 = env_r_at(f32(j + 1u) / (envp.n_rho - 1.0));
    let area = (SB_TAU / envp.n_theta) * (rj1 * rj1 - rj * rj) / 2.0;
    if (!(area > 0.0)) {
        return 0.0;
    }
    return p / area;
}

// Share of the draws uniform over the hemisphere (env::DEFENSIVE): bounds the
// integrand's 1 / cos(theta_i), which the proposal follows only at its
// cells' sub-points.
const ENV_DEFENSIVE: f32 = 0.25;

// A grazing view: below this cos(theta_r) a still frame takes
// ENV_GRAZING_SAMPLES times the draws per pixel (env_shade), and with MSAA a
// partly covered pixel shades at one of its covered samples (fs_main).
const ENV_GRAZING_COS: f32 = 0.2;
const ENV_GRAZING_SAMPLES: u32 = 4u;

// The views the cells' coarse grid serves: above ENV_GRAZING_COS in a frame,
// where the term changes fastest across a pixel at the limb, the grid's
// blocks fail their cone there and its points would walk for nothing (the
// centre pass walks those pixels, once each); every view above the horizon
// in a tile of edge refinement (g.cells_grazing: its texels are 1 / m of
// the image's pixels, so the grid's blocks pass their cone and curvature
// tests at the limb too: docs/LIGHTING.md "Edge refinement").
fn env_grid_serves(wr_z: f32) -> bool {
    return wr_z > select(ENV_GRAZING_COS, 0.0, g.cells_grazing == 1u);
}

// Density per unit (u, v) of a direction uniform over the hemisphere.
fn env_hemi_pdf(wr: vec3<f32>, uv: vec2<f32>) -> f32 {
    let wxy = -uv - wr.xy;
    let r2 = dot(wxy, wxy);
    if (r2 >= 1.0) {
        return 0.0;
    }
    return 1.0 / (SB_TAU * sqrt(1.0 - r2));
}

struct EnvDraw {
    uv: vec2<f32>,
    // density over (u, v); 0: no sample
    pdf: f32,
};

// One (u, v) from the pyramid for view wr and uniforms u (contract: "Descent").
// u.x is rescaled from level to level (the contract's one u0: a stratified
// u.x over the frames keeps the children stratified) while float32 keeps
// enough of its bits: once a uniform has been stretched by more than 2^18
// (the product of total / picked), the next level takes a fresh uniform
// env_rand(q + 3 + l).
fn env_descend(wr: vec3<f32>, u: vec3<f32>, q: u32) -> EnvDraw {
    var out: EnvDraw;
    out.pdf = 0.0;
    out.uv = vec2<f32>(0.0);
    var x = 0u;
    var y = 0u;
    var p = 1.0;
    var u0 = u.x;
    var stretch = 1.0;
    for (var l = envp.top; l > 0u; l = l - 1u) {
        let lc = l - 1u;
        if (stretch > 262144.0) {
            u0 = env_rand(q + 3u + l);
            stretch = 1.0;
        }
        var ch = env_children(l, x, y, wr);
        let x0 = ch.x0;
        let y0 = ch.y0;
        var e = ch.e;
        let total = ch.total;
        if (!(total > 0.0)) {
            return out;
        }
        let target_ = u0 * total;
        // the first child whose cumulative weight passes u0 * total
        var acc = 0.0;
        var pick = 4u;
        var last = 0u;
        var acc_last = 0.0;
        for (var c = 0u; c < 4u; c = c + 1u) {
            if (pick == 4u && e[c] > 0.0) {
                if (acc + e[c] > target_) {
                    pick = c;
                } else {
                    last = c;
                    acc_last = acc;
                    acc = acc + e[c];
                }
            }
        }
        if (pick == 4u) {
            pick = last;
            acc = acc_last;
        }
        let pe = e[pick];
        p = p * pe / total;
        x = x0 + (pick & 1u);
        y = y0 + (pick >> 1u);
        u0 = clamp((target_ - acc) / pe, 0.0, 0.99999994);
        stretch = stretch * total / pe;
    }
    let rj = env_r_at(f32(y) / (envp.n_rho - 1.0));
    let rj1 = env_r_at(f32(y + 1u) / (envp.n_rho - 1.0));
    let area = (SB_TAU / envp.n_theta) * (rj1 * rj1 - rj * rj) / 2.0;
    if (!(area > 0.0)) {
        return out;
    }
    let theta = SB_TAU * (f32(x) + u.y) / envp.n_theta;
    let r = sqrt(rj * rj + u.z * (rj1 * rj1 - rj * rj));
    out.uv = r * vec2<f32>(cos(theta), sin(theta));
    out.pdf = p / area;
    return out;
}

// ---------------------------------------------------------------- the cells
// The cells' evaluation is shaders/env_cells.wgsl (shared with the engines'
// export, shaders/export_env.wgsl); the player supplies its data access here:
// the nodes from the storage buffer, the chain and irradiance tables from
// group 2, the mesh's gain with its masking.
fn env_cell_v4(i: u32) -> vec4<f32> {
    return cells[i];
}

fn env_cells_top() -> u32 {
    return envp.n_cells;
}

fn env_cells_nodes() -> u32 {
    return arrayLength(&cells) / env_cell_stride(envp.n_s);
}

fn env_cells_layers() -> u32 {
    return envp.n_s;
}

fn env_cells_view(wr: vec3<f32>) -> vec2<f32> {
    let slope = vec2<f32>(mat.mask_sx, mat.mask_sy);
    return vec2<f32>(sb_gain_view(wr.z, skin()), sb_smith_lambda(wr, slope));
}

fn env_cells_gain(wi: vec3<f32>, wr: vec3<f32>, view: vec2<f32>) -> f32 {
    let slope = vec2<f32>(mat.mask_sx, mat.mask_sy);
    return sb_gain_pair(wi, wr, mat.ior) * view.x * sb_masking_with(wi, wr.z, view.y, slope);
}

fn env_chain_height() -> u32 {
    return envg.table_h;
}

fn env_chain_levels() -> u32 {
    return envg.chain_levels;
}

fn env_chain_read(uv: vec2<f32>, level: f32) -> vec3<f32> {
    // (the sampler repeats in u)
    return textureSampleLevel(env_chain, env_smp, vec2<f32>(uv.x - envg.table_phase, uv.y), level).xyz;
}

fn env_irradiance_read(skin: bool, uv: vec2<f32>) -> vec3<f32> {
    if (skin) {
        return textureSampleLevel(env_irr_skin, env_smp, uv, 0.0).xyz;
    }
    return textureSampleLevel(env_irr_plain, env_smp, uv, 0.0).xyz;
}

// ---------------------------------------------------------------- cells at a lower rate
// A pre-pass (fs_cells, shaders/default.wgsl) shades the cells at every K-th
// pixel corner (K = g.cells_rate: grid point (i, j) at the frame's pixel
// coordinates (i K, j K)); a pixel in the block [i K, (i + 1) K) takes the
// bilinear mix of the block's four corners when they saw one smooth patch
// of surface: all shaded (a diffracting mesh, views env_grid_serves takes),
// their normals and tangents within ENV_LOWRES_CONE (2 degrees) of their
// mean, and the pixel's own normal and tangent within the cone of that mean.
// Not their distances: the term depends on the frame and the view alone
// (the environment is unoccluded), and the view turns by no more than the
// block's angular size whatever the depth, so two surfaces at different
// depths with one frame take one value; a distance test failed wherever
// the surface recedes (docs/LIGHTING.md "The block test: frames, not
// distances"). Elsewhere (silhouettes, limbs, scale borders, where the
// surface turns faster than the cone across a block) the centre pass marks
// the pixel, and a full-screen pass per mesh walks the cells at the marked
// pixels (fs_cells_walk, the grid's walk), so that the walks fill whole SIMD
// blocks whatever the triangles' size and wherever mixed and walked pixels
// meet. This runs in the centre pass (fs_cells_centre, once per pixel; the
// frame's pass reads its result through env_cells_pixel below). The
// cells' term is a smooth function of the frame and the view on the scale
// of a cell's spread, a few degrees (the sun and the hot spots have their
// own exact paths at every pixel), so its error is second order in the
// cone (docs/LIGHTING.md "Cells at a lower rate").
const ENV_LOWRES_CONE: f32 = 0.99939;
const ENV_LOWRES_OWN: f32 = 0.985;
const ENV_LOWRES_DEPTH: f32 = 0.02;

// A point with normal n at distance dist from the eye lies on the surface a
// pre-pass saw with normal n_seen at distance d_seen: the normals within
// ENV_LOWRES_OWN, the distances within ENV_LOWRES_DEPTH.
fn env_same_surface(n_seen: vec3<f32>, d_seen: f32, n: vec3<f32>, dist: f32) -> bool {
    return dot(n_seen, n) >= ENV_LOWRES_OWN && abs(dist - d_seen) <= ENV_LOWRES_DEPTH * d_seen;
}

// The centre pass's value at a pixel with tangent t and normal n from the
// coarse grid: (the bilinear mix, 1) where the block's corners saw one
// smooth patch of this pixel's frame, else 0 (the pixel is walked in the
// centre's full-screen walk, fs_cells_walk).
fn env_cells_mixed(t: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, clip: vec2<f32>) -> vec4<f32> {
    let k = g.cells_rate;
    if (k > 1u && env_grid_serves(wr.z)) {
        let q = clip / f32(k);
        let q0 = floor(q);
        let c0 = vec2<i32>(q0);
        if (env_block_smooth(c0, 1, t, n) && env_block_linear(cells_xyz, c0)) {
            return vec4<f32>(env_bilinear(cells_xyz, c0, q - q0), 1.0);
        }
    }
    return vec4<f32>(0.0);
}

// Whether the grid's points c0 + step o, o in {0, 1}^2 (bindings 2-4: the
// mark in binding 2's w, the mesh in binding 4's), saw one smooth patch of
// this mesh's frames that a point with tangent t and normal n shares: all
// inside the grid and marked with this mesh, their normals and tangents
// within ENV_LOWRES_CONE of their mean, and t and n too. For a pixel's
// block (env_cells_mixed) and for a grid point's block of the half grid
// (shaders/default.wgsl cells_from_half).
fn env_block_smooth(c0: vec2<i32>, step: i32, t: vec3<f32>, n: vec3<f32>) -> bool {
    let last = vec2<i32>(textureDimensions(cells_xyz)) - vec2<i32>(1);
    var ok = true;
    var ns = vec3<f32>(0.0);
    var ts = vec3<f32>(0.0);
    var nn: array<vec3<f32>, 4>;
    var tt: array<vec3<f32>, 4>;
    for (var j = 0; j < 4; j = j + 1) {
        let c = c0 + step * vec2<i32>(j & 1, j >> 1u);
        ok = ok && c.x <= last.x && c.y <= last.y;
        let cc = min(c, last);
        let tc = textureLoad(cells_t, cc, 0);
        ok = ok && textureLoad(cells_xyz, cc, 0).w > 0.5 && tc.w == f32(mat.cells_id);
        nn[j] = textureLoad(cells_nd, cc, 0).xyz;
        tt[j] = tc.xyz;
        ns = ns + nn[j];
        ts = ts + tt[j];
    }
    let nm = ns / max(length(ns), 1e-12);
    let tm = ts / max(length(ts), 1e-12);
    for (var j = 0; j < 4; j = j + 1) {
        ok = ok && dot(nn[j], nm) >= ENV_LOWRES_CONE && dot(tt[j], tm) >= ENV_LOWRES_CONE;
    }
    return ok && dot(n, nm) >= ENV_LOWRES_CONE && dot(t, tm) >= ENV_LOWRES_CONE;
}

// Whether the bilinear mix of the block of texels c0 + o, o in {0, 1}^2,
// of `tex` stays within ENV_LOWRES_CURVE of the block's mean luminance Y:
// a smooth patch of surface can still see a sharp edge of the environment
// (the sky's horizon mirrored across a sphere), which the mix would spread
// over the block. The linear interpolant's error is about an eighth of the
// second difference, taken along both axes at each corner through its
// neighbours outside the block (where they were shaded: w set).
const ENV_LOWRES_CURVE: f32 = 0.01;
fn env_block_linear(tex: texture_2d<f32>, c0: vec2<i32>) -> bool {
    let last = vec2<i32>(textureDimensions(tex)) - vec2<i32>(1);
    var m = 0.0;
    var worst = vec3<f32>(0.0);
    for (var j = 0; j < 4; j = j + 1) {
        let o = vec2<i32>(j & 1, j >> 1u);
        let c = min(c0 + o, last);
        let v = textureLoad(tex, c, 0).xyz;
        m = m + v.y;
        for (var a = 0; a < 2; a = a + 1) {
            let e = vec2<i32>(1 - a, a);
            let p = c - e;
            let q = c + e;
            if (all(p >= vec2<i32>(0)) && all(q <= last)) {
                let vp = textureLoad(tex, p, 0);
                let vq = textureLoad(tex, q, 0);
                if (vp.w > 0.5 && vq.w > 0.5) {
                    worst = max(worst, abs(vp.xyz - 2.0 * v + vq.xyz));
                }
            }
        }
    }
    return 0.125 * max(worst.x, max(worst.y, worst.z)) <= ENV_LOWRES_CURVE * max(0.25 * m, 0.0);
}

// The bilinear mix at fraction f of the block of texels c0 + o, o in
// {0, 1}^2, of `tex`, clamped to its last texel.
fn env_bilinear(tex: texture_2d<f32>, c0: vec2<i32>, f: vec2<f32>) -> vec3<f32> {
    let last = vec2<i32>(textureDimensions(tex)) - vec2<i32>(1);
    var acc = vec3<f32>(0.0);
    for (var j = 0; j < 4; j = j + 1) {
        let o = vec2<i32>(j & 1, j >> 1u);
        let wx = select(1.0 - f.x, f.x, o.x == 1);
        let wy = select(1.0 - f.y, f.y, o.y == 1);
        acc = acc + (wx * wy) * textureLoad(tex, min(c0 + o, last), 0).xyz;
    }
    return acc;
}

// The frame's pass after the centre pass (g.cells_rate >= 1): the centre
// pass's value of this pixel where this fragment sees the surface it saw
// (its normal within ENV_LOWRES_OWN, its distance within ENV_LOWRES_DEPTH;
// the fragment of the triangle under the pixel centre matches exactly), so
// that a pixel walks the cells once whatever the triangles touching it:
// (its XYZ, 1); else (another surface behind a silhouette, no centre pass)
// 0: the fragment walks them itself. At a grazing view, the point's or the
// centre's (one the grid does not serve, env_grid_serves: w = 2), the
// value is read at the pixel's centre (`at_centre`: a fragment that covers
// the pixel) and at the samples of a pixel inside the surface's outline
// (env_inside_outline: an edge between its triangles); on the silhouette a
// partly covered pixel's samples walk once at their mean, the covered
// part's centre, as the reference averages that part: at the limb the term
// turns fastest (read there, the 64 x 64 sphere's silhouette ring was
// CIEDE2000 up to 5 off every fragment walking: docs/LIGHTING.md "One walk
// per pixel"). Only on
// meshes that read the pre-passes (`mat.reads_cells`, decided by the
// renderer: not a mesh with scale maps under MSAA,
// crates/sunbeam-render/src/renderer/mod.rs `reads_centre`).
fn env_cells_read(n: vec3<f32>, wr: vec3<f32>, clip: vec2<f32>, dist: f32, at_centre: bool) -> vec4<f32> {
    if (g.cells_rate > 0u && wr.z > 0.0 && mat.reads_cells == 1u) {
        let last = vec2<i32>(textureDimensions(cells_xyz)) - vec2<i32>(1);
        let p = clamp(vec2<i32>(floor(clip)), vec2<i32>(0), last);
        let x = textureLoad(cells_xyz, p, 0);
        let nd = textureLoad(cells_nd, p, 0);
        let plain = x.w < 1.5 && env_grid_serves(wr.z);
        if (x.w > 0.5 && env_same_surface(nd.xyz, nd.w, n, dist) && (at_centre || plain || env_inside_outline(p, n, dist))) {
            return vec4<f32>(x.xyz, 1.0);
        }
    }
    return vec4<f32>(0.0);
}

// Whether the centres of the four pixels next to pixel p saw the surface
// with normal n at distance dist too: p lies inside that surface's outline
// (at an edge between its triangles), not on its silhouette.
fn env_inside_outline(p: vec2<i32>, n: vec3<f32>, dist: f32) -> bool {
    let last = vec2<i32>(textureDimensions(cells_xyz)) - vec2<i32>(1);
    var ok = true;
    for (var j = 0; j < 4; j = j + 1) {
        let e = select(vec2<i32>(1, 0), vec2<i32>(0, 1), (j & 1) == 1) * select(1, -1, j >= 2);
        let q = clamp(p + e, vec2<i32>(0), last);
        let nq = textureLoad(cells_nd, q, 0);
        ok = ok && textureLoad(cells_xyz, q, 0).w > 0.5 && env_same_surface(nq.xyz, nq.w, n, dist);
    }
    return ok;
}

// The cells' XYZ at a fragment: the centre pass's (env_cells_read) or,
// with `walk`, a walk of its own; without, 0 (the caller walks once for
// several points: shaders/diffraction.wgsl env_cells_carried). With `walk`
// the point is the pixel's centre; without, one of a partly covered
// pixel's samples.
fn env_cells_pixel(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, clip: vec2<f32>, dist: f32, walk: bool) -> vec3<f32> {
    let r = env_cells_read(n, wr, clip, dist, walk);
    if (r.w > 0.5 || !walk) {
        return r.xyz;
    }
    return env_cells(t, b, n, wr);
}

// Whether env_shade would walk the cells at this sample of a partly covered
// pixel (were `walk` set; the caller walks once at the samples' mean): the
// first-frame estimator's diffraction part where the centre pass has no
// value for it.
fn env_cells_walks(n: vec3<f32>, wr: vec3<f32>, dw: f32, diffract: bool, clip: vec2<f32>, dist: f32) -> bool {
    return envg.on == 1u && env_by_cells() && wr.z > 0.0 && diffract && envp.on == 1u && dw < 1.0
        && env_cells_read(n, wr, clip, dist, false).w < 0.5;
}

// ---------------------------------------------------------------- the estimator
// Linear sRGB leaving the surface towards the viewer under the environment (both
// parts, dw applied): frame (t, b, n), local view wr, base colour, diffuse weight
// dw, diffract: the mesh has a pack's maps; walk: the first-frame estimator
// walks the cells where the centre pass has no value (else the caller does,
// once for several points: env_cells_walks, shaders/diffraction.wgsl
// env_cells_carried); sun: the first-frame estimator adds the sun's disc
// (else the caller does: env_sun_disc_carried on a mesh with scale maps).
fn env_shade(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, base: vec3<f32>, dw: f32, diffract: bool, clip: vec2<f32>, dist: f32, fp: EnvFootprint, walk: bool, sun: bool) -> vec3<f32> {
    if (envg.on == 0u || wr.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    env_seed_at(vec2<u32>(clip), envg.frame);
    var rgb = vec3<f32>(0.0);
    // Diffuse: one cosine-weighted direction (pdf cos / pi) plus the sun's
    // disc, each times the share the skin transmits at its incidence.
    let tabled = env_by_cells() && (!diffract || abs(mat.ior - envg.irr_ior) < 1e-6);
    if (dw > 0.0 && tabled) {
        // The first-frame estimator: the tabulated (transmitted) irradiance.
        var irr = env_irradiance(false, n);
        if (diffract) {
            irr = env_irradiance(true, n);
        }
        var irr_over_pi = irr / ENV_PI;
        if (envg.has_sun == 1u) {
            let cs = max(dot(envg.sun_dir.xyz, n), 0.0);
            irr_over_pi = irr_over_pi
                + envg.sun_rgb.xyz * envg.sun_rgb.w * cs / ENV_PI * sb_base_transmission(cs, mat.ior, diffract);
        }
        rgb = rgb + dw * base * irr_over_pi;
    } else if (dw > 0.0) {
        let r = sqrt(env_qmc(envg.frame + 1u, 23u));
        let phi = SB_TAU * env_qmc(envg.frame + 1u, 29u);
        let wl = vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - r * r, 0.0)));
        let d = wl.x * t + wl.y * b + wl.z * n;
        var irr_over_pi = env_basis_rgb(env_coefficients(d)) * sb_base_transmission(wl.z, mat.ior, diffract);
        if (envg.has_sun == 1u) {
            let cs = max(dot(envg.sun_dir.xyz, n), 0.0);
            irr_over_pi = irr_over_pi
                + envg.sun_rgb.xyz * envg.sun_rgb.w * cs / ENV_PI * sb_base_transmission(cs, mat.ior, diffract);
        }
        rgb = rgb + dw * base * irr_over_pi;
    }
    if (!(diffract && envp.on == 1u && dw < 1.0)) {
        return rgb;
    }
    let gr = env_grid();
    var xyz = vec3<f32>(0.0);
    // The pixel's footprint for the sharp lights (the hot spots, the sun's
    // disc), this frame's share of it in a running mean; a point under
    // `--no-footprint`.
    var hot_fp = env_no_footprint();
    if (envg.hot_footprint == 1u) {
        hot_fp = env_footprint_times(fp, envg.frame_share);
    }
    if (env_by_cells()) {
        xyz = env_cells_pixel(t, b, n, wr, clip, dist, walk) + env_hotspots_footprint(t, b, n, wr, hot_fp);
    } else {
    // The first frame after a reset (every frame while the view moves) is the
    // preview: one direction uniform over the hemisphere, no descent (the
    // descent costs ~10x a Lambert frame on lavapipe). Unbiased as well, so
    // it stays in the running mean; later frames use the mixture.
    let preview = envg.frame == 0u;
    var ns = max(envg.samples, 1u);
    if (preview) {
        ns = 1u;
    } else if (wr.z < ENV_GRAZING_COS) {
        // Grazing views (limbs, silhouettes) vary most from sample to sample
        // (G with its masking, the horizon's texels) and a silhouette pixel is
        // covered in only part of the jittered frames: they take
        // ENV_GRAZING_SAMPLES times the draws, so they settle with the rest.
        ns = ns * ENV_GRAZING_SAMPLES;
    }
    for (var k = 0u; k < ns; k = k + 1u) {
        let q = 8u + 32u * k;
        // Three stratified uniforms per draw (env_qmc, point `i` of the
        // pixel's sequence): the first picks the technique (below
        // ENV_DEFENSIVE: the hemisphere) and, stretched, the descent's top
        // levels; the other two the point in the leaf cell or the hemisphere
        // direction.
        let i = envg.frame * ns + k + 1u;
        let u5 = env_qmc(i, 5u);
        let u7 = env_qmc(i, 7u);
        let u11 = env_qmc(i, 11u);
        // One-sample MIS over the mixture (EnvResponse::draw / density).
        var uvd = vec2<f32>(0.0);
        var pdf = 0.0;
        if (preview) {
            let z = u7;
            let ph = SB_TAU * u11;
            let sr = sqrt(max(1.0 - z * z, 0.0));
            uvd = -sr * vec2<f32>(cos(ph), sin(ph)) - wr.xy;
            pdf = env_hemi_pdf(wr, uvd);
        } else if (u5 < ENV_DEFENSIVE) {
            let z = u7;
            let ph = SB_TAU * u11;
            let sr = sqrt(max(1.0 - z * z, 0.0));
            uvd = -sr * vec2<f32>(cos(ph), sin(ph)) - wr.xy;
            pdf = ENV_DEFENSIVE * env_hemi_pdf(wr, uvd) + (1.0 - ENV_DEFENSIVE) * env_pdf(wr, uvd);
        } else {
            let ux = min((u5 - ENV_DEFENSIVE) / (1.0 - ENV_DEFENSIVE), 0.99999994);
            let dr = env_descend(wr, vec3<f32>(ux, u7, u11), q);
            if (!(dr.pdf > 0.0)) {
                continue;
            }
            uvd = dr.uv;
            pdf = ENV_DEFENSIVE * env_hemi_pdf(wr, uvd) + (1.0 - ENV_DEFENSIVE) * dr.pdf;
        }
        if (!(pdf > 0.0)) {
            continue;
        }
        let wxy = -uvd - wr.xy;
        let r2 = dot(wxy, wxy);
        if (r2 >= 1.0) {
            continue;
        }
        let wi = vec3<f32>(wxy, sqrt(1.0 - r2));
        let uvw = vec3<f32>(uvd, -(wi.z + wr.z));
        let d = wi.x * t + wi.y * b + wi.z * n;
        let c = env_coefficients(d);
        let rc = sb_resp_coords(uvw, gr);
        let e = c.x * env_map(env_e0, rc, gr) + c.y * env_map(env_e1, rc, gr) + c.z * env_map(env_e2, rc, gr);
        let wgt = gain(wi, wr) / (wi.z * pdf);
        xyz = xyz + e * wgt;
    }
    xyz = xyz / f32(ns);
    }
    if (envg.has_sun == 1u && envp.has_sun == 1u) {
        if (env_by_cells()) {
            if (sun) {
                xyz = xyz + env_sun_disc(t, b, n, wr, gr, hot_fp);
            }
        } else {
            // Uniform on the disc (Sky::sample_sun).
            let u = env_qmc(envg.frame + 1u, 17u);
            xyz = xyz + env_sun_point(t, b, n, wr, gr, u, SB_TAU * env_qmc(envg.frame + 1u, 19u));
        }
    }
    return rgb + (1.0 - dw) * xyz_to_rgb(xyz);
}

// The sun at one point of its disc, `u` uniform in [0, 1) over the cap's
// solid angle, `ph` the angle around its centre: G times the sun's map (which
// holds Omega_sun E_sun, EnvResponse::sun).
fn env_sun_point(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, gr: SbGrid, u: f32, ph: f32) -> vec3<f32> {
    return env_sun_point_fp(t, b, n, wr, gr, u, ph, vec2<f32>(0.0), env_no_footprint());
}

// As env_sun_point, the map read at offset o (in pixels, within the pixel's
// square) across the pixel's footprint fp: the point's (u, v, w) = -wi - wr
// moves with the frame and the view as a hot spot's tap does
// (env_hotspots_footprint). G and the masking, smooth over the pixel, at the
// centre.
fn env_sun_point_fp(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, gr: SbGrid, u: f32, ph: f32, o: vec2<f32>, fp: EnvFootprint) -> vec3<f32> {
    let d = sb_sun_disc_dir(envg.sun_dir.xyz, envg.sun_t.xyz, envg.sun_b.xyz, envg.sun_dir.w, u, ph);
    let wi = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
    if (wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return gain(wi, wr) * env_sun_read(d, wi, wr, gr, o, fp);
}

// The sun's map at disc direction d (local wi) for local view wr, read at
// offset o across the pixel's footprint fp (env_sun_point_fp).
fn env_sun_read(d: vec3<f32>, wi: vec3<f32>, wr: vec3<f32>, gr: SbGrid, o: vec2<f32>, fp: EnvFootprint) -> vec3<f32> {
    let rc = sb_resp_coords(-wi - wr + o.x * env_footprint_dx(d, fp) + o.y * env_footprint_dy(d, fp), gr);
    return env_map(env_esun, rc, gr);
}

// As env_sun_point_fp, with G and the masking from the disc's plane gp
// (env_sun_gain_plane).
fn env_sun_point_plane(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, gr: SbGrid, u: f32, ph: f32, o: vec2<f32>, fp: EnvFootprint, gp: vec4<f32>) -> vec3<f32> {
    let d = sb_sun_disc_dir(envg.sun_dir.xyz, envg.sun_t.xyz, envg.sun_b.xyz, envg.sun_dir.w, u, ph);
    let wi = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
    if (wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return sb_sun_gain_at(gp, d, envg.sun_t.xyz, envg.sun_b.xyz) * env_sun_read(d, wi, wr, gr, o, fp);
}

// The sky's sun's plane of G over its disc for frame (t, b, n) and local
// view wr (sun_gain.wgsl sb_sun_gain_plane): w 1 where the disc is at least
// SB_SUN_PLANE_COS above the horizon, else 0.
fn env_sun_gain_plane(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec4<f32> {
    return sb_sun_gain_plane(envg.sun_dir.xyz, envg.sun_t.xyz, envg.sun_b.xyz, envg.sun_dir.w, t, b, n, wr, skin());
}

// The first-frame estimator's sun: the mean over SB_SUN_POINTS points of
// its disc (a Vogel spiral, equal solid angles; turned per frame), not one
// point per frame: on a pack of real size the orders of a point are as
// narrow as the disc (82 um: a lobe of about 0.4 degrees, the disc 0.53),
// so one point per sample leaves the sun's streaks noisy in the first frame
// (docs/LIGHTING.md "The sun's disc in the first frame"). Each point is
// also read at its own place in the pixel's footprint fp
// (sb_sun_pixel_offset): the points integrate the disc and the pixel
// together, as a camera's pixel does; where the sun's orders are sharp
// within a pixel (a domed scale, a pack of real size) one place in the
// pixel is a point sample of them (docs/LIGHTING.md "The sun over the
// pixel"). Written out: llvmpipe counts loop iterations against one limit
// per invocation, which the cells' walk needs.
fn env_sun_disc(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, gr: SbGrid, fp: EnvFootprint) -> vec3<f32> {
    let r = SB_TAU * env_qmc(envg.frame + 1u, 19u);
    let gp = env_sun_gain_plane(t, b, n, wr);
    if (gp.w < 0.5) {
        // near the horizon each point takes its own G, in a loop: G's code
        // written out 16 times made the whole frame's shader slower, the
        // Lambert mode's too (docs/LIGHTING.md "The sun's gain over its
        // disc")
        var e = vec3<f32>(0.0);
        for (var i = 0u; i < u32(SB_SUN_POINTS); i = i + 1u) {
            e = e + env_sun_point_fp(t, b, n, wr, gr, (f32(i) + 0.5) / SB_SUN_POINTS, r + f32(i) * SB_GOLDEN, sb_sun_pixel_offset(i), fp);
        }
        return e / SB_SUN_POINTS;
    }
    var s = env_sun_point_plane(t, b, n, wr, gr, 0.5 / SB_SUN_POINTS, r, sb_sun_pixel_offset(0u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 1.5 / SB_SUN_POINTS, r + 1.0 * SB_GOLDEN, sb_sun_pixel_offset(1u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 2.5 / SB_SUN_POINTS, r + 2.0 * SB_GOLDEN, sb_sun_pixel_offset(2u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 3.5 / SB_SUN_POINTS, r + 3.0 * SB_GOLDEN, sb_sun_pixel_offset(3u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 4.5 / SB_SUN_POINTS, r + 4.0 * SB_GOLDEN, sb_sun_pixel_offset(4u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 5.5 / SB_SUN_POINTS, r + 5.0 * SB_GOLDEN, sb_sun_pixel_offset(5u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 6.5 / SB_SUN_POINTS, r + 6.0 * SB_GOLDEN, sb_sun_pixel_offset(6u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 7.5 / SB_SUN_POINTS, r + 7.0 * SB_GOLDEN, sb_sun_pixel_offset(7u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 8.5 / SB_SUN_POINTS, r + 8.0 * SB_GOLDEN, sb_sun_pixel_offset(8u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 9.5 / SB_SUN_POINTS, r + 9.0 * SB_GOLDEN, sb_sun_pixel_offset(9u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 10.5 / SB_SUN_POINTS, r + 10.0 * SB_GOLDEN, sb_sun_pixel_offset(10u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 11.5 / SB_SUN_POINTS, r + 11.0 * SB_GOLDEN, sb_sun_pixel_offset(11u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 12.5 / SB_SUN_POINTS, r + 12.0 * SB_GOLDEN, sb_sun_pixel_offset(12u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 13.5 / SB_SUN_POINTS, r + 13.0 * SB_GOLDEN, sb_sun_pixel_offset(13u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 14.5 / SB_SUN_POINTS, r + 14.0 * SB_GOLDEN, sb_sun_pixel_offset(14u), fp, gp);
    s = s + env_sun_point_plane(t, b, n, wr, gr, 15.5 / SB_SUN_POINTS, r + 15.0 * SB_GOLDEN, sb_sun_pixel_offset(15u), fp, gp);
    return s / SB_SUN_POINTS;
}
