//! sunbeam-import: read an AFM/SPM scan, pick a channel, convert to metres,
//! optionally level / align rows / fill / remove scars / rotate / flip / crop /
//! resample, and write a height field (`.exr` or `.gsf`). See docs/IMPORT.md.

use clap::Parser;
use std::path::{Path, PathBuf};
use sunbeam_afm::{Channel, ChannelInfo, Format, ReadOptions};
use sunbeam_common::units::{format_length, parse_positive_length, parse_size};
use sunbeam_common::{Error, Result};
use sunbeam_field::align::AlignRows;
use sunbeam_field::geom::CropSpec;
use sunbeam_field::io::{self, Kind};
use sunbeam_field::pipeline::{self, FlipAxis, Level, Step};
use sunbeam_field::resample::Target;
use sunbeam_field::stats::Stats;
use sunbeam_field::HeightField;

#[derive(Parser, Debug)]
#[command(
    name = "sunbeam-import",
    version,
    about = "Read an AFM scan and write a calibrated height field (.exr or .gsf)",
    after_help = "Exit codes: 0 ok, 1 usage, 2 input unreadable or invalid, 3 output not written, 4 internal.\n\
                  Processing order: crop, fill-nonfinite, level, align-rows, remove-scars, zero-mean, rotate, flip, resample.\n\
                  See docs/IMPORT.md."
)]
struct Cli {
    /// The scan (format detected from content), or `synthetic:NAME` for a built-in
    /// synthetic field (elaphe, xenopeltis, sine, blazed).
    input: PathBuf,
    /// Output height field: .exr (float32, metres) or .gsf.
    #[arg(short, long, required_unless_present = "list")]
    output: Option<PathBuf>,
    /// Force the input format (nanoscope, gwy, gsf, ibw, sxm, park, jpk, png, tiff, bmp, ascii, xyz, exr).
    #[arg(long, value_name = "NAME")]
    format: Option<String>,
    /// List the channels (name, size, physical size, units) and exit.
    #[arg(long)]
    list: bool,
    /// Channel by name or index; default: the first height channel.
    #[arg(long, value_name = "NAME|INDEX")]
    channel: Option<String>,
    /// Background levelling: plane (Gwyddion's Plane Level) or poly:N.
    #[arg(long, value_name = "plane|poly:N")]
    level: Option<String>,
    /// Row alignment: median, median-diff or none (Gwyddion's Align Rows).
    #[arg(long, value_name = "METHOD")]
    align_rows: Option<String>,
    /// Replace NaN/Inf values by Laplace interpolation.
    #[arg(long)]
    fill_nonfinite: bool,
    /// Shift the mean height to zero.
    #[arg(long)]
    zero_mean: bool,
    /// Mark and interpolate scars (short horizontal streaks).
    #[arg(long)]
    remove_scars: bool,
    /// Rotate counter-clockwise by 0, 90, 180 or 270 degrees.
    #[arg(long, value_name = "DEG", allow_hyphen_values = true)]
    rotate: Option<i32>,
    /// Mirror along x (left-right) or y (top-bottom).
    #[arg(long, value_name = "x|y")]
    flip: Option<String>,
    /// Crop X,Y,W,H from the top-left corner: pixels (10,10,256,256) or lengths (0um,0um,1um,1um).
    #[arg(long, value_name = "X,Y,W,H")]
    crop: Option<String>,
    /// Pixel size. For files without lateral calibration (plain images, bare
    /// ASCII matrices, EXRs from other tools) it IS the calibration; for
    /// calibrated files it resamples to square pixels of this size.
    /// Give `DX,DY` to calibrate non-square pixels.
    #[arg(long, value_name = "LEN")]
    pixel_size: Option<String>,
    /// Resample to square pixels of this size (always resamples, never calibrates).
    #[arg(long, value_name = "LEN", conflicts_with = "size")]
    resample_to: Option<String>,
    /// Resample to WxH pixels (square pixels; the longer side is cropped if the aspect differs).
    #[arg(long, value_name = "WxH")]
    size: Option<String>,
    /// Calibration for uncalibrated images: height of the full grey range.
    #[arg(long, value_name = "LEN")]
    z_range: Option<String>,
    /// Calibration for uncalibrated data: metres per grey level / per number.
    #[arg(long, value_name = "LEN")]
    z_scale: Option<String>,
    /// `synthetic:NAME` inputs: the field's size in pixels (square).
    #[arg(long, value_name = "N", default_value_t = 256)]
    synthetic_size: usize,
    /// `synthetic:NAME` inputs: the pixel size.
    #[arg(long, value_name = "LEN", default_value = "25nm")]
    synthetic_pixel: String,
    /// Also write a false-colour PNG preview with a scale bar.
    #[arg(long, value_name = "PNG")]
    preview: Option<PathBuf>,
    /// Print a JSON report on stdout.
    #[arg(long)]
    json: bool,
    /// Write a Make-style depfile.
    #[arg(long, value_name = "FILE")]
    depfile: Option<PathBuf>,
    /// Print nothing but errors.
    #[arg(short, long, conflicts_with = "verbose")]
    quiet: bool,
    /// Print the steps.
    #[arg(short, long)]
    verbose: bool,
}

