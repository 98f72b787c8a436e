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
//   env_cells_view, env_cells_gain (as env_cells.wgsl asks).

// XYZ of the hot spots at local view wr, frame (t, b, n).
fn env_hotspots(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    var xyz = vec3<f32>(0.0);
    let count = env_hot_count();
    // G's and the masking's factors of the view alone, once for all taps.
    let view = env_cells_view(wr);
    for (var i = 0u; i < count; i = i + 1u) {
        let d = env_hot_dir(i);
        let wi = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
        // (a zero direction, the stand-in without lights, stops here too)
        if (wi.z <= 0.0) {
            continue;
        }
        let e = env_hot_maps(env_hot_power(i), -wi - wr);
        xyz = xyz + env_cells_gain(wi, wr, view) * e;
    }
    return xyz;
}
