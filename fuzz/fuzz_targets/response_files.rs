#![no_main]
//! Fuzz the readers of the files `sunbeam-pack --response` writes beside a
//! pack (sunbeam-response: the response map, the environment's maps, the
//! first-frame cells; docs/PACK_FORMAT.md): any input decodes or gives an
//! input error (exit code 2), never a panic.

use libfuzzer_sys::fuzz_target;
use sunbeam_response::{cells_file, env_file, ktx2};

fuzz_target!(|data: &[u8]| {
    if let Err(e) = ktx2::decode(data) {
        assert_eq!(e.exit_code(), 2, "{e}");
    }
    if let Err(e) = env_file::decode(data) {
        assert_eq!(e.exit_code(), 2, "{e}");
    }
    if let Err(e) = cells_file::decode(data) {
        assert_eq!(e.exit_code(), 2, "{e}");
    }
});
