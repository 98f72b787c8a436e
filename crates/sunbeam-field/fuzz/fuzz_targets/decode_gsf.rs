#![no_main]
//! GSF decoding must never panic nor allocate beyond what the input justifies.
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(f) = sunbeam_field::io::gsf::decode(data) {
        assert_eq!(f.data.len(), f.width * f.height);
    }
});
