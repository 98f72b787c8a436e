//! Helpers shared by the end-to-end tests.

use std::path::Path;
use std::process::{Command, Output};

/// The Khronos validator on `files` (skips, or fails under SUNBEAM_REQUIRE_ALL=1, without node).
pub fn validate(files: &[&Path]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let node_dir = root.join("tests/node");
    if !sunbeam_common::testdata::have_command("node", &[]) {
        return;
    }
    if !node_dir.join("node_modules/gltf-validator").is_dir() {
        assert!(
            !sunbeam_common::testdata::require_all(),
            "tests/node/node_modules/gltf-validator missing (run scripts/ensure-deps.sh)"
        );
        eprintln!("SKIP: tests/node/node_modules/gltf-validator missing");
        return;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/validate.mjs");
    let o = Command::new("node")
        .arg(script)
        .arg(&node_dir)
        .args(files)
        .output()
        .expect("run node");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "glTF-Validator reports errors:\n{out}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert_eq!(out.lines().count(), files.len(), "{out}");
}

/// Assert a run succeeded, showing its stderr when not.
pub fn ok(o: &Output) {
    assert!(
        o.status.success(),
        "exit {:?}\nstderr: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
}
