//! What each subcommand of sunbeam-eval does with its parsed arguments.

use crate::args::*;
use crate::{bench, brdf, diff, grating_plot, input, probe, render, sheet};
use serde_json::json;

use sunbeam_analysis::{compare, grating, sample, Source};
use sunbeam_common::{Error, Result};

pub(crate) fn run(cli: Cli) -> Result<()> {
    match cli.cmd {
        Cmd::Probe(a) => {
            let src = Source::open(&a.input, &a.heights.options(), &a.model.params()?, a.truth)?;
            probe::run(&src, &a.points)
        }
        Cmd::Grating(a) => grating_cmd(a, cli.quiet),
        Cmd::Compare(a) => compare_cmd(a),
        Cmd::Brdf(a) => brdf_cmd(a),
        Cmd::Bench(a) => {
            let snake = a.snake.clone().or_else(|| {
                sunbeam_common::testdata::shared_data()
                    .map(|d| d.join("snake"))
                    .filter(|d| d.is_dir())
            });
            bench::run(&bench::Options {
                snake_dir: snake,
                out_dir: a.output,
                points: a.points.max(10),
                quick: a.quick,
            })
        }
        Cmd::Render(a) => render::run(&a, cli.quiet),
        Cmd::Sheet(a) => sheet::run(&a.output, &a.inputs, a.columns),
        Cmd::Diff(a) => diff::run(
            &a.image,
            &a.reference,
            a.heatmap.as_deref(),
            a.mask.as_deref(),
            a.scale,
            a.json,
        ),
    }
}

fn grating_cmd(a: GratingArgs, quiet: bool) -> Result<()> {
    let (theta_i, azimuth) = (a.theta_i, a.azimuth);
    let (lmin, lmax) = a.lambda;
    let lstep = a.lambda_step;
    let astep = a.angle_step;
    let (max_period, true_period) = (a.max_period, a.true_period);
    let params = a.model.params()?;
    let src = if input::is_pack(&a.input)? {
        if a.tile.is_some() {
            return Err(Error::usage("--tile applies to height fields, not packs"));
        }
        Source::open(&a.input, &a.heights.options(), &a.model.params()?, false)?
    } else {
        let mut f = input::read_height(&a.input, &a.heights)?;
        if let Some((nx, ny)) = a.tile {
            f = sunbeam_field::geom::tile(&f, nx, ny)?;
        }
        Source::from_field(f, &params).map_err(|e| e.context(a.input.display()))?
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
                s.push_str(&format!(
                    "{:e},{},{:e}\n",
                    out.lambdas[li], out.angles_deg[j], r
                ));
            }
        }
        sunbeam_common::output::write_atomic(p, s.as_bytes())?;
    }
    let name = a
        .input
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
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
    if !out.orders.found && !quiet {
        eprintln!("sunbeam-eval: grating: {name}: {}", out.orders.note);
    }
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
            "peak_order": out.peaks.iter().map(|p| p.order).collect::<Vec<_>>(),
            "peak_brightest": out.peaks.iter().map(|p| p.brightest).collect::<Vec<_>>(),
            "peak_in_fit": out.peaks.iter().map(|p| p.in_fit).collect::<Vec<_>>(),
            "orders_found": out.orders.found,
            "orders_note": out.orders.note,
            "fundamental_f_per_m": out.orders.f0,
        });
        println!("{report}");
    } else if !quiet {
        println!(
            "{name}: period {:.3} nm (least squares over {} peaks at {} wavelengths; mean {:.3} nm, sd {:.3} nm; {}){}",
            out.period_m * 1e9,
            out.peaks.iter().filter(|p| p.in_fit).count(),
            out.peaks.iter().filter(|p| p.brightest).count(),
            out.period_mean_m * 1e9,
            out.period_std_m * 1e9,
            out.orders.note,
            rel.map(|r| format!(", {:+.4} % from the true period", r * 100.0)).unwrap_or_default()
        );
    }
    Ok(())
}

