//! `sunbeam-eval bench`: run time against error. Sweeps basis, error budget
//! (hence term count), storage precision and interpolation taps on the shared
//! snake patches and a synthetic ridge field; the wavelength sample count of
//! the colour integral; and a stress sweep of |t| up to 60. Writes CSV files,
//! a Pareto plot and a markdown summary (stdout).

use crate::plot::{perr, png};
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Instant;
use sunbeam_analysis::compare::{colour_vs, spectral_at, truth_colours, SpectralError};
use sunbeam_common::{output, Error, Result};
use sunbeam_field::HeightField;
use sunbeam_optics::truth::{Params, Truth};
use sunbeam_optics::Model;
use sunbeam_pack::{Basis, BuildOptions, FieldRef, Pack, Precision};

pub struct Options {
    pub snake_dir: Option<PathBuf>,
    pub out_dir: PathBuf,
    pub points: usize,
    pub quick: bool,
}

struct Row {
    field: String,
    basis: Basis,
    max_error: f64,
    precision: Precision,
    taps: usize,
    terms: usize,
    bytes: usize,
    build_ms: f64,
    eval_ns: f64,
    err: SpectralError,
    default: bool,
}

fn basis_name(b: Basis) -> &'static str {
    match b {
        Basis::Chebyshev => "chebyshev",
        Basis::Taylor => "taylor",
    }
}
fn prec_name(p: Precision) -> &'static str {
    match p {
        Precision::F32 => "f32",
        Precision::F16 => "f16",
    }
}

/// A synthetic ridge field like the snake scales (sunbeam-synth): ridges 1.2 um
/// apart, wavy with a 3.1 um wavelength, no roughness), rescaled so that its
/// heights span exactly `0..2H` (the benchmark sets `|t|` through `H`).
pub fn ridge_field(n: usize, dx: f64, half_range: f64) -> Result<HeightField> {
    let mut f = sunbeam_synth::Ridges {
        period: 1.2e-6,
        height: 2.0 * half_range,
        rise: 0.5,
        wave_amplitude: 0.15e-6,
        wave_length: 3.1e-6,
        finger_length: 0.0,
        roughness: 0.0,
        seed: 1,
    }
    .generate("ridge", n, n, dx)?;
    let (lo, hi) = f.finite_range().unwrap_or((0.0, 0.0));
    let scale = if hi > lo {
        2.0 * half_range / (hi - lo)
    } else {
        1.0
    };
    for v in &mut f.data {
        *v = (*v - lo) * scale;
    }
    Ok(f)
}

fn fref(f: &HeightField) -> FieldRef<'_> {
    FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    }
}

fn points(n: usize, seed: u64, min_cos: f64, lambda: (f64, f64)) -> Vec<[f64; 4]> {
    sunbeam_analysis::sample::scatter_points(n, seed, min_cos, f64::INFINITY, lambda)
}

fn build(
    f: &HeightField,
    basis: Basis,
    max_error: f64,
    precision: Precision,
    taps: usize,
) -> Result<(Pack, f64)> {
    let o = BuildOptions {
        basis,
        max_error,
        precision,
        taps,
        ..BuildOptions::default()
    };
    let t0 = Instant::now();
    let p = sunbeam_pack::build(fref(f), &o, &mut |_, _| {})?;
    Ok((p, t0.elapsed().as_secs_f64() * 1e3))
}

/// CPU time per R on one core: the best of 5 runs (the machine is shared).
fn eval_time_ns(p: &Pack, pts: &[[f64; 4]]) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        let mut acc = 0.0;
        for q in pts {
            acc += p.reflectance(q[0], q[1], q[2], q[3]);
        }
        std::hint::black_box(acc);
        best = best.min(t0.elapsed().as_secs_f64() * 1e9 / pts.len().max(1) as f64);
    }
    best
}

fn load_snake(dir: &Path, name: &str, z: f64) -> Result<HeightField> {
    let opts = sunbeam_afm::height::HeightOptions {
        pixel_size: Some((65e-9, 65e-9)),
        z_range: Some(z),
        ..Default::default()
    };
    Ok(sunbeam_afm::height::read_height_field(&dir.join(name), &opts)?.field)
}

