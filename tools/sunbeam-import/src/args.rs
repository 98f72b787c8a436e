//! Command line of sunbeam-import (clap).

use clap::Parser;
use std::path::PathBuf;
use sunbeam_afm::Format;
use sunbeam_common::cli::{pixel_size, positive_length, PixelSize};
use sunbeam_common::units::parse_size;
use sunbeam_common::{Error, Result};
use sunbeam_field::align::AlignRows;
use sunbeam_field::geom::CropSpec;
use sunbeam_field::pipeline::{FlipAxis, Level};

#[derive(Parser, Debug)]
#[command(
    name = "sunbeam-import",
    version,
    about = "Read an AFM scan and write a calibrated height field (.exr or .gsf)",
    after_help = "Exit codes: 0 ok, 1 usage, 2 input unreadable or invalid, 3 output not written, 4 internal.\n\
                  Processing order: crop, fill-nonfinite, level, align-rows, remove-scars, zero-mean, rotate, flip, resample.\n\
                  See docs/IMPORT.md."
)]
pub(crate) struct Cli {
    /// The scan (format detected from content), or `synthetic:NAME` for a built-in
    /// synthetic field (elaphe, xenopeltis, sine, blazed).
    pub(crate) input: PathBuf,
    /// Output height field: .exr (float32, metres) or .gsf.
    #[arg(short, long, required_unless_present = "list")]
    pub(crate) output: Option<PathBuf>,
    /// Force the input format (nanoscope, gwy, gsf, ibw, sxm, park, jpk, png, tiff, bmp, ascii, xyz, exr).
    #[arg(long, value_name = "NAME", value_parser = format_name)]
    pub(crate) format: Option<Format>,
    /// List the channels (name, size, physical size, units) and exit.
    #[arg(long)]
    pub(crate) list: bool,
    /// Channel by name or index; default: the first height channel.
    #[arg(long, value_name = "NAME|INDEX")]
    pub(crate) channel: Option<String>,
    /// Background levelling: plane (Gwyddion's Plane Level) or poly:N.
    #[arg(long, value_name = "plane|poly:N")]
    pub(crate) level: Option<Level>,
    /// Row alignment: median, median-diff or none (Gwyddion's Align Rows).
    #[arg(long, value_name = "METHOD")]
    pub(crate) align_rows: Option<AlignRows>,
    /// Replace NaN/Inf values by Laplace interpolation.
    #[arg(long)]
    pub(crate) fill_nonfinite: bool,
    /// Accept heights no instrument measures: NaN/Inf kept (without
    /// --fill-nonfinite) or a range beyond 1 mm (docs/IMPORT.md).
    #[arg(long)]
    pub(crate) allow_implausible: bool,
    /// Shift the mean height to zero.
    #[arg(long)]
    pub(crate) zero_mean: bool,
    /// Mark and interpolate scars (short horizontal streaks).
    #[arg(long)]
    pub(crate) remove_scars: bool,
    /// Rotate counter-clockwise by 0, 90, 180 or 270 degrees.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    pub(crate) rotate: Option<i32>,
    /// Mirror along x (left-right) or y (top-bottom).
    #[arg(long, value_name = "x|y")]
    pub(crate) flip: Option<FlipAxis>,
    /// Crop X,Y,W,H from the top-left corner: pixels (10,10,256,256) or lengths (0um,0um,1um,1um).
    #[arg(long, value_name = "X,Y,W,H", value_parser = CropSpec::parse)]
    pub(crate) crop: Option<CropSpec>,
    /// Pixel size. For files without lateral calibration (plain images, bare
    /// ASCII matrices, EXRs from other tools) it IS the calibration; for
    /// calibrated files it resamples to square pixels of this size.
    /// Give `DX,DY` to calibrate non-square pixels.
    #[arg(long, value_name = "LEN", value_parser = pixel_size)]
    pub(crate) pixel_size: Option<PixelSize>,
    /// Resample to square pixels of this size (always resamples, never calibrates).
    #[arg(long, value_name = "LEN", conflicts_with = "size", value_parser = positive_length)]
    pub(crate) resample_to: Option<f64>,
    /// Resample to WxH pixels (square pixels; the longer side is cropped if the aspect differs).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub(crate) size: Option<(usize, usize)>,
    /// Calibration for uncalibrated images: height of the full grey range.
    #[arg(long, value_name = "LEN", value_parser = positive_length)]
    pub(crate) z_range: Option<f64>,
    /// Calibration for uncalibrated data: metres per grey level / per number.
    #[arg(long, value_name = "LEN", value_parser = positive_length)]
    pub(crate) z_scale: Option<f64>,
    /// `synthetic:NAME` inputs: the field's size in pixels (square).
    #[arg(long, value_name = "N", default_value_t = 256)]
    pub(crate) synthetic_size: usize,
    /// `synthetic:NAME` inputs: the pixel size.
    #[arg(long, value_name = "LEN", default_value = "25nm", value_parser = positive_length)]
    pub(crate) synthetic_pixel: f64,
    /// Also write a false-colour PNG preview with a scale bar.
    #[arg(long, value_name = "PNG")]
    pub(crate) preview: Option<PathBuf>,
    /// Print a JSON report on stdout.
    #[arg(long)]
    pub(crate) json: bool,
    /// Write a Make-style depfile.
    #[arg(long, value_name = "FILE")]
    pub(crate) depfile: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(short, long, conflicts_with = "verbose")]
    pub(crate) quiet: bool,
    /// Print the steps.
    #[arg(short, long)]
    pub(crate) verbose: bool,
}

/// clap value parser of `--format`: a format's name or alias.
fn format_name(s: &str) -> Result<Format> {
    Format::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Format::ALL.iter().map(|f| f.name()).collect();
        Error::usage(format!("unknown format (one of {})", names.join(", ")))
    })
}
