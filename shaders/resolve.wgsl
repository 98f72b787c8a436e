// The window's resolve of the progressive sum (shaders/accumulate.wgsl): the
// mean of the frames, then the display transform of shaders/diffraction.wgsl
// (the exposure is already in the frames): tone curve, sRGB OETF
// (sunbeam_optics::colour::display_encode), linearised again for an sRGB target.

struct ResolveU {
    width: u32,
    // 1 / frames in the sum
    inv_n: f32,
    // 0 clamp, 1 Reinhard
    curve: u32,
    // 0: display values (UNORM target); 1: their linear value (sRGB target)
    output: u32,
};

@group(0) @binding(0) var<uniform> res_u: ResolveU;
@group(0) @binding(1) var<storage, read> res_sum: array<vec4<f32>>;

@vertex
fn vs_full(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32((i << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(i & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_resolve(@builtin(position) p: vec4<f32>) -> @location(0) vec4<f32> {
    let i = u32(p.y) * res_u.width + u32(p.x);
    let lin = res_sum[i].xyz * res_u.inv_n;
    var out = vec3<f32>(0.0);
    for (var k = 0; k < 3; k = k + 1) {
        out[k] = sb_display_channel(lin[k], res_u.curve, res_u.output);
    }
    return vec4<f32>(out, 1.0);
}
