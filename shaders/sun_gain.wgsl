// ---------------------------------------------------------------- the sun's G
// G with the masking over the sun's disc to first order about its centre:
// the player's first frame (environment.wgsl env_sun_disc) and the
// export's sun (export_env.wgsl sunbeam_shade_sun) take the 16 points' G
// from this plane wherever the disc is well above the surface's horizon. G
// was most of the sun's cost (1.0 of its 1.2 s on a 512 x 512 sky-lit
// sphere on lavapipe, docs/LIGHTING.md "The sun's gain over its disc"); the
// plane needs three evaluations. Needs material.wgsl
// (sb_gain_masked) and env_table.wgsl (sb_sun_disc_dir);
// tests/sun_gain_wgsl.rs runs it against each point's own G in float64.

// The disc's centre at least this cosine above the surface's horizon (about
// 6 degrees, 20 radii of the disc) takes the plane: G is smooth over the
// disc's 0.27 degrees there, and what the plane leaves out is second order
// in that radius (measured: tests/sun_gain_wgsl.rs).
const SB_SUN_PLANE_COS: f32 = 0.1;

// The plane of G with the masking over the disc of centre c (world, unit),
// axes st and sb (unit, perpendicular to c and to each other) and cap cosine
// cos_cap, for the frame (t, b, n) and the local view wr: (G at the centre,
// its change from the centre to the disc's edge along st, and along sb, each
// over the disc's radius, 1) where the centre is at least SB_SUN_PLANE_COS
// above the horizon, else 0 (each point takes its own G).
fn sb_sun_gain_plane(c: vec3<f32>, st: vec3<f32>, sb: vec3<f32>, cos_cap: f32, t: vec3<f32>, b: vec3<f32>, n: vec3<f32>, wr: vec3<f32>, skin: SbSkin) -> vec4<f32> {
    let cz = dot(c, n);
    if (cz < SB_SUN_PLANE_COS) {
        return vec4<f32>(0.0);
    }
    // the disc's edge along its axes
    let et = sb_sun_disc_dir(c, st, sb, cos_cap, 1.0, 0.0);
    let eb = sb_sun_disc_dir(c, st, sb, cos_cap, 1.0, 1.5707964);
    let g0 = sb_gain_masked(vec3<f32>(dot(c, t), dot(c, b), cz), wr, skin);
    let gt = sb_gain_masked(vec3<f32>(dot(et, t), dot(et, b), dot(et, n)), wr, skin);
    let gb = sb_gain_masked(vec3<f32>(dot(eb, t), dot(eb, b), dot(eb, n)), wr, skin);
    // the radius once here, not at each of the disc's points
    let rad = max(sqrt(max(1.0 - cos_cap * cos_cap, 0.0)), 1e-10);
    return vec4<f32>(g0, (gt - g0) / rad, (gb - g0) / rad, 1.0);
}

// G at the disc's direction d from its plane gp (sb_sun_gain_plane; disc
// axes st, sb as there): the centre's G plus each change times d's offset
// from the centre along that axis (sb_sun_disc_dir: st (cos ph st + sin ph
// sb)).
fn sb_sun_gain_at(gp: vec4<f32>, d: vec3<f32>, st: vec3<f32>, sb: vec3<f32>) -> f32 {
    return gp.x + dot(d, st) * gp.y + dot(d, sb) * gp.z;
}
