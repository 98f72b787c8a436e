//! Where tests find `../shared/data` (real AFM files, the thesis' snake patches)
//! and what they do when it is missing: under `SUNBEAM_REQUIRE_ALL=1` (CI) they
//! fail loudly; elsewhere they print a SKIP line and return None.

use std::path::PathBuf;

/// True when CI demands every test to run (`SUNBEAM_REQUIRE_ALL=1`).
pub fn require_all() -> bool {
    std::env::var("SUNBEAM_REQUIRE_ALL").is_ok_and(|v| v == "1")
}

/// The shared data folder: `$SUNBEAM_SHARED_DATA`, else the first `shared/data`
/// next to an ancestor of `$CARGO_MANIFEST_DIR` (or of the current directory).
pub fn shared_data() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("SUNBEAM_SHARED_DATA").map(PathBuf::from) {
        return found_or_skip(Some(p));
    }
    let start = std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .or_else(|| std::env::current_dir().ok());
    let found = start.and_then(|s| {
        s.ancestors()
            .map(|a| a.join("../shared/data"))
            .find(|p| p.join("afm").is_dir() || p.join("snake").is_dir())
    });
    found_or_skip(found)
}

/// `shared_data()/rel`, with the same skip/fail rule if that file is missing.
pub fn shared_file(rel: &str) -> Option<PathBuf> {
    let p = shared_data()?.join(rel);
    if p.exists() {
        return Some(p);
    }
    missing(&format!("shared data file {}", p.display()))
}

fn found_or_skip(p: Option<PathBuf>) -> Option<PathBuf> {
    match p {
        Some(p) if p.is_dir() => Some(p),
        other => missing(&format!(
            "shared data folder ({})",
            other
                .map(|p| p.display().to_string())
                .unwrap_or_else(|| "../shared/data".into())
        )),
    }
}

fn missing(what: &str) -> Option<PathBuf> {
    if require_all() {
        panic!("{what} is missing and SUNBEAM_REQUIRE_ALL=1: CI needs it");
    }
    eprintln!(
        "SKIP: {what} not found (set SUNBEAM_SHARED_DATA or SUNBEAM_REQUIRE_ALL=1 to fail instead)"
    );
    None
}

/// Skip-or-fail for a missing system tool (node, oiiotool, xvfb-run ...): returns
/// true when `cmd --version` (or `args`) runs.
pub fn have_command(cmd: &str, args: &[&str]) -> bool {
    let ok = std::process::Command::new(cmd)
        .args(if args.is_empty() {
            &["--version"][..]
        } else {
            args
        })
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        if require_all() {
            panic!(
                "`{cmd}` is not available and SUNBEAM_REQUIRE_ALL=1 (run scripts/ensure-deps.sh)"
            );
        }
        eprintln!("SKIP: `{cmd}` not available (scripts/ensure-deps.sh installs it)");
    }
    ok
}
