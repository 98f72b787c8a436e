//! `compare` and `brdf` on packs built in process from a small field.
mod common;
use common::*;
use sunbeam_pack::{Basis, BuildOptions, FieldRef, Precision};

fn field() -> (usize, usize, Vec<f64>) {
    // Ridges 1 um apart along y, wavy along x, 64 x 64 at 40 nm, 0..300 nm.
    let n = 64;
    let mut z = Vec::new();
    for r in 0..n {
        for c in 0..n {
            let (x, y) = (c as f64 * 40e-9, (n - 1 - r) as f64 * 40e-9);
            let ph = 2.0 * std::f64::consts::PI * (y / 1e-6 + 0.2 * (x / 1.3e-6).sin());
            z.push(150e-9 * (1.0 + 0.8 * ph.sin() + 0.2 * (2.0 * ph).sin()) / 1.2);
        }
    }
    (n, n, z)
}

fn pack(
    dir: &std::path::Path,
    name: &str,
    basis: Basis,
    precision: Precision,
    terms: Option<usize>,
) -> std::path::PathBuf {
    let (w, h, z) = field();
    let o = BuildOptions {
        basis,
        precision,
        terms,
        threads: 1,
        ..BuildOptions::default()
    };
    let p = sunbeam_pack::build(
        FieldRef {
            width: w,
            height: h,
            dx: 40e-9,
            dy: 40e-9,
            data: &z,
        },
        &o,
        &mut |_, _| {},
    )
    .expect("pack builds");
    let path = dir.join(name);
    std::fs::write(&path, sunbeam_pack::ktx2::encode(&p, "test")).unwrap();
    path
}

#[test]
fn compare_passes_and_fails() {
    let dir = tmpdir("compare");
    let (w, h, z) = field();
    let hf = dir.join("h.txt");
    write_ascii(&hf, w, h, &z);
    let good = pack(&dir, "good.ktx2", Basis::Chebyshev, Precision::F32, None);
    let args = |p: &std::path::Path| {
        vec![
            "compare".to_string(),
            p.display().to_string(),
            hf.display().to_string(),
            "--pixel-size".into(),
            "40nm".into(),
            "--points".into(),
            "300".into(),
            "--views".into(),
            "16".into(),
            "--light".into(),
            "45deg,90deg".into(),
            "--json".into(),
        ]
    };
    let a = args(&good);
    let out = ok(&a.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    let v: serde_json::Value = serde_json::from_str(out.trim()).unwrap();
    let max = v["spectral"]["max_abs_dR"].as_f64().unwrap();
    assert!(max < 1e-4, "default pack error {max}");
    assert!(v["colour"]["de_p99"].as_f64().unwrap() < 1.0);
    assert_eq!(v["pass"], true);
    // Too few terms: the truncated series is far off and compare exits 5.
    let bad = pack(&dir, "bad.ktx2", Basis::Taylor, Precision::F16, Some(3));
    let a = args(&bad);
    let o = run(&a.iter().map(|s| s.as_str()).collect::<Vec<_>>());
    assert_eq!(
        o.status.code(),
        Some(5),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(String::from_utf8_lossy(&o.stdout).trim()).unwrap();
    assert_eq!(v["pass"], false);
    // brdf draws a picture.
    let png = dir.join("brdf.png");
    ok(&[
        "brdf",
        good.to_str().unwrap(),
        "--light",
        "45deg,90deg",
        "-o",
        png.to_str().unwrap(),
        "--size",
        "48",
    ]);
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"));
    // A pack is refused where the truth is asked for.
    let pts = dir.join("p.csv");
    std::fs::write(&pts, "0,0,-2,5e-7\n").unwrap();
    let o = run(&[
        "probe",
        good.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
        "--truth",
    ]);
    assert_eq!(o.status.code(), Some(1));
    // ... and evaluated by its own evaluator otherwise: specular of a pack is close to the truth.
    let rp: f64 = ok(&[
        "probe",
        good.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
    ])
    .trim()
    .parse()
    .unwrap();
    let rt: f64 = ok(&[
        "probe",
        hf.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
        "--pixel-size",
        "40nm",
    ])
    .trim()
    .parse()
    .unwrap();
    assert!((rp - rt).abs() < 1e-4, "{rp} vs {rt}");
    // render: the CPU reference image of the default scene of a quad with this pack.
    let obj = dir.join("quad.obj");
    std::fs::write(
        &obj,
        "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
         f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    let frame = dir.join("frame.png");
    ok(&[
        "render",
        "--mesh",
        obj.to_str().unwrap(),
        "--pack",
        good.to_str().unwrap(),
        "--size",
        "32x24",
        "-o",
        frame.to_str().unwrap(),
    ]);
    let b = std::fs::read(&frame).unwrap();
    assert!(b.starts_with(b"\x89PNG"));
    assert_eq!(u32::from_be_bytes([b[16], b[17], b[18], b[19]]), 32);
    assert_eq!(u32::from_be_bytes([b[20], b[21], b[22], b[23]]), 24);
    std::fs::remove_dir_all(&dir).ok();
}
