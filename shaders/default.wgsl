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

// The cells' coarse pre-pass (g.cells_rate > 1), its raster part: at each
// grid point the view (world; w: 1 where this mesh diffracts under the
// environment and the grid serves the view (env_grid_serves), else 0: the
// centre pass walks those pixels), the frame's normal and the distance to
// the eye, and its tangent with the mesh (mat.cells_id).
// fs_cells_walk then walks the cells at the marked points; the centre
// pass mixes their XYZ (shaders/environment.wgsl env_cells_mixed).
struct CellsOut {
    @location(0) xyz: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) t: vec4<f32>,
};

// Whether the pre-passes shade the cells at a point seen from local view
// wr_l: a mesh diffracting under the environment whose fragments read them
// (`mat.reads_cells`), a view above the horizon. The centre pass shades
// every such point; the grid those whose view it serves too
// (env_grid_serves).
fn cells_shaded_here(wr_l: vec3<f32>) -> bool {
    return envg.on == 1u && envp.on == 1u && mat.reads_cells == 1u && mat.base.w < 1.0 && wr_l.z > 0.0;
}

// The centre pass (g.cells_rate >= 1): single-sampled at the frame's size,
// the cells' XYZ at each pixel centre from the coarse grid where it serves
// (shaders/environment.wgsl env_cells_mixed; w: 1), else 0 with the pixel
// marked for the centre's walk, and what that walk and the frame's pass
// read: the frame's normal with the distance to the eye, the view with the
// mark and the tangent with the mesh (as fs_cells). fs_cells_walk then
// walks the marked pixels into the XYZ (loaded, not cleared), and the
// frame's pass reads it (env_cells_pixel) instead of walking once per
// triangle that touches the pixel.
struct CentreOut {
    @location(0) xyz: vec4<f32>,
    @location(1) nd: vec4<f32>,
    @location(2) view: vec4<f32>,
    @location(3) t: vec4<f32>,
};

@fragment
fn fs_cells_centre(in: VsOut) -> CentreOut {
    let fr = frame_at(in.normal, in.tangent, in.uv, in.uv_tangent);
    let wr = normalize(g.eye.xyz - in.world);
    let wr_l = vec3<f32>(dot(wr, fr[0]), dot(wr, fr[1]), dot(wr, fr[2]));
    let dist = length(g.eye.xyz - in.world);
    var o: CentreOut;
    o.xyz = vec4<f32>(0.0);
    o.view = vec4<f32>(wr, 0.0);
    if (cells_shaded_here(wr_l)) {
        o.xyz = env_cells_mixed(fr[0], fr[2], wr_l, in.clip.xy);
        o.view.w = 1.0 - o.xyz.w;
    }
    o.nd = vec4<f32>(fr[2], dist);
    o.t = vec4<f32>(fr[0], f32(mat.cells_id));
    return o;
}

@fragment
fn fs_cells(in: VsOut) -> CellsOut {
    let fr = frame_at(in.normal, in.tangent, in.uv, in.uv_tangent);
    let wr = normalize(g.eye.xyz - in.world);
    let wr_l = vec3<f32>(dot(wr, fr[0]), dot(wr, fr[1]), dot(wr, fr[2]));
    var o: CellsOut;
    // the walk follows in fs_cells_walk: here the view (world) and whether
    // the cells are shaded here
    o.xyz = vec4<f32>(wr, 0.0);
    if (cells_shaded_here(wr_l) && env_grid_serves(wr_l.z)) {
        o.xyz.w = 1.0;
    }
    o.nd = vec4<f32>(fr[2], length(g.eye.xyz - in.world));
    o.t = vec4<f32>(fr[0], f32(mat.cells_id));
    return o;
}

// A full-screen triangle (the cells' grid walk).
@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
}

// The cells' XYZ at point p of the pass's targets (bindings 2-4) where the
// raster pass marked it with this mesh: (XYZ, 1 or 2), else 0. The walk is
// inside the branch: after a discard WGSL demotes the invocation to a
// helper, which goes on running the walk's loop beside the live lanes, so
// every point (the background, the other meshes') would walk.
fn cells_walk_at(p: vec2<i32>) -> vec4<f32> {
    let a = textureLoad(cells_xyz, p, 0);
    let tc = textureLoad(cells_t, p, 0);
    var o = vec4<f32>(0.0);
    if (a.w > 0.5 && tc.w == f32(mat.cells_id)) {
        // the frame the raster pass had (shaders/material.wgsl sb_frame, as
        // frame_at builds it: b = n x t)
        let fr = sb_frame(textureLoad(cells_nd, p, 0).xyz, tc.xyz);
        let wr = a.xyz;
        let wr_l = vec3<f32>(dot(wr, fr[0]), dot(wr, fr[1]), dot(wr, fr[2]));
        // w: 2 at a view the grid does not serve (env_grid_serves), which
        // the frame's pass reads at the pixel's centre and inside the
        // surface's outline only (env_cells_read)
        o = vec4<f32>(env_cells(fr[0], fr[1], fr[2], wr_l), select(1.0, 2.0, !env_grid_serves(wr_l.z)));
    }
    return o;
}

