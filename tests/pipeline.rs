//! The examples/ Makefile as artists run it, and its Ninja file
//! (`examples/ninja.sh`, docs/PIPELINE.md): incremental rebuilds from the
//! tools' depfiles, byte-identical outputs under make -j2 and a serial Ninja,
//! and an interrupted build (the make process group SIGKILLed while a pack is
//! being written) that leaves no half-written target and is redone by the next run.
//!
//! Small inputs and sizes (make variables) keep it fast. The player's frames
//! are built only where a GPU stack is present (skipped otherwise, failing under
//! SUNBEAM_REQUIRE_ALL=1), the contact sheet only when `sunbeam-eval sheet` exists.

mod common;
use common::*;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};
use sunbeam::{scratch, workspace_root};
use sunbeam_common::testdata;

/// `ninja -C examples -f OUT/build.ninja ARGS` (paths in the file are relative
/// to examples/, as make sees them); its stdout. Panics when it fails.
fn ninja(build_file: &Path, args: &[&str]) -> String {
    let o = Command::new("ninja")
        .arg("-C")
        .arg(workspace_root().join("examples"))
        .arg("-f")
        .arg(build_file)
        .args(args)
        .output()
        .expect("run ninja");
    let said = format!(
        "{}\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(o.status.success(), "ninja {args:?} failed:\n{said}");
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// The steps `ninja -n` would run: the descriptions after `[i/n] `.
fn planned(build_file: &Path, goals: &[&str]) -> BTreeSet<String> {
    let mut args = vec!["-n"];
    args.extend_from_slice(goals);
    ninja(build_file, &args)
        .lines()
        .filter_map(|l| l.split_once("] ").map(|(_, d)| d.to_string()))
        .collect()
}

/// `make -q`: exit 0 when everything is up to date.
fn make_up_to_date(vars: &[String], goals: &[String]) -> bool {
    Command::new("make")
        .arg("-C")
        .arg(workspace_root().join("examples"))
        .arg("-q")
        .args(vars)
        .args(goals)
        .status()
        .unwrap()
        .success()
}

/// Outputs whose mtime changed between two snapshots must be exactly Elaphe's
/// (not its scene files), its snake and the sheet.
fn only_elaphe_rebuilt(
    before: &BTreeMap<String, SystemTime>,
    after: &BTreeMap<String, SystemTime>,
    who: &str,
) {
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
            "{who}: {k}: rebuilt = {}, expected {should}; rebuilt: {changed:?}",
            before.get(k) != after.get(k)
        );
    }
    assert!(changed.iter().any(|k| *k == "elaphe.ktx2"), "{changed:?}");
}

