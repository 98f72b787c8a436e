//! Shared helpers for the player's tests (tests/match_reference.rs,
//! tests/material_wgsl.rs, tests/sun_gain_wgsl.rs, tests/silhouette.rs, tests/scales_player.rs): the headless adapter
//! (`SUNBEAM_TEST_BACKEND`; None to skip, a failure under
//! SUNBEAM_REQUIRE_ALL=1), a compute pass over an array of cases (the WGSL
//! function tests) and the synthetic ridge packs of the real-scale
//! comparisons on a point-lit sphere.
#![allow(dead_code)]

use sunbeam_render::Gpu;
use wgpu::util::DeviceExt;

/// The headless adapter (`SUNBEAM_TEST_BACKEND` picks the backend); without
/// one the test skips with a message, or fails under SUNBEAM_REQUIRE_ALL=1.
pub fn gpu() -> Option<Gpu> {
    let backend = std::env::var("SUNBEAM_TEST_BACKEND")
        .ok()
        .and_then(|b| b.parse().ok())
        .unwrap_or_default();
    match Gpu::headless(backend) {
        Ok(g) => {
            eprintln!("adapter: {}", g.describe());
            Some(g)
        }
        Err(e) => {
            if sunbeam_common::testdata::require_all() {
                panic!("{e} (SUNBEAM_REQUIRE_ALL=1: CI needs a GPU adapter; scripts/ensure-deps.sh installs lavapipe)");
            }
            eprintln!("SKIP: {e}");
            None
        }
    }
}

/// A window-model pack of the synthetic Xenopeltis-like ridge field
/// (`sunbeam_synth::preset`: 443 nm tall, 1.55 um period, rough) of `n^2`
/// samples of `pixel` metres, default build options.
pub fn ridge_pack(n: usize, pixel: f64) -> sunbeam_pack::Pack {
    let f = sunbeam_synth::preset("xenopeltis", n, pixel).unwrap();
    let fr = sunbeam_pack::build::FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    sunbeam_pack::build::build(fr, &Default::default(), &mut |_, _| {}).unwrap()
}

/// A unit-diameter sphere (`Mesh::uv_sphere(96, 48)`) with `pack`, seen from
/// `eye_z` on +z (35 deg field of view) in a `size` x `size` frame, lit from
/// (0.15, 0.1, 1), diffuse weight 0.1, in absolute reflectance at +4.64 EV
/// (`log2(1 / F(0))`) with the base times F(0): the frame as the response-map
/// tests had it in the relative normalisation (the diffraction as bright, the
/// grey base as faint beside it).
pub fn ridge_sphere(pack: sunbeam_pack::Pack, eye_z: f64, size: u32) -> sunbeam_frame::Prepared {
    let mesh = sunbeam_frame::Mesh::uv_sphere(96, 48);
    let mut scene = sunbeam_scene::Scene::default_lit(
        "builtin:sphere".into(),
        Some("pack".into()),
        mesh.bounds(),
        sunbeam_scene::DefaultLighting::Point,
    );
    scene.camera.eye = [0.0, 0.0, eye_z];
    scene.camera.target = [0.0, 0.0, 0.0];
    scene.camera.fov_y_deg = 35.0;
    scene.lights[0].direction = [0.15, 0.1, 1.0];
    scene.meshes[0].diffuse_weight = 0.1;
    scene.size = [size, size];
    let f0 = sunbeam_optics::gain::f0(sunbeam_optics::gain::DEFAULT_IOR);
    scene.exposure -= f0.log2();
    scene.meshes[0].base_color = scene.meshes[0].base_color.map(|c| c * f0);
    sunbeam_frame::fixtures::prepared(scene, mesh, Some(std::sync::Arc::new(pack)))
}

/// The entry point [`compute`] adds: each case through `run_case`.
const COMPUTE_MAIN: &str = r#"
@group(0) @binding(0) var<storage, read> cases: array<Case>;
@group(0) @binding(1) var<storage, read_write> outs: array<Out>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x < arrayLength(&cases)) {
        outs[id.x] = run_case(cases[id.x]);
    }
}
"#;

/// Runs `fn run_case(c: Case) -> Out` of WGSL `src` (which defines the
/// structs `Case` and `Out`, the layouts of `C` and `O`) over `cases` in a
/// compute pass, and reads the outputs back. Panics on a validation error.
pub fn compute<C: bytemuck::Pod, O: bytemuck::Pod>(
    gpu: &Gpu,
    label: &str,
    src: &str,
    cases: &[C],
) -> Vec<O> {
    let src = format!("{src}\n{COMPUTE_MAIN}");
    let device = &gpu.device;
    let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(src.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: Default::default(),
        cache: None,
    });
    if let Some(e) = pollster::block_on(scope.pop()) {
        panic!("{label}: the compute pipeline: {e}");
    }
    let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("cases"),
        contents: bytemuck::cast_slice(cases),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let size = (cases.len() * std::mem::size_of::<O>()) as u64;
    let output = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("outs"),
        size,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    });
    let readback = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: input.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: output.as_entire_binding(),
            },
        ],
    });
    let mut enc = device.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind, &[]);
        pass.dispatch_workgroups(cases.len().div_ceil(64) as u32, 1, 1);
    }
    enc.copy_buffer_to_buffer(&output, 0, &readback, 0, size);
    gpu.queue.submit([enc.finish()]);
    let (tx, rx) = std::sync::mpsc::channel();
    readback.map_async(wgpu::MapMode::Read, .., move |r| {
        let _ = tx.send(r);
    });
    gpu.wait().unwrap();
    rx.recv().unwrap().unwrap();
    gpu.take_errors().unwrap();
    let data = readback.get_mapped_range(..).unwrap();
    bytemuck::cast_slice::<u8, O>(&data).to_vec()
}
