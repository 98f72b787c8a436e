//! The processing steps of `sunbeam-import`, each recording itself in the
//! field's provenance. [`Step::canonical_order`] is the order the tool applies them.

use crate::align::{align_rows, AlignRows};
use crate::geom::{crop, flip_x, flip_y, rotate, CropSpec};
use crate::level::{level_plane, level_poly, zero_mean};
use crate::resample::{resample, Target};
use crate::scars::{remove_scars, ScarParams};
use crate::{fill, HeightField};
use sunbeam_common::units::format_length;
use sunbeam_common::{Error, Result};

/// Background levelling.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    Plane,
    Poly(usize),
}

impl std::str::FromStr for Level {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        if s == "plane" {
            return Ok(Level::Plane);
        }
        if let Some(n) = s.strip_prefix("poly:") {
            let d: usize = n
                .parse()
                .map_err(|_| Error::usage(format!("'{s}': degree must be an integer (poly:2)")))?;
            if d > crate::level::MAX_POLY_DEGREE {
                return Err(Error::usage(format!(
                    "'{s}': degree above {}",
                    crate::level::MAX_POLY_DEGREE
                )));
            }
            return Ok(Level::Poly(d));
        }
        Err(Error::usage(format!(
            "'{s}': unknown levelling (plane, poly:N)"
        )))
    }
}

/// Mirror axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlipAxis {
    X,
    Y,
}

impl std::str::FromStr for FlipAxis {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "x" | "X" => Ok(FlipAxis::X),
            "y" | "Y" => Ok(FlipAxis::Y),
            _ => Err(Error::usage(format!("'{s}': flip axis must be x or y"))),
        }
    }
}

/// One processing step.
#[derive(Debug, Clone, PartialEq)]
pub enum Step {
    Crop(CropSpec),
    FillNonFinite,
    Level(Level),
    AlignRows(AlignRows),
    RemoveScars,
    ZeroMean,
    Rotate(i32),
    Flip(FlipAxis),
    Resample(Target),
}

impl Step {
    /// Rank in the tool's fixed order: crop, fill, level, align rows, scars,
    /// zero mean, rotate, flip, resample.
    pub fn canonical_order(&self) -> usize {
        match self {
            Step::Crop(_) => 0,
            Step::FillNonFinite => 1,
            Step::Level(_) => 2,
            Step::AlignRows(_) => 3,
            Step::RemoveScars => 4,
            Step::ZeroMean => 5,
            Step::Rotate(_) => 6,
            Step::Flip(_) => 7,
            Step::Resample(_) => 8,
        }
    }
}

/// Apply one step; returns the description added to the provenance (None when
/// the step changed nothing, e.g. `--align-rows none`, `--rotate 0`).
pub fn apply(f: &mut HeightField, step: &Step) -> Result<Option<String>> {
    let desc = match step {
        Step::Crop(spec) => {
            let (x, y, w, h) = spec.to_pixels(f);
            *f = crop(f, x, y, w, h)?;
            format!("crop {x},{y},{w},{h} px")
        }
        Step::FillNonFinite => {
            let n = fill::fill_nonfinite(f)?;
            format!("fill-nonfinite laplace ({n} values)")
        }
        Step::Level(Level::Plane) => {
            level_plane(f)?;
            "level plane".into()
        }
        Step::Level(Level::Poly(d)) => {
            level_poly(f, *d)?;
            format!("level poly:{d}")
        }
        Step::AlignRows(AlignRows::None) => return Ok(None),
        Step::AlignRows(m) => {
            align_rows(f, *m)?;
            format!("align-rows {}", m.name())
        }
        Step::RemoveScars => {
            let n = remove_scars(f, &ScarParams::default())?;
            format!("remove-scars ({n} values)")
        }
        Step::ZeroMean => {
            zero_mean(f)?;
            "zero-mean".into()
        }
        Step::Rotate(d) => {
            if d.rem_euclid(360) == 0 {
                return Ok(None);
            }
            *f = rotate(f, *d)?;
            format!("rotate {}", d.rem_euclid(360))
        }
        Step::Flip(FlipAxis::X) => {
            flip_x(f);
            "flip x".into()
        }
        Step::Flip(FlipAxis::Y) => {
            flip_y(f);
            "flip y".into()
        }
        Step::Resample(t) => {
            let (w0, h0) = (f.width, f.height);
            *f = resample(f, *t)?;
            format!(
                "resample {w0}x{h0} -> {}x{} px of {} (kaiser-sinc)",
                f.width,
                f.height,
                format_length(f.dx)
            )
        }
    };
    f.provenance.processing.push(desc.clone());
    Ok(Some(desc))
}
