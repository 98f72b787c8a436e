//! sunbeam-bake end to end: every output passes the Khronos glTF-Validator with
//! 0 errors, exit codes, depfile, determinism, texture.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

mod common;
use common::{ok, validate};

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-bake");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sunbeam-bake-test-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bake(args: &[&str]) -> Output {
    Command::new(BIN)
        .args(args)
        .output()
        .expect("run sunbeam-bake")
}

const OBJ_PLAIN: &str =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 0.4\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
const OBJ_FULL: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl red\nf 1/1/1 2/2/1 3/3/1\nusemtl blue\nf 1/1/1 3/3/1 4/4/1\n";

#[test]
fn every_output_passes_the_validator() {
    let d = tmpdir("valid");
    let p = |n: &str| d.join(n);
    std::fs::write(p("plain.obj"), OBJ_PLAIN).unwrap();
    std::fs::write(p("full.obj"), OBJ_FULL).unwrap();
    std::fs::write(
        p("m.mtl"),
        "newmtl red\nKd 1 0 0\nmap_Kd tex.png\nnewmtl blue\nKd 0 0 1\nd 0.5\n",
    )
    .unwrap();
    // A tiny valid PNG for map_Kd (1x1 grey), made with the png encoder through the baker's texture path
    // is overkill: write a known 1x1 PNG.
    std::fs::write(p("tex.png"), TINY_PNG).unwrap();
    std::fs::write(
        p("uv.csv"),
        "u,v,angle_deg\n0.1,0.1,0\n0.9,0.2,45\n0.5,0.9,90\n0.5,0.5,-30\n",
    )
    .unwrap();
    let s = |x: &PathBuf| x.to_str().unwrap().to_string();
    let runs: Vec<Vec<String>> = vec![
        vec![
            "--generate-snake".into(),
            "-o".into(),
            s(&p("snake.glb")),
            "--spine-out".into(),
            s(&p("spine.json")),
            "--snake-detail".into(),
            "0.5".into(),
        ],
        vec![
            s(&p("snake.glb")),
            "-o".into(),
            s(&p("snake_curve.glb")),
            "--curve".into(),
            s(&p("spine.json")),
            "--texture".into(),
            s(&p("dir.png")),
            "--texture-size".into(),
            "128".into(),
        ],
        vec![
            s(&p("snake.glb")),
            "-o".into(),
            s(&p("snake_uv.glb")),
            "--uv-direction".into(),
            "v".into(),
            "--rotate-deg".into(),
            "15".into(),
            "--texture".into(),
            s(&p("dir.exr")),
            "--texture-size".into(),
            "64".into(),
        ],
        vec![
            s(&p("snake.glb")),
            "-o".into(),
            s(&p("snake_samples.glb")),
            "--samples".into(),
            s(&p("uv.csv")),
        ],
        vec![
            s(&p("snake.glb")),
            "-o".into(),
            s(&p("snake_sibson.glb")),
            "--samples".into(),
            s(&p("uv.csv")),
            "--interpolation".into(),
            "sibson".into(),
        ],
        vec![
            s(&p("plain.obj")),
            "-o".into(),
            s(&p("plain.glb")),
            "--axis".into(),
            "1,0.2,0".into(),
        ],
        vec![
            s(&p("full.obj")),
            "-o".into(),
            s(&p("full.glb")),
            "--axis".into(),
            "0,1,0".into(),
        ],
        vec![
            s(&p("full.glb")),
            "-o".into(),
            s(&p("full2.glb")),
            "--uv-direction".into(),
            "u".into(),
        ],
    ];
    for r in &runs {
        let args: Vec<&str> = r.iter().map(String::as_str).collect();
        ok(&bake(&args));
    }
    // 3D samples: points of the spine (inside the body, ~radius from the surface) with the
    // spine direction, snapped with a generous --max-snap; one sample far away is rejected.
    let spine: serde_json::Value =
        serde_json::from_slice(&std::fs::read(p("spine.json")).unwrap()).unwrap();
    let pts = spine["points"].as_array().unwrap();
    let mut csv = String::from("x,y,z,dx,dy,dz,comment\n");
    for k in (1..pts.len() - 1).step_by(15) {
        let a: Vec<f64> = pts[k - 1]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let b: Vec<f64> = pts[k + 1]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let c: Vec<f64> = pts[k]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        // Every other sample points backwards: axial data.
        let sg = if k % 2 == 0 { 1.0 } else { -1.0 };
        csv += &format!(
            "{},{},{},{},{},{},spine\n",
            c[0],
            c[1],
            c[2] + 0.02,
            sg * (b[0] - a[0]),
            sg * (b[1] - a[1]),
            sg * (b[2] - a[2])
        );
    }
    csv += "5,5,5,1,0,0,far\n";
    std::fs::write(p("xyz.csv"), csv).unwrap();
    let o = bake(&[
        &s(&p("snake.glb")),
        "-o",
        &s(&p("snake_xyz.glb")),
        "--samples",
        &s(&p("xyz.csv")),
        "--max-snap",
        "0.1",
        "--json",
    ]);
    ok(&o);
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["samples"]["rejected"].as_array().unwrap().len(), 1, "{r}");
    assert!(r["samples"]["used"].as_u64().unwrap() > 10, "{r}");
    let outs = [
        "snake.glb",
        "snake_curve.glb",
        "snake_uv.glb",
        "snake_samples.glb",
        "snake_sibson.glb",
        "plain.glb",
        "full.glb",
        "full2.glb",
    ]
    .map(p);
    let refs: Vec<&Path> = outs.iter().map(PathBuf::as_path).collect();
    validate(&refs);
    // Everything of the input is kept: materials (2), the embedded texture image.
    let m = sunbeam_mesh::load_document(&p("full2.glb")).unwrap();
    assert_eq!(m.array("materials").len(), 2);
    assert_eq!(m.array("images").len(), 1);
    assert_eq!(
        m.json["materials"][1]["pbrMetallicRoughness"]["baseColorFactor"][3],
        0.5
    );
    let _ = std::fs::remove_dir_all(d);
}

