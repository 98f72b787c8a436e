//! The examples/ Makefile as artists run it: incremental rebuilds from the
//! tools' depfiles, byte-identical outputs under -j1 and -j2, and an
//! interrupted build (the make process group SIGKILLed while a pack is being
//! written) that leaves no half-written target and is redone by the next run.
//!
//! Small inputs and sizes (make variables) keep it fast. The player's frames
//! are built only where a GPU stack is present (skipped otherwise, failing under
//! SUNBEAM_REQUIRE_ALL=1), the contact sheet only when `sunbeam-eval sheet` exists.

mod common;
use common::*;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};
use sunbeam::{scratch, workspace_root};
use sunbeam_common::testdata;

#[test]
fn parallel_builds_are_byte_identical() {
    let d = scratch("pipeline-parallel");
    let g = goals(&d);
    let bin = bin_dir();
    let (a, b) = (d.join("j1"), d.join("j2"));
    let mut va = small_vars(&bin, &a);
    let mut vb = small_vars(&bin, &b);
    va.push("SHARED=".into());
    vb.push("SHARED=".into());
    make(1, &va, &g);
    make(2, &vb, &g);
    let (ca, cb) = (contents(&a), contents(&b));
    assert_eq!(ca.keys().collect::<Vec<_>>(), cb.keys().collect::<Vec<_>>());
    for name in [
        "elaphe.exr",
        "xeno.ktx2",
        "elaphe-brdf.png",
        "xeno-grating.png",
        "elaphe-height.png",
    ] {
        assert!(ca.contains_key(name), "{name} not built: {:?}", ca.keys());
    }
    for (name, bytes) in &ca {
        assert!(bytes == &cb[name], "{name} differs between -j1 and -j2");
    }
    // Nothing left to do after a full build (make -q: exit 0 when up to date).
    let q = Command::new("make")
        .arg("-C")
        .arg(workspace_root().join("examples"))
        .arg("-q")
        .args(&vb)
        .args(&g)
        .status()
        .unwrap();
    assert!(q.success(), "a second make would rebuild something");
}

/// Touch the Elaphe patch: its height field, pack and pictures (and frame)
/// rebuild (with the snake baked with its pack); Xenopeltis' do not.
#[test]
fn touching_a_scan_rebuilds_only_its_dependents() {
    let (Some(elaphe), Some(xeno)) = (
        testdata::shared_file("snake/Elaph100x100.png"),
        testdata::shared_file("snake/Xeno100x100.png"),
    ) else {
        return;
    };
    let d = scratch("pipeline-incremental");
    // A private copy of the inputs, so touching one does not disturb anyone.
    let shared = d.join("shared");
    std::fs::create_dir_all(shared.join("snake")).unwrap();
    std::fs::copy(&elaphe, shared.join("snake/Elaph100x100.png")).unwrap();
    std::fs::copy(&xeno, shared.join("snake/Xeno100x100.png")).unwrap();
    let out = d.join("out");
    let g = goals(&d);
    let mut vars = small_vars(&bin_dir(), &out);
    vars.push(format!("SHARED={}", shared.display()));
    vars.push("MATERIALS=elaphe xeno".into());
    make(2, &vars, &g);
    let before = mtimes(&out);
    std::thread::sleep(Duration::from_millis(1100)); // coarse mtime file systems
    let f = std::fs::File::options()
        .append(true)
        .open(shared.join("snake/Elaph100x100.png"))
        .unwrap();
    f.set_modified(SystemTime::now()).unwrap();
    drop(f);
    make(2, &vars, &g);
    let after = mtimes(&out);
    let changed: Vec<&String> = after
        .keys()
        .filter(|k| before.get(*k) != after.get(*k))
        .collect();
    for k in after.keys() {
        let should = k.starts_with("elaphe") && k != "elaphe-scene.json" && k != "elaphe-sky.json"
            || k.starts_with("snake-elaphe.glb")
            || k == "contact-sheet.png";
        assert_eq!(
            before.get(k) != after.get(k),
            should,
            "{k}: rebuilt = {}, expected {should}; rebuilt: {changed:?}",
            before.get(k) != after.get(k)
        );
    }
    assert!(changed.iter().any(|k| *k == "elaphe.ktx2"), "{changed:?}");
}

