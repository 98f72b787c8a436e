//! The grating figure: response over (viewing angle, wavelength), peaks, and
//! the grating equation for the estimated (and, if given, the true) period.

use crate::plot::{perr, png, viridis};
use plotters::prelude::*;
use std::path::Path;
use sunbeam_analysis::grating::{grating_angle_deg, Outcome};
use sunbeam_common::Result;

pub fn draw(
    path: &Path,
    out: &Outcome,
    theta_i: f64,
    order: i32,
    title: &str,
    true_period: Option<f64>,
) -> Result<()> {
    let lmin = out.lambdas[0] * 1e9;
    let lmax = *out.lambdas.last().unwrap_or(&out.lambdas[0]) * 1e9;
    let dl = if out.lambdas.len() > 1 {
        (out.lambdas[1] - out.lambdas[0]) * 1e9
    } else {
        10.0
    };
    let (y0, y1) = (lmin - 0.5 * dl, lmax + 0.5 * dl);
    // Angle range: around the peaks and the specular direction, rounded to 5 degrees.
    let spec = -theta_i.to_degrees();
    let mut amin = spec;
    let mut amax = spec;
    for p in &out.peaks {
        amin = amin.min(p.theta_r_deg);
        amax = amax.max(p.theta_r_deg);
    }
    let x0 = ((amin - 10.0) / 5.0).floor() * 5.0;
    let x1 = ((amax + 10.0) / 5.0).ceil() * 5.0;
    let (x0, x1) = (x0.max(-90.0), x1.min(90.0));
    png(path, 1100, 760, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, ("sans-serif", 24))
            .margin(16)
            .x_label_area_size(54)
            .y_label_area_size(72)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(perr)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("viewing angle theta_r (deg, signed; specular at -theta_i)")
            .y_desc("wavelength (nm)")
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .draw()
            .map_err(perr)?;
        // Heat map: R per wavelength normalised by the peak R of that row (square-root scale).
        let da = if out.angles_deg.len() > 1 {
            out.angles_deg[1] - out.angles_deg[0]
        } else {
            0.1
        };
        let bin = (0.25f64).max(da);
        let mut cells = Vec::new();
        for (li, row) in out.response.iter().enumerate() {
            let lam = out.lambdas[li] * 1e9;
            let norm = out
                .peaks
                .iter()
                .filter(|p| (p.lambda_m * 1e9 - lam).abs() < 1e-6)
                .map(|p| p.r)
                .fold(0.0, f64::max);
            if norm <= 0.0 {
                continue;
            }
            let mut a = x0;
            while a < x1 {
                let mut mx: f64 = 0.0;
                for (j, &r) in row.iter().enumerate() {
                    let ang = out.angles_deg[j];
                    if ang >= a && ang < a + bin {
                        mx = mx.max(r);
                    }
                }
                let t = (mx / norm).clamp(0.0, 1.0).sqrt();
                cells.push(Rectangle::new(
                    [(a, lam - 0.5 * dl), (a + bin, lam + 0.5 * dl)],
                    viridis(t).filled(),
                ));
                a += bin;
            }
        }
        chart.draw_series(cells).map_err(perr)?;
        // Grating equation for the estimated period, one curve per order seen
        // (or the assumed order), labelled with its order at the short-wavelength end.
        let curve = |d: f64, m: i32| -> Vec<(f64, f64)> {
            let mut v = Vec::new();
            let steps = 400;
            for i in 0..=steps {
                let l = (y0 + (y1 - y0) * i as f64 / steps as f64) * 1e-9;
                if let Some(a) = grating_angle_deg(theta_i, m, l, d) {
                    if a >= x0 && a <= x1 {
                        v.push((a, l * 1e9));
                    }
                }
            }
            v
        };
        let mut orders: Vec<i32> = out
            .peaks
            .iter()
            .map(|p| p.order)
            .filter(|&m| m != 0)
            .collect();
        orders.sort();
        orders.dedup();
        if orders.is_empty() {
            orders.push(order);
        }
        let est = out.period_m;
        let what = if out.orders.found {
            "orders found"
        } else {
            "order assumed"
        };
        for (i, &m) in orders.iter().enumerate() {
            let c = curve(est, m);
            let s = chart
                .draw_series(LineSeries::new(c.clone(), RED.stroke_width(2)))
                .map_err(perr)?;
            if i == 0 {
                s.label(format!(
                    "grating equation, d = {:.2} nm (estimated; {what}: m = {})",
                    est * 1e9,
                    orders
                        .iter()
                        .map(|m| m.to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], RED.stroke_width(2)));
            }
            if let Some(&(a, l)) = c.first() {
                chart
                    .draw_series(std::iter::once(Text::new(
                        format!("m={m}"),
                        (a, l),
                        ("sans-serif", 16).into_font().color(&RED),
                    )))
                    .map_err(perr)?;
            }
        }
        if let Some(d) = true_period {
            for (i, &m) in orders.iter().enumerate() {
                let s = chart
                    .draw_series(DashedLineSeries::new(
                        curve(d, m),
                        8,
                        6,
                        WHITE.stroke_width(1),
                    ))
                    .map_err(perr)?;
                if i == 0 {
                    s.label(format!("grating equation, d = {:.2} nm (true)", d * 1e9))
                        .legend(|(x, y)| {
                            PathElement::new(vec![(x, y), (x + 24, y)], BLACK.stroke_width(2))
                        });
                }
            }
        }
        chart
            .draw_series(
                out.peaks.iter().filter(|p| p.order != 0).map(|p| {
                    Cross::new((p.theta_r_deg, p.lambda_m * 1e9), 5, WHITE.stroke_width(2))
                }),
            )
            .map_err(perr)?
            .label("peaks of R with an order (on the m curves)")
            .legend(|(x, y)| Cross::new((x + 12, y), 5, BLACK.stroke_width(2)));
        if out.peaks.iter().any(|p| p.order == 0) {
            chart
                .draw_series(out.peaks.iter().filter(|p| p.order == 0).map(|p| {
                    Circle::new(
                        (p.theta_r_deg, p.lambda_m * 1e9),
                        4,
                        MAGENTA.stroke_width(2),
                    )
                }))
                .map_err(perr)?
                .label("peaks without an order (not in the fit)")
                .legend(|(x, y)| Circle::new((x + 12, y), 4, MAGENTA.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font(("sans-serif", 16))
            .draw()
            .map_err(perr)?;
        Ok(())
    })
}
