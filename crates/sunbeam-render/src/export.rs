//! `sunbeam-play --export-shader`: the response-map material for other
//! engines, translated by naga from the same WGSL the player draws with
//! (shaders/material.wgsl: Fresnel, G, Smith masking, the diffuse base's share
//! and the frame; shaders/response_map.wgsl; plus the engine interface in
//! shaders/export.wgsl: one uniform block, the map, its sampler,
//! `sunbeam_shade(t, b, n, wi, wr)`; the environment: shaders/env_cells.wgsl,
//! the player's first-frame cells, and shaders/env_hotspots.wgsl, a map's hot
//! spots as lights, with shaders/export_env.wgsl reading their data from
//! textures, `sunbeam_shade_environment(t, b, n, wr)`; the scale
//! maps: shaders/scales.wgsl, the player's frame function, with
//! shaders/export_scales.wgsl binding the two textures,
//! `sunbeam_scale_frame`).
//! docs/ENGINES.md documents the interface and how each engine takes it.
//! naga does the translation (it is already in the tree through wgpu) rather
//! than hand-kept copies per language, so the languages cannot drift apart.

use sunbeam_common::{Error, Result};

/// The exported module's WGSL source.
pub const SOURCE: &str = concat!(
    include_str!("../../../shaders/material.wgsl"),
    include_str!("../../../shaders/response_map.wgsl"),
    include_str!("../../../shaders/export.wgsl"),
    include_str!("../../../shaders/scales.wgsl"),
    include_str!("../../../shaders/export_scales.wgsl"),
    include_str!("../../../shaders/env_table.wgsl"),
    include_str!("../../../shaders/sun_gain.wgsl"),
    include_str!("../../../shaders/export_env.wgsl"),
    include_str!("../../../shaders/env_cells.wgsl"),
    include_str!("../../../shaders/env_hotspots.wgsl")
);

/// The fragment entry point that shows the call (the function engines use is
/// `sunbeam_shade`).
pub const ENTRY: &str = "sunbeam_fragment";

/// Target languages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lang {
    /// GLSL 4.50 core (OpenGL, Vulkan GLSL, Godot via its shading language).
    Glsl,
    /// GLSL ES 3.00 (WebGL2, three.js).
    GlslEs,
    /// HLSL shader model 5.1 (Unity, Unreal, Direct3D).
    Hlsl,
    /// Metal Shading Language 2.0.
    Msl,
    /// SPIR-V binary (Vulkan).
    Spv,
    /// WGSL (WebGPU, wgpu, Bevy): the source itself, validated.
    Wgsl,
}

impl Lang {
    pub const NAMES: [&'static str; 6] = ["glsl", "glsl-es", "hlsl", "msl", "spv", "wgsl"];
}

impl std::str::FromStr for Lang {
    type Err = Error;
    fn from_str(s: &str) -> Result<Lang> {
        Ok(match s {
            "glsl" => Lang::Glsl,
            "glsl-es" => Lang::GlslEs,
            "hlsl" => Lang::Hlsl,
            "msl" => Lang::Msl,
            "spv" => Lang::Spv,
            "wgsl" => Lang::Wgsl,
            _ => {
                return Err(Error::usage(format!(
                    "shader language '{s}': expected one of {}",
                    Lang::NAMES.join(", ")
                )))
            }
        })
    }
}

fn module() -> Result<(naga::Module, naga::valid::ModuleInfo)> {
    let module = naga::front::wgsl::parse_str(SOURCE)
        .map_err(|e| Error::internal(format!("export shader: {}", e.emit_to_string(SOURCE))))?;
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::empty(),
    )
    .validate(&module)
    .map_err(|e| Error::internal(format!("export shader: validation: {e:?}")))?;
    Ok((module, info))
}

/// The material in `lang` (text, or SPIR-V words as little-endian bytes).
pub fn export(lang: Lang) -> Result<Vec<u8>> {
    let (module, info) = module()?;
    let err = |what: &str, e: &dyn std::fmt::Debug| {
        Error::internal(format!("export shader: {what}: {e:?}"))
    };
    match lang {
        Lang::Wgsl => Ok(SOURCE.as_bytes().to_vec()),
        Lang::Glsl | Lang::GlslEs => {
            use naga::back::glsl;
            let options = glsl::Options {
                version: if lang == Lang::Glsl {
                    glsl::Version::Desktop(450)
                } else {
                    glsl::Version::new_gles(300)
                },
                writer_flags: glsl::WriterFlags::empty(),
                ..Default::default()
            };
            let pipeline = glsl::PipelineOptions {
                shader_stage: naga::ShaderStage::Fragment,
                entry_point: ENTRY.to_string(),
                multiview: None,
            };
            let mut out = String::new();
            let mut w = glsl::Writer::new(
                &mut out,
                &module,
                &info,
                &options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .map_err(|e| err("GLSL", &e))?;
            w.write().map_err(|e| err("GLSL", &e))?;
            Ok(out.into_bytes())
        }
        Lang::Hlsl => {
            use naga::back::hlsl;
            let options = hlsl::Options::default();
            let pipeline = hlsl::PipelineOptions {
                entry_point: Some((naga::ShaderStage::Fragment, ENTRY.to_string())),
            };
            let mut out = String::new();
            let mut w = hlsl::Writer::new(&mut out, &options, &pipeline);
            w.write(&module, &info, None).map_err(|e| err("HLSL", &e))?;
            Ok(out.into_bytes())
        }
        Lang::Msl => {
            use naga::back::msl;
            let options = msl::Options {
                lang_version: (2, 0),
                ..Default::default()
            };
            let pipeline = msl::PipelineOptions {
                entry_point: Some((naga::ShaderStage::Fragment, ENTRY.to_string())),
                ..Default::default()
            };
            let (out, _) = msl::write_string(&module, &info, &options, &pipeline)
                .map_err(|e| err("MSL", &e))?;
            Ok(out.into_bytes())
        }
        Lang::Spv => {
            use naga::back::spv;
            let options = spv::Options::default();
            let pipeline = spv::PipelineOptions {
                shader_stage: naga::ShaderStage::Fragment,
                entry_point: ENTRY.to_string(),
            };
            let words = spv::write_vec(&module, &info, &options, Some(&pipeline))
                .map_err(|e| err("SPIR-V", &e))?;
            Ok(words.iter().flat_map(|w| w.to_le_bytes()).collect())
        }
    }
}
