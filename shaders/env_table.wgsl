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


// A direction of the sun's disc about its centre c (unit; t and b unit,
// perpendicular to c and to each other): u uniform in [0, 1) over the cap's
// solid angle (cos_cap: the cosine of its half-angle), ph the angle around
// the centre. The player's sun (environment.wgsl env_sun_point) and the
// engines' (export_env.wgsl sunbeam_shade_sun) take their points here.
fn sb_sun_disc_dir(c: vec3<f32>, t: vec3<f32>, b: vec3<f32>, cos_cap: f32, u: f32, ph: f32) -> vec3<f32> {
    let ct = 1.0 - u * (1.0 - cos_cap);
    let st = sqrt(max(1.0 - ct * ct, 0.0));
    return st * (cos(ph) * t + sin(ph) * b) + ct * c;
}

// Points of the sun's disc in a first frame (a Vogel spiral: point i at
// u = (i + 1/2) / SB_SUN_POINTS, turned by i golden angles), and the golden
// angle: on a pack of real size a point's diffraction orders are as narrow
// as the disc (docs/LIGHTING.md "The sun's disc in the first frame").
const SB_SUN_POINTS: f32 = 16.0;
const SB_GOLDEN: f32 = 2.3999631;

// Where in the pixel sun point i is read (env_sun_disc): an offset in
// [-1/2, 1/2]^2 pixels, ((9 i mod 16 + 1/2) / 16, (13 i mod 16 + 1/2) / 16)
// less one half: one point in every sixteenth of the pixel's rows and of
// its columns (9 and 13 are prime to 16), and rank-1 lattices against the
// point's index, so that the disc's radius (which grows with i) lines up
// with neither axis of the pixel (offsets (i + 1/2) / 16 along x read the
// disc's rim only at the pixel's right side: three.js' sky-lit sphere p99
// 0.70 against 0.53 with no footprint, docs/LIGHTING.md "The sun over the
// pixel").
fn sb_sun_pixel_offset(i: u32) -> vec2<f32> {
    let x = f32((9u * i) % 16u) + 0.5;
    let y = f32((13u * i) % 16u) + 0.5;
    return vec2<f32>(x, y) / SB_SUN_POINTS - vec2<f32>(0.5);
}