fn compare_cmd(a: CompareArgs) -> Result<()> {
    use sunbeam_optics::truth::{Params, Truth};
    if a.points == 0 || a.views == 0 || a.lambda_samples == 0 {
        return Err(Error::usage(
            "--points, --views and --lambda-samples must be positive",
        ));
    }
    let mut lights = a.light.clone();
    if lights.is_empty() {
        for (t, p) in [
            (0.0, 0.0),
            (30.0, 0.0),
            (60.0, 0.0),
            (75.0, 0.0),
            (60.0, 90.0),
        ] {
            lights.push(sample::dir(f64::to_radians(t), f64::to_radians(p)));
        }
    }
    let pack = sunbeam_pack::Pack::read(&a.pack)?;
    let field = input::read_height(&a.height, &a.heights)?;
    let m = &pack.manifest;
    if field.width != m.patch.width || field.height != m.patch.height {
        return Err(Error::input_file(
            &a.height,
            format!(
                "height field is {}x{} but the pack was built from {}x{} pixels",
                field.width, field.height, m.patch.width, m.patch.height
            ),
        ));
    }
    let model = m.model;
    let truth = Truth::new(
        &field,
        &Params {
            model,
            coherence_m: m.coherence_m,
        },
    )
    .map_err(|e| e.context(a.height.display()))?;
    let spec = compare::spectral(&pack, &truth, a.points, 1);
    let cols: Vec<compare::ColourError> = lights
        .iter()
        .map(|l| compare::colour(&pack, &truth, *l, a.views, a.lambda_samples, None))
        .collect();
    let mean = cols.iter().map(|c| c.mean).sum::<f64>() / cols.len() as f64;
    let p99 = cols.iter().map(|c| c.p99).fold(0.0, f64::max);
    let pass = spec.max_abs <= a.tolerance && p99 <= a.de_tolerance;
    if a.json {
        let report = json!({
            "pack": a.pack.file_name().map(|n| n.to_string_lossy().into_owned()),
            "height": a.height.file_name().map(|n| n.to_string_lossy().into_owned()),
            "model": format!("{model}"),
            "spectral": {
                "points": spec.points,
                "max_abs_dR": spec.max_abs,
                "peak_relative": spec.peak_relative,
                "strong_relative": spec.strong_relative,
                "worst_point": spec.worst,
            },
            "colour": {
                "lambda_samples": a.lambda_samples,
                "views_per_light": a.views,
                "de_mean": mean,
                "de_p99": p99,
                "lights": cols.iter().map(|c| json!({
                    "light": c.light, "exposure_scale": c.exposure_scale,
                    "de_mean": c.mean, "de_p99": c.p99, "de_max": c.max
                })).collect::<Vec<_>>(),
            },
            "tolerance": a.tolerance,
            "de_tolerance": a.de_tolerance,
            "pass": pass,
        });
        println!("{report}");
    } else {
        println!(
            "spectral: max |dR| {:.3e}, peak-relative {:.3e}, strong lobes {:.3e} ({} points)",
            spec.max_abs, spec.peak_relative, spec.strong_relative, spec.points
        );
        for c in &cols {
            println!(
                "colour, light ({:.0} deg, {:.0} deg): dE00 mean {:.3}, p99 {:.3}, max {:.3}",
                c.light[2].acos().to_degrees(),
                c.light[1].atan2(c.light[0]).to_degrees(),
                c.mean,
                c.p99,
                c.max
            );
        }
        println!("{}", if pass { "PASS" } else { "FAIL" });
    }
    if !pass {
        // Exit 5 (docs/EVAL.md), printed as `sunbeam-eval: compare: ...`.
        return Err(Error::check_failed(format!(
            "compare: above tolerance (max |dR| {:.3e} vs {:.1e}, p99 dE00 {:.3} vs {:.2})",
            spec.max_abs, a.tolerance, p99, a.de_tolerance
        )));
    }
    Ok(())
}

fn brdf_cmd(a: BrdfArgs) -> Result<()> {
    use sunbeam_optics::colour::ToneMap;
    let light = a.light;
    if !(16..=2048).contains(&a.size) || a.lambda_samples == 0 {
        return Err(Error::usage(
            "--size must be 16..2048 and --lambda-samples positive",
        ));
    }
    let curve = a.tone;
    let pack = sunbeam_pack::Pack::read(&a.pack)?;
    let title = a
        .pack
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let o = brdf::Options {
        light,
        size: a.size,
        lambda_samples: a.lambda_samples,
        exposure_ev: a.exposure,
        tone: ToneMap {
            exposure_ev: 0.0,
            curve,
        },
        title,
    };
    let out = brdf::run(&pack, &o, &a.output)?;
    if a.json {
        println!(
            "{}",
            json!({"output": a.output.display().to_string(), "exposure_ev": out.exposure_ev, "max_y": out.max_y})
        );
    }
    Ok(())
}