const TINY_PNG: &[u8] = &[
    0x89, 0x50, 0x4E, 0x47, 0x0D, 0x0A, 0x1A, 0x0A, 0x00, 0x00, 0x00, 0x0D, 0x49, 0x48, 0x44, 0x52,
    0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x00, 0x00, 0x00, 0x00, 0x3A, 0x7E, 0x9B,
    0x55, 0x00, 0x00, 0x00, 0x0A, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9C, 0x63, 0x68, 0x00, 0x00, 0x00,
    0x82, 0x00, 0x81, 0x4C, 0x17, 0xD7, 0xDF, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4E, 0x44, 0xAE,
    0x42, 0x60, 0x82,
];

#[test]
fn exit_codes_json_depfile_and_determinism() {
    let d = tmpdir("codes");
    let p = |n: &str| d.join(n);
    let s = |x: PathBuf| x.to_str().unwrap().to_string();
    std::fs::write(p("plain.obj"), OBJ_PLAIN).unwrap();
    std::fs::write(p("junk.glb"), b"glTF\x02\0\0\0junkjunkjunkjunk").unwrap();
    std::fs::write(p("bad.csv"), "x,y,z,dx,dy,dz\n0,0,nan,1,0,0\n").unwrap();
    // Usage errors: 1.
    assert_eq!(
        bake(&[&s(p("plain.obj")), "-o", &s(p("o.glb"))])
            .status
            .code(),
        Some(1),
        "no source"
    );
    assert_eq!(
        bake(&[&s(p("plain.obj")), "-o", &s(p("o.glb")), "--axis", "0,0,0"])
            .status
            .code(),
        Some(1)
    );
    assert_eq!(
        bake(&[
            &s(p("plain.obj")),
            "-o",
            &s(p("o.glb")),
            "--axis",
            "1,0,0",
            "--curve",
            "x.json"
        ])
        .status
        .code(),
        Some(1)
    );
    assert_eq!(bake(&["--bogus"]).status.code(), Some(1));
    // Bad inputs: 2, naming the file, no output left.
    for (args, name) in [
        (
            vec![
                s(p("junk.glb")),
                "-o".into(),
                s(p("o.glb")),
                "--axis".into(),
                "1,0,0".into(),
            ],
            "junk.glb",
        ),
        (
            vec![
                s(p("missing.obj")),
                "-o".into(),
                s(p("o.glb")),
                "--axis".into(),
                "1,0,0".into(),
            ],
            "missing.obj",
        ),
        (
            vec![
                s(p("plain.obj")),
                "-o".into(),
                s(p("o.glb")),
                "--samples".into(),
                s(p("bad.csv")),
            ],
            "bad.csv",
        ),
        (
            vec![
                s(p("plain.obj")),
                "-o".into(),
                s(p("o.glb")),
                "--uv-direction".into(),
                "u".into(),
            ],
            "plain.obj",
        ),
        (
            vec![
                s(p("plain.obj")),
                "-o".into(),
                s(p("o.glb")),
                "--curve".into(),
                s(p("bad.csv")),
            ],
            "bad.csv",
        ),
    ] {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = bake(&args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(name), "{args:?}: {err}");
        assert!(!p("o.glb").exists());
    }
    // Output not writable: 3.
    let o = bake(&[
        &s(p("plain.obj")),
        "-o",
        &s(p("no/such/dir/o.glb")),
        "--axis",
        "1,0,0",
    ]);
    assert_eq!(
        o.status.code(),
        Some(3),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // JSON report + depfile; identical bytes on a second run.
    let o = bake(&[
        &s(p("plain.obj")),
        "-o",
        &s(p("a.glb")),
        "--axis",
        "1,0,0",
        "--json",
        "--depfile",
        &s(p("a.d")),
    ]);
    ok(&o);
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["vertices"], 5);
    assert_eq!(r["primitives"], 1);
    assert_eq!(r["without_direction"], serde_json::json!({}));
    let dep = std::fs::read_to_string(p("a.d")).unwrap();
    assert!(dep.contains("a.glb:") && dep.contains("plain.obj"), "{dep}");
    ok(&bake(&[
        &s(p("plain.obj")),
        "-o",
        &s(p("b.glb")),
        "--axis",
        "1,0,0",
    ]));
    assert_eq!(
        std::fs::read(p("a.glb")).unwrap(),
        std::fs::read(p("b.glb")).unwrap()
    );
    // Stdout output.
    let o = bake(&[&s(p("plain.obj")), "-o", "-", "--axis", "1,0,0"]);
    ok(&o);
    assert_eq!(o.stdout, std::fs::read(p("a.glb")).unwrap());
    let _ = std::fs::remove_dir_all(d);
}

