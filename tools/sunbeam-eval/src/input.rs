//! What the subcommands read: a height field (anything sunbeam-afm reads, or
//! the EXR/GSF height fields of sunbeam-import) or a pack (KTX2/EXR with a
//! Sunbeam manifest).

use std::path::Path;
use sunbeam_afm::height::{self, HeightOptions};
use sunbeam_common::{cli, Error, Result};
use sunbeam_field::HeightField;

/// How to read a height field (the one reader, `sunbeam_afm::height`).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct HeightArgs {
    /// Pixel size for files that do not record one (images): `65nm` or `65nm,70nm` (dx,dy).
    #[arg(long, value_name = "LEN[,LEN]", value_parser = cli::pixel_size)]
    pub pixel_size: Option<cli::PixelSize>,
    /// Height of the full grey range of an uncalibrated image, e.g. `375nm`.
    #[arg(long, value_name = "LEN", value_parser = cli::positive_length)]
    pub z_range: Option<f64>,
    /// Channel to use (name or index); default: the first height channel.
    #[arg(long)]
    pub channel: Option<String>,
    /// Accept NaN/Inf heights or a height range beyond 1 mm (docs/IMPORT.md).
    #[arg(long)]
    pub allow_implausible: bool,
}

impl HeightArgs {
    pub fn options(&self) -> HeightOptions {
        HeightOptions {
            channel: self.channel.clone(),
            pixel_size: self.pixel_size.map(cli::PixelSize::pair),
            z_range: self.z_range,
            allow_implausible: self.allow_implausible,
            ..HeightOptions::default()
        }
    }
}

/// A KTX2 file, or an EXR whose header carries the `sunbeam.manifest` attribute.
pub fn is_pack(path: &Path) -> Result<bool> {
    sunbeam_pack::formats::is_pack(path)
}

/// Read a height field in metres (`sunbeam_afm::height`, the rules of docs/IMPORT.md).
pub fn read_height(path: &Path, args: &HeightArgs) -> Result<HeightField> {
    Ok(height::read_height_field(path, &args.options())?.field)
}

/// `NxM` (or `N`, meaning `Nx1`).
pub fn parse_tile(s: &str) -> Result<(usize, usize)> {
    let (a, b) = s.split_once(['x', 'X']).unwrap_or((s, "1"));
    let p = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| (1..=64).contains(&n))
            .ok_or_else(|| Error::usage("expected NxM with 1 <= N, M <= 64"))
    };
    Ok((p(a)?, p(b)?))
}
