//! sunbeam-eval: ground truth, error and run-time benchmarks, the thesis'
//! grating check, and BRDF pictures (docs/EVAL.md).

mod grating;
mod grating_plot;
mod input;
mod packinfo;
mod plot;
mod probe;
mod render;
mod source;

use clap::{Parser, Subcommand};
use serde_json::json;
use source::{Source, TruthArgs};
use std::path::PathBuf;
use sunbeam_common::{units, Error, Result};

#[derive(Parser)]
#[command(name = "sunbeam-eval", version, about = "Ground truth, errors, grating check and BRDF pictures for Sunbeam packs")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
    /// Less output.
    #[arg(short, long, global = true)]
    quiet: bool,
    /// More output.
    #[arg(short, long, global = true)]
    verbose: bool,
}

#[derive(Subcommand)]
enum Cmd {
    /// R(u, v, w, lambda) at the points of a CSV file, one value per line on stdout (docs/EVAL.md).
    Probe(ProbeArgs),
    /// The thesis' grating evaluation: peak viewing angle per wavelength and the period.
    Grating(GratingArgs),
    /// The CPU reference image of a scene (needs sunbeam-raster).
    Render(RenderArgs),
}

#[derive(clap::Args)]
struct ProbeArgs {
    /// A pack (KTX2/EXR) or a height field (anything sunbeam-import reads).
    input: PathBuf,
    /// Points, one `u,v,w,lambda_m` per line.
    #[arg(long, value_name = "FILE.csv")]
    points: PathBuf,
    /// Ground truth of PHYSICS.md 2 (implied for a height field; refused for a pack).
    #[arg(long)]
    truth: bool,
    #[command(flatten)]
    heights: input::HeightArgs,
    #[command(flatten)]
    model: TruthArgs,
}

#[derive(clap::Args)]
struct GratingArgs {
    /// A height field or a pack.
    input: PathBuf,
    /// Incidence angle in the plane of incidence.
    #[arg(long, default_value = "75deg", allow_hyphen_values = true)]
    theta_i: String,
    /// Azimuth of the plane of incidence from the patch's +x axis.
    #[arg(long, default_value = "0deg", allow_hyphen_values = true)]
    azimuth: String,
    /// Wavelength range.
    #[arg(long, default_value = "380nm..780nm")]
    lambda: String,
    /// Wavelength step.
    #[arg(long, default_value = "10nm")]
    lambda_step: String,
    /// Viewing-angle step of the scan (peaks are then refined on the continuous R).
    #[arg(long, default_value = "0.1deg")]
    angle_step: String,
    /// Diffraction order assumed for the peaks.
    #[arg(long, default_value_t = 1, allow_hyphen_values = true)]
    order: i32,
    /// Ignore peaks whose period (1/|f|) is longer than this (default: outside the specular lobe).
    #[arg(long, value_name = "LEN")]
    max_period: Option<String>,
    /// Replicate the height field NxM times first (a periodic patch seen by a wider window).
    #[arg(long, value_name = "NxM")]
    tile: Option<String>,
    /// The true period, if known: drawn in the plot and compared in the report.
    #[arg(long, value_name = "LEN")]
    true_period: Option<String>,
    /// Write the plot of peaks against the grating equation.
    #[arg(long, value_name = "OUT.png")]
    plot: Option<PathBuf>,
    /// Write the response R over (wavelength, angle) as CSV.
    #[arg(long, value_name = "OUT.csv")]
    csv: Option<PathBuf>,
    /// Machine-readable report on stdout.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    heights: input::HeightArgs,
    #[command(flatten)]
    model: TruthArgs,
}

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene JSON.
    scene: Option<PathBuf>,
    #[arg(short, long)]
    output: Option<PathBuf>,
    #[arg(long)]
    mesh: Option<PathBuf>,
    #[arg(long)]
    pack: Option<PathBuf>,
    #[arg(long)]
    size: Option<String>,
}