/// A glTF that uses much of the format: interleaved and strided views, normalised
/// u8 UVs, a sparse accessor, COLOR_0, an existing TANGENT, strips, points, a mesh
/// placed twice, a matrix node, a camera, an animation, a normal-mapped material
/// with an extension, an external .bin and an external image. The input itself
/// must validate; the output must validate and keep all of it.
#[test]
fn rich_gltf_keeps_everything() {
    use serde_json::json;
    let d = tmpdir("rich");
    let mut bin: Vec<u8> = Vec::new();
    let f32s =
        |b: &mut Vec<u8>, v: &[f32]| v.iter().for_each(|x| b.extend_from_slice(&x.to_le_bytes()));
    // View 0: interleaved POSITION + NORMAL, 4 vertices, stride 24.
    for (p, n) in [
        ([0f32, 0., 0.], [0f32, 0., 1.]),
        ([1., 0., 0.], [0., 0., 1.]),
        ([1., 1., 0.], [0., 0., 1.]),
        ([0., 1., 0.], [0., 0., 1.]),
    ] {
        f32s(&mut bin, &p);
        f32s(&mut bin, &n);
    }
    // View 1 at 96: UVs as normalised u8, stride 4.
    for uv in [[0u8, 255], [255, 255], [255, 0], [0, 0]] {
        bin.extend_from_slice(&[uv[0], uv[1], 0, 0]);
    }
    // View 2 at 112: COLOR_0 vec4 float.
    for _ in 0..4 {
        f32s(&mut bin, &[1.0, 0.5, 0.25, 1.0]);
    }
    // View 3 at 176: indices u16 (6) + pad.
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin.extend_from_slice(&[0, 0, 0, 0]);
    // View 4 at 192: sparse indices (u8 [2]) padded, view 5 at 196: sparse values (one vec3).
    bin.extend_from_slice(&[2, 0, 0, 0]);
    f32s(&mut bin, &[0.5, 2.0, 0.0]);
    // View 6 at 208: existing TANGENT for 4 vertices (x axis, w=1).
    for _ in 0..4 {
        f32s(&mut bin, &[1.0, 0.0, 0.0, 1.0]);
    }
    // View 7 at 272: animation times [0,1], view 8 at 280: translations.
    f32s(&mut bin, &[0.0, 1.0]);
    f32s(&mut bin, &[0.0, 0.0, 0.0, 0.0, 0.5, 0.0]);
    assert_eq!(bin.len(), 304);
    std::fs::write(d.join("rich.bin"), &bin).unwrap();
    std::fs::write(d.join("normal.png"), TINY_PNG).unwrap();
    let g = json!({
        "asset": {"version": "2.0", "generator": "sunbeam test", "extras": {"who": "test"}},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "buffers": [{"uri": "rich.bin", "byteLength": 304}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 96, "byteStride": 24, "target": 34962},
            {"buffer": 0, "byteOffset": 96, "byteLength": 16, "byteStride": 4, "target": 34962},
            {"buffer": 0, "byteOffset": 112, "byteLength": 64, "target": 34962},
            {"buffer": 0, "byteOffset": 176, "byteLength": 12, "target": 34963},
            {"buffer": 0, "byteOffset": 192, "byteLength": 1},
            {"buffer": 0, "byteOffset": 196, "byteLength": 12},
            {"buffer": 0, "byteOffset": 208, "byteLength": 64, "target": 34962},
            {"buffer": 0, "byteOffset": 272, "byteLength": 8},
            {"buffer": 0, "byteOffset": 280, "byteLength": 24}
        ],
        "accessors": [
            {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"bufferView": 0, "byteOffset": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 2, 0],
             "sparse": {"count": 1, "indices": {"bufferView": 4, "componentType": 5121}, "values": {"bufferView": 5}}},
            {"bufferView": 6, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": 7, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
            {"bufferView": 8, "componentType": 5126, "count": 2, "type": "VEC3"},
            {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 1], "max": [0, 0, 1]}
        ],
        "images": [{"uri": "normal.png", "name": "nrm"}],
        "samplers": [{"magFilter": 9729}],
        "textures": [{"source": 0, "sampler": 0}],
        "materials": [{"name": "skin", "normalTexture": {"index": 0, "scale": 0.5},
                       "emissiveFactor": [1, 0, 0],
                       "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}, "extras": {"note": 1}}],
        "meshes": [
            {"name": "quad", "primitives": [
                {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "COLOR_0": 3}, "indices": 4, "material": 0},
                {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "mode": 5},
                {"attributes": {"POSITION": 0}, "mode": 0}
            ]},
            {"name": "sparse", "primitives": [
                {"attributes": {"POSITION": 5, "NORMAL": 1, "TEXCOORD_0": 2, "TANGENT": 6}, "indices": 4, "material": 0,
                 "targets": [{"POSITION": 9}]}
            ], "weights": [0.5]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
        "nodes": [
            {"name": "a", "mesh": 0, "translation": [2, 0, 0]},
            {"name": "b", "mesh": 0, "rotation": [0, 0, 0.6, 0.8], "children": [2]},
            {"name": "c", "mesh": 1, "matrix": [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,-1,1]},
            {"name": "cam", "camera": 0, "extras": {"x": true}}
        ],
        "animations": [{"channels": [{"sampler": 0, "target": {"node": 0, "path": "translation"}}],
                        "samplers": [{"input": 7, "output": 8}]}],
        "scenes": [{"nodes": [0, 1, 3]}],
        "scene": 0
    });
    let input = d.join("rich.gltf");
    std::fs::write(&input, serde_json::to_vec_pretty(&g).unwrap()).unwrap();
    validate(&[&input]);
    let out = d.join("rich.glb");
    let o = bake(&[
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--axis",
        "1,1,0",
        "--json",
        "--depfile",
        d.join("rich.d").to_str().unwrap(),
    ]);
    ok(&o);
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(r["primitives"], 3, "{r}");
    assert_eq!(r["skipped_primitives"].as_array().unwrap().len(), 1);
    assert!(r["warnings"].to_string().contains("meshes[0]"), "{r}");
    validate(&[&out]);
    let back = sunbeam_mesh::load_document(&out).unwrap();
    let j = &back.json;
    assert_eq!(j["asset"]["extras"]["who"], "test");
    assert_eq!(
        j["materials"][0]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"],
        2.0
    );
    assert_eq!(j["materials"][0]["normalTexture"]["scale"], 0.5);
    assert_eq!(j["images"][0]["name"], "nrm");
    assert_eq!(j["animations"].as_array().unwrap().len(), 1);
    assert_eq!(j["cameras"][0]["type"], "perspective");
    assert_eq!(j["meshes"][1]["primitives"][0]["targets"][0]["POSITION"], 9);
    assert_eq!(j["meshes"][1]["weights"][0], 0.5);
    assert_eq!(j["nodes"][3]["extras"]["x"], true);
    assert_eq!(j["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"], 3);
    assert!(
        j["meshes"][0]["primitives"][2]["attributes"]
            .get("TANGENT")
            .is_none(),
        "points untouched"
    );
    assert_ne!(
        j["meshes"][1]["primitives"][0]["attributes"]["TANGENT"], 6,
        "old TANGENT replaced"
    );
    // The sparse vertex was read with its override, and the loader sees the baked field.
    let m = sunbeam_mesh::load_scene_mesh(&out).unwrap();
    assert_eq!(
        m.orientation_source,
        Some(sunbeam_mesh::OrientationSource::Baked)
    );
    // Node c (x2, z-1) is a child of b (quaternion (0,0,0.6,0.8): cos 0.28, sin 0.96 about z):
    // (0.5,2,0) -> (1,2,-1) -> (0.28-1.92, 0.96+0.56, -1).
    assert!(
        m.positions.iter().any(|p| (p[0] + 1.64).abs() < 1e-5
            && (p[1] - 1.52).abs() < 1e-5
            && (p[2] + 1.0).abs() < 1e-6),
        "sparse override"
    );
    let dep = std::fs::read_to_string(d.join("rich.d")).unwrap();
    assert!(
        dep.contains("rich.bin") && dep.contains("normal.png"),
        "{dep}"
    );
    let _ = std::fs::remove_dir_all(d);
}

/// The JSON chunk of a GLB.
fn glb_json(glb: &Path) -> serde_json::Value {
    let b = std::fs::read(glb).unwrap();
    let len = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&b[20..20 + len]).unwrap()
}

