//! Any file into a height field in metres: the ONE reader that sunbeam-import,
//! sunbeam-pack and sunbeam-eval call, with one rule set (docs/IMPORT.md):
//!
//! - **Formats**: every AFM format of this crate, EXR height fields (any
//!   single-layer EXR: the channel `Z`, else the only channel, else `Y`) and
//!   Gwyddion `.gsf`. Detected from the content, or forced with `format`.
//! - **Calibration**: `pixel_size` calibrates files that record no lateral size
//!   (plain images, bare ASCII matrices, EXRs from other tools, XYZ point grids);
//!   a calibrated file keeps its own calibration, and [`HeightRead::pixel_size_calibrated`]
//!   says which happened (sunbeam-import then resamples to the given size).
//!   `z_range` / `z_scale` calibrate uncalibrated grey levels and unitless
//!   channels. The channel must end up in metres, laterally and in z.
//! - **Plausibility**: non-finite heights are refused unless the caller fills
//!   them (`fill_nonfinite`, sunbeam-import `--fill-nonfinite`), and a height range
//!   (max - min of the finite values) beyond [`MAX_PLAUSIBLE_RANGE_M`] = 1 mm is
//!   refused: no AFM scanner has that z travel, so such values come from a
//!   damaged file or a wrong unit. `allow_implausible` (`--allow-implausible`)
//!   forces both. Refusals are input errors (exit 2) naming the file and channel.

use crate::{detect, list_channels_bytes, read_bytes, select_channel};
use crate::{Channel, ChannelInfo, Format, ReadOptions};
use std::path::Path;
use sunbeam_common::units::format_length;
use sunbeam_common::{Error, Result};
use sunbeam_field::HeightField;

/// The largest height range (max - min) a real scan can have: 1 mm. AFM
/// scanners travel a few to a few tens of micrometres in z; beyond a millimetre
/// the numbers cannot be a measurement.
pub const MAX_PLAUSIBLE_RANGE_M: f64 = 1e-3;

/// How to read a height field.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HeightOptions {
    /// Skip detection and use this format.
    pub format: Option<Format>,
    /// Channel by name or index; `None`: the first height channel.
    pub channel: Option<String>,
    /// Pixel size (dx, dy) in metres for files that record none.
    pub pixel_size: Option<(f64, f64)>,
    /// Height of the full grey range of an uncalibrated image, metres.
    pub z_range: Option<f64>,
    /// Metres per grey level / per number / per unit of a unitless channel.
    pub z_scale: Option<f64>,
    /// The caller fills NaN/Inf afterwards: do not refuse them.
    pub fill_nonfinite: bool,
    /// Accept non-finite values and height ranges beyond [`MAX_PLAUSIBLE_RANGE_M`].
    pub allow_implausible: bool,
}

impl HeightOptions {
    fn read_options(&self) -> ReadOptions {
        ReadOptions {
            format: self.format,
            pixel_size: None,
            z_range: self.z_range,
            z_scale: self.z_scale,
        }
    }
}

/// A height field and how it was obtained.
#[derive(Debug, Clone)]
pub struct HeightRead {
    /// Heights in metres, row 0 at the top. Provenance: `source_file` is the
    /// file read (no directories), `source_format` and `channel` as the file
    /// records them (else the detected format and the channel's name), and the
    /// calibrations applied in `processing`.
    pub field: HeightField,
    /// Name of the channel read.
    pub channel: String,
    /// The format the file was read as.
    pub format: Format,
    /// `pixel_size` served as the calibration (the file records none).
    pub pixel_size_calibrated: bool,
    /// The calibrations applied here, as added to `field.provenance.processing`.
    pub processing: Vec<String>,
}

/// Read a file into a height field in metres (see the module docs). Messages
/// start with "FILE: ".
pub fn read_height_field(path: &Path, o: &HeightOptions) -> Result<HeightRead> {
    let bytes =
        std::fs::read(path).map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    let mut r = read_height_bytes(&bytes, o).map_err(|e| e.context(path.display()))?;
    r.field.provenance.source_file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(r)
}

/// [`read_height_field`] on a file held in memory (messages without a file name).
pub fn read_height_bytes(bytes: &[u8], o: &HeightOptions) -> Result<HeightRead> {
    let (chans, format, calibrated) = read_channels(bytes, o)?;
    from_channels(&chans, format, calibrated, o)
}

