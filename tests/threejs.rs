//! examples/threejs/load.mjs, the engine hand-off example, run under node with
//! three.js (tests/node/node_modules): it must load the baked GLB (with its
//! `_ORIENTATION` attribute) and the KTX2 pack as a DataArrayTexture, and agree
//! with what the tools themselves report (sunbeam-bake --json, sunbeam-pack --manifest).

use std::process::Command;
use sunbeam::{run_ok, scratch, tool, workspace_root};
use sunbeam_common::testdata;

#[test]
fn threejs_loads_the_baked_glb_and_the_ktx2_pack() {
    if !testdata::have_command("node", &[]) {
        return;
    }
    let modules = workspace_root().join("tests/node/node_modules");
    if !modules.join("three/package.json").exists() {
        if testdata::require_all() {
            panic!("tests/node/node_modules/three missing and SUNBEAM_REQUIRE_ALL=1 (run scripts/ensure-deps.sh)");
        }
        eprintln!("SKIP: three.js not installed in tests/node/node_modules");
        return;
    }
    let d = scratch("threejs");
    let glb = d.join("snake.glb");
    let exr = d.join("elaphe.exr");
    let ktx2 = d.join("elaphe.ktx2");
    let manifest = d.join("elaphe.json");
    let bake = run_ok(
        Command::new(tool("sunbeam-bake"))
            .arg("--generate-snake")
            .arg("-o")
            .arg(&glb)
            .arg("--json"),
    );
    let bake: serde_json::Value = serde_json::from_slice(&bake.stdout).unwrap();
    run_ok(
        Command::new(tool("sunbeam-import"))
            .args(["synthetic:elaphe", "--synthetic-size", "96", "-q", "-o"])
            .arg(&exr),
    );
    run_ok(
        Command::new(tool("sunbeam-pack"))
            .arg(&exr)
            .arg("-o")
            .arg(&ktx2)
            .arg("--manifest")
            .arg(&manifest)
            .arg("-q"),
    );
    let m: serde_json::Value = serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();

    // The example, as a user would run it, next to a node_modules with three.
    let js = d.join("js");
    std::fs::create_dir_all(&js).unwrap();
    std::fs::copy(
        workspace_root().join("examples/threejs/load.mjs"),
        js.join("load.mjs"),
    )
    .unwrap();
    std::os::unix::fs::symlink(&modules, js.join("node_modules")).unwrap();
    let o = run_ok(
        Command::new("node")
            .arg(js.join("load.mjs"))
            .arg(&glb)
            .arg(&ktx2),
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();

    let mesh = &v["mesh"];
    assert_eq!(mesh["vertices"], bake["vertices"]);
    assert_eq!(mesh["triangles"], bake["triangles"]);
    assert_eq!(mesh["orientation_item_size"], 3);
    assert_eq!(mesh["tangent_item_size"], 4);
    assert!(mesh["orientation_max_length_error"].as_f64().unwrap() < 1e-5);
    assert!(mesh["orientation_max_dot_normal"].as_f64().unwrap() < 1e-4);

    let p = &v["pack"];
    assert_eq!(p["is_data_array_texture"], true);
    assert_eq!(p["type"], "FloatType");
    assert_eq!(p["width"], m["crop"]["width"]);
    assert_eq!(p["height"], m["crop"]["height"]);
    assert_eq!(p["depth"], m["terms"]);
    assert_eq!(p["manifest_terms"], m["terms"]);
    assert_eq!(p["manifest_crop"], m["crop"]);
    // Term 0 (T_0 = 1) at frequency 0 is real and positive (the windowed mean, deapodised).
    let t0 = p["term0_centre"].as_array().unwrap();
    assert!(
        t0[0].as_f64().unwrap() > 0.5 && t0[1].as_f64().unwrap().abs() < 1e-6,
        "{t0:?}"
    );
    assert_eq!(v["material"], "ShaderMaterial");
}
