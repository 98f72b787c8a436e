//! AFM/SPM file readers for Sunbeam: every image channel of a scan, as height
//! fields in SI units with row 0 at the top (as Gwyddion shows it).
//!
//! Formats are detected from the content (magic bytes, header), never from the
//! file name: Bruker/Veeco Nanoscope, Gwyddion `.gwy` and `.gsf`, Asylum Igor
//! `.ibw`, Nanonis `.sxm`, Park Systems TIFF, JPK TIFF, 8/16-bit grey PNG, TIFF
//! and BMP, ASCII matrices and XYZ point lists. See docs/FORMATS.md.
//!
//! Every parser checks sizes from headers against the data before allocating
//! and reports bad input as `Error::input` naming the field; none panics (the
//! parsers are fuzzed, see fuzz/).

use std::path::Path;

pub use sunbeam_common::{Error, ExitCode as ErrorCode, Result};
use sunbeam_field::HeightField;

mod util;

pub mod height;

mod ascii;
mod gsf;
mod gwy;
mod ibw;
mod image;
mod nanoscope;
mod park;
mod sxm;
mod tiffdir;
mod xyz;

mod mdt;
mod mi;
mod nid;
mod text;
mod wsxm;

/// The file formats this crate reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Format {
    Nanoscope,
    Gwy,
    Gsf,
    Ibw,
    Sxm,
    ParkTiff,
    Jpk,
    Png,
    Tiff,
    Ascii,
    Xyz,
    Exr,
    Bmp,
    /// Nanosurf `.nid`/`.ezd`.
    Nid,
    /// Keysight/Agilent PicoView `.mi`.
    Mi,
    /// WSxM `.top`/`.stp`/`.tom`.
    Wsxm,
    /// NT-MDT `.mdt`.
    Mdt,
}

impl Format {
    /// All formats, in the order `detect` tries them.
    pub const ALL: [Format; 17] = [
        Format::Nanoscope,
        Format::Gwy,
        Format::Gsf,
        Format::Ibw,
        Format::Sxm,
        Format::Nid,
        Format::Mi,
        Format::Wsxm,
        Format::Mdt,
        Format::ParkTiff,
        Format::Jpk,
        Format::Png,
        Format::Tiff,
        Format::Bmp,
        Format::Exr,
        Format::Xyz,
        Format::Ascii,
    ];

    /// Short name, as accepted by `--format` and written into provenance.
    pub fn name(self) -> &'static str {
        match self {
            Format::Nanoscope => "nanoscope",
            Format::Gwy => "gwy",
            Format::Gsf => "gsf",
            Format::Ibw => "ibw",
            Format::Sxm => "sxm",
            Format::ParkTiff => "park-tiff",
            Format::Jpk => "jpk",
            Format::Png => "png",
            Format::Tiff => "tiff",
            Format::Ascii => "ascii",
            Format::Xyz => "xyz",
            Format::Exr => "exr",
            Format::Bmp => "bmp",
            Format::Nid => "nid",
            Format::Mi => "mi",
            Format::Wsxm => "wsxm",
            Format::Mdt => "mdt",
        }
    }

    /// Parse a `--format` name (case-insensitive; a few aliases).
    pub fn from_name(s: &str) -> Option<Format> {
        let s = s.to_ascii_lowercase();
        let f = match s.as_str() {
            "nanoscope" | "bruker" | "veeco" | "spm" => Format::Nanoscope,
            "gwy" | "gwyddion" => Format::Gwy,
            "gsf" => Format::Gsf,
            "ibw" | "igor" | "asylum" => Format::Ibw,
            "sxm" | "nanonis" => Format::Sxm,
            "park-tiff" | "park" | "psia" => Format::ParkTiff,
            "jpk" => Format::Jpk,
            "png" => Format::Png,
            "tiff" | "tif" => Format::Tiff,
            "ascii" | "txt" | "matrix" => Format::Ascii,
            "xyz" => Format::Xyz,
            "exr" => Format::Exr,
            "bmp" => Format::Bmp,
            "nid" | "nanosurf" | "ezd" => Format::Nid,
            "mi" | "picoview" | "keysight" | "agilent" => Format::Mi,
            "wsxm" | "top" | "stp" | "tom" => Format::Wsxm,
            "mdt" | "nt-mdt" | "ntmdt" => Format::Mdt,
            _ => return None,
        };
        Some(f)
    }
}

