//! Helpers the end-to-end tests share: the sibling tool binaries, a small
//! synthetic pack with its response map, a fresh scratch folder, and the
//! GPU-or-skip rule (under SUNBEAM_REQUIRE_ALL=1 a missing adapter fails).

use std::path::{Path, PathBuf};
use std::process::Command;

pub const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-play");

/// Another tool of the workspace, built next to sunbeam-play.
pub fn tool(name: &str) -> PathBuf {
    PathBuf::from(BIN).with_file_name(name)
}

/// Run `c` and fail the test with its stderr unless it succeeds.
pub fn ok(c: &mut Command) {
    let o = c.output().unwrap();
    assert!(
        o.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

/// `dir/name.ktx2` with its response map, from a 64 x 64 synthetic `preset`.
pub fn pack(dir: &Path, name: &str, preset: &str) -> PathBuf {
    let h = dir.join(format!("{name}.exr"));
    let p = dir.join(format!("{name}.ktx2"));
    ok(Command::new(tool("sunbeam-import"))
        .args([
            &format!("synthetic:{preset}"),
            "--synthetic-size",
            "64",
            "-q",
            "-o",
        ])
        .arg(&h));
    ok(Command::new(tool("sunbeam-pack"))
        .arg(&h)
        .arg("-o")
        .arg(&p)
        .args(["--response", "-q"]));
    p
}

/// An empty scratch folder for test `name`.
pub fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// True when a GPU adapter exists; otherwise skip with a message, or fail
/// under SUNBEAM_REQUIRE_ALL=1.
pub fn gpu_available() -> bool {
    if sunbeam_render::Gpu::headless(Default::default()).is_ok() {
        return true;
    }
    assert!(
        !sunbeam_common::testdata::require_all(),
        "no GPU adapter and SUNBEAM_REQUIRE_ALL=1 (install mesa-vulkan-drivers)"
    );
    eprintln!("SKIP: no GPU adapter");
    false
}
