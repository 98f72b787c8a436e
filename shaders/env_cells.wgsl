// The first-frame cells (docs/LIGHTING.md "The first frame"), one source
// for the player (appended after shaders/environment.wgsl) and the engines'
// export (after shaders/export_env.wgsl): the pack's extended-light response
// clustered into cells (sunbeam_response::cells::Cells::gpu_data), each
// evaluated per shading point against the prefiltered coefficient table
// (sunbeam_light::prefilter), and the irradiance tables of the diffuse base.
// A cell that straddles the view's horizon counts each of its 9 masses'
// share inside the disc from that mass's own centroid: on a pack of real
// size a cell on a narrow diffraction order is a rainbow, and the horizon
// keeps one end of it.
//
// Needs shaders/material.wgsl (sb_erf), shaders/response_map.wgsl (SB_TAU)
// and shaders/env_table.wgsl (sb_env_equirect) before it. The host supplies
// the data, so that the player reads a storage buffer and the export a data
// texture (WebGL2 has no storage buffers):
//   env_cell_v4(i): floats 4 i to 4 i + 3 of Cells::gpu_data (the links
//     are u32 bits: bitcast);
//   env_cells_top(): cells of the top cut; env_cells_nodes(): every node;
//   env_cells_layers(): the maps' s layers;
//   env_cells_view(wr): what the mesh's gain and masking need of the view
//     alone, once per shading point (sb_gain_view, Smith's Lambda(wr));
//   env_cells_gain(wi, wr, view): the mesh's gain G with its masking, view
//     from env_cells_view(wr);
//   env_chain_height(), env_chain_levels(): the chain's level-0 height and levels;
//   env_chain_read(uv, level): the chain at equirectangular uv, trilinear;
//   env_irradiance_read(skin, uv): a table (skin: transmitted, else plain).

const ENV_PI: f32 = 3.141592653589793;

// The coefficients at d averaged over about omega steradians
// (Prefiltered::lookup: the level whose texel's polar extent squared is omega).
fn env_prefiltered(d: vec3<f32>, omega: f32) -> vec3<f32> {
    let texel = ENV_PI / f32(env_chain_height());
    let level = clamp(0.5 * log2(max(omega, 1e-30) / (texel * texel)), 0.0, f32(env_chain_levels() - 1u));
    return env_chain_read(sb_env_equirect(d), level);
}

// Cells refine near the horizon while their spread times this reaches it
// (sunbeam_response::cells::REFINE).
const ENV_REFINE: f32 = 3.0;
// Cells::gpu_data in fours of floats (cells::GPU_HEADER, GPU_LAYER): per
// node (u, v, spread, first), (next, the width uu, uv, vv), per basis its 3
// masses' offsets in two fours, then per layer one four per basis (XYZ, 0).
// A four is one load: a leaf's reads were most of a walk's time on llvmpipe
// as single floats (docs/LIGHTING.md "Where a walk's time goes").
const ENV_CELL_HEADER: u32 = 8u;
const ENV_CELL_LAYER: u32 = 3u;

// Fours per node for maps of ns layers (cells::gpu_stride / 4).
fn env_cell_stride(ns: u32) -> u32 {
    return ENV_CELL_HEADER + ENV_CELL_LAYER * ns;
}
// Cells within this many of their widths of the horizon integrate G / cos
// across them (cells::RIM_WIDTHS); outside the disc by less than this they
// still count (cells::RIM_OUTSIDE); the half-width of env_rim_moments'
// box in rms widths (cells::RIM_BOX).
const ENV_RIM_WIDTHS: f32 = 5.0;
const ENV_RIM_OUTSIDE: f32 = 0.05;
const ENV_RIM_BOX: f32 = 1.7320508;
// A cell inside the disc by less than this share straddles the horizon
// (cells::STRADDLE).
const ENV_CELL_STRADDLE: f32 = 0.999;
const ENV_CELL_NONE: u32 = 0xffffffffu;

