// Progressive accumulation (docs/PLAY.md "Environment"): each frame of the
// environment mode (linear light times the exposure, RGBA16F, MSAA resolved) is
// added into an RGBA32F sum, one vec4 per pixel; count 0 starts a new sum.

struct AccU {
    width: u32,
    height: u32,
    // frames in the sum before this one (0: overwrite)
    count: u32,
    _a0: u32,
};

@group(0) @binding(0) var<uniform> acc_u: AccU;
@group(0) @binding(1) var<storage, read_write> acc_sum: array<vec4<f32>>;
@group(0) @binding(2) var frame_tex: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn cs_add(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= acc_u.width || id.y >= acc_u.height) {
        return;
    }
    let i = id.y * acc_u.width + id.x;
    let v = textureLoad(frame_tex, id.xy, 0);
    if (acc_u.count == 0u) {
        acc_sum[i] = v;
    } else {
        acc_sum[i] = acc_sum[i] + v;
    }
}
