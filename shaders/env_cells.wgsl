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
//   env_cell_f32(i), env_cell_u32(i): float i of Cells::gpu_data, as a float
//     or as its bits (the child pointers);
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
// Cells::gpu_data: floats per node before its masses (u, v, spread, first,
// next, the 9 masses' offsets, then the width uu, uv, vv), and "no node".
const ENV_CELL_HEADER: u32 = 26u;
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
    let stride = ENV_CELL_HEADER + 9u * ns;
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
        let o = id * stride;
        let uv = vec2<f32>(env_cell_f32(o), env_cell_f32(o + 1u));
        let spread = env_cell_f32(o + 2u);
        let first = env_cell_u32(o + 3u);
        let wxy = -uv - wr.xy;
        let l = length(wxy);
        let dist = 1.0 - l;
        if (first != ENV_CELL_NONE && dist < ENV_REFINE * spread) {
            id = first;
            continue;
        }
        id = env_cell_u32(o + 4u);
        var inside = select(0.0, 1.0, dist > 0.0);
        if (spread > 0.0) {
            inside = env_gaussian_inside(dist, spread);
        }
        // near the horizon: the cell's width towards it (cells::Cells::estimate)
        let dir = wxy / max(l, 1e-12);
        let wq = vec3<f32>(env_cell_f32(o + 23u), env_cell_f32(o + 24u), env_cell_f32(o + 25u));
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
        if (rim) {
            // G / cos integrated across the cell (cells::rim_gain), G and
            // the layer read where that integral puts its weight
            let rg = env_rim_gain(dist, sigma, dir, wr, view);
            let gr = rg.x;
            let wz = rg.y;
            if (!(gr > 0.0)) {
                continue;
            }
            let lr = env_cell_layer(wz, wr.z, r, ns);
            let mr0 = o + ENV_CELL_HEADER + lr.k0 * 9u;
            // a cell that straddles the horizon integrates each value about
            // its own centroid (env_cell_rim_gain, as env_cell_inside shares it)
            let straddles_rim = inside < ENV_CELL_STRADDLE && spread > 0.0;
            // the three bases written out: llvmpipe counts every loop
            // iteration of an invocation ("One walk per fragment")
            xyz = xyz + env_cell_rim_basis(o, 0u, mr0, lr.f, c[0], gr, straddles_rim, dist, sigma, dir, wr, view);
            xyz = xyz + env_cell_rim_basis(o, 1u, mr0, lr.f, c[1], gr, straddles_rim, dist, sigma, dir, wr, view);
            xyz = xyz + env_cell_rim_basis(o, 2u, mr0, lr.f, c[2], gr, straddles_rim, dist, sigma, dir, wr, view);
            continue;
        }
        let gw = env_cells_gain(wi, wr, view) / wi.z;
        if (!(gw > 0.0)) {
            continue;
        }
        let straddles = inside < ENV_CELL_STRADDLE && spread > 0.0;
        let ly = env_cell_layer(wi.z, wr.z, r, ns);
        let m0 = o + ENV_CELL_HEADER + ly.k0 * 9u;
        var e = vec3<f32>(0.0);
        for (var bb = 0u; bb < 3u; bb = bb + 1u) {
            var share = vec3<f32>(inside);
            if (straddles) {
                let q = o + 5u + 6u * bb;
                share = vec3<f32>(
                    env_cell_inside(uv, spread, vec2<f32>(env_cell_f32(q), env_cell_f32(q + 1u)), wr),
                    env_cell_inside(uv, spread, vec2<f32>(env_cell_f32(q + 2u), env_cell_f32(q + 3u)), wr),
                    env_cell_inside(uv, spread, vec2<f32>(env_cell_f32(q + 4u), env_cell_f32(q + 5u)), wr));
            }
            e = e + c[bb] * env_cell_mass(m0, bb, ly.f) * share;
        }
        xyz = xyz + gw * e;
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

// Basis bb's XYZ of a cell at the horizon: its masses at layer mr0 (and the
// next, mixed by fr) times the basis' coefficient cb and the rim's G / cos,
// gr, or each mass's own (env_cell_rim_gain) when the cell straddles.
fn env_cell_rim_basis(o: u32, bb: u32, mr0: u32, fr: f32, cb: f32, gr: f32, straddles: bool, dist: f32, sigma: f32, dir: vec2<f32>, wr: vec3<f32>, view: vec2<f32>) -> vec3<f32> {
    var g3 = vec3<f32>(gr);
    if (straddles) {
        let q = o + 5u + 6u * bb;
        g3 = vec3<f32>(
            env_cell_rim_gain(dist, sigma, dir, vec2<f32>(env_cell_f32(q), env_cell_f32(q + 1u)), wr, view),
            env_cell_rim_gain(dist, sigma, dir, vec2<f32>(env_cell_f32(q + 2u), env_cell_f32(q + 3u)), wr, view),
            env_cell_rim_gain(dist, sigma, dir, vec2<f32>(env_cell_f32(q + 4u), env_cell_f32(q + 5u)), wr, view));
    }
    return cb * env_cell_mass(mr0, bb, fr) * g3;
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
    let m1 = m0 + 9u;
    let a0 = vec3<f32>(env_cell_f32(m0 + 3u * bb), env_cell_f32(m0 + 3u * bb + 1u), env_cell_f32(m0 + 3u * bb + 2u));
    let a1 = vec3<f32>(env_cell_f32(m1 + 3u * bb), env_cell_f32(m1 + 3u * bb + 1u), env_cell_f32(m1 + 3u * bb + 2u));
    return mix(a0, a1, f);
}

// G / cos integrated across a cell at the horizon, times its share inside,
// and cos(theta_i) where that integral puts its weight (cells::rim_gain): a
// box of rms sigma in x = 1 - |wi_xy| about dist, cut at x = 0.
fn env_rim_gain(dist: f32, sigma: f32, dir: vec2<f32>, wr: vec3<f32>, view: vec2<f32>) -> vec2<f32> {
    let hm = env_rim_moments(dist / sigma);
    if (!(hm.x > 0.0)) {
        return vec2<f32>(0.0);
    }
    let x = min(sigma * hm.y / hm.x, 1.0);
    let d = 1.0 - x;
    let wz = max(sqrt(max(1.0 - d * d, 0.0)), 1e-6);
    let g = env_cells_gain(vec3<f32>(dir * d, wz), wr, view) * hm.x / sqrt(2.0 * sigma) * sqrt(2.0 / (2.0 - x));
    return vec2<f32>(g, wz);
}

// env_rim_gain for one mass of a straddling cell, about the mass's own
// centroid (the cell's plus `off`) with the cell's width less the offset, at
// least a quarter of it.
fn env_cell_rim_gain(dist: f32, sigma: f32, dir: vec2<f32>, off: vec2<f32>, wr: vec3<f32>, view: vec2<f32>) -> f32 {
    let po = dot(dir, off);
    let sq = sqrt(max(sigma * sigma - po * po, sigma * sigma / 16.0));
    return env_rim_gain(dist + po, sq, dir, wr, view).x;
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
