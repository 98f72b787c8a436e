//! `sunbeam-play SCENE.json --export-environment DIR` (docs/ENGINES.md
//! "Environment"): the files an engine binds for `sunbeam_shade_environment`.
//! They hold the player's own data (the chain's levels as
//! `sunbeam_light::prefilter` makes them, the cells as
//! `Cells::gpu_data`), the same bytes on every run, and a scene without an
//! environment is a usage error that writes nothing. No GPU needed.

#[allow(dead_code)] // this test uses the pack builder and the scratch folder only
mod common;

use common::{pack, scratch};
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-play");

fn tmp(name: &str) -> std::path::PathBuf {
    scratch(&format!("play-export-env-{name}"))
}

fn u32_at(b: &[u8], o: usize) -> u32 {
    u32::from_le_bytes(b[o..o + 4].try_into().unwrap())
}

/// vkFormat, width, height, level count and each level's (offset, length).
fn ktx2_head(b: &[u8]) -> (u32, u32, u32, Vec<(usize, usize)>) {
    assert_eq!(&b[..12], &sunbeam_common::magic::KTX2, "KTX2 identifier");
    let levels = u32_at(b, 40) as usize;
    let index = (0..levels)
        .map(|m| {
            let o = 80 + 24 * m;
            let off = u64::from_le_bytes(b[o..o + 8].try_into().unwrap()) as usize;
            let len = u64::from_le_bytes(b[o + 8..o + 16].try_into().unwrap()) as usize;
            assert!(off + len <= b.len(), "level {m} past the end");
            (off, len)
        })
        .collect();
    (u32_at(b, 12), u32_at(b, 20), u32_at(b, 24), index)
}

#[test]
fn writes_the_players_data_deterministically() {
    let d = tmp("sky");
    pack(&d, "ridge", "xenopeltis");
    let scene = d.join("sky.json");
    std::fs::write(
        &scene,
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridge.ktx2", "ior": 1.4 },
              { "mesh": "builtin:quad", "pack": "ridge.ktx2" } ],
  "environment": { "sky": { "sun_elevation_deg": 35 } } }"#,
    )
    .unwrap();
    let run = |out: &Path| {
        let o = Command::new(BIN)
            .arg(&scene)
            .args(["--env-cells", "32", "-q", "--export-environment"])
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (a, b) = (d.join("a"), d.join("b"));
    run(&a);
    run(&b);
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(a.join("environment.json")).unwrap()).unwrap();
    let mut names: Vec<String> = std::fs::read_dir(&a)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "cells-0.ktx2",
            "chain.ktx2",
            "environment.json",
            "irradiance-skin.ktx2",
            "irradiance.ktx2",
            "sun-0.ktx2"
        ]
    );
    for n in &names {
        assert_eq!(
            std::fs::read(a.join(n)).unwrap(),
            std::fs::read(b.join(n)).unwrap(),
            "{n} differs between two runs"
        );
    }
    // The chain: RGBA16F, every level of sunbeam_light::prefilter, 512 x 256 to 2 x 1.
    let chain = std::fs::read(a.join("chain.ktx2")).unwrap();
    let (fmt, w, h, levels) = ktx2_head(&chain);
    assert_eq!((fmt, w, h), (97, 512, 256));
    assert_eq!(levels.len(), 9);
    assert_eq!(json["chain"]["levels"], 9);
    for (m, (_, len)) in levels.iter().enumerate() {
        assert_eq!(*len, (512 >> m) * (256 >> m) * 8, "level {m}");
    }
    // The sky's sun: its colour for the base, its spectral map (a response
    // map on the cells' grid) for the diffraction; the skin's index is the
    // first mesh's.
    assert_eq!(json["irradiance"]["ior"], 1.4);
    assert!(json["sun"]["rgb"][1].as_f64().unwrap() > 0.0, "{json}");
    let sun = std::fs::read(a.join("sun-0.ktx2")).unwrap();
    let (fmt, w, _, _) = ktx2_head(&sun);
    assert_eq!(fmt, 97);
    assert_eq!(json["meshes"][0]["sun_grid"][0], w);
    // One cells file for the pack both meshes share; 32 cells of the pack's layers.
    let meshes = json["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 2);
    assert!(meshes.iter().all(|m| m["file"] == "cells-0.ktx2"));
    assert_eq!(meshes[0]["n_top"], 32);
    let cells = std::fs::read(a.join("cells-0.ktx2")).unwrap();
    let (fmt, w, h, levels) = ktx2_head(&cells);
    assert_eq!(fmt, 98, "R32_UINT");
    assert_eq!(
        (w as u64, h as u64),
        (
            meshes[0]["width"].as_u64().unwrap(),
            meshes[0]["height"].as_u64().unwrap()
        )
    );
    let (off, len) = levels[0];
    let words: Vec<u32> = cells[off..off + len]
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    // Node 0: a centroid inside the (u, v) disc of radius 2, a spread >= 0,
    // then a child pointer (u32::MAX for a leaf, else within the nodes).
    let nodes = meshes[0]["nodes"].as_u64().unwrap() as u32;
    let (u, v, spread) = (
        f32::from_bits(words[0]),
        f32::from_bits(words[1]),
        f32::from_bits(words[2]),
    );
    assert!(u.hypot(v) < 2.0 && spread >= 0.0, "{u} {v} {spread}");
    assert!(words[3] == u32::MAX || words[3] < nodes, "{}", words[3]);
}

#[test]
fn a_scene_without_an_environment_is_refused() {
    let d = tmp("none");
    let scene = d.join("plain.json");
    std::fs::write(
        &scene,
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:quad" } ] }"#,
    )
    .unwrap();
    let o = Command::new(BIN)
        .arg(&scene)
        .arg("--export-environment")
        .arg(d.join("out"))
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("environment"));
    assert!(!d.join("out").exists());
}
