//! Helpers shared by the end-to-end tests in `tests/`: where the tool binaries are.
//! Shared data and system tools: `sunbeam_common::testdata`.

use std::path::{Path, PathBuf};

/// The workspace root (where the top Cargo.toml is).
pub fn workspace_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Path to a built tool binary (`sunbeam-import`, ...), in the same profile
/// directory as the running test. `make test` builds all binaries first.
pub fn tool(name: &str) -> PathBuf {
    let exe = std::env::current_exe().expect("current_exe");
    // target/<profile>/deps/test-xxxx -> target/<profile>/
    let profile_dir = exe
        .parent()
        .and_then(Path::parent)
        .expect("test binary lives in target/<profile>/deps");
    let p = profile_dir.join(format!("{name}{}", std::env::consts::EXE_SUFFIX));
    assert!(
        p.exists(),
        "{} not built: run `cargo build --release --workspace` (make test does this)",
        p.display()
    );
    p
}

/// A fresh temporary directory under target/ for one test.
pub fn scratch(test: &str) -> PathBuf {
    let d = workspace_root().join("target/test-scratch").join(test);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create scratch dir");
    d
}

/// Run a command and fail the test, with its output, unless it exits 0.
pub fn run_ok(cmd: &mut std::process::Command) -> std::process::Output {
    let o = cmd.output().expect("run");
    assert!(
        o.status.success(),
        "{cmd:?}: {}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}
