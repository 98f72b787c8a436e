// The default technique (docs/PLAY.md "Shading"), composed after
// shaders/diffraction.wgsl into the default pipeline: a point light's
// diffraction term read from the pack's response map (sunbeam-response: T(u,
// v, w), the XYZ of PHYSICS.md 2 without G, precomputed per pack on a polar
// grid, docs/PACK_FORMAT.md "Response map"), trilinear samples averaged over
// the pixel's footprint (shaders/response_map.wgsl).

// The response map's XYZ times G at (u, v, w) = uvw seen from wi, averaged
// over the footprint (screen derivatives dx, dy of uvw, jx, jy of the texel
// coordinates) or read at the pixel centre.
fn response_map_xyz(wi: vec3<f32>, uvw: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, jx: vec3<f32>, jy: vec3<f32>) -> vec3<f32> {
    let gr = resp_grid();
    if (mat.resp_footprint == 1u) {
        return sb_diffraction_xyz_filtered(wi, uvw, dx, dy, jx, jy, gr, skin());
    }
    return sb_diffraction_xyz(wi, -uvw - wi, gr, skin());
}

// A point light's diffraction term (XYZ with G and the masking) for local
// directions wi, wr: none without a map (a scene lit by its environment
// alone builds none).
fn point_xyz(wi: vec3<f32>, wr: vec3<f32>, uvw: vec3<f32>, dx: vec3<f32>, dy: vec3<f32>, jx: vec3<f32>, jy: vec3<f32>) -> vec3<f32> {
    if (mat.resp_on == 0u) {
        return vec3<f32>(0.0);
    }
    // G is inside the footprint average; the masking, smooth over the
    // footprint, at its centre
    return response_map_xyz(wi, uvw, dx, dy, jx, jy) * masking(wi, wr);
}

@fragment
fn fs_main(in: VsOut, @builtin(sample_mask) covered: u32) -> @location(0) vec4<f32> {
    return shade(in, covered);
}