/// Everything parsed and checked before the input is touched.
struct Plan {
    steps: Vec<Step>,
    /// --pixel-size: calibration or resampling target, decided once the file is read.
    pixel_size: Option<(f64, f64)>,
    read: ReadOptions,
}

fn parse_pixel_size(s: &str) -> Result<(f64, f64)> {
    match s.split_once(',') {
        Some((a, b)) => Ok((parse_positive_length(a)?, parse_positive_length(b)?)),
        None => {
            let p = parse_positive_length(s)?;
            Ok((p, p))
        }
    }
}

fn plan(cli: &Cli) -> Result<Plan> {
    let ctx = |flag: &'static str| move |e: Error| e.context(flag);
    let mut steps = Vec::new();
    if let Some(c) = &cli.crop {
        steps.push(Step::Crop(CropSpec::parse(c)?));
    }
    if cli.fill_nonfinite {
        steps.push(Step::FillNonFinite);
    }
    if let Some(l) = &cli.level {
        steps.push(Step::Level(l.parse::<Level>().map_err(ctx("--level"))?));
    }
    if let Some(a) = &cli.align_rows {
        steps.push(Step::AlignRows(
            a.parse::<AlignRows>().map_err(ctx("--align-rows"))?,
        ));
    }
    if cli.remove_scars {
        steps.push(Step::RemoveScars);
    }
    if cli.zero_mean {
        steps.push(Step::ZeroMean);
    }
    if let Some(r) = cli.rotate {
        if r % 90 != 0 {
            return Err(Error::usage(format!("--rotate {r}: use 0, 90, 180 or 270")));
        }
        steps.push(Step::Rotate(r));
    }
    if let Some(f) = &cli.flip {
        steps.push(Step::Flip(f.parse::<FlipAxis>().map_err(ctx("--flip"))?));
    }
    if let Some(r) = &cli.resample_to {
        steps.push(Step::Resample(Target::PixelSize(
            parse_positive_length(r).map_err(ctx("--resample-to"))?,
        )));
    }
    if let Some(s) = &cli.size {
        let (w, h) = parse_size(s).map_err(ctx("--size"))?;
        steps.push(Step::Resample(Target::Size(w, h)));
    }
    steps.sort_by_key(Step::canonical_order);
    let pixel_size = cli
        .pixel_size
        .as_deref()
        .map(parse_pixel_size)
        .transpose()
        .map_err(ctx("--pixel-size"))?;
    let format = cli
        .format
        .as_deref()
        .map(|f| {
            Format::from_name(f)
                .ok_or_else(|| Error::usage(format!("--format {f}: unknown format")))
        })
        .transpose()?;
    let z_range = cli
        .z_range
        .as_deref()
        .map(parse_positive_length)
        .transpose()
        .map_err(ctx("--z-range"))?;
    let z_scale = cli
        .z_scale
        .as_deref()
        .map(parse_positive_length)
        .transpose()
        .map_err(ctx("--z-scale"))?;
    if let Some(o) = &cli.output {
        Kind::from_path(o)?;
        if same_file(o, &cli.input) {
            return Err(Error::usage(format!(
                "{}: the output would overwrite the input",
                o.display()
            )));
        }
    }
    if let Some(p) = &cli.preview {
        let ok = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !ok {
            return Err(Error::usage(format!(
                "--preview {}: the preview is a .png",
                p.display()
            )));
        }
    }
    Ok(Plan {
        steps,
        pixel_size,
        read: ReadOptions {
            format,
            pixel_size: None,
            z_range,
            z_scale,
        },
    })
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
}