/// The demo from private copies of the two snake scans, built two ways:
/// `make -j2` and the Ninja file (`examples/ninja.sh`) run serially, `ninja
/// -j1`. Every file is byte-identical across the two (depfiles too, kept with
/// `-d keepdepfile`), so neither the build tool nor running jobs at once
/// changes a byte; `make -q` and `ninja -n` find nothing to do; Ninja
/// recorded the depfiles (`deps = gcc`: `ninja -t deps`). Then the Elaphe scan
/// is touched: make rebuilds exactly its dependents, `ninja -n` plans exactly
/// them, and Ninja's rebuild (`-j2`) touches nothing else. One set of builds
/// serves the three properties (each full build is about a minute on 2 cores;
/// a third, `make -j1`, would check nothing these two do not).
///
/// Needs `ninja` (Debian ninja-build, scripts/ensure-deps.sh) and ../shared/data
/// (skipped without them, failing under SUNBEAM_REQUIRE_ALL=1).
#[test]
fn make_and_ninja_build_the_same_bytes_and_rebuild_only_dependents() {
    if !testdata::have_command("ninja", &["--version"]) {
        return;
    }
    let (Some(elaphe), Some(xeno)) = (
        testdata::shared_file("snake/Elaph100x100.png"),
        testdata::shared_file("snake/Xeno100x100.png"),
    ) else {
        return;
    };
    let d = scratch("pipeline-builds");
    // A private copy of the inputs, so touching one does not disturb anyone.
    let shared = d.join("shared");
    std::fs::create_dir_all(shared.join("snake")).unwrap();
    let scan = shared.join("snake/Elaph100x100.png");
    std::fs::copy(&elaphe, &scan).unwrap();
    std::fs::copy(&xeno, shared.join("snake/Xeno100x100.png")).unwrap();
    let goals = goals(&d);
    let goal_refs: Vec<&str> = goals.iter().map(String::as_str).collect();
    let vars = |out: &Path| {
        let mut v = small_vars(&bin_dir(), out);
        v.push(format!("SHARED={}", shared.display()));
        v.push("MATERIALS=elaphe xeno".into());
        v
    };
    let (j2, by_ninja) = (d.join("j2"), d.join("ninja"));
    make(2, &vars(&j2), &goals);

    // The Ninja file, generated with the same variables, and its build.
    let g = Command::new(workspace_root().join("examples/ninja.sh"))
        .args(vars(&by_ninja))
        .output()
        .expect("run examples/ninja.sh");
    assert!(
        g.status.success(),
        "ninja.sh failed: {}",
        String::from_utf8_lossy(&g.stderr)
    );
    let build_file = by_ninja.join("build.ninja");
    let mut serial = vec!["-j1", "-d", "keepdepfile"];
    serial.extend_from_slice(&goal_refs);
    ninja(&build_file, &serial);

    // Same files, same bytes (depfiles with their folder's name made generic).
    let (a, mut n) = (contents(&j2), contents(&by_ninja));
    n.remove("build.ninja");
    for name in [
        "elaphe.exr",
        "xeno.ktx2",
        "elaphe-brdf.png",
        "xeno-grating.png",
        "elaphe-height.png",
    ] {
        assert!(a.contains_key(name), "{name} not built: {:?}", a.keys());
    }
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        n.keys().collect::<Vec<_>>(),
        "make -j2 and ninja -j1 built different files"
    );
    for (name, bytes) in &a {
        assert!(
            bytes == &n[name],
            "{name}: ninja -j1's differs from make -j2's"
        );
    }
    assert!(
        make_up_to_date(&vars(&j2), &goals),
        "a second make would rebuild something"
    );

    // deps = gcc: Ninja read the depfiles into its log (the scan, for the import).
    let deps = ninja(&build_file, &["-t", "deps"]);
    let import_deps = deps
        .split("\n\n")
        .find(|b| b.contains("elaphe.exr") && b.contains("#deps"))
        .unwrap_or_else(|| panic!("no deps recorded for elaphe.exr:\n{deps}"));
    assert!(
        import_deps.contains("(VALID)") && import_deps.contains("Elaph100x100.png"),
        "{import_deps}"
    );
    assert!(
        deps.contains("elaphe.ktx2")
            && deps.contains("elaphe-frame.png") == goals.iter().any(|g| g == "frames"),
        "{deps}"
    );
    assert!(
        planned(&build_file, &goal_refs).is_empty(),
        "ninja -n wants to redo work after a build"
    );

    // Touch the Elaphe scan: make rebuilds its import, pack, pictures (frames,
    // sheet) and nothing of Xenopeltis or the other snake.
    let (before_make, before_ninja) = (mtimes(&j2), mtimes(&by_ninja));
    std::thread::sleep(Duration::from_millis(1100)); // coarse mtime file systems
    let f = std::fs::File::options().append(true).open(&scan).unwrap();
    f.set_modified(SystemTime::now()).unwrap();
    drop(f);
    make(2, &vars(&j2), &goals);
    only_elaphe_rebuilt(&before_make, &mtimes(&j2), "make");

    // `ninja -n` plans just that, and its rebuild does just that.
    let plan = planned(&build_file, &goal_refs);
    let o = by_ninja.display().to_string();
    let mut want: BTreeSet<String> = [
        "import elaphe".to_string(),
        format!("pack {o}/elaphe.ktx2"),
        format!("brdf {o}/elaphe-brdf.png"),
        format!("grating {o}/elaphe-grating.png"),
    ]
    .into();
    if goals.iter().any(|g| g == "frames") {
        want.insert(format!("play {o}/elaphe-frame.png"));
        want.insert(format!("sky {o}/elaphe-sky.png"));
        want.insert(format!("play_sky {o}/elaphe-play-sky.png"));
        want.insert(format!("play_first {o}/elaphe-play-first.png"));
        // the frames show the snake with Elaphe's scales, baked with its pack
        want.insert(format!("bake {o}/snake-elaphe.glb"));
    }
    if goals.iter().any(|g| g == "sheet") {
        want.insert(format!("sheet {o}/contact-sheet.png"));
    }
    assert_eq!(plan, want, "ninja -n after touching the Elaphe scan");
    let mut args = vec!["-j2", "-d", "keepdepfile"];
    args.extend_from_slice(&goal_refs);
    ninja(&build_file, &args);
    only_elaphe_rebuilt(&before_ninja, &mtimes(&by_ninja), "ninja");
    assert!(planned(&build_file, &goal_refs).is_empty());
}

