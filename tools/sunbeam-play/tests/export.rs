//! `sunbeam-play --export-shader`: every language is produced; the real
//! validators accept what they can read (glslangValidator for GLSL 4.50 and
//! GLSL ES 3.00, spirv-val for SPIR-V; HLSL and MSL are checked by naga's own
//! validator before they are written); the interface docs/ENGINES.md promises
//! is in the output (the map, the skin's exact Fresnel, G and Smith masking,
//! the frame); usage errors exit 1 and write nothing.

use std::path::{Path, PathBuf};
use std::process::Command;
use sunbeam_common::testdata::have_command;

fn play() -> Command {
    Command::new(env!("CARGO_BIN_EXE_sunbeam-play"))
}

fn export(lang: &str, dir: &Path, name: &str) -> PathBuf {
    let out = dir.join(name);
    let o = play()
        .args(["--export-shader", lang, "-o"])
        .arg(&out)
        .arg("-q")
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "--export-shader {lang}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    out
}

fn tmp(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sb-export-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn glsl_passes_glslang() {
    let d = tmp("glsl");
    // glslangValidator picks the stage from the extension.
    for (lang, name) in [("glsl", "sunbeam.frag"), ("glsl-es", "sunbeam-es.frag")] {
        let f = export(lang, &d, name);
        let text = std::fs::read_to_string(&f).unwrap();
        assert!(text.contains("sunbeam_shade("), "{lang}: no sunbeam_shade");
        assert!(text.contains("sampler3D"), "{lang}: no 3D texture");
        // The material's skin (docs/ENGINES.md): index, normalisation and
        // masking slopes in the uniform block, Smith masking in the shading.
        for m in ["vec4 skin;", "sb_fresnel(", "sb_masking(", "sb_frame("] {
            assert!(text.contains(m), "{lang}: missing {m}");
        }
        // The environment (docs/ENGINES.md "Environment"): the player's cells
        // read from an unsigned integer texture, the prefiltered chain, the
        // environment's numbers, the sun as a light.
        for m in [
            "vec3 sunbeam_shade_environment(",
            "vec3 sunbeam_shade_sun(",
            // the sun point by point on scaled meshes (docs/ENGINES.md
            // "Scale maps under an environment")
            "vec3 sunbeam_shade_sun_point(",
            "vec3 sunbeam_shade_sun_base(",
            "vec2 sunbeam_sun_pixel_offset(",
            "vec3 sunbeam_sun_point_dir(",
            // and its 64 points per sub-pixel
            "vec3 sunbeam_shade_sun_sample_point(",
            "vec2 sunbeam_sun_sample_offset(",
            "const uint SB_SUN_SAMPLE_POINTS = 64u;",
            "vec3 env_cells(",
            "usampler2D _group_0_binding_7_fs",
            "sampler2D _group_0_binding_3_fs",
            "vec4 cells;",
        ] {
            assert!(text.contains(m), "{lang}: missing {m}");
        }
        // The scale maps (docs/ENGINES.md "Scale maps"): the player's frame
        // function on the two textures, by texel (texelFetch).
        for m in [
            "mat3x3 sunbeam_scale_frame(",
            "mat3x3 sb_scale_frame(",
            "sampler2D _group_0_binding_10_fs",
            "sampler2D _group_0_binding_11_fs",
            "texelFetch(",
        ] {
            assert!(text.contains(m), "{lang}: missing {m}");
        }
        if have_command("glslangValidator", &["--version"]) {
            let o = Command::new("glslangValidator").arg(&f).output().unwrap();
            assert!(
                o.status.success(),
                "glslangValidator {lang}: {}",
                String::from_utf8_lossy(&o.stdout)
            );
        }
    }
    // The validator can fail: a broken shader is refused.
    if have_command("glslangValidator", &["--version"]) {
        let bad = d.join("bad.frag");
        std::fs::write(&bad, "#version 450\nvoid main() { undefined_call(); }\n").unwrap();
        assert!(!Command::new("glslangValidator")
            .arg(&bad)
            .status()
            .unwrap()
            .success());
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn spirv_passes_spirv_val() {
    let d = tmp("spv");
    let f = export("spv", &d, "sunbeam.spv");
    let b = std::fs::read(&f).unwrap();
    assert_eq!(&b[..4], &0x0723_0203u32.to_le_bytes(), "SPIR-V magic");
    if have_command("spirv-val", &["--version"]) {
        let o = Command::new("spirv-val").arg(&f).output().unwrap();
        assert!(
            o.status.success(),
            "spirv-val: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let mut cut = b.clone();
        cut.truncate(b.len() / 2);
        let badf = d.join("cut.spv");
        std::fs::write(&badf, cut).unwrap();
        assert!(!Command::new("spirv-val")
            .arg(&badf)
            .status()
            .unwrap()
            .success());
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn hlsl_msl_wgsl_are_written_with_the_interface() {
    let d = tmp("text");
    for (lang, marks) in [
        (
            "hlsl",
            &[
                "sunbeam_shade(",
                "Texture3D",
                "cbuffer sunbeam",
                "float4 skin",
                "sb_masking(",
                "sunbeam_shade_environment(",
                "sunbeam_shade_sun(",
                "Texture2D<uint4>",
            ][..],
        ),
        (
            "msl",
            &[
                "sunbeam_shade(",
                "texture3d<float",
                "sb_masking(",
                "sunbeam_shade_environment(",
                "texture2d<uint",
            ][..],
        ),
        (
            "wgsl",
            &[
                "fn sunbeam_shade(",
                "texture_3d<f32>",
                "fn sb_gain(",
                "fn sb_fresnel(",
                "fn sb_masking(",
                "fn sb_frame(",
                "skin: vec4<f32>",
                "fn sunbeam_shade_environment(",
                "fn env_cells(",
                "texture_2d<u32>",
            ][..],
        ),
    ] {
        let f = export(lang, &d, &format!("sunbeam.{lang}"));
        let text = std::fs::read_to_string(&f).unwrap();
        for m in marks {
            assert!(text.contains(m), "{lang}: missing {m}");
        }
    }
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn usage_errors_write_nothing() {
    let d = tmp("bad");
    let out = d.join("x.glsl");
    let o = play()
        .args(["--export-shader", "cobol", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "unknown language");
    let o = play().args(["--export-shader", "glsl"]).output().unwrap();
    assert_eq!(o.status.code(), Some(1), "no -o");
    assert!(String::from_utf8_lossy(&o.stderr).contains("-o"));
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).ok();
}
