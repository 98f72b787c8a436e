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

// The sun's disc points of one shading point on a mesh with scale maps:
// 64, not SB_SUN_POINTS' 16 (the player's env_sun_disc_carried, for an
// MSAA sample's quarter of the pixel or the pixel; three.js for its
// sub-pixel, through the export's sunbeam_shade_sun_sample_point). Each
// point pairs a place in that part of the pixel with a direction in the
// disc, and a domed scale's glint at 20 um is smaller than a quarter and
// as narrow as the disc: on a 16 x 16 window of the scaled snake under the
// sky (the player, 8 x 8, 4x MSAA) p99 4.23 with 16 points, 2.24 with 64
// (docs/bench/play.md "With a 20 um pack"). Point i's place is a rank-1
// lattice, one point in each of the part's 64 rows and columns (25 and 41
// are prime to 64), for the same reason as sb_sun_pixel_offset's.
const SB_SUN_SAMPLE_POINTS: u32 = 64u;

fn sb_sun_sample_offset(i: u32) -> vec2<f32> {
    let n = SB_SUN_SAMPLE_POINTS;
    return (vec2<f32>(f32((25u * i) % n), f32((41u * i) % n)) + 0.5) / f32(n) - 0.5;
}
