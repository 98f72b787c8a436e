//! What sunbeam-import does with its parsed arguments.

use crate::args::*;
use std::path::Path;
use sunbeam_afm::height::{self, HeightOptions};
use sunbeam_afm::{Channel, ChannelInfo, Format};
use sunbeam_common::cli::PixelSize;
use sunbeam_common::units::format_length;
use sunbeam_common::{Error, Result};
use sunbeam_field::io::{self, Kind};
use sunbeam_field::pipeline::{self, Step};
use sunbeam_field::resample::Target;
use sunbeam_field::stats::Stats;

/// Everything parsed and checked before the input is touched.
struct Plan {
    steps: Vec<Step>,
    /// How the input is read (the one reader, sunbeam_afm::height); its
    /// --pixel-size is calibration or a resampling target, decided once the file is read.
    read: HeightOptions,
}

fn plan(cli: &Cli) -> Result<Plan> {
    let mut steps = Vec::new();
    if let Some(c) = cli.crop {
        steps.push(Step::Crop(c));
    }
    if cli.fill_nonfinite {
        steps.push(Step::FillNonFinite);
    }
    if let Some(l) = cli.level {
        steps.push(Step::Level(l));
    }
    if let Some(a) = cli.align_rows {
        steps.push(Step::AlignRows(a));
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
    if let Some(f) = cli.flip {
        steps.push(Step::Flip(f));
    }
    if let Some(r) = cli.resample_to {
        steps.push(Step::Resample(Target::PixelSize(r)));
    }
    if let Some((w, h)) = cli.size {
        steps.push(Step::Resample(Target::Size(w, h)));
    }
    steps.sort_by_key(Step::canonical_order);
    let format = cli.format;
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
        read: HeightOptions {
            format,
            channel: cli.channel.clone(),
            pixel_size: cli.pixel_size.map(PixelSize::pair),
            z_range: cli.z_range,
            z_scale: cli.z_scale,
            fill_nonfinite: cli.fill_nonfinite,
            allow_implausible: cli.allow_implausible,
        },
    })
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => a == b,
    }
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
    let field = sunbeam_synth::preset(name, cli.synthetic_size, cli.synthetic_pixel)?;
    Ok(vec![Channel {
        name: "Height".into(),
        z_unit: "m".into(),
        is_height: true,
        field,
        xy_unit: "m".into(),
        offset: (0.0, 0.0),
    }])
}

pub(crate) fn run(cli: Cli) -> Result<()> {
    let plan = plan(&cli)?;
    let input = &cli.input;
    let synth = synthetic_name(input);
    let in_file = |e: Error| e.context(input.display());
    let read = if let Some(name) = synth {
        if plan.read.format.is_some() || plan.read.z_range.is_some() || plan.read.z_scale.is_some()
        {
            return Err(Error::usage(format!(
                "{}: --format, --z-range and --z-scale do not apply to synthetic fields",
                input.display()
            )));
        }
        let chans = synthetic(&cli, name)?;
        if cli.list {
            let info = ChannelInfo::of(0, &chans[0], Format::Exr);
            list(&cli, &[info], Format::Exr);
            return Ok(());
        }
        height::from_channels(&chans, Format::Exr, false, &plan.read).map_err(in_file)?
    } else {
        let bytes = std::fs::read(input)
            .map_err(|e| Error::input_file(input, format!("cannot read: {e}")))?;
        if cli.list {
            let (infos, fmt) = height::list(&bytes, &plan.read).map_err(in_file)?;
            list(&cli, &infos, fmt);
            return Ok(());
        }
        height::read_height_bytes(&bytes, &plan.read).map_err(in_file)?
    };
    let (mut field, fmt, channel) = (read.field, read.format, read.channel);
    let mut processing = read.processing;
    let mut steps = plan.steps.clone();
    let pixel_size_role = match cli.pixel_size {
        _ if read.pixel_size_calibrated => "calibration",
        // A calibrated file: --pixel-size resamples.
        Some(p) => {
            if p.dx != p.dy {
                return Err(Error::usage(format!(
                    "--pixel-size {p}: the file is calibrated, so --pixel-size resamples, to square pixels: give one length"
                )));
            }
            if steps.iter().any(|s| matches!(s, Step::Resample(_))) {
                return Err(Error::usage(
                    "the file is calibrated, so --pixel-size would resample; it cannot be combined with --resample-to/--size",
                ));
            }
            steps.push(Step::Resample(Target::PixelSize(p.dx)));
            "resample"
        }
        None => "none",
    };
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
    field.provenance.channel = channel.clone();
    if cli.verbose {
        eprintln!(
            "sunbeam-import: {}: {} channel '{}', {}x{} px of {} x {}",
            input.display(),
            source_format,
            channel,
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
            "source_format": source_format, "channel": channel,
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