pub fn run(o: &Options) -> Result<()> {
    std::fs::create_dir_all(&o.out_dir).map_err(|e| Error::output_file(&o.out_dir, e))?;
    let mut fields: Vec<(String, HeightField)> = Vec::new();
    if let Some(d) = &o.snake_dir {
        fields.push(("elaphe".into(), load_snake(d, "Elaph100x100.png", 375e-9)?));
        fields.push((
            "xenopeltis".into(),
            load_snake(d, "Xeno100x100.png", 443.45e-9)?,
        ));
    }
    fields.push((
        "ridge".into(),
        ridge_field(if o.quick { 64 } else { 128 }, 25e-9, 150e-9)?,
    ));
    let lam = (380e-9, 780e-9);

    let mut rows: Vec<Row> = Vec::new();
    let mut truth_ns = Vec::new();
    let mut colour_rows = Vec::new();
    for (name, f) in &fields {
        let truth = Truth::new(
            f,
            &Params {
                model: Model::Window,
                coherence_m: 65e-6,
            },
        )?;
        let pts = points(o.points, 17, 0.05, lam);
        let t0 = Instant::now();
        let _ = sunbeam_analysis::par_map(1, |_| ());
        let tr: Vec<f64> = pts
            .iter()
            .take(50)
            .map(|q| truth.reflectance(q[0], q[1], q[2], q[3]))
            .collect();
        std::hint::black_box(tr);
        truth_ns.push((name.clone(), t0.elapsed().as_secs_f64() * 1e9 / 50.0));
        let mut configs = Vec::new();
        let budgets: &[f64] = if o.quick {
            &[1e-2, 1e-4]
        } else {
            &[1e-2, 1e-3, 1e-4, 1e-5]
        };
        for basis in [Basis::Chebyshev, Basis::Taylor] {
            for &me in budgets {
                for prec in [Precision::F32, Precision::F16] {
                    configs.push((basis, me, prec, 6usize));
                }
            }
        }
        for taps in [4usize, 8] {
            configs.push((Basis::Chebyshev, 1e-4, Precision::F32, taps));
        }
        for (basis, me, prec, taps) in configs {
            let (p, build_ms) = match build(f, basis, me, prec, taps) {
                Ok(v) => v,
                Err(e) => {
                    eprintln!(
                        "bench: {name} {} {me:e} {}: not built: {e}",
                        basis_name(basis),
                        prec_name(prec)
                    );
                    continue;
                }
            };
            let err = spectral_at(&p, &truth, &pts);
            let eval_ns = eval_time_ns(&p, &pts);
            let bytes = p.manifest.terms
                * p.manifest.layer_texels()
                * if prec == Precision::F32 { 8 } else { 4 };
            rows.push(Row {
                field: name.clone(),
                basis,
                max_error: me,
                precision: prec,
                taps,
                terms: p.manifest.terms,
                bytes,
                build_ms,
                eval_ns,
                err,
                default: basis == Basis::Chebyshev
                    && me == 1e-4
                    && prec == Precision::F32
                    && taps == 6,
            });
        }
        // Wavelength samples of the colour integral (default pack) against 1 nm.
        let (p, _) = build(f, Basis::Chebyshev, 1e-4, Precision::F32, 6)?;
        for light in [
            sunbeam_analysis::sample::dir(60f64.to_radians(), 0.0),
            sunbeam_analysis::sample::dir(30f64.to_radians(), std::f64::consts::FRAC_PI_2),
        ] {
            let tc = truth_colours(&truth, &p, light, if o.quick { 16 } else { 32 });
            for samples in [8usize, 16, 32, 40, 64] {
                let t0 = Instant::now();
                let c = colour_vs(&p, &tc, light, samples, None);
                colour_rows.push((name.clone(), samples, light, c, t0.elapsed().as_secs_f64()));
            }
        }
    }

    // Stress: |t| up to 60 on a small ridge field.
    let mut stress = Vec::new();
    let ts: &[f64] = if o.quick {
        &[5.0, 12.0, 30.0, 60.0]
    } else {
        &[1.0, 5.0, 9.0, 12.0, 20.0, 30.0, 45.0, 60.0]
    };
    for &t in ts {
        let h = t * 380e-9 / (4.0 * std::f64::consts::PI);
        let f = ridge_field(48, 25e-9, h)?;
        let truth = Truth::new(
            &f,
            &Params {
                model: Model::Window,
                coherence_m: 65e-6,
            },
        )?;
        let pts = points(o.points.min(300), 23, 0.8, (380e-9, 480e-9));
        for basis in [Basis::Chebyshev, Basis::Taylor] {
            for prec in [Precision::F32, Precision::F16] {
                match build(&f, basis, 1e-4, prec, 6) {
                    Ok((p, _)) => {
                        let e = spectral_at(&p, &truth, &pts);
                        stress.push((
                            t,
                            basis,
                            prec,
                            Some((
                                p.manifest.terms,
                                p.manifest.error.series_bound,
                                p.manifest.error.f32_rounding_estimate,
                                e,
                            )),
                            String::new(),
                        ));
                    }
                    Err(e) => stress.push((t, basis, prec, None, e.message)),
                }
            }
        }
    }

    // CSV files.
    let mut csv = String::from(
        "field,basis,max_error,precision,taps,terms,bytes,build_ms,eval_ns_per_R,max_abs_dR,peak_rel,strong_rel,default\n",
    );
    for r in &rows {
        csv.push_str(&format!(
            "{},{},{:e},{},{},{},{},{:.2},{:.1},{:e},{:e},{:e},{}\n",
            r.field,
            basis_name(r.basis),
            r.max_error,
            prec_name(r.precision),
            r.taps,
            r.terms,
            r.bytes,
            r.build_ms,
            r.eval_ns,
            r.err.max_abs,
            r.err.peak_relative,
            r.err.strong_relative,
            r.default
        ));
    }
    output::write_atomic(&o.out_dir.join("bench.csv"), csv.as_bytes())?;
    let mut ccsv = String::from(
        "field,lambda_samples,light_theta_deg,light_phi_deg,de_mean,de_p99,de_max,seconds\n",
    );
    for (name, s, l, c, secs) in &colour_rows {
        ccsv.push_str(&format!(
            "{name},{s},{:.1},{:.1},{:.4},{:.4},{:.4},{:.3}\n",
            l[2].acos().to_degrees(),
            l[1].atan2(l[0]).to_degrees(),
            c.mean,
            c.p99,
            c.max,
            secs
        ));
    }
    output::write_atomic(&o.out_dir.join("colour.csv"), ccsv.as_bytes())?;
    let mut scsv = String::from(
        "t_max,basis,precision,terms,series_bound,f32_rounding_estimate,max_abs_dR,peak_rel,note\n",
    );
    for (t, b, p, r, note) in &stress {
        match r {
            Some((n, sb, fr, e)) => scsv.push_str(&format!(
                "{t},{},{},{n},{sb:e},{fr:e},{:e},{:e},\n",
                basis_name(*b),
                prec_name(*p),
                e.max_abs,
                e.peak_relative
            )),
            None => scsv.push_str(&format!(
                "{t},{},{},,,,,,\"{}\"\n",
                basis_name(*b),
                prec_name(*p),
                note.replace('"', "'")
            )),
        }
    }
    output::write_atomic(&o.out_dir.join("stress.csv"), scsv.as_bytes())?;
    pareto_plot(&o.out_dir.join("pareto.png"), &rows)?;

    // Markdown summary.
    println!(
        "### Run time against error (window model, {} random points per field)\n",
        o.points
    );
    println!("| field | basis | budget | precision | taps | terms | MiB | build ms | eval ns/R | max abs dR | peak-rel | default |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!(
            "| {} | {} | {:.0e} | {} | {} | {} | {:.2} | {:.1} | {:.0} | {:.2e} | {:.2e} | {} |",
            r.field,
            basis_name(r.basis),
            r.max_error,
            prec_name(r.precision),
            r.taps,
            r.terms,
            r.bytes as f64 / (1 << 20) as f64,
            r.build_ms,
            r.eval_ns,
            r.err.max_abs,
            r.err.peak_relative,
            if r.default { "**default**" } else { "" }
        );
    }
    println!("\nGround truth (float64 direct sum) per R, for scale:");
    for (n, ns) in &truth_ns {
        println!("- {n}: {:.0} ns per R", ns);
    }
    println!("\n### Colour: wavelength samples against the 1 nm integral (CIEDE2000 over view directions)\n");
    println!("| field | samples | light (theta, phi) | mean dE00 | p99 dE00 | max dE00 |");
    println!("|---|---|---|---|---|---|");
    for (name, s, l, c, _) in &colour_rows {
        println!(
            "| {name} | {s} | ({:.0}, {:.0}) | {:.3} | {:.3} | {:.3} |",
            l[2].acos().to_degrees(),
            l[1].atan2(l[0]).to_degrees(),
            c.mean,
            c.p99,
            c.max
        );
    }
    println!("\n### Stress: |t| up to 60 (ridge field, views within 37 deg of the normal, 380-480 nm, budget 1e-4)\n");
    println!("| t_max | basis | precision | terms | series bound | f32 rounding est. | max abs dR | peak-rel | note |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for (t, b, p, r, note) in &stress {
        match r {
            Some((n, sb, fr, e)) => println!(
                "| {t} | {} | {} | {n} | {sb:.1e} | {fr:.1e} | {:.2e} | {:.2e} | |",
                basis_name(*b),
                prec_name(*p),
                e.max_abs,
                e.peak_relative
            ),
            None => println!(
                "| {t} | {} | {} | - | - | - | - | - | refused: {} |",
                basis_name(*b),
                prec_name(*p),
                note
            ),
        }
    }
    Ok(())
}