/// A channel of an EXR height field (read here: sunbeam-afm leaves EXR to sunbeam-field).
fn read_exr(bytes: &[u8], pixel_size: Option<(f64, f64)>) -> Result<(Vec<Channel>, bool)> {
    let raw = io::exr::decode_raw(bytes)?;
    let (dx, dy, xy_unit, calibrated_by_user) = match (raw.dx, raw.dy, pixel_size) {
        (Some(dx), dy, _) => (dx, dy.unwrap_or(dx), "m", false),
        (None, _, Some((dx, dy))) => (dx, dy, "m", true),
        (None, _, None) => (1.0, 1.0, "", false),
    };
    let z_unit = raw.z_unit.clone().unwrap_or_else(|| "m".into());
    let mut field = HeightField::new(raw.width, raw.height, dx, dy, raw.data)?;
    field.provenance = raw.provenance;
    let name = if field.provenance.channel.is_empty() {
        raw.channel_name
    } else {
        field.provenance.channel.clone()
    };
    Ok((
        vec![Channel {
            name,
            is_height: z_unit == "m",
            z_unit,
            field,
            xy_unit: xy_unit.into(),
            offset: (0.0, 0.0),
        }],
        calibrated_by_user,
    ))
}

/// Read all channels; returns them, the format, and whether --pixel-size served as calibration.
fn read_channels(bytes: &[u8], plan: &Plan) -> Result<(Vec<Channel>, Format, bool)> {
    let format = plan.read.format.or_else(|| sunbeam_afm::detect(bytes));
    if format == Some(Format::Exr) {
        let (c, cal) = read_exr(bytes, plan.pixel_size)?;
        return Ok((c, Format::Exr, cal));
    }
    let fmt = format.unwrap_or(Format::Ascii);
    // XYZ points: the pixel size is the grid the points are sampled onto.
    if fmt == Format::Xyz && plan.pixel_size.is_some() {
        let opts = ReadOptions {
            pixel_size: plan.pixel_size,
            ..plan.read.clone()
        };
        return Ok((sunbeam_afm::read_bytes(bytes, &opts)?, fmt, true));
    }
    match sunbeam_afm::read_bytes(bytes, &plan.read) {
        Ok(c) => Ok((c, fmt, false)),
        Err(e) => match plan.pixel_size {
            // Files without calibration refuse to load without a pixel size.
            Some(p) => {
                let opts = ReadOptions {
                    pixel_size: Some(p),
                    ..plan.read.clone()
                };
                Ok((sunbeam_afm::read_bytes(bytes, &opts)?, fmt, true))
            }
            None => Err(e),
        },
    }
}

/// The channels of the input without processing them. Nanoscope files list
/// from the header alone (so files with damaged data still list).
fn list_infos(bytes: &[u8], plan: &Plan) -> Result<(Vec<ChannelInfo>, Format)> {
    let format = plan.read.format.or_else(|| sunbeam_afm::detect(bytes));
    if format == Some(Format::Exr) {
        let (chans, _) = read_exr(bytes, plan.pixel_size)?;
        let infos = chans
            .iter()
            .enumerate()
            .map(|(index, c)| ChannelInfo::of(index, c, Format::Exr))
            .collect();
        return Ok((infos, Format::Exr));
    }
    let opts = ReadOptions {
        pixel_size: plan.pixel_size,
        ..plan.read.clone()
    };
    let infos = sunbeam_afm::list_channels_bytes(bytes, &opts)?;
    let fmt = infos
        .first()
        .map(|i| i.format)
        .or(format)
        .unwrap_or(Format::Ascii);
    Ok((infos, fmt))
}