impl std::fmt::Display for Format {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Format {
    type Err = Error;
    fn from_str(s: &str) -> Result<Format> {
        Format::from_name(s).ok_or_else(|| {
            let names: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
            Error::usage(format!(
                "unknown format '{s}' (known: {})",
                names.join(", ")
            ))
        })
    }
}

/// One image channel of a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// Channel title as the file names it ("Height", "Z (Forward)" ...).
    pub name: String,
    /// SI unit of the values: "m", "V", "A", "deg", "" (none) ...
    pub z_unit: String,
    /// A height/topography channel (z in metres, named like one).
    pub is_height: bool,
    /// Values in SI units of `z_unit`, row 0 at the top; `dx`, `dy` in metres
    /// (or in the file's own lateral unit when `xy_unit` is not "m").
    pub field: HeightField,
    /// Lateral unit: "m", or "" where the file has no lateral unit (its
    /// numbers are kept as they are).
    pub xy_unit: String,
    /// Position of the top-left corner as the file records it (xoff, yoff), in `xy_unit`.
    pub offset: (f64, f64),
}

/// What a channel is, without its values (`list_channels`).
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelInfo {
    pub index: usize,
    pub name: String,
    pub z_unit: String,
    pub xy_unit: String,
    pub is_height: bool,
    pub width: usize,
    pub height: usize,
    /// Physical size (xreal, yreal).
    pub size: (f64, f64),
    pub format: Format,
}

/// Options for files that lack calibration, and a format override.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// Skip detection and use this format.
    pub format: Option<Format>,
    /// Pixel size (dx, dy) in metres for files that do not record it (images,
    /// ASCII matrices without header); overrides nothing in calibrated files.
    pub pixel_size: Option<(f64, f64)>,
    /// Height of the full grey range (0 -> 0, max grey -> z_range) in metres, for
    /// uncalibrated images.
    pub z_range: Option<f64>,
    /// Metres per raw unit: per grey level for uncalibrated images (instead of
    /// z_range), per number for ASCII matrices without header and XYZ files
    /// (default 1: the numbers are metres).
    pub z_scale: Option<f64>,
}

/// Identify the format from the first bytes of a file (never the name).
pub fn detect(bytes: &[u8]) -> Option<Format> {
    if nanoscope::detect(bytes) {
        return Some(Format::Nanoscope);
    }
    if bytes.starts_with(b"GWYP") {
        return Some(Format::Gwy);
    }
    if bytes.starts_with(gsf::MAGIC) {
        return Some(Format::Gsf);
    }
    if bytes.starts_with(b":NANONIS_VERSION:") {
        return Some(Format::Sxm);
    }
    if nid::detect(bytes) {
        return Some(Format::Nid);
    }
    if mi::detect(bytes) {
        return Some(Format::Mi);
    }
    if wsxm::detect(bytes) {
        return Some(Format::Wsxm);
    }
    if mdt::detect(bytes) {
        return Some(Format::Mdt);
    }
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        return Some(Format::Png);
    }
    if bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*") {
        return Some(tiffdir::classify(bytes));
    }
    if bytes.starts_with(b"BM") && bytes.len() >= 26 {
        return Some(Format::Bmp);
    }
    if sunbeam_common::magic::is_exr(bytes) {
        return Some(Format::Exr);
    }
    if ibw::detect(bytes) {
        return Some(Format::Ibw);
    }
    if xyz::detect(bytes) {
        return Some(Format::Xyz);
    }
    if ascii::detect(bytes) {
        return Some(Format::Ascii);
    }
    None
}

