// ---------------------------------------------------------------- hot spots
// The environment's hot spots as small lights, for the first-frame estimator
// (sunbeam_light::hotspots; sunbeam_response::hotspots is the float64 twin;
// docs/LIGHTING.md "The first frame"). Each light is a few taps
// (sunbeam_response::hotspots::taps, made once on the CPU: they do not depend
// on the view), two vec4 per tap: (world direction, 0) and (the light's
// basis power int c_k d(omega) times the tap's weight, 0). A tap adds
// G(wi, wr) sum_k P_k E_k(-wi - wr). The prefiltered chain the cells read
// holds the rest of the environment.
@group(2) @binding(13) var<storage, read> env_lights: array<vec4<f32>>;

// XYZ of the hot spots at local view wr, frame (t, b, n).
fn env_hotspots(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let gr = env_grid();
    var xyz = vec3<f32>(0.0);
    let count = arrayLength(&env_lights) / 2u;
    // G's and the masking's factors of the view alone, once for all taps.
    let view = env_cells_view(wr);
    for (var i = 0u; i < count; i = i + 1u) {
        let d = env_lights[2u * i].xyz;
        let p = env_lights[2u * i + 1u].xyz;
        let wi = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
        // (a zero direction, the stand-in without lights, stops here too)
        if (wi.z <= 0.0) {
            continue;
        }
        let rc = sb_resp_coords(-wi - wr, gr);
        let e = p.x * env_map(env_e0, rc, gr) + p.y * env_map(env_e1, rc, gr) + p.z * env_map(env_e2, rc, gr);
        xyz = xyz + env_cells_gain(wi, wr, view) * e;
    }
    return xyz;
}
