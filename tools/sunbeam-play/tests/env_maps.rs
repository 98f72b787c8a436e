//! The environment's maps from the pipeline (`sunbeam-pack --response` writes
//! `NAME.env-response.ktx2`, docs/PACK_FORMAT.md "Environment maps file"): the
//! player draws with them when they serve the scene (no build at start, the
//! same frame bit for bit as with the maps built in memory), rebuilds them in
//! memory with a note for another sun or another pack (no line that says
//! error), and refuses a damaged file naming it (exit 2, no panic). The same
//! for the first-frame cells (`NAME.env-cells.ktx2`, docs/PACK_FORMAT.md
//! "Cells file"), clustered at start for a count the file does not hold.

mod common;

use common::{gpu_available, pack, scratch, BIN};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A sky-lit sphere with `x.ktx2`, the sun `elevation` degrees up at 70
/// degrees azimuth, turbidity 3 (the pack tool's default sky at 35).
fn sky_scene(dir: &Path, name: &str, elevation: f64) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!(
            r#"{{ "camera": {{ "eye": [0, 0.3, 2], "target": [0, 0, 0] }},
  "meshes": [ {{ "mesh": "builtin:sphere", "pack": "x.ktx2" }} ],
  "environment": {{ "sky": {{ "sun_elevation_deg": {elevation}, "sun_azimuth_deg": 70, "turbidity": 3 }} }} }}"#
        ),
    )
    .unwrap();
    p
}

fn render(scene: &Path, out: &str) -> Output {
    Command::new(BIN)
        .arg(scene)
        .args(["--headless", "--size", "24x24", "--frames", "2", "-o"])
        .arg(scene.with_file_name(out))
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

const BUILT: &str = "built the environment's response maps";

#[test]
fn the_pipelines_environment_maps_are_read_rebuilt_when_stale_refused_when_damaged() {
    if !gpu_available() {
        return;
    }
    let d = scratch("play-env-maps");
    pack(&d, "x", "xenopeltis");
    let other = pack(&d, "y", "elaphe");
    let maps = d.join("x.env-response.ktx2");
    assert!(maps.is_file(), "sunbeam-pack --response wrote {maps:?}");
    let scene = sky_scene(&d, "sky.json", 35.0);

    // Current: read, not built.
    let o = render(&scene, "read.exr");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(!err.contains(BUILT), "maps built although current: {err}");

    // Without the file the player builds them: the same frame, bit for bit.
    std::fs::rename(&maps, d.join("aside.ktx2")).unwrap();
    let o = render(&scene, "built.exr");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains(BUILT), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(d.join("read.exr")).unwrap(),
        std::fs::read(d.join("built.exr")).unwrap(),
        "the frame from the file's maps differs from the one from maps built in memory"
    );
    std::fs::rename(d.join("aside.ktx2"), &maps).unwrap();

    // Another sun: rebuilt with a note naming the file, no error line.
    let low = sky_scene(&d, "low.json", 20.0);
    let o = render(&low, "low.exr");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains(BUILT) && err.contains("another sky"), "{err}");
    assert!(err.contains("x.env-response.ktx2"), "{err}");
    assert!(!err.to_lowercase().contains("error"), "{err}");

    // Another pack's maps: rebuilt (the pack read whole), no error line.
    std::fs::copy(other.with_extension("env-response.ktx2"), &maps).unwrap();
    let o = render(&scene, "stale.exr");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains(BUILT) && err.contains("another pack"), "{err}");
    assert!(!err.to_lowercase().contains("error"), "{err}");
    assert_eq!(
        std::fs::read(d.join("read.exr")).unwrap(),
        std::fs::read(d.join("stale.exr")).unwrap(),
        "rebuilt maps give another frame"
    );

    // Damaged: cut short, or its JSON broken: an input error naming the file.
    let good = std::fs::read(other.with_extension("env-response.ktx2")).unwrap();
    let brace = good.windows(9).position(|w| w == b"{\"format\"").unwrap();
    let mut broken = good.clone();
    broken[brace] = b'[';
    for bytes in [good[..good.len() / 2].to_vec(), broken] {
        std::fs::write(&maps, &bytes).unwrap();
        let o = render(&scene, "bad.exr");
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains("x.env-response.ktx2"), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// One first frame of `scene` with the cells (`--env-cells` `cells`).
fn render_cells(scene: &Path, out: &str, cells: &str) -> Output {
    Command::new(BIN)
        .arg(scene)
        .args(["--headless", "--size", "16x16", "--env-estimator", "cells"])
        .args(["--env-cells", cells, "-o"])
        .arg(scene.with_file_name(out))
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap()
}

const CLUSTERED: &str = "clustered the environment's maps";

#[test]
fn the_pipelines_cells_are_read_clustered_when_missing_refused_when_damaged() {
    if !gpu_available() {
        return;
    }
    let d = scratch("play-env-cells");
    pack(&d, "x", "xenopeltis");
    let cells = d.join("x.env-cells.ktx2");
    assert!(cells.is_file(), "sunbeam-pack --response wrote {cells:?}");
    let scene = sky_scene(&d, "sky.json", 35.0);

    // Current (the default count): read, not clustered.
    let o = render_cells(&scene, "read.exr", "512");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        !err.contains(CLUSTERED),
        "cells clustered although current: {err}"
    );

    // Without the file: clustered with a note naming it, the same frame.
    std::fs::rename(&cells, d.join("aside.ktx2")).unwrap();
    let o = render_cells(&scene, "built.exr", "512");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(CLUSTERED) && err.contains("x.env-cells.ktx2"),
        "{err}"
    );
    assert_eq!(
        std::fs::read(d.join("read.exr")).unwrap(),
        std::fs::read(d.join("built.exr")).unwrap(),
        "the frame from the file's cells differs from the one from cells clustered in memory"
    );
    std::fs::rename(d.join("aside.ktx2"), &cells).unwrap();

    // A count the file does not hold: clustered, the flag that writes it named.
    let o = render_cells(&scene, "other.exr", "64");
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains(CLUSTERED) && err.contains("--response-cells 64"),
        "{err}"
    );
    assert!(!err.to_lowercase().contains("error"), "{err}");

    // Damaged: an input error naming the file, nothing written.
    let good = std::fs::read(&cells).unwrap();
    std::fs::write(&cells, &good[..good.len() / 2]).unwrap();
    let o = render_cells(&scene, "bad.exr", "512");
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("x.env-cells.ktx2"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(!d.join("bad.exr").exists());
}