/// Read every image channel of a file held in memory. Errors are
/// `Error::input` naming the field; no file name (see `read_file`).
pub fn read_bytes(bytes: &[u8], opts: &ReadOptions) -> Result<Vec<Channel>> {
    if bytes.is_empty() {
        return Err(Error::input("the file is empty"));
    }
    let fmt = match opts.format.or_else(|| detect(bytes)) {
        Some(f) => f,
        None => {
            return Err(Error::input(
                "unknown file format (not Nanoscope, Gwyddion .gwy/.gsf, Igor .ibw, Nanonis .sxm, Park/JPK TIFF, \
                 Nanosurf .nid, PicoView .mi, WSxM, NT-MDT .mdt, PNG/TIFF/BMP, ASCII matrix or XYZ); \
                 convert it with `gwyddion --convert-to-gwy` (docs/FORMATS.md)",
            ))
        }
    };
    let chans = match fmt {
        Format::Nanoscope => nanoscope::read(bytes)?,
        Format::Gwy => gwy::read(bytes)?,
        Format::Gsf => gsf::read(bytes)?,
        Format::Ibw => ibw::read(bytes)?,
        Format::Sxm => sxm::read(bytes)?,
        Format::ParkTiff => park::read(bytes)?,
        Format::Jpk => park::read_jpk(bytes)?,
        Format::Png => image::read_png(bytes, opts)?,
        Format::Tiff => image::read_tiff(bytes, opts)?,
        Format::Bmp => image::read_bmp(bytes, opts)?,
        Format::Ascii => ascii::read(bytes, opts)?,
        Format::Xyz => xyz::read(bytes, opts)?,
        Format::Exr => vec![height::exr_channel(bytes, opts.pixel_size)?.0],
        Format::Nid => nid::read(bytes)?,
        Format::Mi => mi::read(bytes)?,
        Format::Wsxm => wsxm::read(bytes)?,
        Format::Mdt => mdt::read(bytes)?,
    };
    if chans.is_empty() {
        return Err(Error::input(format!(
            "no image channel found in this {} file",
            fmt.name()
        )));
    }
    Ok(chans)
}

/// Read every image channel of a file. Error messages start with "FILE: ".
pub fn read_file(path: &Path, opts: &ReadOptions) -> Result<Vec<Channel>> {
    let bytes =
        std::fs::read(path).map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    let mut chans = read_bytes(&bytes, opts).map_err(|e| e.context(path.display()))?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    for c in &mut chans {
        c.field.provenance.source_file = name.clone();
    }
    Ok(chans)
}

/// The channels of a file held in memory, without their values.
/// For Nanoscope files only the header is read, so files whose data are
/// damaged still list their channels.
pub fn list_channels_bytes(bytes: &[u8], opts: &ReadOptions) -> Result<Vec<ChannelInfo>> {
    let fmt = opts.format.or_else(|| detect(bytes));
    if fmt == Some(Format::Nanoscope) {
        return Ok(nanoscope::header_images(bytes)?
            .into_iter()
            .enumerate()
            .map(|(index, h)| ChannelInfo {
                index,
                is_height: util::looks_like_height(&h.name, &h.z_unit),
                name: h.name,
                z_unit: h.z_unit,
                xy_unit: h.xy_unit,
                width: h.xres,
                height: h.yres,
                size: (h.xreal, h.yreal),
                format: Format::Nanoscope,
            })
            .collect());
    }
    Ok(read_bytes(bytes, opts)?
        .iter()
        .enumerate()
        .map(|(i, c)| ChannelInfo::of(i, c, fmt.unwrap_or(Format::Ascii)))
        .collect())
}

/// The channels of a file, without their values (for `--list`).
pub fn list_channels(path: &Path, opts: &ReadOptions) -> Result<Vec<ChannelInfo>> {
    let bytes =
        std::fs::read(path).map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    list_channels_bytes(&bytes, opts).map_err(|e| e.context(path.display()))
}

impl ChannelInfo {
    /// The description of channel `index` of a file in format `format`.
    pub fn of(index: usize, c: &Channel, format: Format) -> Self {
        ChannelInfo {
            index,
            name: c.name.clone(),
            z_unit: c.z_unit.clone(),
            xy_unit: c.xy_unit.clone(),
            is_height: c.is_height,
            width: c.field.width,
            height: c.field.height,
            size: (c.field.size_x(), c.field.size_y()),
            format,
        }
    }
}

/// Pick a channel by name (exact, then case-insensitive) or index; `None`
/// picks the first height channel, else the first channel.
pub fn select_channel<'a>(chans: &'a [Channel], which: Option<&str>) -> Result<&'a Channel> {
    let names = || {
        chans
            .iter()
            .enumerate()
            .map(|(i, c)| format!("{i}: {}", c.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match which {
        None => chans
            .iter()
            .find(|c| c.is_height)
            .or_else(|| chans.first())
            .ok_or_else(|| Error::input("no channel")),
        Some(w) => {
            if let Some(c) = chans.iter().find(|c| c.name == w) {
                return Ok(c);
            }
            if let Some(c) = chans.iter().find(|c| c.name.eq_ignore_ascii_case(w)) {
                return Ok(c);
            }
            if let Ok(i) = w.parse::<usize>() {
                if let Some(c) = chans.get(i) {
                    return Ok(c);
                }
            }
            Err(Error::usage(format!(
                "no channel '{w}' (channels: {})",
                names()
            )))
        }
    }
}
