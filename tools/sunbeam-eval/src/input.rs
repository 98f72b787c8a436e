//! What the subcommands read: a height field (anything sunbeam-afm reads, or
//! the EXR/GSF height fields of sunbeam-import) or a pack (KTX2/EXR with a
//! Sunbeam manifest).

use std::path::Path;
use sunbeam_common::{units, Error, Result};
use sunbeam_field::HeightField;

/// How to read a height field (options for files without calibration).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct HeightArgs {
    /// Pixel size for files that do not record one (images): `65nm` or `65nm,70nm` (dx,dy).
    #[arg(long, value_name = "LEN[,LEN]")]
    pub pixel_size: Option<String>,
    /// Height of the full grey range of an uncalibrated image, e.g. `375nm`.
    #[arg(long, value_name = "LEN")]
    pub z_range: Option<String>,
    /// Channel to use (name or index); default: the first height channel.
    #[arg(long)]
    pub channel: Option<String>,
}

impl HeightArgs {
    pub fn read_options(&self) -> Result<sunbeam_afm::ReadOptions> {
        let mut o = sunbeam_afm::ReadOptions::default();
        if let Some(s) = &self.pixel_size {
            let (a, b) = match s.split_once(',') {
                Some((a, b)) => (
                    units::parse_positive_length(a)?,
                    units::parse_positive_length(b)?,
                ),
                None => {
                    let a = units::parse_positive_length(s)?;
                    (a, a)
                }
            };
            o.pixel_size = Some((a, b));
        }
        if let Some(s) = &self.z_range {
            o.z_range = Some(units::parse_positive_length(s)?);
        }
        Ok(o)
    }
}

/// A KTX2 file, or an EXR whose header carries the `sunbeam.manifest` attribute.
pub fn is_pack(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut f = std::fs::File::open(path)
        .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    let mut head = Vec::with_capacity(1 << 16);
    f.by_ref()
        .take(1 << 16)
        .read_to_end(&mut head)
        .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    const KTX2: &[u8] = b"\xABKTX 20\xBB\r\n\x1A\n";
    if head.starts_with(KTX2) {
        return Ok(true);
    }
    if head.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return Ok(head.windows(16).any(|w| w == b"sunbeam.manifest"));
    }
    Ok(false)
}

/// Read a height field in metres: EXR height fields through sunbeam-field,
/// everything else through sunbeam-afm.
pub fn read_height(path: &Path, args: &HeightArgs) -> Result<HeightField> {
    let bytes =
        std::fs::read(path).map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return sunbeam_field::io::read(path);
    }
    let opts = args.read_options()?;
    let chans = sunbeam_afm::read_bytes(&bytes, &opts).map_err(|e| e.context(path.display()))?;
    let ch = sunbeam_afm::select_channel(&chans, args.channel.as_deref())
        .map_err(|e| e.context(path.display()))?;
    if ch.z_unit != "m" {
        return Err(Error::input_file(
            path,
            format!(
                "channel '{}' has values in '{}', not heights in metres (give --z-range for an uncalibrated image)",
                ch.name, ch.z_unit
            ),
        ));
    }
    if ch.xy_unit != "m" {
        return Err(Error::input_file(
            path,
            format!(
                "channel '{}' has no lateral calibration (give --pixel-size)",
                ch.name
            ),
        ));
    }
    let mut f = ch.field.clone();
    f.provenance.source_file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(f)
}

/// Replicate a height field `nx` x `ny` times (a periodic patch seen by a
/// window larger than one period).
pub fn tile(f: &HeightField, nx: usize, ny: usize) -> Result<HeightField> {
    if nx == 1 && ny == 1 {
        return Ok(f.clone());
    }
    let (w, h) = (f.width * nx, f.height * ny);
    let mut data = Vec::with_capacity(w * h);
    for r in 0..h {
        for c in 0..w {
            data.push(f.at(r % f.height, c % f.width));
        }
    }
    let mut t = HeightField::new(w, h, f.dx, f.dy, data)?;
    t.provenance = f.provenance.clone();
    t.provenance.processing.push(format!("tiled {nx}x{ny}"));
    Ok(t)
}

/// `NxM` (or `N`, meaning `Nx1`).
pub fn parse_tile(s: &str) -> Result<(usize, usize)> {
    let (a, b) = s.split_once(['x', 'X']).unwrap_or((s, "1"));
    let p = |v: &str| {
        v.trim()
            .parse::<usize>()
            .ok()
            .filter(|&n| (1..=64).contains(&n))
            .ok_or_else(|| Error::usage(format!("--tile '{s}': expected NxM with 1 <= N, M <= 64")))
    };
    Ok((p(a)?, p(b)?))
}
