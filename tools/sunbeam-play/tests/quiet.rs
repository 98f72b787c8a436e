//! A run that succeeds prints no line that says error, also where the
//! environment has no `XDG_RUNTIME_DIR` (a fresh container, a CI job, ssh
//! without a session): the first command a new user runs, the built-in sky on
//! a sphere, headless.

mod common;

use common::{gpu_available, pack, scratch, BIN};
use std::process::Command;

#[test]
fn a_successful_run_without_xdg_runtime_dir_prints_no_error() {
    if !gpu_available() {
        return;
    }
    let d = scratch("play-quiet");
    let p = pack(&d, "x", "xenopeltis");
    let frame = d.join("f.png");
    let o = Command::new(BIN)
        .args(["--mesh", "builtin:sphere", "--pack"])
        .arg(&p)
        .args(["--headless", "--size", "32x32", "-o"])
        .arg(&frame)
        .env_remove("XDG_RUNTIME_DIR")
        .env_remove("NODEVICE_SELECT")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "{text}");
    assert!(frame.is_file());
    let errors: Vec<&str> = text
        .lines()
        .filter(|l| l.to_ascii_lowercase().contains("error"))
        .collect();
    assert!(errors.is_empty(), "error lines on success: {errors:?}");
}
