//! `sunbeam-eval brdf PACK --light THETA,PHI -o out.png`: the reflected colour
//! over the hemisphere of view directions (left; orthographic projection of
//! `wr`, +x right, +y up, through the shared display transform), and
//! `log10 R` over (viewing angle, wavelength) in the plane of incidence (right).

use crate::plot::{perr, png, viridis};
use plotters::prelude::*;
use std::path::Path;
use sunbeam_analysis::brdf;
use sunbeam_common::Result;
use sunbeam_optics::colour::{self, ToneMap};
use sunbeam_pack::Pack;

pub struct Options {
    pub light: [f64; 3],
    pub size: usize,
    pub lambda_samples: usize,
    /// None: auto (95th percentile of Y over the disk at 1).
    pub exposure_ev: Option<f64>,
    pub tone: ToneMap,
    pub title: String,
}

pub struct Outcome {
    pub exposure_ev: f64,
    pub max_y: f64,
}

pub fn run(pack: &Pack, o: &Options, out: &Path) -> Result<Outcome> {
    let n = o.size;
    let hemi = brdf::hemisphere(pack, o.light, n, o.lambda_samples);
    let max_y = hemi.max_y;
    let ev = o.exposure_ev.unwrap_or_else(|| hemi.auto_exposure_ev());
    let tm = ToneMap {
        exposure_ev: ev,
        curve: o.tone.curve,
    };
    let img: Vec<Option<[u8; 3]>> = hemi
        .xyz
        .iter()
        .map(|c| c.map(|xyz| colour::xyz_to_srgb8(xyz, &tm)))
        .collect();

    // Right panel: R over (theta_r, lambda) in the plane of incidence.
    let lt = o.light[2].acos();
    let m = &pack.manifest;
    let plane = brdf::plane_of_incidence(pack, o.light, 80, 360);
    let (nl, na, grid) = (plane.lambdas, plane.angles, &plane.r);
    let (a0, a1) = brdf::PlaneGrid::ANGLE_RANGE_DEG;
    let lo_nm = m.lambda_min_m * 1e9;
    let hi_nm = m.lambda_max_m * 1e9;
    png(out, 1300, 640, |root| {
        let (left, right) = root.split_horizontally(620);
        let mut c1 = ChartBuilder::on(&left)
            .caption(
                format!("{}: colour over view directions", o.title),
                ("sans-serif", 18),
            )
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(54)
            .build_cartesian_2d(-1.0f64..1.0, -1.0f64..1.0)
            .map_err(perr)?;
        c1.configure_mesh()
            .disable_mesh()
            .x_desc("wr.x (toward patch +x)")
            .y_desc("wr.y (toward patch +y)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(perr)?;
        let d = 2.0 / n as f64;
        c1.draw_series(img.iter().enumerate().map(|(k, c)| {
            let (i, j) = (k % n, k / n);
            let x = -1.0 + i as f64 * d;
            let y = 1.0 - (j + 1) as f64 * d;
            let col = c
                .map(|c| RGBColor(c[0], c[1], c[2]))
                .unwrap_or(RGBColor(40, 40, 40));
            Rectangle::new([(x, y), (x + d, y + d)], col.filled())
        }))
        .map_err(perr)?;
        // Light's mirror direction.
        c1.draw_series(std::iter::once(Circle::new(
            (-o.light[0], -o.light[1]),
            6,
            WHITE.stroke_width(2),
        )))
        .map_err(perr)?
        .label(format!(
            "specular direction (light {:.0} deg, exposure {:+.2} EV)",
            lt.to_degrees(),
            ev
        ))
        .legend(|(x, y)| Circle::new((x + 8, y), 5, BLACK.stroke_width(2)));
        c1.configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(perr)?;

        let mut c2 = ChartBuilder::on(&right)
            .caption("log10 R in the plane of incidence", ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(a0..a1, lo_nm..hi_nm)
            .map_err(perr)?;
        c2.configure_mesh()
            .disable_mesh()
            .x_desc("viewing angle theta_r (deg, signed; + on the light's side)")
            .y_desc("wavelength (nm)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(perr)?;
        let dl = (hi_nm - lo_nm) / nl as f64;
        let da = (a1 - a0) / na as f64;
        c2.draw_series(grid.iter().enumerate().map(|(k, r)| {
            let (li, ai) = (k / na, k % na);
            let a = a0 + ai as f64 * da;
            let l = lo_nm + li as f64 * dl;
            // log10 R from -6 to 0 mapped to the colour map.
            let t = ((r.max(1e-12)).log10() + 6.0) / 6.0;
            Rectangle::new([(a, l), (a + da, l + dl)], viridis(t).filled())
        }))
        .map_err(perr)?;
        c2.draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(perr)?
            .label("colour: log10 R from -6 (dark) to 0 (yellow)")
            .legend(|(x, y)| Rectangle::new([(x, y - 5), (x + 16, y + 5)], viridis(0.8).filled()));
        c2.configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 13))
            .draw()
            .map_err(perr)?;
        Ok(())
    })?;
    Ok(Outcome {
        exposure_ev: ev,
        max_y,
    })
}
