//! One interface over the two things that give `R(u, v, w, lambda)`: the
//! float64 ground truth of a height field, and a pack's CPU evaluator.

use std::path::Path;
use sunbeam_afm::height::{read_height_field, HeightOptions};
use sunbeam_common::{Error, Result};
use sunbeam_field::HeightField;
use sunbeam_optics::truth::{Model, Params, Truth};

pub enum Source {
    Truth {
        truth: Box<Truth>,
        field: Box<HeightField>,
    },
    Pack(Box<sunbeam_pack::Pack>),
}

impl Source {
    /// Open `path` as a pack (KTX2, or EXR with a manifest) unless `force_truth`,
    /// else as a height field with its ground truth.
    pub fn open(
        path: &Path,
        heights: &HeightOptions,
        params: &Params,
        force_truth: bool,
    ) -> Result<Source> {
        if sunbeam_pack::formats::is_pack(path)? {
            if force_truth {
                return Err(Error::usage(format!(
                    "{}: is a pack; the ground truth needs the height field it was made from",
                    path.display()
                )));
            }
            let p = sunbeam_pack::Pack::read(path)?;
            return Ok(Source::Pack(Box::new(p)));
        }
        let field = read_height_field(path, heights)?.field;
        Self::from_field(field, params).map_err(|e| e.context(path.display()))
    }

    pub fn from_field(field: HeightField, p: &Params) -> Result<Source> {
        let truth = Truth::new(&field, p)?;
        Ok(Source::Truth {
            truth: Box::new(truth),
            field: Box::new(field),
        })
    }

    pub fn reflectance(&self, u: f64, v: f64, w: f64, lambda_m: f64) -> f64 {
        match self {
            Source::Truth { truth, .. } => truth.reflectance(u, v, w, lambda_m),
            Source::Pack(p) => p.reflectance(u, v, w, lambda_m),
        }
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Source::Truth { .. } => "truth",
            Source::Pack(_) => "pack",
        }
    }

    /// Patch size (Lx, Ly) in metres.
    pub fn patch_size(&self) -> (f64, f64) {
        match self {
            Source::Truth { field, .. } => (field.size_x(), field.size_y()),
            Source::Pack(p) => crate::packinfo::patch_size(p),
        }
    }

    /// Model name ("window"/"tiled").
    pub fn model_name(&self) -> String {
        match self {
            Source::Truth { truth, .. } => truth.params().model.name().to_string(),
            Source::Pack(p) => crate::packinfo::model_name(p),
        }
    }

    /// Width of the specular lobe in cycles per metre (peaks closer to f = 0 are
    /// taken as specular): half a bin for the tiled model, 0.6/sigma for the window.
    pub fn specular_halfwidth(&self) -> f64 {
        let (lx, ly) = self.patch_size();
        let half_bin = 0.5 / lx.min(ly);
        match self {
            Source::Truth { truth, .. } => match truth.params().model {
                Model::Tiled => half_bin,
                Model::Window => half_bin.max(0.6 / truth.window_sigma_m()),
            },
            Source::Pack(p) => half_bin.max(crate::packinfo::specular_halfwidth(p)),
        }
    }
}

/// Evaluate `f(i)` for `i in 0..n` on all cores, in order (rayon's indexed
/// collect keeps the order, so results do not depend on the thread count).
pub fn par_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    use rayon::prelude::*;
    (0..n).into_par_iter().map(f).collect()
}
