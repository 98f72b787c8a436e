//! The player does not shade a scene `environment` yet: it refuses it (exit 2,
//! naming the field, no output) instead of drawing a plausible wrong frame.

use std::process::Command;

#[test]
fn environment_scenes_are_refused_on_the_gpu_path() {
    let d = std::env::temp_dir().join(format!("sb-play-env-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let s = d.join("sky.json");
    std::fs::write(
        &s,
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere" } ],
  "environment": { "sky": { "sun_elevation_deg": 35 } }, "size": [8, 8] }"#,
    )
    .unwrap();
    let out = d.join("f.png");
    let o = Command::new(env!("CARGO_BIN_EXE_sunbeam-play"))
        .arg(&s)
        .args(["--headless", "-o"])
        .arg(&out)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("environment"), "{err}");
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).ok();
}
