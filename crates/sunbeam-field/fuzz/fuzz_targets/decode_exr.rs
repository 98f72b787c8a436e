#![no_main]
//! EXR height-field decoding must never panic nor allocate beyond what the input justifies.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(raw) = sunbeam_field::io::exr::decode_raw(data) {
        assert_eq!(raw.data.len(), raw.width * raw.height);
    }
});
