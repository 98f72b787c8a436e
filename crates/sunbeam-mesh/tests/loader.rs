//! The renderers' loader (`load_scene_mesh`) and the readers: world space, node
//! transforms, external/embedded buffers, OBJ, and the baked attributes read back.

mod common;
use common::*;
use serde_json::json;
use sunbeam_mesh::bake::{bake, BakeOptions};
use sunbeam_mesh::orient::Source;
use sunbeam_mesh::{load_scene_mesh, scene_mesh, OrientationSource};

const TRI: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
const UV: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

fn close(a: [f32; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k] as f64 - b[k]).abs() < tol)
}

#[test]
fn node_hierarchy_is_applied() {
    let mut d = doc_from(
        &TRI,
        Some(&[[0.0, 0.0, 1.0]; 3]),
        Some(&UV),
        &[0, 1, 2],
        json!({"translation": [5.0, 0.0, 0.0], "children": [1]}),
    );
    let s = std::f64::consts::FRAC_1_SQRT_2;
    d.json_array_mut("nodes")
        .push(json!({"mesh": 0, "rotation": [0.0, 0.0, s, s], "scale": [2.0, 2.0, 2.0]}));
    let m = scene_mesh(&d).unwrap();
    assert_eq!(m.positions.len(), 6);
    assert_eq!(m.submeshes.len(), 2);
    assert!(close(m.positions[1], [6.0, 0.0, 0.0], 1e-6));
    // Child: rotate 90 degrees about z, scale 2, then the parent's translation.
    assert!(
        close(m.positions[4], [5.0, 2.0, 0.0], 1e-6),
        "{:?}",
        m.positions[4]
    );
    assert!(
        close(m.positions[5], [3.0, 0.0, 0.0], 1e-6),
        "{:?}",
        m.positions[5]
    );
    for n in &m.normals {
        assert!(close(*n, [0.0, 0.0, 1.0], 1e-6));
    }
    // Not baked: the orientation is derived from the UVs (+u), rotated with the node.
    assert_eq!(m.orientation_source, Some(OrientationSource::Derived));
    assert!(close(m.orientation[0], [1.0, 0.0, 0.0], 1e-6));
    assert!(
        close(m.orientation[3], [0.0, 1.0, 0.0], 1e-6),
        "{:?}",
        m.orientation[3]
    );
    assert!(m.has_uvs);
}

#[test]
fn mirroring_node_keeps_front_faces_ccw() {
    let d = doc_from(
        &TRI,
        None,
        None,
        &[0, 1, 2],
        json!({"scale": [-1.0, 1.0, 1.0]}),
    );
    let m = scene_mesh(&d).unwrap();
    let p: Vec<[f64; 3]> = m
        .indices
        .iter()
        .map(|&i| m.positions[i as usize].map(|x| x as f64))
        .collect();
    let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], 0.0];
    let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], 0.0];
    let cz = e1[0] * e2[1] - e1[1] * e2[0];
    assert!(cz > 0.0, "winding must stay CCW about the world normal");
    assert!(close(m.normals[0], [0.0, 0.0, 1.0], 1e-6));
    assert!(!m.has_uvs);
    for (t, n) in m.orientation.iter().zip(&m.normals) {
        let dot: f32 = (0..3).map(|k| t[k] * n[k]).sum();
        assert!(dot.abs() < 1e-6);
    }
}