// The diffraction part (XYZ) of the environment without the sun at local
// view wr, frame (t, b, n): each cell's mass at its layer times G / cos and
// the prefiltered coefficients at its centroid (Cells::estimate, the CPU
// twin; docs/LIGHTING.md "The first frame").
fn env_cells(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    var xyz = vec3<f32>(0.0);
    let ns = env_cells_layers();
    let stride = env_cell_stride(ns);
    if (env_cells_top() == 0u) {
        return xyz;
    }
    // A depth-first walk threaded by each node's `next` (Cells::gpu_data): one
    // index and no stack, whose dynamic indexing would live in local memory.
    // Each node is visited at most once, which bounds the loop.
    let n_nodes = env_cells_nodes();
    // G's and the masking's factors of the view alone, once for all cells.
    let view = env_cells_view(wr);
    var id = 0u;
    for (var visit = 0u; visit < n_nodes && id != ENV_CELL_NONE; visit = visit + 1u) {
        // down to the first node that does not refine (a node whose spread
        // reaches the horizon, from inside or outside, is replaced by its
        // children: cells::Cells::estimate), in a loop of its
        // own: on llvmpipe a refined node then costs this loop's body, not
        // the leaf's ("What a branch costs on llvmpipe"); each step goes one
        // level down. A walk counts a leaf twice against llvmpipe's loop
        // limit (CPU_CELL_NODES in crates/sunbeam-render).
        var o = 0u;
        var uv = vec2<f32>(0.0);
        var spread = 0.0;
        var wxy = vec2<f32>(0.0);
        var l = 0.0;
        for (var depth = 0u; depth < n_nodes; depth = depth + 1u) {
            o = id * stride;
            let h0 = env_cell_v4(o);
            uv = h0.xy;
            spread = h0.z;
            wxy = -uv - wr.xy;
            l = length(wxy);
            let first = bitcast<u32>(h0.w);
            if (first == ENV_CELL_NONE || abs(1.0 - l) >= ENV_REFINE * spread) {
                break;
            }
            id = first;
        }
        let dist = 1.0 - l;
        let h1 = env_cell_v4(o + 1u);
        id = bitcast<u32>(h1.x);
        var inside = select(0.0, 1.0, dist > 0.0);
        if (spread > 0.0) {
            inside = env_gaussian_inside(dist, spread);
        }
        // near the horizon: the cell's width towards it (cells::Cells::estimate)
        let dir = wxy / max(l, 1e-12);
        let wq = h1.yzw;
        let sigma = sqrt(max(dir.x * dir.x * wq.x + 2.0 * dir.x * dir.y * wq.y + dir.y * dir.y * wq.z, 0.0));
        let rim = l > 1e-9 && sigma > 0.0 && dist < ENV_RIM_WIDTHS * sigma && dist > -ENV_RIM_OUTSIDE;
        if (!rim && (inside <= 0.0 || dist <= -0.5)) {
            continue;
        }
        var w2 = wxy;
        if (l > 0.999) {
            w2 = wxy * (0.999 / l);
        }
        let wi = vec3<f32>(w2, sqrt(max(1.0 - dot(w2, w2), 0.0)));
        let r = length(uv);
        // the footprint: a disc of the area of the width's ellipse (cells::Cells::estimate)
        let omega = max(SB_TAU * sqrt(max(wq.x * wq.z - wq.y * wq.y, 0.0)) / wi.z, 1e-9);
        let c = env_prefiltered(wi.x * t + wi.y * b + wi.z * n, omega);
        // G is read once per cell, at the rim's weighted mean or at the
        // centroid: llvmpipe runs both sides of every branch (docs/LIGHTING.md
        // "What a branch costs on llvmpipe"), so the rim's path and the
        // inner one share their reads
        let rg = env_rim_point(dist, sigma);
        var wg = wi;
        var k = 1.0 / wi.z;
        if (rim) {
            if (!(rg.x > 0.0)) {
                continue;
            }
            wg = vec3<f32>(dir * (1.0 - rg.z), rg.w);
            k = rg.y;
        }
        let g0 = env_cells_gain(wg, wr, view);
        let gw = g0 * k;
        if (!(gw > 0.0)) {
            continue;
        }
        let straddles = inside < ENV_CELL_STRADDLE && spread > 0.0;
        // a rim cell that straddles reads each mass's G on a line through G
        // at the cell's mean (env_rim_slope)
        let slope = env_rim_slope(rg, sigma, dir, wr, view, g0);
        let ly = env_cell_layer(wg.z, wr.z, r, ns);
        let m0 = o + ENV_CELL_HEADER + ly.k0 * ENV_CELL_LAYER;
        var gc = gw * inside;
        if (rim) {
            gc = gw;
        }
        // the three bases written out: llvmpipe counts every loop iteration
        // of an invocation ("One walk per fragment")
        let cs = EnvCellShare(o, uv, spread, dist, sigma, dir, rg.w, g0, slope, gw, gc, rim, straddles);
        xyz = xyz + env_cell_basis(cs, 0u, m0, ly.f, c[0], wr);
        xyz = xyz + env_cell_basis(cs, 1u, m0, ly.f, c[1], wr);
        xyz = xyz + env_cell_basis(cs, 2u, m0, ly.f, c[2], wr);
    }
    return xyz;
}