/// `--pack`: the SUNBEAM_materials_diffraction extension names the pack and its
/// response map relative to the GLB, carries the map's grid as the map's own
/// header says, is used but not required, lands on every material (one is made
/// for primitives without), passes glTF-Validator; a pack without a map is refused.
#[test]
fn pack_writes_the_diffraction_extension() {
    let d = tmpdir("ext");
    let tool = |name: &str| PathBuf::from(env!("CARGO_BIN_EXE_sunbeam-bake")).with_file_name(name);
    let h = d.join("h.exr");
    let packs = d.join("packs");
    std::fs::create_dir_all(&packs).unwrap();
    let pack = packs.join("x.ktx2");
    ok(&Command::new(tool("sunbeam-import"))
        .args(["synthetic:xenopeltis", "--synthetic-size", "64", "-q", "-o"])
        .arg(&h)
        .output()
        .unwrap());
    ok(&Command::new(tool("sunbeam-pack"))
        .arg(&h)
        .arg("-o")
        .arg(&pack)
        .arg("-q")
        .output()
        .unwrap());
    let glb = d.join("out").join("snake.glb");
    std::fs::create_dir_all(glb.parent().unwrap()).unwrap();
    let s = |p: &Path| p.to_str().unwrap().to_string();
    // No map yet: refused, nothing written.
    let o = bake(&[
        "--generate-snake",
        "--snake-detail",
        "0.3",
        "--pack",
        &s(&pack),
        "-o",
        &s(&glb),
    ]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("response map"));
    assert!(!glb.exists());
    ok(&Command::new(tool("sunbeam-pack"))
        .arg(&h)
        .arg("-o")
        .arg(&pack)
        .args(["--response", "-q"])
        .output()
        .unwrap());
    let dep = d.join("snake.d");
    ok(&bake(&[
        "--generate-snake",
        "--snake-detail",
        "0.3",
        "--pack",
        &s(&pack),
        "--diffuse-weight",
        "0.3",
        "-o",
        &s(&glb),
        "--depfile",
        &s(&dep),
    ]));
    let j = glb_json(&glb);
    assert!(j["extensionsUsed"]
        .as_array()
        .unwrap()
        .iter()
        .any(|v| v == "SUNBEAM_materials_diffraction"));
    assert!(j.get("extensionsRequired").is_none_or(|r| !r
        .as_array()
        .unwrap()
        .iter()
        .any(|v| v == "SUNBEAM_materials_diffraction")));
    let mats = j["materials"].as_array().unwrap();
    assert!(!mats.is_empty());
    let header = std::fs::read(packs.join("x.response.ktx2")).unwrap();
    let text = String::from_utf8_lossy(&header);
    for m in mats {
        let e = &m["extensions"]["SUNBEAM_materials_diffraction"];
        assert_eq!(e["responseMap"]["uri"], "../packs/x.response.ktx2");
        assert_eq!(e["pack"]["uri"], "../packs/x.ktx2");
        assert_eq!(e["diffuseWeight"], 0.3);
        // The skin: the flags' defaults, f0 from the index (0.04 at 1.5).
        assert_eq!(e["ior"], 1.5);
        assert!((e["f0"].as_f64().unwrap() - 0.04).abs() < 1e-15);
        assert_eq!(e["reflectance"], "absolute");
        assert_eq!(e["masking"], "off");
        assert!(e.get("rmsSlope").is_none());
        // The grid as the map's own header records it.
        let n_theta = e["grid"]["nTheta"].as_u64().unwrap();
        assert!(
            text.contains(&format!("\"n_theta\":{n_theta}")),
            "nTheta {n_theta} not in the map's header"
        );
    }
    for p in j["meshes"][0]["primitives"].as_array().unwrap() {
        assert!(p.get("material").is_some());
    }
    let deps = std::fs::read_to_string(&dep).unwrap();
    assert!(deps.contains("x.response.ktx2") && deps.contains("x.ktx2"));
    validate(&[&glb]);

    // The skin as given: written as the scene's fields spell them.
    let glb2 = d.join("out").join("skin.glb");
    let snake_with = |flags: &[&str], out: &Path| {
        let (p, o) = (s(&pack), s(out));
        let mut a = vec!["--generate-snake", "--snake-detail", "0.3", "--pack", &p];
        a.extend_from_slice(flags);
        a.extend(["-o", &o]);
        bake(&a)
    };
    ok(&snake_with(
        &[
            "--ior",
            "1.33",
            "--reflectance",
            "relative",
            "--masking",
            "smith",
            "--rms-slope",
            "0.1,0.2",
        ],
        &glb2,
    ));
    let j = glb_json(&glb2);
    let e = &j["materials"][0]["extensions"]["SUNBEAM_materials_diffraction"];
    assert_eq!(e["ior"], 1.33);
    let f0 = (0.33f64 / 2.33).powi(2);
    assert!(
        (e["f0"].as_f64().unwrap() - f0).abs() < 1e-15,
        "{}",
        e["f0"]
    );
    assert_eq!(e["reflectance"], "relative");
    assert_eq!(e["masking"], "smith");
    assert_eq!(e["rmsSlope"], serde_json::json!([0.1, 0.2]));
    validate(&[&glb2]);
    // Bad values are usage errors naming the flag; nothing written.
    for (flag, v) in [
        ("--ior", "1.0"),
        ("--ior", "x"),
        ("--rms-slope", "-1"),
        ("--masking", "on"),
    ] {
        let bad = d.join("out").join("bad.glb");
        let o = snake_with(&[flag, v], &bad);
        assert_eq!(o.status.code(), Some(1), "{flag} {v}");
        assert!(
            String::from_utf8_lossy(&o.stderr).contains(flag),
            "{flag} {v}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(!bad.exists());
    }
}
