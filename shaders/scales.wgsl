// Scale maps (`sunbeam-bake --scales`, docs/BAKE.md "Scales"): the material's
// tangent-space normal map and SUNBEAM_materials_diffraction's
// orientationTexture, applied per fragment exactly as the reference does
// (sunbeam_mesh::scale_maps::ScaleMaps::sample, sunbeam_frame::MeshScales::perturb).
// Prepended to the player's shader (crates/sunbeam-render: renderer::SHADER);
// the textures are parameters, so this file binds nothing.
//
// Both maps are read with textureLoad and filtered here, not by a sampler:
// bilinear with texel centres at (i + 0.5) / size and each texture's own wrap
// (REPEAT or CLAMP_TO_EDGE per axis), normals interpolated as vectors and
// renormalised, ridge vectors weighted by the groove mask (B) so that across a
// scale border the visible scale dominates; a sampler's filter can not weight
// one channel by another.

// A texel index along one axis: wrapped (REPEAT) or clamped (CLAMP_TO_EDGE).
fn sb_scale_index(i: i32, n: i32, repeat: bool) -> i32 {
    if (repeat) {
        return ((i % n) + n) % n;
    }
    return clamp(i, 0, n - 1);
}

// The four bilinear taps of `tex` at `uv` (as sunbeam_mesh::scale_maps::Rgba8::taps):
// texels (x0, y0), (x1, y0), (x0, y1), (x1, y1) in `texels`, their weights
// returned; `wrap` bit 0: REPEAT along s (u), bit 1: along t (v).
fn sb_scale_taps(tex: texture_2d<f32>, uv: vec2<f32>, wrap: u32, texels: ptr<function, array<vec4<f32>, 4>>) -> vec4<f32> {
    let size = vec2<i32>(textureDimensions(tex, 0));
    let n = max(size, vec2<i32>(1));
    let p = uv * vec2<f32>(n) - 0.5;
    let f = floor(p);
    let w = p - f;
    let i = vec2<i32>(f);
    let rs = (wrap & 1u) == 1u;
    let rt = (wrap & 2u) == 2u;
    let x0 = sb_scale_index(i.x, n.x, rs);
    let x1 = sb_scale_index(i.x + 1, n.x, rs);
    let y0 = sb_scale_index(i.y, n.y, rt);
    let y1 = sb_scale_index(i.y + 1, n.y, rt);
    (*texels)[0] = textureLoad(tex, vec2<i32>(x0, y0), 0);
    (*texels)[1] = textureLoad(tex, vec2<i32>(x1, y0), 0);
    (*texels)[2] = textureLoad(tex, vec2<i32>(x0, y1), 0);
    (*texels)[3] = textureLoad(tex, vec2<i32>(x1, y1), 0);
    return vec4<f32>((1.0 - w.x) * (1.0 - w.y), w.x * (1.0 - w.y), (1.0 - w.x) * w.y, w.x * w.y);
}

// The scale id at `uv`: the orientation map's alpha (the id modulo 256,
// docs/BAKE.md) at the texel under `uv`, with the map's wrap bits as in
// sb_scale_taps; a change between neighbouring fragments marks a scale border.
fn sb_scale_id(ot: texture_2d<f32>, uv: vec2<f32>, wrap: u32) -> f32 {
    let n = max(vec2<i32>(textureDimensions(ot, 0)), vec2<i32>(1));
    let i = vec2<i32>(floor(uv * vec2<f32>(n)));
    let x = sb_scale_index(i.x, n.x, (wrap & 1u) == 1u);
    let y = sb_scale_index(i.y, n.y, (wrap & 2u) == 2u);
    return textureLoad(ot, vec2<i32>(x, y), 0).a * 255.0;
}

// The shading frame (columns t, b, n) at a fragment of a scaled mesh:
// `normal` and `tangent` (the glTF TANGENT: xyz = the UV frame, w = the
// bitangent's sign) interpolated from the vertices, `uv` its TEXCOORD_0;
// `wraps` the wrap bits of the normal map (bits 0-1) and of the orientation
// map (bits 2-3). The normal map's (X, Y, Z) are along T, w (n x T) and n;
// the ridge direction cos(a) T + sin(a) (n x T) is made orthogonal to the new
// normal and is t. `fallback` (the unperturbed frame) where the vertex frame
// is degenerate, as the reference keeps its fragment's own frame there.
fn sb_scale_frame(nt: texture_2d<f32>, ot: texture_2d<f32>, wraps: u32, normal: vec3<f32>, tangent: vec4<f32>, uv: vec2<f32>, fallback: mat3x3<f32>) -> mat3x3<f32> {
    let ln = length(normal);
    if (!(ln > 0.0)) {
        return fallback;
    }
    let n = normal / ln;
    let tp = tangent.xyz - n * dot(tangent.xyz, n);
    let lt = length(tp);
    if (!(lt > 0.0)) {
        return fallback;
    }
    let t = tp / lt;
    let nxt = cross(n, t);
    let hand = select(1.0, -1.0, tangent.w < 0.0);
    var tx: array<vec4<f32>, 4>;
    // the normal map: vectors interpolated, renormalised
    let wn = sb_scale_taps(nt, uv, wraps & 3u, &tx);
    var m = vec3<f32>(0.0);
    for (var k = 0; k < 4; k = k + 1) {
        m = m + wn[k] * (tx[k].xyz * 2.0 - 1.0);
    }
    if (length(m) > 1e-9) {
        m = normalize(m);
    } else {
        m = vec3<f32>(0.0, 0.0, 1.0);
    }
    // the ridge vectors, weighted by the groove mask; where all four masks
    // and vectors cancel, the nearest (largest-weight) texel's own
    let wo = sb_scale_taps(ot, uv, (wraps >> 2u) & 3u, &tx);
    var r = vec2<f32>(0.0);
    var best = 0;
    var best_w = -1.0;
    for (var k = 0; k < 4; k = k + 1) {
        r = r + wo[k] * (tx[k].z + 1e-3) * (tx[k].xy * 2.0 - 1.0);
        if (wo[k] > best_w) {
            best_w = wo[k];
            best = k;
        }
    }
    if (length(r) > 1e-9) {
        r = normalize(r);
    } else {
        let rb = tx[best].xy * 2.0 - 1.0;
        if (length(rb) > 1e-9) {
            r = normalize(rb);
        } else {
            r = vec2<f32>(1.0, 0.0);
        }
    }
    let n2u = m.x * t + m.y * hand * nxt + m.z * n;
    let l2 = length(n2u);
    if (!(l2 > 0.0)) {
        return fallback;
    }
    let n2 = n2u / l2;
    let d = r.x * t + r.y * nxt;
    let t2u = d - n2 * dot(d, n2);
    let lt2 = length(t2u);
    if (!(lt2 > 0.0)) {
        return fallback;
    }
    let t2 = t2u / lt2;
    return mat3x3<f32>(t2, cross(n2, t2), n2);
}
