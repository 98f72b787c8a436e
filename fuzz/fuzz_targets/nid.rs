#![no_main]
//! Fuzz the nid parser of sunbeam-afm: any input gives channels or an Input error, never a panic.

use libfuzzer_sys::fuzz_target;
use sunbeam_afm::{read_bytes, ErrorCode, Format, ReadOptions};

fuzz_target!(|data: &[u8]| {
    let o = ReadOptions {
        format: Some(Format::Nid),
        pixel_size: Some((1e-9, 1e-9)),
        z_range: Some(1e-6),
        z_scale: None,
    };
    if let Err(e) = read_bytes(data, &o) {
        assert_eq!(e.code, ErrorCode::Input, "{e}");
    }
});