fn list(cli: &Cli, chans: &[ChannelInfo], fmt: Format) {
    if cli.json {
        let v: Vec<serde_json::Value> = chans
            .iter()
            .map(|c| {
                serde_json::json!({
                    "index": c.index, "name": c.name, "is_height": c.is_height,
                    "width": c.width, "height": c.height,
                    "size_x": c.size.0, "size_y": c.size.1,
                    "dx": c.size.0 / c.width as f64, "dy": c.size.1 / c.height as f64,
                    "xy_unit": c.xy_unit, "z_unit": c.z_unit, "format": fmt.name(),
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&serde_json::json!({ "file": cli.input, "channels": v }))
                .unwrap_or_default()
        );
    } else {
        println!("{} ({}):", cli.input.display(), fmt.name());
        for c in chans {
            let size = |v: f64| {
                if c.xy_unit == "m" {
                    format_length(v)
                } else {
                    format!("{v} {}", c.xy_unit)
                }
            };
            println!(
                "  {}: {:<24} {}x{} px, {} x {}, z unit {}{}",
                c.index,
                format!("\"{}\"", c.name),
                c.width,
                c.height,
                size(c.size.0),
                size(c.size.1),
                if c.z_unit.is_empty() {
                    "(none)"
                } else {
                    &c.z_unit
                },
                if c.is_height { ", height" } else { "" }
            );
        }
    }
}

/// `synthetic:NAME` -> the preset name, for the built-in synthetic fields.
fn synthetic_name(input: &Path) -> Option<&str> {
    input.to_str()?.strip_prefix("synthetic:")
}

/// A built-in synthetic field (crates/sunbeam-synth) as a one-channel "scan".
fn synthetic(cli: &Cli, name: &str) -> Result<Vec<Channel>> {
    if cli.synthetic_size < 2 || cli.synthetic_size > 8192 {
        return Err(Error::usage(format!(
            "--synthetic-size {}: use 2..8192 pixels",
            cli.synthetic_size
        )));
    }
    let pixel =
        parse_positive_length(&cli.synthetic_pixel).map_err(|e| e.context("--synthetic-pixel"))?;
    let field = sunbeam_synth::preset(name, cli.synthetic_size, pixel)?;
    Ok(vec![Channel {
        name: "Height".into(),
        z_unit: "m".into(),
        is_height: true,
        field,
        xy_unit: "m".into(),
        offset: (0.0, 0.0),
    }])
}

fn run(cli: Cli) -> Result<()> {
    let plan = plan(&cli)?;
    let input = &cli.input;
    let synth = synthetic_name(input);
    let in_file = |e: Error| e.context(input.display());
    let (chans, fmt, calibrated_by_user) = if let Some(name) = synth {
        if plan.read.format.is_some() || plan.read.z_range.is_some() || plan.read.z_scale.is_some()
        {
            return Err(Error::usage(format!(
                "{}: --format, --z-range and --z-scale do not apply to synthetic fields",
                input.display()
            )));
        }
        let chans = synthetic(&cli, name)?;
        if cli.list {
            let c = &chans[0];
            let info = ChannelInfo {
                index: 0,
                name: c.name.clone(),
                z_unit: c.z_unit.clone(),
                xy_unit: c.xy_unit.clone(),
                is_height: true,
                width: c.field.width,
                height: c.field.height,
                size: (c.field.size_x(), c.field.size_y()),
                format: Format::Exr,
            };
            list(&cli, &[info], Format::Exr);
            return Ok(());
        }
        (chans, Format::Exr, false)
    } else {
        let bytes = std::fs::read(input)
            .map_err(|e| Error::input_file(input, format!("cannot read: {e}")))?;
        if cli.list {
            let (infos, fmt) = list_infos(&bytes, &plan).map_err(in_file)?;
            list(&cli, &infos, fmt);
            return Ok(());
        }
        read_channels(&bytes, &plan).map_err(in_file)?
    };
    let ch = sunbeam_afm::select_channel(&chans, cli.channel.as_deref()).map_err(in_file)?;
    // A channel without a z unit: --z-scale (metres per unit) calibrates it.
    let unitless_scale = match (ch.z_unit.is_empty(), plan.read.z_scale) {
        (true, Some(s)) => Some(s),
        _ => None,
    };
    if ch.z_unit != "m" && unitless_scale.is_none() {
        return Err(in_file(Error::input(format!(
            "channel '{}' is in '{}', not metres: not a height field (pick a height channel with --channel, --list shows them; a channel without unit takes --z-scale)",
            ch.name,
            if ch.z_unit.is_empty() { "no unit" } else { &ch.z_unit }
        ))));
    }
    let mut field = ch.field.clone();
    let mut processing = Vec::new();
    if let Some(sc) = unitless_scale {
        field.data.iter_mut().for_each(|v| *v *= sc);
        let d = format!("calibrate z scale {} per unit", format_length(sc));
        field.provenance.processing.push(d.clone());
        processing.push(d);
    }
    let mut steps = plan.steps.clone();
    let pixel_size_role;
    if ch.xy_unit != "m" {
        match plan.pixel_size {
            Some((dx, dy)) => {
                field.dx = dx;
                field.dy = dy;
                pixel_size_role = "calibration";
            }
            None => {
                return Err(in_file(Error::input(format!(
                    "channel '{}' has no lateral calibration (unit '{}'): give --pixel-size",
                    ch.name, ch.xy_unit
                ))))
            }
        }
    } else if let Some((dx, dy)) = plan.pixel_size {
        if calibrated_by_user {
            pixel_size_role = "calibration";
        } else {
            if dx != dy {
                return Err(Error::usage(format!(
                    "--pixel-size {}: the file is calibrated, so --pixel-size resamples, to square pixels: give one length",
                    cli.pixel_size.as_deref().unwrap_or("")
                )));
            }
            if steps.iter().any(|s| matches!(s, Step::Resample(_))) {
                return Err(Error::usage(
                    "the file is calibrated, so --pixel-size would resample; it cannot be combined with --resample-to/--size",
                ));
            }
            steps.push(Step::Resample(Target::PixelSize(dx)));
            pixel_size_role = "resample";
        }
    } else {
        pixel_size_role = "none";
    }
    if pixel_size_role == "calibration" {
        let d = format!(
            "calibrate pixel size {} x {}",
            format_length(field.dx),
            format_length(field.dy)
        );
        field.provenance.processing.push(d.clone());
        processing.push(d);
    }
    let source_format = if synth.is_some() {
        "synthetic"
    } else {
        field.provenance.source_file = input
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        fmt.name()
    };
    field.provenance.source_format = source_format.to_string();
    field.provenance.channel = ch.name.clone();
    if cli.verbose {
        eprintln!(
            "sunbeam-import: {}: {} channel '{}', {}x{} px of {} x {}",
            input.display(),
            source_format,
            ch.name,
            field.width,
            field.height,
            format_length(field.dx),
            format_length(field.dy)
        );
    }
    for step in &steps {
        if let Some(d) = pipeline::apply(&mut field, step).map_err(in_file)? {
            if cli.verbose {
                eprintln!("sunbeam-import: {d}");
            }
            processing.push(d);
        }
    }
    if !cli.quiet && field.count_nonfinite() > 0 {
        eprintln!(
            "sunbeam-import: warning: {} non-finite values kept (use --fill-nonfinite)",
            field.count_nonfinite()
        );
    }
    let output = cli
        .output
        .as_ref()
        .ok_or_else(|| Error::usage("-o/--output is required"))?;
    io::write(output, &field)?;
    if let Some(p) = &cli.preview {
        sunbeam_field::preview::write_png(p, &field)?;
    }
    if let Some(d) = &cli.depfile {
        let mut outs: Vec<&Path> = vec![output.as_path()];
        if let Some(p) = &cli.preview {
            outs.push(p.as_path());
        }
        // A synthetic field depends on no file (only on the tool and its flags).
        let ins: Vec<&Path> = if synth.is_some() {
            vec![]
        } else {
            vec![input.as_path()]
        };
        sunbeam_common::depfile::write(d, &outs, &ins)?;
    }
    let st = Stats::of(&field);
    if cli.json {
        let num = |v: f64| {
            if v.is_finite() {
                serde_json::json!(v)
            } else {
                serde_json::Value::Null
            }
        };
        let report = serde_json::json!({
            "input": input, "output": output, "preview": cli.preview,
            "source_format": source_format, "channel": ch.name,
            "width": field.width, "height": field.height, "dx_m": field.dx, "dy_m": field.dy,
            "size_x_m": field.size_x(), "size_y_m": field.size_y(),
            "z_min_m": num(st.min), "z_max_m": num(st.max), "z_mean_m": num(st.mean), "z_rms_m": num(st.rms),
            "nonfinite": st.nonfinite, "pixel_size_role": pixel_size_role,
            "processing": processing,
        });
        println!(
            "{}",
            serde_json::to_string_pretty(&report).unwrap_or_default()
        );
    } else if !cli.quiet {
        eprintln!(
            "sunbeam-import: wrote {} ({}x{} px of {}, z {} .. {})",
            output.display(),
            field.width,
            field.height,
            format_length(field.dx),
            format_length(st.min),
            format_length(st.max)
        );
    }
    Ok(())
}

fn main() {
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            let code = match e.kind() {
                ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => 0,
                _ => 1,
            };
            let _ = e.print();
            std::process::exit(code);
        }
    };
    sunbeam_common::error::run_main("sunbeam-import", || run(cli))
}
