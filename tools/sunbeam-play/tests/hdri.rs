//! A real HDRI as distributed (../shared/data/hdri/night.exr, DWAB: 829
//! negative values in 596 texels, from the data's README) lights a scene: the
//! values set to 0 are counted in the `--json` report and reported in exactly
//! one warning line, none with `-q` (docs/SCENE.md "environment").

#[allow(dead_code)] // this test uses the GPU check and the scratch folder only
mod common;

use common::{gpu_available, scratch, BIN};
use std::process::Command;

#[test]
fn real_hdri_negatives_are_counted_and_warned_once() {
    let Some(night) = sunbeam_common::testdata::shared_file("hdri/night.exr") else {
        return;
    };
    if !gpu_available() {
        return;
    }
    let d = scratch("play-hdri");
    let s = d.join("night.json");
    std::fs::write(
        &s,
        format!(
            r#"{{ "camera": {{ "eye": [0, 0.5, 2.5], "target": [0, 0, 0] }},
  "meshes": [ {{ "mesh": "builtin:sphere", "base_color": [0.8, 0.8, 0.8] }} ],
  "environment": {{ "map": "{}" }}, "size": [12, 12] }}"#,
            night.display()
        ),
    )
    .unwrap();
    let run = |extra: &[&str]| {
        Command::new(BIN)
            .arg(&s)
            .args(["--headless", "-o"])
            .arg(d.join("f.png"))
            .args(extra)
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap()
    };
    let o = run(&["--json"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let zeroed = &r["environment_negatives_zeroed"];
    assert_eq!(zeroed["values"], 829, "{r}");
    assert_eq!(zeroed["texels"], 596, "{r}");
    assert_eq!(err.matches("warning:").count(), 1, "{err}");
    assert!(err.contains("night.exr"), "{err}");
    let o = run(&["-q"]);
    assert!(o.status.success());
    assert!(!String::from_utf8_lossy(&o.stderr).contains("warning"));
}
