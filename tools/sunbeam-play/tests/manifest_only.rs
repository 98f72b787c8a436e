//! The default mode reads only a pack's manifest when a response map built
//! from it stands beside it (the map is all it draws with): shown by spoiling
//! the pack's term data, which a full read refuses (non-finite terms). The
//! default mode still renders; `--mode direct` (which needs the terms) and a
//! map from another pack (which forces a rebuild from the terms) do not.

mod common;

use common::{gpu_available, pack, scratch, BIN};
use std::path::Path;
use std::process::Command;

/// Overwrite the first term values of a KTX2 pack with NaN (level 0 offset at byte 80).
fn spoil(p: &Path) {
    let mut b = std::fs::read(p).unwrap();
    let off = u64::from_le_bytes(b[80..88].try_into().unwrap()) as usize;
    for v in b[off..off + 64].chunks_exact_mut(4) {
        v.copy_from_slice(&f32::NAN.to_le_bytes());
    }
    std::fs::write(p, b).unwrap();
}

fn render(scene: &Path, extra: &[&str]) -> std::process::Output {
    Command::new(BIN)
        .arg(scene)
        .args(["--headless", "--size", "16x16", "-q", "-o"])
        .arg(scene.with_file_name("f.png"))
        .args(extra)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap()
}

#[test]
fn default_mode_reads_the_manifest_only_when_the_map_is_current() {
    if !gpu_available() {
        return;
    }
    let d = scratch("play-manifest-only");
    let p = pack(&d, "x", "xenopeltis");
    let other = pack(&d, "y", "elaphe");
    let scene = d.join("scene.json");
    std::fs::write(
        &scene,
        r#"{ "camera": { "eye": [0, 0, 2], "target": [0, 0, 0] }, "meshes": [ { "mesh": "builtin:sphere", "pack": "x.ktx2" } ] }"#,
    )
    .unwrap();
    spoil(&p);
    // A full read refuses the spoiled pack...
    let o = render(&scene, &["--mode", "direct"]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "direct mode read the spoiled terms: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    // ...the default mode never reads them.
    let o = render(&scene, &[]);
    assert!(
        o.status.success(),
        "default mode: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    // A map from another pack: the terms are needed to rebuild it, and refused.
    std::fs::copy(
        other.with_extension("response.ktx2"),
        p.with_extension("response.ktx2"),
    )
    .unwrap();
    let o = render(&scene, &[]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "stale map: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}
