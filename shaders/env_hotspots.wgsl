// ---------------------------------------------------------------- hot spots
// The environment's hot spots as small lights, for the first-frame estimator
// (sunbeam_light::hotspots; sunbeam_response::hotspots is the float64 twin;
// docs/LIGHTING.md "The first frame"): per light two vec4, (world direction,
// spread in radians) and (basis power int c_k d(omega), 0). A light adds
// G(wi, wr) sum_k P_k E_k(-wi - wr), over four taps at its spread around its
// direction (one when it has none). The prefiltered chain the cells read
// holds the rest of the environment.
@group(2) @binding(13) var<storage, read> env_lights: array<vec4<f32>>;

fn env_hotspot_tap(d: vec3<f32>, t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, p: vec3<f32>, gr: SbGrid) -> vec3<f32> {
    let wi = vec3<f32>(dot(d, t), dot(d, b), dot(d, n));
    if (wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let rc = sb_resp_coords(-wi - wr, gr);
    let e = p.x * env_map(env_e0, rc, gr) + p.y * env_map(env_e1, rc, gr) + p.z * env_map(env_e2, rc, gr);
    return gain(wi, wr) * e;
}

// XYZ of the hot spots at local view wr, frame (t, b, n).
fn env_hotspots(t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>) -> vec3<f32> {
    let gr = env_grid();
    var xyz = vec3<f32>(0.0);
    let count = arrayLength(&env_lights) / 2u;
    for (var i = 0u; i < count; i = i + 1u) {
        let a = env_lights[2u * i];
        let p = env_lights[2u * i + 1u].xyz;
        if (!(dot(a.xyz, a.xyz) > 0.0)) {
            continue;
        }
        if (!(a.w > 0.0)) {
            xyz = xyz + env_hotspot_tap(a.xyz, t, b, n, wr, p, gr);
            continue;
        }
        // the taps of sunbeam_response::hotspots::taps
        var up = vec3<f32>(1.0, 0.0, 0.0);
        if (abs(a.y) < 0.9) {
            up = vec3<f32>(0.0, 1.0, 0.0);
        }
        let e1 = normalize(cross(up, a.xyz));
        let e2 = cross(a.xyz, e1);
        xyz = xyz + 0.25 * (env_hotspot_tap(normalize(a.xyz + a.w * e1), t, b, n, wr, p, gr)
            + env_hotspot_tap(normalize(a.xyz - a.w * e1), t, b, n, wr, p, gr)
            + env_hotspot_tap(normalize(a.xyz + a.w * e2), t, b, n, wr, p, gr)
            + env_hotspot_tap(normalize(a.xyz - a.w * e2), t, b, n, wr, p, gr));
    }
    return xyz;
}