/// Every channel of a file; returns them, the format, and whether
/// `pixel_size` served as the calibration.
pub fn read_channels(bytes: &[u8], o: &HeightOptions) -> Result<(Vec<Channel>, Format, bool)> {
    let read = o.read_options();
    let format = o.format.or_else(|| detect(bytes));
    if format == Some(Format::Exr) {
        let (c, cal) = exr_channel(bytes, o.pixel_size)?;
        return Ok((vec![c], Format::Exr, cal));
    }
    let fmt = format.unwrap_or(Format::Ascii);
    // XYZ points: the pixel size is the grid the points are sampled onto.
    if fmt == Format::Xyz && o.pixel_size.is_some() {
        let opts = ReadOptions {
            pixel_size: o.pixel_size,
            ..read
        };
        return Ok((read_bytes(bytes, &opts)?, fmt, true));
    }
    match read_bytes(bytes, &read) {
        Ok(c) => Ok((c, fmt, false)),
        Err(e) => match o.pixel_size {
            // Files without calibration refuse to load without a pixel size.
            Some(p) => {
                let opts = ReadOptions {
                    pixel_size: Some(p),
                    ..read
                };
                Ok((read_bytes(bytes, &opts)?, fmt, true))
            }
            None => Err(e),
        },
    }
}

/// The channels of a file without reading their values where the format
/// allows it (Nanoscope lists from the header alone, so damaged files list).
pub fn list(bytes: &[u8], o: &HeightOptions) -> Result<(Vec<ChannelInfo>, Format)> {
    let format = o.format.or_else(|| detect(bytes));
    if format == Some(Format::Exr) {
        let (c, _) = exr_channel(bytes, o.pixel_size)?;
        return Ok((vec![ChannelInfo::of(0, &c, Format::Exr)], Format::Exr));
    }
    let opts = ReadOptions {
        pixel_size: o.pixel_size,
        ..o.read_options()
    };
    let infos = list_channels_bytes(bytes, &opts)?;
    let fmt = infos
        .first()
        .map(|i| i.format)
        .or(format)
        .unwrap_or(Format::Ascii);
    Ok((infos, fmt))
}

/// The channel of an EXR height field (sunbeam_field::io::exr): the pixel size
/// from its attributes, else `pixel_size` (returned `true`), else unitless.
pub fn exr_channel(bytes: &[u8], pixel_size: Option<(f64, f64)>) -> Result<(Channel, bool)> {
    let raw = sunbeam_field::io::exr::decode_raw(bytes)?;
    let (dx, dy, xy_unit, calibrated_by_user) = match (raw.dx, raw.dy, pixel_size) {
        (Some(dx), dy, _) => (dx, dy.unwrap_or(dx), "m", false),
        (None, _, Some((dx, dy))) => (dx, dy, "m", true),
        (None, _, None) => (1.0, 1.0, "", false),
    };
    let z_unit = raw.z_unit.clone().unwrap_or_else(|| "m".into());
    let mut field = HeightField::new(raw.width, raw.height, dx, dy, raw.data)?;
    field.provenance = raw.provenance;
    if field.provenance.source_format.is_empty() {
        field.provenance.source_format = Format::Exr.name().to_string();
    }
    let name = if field.provenance.channel.is_empty() {
        raw.channel_name
    } else {
        field.provenance.channel.clone()
    };
    Ok((
        Channel {
            name,
            is_height: z_unit == "m",
            z_unit,
            field,
            xy_unit: xy_unit.into(),
            offset: (0.0, 0.0),
        },
        calibrated_by_user,
    ))
}