fn pareto_plot(path: &Path, rows: &[Row]) -> Result<()> {
    let xs: Vec<f64> = rows.iter().map(|r| r.eval_ns.max(1.0)).collect();
    let ys: Vec<f64> = rows
        .iter()
        .map(|r| r.err.max_abs.clamp(1e-9, 10.0))
        .collect();
    if xs.is_empty() {
        return Ok(());
    }
    let (x0, x1) = (0.0, xs.iter().copied().fold(0.0, f64::max) * 1.1);
    let (y0, y1) = (
        ys.iter().copied().fold(f64::INFINITY, f64::min) / 3.0,
        ys.iter().copied().fold(0.0, f64::max) * 3.0,
    );
    // Pareto front over all rows: no other row is both faster and more accurate.
    let mut idx: Vec<usize> = (0..rows.len()).collect();
    idx.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in idx {
        if ys[i] < best {
            best = ys[i];
            front.push((xs[i], ys[i]));
        }
    }
    png(path, 1100, 720, |root| {
        let mut ch = ChartBuilder::on(root)
            .caption(
                "Pack evaluation: run time against error (window model, all fields)",
                ("sans-serif", 22),
            )
            .margin(16)
            .x_label_area_size(54)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(perr)?;
        ch.configure_mesh()
            .x_desc("CPU evaluation time per R (ns, one core)")
            .y_desc("max |R_pack - R_truth|")
            .label_style(("sans-serif", 15))
            .axis_desc_style(("sans-serif", 17))
            .x_labels(10)
            .x_label_formatter(&|v| format!("{:.0}", v))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(perr)?;
        let groups = [
            (Basis::Chebyshev, Precision::F32, BLUE, "Chebyshev f32"),
            (Basis::Chebyshev, Precision::F16, CYAN, "Chebyshev f16"),
            (Basis::Taylor, Precision::F32, RED, "Taylor f32"),
            (Basis::Taylor, Precision::F16, MAGENTA, "Taylor f16"),
        ];
        for (b, p, col, label) in groups {
            let pts: Vec<(f64, f64)> = rows
                .iter()
                .enumerate()
                .filter(|(_, r)| r.basis == b && r.precision == p)
                .map(|(i, _)| (xs[i], ys[i]))
                .collect();
            ch.draw_series(pts.iter().map(|&q| TriangleMarker::new(q, 7, col.filled())))
                .map_err(perr)?
                .label(label)
                .legend(move |(x, y)| TriangleMarker::new((x + 8, y), 6, col.filled()));
        }
        ch.draw_series(LineSeries::new(front.clone(), BLACK.stroke_width(2)))
            .map_err(perr)?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        ch.draw_series(
            rows.iter()
                .enumerate()
                .filter(|(_, r)| r.default)
                .map(|(i, _)| Circle::new((xs[i], ys[i]), 12, GREEN.stroke_width(3))),
        )
        .map_err(perr)?
        .label("default (Chebyshev, 1e-4, f32, 6 taps)")
        .legend(|(x, y)| Circle::new((x + 8, y), 7, GREEN.stroke_width(3)));
        ch.configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(perr)?;
        Ok(())
    })
}
