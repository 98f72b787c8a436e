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
    assert_eq!(fmt, 107, "R32G32B32A32_UINT");
    // KTX 2.0 sections 3-4: typeSize 4; a basic descriptor of four 32-bit
    // unsigned samples R, G, B, A (bytesPlane0 16); the level at a multiple
    // of lcm(16, 4), as long as the texels
    assert_eq!(u32_at(&cells, 16), 4, "typeSize");
    let dfd = u32_at(&cells, 48) as usize;
    assert_eq!(u32_at(&cells, dfd), 4 + 24 + 4 * 16, "DFD size");
    assert_eq!(cells[dfd + 20], 16, "bytesPlane0");
    for (c, id) in [0, 1, 2, 15].into_iter().enumerate() {
        let w0 = u32_at(&cells, dfd + 28 + 16 * c);
        assert_eq!(
            (w0 & 0xffff, (w0 >> 16) & 0xff, w0 >> 24),
            (32 * c as u32, 31, id),
            "sample {c}"
        );
    }
    assert_eq!(levels[0].0 % 16, 0, "level offset");
    assert_eq!(levels[0].1, 16 * w as usize * h as usize, "level length");
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

/// A map's hot spots (docs/ENGINES.md "Environment"): a white map of
/// radiance 1 with a 2 x 2 texel lamp of radiance 200 on the horizon. The
/// export carries the lamp as lights: every tap points at the lamp (within its
/// size) and the taps' power, through basis_to_rgb, is the lamp's energy
/// above the threshold of 8 times the map's mean (between 90 % and all of
/// 200 x its solid angle; both from docs/SCENE.md's equirectangular
/// convention, not from the code), read through the pack's three basis maps,
/// which are written for it; `--env-hot-spots 0` writes neither.
#[test]
fn a_maps_hot_spots_are_exported_as_lights() {
    use std::f64::consts::PI;
    let d = tmp("hot");
    pack(&d, "ridge", "xenopeltis");
    let (w, h) = (64u32, 32u32);
    let lamp = |i: u32, j: u32| (16..18).contains(&i) && (15..17).contains(&j);
    let rgb = (0..w * h)
        .map(|t| {
            if lamp(t % w, t / w) {
                [200.0; 3]
            } else {
                [1.0; 3]
            }
        })
        .collect();
    sunbeam_frame::LinearImage {
        width: w,
        height: h,
        rgb,
    }
    .write_exr(&d.join("lamp.exr"))
    .unwrap();
    let scene = d.join("lamp.json");
    std::fs::write(
        &scene,
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "ridge.ktx2" } ],
  "environment": { "map": "lamp.exr" } }"#,
    )
    .unwrap();
    let run_with = |out: &Path, hot: &str, threshold: &str| {
        let o = Command::new(BIN)
            .arg(&scene)
            .args(["--env-cells", "32", "--env-hot-spots", hot, "-q"])
            .args(["--env-hot-threshold", threshold])
            .arg("--export-environment")
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(
            &std::fs::read(out.join("environment.json")).unwrap(),
        )
        .unwrap()
    };
    let run = |out: &Path, hot: &str| run_with(out, hot, "8");
    let json = run(&d.join("on"), "32");
    // The lamp: columns 16-17 (phi 2 pi [16, 18) / 64), rows 15-16 (theta
    // pi [15, 17) / 32 from +y).
    let phi = 2.0 * PI * 17.0 / 64.0;
    let centre = [phi.cos(), 0.0, phi.sin()];
    let omega: f64 = (15..17)
        .map(|j| {
            let j = f64::from(j);
            ((PI * j / 32.0).cos() - (PI * (j + 1.0) / 32.0).cos()) * 2.0 * PI / 64.0
        })
        .sum::<f64>()
        * 2.0;
    let m: Vec<Vec<f64>> = serde_json::from_value(json["basis_to_rgb"].clone()).unwrap();
    let taps = json["hot_spots"].as_array().unwrap();
    assert!(!taps.is_empty(), "no hot spots: {json}");
    let tap_power = |taps: &[serde_json::Value]| {
        let mut power = [0.0f64; 3];
        for t in taps {
            let t: Vec<f64> = serde_json::from_value(t.clone()).unwrap();
            for (r, row) in m.iter().enumerate() {
                power[r] += row[0] * t[3] + row[1] * t[4] + row[2] * t[5];
            }
        }
        power
    };
    for t in taps {
        let t: Vec<f64> = serde_json::from_value(t.clone()).unwrap();
        let cos = t[0] * centre[0] + t[1] * centre[1] + t[2] * centre[2];
        assert!(
            cos > 8f64.to_radians().cos(),
            "a tap {:.1} deg from the lamp: {t:?}",
            cos.min(1.0).acos().to_degrees()
        );
    }
    let power = tap_power(taps);
    eprintln!(
        "{} taps, power {power:?} against the lamp's 200 x {omega:.5} sr",
        taps.len()
    );
    for (c, p) in power.iter().enumerate() {
        let ratio = p / (200.0 * omega);
        assert!(
            (0.9..=1.0).contains(&ratio),
            "channel {c}: the taps carry {ratio:.3} of the lamp's 200 x {omega:.5} sr"
        );
    }
    // The taps' power-weighted direction is the lamp's centre; with the map
    // turned by 0.4 texel (docs/SCENE.md: from +x towards +z, so phi grows)
    // it turns with it: the table holds the turned map exactly, its columns
    // starting 0.4 texel after phi = 0 (chain.phase), and the taps follow
    // (at the texel centres of the turned map they stayed put: 2.25 degrees).
    let towards = |taps: &[serde_json::Value]| {
        let mut s = [0.0f64; 3];
        for t in taps {
            let t: Vec<f64> = serde_json::from_value(t.clone()).unwrap();
            for k in 0..3 {
                s[k] += t[k] * t[4];
            }
        }
        let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
        s.map(|v| v / n)
    };
    let degrees_from = |a: [f64; 3], b: [f64; 3]| {
        (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    };
    let off = degrees_from(towards(taps), centre);
    assert!(off < 0.2, "the taps point {off:.3} degrees from the lamp");
    assert_eq!(json["chain"]["phase"], 0.0);
    let turn: f64 = 0.4 * 360.0 / 64.0;
    let turned_scene = d.join("lamp-turned.json");
    std::fs::write(
        &turned_scene,
        std::fs::read_to_string(&scene).unwrap().replace(
            r#""map": "lamp.exr""#,
            &format!(r#""map": "lamp.exr", "rotation_deg": {turn}"#),
        ),
    )
    .unwrap();
    let o = Command::new(BIN)
        .arg(&turned_scene)
        .args(["--env-cells", "32", "-q", "--export-environment"])
        .arg(d.join("turned"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let turned: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.join("turned/environment.json")).unwrap()).unwrap();
    let phase = turned["chain"]["phase"].as_f64().unwrap();
    assert!((phase - 0.4 / 64.0).abs() < 1e-9, "phase {phase}");
    let phi_t = phi + turn.to_radians();
    let off = degrees_from(
        towards(turned["hot_spots"].as_array().unwrap()),
        [phi_t.cos(), 0.0, phi_t.sin()],
    );
    assert!(
        off < 0.2,
        "turned: the taps point {off:.3} degrees from the lamp"
    );
    // `--env-hot-threshold`: a texel is hot above that many times the map's
    // mean, which is 1 + 199 omega / (4 pi), and a light keeps the lamp's
    // radiance above it: at 100 x the mean the taps carry (200 - 100 mean) /
    // 200 of the lamp; at 300 x the mean the lamp is not hot.
    let mean = 1.0 + 199.0 * omega / (4.0 * PI);
    let hundred = run_with(&d.join("t100"), "32", "100");
    let p100 = tap_power(hundred["hot_spots"].as_array().unwrap());
    let want = (200.0 - 100.0 * mean) / 200.0;
    for (c, p) in p100.iter().enumerate() {
        let ratio = p / (200.0 * omega);
        assert!(
            (ratio - want).abs() < 0.05,
            "threshold 100, channel {c}: the taps carry {ratio:.3} of the lamp, want {want:.3}"
        );
    }
    let cold = run_with(&d.join("t300"), "32", "300");
    assert_eq!(
        cold["hot_spots"].as_array().map(Vec::len),
        Some(0),
        "{cold}"
    );
    let basis: Vec<String> = serde_json::from_value(json["meshes"][0]["basis"].clone()).unwrap();
    assert_eq!(
        basis,
        ["basis-0-0.ktx2", "basis-0-1.ktx2", "basis-0-2.ktx2"]
    );
    for f in &basis {
        let (fmt, w, _, _) = ktx2_head(&std::fs::read(d.join("on").join(f)).unwrap());
        assert_eq!(fmt, 97, "{f}: RGBA16F");
        assert_eq!(json["meshes"][0]["basis_grid"][0], w, "{f}");
    }
    // The whole map for a background, the chain being the rest: the lamp's
    // texel is in the table at full radiance, not in level 0 of the chain.
    assert_eq!(json["table"], "table.ktx2");
    let level0 = |f: &str| {
        let b = std::fs::read(d.join("on").join(f)).unwrap();
        let (_, tw, _, levels) = ktx2_head(&b);
        let (off, _) = levels[0];
        // k = tw / 64 table texels per map texel (a map's table is its own
        // size, k = 1): table texel (16 k, 15 k) lies in the lamp's texel
        // (16, 15); channel 1
        let k = tw as usize / 64;
        let o = off + 8 * (15 * k * tw as usize + 16 * k) + 2;
        f16_to_f32(u16::from_le_bytes([b[o], b[o + 1]]))
    };
    let (in_table, in_chain) = (level0("table.ktx2"), level0("chain.ktx2"));
    eprintln!("the lamp's texel: {in_table} in the table, {in_chain} in the chain");
    assert!(in_table > 100.0 && in_chain < 20.0, "{in_table} {in_chain}");
    // Without hot spots: no taps, no basis maps, no separate table.
    let json = run(&d.join("off"), "0");
    assert_eq!(
        json["hot_spots"].as_array().map(Vec::len),
        Some(0),
        "{json}"
    );
    assert!(json["meshes"][0].get("basis").is_none(), "{json}");
    assert!(json["table"].is_null(), "{json}");
    assert!(!d.join("off/basis-0-0.ktx2").exists());
    assert!(!d.join("off/table.ktx2").exists());
}

/// An IEEE half float's value (normal and subnormal; no crate for one line).
fn f16_to_f32(h: u16) -> f32 {
    let (sign, exp, frac) = (h >> 15, (h >> 10) & 0x1f, f32::from(h & 0x3ff));
    let v = match exp {
        0 => frac * 2f32.powi(-24),
        31 => f32::INFINITY,
        e => (1.0 + frac / 1024.0) * 2f32.powi(i32::from(e) - 15),
    };
    if sign == 1 {
        -v
    } else {
        v
    }
}