/// Process group of a process, from /proc (Linux).
fn pgrp_of(pid: &str) -> Option<u32> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // "pid (comm) state ppid pgrp ...": fields after the last ')'.
    stat.rsplit_once(')')?
        .1
        .split_whitespace()
        .nth(2)?
        .parse()
        .ok()
}

/// SIGKILL every process of the group `pgid` (make and the tool it runs), one by
/// one by id; never our own group.
fn kill_group(pgid: u32) {
    let own = pgrp_of("self");
    assert_ne!(
        own,
        Some(pgid),
        "refusing to kill the test's own process group"
    );
    let pids: Vec<String> = std::fs::read_dir("/proc")
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.bytes().all(|b| b.is_ascii_digit()))
        .filter(|n| pgrp_of(n) == Some(pgid))
        .collect();
    for pid in pids {
        let _ = Command::new("kill").args(["-KILL", &pid]).status();
    }
}

fn ktx2_complete(path: &Path) -> bool {
    let b = std::fs::read(path).unwrap();
    let magic = b"\xABKTX 20\xBB\r\n\x1A\n";
    if b.len() < 104 || &b[..12] != magic {
        return false;
    }
    let u64at = |o: usize| u64::from_le_bytes(b[o..o + 8].try_into().unwrap()) as usize;
    // Level 0 of the level index (one level): byteOffset, byteLength.
    let (off, len) = (u64at(80), u64at(88));
    off + len == b.len()
}

#[test]
fn interrupted_build_keeps_nothing_half_written_and_is_redone() {
    let d = scratch("pipeline-interrupt");
    let out = d.join("out");
    let mut vars = small_vars(&bin_dir(), &out);
    // A larger field so the pack takes a moment; no frames needed here.
    vars.retain(|v| !v.starts_with("SYNTH_SIZE="));
    vars.push("SYNTH_SIZE=384".into());
    vars.push("SHARED=".into());
    let goals = ["packs".to_string()];
    let mut child = {
        use std::os::unix::process::CommandExt;
        Command::new("make")
            .arg("-C")
            .arg(workspace_root().join("examples"))
            .arg("-j2")
            .args(&vars)
            .args(&goals)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .process_group(0)
            .spawn()
            .unwrap()
    };
    let pgid = child.id();
    // Kill the whole group as soon as a pack's temp file appears (mid-write); if
    // none is seen within 60 ms of a pack starting (its input exists), kill it mid-run.
    let t0 = Instant::now();
    let mut started: Option<Instant> = None;
    let mut exited = false;
    let mut how = "not caught (make finished first)";
    while t0.elapsed() < Duration::from_secs(120) {
        if child.try_wait().unwrap().is_some() {
            exited = true;
            break;
        }
        let names: Vec<String> = std::fs::read_dir(&out)
            .map(|r| {
                r.filter_map(|e| e.ok())
                    .map(|e| e.file_name().to_string_lossy().into_owned())
                    .collect()
            })
            .unwrap_or_default();
        if names
            .iter()
            .any(|n| n.starts_with('.') && n.contains(".ktx2.tmp."))
        {
            how = "while a pack was being written";
            break;
        }
        if started.is_none() && names.iter().any(|n| n == "xeno.exr" || n == "elaphe.exr") {
            started = Some(Instant::now());
        }
        if started.is_some_and(|s| s.elapsed() > Duration::from_millis(60)) {
            how = "while a pack was running";
            break;
        }
        std::thread::sleep(Duration::from_micros(200));
    }
    if !exited {
        kill_group(pgid);
    }
    let _ = child.wait();
    eprintln!(
        "killed make {how} after {:.2} s",
        t0.elapsed().as_secs_f64()
    );
    // Whatever exists under a target's name is complete.
    for name in ["elaphe.ktx2", "xeno.ktx2"] {
        let p = out.join(name);
        if p.exists() {
            assert!(ktx2_complete(&p), "{name} is half-written");
        }
    }
    // The next run redoes what was cut off and leaves no temp files of those rules.
    let o = make(2, &vars, &goals);
    for name in ["elaphe.ktx2", "xeno.ktx2"] {
        assert!(
            ktx2_complete(&out.join(name)),
            "{name} missing or incomplete after the rerun"
        );
    }
    let stray: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains(".ktx2.tmp."))
        .collect();
    assert!(
        stray.is_empty(),
        "temp files left: {stray:?}\n{}",
        String::from_utf8_lossy(&o.stdout)
    );
    // And the result equals a clean build's.
    let clean = d.join("clean");
    let mut cv = vars.clone();
    cv.retain(|v| !v.starts_with("OUT="));
    cv.push(format!("OUT={}", clean.display()));
    make(1, &cv, &goals);
    for name in ["elaphe.ktx2", "xeno.ktx2", "elaphe.exr", "xeno.exr"] {
        assert!(
            std::fs::read(out.join(name)).unwrap() == std::fs::read(clean.join(name)).unwrap(),
            "{name} differs from a clean build"
        );
    }
}

