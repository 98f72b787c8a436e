// ---------------------------------------------------------------- hot spots
// The environment's hot spots as small lights, for the first-frame estimator
// (sunbeam_light::hotspots; sunbeam_response::hotspots is the float64 twin;
// docs/LIGHTING.md "The first frame"), shared by the player and the engines'
// export. Each light is a few taps (sunbeam_response::hotspots::taps, made
// once on the CPU: they do not depend on the view): a world direction and the
// light's basis power int c_k d(omega) times the tap's weight. A tap adds
// G(wi, wr) sum_k P_k E_k(-wi - wr). The prefiltered chain the cells read
// holds the rest of the environment.
//
// What it asks of its host (the player: shaders/environment.wgsl, a storage
// buffer; the export: shaders/export_env.wgsl, textures):
//   env_hot_count() -> u32: the taps;
//   env_hot_dir(i) -> vec3<f32>, env_hot_power(i) -> vec3<f32>: tap i;
//   env_hot_maps(p, uvw) -> vec3<f32>: sum_k p_k E_k at (u, v, w) = uvw, XYZ;
//   env_hot_grid() -> SbGrid: the maps' grid (shaders/response_map.wgsl);
//   env_cells_view, env_cells_gain (as env_cells.wgsl asks).

// The pixel's footprint: the screen derivatives, along x and y, of the
// shading frame's columns (world) and of the local view. All zero: a point.
struct EnvFootprint {
    tx: vec3<f32>,
    ty: vec3<f32>,
    bx: vec3<f32>,
    by: vec3<f32>,
    nx: vec3<f32>,
    ny: vec3<f32>,
    wrx: vec3<f32>,
    wry: vec3<f32>,
};

fn env_no_footprint() -> EnvFootprint {
    let z = vec3<f32>(0.0);
    return EnvFootprint(z, z, z, z, z, z, z, z);
}

// The footprint fp scaled by k along both axes (a sample that stands for a
// part of the pixel).
fn env_footprint_times(fp: EnvFootprint, k: f32) -> EnvFootprint {
    return EnvFootprint(k * fp.tx, k * fp.ty, k * fp.bx, k * fp.by, k * fp.nx, k * fp.ny, k * fp.wrx, k * fp.wry);
}

// How (u, v, w) = -wi - wr of a fixed world direction d moves across the
// pixel, along x: the frame's columns turn under d and the view changes
// (the hot spots' taps, the sun's disc points).
fn env_footprint_dx(d: vec3<f32>, fp: EnvFootprint) -> vec3<f32> {
    return -vec3<f32>(dot(d, fp.tx), dot(d, fp.bx), dot(d, fp.nx)) - fp.wrx;
}

// As env_footprint_dx, along y.
fn env_footprint_dy(d: vec3<f32>, fp: EnvFootprint) -> vec3<f32> {
    return -vec3<f32>(dot(d, fp.ty), dot(d, fp.by), dot(d, fp.ny)) - fp.wry;
}

// XYZ of the hot spots at local view wr, frame (t, b, n), read at one point
// of each tap's (u, v, w) (the export; the player without a footprint).
fn env_hotspots(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    return env_hotspots_footprint(t, b, n, wr, env_no_footprint());
}

// As env_hotspots, each tap's maps averaged over the pixel's footprint fp:
// a tap's (u, v, w) = -wi - wr moves across the pixel with the frame (wi is
// a fixed world direction seen in a turning frame) and the view, so its
// derivatives are those of the frame's columns projected on the direction
// plus the view's. A box filter of up to ENV_HOT_FOOTPRINT^2 stratified
// reads per tap, as many per axis as the maps' texels the footprint spans
// (one within a texel), as the point lights' sb_diffraction_xyz_filtered: a
// hot spot's diffraction orders are sharp within a pixel (a softbox's edge),
// and a camera pixel integrates them (docs/LIGHTING.md "The first frame").
// G and the masking, smooth over the pixel, at the centre.
fn env_hotspots_footprint(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, fp: EnvFootprint) -> vec3<f32> {
    var xyz = vec3<f32>(0.0);
    let count = env_hot_count();
    let gr = env_hot_grid();
    // G's and the masking's factors of the view alone, once for all taps.
    let view = env_cells_view(wr);
    for (var i = 0u; i < count; i = i + 1u) {
        let d = env_hot_dir(i);
        let wi = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
        // (a zero direction, the stand-in without lights, stops here too)
        if (wi.z <= 0.0) {
            continue;
        }
        let p = env_hot_power(i);
        let uvw = -wi - wr;
        let dx = env_footprint_dx(d, fp);
        let dy = env_footprint_dy(d, fp);
        let sx = u32(clamp(ceil(2.0 * length(sb_resp_dcoords(uvw, dx, gr))), 1.0, ENV_HOT_FOOTPRINT));
        let sy = u32(clamp(ceil(2.0 * length(sb_resp_dcoords(uvw, dy, gr))), 1.0, ENV_HOT_FOOTPRINT));
        var e = vec3<f32>(0.0);
        for (var a = 0u; a < sx; a = a + 1u) {
            for (var c = 0u; c < sy; c = c + 1u) {
                let ox = (f32(a) + 0.5) / f32(sx) - 0.5;
                let oy = (f32(c) + 0.5) / f32(sy) - 0.5;
                e = e + env_hot_maps(p, uvw + ox * dx + oy * dy);
            }
        }
        xyz = xyz + env_cells_gain(wi, wr, view) * e / f32(sx * sy);
    }
    return xyz;
}

// Reads per axis and tap at most (env_hotspots_footprint).
const ENV_HOT_FOOTPRINT: f32 = 4.0;
