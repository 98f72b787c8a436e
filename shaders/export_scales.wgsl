// Scale maps in the exported material (`sunbeam-bake --scales`, docs/BAKE.md
// "Scales"; docs/ENGINES.md "Scale maps"): the player's own frame function
// (shaders/scales.wgsl sb_scale_frame, prepended to the player's shader too)
// on the engine's two textures.
//
// Bindings (group 0): 10 the material's glTF normalTexture, 11 the
// SUNBEAM_materials_diffraction orientationTexture, both RGBA8 unorm, no
// colour-space conversion, no premultiplied alpha, image row 0 at t = 0 (glTF's
// flipY false), read texel by texel (textureLoad), so their samplers' filters
// do not matter.

@group(0) @binding(10) var scale_normal_tex: texture_2d<f32>;
@group(0) @binding(11) var scale_orient_tex: texture_2d<f32>;

// The shading frame (columns t, b, n) of a fragment: `normal` and
// `orientation` interpolated as for sb_frame, `tangent` the interpolated glTF
// TANGENT (xyz the UV frame, w the bitangent's sign) and `uv` the maps'
// TEXCOORD. `scales`: 0 for a mesh without scale maps (then sb_frame(normal,
// orientation)); else 16 plus the wrap bits: 1 the normal map repeats along
// s, 2 along t, 4 the orientation map along s, 8 along t (glTF wrapS/wrapT
// other than CLAMP_TO_EDGE 33071). As the player's frame_at.
fn sunbeam_scale_frame(normal: vec3<f32>, orientation: vec3<f32>, tangent: vec4<f32>, uv: vec2<f32>, scales: u32) -> mat3x3<f32> {
    let fr = sb_frame(normal, orientation);
    if ((scales & 16u) == 0u) {
        return fr;
    }
    return sb_scale_frame(scale_normal_tex, scale_orient_tex, scales & 15u, normal, tangent, uv, fr);
}

// The scale id under `uv` (sb_scale_id; 0 without scale maps): where it
// differs across a pixel's 2 x 2 quad (fwidth) the quad spans a scale
// border, and the screen derivatives of the frame jump there.
fn sunbeam_scale_id(uv: vec2<f32>, scales: u32) -> f32 {
    if ((scales & 16u) == 0u) {
        return 0.0;
    }
    return sb_scale_id(scale_orient_tex, uv, (scales >> 2u) & 3u);
}