fn main() {
    sunbeam_common::error::run_main("sunbeam-eval", || {
        let cli = match Cli::try_parse() {
            Ok(c) => c,
            Err(e) => {
                use clap::error::ErrorKind;
                if matches!(e.kind(), ErrorKind::DisplayHelp | ErrorKind::DisplayVersion) {
                    print!("{e}");
                    return Ok(());
                }
                return Err(Error::usage(e.to_string().trim_end().to_string()));
            }
        };
        match cli.cmd {
            Cmd::Probe(a) => {
                let src = Source::open(&a.input, &a.heights, &a.model, a.truth)?;
                probe::run(&src, &a.points)
            }
            Cmd::Grating(a) => grating_cmd(a, cli.quiet),
            Cmd::Render(a) => render::run(&a),
        }
    })
}

fn grating_cmd(a: GratingArgs, quiet: bool) -> Result<()> {
    let theta_i = units::parse_angle(&a.theta_i)?;
    let azimuth = units::parse_angle(&a.azimuth)?;
    let (lmin, lmax) = units::parse_length_range(&a.lambda)?;
    let lstep = units::parse_positive_length(&a.lambda_step)?;
    let astep = units::parse_angle(&a.angle_step)?;
    let max_period = a.max_period.as_deref().map(units::parse_positive_length).transpose()?;
    let true_period = a.true_period.as_deref().map(units::parse_positive_length).transpose()?;
    let src = if input::is_pack(&a.input)? {
        if a.tile.is_some() {
            return Err(Error::usage("--tile applies to height fields, not packs"));
        }
        Source::open(&a.input, &a.heights, &a.model, false)?
    } else {
        let mut f = input::read_height(&a.input, &a.heights)?;
        if let Some(t) = &a.tile {
            let (nx, ny) = input::parse_tile(t)?;
            f = input::tile(&f, nx, ny)?;
        }
        Source::from_field(f, &a.model.params()?).map_err(|e| e.context(a.input.display()))?
    };
    let opts = grating::Options {
        theta_i,
        azimuth,
        lambda_min: lmin,
        lambda_max: lmax,
        lambda_step: lstep,
        angle_step: astep,
        order: a.order,
        min_frequency: max_period.map(|d| 1.0 / d),
    };
    let out = grating::run(&src, &opts)?;
    if let Some(p) = &a.csv {
        let mut s = String::from("lambda_m,theta_r_deg,R\n");
        for (li, row) in out.response.iter().enumerate() {
            for (j, r) in row.iter().enumerate() {
                s.push_str(&format!("{:e},{},{:e}\n", out.lambdas[li], out.angles_deg[j], r));
            }
        }
        sunbeam_common::output::write_atomic(p, s.as_bytes())?;
    }
    let name = a.input.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if let Some(p) = &a.plot {
        let title = format!(
            "{name}: {} {} model, theta_i = {:.1} deg: d = {:.2} nm",
            src.kind(),
            src.model_name(),
            theta_i.to_degrees(),
            out.period_m * 1e9
        );
        grating_plot::draw(p, &out, theta_i, a.order, &title, true_period)?;
    }
    let rel = true_period.map(|d| (out.period_m - d) / d);
    if a.json {
        let report = json!({
            "input": name,
            "source": src.kind(),
            "model": src.model_name(),
            "theta_i_deg": theta_i.to_degrees(),
            "azimuth_deg": azimuth.to_degrees(),
            "order": a.order,
            "period_m": out.period_m,
            "period_mean_m": out.period_mean_m,
            "period_std_m": out.period_std_m,
            "true_period_m": true_period,
            "relative_error": rel,
            "min_frequency_per_m": out.min_frequency,
            "patch_m": [src.patch_size().0, src.patch_size().1],
            "peaks": out.peaks.iter().map(|p| json!([p.lambda_m, p.theta_r_deg])).collect::<Vec<_>>(),
            "peak_r": out.peaks.iter().map(|p| p.r).collect::<Vec<_>>(),
            "peak_f_per_m": out.peaks.iter().map(|p| p.f).collect::<Vec<_>>(),
        });
        println!("{report}");
    } else if !quiet {
        println!(
            "{name}: period {:.3} nm (least squares over {} wavelengths; mean {:.3} nm, sd {:.3} nm){}",
            out.period_m * 1e9,
            out.peaks.len(),
            out.period_mean_m * 1e9,
            out.period_std_m * 1e9,
            rel.map(|r| format!(", {:+.4} % from the true period", r * 100.0)).unwrap_or_default()
        );
    }
    Ok(())
}