// h(a) = int_0^inf p(y - a) y^(-1/2) dy and h1(a) (with y^(1/2)), p the
// uniform density of unit variance (cells::rim_moments: why a box), in
// closed form.
fn env_rim_moments(a: f32) -> vec2<f32> {
    if (!(a + ENV_RIM_BOX > 0.0)) {
        return vec2<f32>(0.0);
    }
    let hi = a + ENV_RIM_BOX;
    let lo = max(a - ENV_RIM_BOX, 0.0);
    return vec2<f32>((sqrt(hi) - sqrt(lo)) / ENV_RIM_BOX, (hi * sqrt(hi) - lo * sqrt(lo)) / (3.0 * ENV_RIM_BOX));
}

// What a leaf's masses share, for env_cell_basis.
struct EnvCellShare {
    // the node's offset in the cells' data, in fours
    o: u32,
    uv: vec2<f32>,
    spread: f32,
    // the rim's: its distance inside the horizon, width and direction, cos
    // at its weighted mean, G there and its slope (env_rim_slope)
    dist: f32,
    sigma: f32,
    dir: vec2<f32>,
    wz0: f32,
    g0: f32,
    slope: f32,
    // G / cos, and G / cos times the share inside (the rim's integral at a rim)
    gw: f32,
    gc: f32,
    rim: bool,
    straddles: bool,
}

// Basis bb's XYZ of a leaf: its masses at layer m0 (and the next, mixed by
// f) times the basis' coefficient cb and the leaf's G / cos and share, or,
// when the leaf straddles the horizon, each mass's own about its own
// centroid (env_cell_rim_gain at the rim, else env_cell_inside).
fn env_cell_basis(cs: EnvCellShare, bb: u32, m0: u32, f: f32, cb: f32, wr: vec3<f32>) -> vec3<f32> {
    var share = vec3<f32>(cs.gc);
    if (cs.straddles) {
        let q01 = env_cell_v4(cs.o + 2u + 2u * bb);
        let o0 = q01.xy;
        let o1 = q01.zw;
        let o2 = env_cell_v4(cs.o + 3u + 2u * bb).xy;
        if (cs.rim) {
            share = vec3<f32>(
                env_cell_rim_gain(cs.dist, cs.sigma, cs.dir, o0, cs.wz0, cs.g0, cs.slope),
                env_cell_rim_gain(cs.dist, cs.sigma, cs.dir, o1, cs.wz0, cs.g0, cs.slope),
                env_cell_rim_gain(cs.dist, cs.sigma, cs.dir, o2, cs.wz0, cs.g0, cs.slope));
        } else {
            share = cs.gw * vec3<f32>(
                env_cell_inside(cs.uv, cs.spread, o0, wr),
                env_cell_inside(cs.uv, cs.spread, o1, wr),
                env_cell_inside(cs.uv, cs.spread, o2, wr));
        }
    }
    return cb * env_cell_mass(m0, bb, f) * share;
}

// The layer of the cells' masses at cos(theta_i) = wz (Cells::estimate's
// `layer`): k0 and the weight f of k0 + 1, for a cell at radius r in (u, v).
struct EnvCellLayer {
    k0: u32,
    f: f32,
}

fn env_cell_layer(wz: f32, wrz: f32, r: f32, ns: u32) -> EnvCellLayer {
    let s = clamp((wz + wrz) / sqrt(max(4.0 - r * r, 1e-12)), 0.0, 1.0);
    let sc = s * f32(ns - 1u);
    let k0 = min(u32(floor(sc)), ns - 2u);
    return EnvCellLayer(k0, sc - f32(k0));
}