/// The default count follows the pack (docs/LIGHTING.md "How many cells"):
/// a patch of 10 um or more takes 1024 cells, a smaller one 512, in the
/// pipeline's cells file (`sunbeam-pack --response` with no
/// `--response-cells`) and in the player alike, so the player reads the file
/// and clusters nothing. So does the cells' grid ("Cells at a lower rate"):
/// one pixel in 2 x 2 from 32 um, in 4 x 4 below (the bound itself: the
/// unit test in crates/sunbeam-render/src/renderer/cells_rate.rs), and with both packs in
/// one scene the finer of those whose meshes read it.
#[test]
fn the_default_cells_follow_the_patchs_size() {
    if !gpu_available() {
        return;
    }
    let d = scratch("play-env-cells-default");
    let small = pack(&d, "x", "xenopeltis");
    // 256 px of 128 nm: 32.8 um, above both bounds (the cells' count from
    // 10 um, the grid of 2 from 32 um), which follow the patch's size, not
    // its pixels. The pack's time follows the size too (about 50 s here,
    // 21 s for 10.24 um): the fewest pixels keep the rest of it small. The
    // pack warns of aliasing, which does not matter here.
    let h = d.join("big.exr");
    common::ok(Command::new(common::tool("sunbeam-import")).args([
        "synthetic:xenopeltis",
        "--synthetic-size",
        "256",
        "--synthetic-pixel",
        "128nm",
        "-q",
        "-o",
        h.to_str().unwrap(),
    ]));
    let big = d.join("big.ktx2");
    common::ok(
        Command::new(common::tool("sunbeam-pack"))
            .arg(&h)
            .arg("-o")
            .arg(&big)
            .args(["--response", "-q"]),
    );
    for (p, want, rate) in [(&small, 512, 4), (&big, 1024, 2)] {
        let o = Command::new(BIN)
            .args(["--mesh", "builtin:sphere", "--pack"])
            .arg(p)
            .args([
                "--headless",
                "--size",
                "16x16",
                "--env-estimator",
                "cells",
                "--json",
                "-o",
            ])
            .arg(d.join("f.exr"))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap();
        let err = stderr(&o);
        assert!(o.status.success(), "{err}");
        assert!(!err.contains(CLUSTERED), "{p:?}: clustered at start: {err}");
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        assert_eq!(r["env_cells"], want, "{p:?}: {r}");
        assert_eq!(r["env_cells_rate"], rate, "{p:?}: {r}");
    }
    // Two meshes in one scene: the finer grid of the packs whose meshes read
    // it. A mesh with scale maps under MSAA reads none ("One walk per
    // pixel"), so the large pack on the scaled snake leaves the small one's 4.
    common::ok(
        Command::new(common::tool("sunbeam-bake"))
            .args(["--generate-snake", "--scales", "-q", "-o"])
            .arg(d.join("snake.glb")),
    );
    let rate_of = |name: &str, first: &str| {
        let scene = d.join(format!("{name}.json"));
        std::fs::write(
            &scene,
            format!(
                r#"{{ "camera": {{ "eye": [0, 0, 3], "target": [0, 0, 0], "fov_y_deg": 40 }},
  "meshes": [ {{ "mesh": "{first}", "pack": {big:?} }}, {{ "mesh": "builtin:sphere", "pack": {small:?} }} ],
  "environment": {{ "sky": {{ "sun_elevation_deg": 35 }} }}, "size": [16, 16] }}"#
            ),
        )
        .unwrap();
        let o = Command::new(BIN)
            .arg(&scene)
            .args(["--headless", "--env-estimator", "cells", "--json", "-o"])
            .arg(d.join(format!("{name}.exr")))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        r["env_cells_rate"].clone()
    };
    assert_eq!(rate_of("both", "builtin:sphere"), 2);
    let snake = d.join("snake.glb");
    assert_eq!(rate_of("scaled", snake.to_str().unwrap()), 4);
}