#[test]
fn gltf_with_external_and_data_uri_buffers() {
    let dir = tmpdir("ext");
    let mut d = doc_from(&TRI, None, Some(&UV), &[0, 1, 2], json!({}));
    // Move buffer 0 into an external file, and add a data-URI image.
    std::fs::write(dir.join("geo data.bin"), &d.buffers[0]).unwrap();
    d.json["buffers"][0]["uri"] = json!("geo%20data.bin");
    let png = [0x89u8, b'P', b'N', b'G', 13, 10, 26, 10];
    use base64::Engine;
    d.json["images"] = json!([{"uri": format!("data:image/png;base64,{}", base64::engine::general_purpose::STANDARD.encode(png))}]);
    d.json["textures"] = json!([{"source": 0}]);
    d.json["materials"] = json!([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [0.5, 0.25, 1.0, 1.0]}, "extras": {"keep": "me"}}]);
    d.json["meshes"][0]["primitives"][0]["material"] = json!(0);
    let f = dir.join("m.gltf");
    std::fs::write(&f, serde_json::to_vec(&d.json).unwrap()).unwrap();
    let m = load_scene_mesh(&f).unwrap();
    assert_eq!(m.positions.len(), 3);
    assert_eq!(m.submeshes[0].base_color, [0.5, 0.25, 1.0, 1.0]);
    // Bake and write a GLB: the image is embedded, extras kept, one buffer.
    let doc = sunbeam_mesh::load_document(&f).unwrap();
    assert_eq!(doc.extra_inputs.len(), 1);
    let mut b = bake(doc, &BakeOptions::new(Source::Axis([1.0, 1.0, 0.0]))).unwrap();
    let glb = b.doc.to_glb();
    let out = dir.join("out.glb");
    std::fs::write(&out, &glb).unwrap();
    let back = sunbeam_mesh::load_document(&out).unwrap();
    assert_eq!(back.json["materials"][0]["extras"]["keep"], "me");
    assert!(back.json["images"][0].get("uri").is_none());
    assert_eq!(back.json["images"][0]["mimeType"], "image/png");
    assert_eq!(back.array("buffers").len(), 1);
    let m2 = load_scene_mesh(&out).unwrap();
    assert_eq!(m2.orientation_source, Some(OrientationSource::Baked));
    let s = std::f32::consts::FRAC_1_SQRT_2;
    assert!(close(m2.orientation[0], [s as f64, s as f64, 0.0], 1e-6));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn baked_orientation_comes_back_in_world_space() {
    // A rotated, non-uniformly scaled node: the baked world direction must be the
    // world axis projected, after the loader applies the node transform.
    let (pos, uv, idx) = grid(9, |x, y| 0.3 * (x * 2.0).sin() * y);
    let d = doc_from(
        &pos,
        None,
        Some(&uv),
        &idx,
        json!({"rotation": [0.2, 0.1, 0.3, 0.927], "scale": [1.0, 3.0, 0.5], "translation": [1.0, 2.0, 3.0]}),
    );
    let axis = [0.3, -0.8, 0.52];
    let mut b = bake(d, &BakeOptions::new(Source::Axis(axis))).unwrap();
    let dir = tmpdir("world");
    let out = dir.join("w.glb");
    std::fs::write(&out, b.doc.to_glb()).unwrap();
    let m = load_scene_mesh(&out).unwrap();
    let a = sunbeam_mesh::geom::normalize(axis).unwrap();
    for i in 0..m.positions.len() {
        let n = m.normals[i].map(|x| x as f64);
        let p = sunbeam_mesh::geom::normalize(sunbeam_mesh::geom::project(a, n)).unwrap();
        assert!(
            close(m.orientation[i], p, 2e-5),
            "vertex {i}: {:?} vs {:?}",
            m.orientation[i],
            p
        );
        let t = m.tangents[i];
        assert!(t[3] == 1.0 || t[3] == -1.0);
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn obj_with_and_without_normals_and_uvs() {
    let dir = tmpdir("obj");
    let f = dir.join("q.obj");
    std::fs::write(&f, "mtllib none.mtl\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 2\nusemtl a\nf 1/1/1 2/2/1 3/3/1 4/4/1\nusemtl b\nf -4 -2 -1\n").unwrap();
    let m = load_scene_mesh(&f).unwrap();
    assert_eq!(m.submeshes.len(), 2);
    assert_eq!(m.indices.len(), 9);
    // OBJ v is up, glTF v is down.
    assert_eq!(m.uvs[0], [0.0, 1.0]);
    assert!(
        close(m.normals[0], [0.0, 0.0, 1.0], 1e-6),
        "normalised from (0,0,2)"
    );
    // Second group has no normals: computed.
    let last = m.positions.len() - 1;
    assert!(close(m.normals[last], [0.0, 0.0, 1.0], 1e-6));
    // Bad index names the file and the line.
    std::fs::write(&f, "v 0 0 0\nf 1 2 3\n").unwrap();
    let e = load_scene_mesh(&f).unwrap_err();
    assert_eq!(e.exit_code(), 2);
    assert!(
        e.message.contains("q.obj") && e.message.contains("line 2"),
        "{}",
        e.message
    );
    std::fs::write(&f, "v 0 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let e = load_scene_mesh(&f).unwrap_err();
    assert!(e.message.contains("NaN"), "{}", e.message);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn bad_files_are_input_errors_naming_the_file() {
    let dir = tmpdir("bad");
    for (name, bytes) in [
        ("trunc.glb", b"glTF\x02\0\0\0\xff\0\0\0".to_vec()),
        ("empty.obj", Vec::new()),
        ("junk.gltf", b"{\"asset\": {\"version\": \"2.0\"}, \"buffers\": [{\"byteLength\": 100, \"uri\": \"missing.bin\"}]}".to_vec()),
        ("v1.gltf", b"{\"asset\": {\"version\": \"1.0\"}}".to_vec()),
        ("notjson.gltf", b"{ nope".to_vec()),
    ] {
        let f = dir.join(name);
        std::fs::write(&f, bytes).unwrap();
        let e = load_scene_mesh(&f).unwrap_err();
        assert_eq!(e.exit_code(), 2, "{name}: {}", e.message);
        assert!(e.message.contains(name), "{name}: {}", e.message);
    }
    // An accessor that runs past its buffer.
    let mut d = doc_from(&TRI, None, None, &[0, 1, 2], json!({}));
    d.json["accessors"][0]["count"] = json!(1000);
    let f = dir.join("short.gltf");
    std::fs::write(&f, serde_json::to_vec(&d.json).unwrap()).unwrap();
    let e = load_scene_mesh(&f);
    assert!(e.is_err());
    let _ = std::fs::remove_dir_all(dir);
}

/// Mutated and truncated files never panic: each load/bake is Ok or an input error.
#[test]
fn mutated_files_never_panic() {
    let mut d = sunbeam_mesh::snake::generate(&sunbeam_mesh::snake::SnakeParams {
        rings: 10,
        segments: 4,
        ..Default::default()
    });
    let glb = d.to_glb();
    let json_len = u32::from_le_bytes([glb[12], glb[13], glb[14], glb[15]]) as usize;
    let mut rng = Lcg(99);
    let dir = tmpdir("fuzz");
    let f = dir.join("f.glb");
    let tokens: [&[u8]; 8] = [
        b"0",
        b"-1",
        b"99999999999",
        b"null",
        b"[]",
        b"{}",
        b"\"x\"",
        b"1e308",
    ];
    for round in 0..600 {
        let mut b = glb.clone();
        match round % 3 {
            0 => b.truncate((rng.next() * b.len() as f64) as usize),
            1 => {
                for _ in 0..3 {
                    let i = 20 + (rng.next() * json_len as f64) as usize;
                    b[i] = (rng.next() * 256.0) as u8;
                }
            }
            _ => {
                // Replace a number in the JSON with another token (keeps it parseable more often).
                let js = String::from_utf8_lossy(&b[20..20 + json_len]).into_owned();
                let digits: Vec<usize> = js
                    .char_indices()
                    .filter(|(_, c)| c.is_ascii_digit())
                    .map(|(i, _)| i)
                    .collect();
                let at = digits[(rng.next() * digits.len() as f64) as usize];
                let tok = tokens[(rng.next() * tokens.len() as f64) as usize];
                let mut njs = js.as_bytes()[..at].to_vec();
                njs.extend_from_slice(tok);
                njs.extend_from_slice(&js.as_bytes()[at + 1..]);
                njs.resize(njs.len().next_multiple_of(4), b' ');
                let mut nb = b[..12].to_vec();
                nb.extend_from_slice(&(njs.len() as u32).to_le_bytes());
                nb.extend_from_slice(b"JSON");
                nb.extend_from_slice(&njs);
                nb.extend_from_slice(&b[20 + json_len..]);
                let total = nb.len() as u32;
                nb[8..12].copy_from_slice(&total.to_le_bytes());
                b = nb;
            }
        }
        std::fs::write(&f, &b).unwrap();
        let r = std::panic::catch_unwind(|| {
            if let Ok(doc) = sunbeam_mesh::load_document(&f) {
                let _ = scene_mesh(&doc);
                if let Ok(mut baked) = bake(doc, &BakeOptions::new(Source::Axis([1.0, 0.0, 0.0]))) {
                    let _ = baked.doc.to_glb();
                }
            }
        });
        assert!(r.is_ok(), "round {round} panicked");
    }
    let _ = std::fs::remove_dir_all(dir);
}
