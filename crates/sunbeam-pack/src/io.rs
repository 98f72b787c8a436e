//! Reading height fields and writing packs to files (atomic writes).

use crate::exr_io;
use crate::ktx2;
use crate::pack::Pack;
use std::path::{Path, PathBuf};
use sunbeam_common::output::{write_atomic, write_atomic_with};
use sunbeam_common::{Error, Result};
use sunbeam_field::HeightField;

/// Options for reading a height field (uncalibrated images need a pixel size and z range).
#[derive(Debug, Clone, Default)]
pub struct InputOptions {
    pub pixel_size: Option<(f64, f64)>,
    pub z_range: Option<f64>,
    pub channel: Option<String>,
}

/// Read a height field from anything sunbeam-import reads (EXR/GSF height fields,
/// AFM files, images with a pixel size and z range). Heights must be metres.
pub fn read_height(path: &Path, o: &InputOptions) -> Result<HeightField> {
    let ro = sunbeam_afm::ReadOptions {
        format: None,
        pixel_size: o.pixel_size,
        z_range: o.z_range,
        z_scale: None,
    };
    let chans = sunbeam_afm::read_file(path, &ro)?;
    let ch = sunbeam_afm::select_channel(&chans, o.channel.as_deref())
        .map_err(|e| e.context(path.display()))?;
    if ch.z_unit != "m" {
        return Err(Error::input_file(
            path,
            format!(
                "channel '{}' has values in '{}', not metres: pick a height channel (--channel) or give --z-range for an image",
                ch.name, ch.z_unit
            ),
        ));
    }
    if ch.xy_unit != "m" {
        return Err(Error::input_file(
            path,
            "the file records no lateral size in metres: give --pixel-size",
        ));
    }
    let mut f = ch.field.clone();
    if f.provenance.channel.is_empty() {
        f.provenance.channel = ch.name.clone();
    }
    let bad = f.count_nonfinite();
    if bad > 0 {
        return Err(Error::input_file(
            path,
            format!("{bad} heights are NaN/Inf: fill them first (sunbeam-import --fill-nonfinite)"),
        ));
    }
    Ok(f)
}

/// Output container and layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    Ktx2,
    ExrLayers,
    ExrSplit,
    ExrAtlas,
}

impl OutputKind {
    /// From the output name and the --split/--atlas flags.
    pub fn from_path(path: &Path, split: bool, atlas: bool) -> Result<OutputKind> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "ktx2" => {
                if split || atlas {
                    return Err(Error::usage("--split and --atlas apply to .exr outputs"));
                }
                Ok(OutputKind::Ktx2)
            }
            "exr" => match (split, atlas) {
                (true, true) => Err(Error::usage("--split and --atlas exclude each other")),
                (true, false) => Ok(OutputKind::ExrSplit),
                (false, true) => Ok(OutputKind::ExrAtlas),
                _ => Ok(OutputKind::ExrLayers),
            },
            _ => Err(Error::usage(format!(
                "{}: output must end in .ktx2 or .exr",
                path.display()
            ))),
        }
    }
}

/// Write the pack; returns the files written with their sizes.
pub fn write_pack(pack: &Pack, path: &Path, kind: OutputKind) -> Result<Vec<(PathBuf, u64)>> {
    let writer = pack.manifest.generator.clone();
    match kind {
        OutputKind::Ktx2 => {
            let mut n = 0;
            write_atomic_with(path, |f| {
                let mut w = std::io::BufWriter::new(f);
                n = ktx2::write_to(pack, &writer, &mut w)?;
                use std::io::Write;
                w.flush()
            })?;
            Ok(vec![(path.to_path_buf(), n)])
        }
        OutputKind::ExrLayers => {
            let b = exr_io::encode_layers(pack)?;
            write_atomic(path, &b)?;
            Ok(vec![(path.to_path_buf(), b.len() as u64)])
        }
        OutputKind::ExrAtlas => {
            let b = exr_io::encode_atlas(pack)?;
            write_atomic(path, &b)?;
            Ok(vec![(path.to_path_buf(), b.len() as u64)])
        }
        OutputKind::ExrSplit => {
            let mut out = vec![];
            for n in 0..pack.manifest.terms {
                let p = exr_io::split_path(path, n);
                let b = exr_io::encode_split_term(pack, n)?;
                write_atomic(&p, &b)?;
                out.push((p, b.len() as u64));
            }
            Ok(out)
        }
    }
}
