//! What the file-format tests share: a small pack of a synthetic skin and
//! the maps' options.

use std::sync::Arc;
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_pack::Pack;
use sunbeam_response::Options;

/// A 32 x 32 patch of 50 nm samples of the synthetic snake skin `preset`.
pub fn pack(preset: &str) -> Arc<Pack> {
    let f = sunbeam_synth::preset(preset, 32, 50e-9).unwrap();
    let r = FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    Arc::new(sunbeam_pack::build(r, &BuildOptions::default(), &mut |_, _| {}).unwrap())
}

/// 24 wavelength samples, a 1 MiB map.
pub fn opts() -> Options {
    Options {
        lambda_samples: 24,
        budget_bytes: 1 << 20,
        grid: None,
    }
}
