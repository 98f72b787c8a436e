//! Helpers shared by the pipeline tests (tests/pipeline.rs):
//! small make variables, what this machine can build, folder contents; the
//! three.js tests' in [`threejs`].
#![allow(dead_code)]

pub mod threejs;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::SystemTime;
use sunbeam::{tool, workspace_root};
use sunbeam_common::testdata;

/// Small-size variables for every run.
pub fn small_vars(bin: &Path, out: &Path) -> Vec<String> {
    vec![
        format!("BIN={}", bin.display()),
        format!("OUT={}", out.display()),
        "SYNTH_SIZE=64".into(),
        "SYNTH_PIXEL=25nm".into(),
        "BRDF_SIZE=40".into(),
        "SIZE=96x54".into(),
        "PLAY_SKY_FRAMES=2".into(),
        // The sky frames' cost, not their accuracy, matters here: the
        // player's first frame with 16 cells (4 s -> 0.9 s at 96 x 54), the
        // reference at 4 samples per pixel.
        "PLAY_FIRST_CELLS=16".into(),
        "SKY_SAMPLES=4".into(),
        "Q=-q".into(),
    ]
}

pub fn bin_dir() -> PathBuf {
    tool("sunbeam-import").parent().unwrap().to_path_buf()
}

/// Does the player render here? (`sunbeam-play` built and a GPU adapter, e.g. lavapipe.)
pub fn player_works(dir: &Path) -> bool {
    let play = bin_dir().join("sunbeam-play");
    let ok = play.exists()
        && Command::new(&play)
            .args([
                "--mesh",
                "builtin:quad",
                "--headless",
                "--size",
                "8x8",
                "-q",
                "-o",
            ])
            .arg(dir.join("probe.png"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
    if !ok {
        if testdata::require_all() {
            panic!("sunbeam-play cannot render headless and SUNBEAM_REQUIRE_ALL=1 (install mesa-vulkan-drivers)");
        }
        eprintln!("SKIP: frames (sunbeam-play cannot render headless here)");
    }
    ok
}

pub fn sheet_works() -> bool {
    let ok = Command::new(bin_dir().join("sunbeam-eval"))
        .args(["sheet", "--help"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        eprintln!("SKIP: contact sheet (this sunbeam-eval has no `sheet` subcommand yet)");
    }
    ok
}

/// The make goals to build: everything this machine can build.
pub fn goals(scratch_dir: &Path) -> Vec<String> {
    let mut g: Vec<String> = ["fields", "packs", "pictures"].map(String::from).to_vec();
    let frames = player_works(scratch_dir);
    if frames {
        g.push("frames".into());
    }
    if frames && sheet_works() {
        g.push("sheet".into());
    }
    g
}

pub fn make(jobs: usize, vars: &[String], goals: &[String]) -> std::process::Output {
    let o = Command::new("make")
        .arg("-C")
        .arg(workspace_root().join("examples"))
        .arg(format!("-j{jobs}"))
        .args(vars)
        .args(goals)
        .output()
        .expect("run make");
    assert!(
        o.status.success(),
        "make failed:\n{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Visible files of a folder (name -> bytes), depfiles with the folder's path made generic.
pub fn contents(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut m = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || !e.file_type().unwrap().is_file() {
            continue;
        }
        let mut bytes = std::fs::read(e.path()).unwrap();
        if name.ends_with(".d") {
            bytes = String::from_utf8(bytes)
                .unwrap()
                .replace(&dir.display().to_string(), "OUT")
                .into_bytes();
        }
        m.insert(name, bytes);
    }
    m
}

pub fn mtimes(dir: &Path) -> BTreeMap<String, SystemTime> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
        .map(|e| {
            (
                e.file_name().to_string_lossy().into_owned(),
                e.metadata().unwrap().modified().unwrap(),
            )
        })
        .collect()
}
