// The environment's table lookup, once for the lighting (environment.wgsl)
// and the background pass (background.wgsl): the texel of an equirectangular
// table of `w` x `h` that contains world direction `d` (no filtering, as
// sunbeam_light's EnvMap::lookup: theta = acos(y) from +y, phi = atan2(z, x)),
// whose columns start `phase` turns after phi = 0 (Environment::table_phase:
// a map's rotation by a fraction of a texel).

fn sb_env_texel(table: texture_2d<f32>, w: u32, h: u32, phase: f32, d: vec3<f32>) -> vec3<f32> {
    let e = sb_env_equirect(d);
    let x = fract(e.x - phase) * f32(w);
    let i = min(u32(x), w - 1u);
    let j = min(u32(e.y * f32(h)), h - 1u);
    return textureLoad(table, vec2<u32>(i, j), 0).xyz;
}

// Equirectangular texture coordinates in [0, 1]^2 of world direction d:
// (phi / 2 pi, theta / pi), theta from +y, phi = atan2(z, x) (also the
// prefiltered chain's and the irradiance tables' coordinates).
fn sb_env_equirect(d: vec3<f32>) -> vec2<f32> {
    let tau = 6.283185307179586;
    var phi = atan2(d.z, d.x);
    if (phi < 0.0) {
        phi = phi + tau;
    }
    return vec2<f32>(phi / tau, acos(clamp(d.y, -1.0, 1.0)) / 3.141592653589793);
}

