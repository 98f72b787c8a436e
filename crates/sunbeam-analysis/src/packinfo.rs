//! What the tools need to know about a pack, from its manifest.

use sunbeam_pack::{Model, Pack};

pub fn patch_size(p: &Pack) -> (f64, f64) {
    (p.manifest.patch.lx_m, p.manifest.patch.ly_m)
}

pub fn model_name(p: &Pack) -> String {
    p.manifest.model.name().into()
}

/// Half width of the specular lobe in cycles per metre (see `Source::specular_halfwidth`).
pub fn specular_halfwidth(p: &Pack) -> f64 {
    match p.manifest.model {
        Model::Window if p.manifest.window_sigma_m > 0.0 => 0.6 / p.manifest.window_sigma_m,
        _ => 0.0,
    }
}
