//! `sunbeam-pack --response`: the response map, the environment's maps and
//! the first-frame cells beside the pack, built from the same pack (its
//! manifest embedded), listed in the depfile and the report, byte-identical
//! across runs and thread counts; bad flags exit 1.

use std::path::{Path, PathBuf};
use std::process::Command;
use sunbeam_field::HeightField;

const BIN: &str = env!("CARGO_BIN_EXE_sunbeam-pack");

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("sb-pack-resp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn height(dir: &Path) -> PathBuf {
    let (w, h) = (40usize, 32usize);
    let d: Vec<f64> = (0..w * h)
        .map(|i| {
            let (c, r) = ((i % w) as f64, (i / w) as f64);
            150e-9 * ((c * 0.9).sin() + 0.3 * (r * 0.4 + c * 0.1).cos())
        })
        .collect();
    let f = HeightField::new(w, h, 25e-9, 25e-9, d).unwrap();
    let p = dir.join("h.exr");
    sunbeam_field::io::write(&p, &f).unwrap();
    p
}

fn pack(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(BIN).args(args).output().unwrap();
    (
        o.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&o.stdout).into(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

#[test]
fn response_map_is_written_beside_the_pack() {
    let d = tmpdir("beside");
    let h = height(&d);
    let out = d.join("skin.ktx2");
    let dep = d.join("skin.d");
    let (code, stdout, stderr) = pack(&[
        h.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--response",
        "--response-lambda",
        "16",
        "--response-cells",
        "8,32",
        "--response-exr",
        d.join("skin.response.exr").to_str().unwrap(),
        "--depfile",
        dep.to_str().unwrap(),
        "--json",
        "-q",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let side = d.join("skin.response.ktx2");
    let map = sunbeam_response::ktx2::read(&side).unwrap();
    let p = sunbeam_pack::Pack::read(&out).unwrap();
    assert_eq!(map.info.pack, p.manifest, "built from the pack beside it");
    assert_eq!(map.info.lambda_samples, 16);
    let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(
        report["response"]["bytes"].as_u64().unwrap() as usize,
        map.byte_len()
    );
    let depfile = std::fs::read_to_string(&dep).unwrap();
    assert!(depfile.contains("skin.response.ktx2"), "{depfile}");
    assert!(depfile.contains("skin.response.exr"), "{depfile}");
    assert!(depfile.contains("skin.env-cells.ktx2"), "{depfile}");
    // The first-frame cells beside the environment's maps, both bases at each
    // count asked for, from this pack and those maps.
    let cells = sunbeam_response::cells_file::read(&d.join("skin.env-cells.ktx2")).unwrap();
    let env = sunbeam_response::env_file::read(&d.join("skin.env-response.ktx2")).unwrap();
    assert_eq!(cells.info.pack, p.manifest);
    assert_eq!(cells.info.grid, env.info.grid);
    let sets: Vec<(String, usize)> = cells
        .info
        .sets
        .iter()
        .map(|s| (s.basis.clone(), s.cells))
        .collect();
    assert_eq!(
        sets,
        [("sky", 8), ("map", 8), ("sky", 32), ("map", 32)].map(|(b, n)| (b.to_string(), n)),
    );
    assert_eq!(report["response"]["cells"].as_array().unwrap().len(), 4);
    let exr = std::fs::read(d.join("skin.response.exr")).unwrap();
    assert_eq!(exr, sunbeam_response::exr::encode(&map).unwrap());
    // Deterministic, whatever the thread count.
    let first = std::fs::read(&side).unwrap();
    let out2 = d.join("again.ktx2");
    let (code, _, stderr) = pack(&[
        h.to_str().unwrap(),
        "-o",
        out2.to_str().unwrap(),
        "--response-out",
        d.join("again.map.ktx2").to_str().unwrap(),
        "--response-lambda",
        "16",
        "--response-cells",
        "32,8,8",
        "--threads",
        "1",
        "-q",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert_eq!(first, std::fs::read(d.join("again.map.ktx2")).unwrap());
    assert_eq!(
        std::fs::read(d.join("skin.env-cells.ktx2")).unwrap(),
        std::fs::read(d.join("again.map.env-cells.ktx2")).unwrap(),
        "the same cells whatever the threads and the counts' order"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn bad_response_budget_is_a_usage_error() {
    let d = tmpdir("budget");
    let h = height(&d);
    let out = d.join("p.ktx2");
    let (code, _, stderr) = pack(&[
        h.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--response",
        "--response-budget",
        "lots",
    ]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stderr.contains("--response-budget"), "{stderr}");
    assert!(!out.exists() && !d.join("p.response.ktx2").exists());
    for bad in ["0", "4097", "512,lots"] {
        let (code, _, stderr) = pack(&[
            h.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--response",
            "--response-cells",
            bad,
        ]);
        assert_eq!(code, 1, "{bad}: {stderr}");
        assert!(stderr.contains("--response-cells"), "{bad}: {stderr}");
        assert!(!out.exists() && !d.join("p.env-cells.ktx2").exists());
    }
    std::fs::remove_dir_all(&d).ok();
}

/// Without `--response-cells` the cells file holds the player's default for
/// the pack (docs/LIGHTING.md "How many cells"): 1024 cells for a patch of
/// 10 um or more, 512 below.
#[test]
fn the_default_cells_follow_the_patchs_size() {
    let d = tmpdir("default-cells");
    for (name, dx, want) in [("small", 25e-9, 512), ("large", 300e-9, 1024)] {
        // 40 x 32 texels: 1 um, or 12 um at 300 nm
        let (w, h) = (40usize, 32usize);
        let z: Vec<f64> = (0..w * h)
            .map(|i| 150e-9 * ((i % w) as f64 * 0.9).sin())
            .collect();
        let f = HeightField::new(w, h, dx, dx, z).unwrap();
        let hp = d.join(format!("{name}.exr"));
        sunbeam_field::io::write(&hp, &f).unwrap();
        let out = d.join(format!("{name}.ktx2"));
        let (code, stdout, stderr) = pack(&[
            hp.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--response",
            "--response-lambda",
            "16",
            "--json",
            "-q",
        ]);
        assert_eq!(code, 0, "{stderr}");
        let cells =
            sunbeam_response::cells_file::read(&out.with_extension("env-cells.ktx2")).unwrap();
        let counts: Vec<usize> = cells.info.sets.iter().map(|s| s.cells).collect();
        assert_eq!(counts, [want, want], "{name}");
        let report: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert!(
            report["response"]["cells"]
                .as_array()
                .unwrap()
                .iter()
                .all(|c| c["cells"] == want),
            "{report}"
        );
    }
}
