// The environment's table lookup, once for the lighting (environment.wgsl)
// and the background pass (background.wgsl): the texel of an equirectangular
// table of `w` x `h` that contains world direction `d` (no filtering, as
// sunbeam_light's EnvMap::lookup: theta = acos(y) from +y, phi = atan2(z, x)).

fn sb_env_texel(table: texture_2d<f32>, w: u32, h: u32, d: vec3<f32>) -> vec3<f32> {
    let tau = 6.283185307179586;
    let theta = acos(clamp(d.y, -1.0, 1.0));
    var phi = atan2(d.z, d.x);
    if (phi < 0.0) {
        phi = phi + tau;
    }
    let i = min(u32(phi / tau * f32(w)), w - 1u);
    let j = min(u32(theta / 3.141592653589793 * f32(h)), h - 1u);
    return textureLoad(table, vec2<u32>(i, j), 0).xyz;
}