/// The viewer's environments (examples/Makefile ENVS, docs/PIPELINE.md): make
/// and the Ninja file plan the same exports for `web`, the studio one only
/// with an HDR image (HDRI), and the sky alone without it. Plans only (`-n`),
/// nothing is built.
#[test]
fn ninja_and_make_plan_the_same_environments() {
    if !testdata::have_command("ninja", &["--version"]) {
        return;
    }
    let d = scratch("ninja-envs");
    let hdri = d.join("studio.exr");
    std::fs::write(&hdri, b"not read: plans only").unwrap();
    for (with_map, want) in [(true, ["sky", "studio"].as_slice()), (false, &["sky"])] {
        let out = d.join(format!("out-{with_map}"));
        let mut vars = small_vars(&bin_dir(), &out);
        vars.push("SHARED=".into());
        vars.push(format!(
            "HDRI={}",
            if with_map {
                hdri.display().to_string()
            } else {
                String::new()
            }
        ));
        let g = Command::new(workspace_root().join("examples/ninja.sh"))
            .args(&vars)
            .output()
            .expect("run examples/ninja.sh");
        assert!(g.status.success(), "{}", String::from_utf8_lossy(&g.stderr));
        let ninja_plan: BTreeSet<String> = planned(&out.join("build.ninja"), &["web"])
            .into_iter()
            .filter_map(|s| s.strip_prefix("export_environment ").map(String::from))
            .collect();
        let o = Command::new("make")
            .arg("-C")
            .arg(workspace_root().join("examples"))
            .arg("-n")
            .args(&vars)
            .arg("web")
            .output()
            .expect("run make -n");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let make_plan: BTreeSet<String> = String::from_utf8_lossy(&o.stdout)
            .lines()
            .filter_map(|l| l.split_once("--export-environment "))
            .map(|(_, r)| r.split_whitespace().next().unwrap().to_string())
            .collect();
        let o = out.display();
        let expected: BTreeSet<String> = want
            .iter()
            .flat_map(|e| ["elaphe", "xeno"].map(|m| format!("{o}/env-{e}-{m}")))
            .collect();
        assert_eq!(make_plan, expected, "make -n web");
        assert_eq!(ninja_plan, expected, "ninja -n web");
    }
}

/// Process group and state of a process, from /proc (Linux).
fn pgrp_of(pid: &str) -> Option<u32> {
    stat_of(pid).map(|(pgrp, _)| pgrp)
}

/// `(pgrp, state)` of a process from /proc/PID/stat ("pid (comm) state ppid
/// pgrp ...": fields after the last ')').
fn stat_of(pid: &str) -> Option<(u32, char)> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let mut f = stat.rsplit_once(')')?.1.split_whitespace();
    let state = f.next()?.chars().next()?;
    let pgrp = f.nth(1)?.parse().ok()?;
    Some((pgrp, state))
}

/// Live (not zombie) processes of the group `pgid`.
fn group_members(pgid: u32) -> Vec<String> {
    std::fs::read_dir("/proc")
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.bytes().all(|b| b.is_ascii_digit()))
        .filter(|n| matches!(stat_of(n), Some((g, st)) if g == pgid && st != 'Z'))
        .collect()
}

/// SIGKILL the process group `pgid` (make and the tools it runs) with one
/// signal to the group (`kill -KILL -- -PGID`), never our own group, and wait
/// until none of it runs. One signal reaches every member, and a fork racing
/// with it fails; a kill per listed process missed the child make forked
/// between the listing and its own death (a pack ran on, and its temp file
/// appeared during the rerun: CI, 2026-12-02).
fn kill_group(pgid: u32) {
    let own = pgrp_of("self");
    assert_ne!(
        own,
        Some(pgid),
        "refusing to kill the test's own process group"
    );
    let _ = Command::new("kill")
        .args(["-KILL", "--", &format!("-{pgid}")])
        .status();
    let t = Instant::now();
    while !group_members(pgid).is_empty() && t.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(10));
    }
    let left = group_members(pgid);
    assert!(
        left.is_empty(),
        "processes of group {pgid} still run: {left:?}"
    );
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
    // A killed run may leave the temp file of any of a rule's outputs (the
    // pack rule writes three): plant one for each of Xeno's and make the
    // rule run again (its pack gone), as a kill during its last write would.
    let _ = std::fs::remove_file(out.join("xeno.ktx2"));
    for f in [
        "xeno.ktx2",
        "xeno.response.ktx2",
        "xeno.env-response.ktx2",
        "xeno.env-cells.ktx2",
    ] {
        std::fs::write(out.join(format!(".{f}.tmp.1")), b"stale").unwrap();
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
