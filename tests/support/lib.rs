//! Helpers shared by the end-to-end tests in `tests/`: where the tool binaries
//! and the shared data are, and how a test that needs them skips or fails.

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

/// True when CI demands every test to run (`SUNBEAM_REQUIRE_ALL=1`).
pub fn require_all() -> bool {
    std::env::var("SUNBEAM_REQUIRE_ALL").is_ok_and(|v| v == "1")
}

/// `../shared/data` (or `$SUNBEAM_SHARED_DATA`), if present. When missing: panics
/// under `SUNBEAM_REQUIRE_ALL=1`, otherwise prints why and returns None so the
/// test can skip.
pub fn shared_data() -> Option<PathBuf> {
    let p = std::env::var_os("SUNBEAM_SHARED_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root().join("../shared/data"));
    if p.is_dir() {
        return Some(p);
    }
    if require_all() {
        panic!(
            "shared data not found at {} and SUNBEAM_REQUIRE_ALL=1",
            p.display()
        );
    }
    eprintln!("SKIP: shared data not found at {}", p.display());
    None
}

/// A fresh temporary directory under target/ for one test.
pub fn scratch(test: &str) -> PathBuf {
    let d = workspace_root().join("target/test-scratch").join(test);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create scratch dir");
    d
}
