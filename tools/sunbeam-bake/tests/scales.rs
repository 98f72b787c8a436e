//! `sunbeam-bake --scales` end to end: the Khronos glTF-Validator, every texel
//! of both maps, determinism across runs and thread counts, bad input.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use sunbeam_mesh::gltf::Document;
use sunbeam_mesh::scale_maps;

mod common;
use common::ok;

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-bake");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sunbeam-bake-scales-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bake_env(args: &[&str], threads: Option<&str>) -> Output {
    let mut c = Command::new(BIN);
    c.args(args);
    if let Some(t) = threads {
        c.env("RAYON_NUM_THREADS", t);
    }
    c.output().expect("run sunbeam-bake")
}

fn s(p: &Path) -> String {
    p.to_str().unwrap().to_string()
}

/// `DIR/quad.obj`: a unit square in z = 0 with UVs 0..1 (u along x, v along y).
fn unit_quad(dir: &Path) -> PathBuf {
    let quad = dir.join("quad.obj");
    std::fs::write(
        &quad,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n",
    )
    .unwrap();
    quad
}

#[test]
fn scaled_snake_validates_and_every_texel_is_unit() {
    let d = tmpdir("snake");
    let glb = d.join("snake.glb");
    let dep = d.join("snake.d");
    let o = bake_env(
        &[
            "--generate-snake",
            "--scales",
            "--scale-texels",
            "16",
            // The steepest keel allowed: its flanks' normals are checked below too.
            "--scale-keel",
            "0.1",
            "-o",
            &s(&glb),
            "--json",
            "--depfile",
            &s(&dep),
        ],
        None,
    );
    ok(&o);
    let rep: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let sc = &rep["scales"];
    assert_eq!(sc["texels_per_scale_width"], 16, "{sc}");
    assert_eq!(sc["params"]["rows"], 20, "{sc}");
    assert_eq!(sc["params"]["keel"], 0.1, "{sc}");
    assert!(sc["field_along_u"].as_f64().unwrap() > 0.9, "{sc}");
    // The snake: 1 m long, ~0.17 m around at its widest: ~100-200 scales along.
    let along = sc["scales_along"].as_u64().unwrap();
    assert!((80..=250).contains(&along), "{sc}");
    let depfile = std::fs::read_to_string(&dep).unwrap();
    assert!(
        depfile.starts_with(&format!("{}:", glb.display())),
        "{depfile}"
    );
    common::validate(&[&glb]);

    let mut doc = Document::load(&glb).unwrap();
    let maps = scale_maps::read(&mut doc, 0).unwrap().expect("scale maps");
    let size = [
        sc["texture_size"][0].as_u64().unwrap() as u32,
        sc["texture_size"][1].as_u64().unwrap() as u32,
    ];
    assert_eq!(maps.normal.size, size);
    assert_eq!(maps.orient.size, size);
    assert_eq!(size[1], 20 * 16);
    assert_eq!(
        maps.orient.repeat,
        [false, true],
        "v repeats (no seam), u clamps"
    );
    // 8-bit quantisation: each component is off by at most 0.5/255 * 2.
    let q = 3f64.sqrt() / 255.0 + 1e-9;
    let dec = |b: u8| b as f64 / 255.0 * 2.0 - 1.0;
    let mut masks = [0usize; 2];
    for (i, px) in maps.normal.data.chunks(4).enumerate() {
        let n = [dec(px[0]), dec(px[1]), dec(px[2])];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!(
            (len - 1.0).abs() <= q,
            "normal texel {i}: {n:?} |n| = {len}"
        );
        assert!(n[2] > 0.0, "normal texel {i} below the surface: {n:?}");
        assert_eq!(px[3], 255);
    }
    for (i, px) in maps.orient.data.chunks(4).enumerate() {
        let (c, sn) = (dec(px[0]), dec(px[1]));
        let len = (c * c + sn * sn).sqrt();
        assert!((len - 1.0).abs() <= q, "orientation texel {i}: ({c}, {sn})");
        // Ridges within the default +-6 deg jitter of the body axis (+u).
        assert!(
            sn.atan2(c).to_degrees().abs() <= 6.5,
            "texel {i}: ({c}, {sn})"
        );
        masks[(px[2] == 255) as usize] += 1;
    }
    // Grooves exist but cover a small part of the skin.
    let groove = masks[0] as f64 / (masks[0] + masks[1]) as f64;
    assert!((0.05..0.5).contains(&groove), "groove fraction {groove}");
    // TANGENT is the UV frame (+u), _ORIENTATION keeps the spine field.
    let m = sunbeam_mesh::load_scene_mesh(&glb).unwrap();
    let along_u = m
        .tangents
        .iter()
        .zip(&m.orientation)
        .filter(|(t, o)| (t[0] * o[0] + t[1] * o[1] + t[2] * o[2]).abs() > 0.9)
        .count();
    assert!(along_u as f64 > 0.9 * m.tangents.len() as f64);
    let _ = std::fs::remove_dir_all(&d);
}