// Basis bb's XYZ mass between the layer at m0 and the next, f the weight of
// the latter (Cell::mass_at).
fn env_cell_mass(m0: u32, bb: u32, f: f32) -> vec3<f32> {
    let a0 = env_cell_v4(m0 + bb).xyz;
    let a1 = env_cell_v4(m0 + ENV_CELL_LAYER + bb).xyz;
    return mix(a0, a1, f);
}

// Where G / cos integrated across a cell at the horizon puts its weight
// (cells::rim_point): a box of rms sigma in x = 1 - |wi_xy| about dist, cut
// at x = 0. Returns (the share inside, 0 when none; the factor that
// multiplies G; the weighted mean x; cos(theta_i) there).
fn env_rim_point(dist: f32, sigma: f32) -> vec4<f32> {
    let hm = env_rim_moments(dist / sigma);
    if (!(hm.x > 0.0)) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    let x = min(sigma * hm.y / hm.x, 1.0);
    return vec4<f32>(hm.x, hm.x / sqrt(2.0 * sigma) * sqrt(2.0 / (2.0 - x)), x, env_rim_cos(x));
}

// cos(theta_i) at x = 1 - |wi_xy|, at least 1e-6 (cells::rim_cos).
fn env_rim_cos(x: f32) -> f32 {
    let d = 1.0 - x;
    return max(sqrt(max(1.0 - d * d, 0.0)), 1e-6);
}

// The slope in cos(theta_i) of the line on which a straddling rim cell's
// masses read G: through G at the cell's mean rg (env_rim_point), g0, and at
// a quarter of the mean's x, or a width further in where the mean is within
// a quarter width of the horizon (cells::rim_slope: why).
fn env_rim_slope(rg: vec4<f32>, sigma: f32, dir: vec2<f32>, wr: vec3<f32>, view: vec2<f32>, g0: f32) -> f32 {
    var x2 = min(rg.z + sigma, 1.0);
    if (rg.z > 0.25 * sigma) {
        x2 = 0.25 * rg.z;
    }
    let wz2 = env_rim_cos(x2);
    let dz = wz2 - rg.w;
    if (!(abs(dz) > 1e-7)) {
        return 0.0;
    }
    return (env_cells_gain(vec3<f32>(dir * (1.0 - x2), wz2), wr, view) - g0) / dz;
}

// G / cos integrated across one mass of a straddling rim cell, about the
// mass's own centroid (the cell's plus `off`) with the cell's width less the
// offset, at least a quarter of it; G on the line g0 + slope (wz - wz0)
// (cells::mass_rim_gain).
fn env_cell_rim_gain(dist: f32, sigma: f32, dir: vec2<f32>, off: vec2<f32>, wz0: f32, g0: f32, slope: f32) -> f32 {
    let po = dot(dir, off);
    let sq = sqrt(max(sigma * sigma - po * po, sigma * sigma / 16.0));
    let rg = env_rim_point(dist + po, sq);
    return max(g0 + slope * (rg.w - wz0), 0.0) * rg.y;
}

// The share of one mass inside the disc for view wr: a Gaussian about the
// mass's own centroid (the cell's plus `off`), with the cell's spread less
// the offset, at least a quarter of it (cells::channel_inside).
fn env_cell_inside(uv: vec2<f32>, spread: f32, off: vec2<f32>, wr: vec3<f32>) -> f32 {
    let sq = sqrt(max(spread * spread - dot(off, off), 0.0625 * spread * spread));
    return env_gaussian_inside(1.0 - length(-uv - off - wr.xy), sq);
}

// The share inside the disc of a Gaussian of rms sigma whose centre lies dist
// inside the horizon (negative: outside) (cells::gaussian_inside).
fn env_gaussian_inside(dist: f32, sigma: f32) -> f32 {
    return 0.5 * (1.0 + sb_erf(dist / (1.4142135623730951 * sigma)));
}

// Irradiance (linear sRGB, without the sun) at world normal n from a table
// over normals (Irradiance::at: bilinear, azimuth wraps): the transmitted
// one under a skin, else the plain one.
fn env_irradiance(skin: bool, n: vec3<f32>) -> vec3<f32> {
    return env_irradiance_read(skin, sb_env_equirect(n));
}
