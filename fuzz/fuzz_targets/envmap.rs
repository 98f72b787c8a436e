#![no_main]
//! Fuzz the environment map readers of sunbeam-light (Radiance RGBE, OpenEXR):
//! any input gives pixels or an error, never a panic, and pixels that decode
//! are accepted or refused by `EnvMap::new` without a panic.

use libfuzzer_sys::fuzz_target;
use sunbeam_light::{io::decode, EnvMap};

fuzz_target!(|data: &[u8]| {
    for ext in ["hdr", "exr"] {
        if let Ok((w, h, rgb)) = decode(data, ext) {
            if w.saturating_mul(h) <= 1 << 22 {
                let _ = EnvMap::new(w, h, rgb, 30.0, 1.0);
            }
        }
    }
});