/// A small scaled snake with scale seed `seed`.
fn bake_seed(glb: &Path, seed: &str, threads: Option<&str>) -> Output {
    bake_env(
        &[
            "--generate-snake",
            "--snake-detail",
            "0.5",
            "--scales",
            "--scale-texels",
            "8",
            "--scale-seed",
            seed,
            "-o",
            &s(glb),
        ],
        threads,
    )
}

#[test]
fn byte_identical_across_runs_and_thread_counts() {
    let d = tmpdir("det");
    let mut outs = Vec::new();
    for (k, t) in [None, Some("1"), Some("2"), Some("1")]
        .into_iter()
        .enumerate()
    {
        let glb = d.join(format!("s{k}.glb"));
        ok(&bake_seed(&glb, "7", t));
        outs.push(std::fs::read(&glb).unwrap());
    }
    for o in &outs[1..] {
        assert!(o == &outs[0], "outputs differ");
    }
    // Another seed gives other scales.
    let glb = d.join("other.glb");
    ok(&bake_seed(&glb, "8", None));
    assert!(std::fs::read(&glb).unwrap() != outs[0]);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_input_is_refused_with_no_output() {
    let d = tmpdir("bad");
    let out = d.join("o.glb");
    std::fs::write(d.join("nouv.obj"), "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n").unwrap();
    // Usage (exit 1), the message names the option.
    for (args, needle) in [
        (vec!["--scale-rows", "2"], "--scale-rows"),
        (vec!["--scale-rows", "500"], "--scale-rows"),
        (vec!["--scale-tilt", "45"], "--scale-tilt"),
        (vec!["--scale-tilt", "-31"], "--scale-tilt"),
        (vec!["--scale-overlap", "nan"], "--scale-overlap"),
        (vec!["--scale-length", "abc"], "--scale-length"),
        (vec!["--scale-dome", "0.5"], "--scale-dome"),
        (vec!["--scale-keel", "0.2"], "--scale-keel"),
        (vec!["--scale-keel=-0.01"], "--scale-keel"),
        (vec!["--scale-ridge-jitter=-1"], "--scale-ridge-jitter"),
        (vec!["--scale-texels", "1000"], "--scale-texels"),
    ] {
        let mut a = vec!["--generate-snake", "--scales", "-o", out.to_str().unwrap()];
        a.extend(args.iter().copied());
        let o = bake_env(&a, None);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists());
    }
    // A --scale-* option without --scales.
    let o = bake_env(
        &["--generate-snake", "--scale-rows", "10", "-o", &s(&out)],
        None,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(!out.exists());
    // A mesh without UVs: input error (2) naming the file.
    let o = bake_env(
        &[
            &s(&d.join("nouv.obj")),
            "--axis",
            "1,0,0",
            "--scales",
            "-o",
            &s(&out),
        ],
        None,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("nouv.obj") && err.contains("UV"), "{err}");
    assert!(!out.exists());
    // A field across u: baked, with a warning.
    let quad = unit_quad(&d);
    let o = bake_env(
        &[&s(&quad), "--axis", "0,1,0", "--scales", "-o", &s(&out)],
        None,
    );
    ok(&o);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("runs along u at only 0 %"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

/// The keel, read back from the normal map of a flat quad (u, v in 0..1; 4
/// rows of 4 scales, 64 texels a width, no dome, tilt or jitter): across a
/// scale's midline the v-slope is positive, then negative (the normal leans
/// toward the ridge's crest from both sides), and integrating it across the
/// scale gives back the keel's height, `--scale-keel` scale widths, at the
/// middle of the scale and little of it near the free edge's tip (the keel
/// fades out there). Without the keel the same texels are flat.
#[test]
fn keel_height_is_read_back_from_the_normal_map() {
    let d = tmpdir("keel");
    let obj = unit_quad(&d);
    // The normal map (256 x 256 RGBA8) of the quad with a keel of `keel` widths.
    let bake = |keel: &str| -> Vec<u8> {
        let glb = d.join(format!("quad-{keel}.glb"));
        let o = bake_env(
            &[
                &s(&obj),
                "--uv-direction",
                "u",
                "--scales",
                "--scale-rows",
                "4",
                "--scale-length",
                "1",
                "--scale-dome",
                "0",
                "--scale-keel",
                keel,
                "--scale-tilt",
                "0",
                "--scale-tilt-jitter",
                "0",
                "--scale-ridge-jitter",
                "0",
                "--scale-texels",
                "64",
                "-o",
                &s(&glb),
            ],
            None,
        );
        ok(&o);
        let mut doc = Document::load(&glb).unwrap();
        let maps = scale_maps::read(&mut doc, 0).unwrap().expect("scale maps");
        assert_eq!(maps.normal.size, [256, 256]);
        maps.normal.data
    };
    // The decoded v-slope ny / nz across row 0 (image rows 0..64, one texel =
    // 1/64 width) at texel column `col`.
    let slopes = |map: &[u8], col: usize| -> Vec<f64> {
        let dec = |b: u8| b as f64 / 255.0 * 2.0 - 1.0;
        (0..64)
            .map(|y| {
                let px = &map[(y * 256 + col) * 4..][..4];
                dec(px[1]) / dec(px[2])
            })
            .collect()
    };
    let keeled = bake("0.05");
    // Column 32: x = 0.5 scale lengths into scale 0 (xi = 0.62, the keel at full height).
    let slope = slopes(&keeled, 32);
    let before: f64 = slope[..32].iter().sum::<f64>() / 64.0;
    let after: f64 = slope[32..].iter().sum::<f64>() / 64.0;
    // Each decoded slope is within 1/255 of the truth (8 bits; a flat texel
    // decodes to +1/255), so a sum over 32 or 64 texels is within 0.004 widths.
    assert!(
        (before - 0.05).abs() < 0.005,
        "height at the crest {before}, want 0.05 widths; slopes {slope:?}"
    );
    assert!(
        (before + after).abs() < 0.005,
        "the ridge ends where it began: {before} + {after}"
    );
    assert!(slope[26] > 0.1 && slope[37] < -0.1, "{slope:?}");
    // Outside the keel's middle 30 % the scale is flat (no dome).
    assert!(slope[..20]
        .iter()
        .chain(&slope[44..])
        .all(|x| x.abs() < 0.01));
    // Column 0: x = 0.008, xi = 0.24 from the tip, where the keel has faded in
    // to smoothstep(0.24 / 0.35) = 0.76 of its height; it is lower than at the middle.
    let tip: f64 = slopes(&keeled, 0)[..32].iter().sum::<f64>() / 64.0;
    assert!(
        tip < 0.9 * before && tip > 0.2 * before,
        "{tip} vs {before}"
    );
    // No keel: flat everywhere.
    assert!(slopes(&bake("0"), 32).iter().all(|x| x.abs() < 0.01));
    let _ = std::fs::remove_dir_all(&d);
}
