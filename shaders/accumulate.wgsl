// Progressive accumulation (docs/PLAY.md "Environment"): each frame of the
// environment mode (linear light times the exposure, RGBA16F) is added into an
// RGBA32F sum, one vec4 per pixel; count 0 starts a new sum. Under MSAA
// (cs_add_ms) a frame of a running mean is read at one sample of each pixel,
// which its jitter put on the pixel's lattice point (EnvGlobals::frame_sample
// in shaders/environment.wgsl), and a frame alone at the mean of the samples
// (the resolved pixel).

struct AccU {
    width: u32,
    height: u32,
    // frames in the sum before this one (0: overwrite)
    count: u32,
    // cs_add_ms: the sample read, 4: the mean of the four
    sample: u32,
};

@group(0) @binding(0) var<uniform> acc_u: AccU;
@group(0) @binding(1) var<storage, read_write> acc_sum: array<vec4<f32>>;
@group(0) @binding(2) var frame_tex: texture_2d<f32>;
@group(0) @binding(3) var frame_ms: texture_multisampled_2d<f32>;

fn add_at(id: vec2<u32>, v: vec4<f32>) {
    let i = id.y * acc_u.width + id.x;
    if (acc_u.count == 0u) {
        acc_sum[i] = v;
    } else {
        acc_sum[i] = acc_sum[i] + v;
    }
}

@compute @workgroup_size(8, 8)
fn cs_add(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= acc_u.width || id.y >= acc_u.height) {
        return;
    }
    add_at(id.xy, textureLoad(frame_tex, id.xy, 0));
}

@compute @workgroup_size(8, 8)
fn cs_add_ms(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= acc_u.width || id.y >= acc_u.height) {
        return;
    }
    var v = vec4<f32>(0.0);
    if (acc_u.sample < 4u) {
        v = textureLoad(frame_ms, id.xy, i32(acc_u.sample));
    } else {
        for (var s = 0; s < 4; s = s + 1) {
            v = v + 0.25 * textureLoad(frame_ms, id.xy, s);
        }
    }
    add_at(id.xy, v);
}