/// `make demo` when cargo builds elsewhere (issue 14, item 2): with
/// `CARGO_TARGET_DIR` (or `build.target-dir`, here as `CARGO_BUILD_TARGET_DIR`)
/// outside the checkout, the top Makefile asks cargo for its target directory
/// and hands `DIR/release` to examples/. Cheap: that folder holds wrappers of
/// the tools already built (which record that they ran), `-o deps -o build`
/// skips the install and build steps, and only the synthetic height fields are made.
#[test]
fn demo_uses_the_folder_cargo_builds_into() {
    use std::os::unix::fs::PermissionsExt;
    let d = scratch("pipeline-target-dir");
    let target = std::env::temp_dir().join(format!("sunbeam-target-dir-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&target);
    let rel = target.join("release");
    std::fs::create_dir_all(&rel).unwrap();
    let log = d.join("ran.log");
    for name in [
        "sunbeam-import",
        "sunbeam-pack",
        "sunbeam-bake",
        "sunbeam-play",
        "sunbeam-eval",
    ] {
        let w = rel.join(name);
        std::fs::write(
            &w,
            format!(
                "#!/bin/sh\necho {name} >> '{}'\nexec '{}' \"$@\"\n",
                log.display(),
                bin_dir().join(name).display()
            ),
        )
        .unwrap();
        std::fs::set_permissions(&w, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    for var in ["CARGO_TARGET_DIR", "CARGO_BUILD_TARGET_DIR"] {
        let _ = std::fs::remove_file(&log);
        let out = d.join(format!("out-{var}"));
        let o = Command::new("make")
            .arg("-C")
            .arg(workspace_root())
            .args(["demo", "-o", "deps", "-o", "build", "DEMO_GOALS=fields"])
            .args(small_vars(&bin_dir(), &out).iter().skip(1)) // not BIN: the Makefile finds it
            .arg("SHARED=")
            .env_remove("CARGO_TARGET_DIR")
            .env_remove("CARGO_BUILD_TARGET_DIR")
            .env(var, &target)
            .output()
            .expect("run make");
        let said = format!(
            "{}\n{}",
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(o.status.success(), "{var}: make demo failed:\n{said}");
        let ran = std::fs::read_to_string(&log).unwrap_or_default();
        assert!(
            ran.lines().any(|l| l == "sunbeam-import"),
            "{var}={}: make demo did not run the tools cargo built there:\n{said}",
            target.display()
        );
        assert!(out.join("elaphe.exr").is_file() && out.join("xeno.exr").is_file());
    }
    std::fs::remove_dir_all(&target).ok();
}
