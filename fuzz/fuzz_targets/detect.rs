#![no_main]
//! Fuzz detection and the whole entry point (whatever format the content looks like),
//! plus the header-only channel listing.

use libfuzzer_sys::fuzz_target;
use sunbeam_afm::{list_channels_bytes, read_bytes, ErrorCode, ReadOptions};

fuzz_target!(|data: &[u8]| {
    let _ = sunbeam_afm::detect(data);
    for o in [
        ReadOptions::default(),
        ReadOptions {
            pixel_size: Some((1e-9, 2e-9)),
            z_range: Some(1e-6),
            ..Default::default()
        },
    ] {
        if let Err(e) = read_bytes(data, &o) {
            assert_eq!(e.code, ErrorCode::Input, "{e}");
        }
        if let Err(e) = list_channels_bytes(data, &o) {
            assert_eq!(e.code, ErrorCode::Input, "{e}");
        }
    }
});
