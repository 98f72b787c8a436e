//! A scene with an `environment` (docs/SCENE.md) is refused, not rendered
//! without its light: exit 2 naming the field, no output.

use std::process::Command;

#[test]
fn environment_scenes_are_refused_until_shaded() {
    let d = std::env::temp_dir().join(format!("sb-eval-env-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let s = d.join("sky.json");
    std::fs::write(
        &s,
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere" } ],
  "environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 120, "turbidity": 3 }, "intensity": 1 },
  "size": [8, 8] }"#,
    )
    .unwrap();
    let out = d.join("f.png");
    let o = Command::new(env!("CARGO_BIN_EXE_sunbeam-eval"))
        .arg("render")
        .arg(&s)
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(String::from_utf8_lossy(&o.stderr).contains("environment"));
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).ok();
}