/// Pick the channel and calibrate it to metres, then check it is plausible
/// (the rules of the module docs). `calibrated` says whether `pixel_size` was
/// already used to read the file.
pub fn from_channels(
    chans: &[Channel],
    format: Format,
    calibrated: bool,
    o: &HeightOptions,
) -> Result<HeightRead> {
    let ch = select_channel(chans, o.channel.as_deref())?;
    // A channel without a z unit: z_scale (metres per unit) calibrates it.
    let unitless_scale = match (ch.z_unit.is_empty(), o.z_scale) {
        (true, Some(s)) => Some(s),
        _ => None,
    };
    if ch.z_unit != "m" && unitless_scale.is_none() {
        return Err(Error::input(format!(
            "channel '{}' is in '{}', not metres: not a height field (pick a height channel with --channel, --list shows them; a channel without unit takes --z-scale)",
            ch.name,
            if ch.z_unit.is_empty() { "no unit" } else { &ch.z_unit }
        )));
    }
    let mut field = ch.field.clone();
    let mut processing = Vec::new();
    if let Some(sc) = unitless_scale {
        field.data.iter_mut().for_each(|v| *v *= sc);
        processing.push(format!("calibrate z scale {} per unit", format_length(sc)));
    }
    let mut pixel_size_calibrated = calibrated;
    if ch.xy_unit != "m" {
        match o.pixel_size {
            Some((dx, dy)) => {
                field.dx = dx;
                field.dy = dy;
                pixel_size_calibrated = true;
            }
            None => {
                return Err(Error::input(format!(
                    "channel '{}' has no lateral calibration (unit '{}'): give --pixel-size",
                    ch.name, ch.xy_unit
                )))
            }
        }
    }
    if pixel_size_calibrated && o.pixel_size.is_some() {
        processing.push(format!(
            "calibrate pixel size {} x {}",
            format_length(field.dx),
            format_length(field.dy)
        ));
    }
    field
        .provenance
        .processing
        .extend(processing.iter().cloned());
    if field.provenance.source_format.is_empty() {
        field.provenance.source_format = format.name().to_string();
    }
    if field.provenance.channel.is_empty() {
        field.provenance.channel = ch.name.clone();
    }
    check_plausible(&field, &ch.name, o)?;
    Ok(HeightRead {
        field,
        channel: ch.name.clone(),
        format,
        pixel_size_calibrated,
        processing,
    })
}

/// The plausibility rule (module docs): non-finite values (unless they will be
/// filled) and a range beyond [`MAX_PLAUSIBLE_RANGE_M`] are input errors.
pub fn check_plausible(field: &HeightField, channel: &str, o: &HeightOptions) -> Result<()> {
    if o.allow_implausible {
        return Ok(());
    }
    let bad = field.count_nonfinite();
    if bad > 0 && !o.fill_nonfinite {
        return Err(Error::input(format!(
            "channel '{channel}': {bad} heights are NaN/Inf: fill them (sunbeam-import --fill-nonfinite) \
             or force with --allow-implausible"
        )));
    }
    let (lo, hi) = field
        .data
        .iter()
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let range = hi - lo;
    // `range` is Inf when the difference overflows: refused too.
    if hi >= lo && (range > MAX_PLAUSIBLE_RANGE_M || range.is_nan()) {
        return Err(Error::input(format!(
            "channel '{channel}': heights span {lo:.3e} m .. {hi:.3e} m, a range of {range:.3e} m; \
             no AFM measures more than {} (a damaged file or a wrong unit?): \
             force with --allow-implausible",
            format_length(MAX_PLAUSIBLE_RANGE_M)
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field(data: Vec<f64>) -> HeightField {
        HeightField::new(2, 2, 1e-8, 1e-8, data).unwrap()
    }

    #[test]
    fn plausibility_rule() {
        let o = HeightOptions::default();
        assert!(check_plausible(&field(vec![0.0, 1e-6, 2e-6, 5e-4]), "Z", &o).is_ok());
        let e = check_plausible(&field(vec![0.0, 1e-6, 2e-6, 2e-3]), "Z", &o).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(
            e.message.contains("'Z'") && e.message.contains("1 mm"),
            "{e}"
        );
        let e = check_plausible(&field(vec![0.0, f64::NAN, 0.0, 0.0]), "Z", &o).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let fill = HeightOptions {
            fill_nonfinite: true,
            ..HeightOptions::default()
        };
        assert!(check_plausible(&field(vec![0.0, f64::NAN, 0.0, 0.0]), "Z", &fill).is_ok());
        // Finite values whose difference overflows.
        let huge = field(vec![-f64::MAX, f64::MAX, 0.0, 0.0]);
        assert!(check_plausible(&huge, "Z", &o).is_err());
        let force = HeightOptions {
            allow_implausible: true,
            ..HeightOptions::default()
        };
        assert!(check_plausible(&huge, "Z", &force).is_ok());
    }
}