// Whether the walk first mixes its points from its even points
// (fs_cells_walk_half): set for the grid's walk when the packs are small
// enough (crates/sunbeam-render/src/renderer/cells_rate.rs HALF_GRID_PATCH_M)
// and for the centre's walk wherever there is a grid (rate > 1).
override SB_WALK_FROM_HALF: bool = false;

// Whether the walk's target is laid out in bands (band_point): set for the
// grid's walks; the centre's walks write the frame's layout.
override SB_WALK_BANDED: bool = false;

// The point of a grid `w` points wide at pixel s of a target laid out in
// bands: the grid's rows cut into bands of g.cells_band rows, put side by
// side (crates/sunbeam-render/src/renderer/cells_rate.rs `Bands`, which
// copies them back). A CPU rasteriser (lavapipe) shares a pass among its
// threads by tiles of 64 x 64 pixels: a grid 65 points square was one tile
// and its slivers, walked by one thread.
fn band_point(s: vec2<i32>, w: i32) -> vec2<i32> {
    let band = s.x / w;
    return vec2<i32>(s.x - band * w, band * i32(g.cells_band) + s.y);
}

// The even points (2i, 2j) of the grid or of the centre's pixels, walked
// into a target half the size: for the grid laid out in bands (band_point)
// of the half grid's rows.
@fragment
fn fs_cells_walk_half(@builtin(position) clip: vec4<f32>) -> @location(0) vec4<f32> {
    let half = (vec2<i32>(textureDimensions(cells_xyz)) + vec2<i32>(1)) / 2;
    var h = vec2<i32>(floor(clip.xy));
    if (SB_WALK_BANDED) {
        h = band_point(h, half.x);
    }
    // no discard before the walk (cells_walk_at): the band's rows past the
    // grid skip it in a branch
    var o = vec4<f32>(0.0);
    if (h.y < half.y) {
        o = cells_walk_at(h * 2);
    }
    if (o.w < 0.5) {
        discard;
    }
    return o;
}

// Point p of this mesh (a grid point, or a pixel the centre pass marked)
// from its even points (binding 5, fs_cells_walk_half): its own walk at an
// even point; elsewhere the bilinear mix of the four even points around it
// where they saw one smooth patch with p on it (shaders/environment.wgsl
// env_block_smooth and env_block_linear, as a pixel's block). (XYZ, 1 or 2
// as cells_walk_at marks it), else 0: p walks for itself.
fn cells_from_half(p: vec2<i32>) -> vec4<f32> {
    let a = textureLoad(cells_xyz, p, 0);
    let tp = textureLoad(cells_t, p, 0);
    if (!(a.w > 0.5 && tp.w == f32(mat.cells_id))) {
        return vec4<f32>(0.0);
    }
    let h = p / 2;
    let odd = p - 2 * h;
    if (odd.x == 0 && odd.y == 0) {
        return textureLoad(cells_half, h, 0);
    }
    let n = textureLoad(cells_nd, p, 0).xyz;
    if (env_block_smooth(2 * h, 2, tp.xyz, n) && env_block_linear(cells_half, h)) {
        // w: 2 at a view the grid does not serve, as cells_walk_at marks it
        return vec4<f32>(env_bilinear(cells_half, h, 0.5 * vec2<f32>(odd)), select(1.0, 2.0, !env_grid_serves(dot(a.xyz, n))));
    }
    return vec4<f32>(0.0);
}

// The cells' walk, one full-screen pass per mesh after fs_cells (the grid,
// into a target laid out in bands) and after fs_cells_centre (the pixels
// the grid does not serve), the points mixed from their even points where
// SB_WALK_FROM_HALF and their blocks allow (cells_from_half): at each point
// the raster pass marked, the cells' XYZ from the
// frame and view it wrote (bindings 2-4: its targets), so that every SIMD
// block of the walk is full whatever the triangles' size.
@fragment
fn fs_cells_walk(@builtin(position) clip: vec4<f32>) -> @location(0) vec4<f32> {
    var p = vec2<i32>(floor(clip.xy));
    let dims = vec2<i32>(textureDimensions(cells_xyz));
    if (SB_WALK_BANDED) {
        p = band_point(p, dims.x);
    }
    var o = vec4<f32>(0.0);
    if (p.y < dims.y) {
        if (SB_WALK_FROM_HALF) {
            o = cells_from_half(p);
        }
        if (o.w < 0.5) {
            o = cells_walk_at(p);
        }
    }
    // after the walk: the other meshes' points and the background keep
    // what their own passes write
    if (o.w < 0.5) {
        discard;
    }
    return o;
}
