//! The demo pipeline under Ninja (docs/PIPELINE.md): `examples/ninja.sh` writes
//! the graph of examples/Makefile as a Ninja file. Built with the same small
//! variables as make, from private copies of the two snake scans: the outputs
//! are make's byte for byte (depfiles too, kept with `-d keepdepfile`); Ninja
//! records every depfile (`deps = gcc`: `ninja -t deps`); nothing is left to do
//! after a build; touching one scan makes `ninja -n` list exactly its
//! dependents, and the real rebuild touches nothing else.
//!
//! Needs `ninja` (Debian ninja-build, scripts/ensure-deps.sh) and ../shared/data
//! (skipped without them, failing under SUNBEAM_REQUIRE_ALL=1).

mod common;
use common::*;
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, SystemTime};
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

#[test]
fn ninja_builds_what_make_builds_and_rebuilds_only_dependents() {
    if !testdata::have_command("ninja", &["--version"]) {
        return;
    }
    let (Some(elaphe), Some(xeno)) = (
        testdata::shared_file("snake/Elaph100x100.png"),
        testdata::shared_file("snake/Xeno100x100.png"),
    ) else {
        return;
    };
    let d = scratch("ninja");
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
    let (by_make, by_ninja) = (d.join("make"), d.join("ninja"));
    make(2, &vars(&by_make), &goals);

    // Generate the Ninja file with the same variables, and build.
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
    let mut args = vec!["-j2", "-d", "keepdepfile"];
    args.extend_from_slice(&goal_refs);
    ninja(&build_file, &args);

    // Same files, same bytes (depfiles with their folder's name made generic).
    let (m, mut n) = (contents(&by_make), contents(&by_ninja));
    n.remove("build.ninja");
    assert_eq!(
        m.keys().collect::<Vec<_>>(),
        n.keys().collect::<Vec<_>>(),
        "make and ninja built different files"
    );
    for (name, bytes) in &m {
        assert!(bytes == &n[name], "{name}: ninja's differs from make's");
    }
    assert!(m.contains_key("elaphe.ktx2") && m.contains_key("xeno-grating.png"));

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

    // Touch the Elaphe scan: `ninja -n` plans its import, pack, pictures (frame,
    // sheet) and nothing of Xenopeltis or the snake.
    std::thread::sleep(Duration::from_millis(1100)); // coarse mtime file systems
    let f = std::fs::File::options().append(true).open(&scan).unwrap();
    f.set_modified(SystemTime::now()).unwrap();
    drop(f);
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

    // And the rebuild does just that.
    let before = mtimes(&by_ninja);
    let mut args = vec!["-j2", "-d", "keepdepfile"];
    args.extend_from_slice(&goal_refs);
    ninja(&build_file, &args);
    let after = mtimes(&by_ninja);
    for (k, t) in &after {
        let should = k.starts_with("elaphe") && k != "elaphe-scene.json" && k != "elaphe-sky.json"
            || k.starts_with("snake-elaphe.glb")
            || k == "contact-sheet.png";
        assert_eq!(
            before.get(k) != Some(t),
            should,
            "{k}: rebuilt = {}, expected {should}",
            before.get(k) != Some(t)
        );
    }
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
