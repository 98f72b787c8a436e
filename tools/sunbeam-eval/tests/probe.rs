//! `probe --truth` against an independent float64 O(M^2) implementation of
//! PHYSICS.md 2 written here, on tiny fields, to 1e-9.
mod common;
use common::*;
use std::f64::consts::PI;

/// PHYSICS.md 2 written out directly: window model and tiled model.
#[allow(clippy::too_many_arguments)]
fn reference(
    w: usize,
    h: usize,
    dx: f64,
    dy: f64,
    z: &[f64],
    tiled: bool,
    coherence: f64,
    q: [f64; 4],
) -> f64 {
    let [u, v, ww, lambda] = q;
    let k = 2.0 * PI / lambda;
    let (fx, fy) = (-u / lambda, -v / lambda);
    // Pixel centres with y up; the patch centre is the mean position.
    let pos = |r: usize, c: usize| (c as f64 * dx, (h - 1 - r) as f64 * dy);
    let (xc, yc) = ((w as f64 - 1.0) * dx / 2.0, (h as f64 - 1.0) * dy / 2.0);
    if !tiled {
        let sigma = (coherence / (4.0 * std::f64::consts::SQRT_2))
            .min((w as f64 * dx).min(h as f64 * dy) / 6.0);
        let (mut re, mut im, mut gs) = (0.0, 0.0, 0.0);
        for r in 0..h {
            for c in 0..w {
                let (x, y) = pos(r, c);
                let (x, y) = (x - xc, y - yc);
                let g = (-(x * x + y * y) / (2.0 * sigma * sigma)).exp();
                let a = k * ww * z[r * w + c] - 2.0 * PI * (fx * x + fy * y);
                re += g * a.cos();
                im += g * a.sin();
                gs += g;
            }
        }
        (re * re + im * im) / (gs * gs)
    } else {
        let sf = 1.0 / (2.0 * PI * (coherence / 4.0));
        let (lx, ly) = (w as f64 * dx, h as f64 * dy);
        let mut total = 0.0;
        for by in -((h / 2) as i64)..(h as i64 - (h / 2) as i64) {
            for bx in -((w / 2) as i64)..(w as i64 - (w / 2) as i64) {
                let (mut re, mut im) = (0.0, 0.0);
                for r in 0..h {
                    for c in 0..w {
                        let (x, y) = pos(r, c);
                        // DFT over sample indices (x/dx, y/dy).
                        let a = k * ww * z[r * w + c]
                            - 2.0
                                * PI
                                * (bx as f64 * (x / dx).round() / w as f64
                                    + by as f64 * (y / dy).round() / h as f64);
                        re += a.cos();
                        im += a.sin();
                    }
                }
                let d2 = (fx - bx as f64 / lx).powi(2) + (fy - by as f64 / ly).powi(2);
                total += (re * re + im * im) * (-d2 / (2.0 * sf * sf)).exp();
            }
        }
        total / ((w * h) as f64).powi(2)
    }
}

#[test]
fn probe_truth_matches_independent_sum() {
    let dir = tmpdir("probe");
    let (w, h, dx, dy) = (7usize, 5usize, 60e-9, 80e-9);
    // Deterministic rough heights, 0..450 nm.
    let z: Vec<f64> = (0..w * h)
        .map(|i| 450e-9 * (((i * 7919 + 13) % 97) as f64 / 96.0))
        .collect();
    let field = dir.join("tiny.txt");
    write_ascii(&field, w, h, &z);
    let mut pts = String::from("# probe points\nu,v,w,lambda_m\n");
    let mut q = Vec::new();
    for i in 0..40 {
        let t = i as f64 * 0.37;
        let p = [
            0.9 * t.sin(),
            0.7 * (1.3 * t).cos(),
            -0.1 - 1.8 * (0.5 + 0.5 * (0.7 * t).sin()),
            380e-9 + 10e-9 * i as f64,
        ];
        pts.push_str(&format!("{:e},{:e},{:e},{:e}\n", p[0], p[1], p[2], p[3]));
        q.push(p);
    }
    pts.push_str("0,0,-2,5.5e-7\n");
    q.push([0.0, 0.0, -2.0, 5.5e-7]);
    let pts_path = dir.join("points.csv");
    std::fs::write(&pts_path, pts).unwrap();
    for (model, coh) in [("window", "65um"), ("tiled", "65um"), ("tiled", "1.5um")] {
        let out = ok(&[
            "probe",
            field.to_str().unwrap(),
            "--points",
            pts_path.to_str().unwrap(),
            "--truth",
            "--pixel-size",
            "60nm,80nm",
            "--model",
            model,
            "--coherence",
            coh,
        ]);
        let got: Vec<f64> = out.lines().map(|l| l.parse().unwrap()).collect();
        assert_eq!(got.len(), q.len());
        let coherence: f64 = if coh == "65um" { 65e-6 } else { 1.5e-6 };
        let mut worst: f64 = 0.0;
        for (g, p) in got.iter().zip(&q) {
            let want = reference(w, h, dx, dy, &z, model == "tiled", coherence, *p);
            worst = worst.max((g - want).abs());
            assert!((g - want).abs() < 1e-9, "{model}: {p:?}: {g} vs {want}");
        }
        eprintln!("{model} coherence {coh}: worst |dR| = {worst:e}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn probe_bad_points_exit_2() {
    let dir = tmpdir("probe-bad");
    let field = dir.join("f.txt");
    write_ascii(&field, 2, 2, &[0.0, 1e-7, 2e-7, 0.0]);
    let pts = dir.join("p.csv");
    std::fs::write(&pts, "0,0,-1,5e-7\n0,0,-1\n").unwrap();
    let o = run(&[
        "probe",
        field.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
        "--pixel-size",
        "50nm",
    ]);
    assert_eq!(o.status.code(), Some(2));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("p.csv") && e.contains("line 2"), "{e}");
    assert!(o.stdout.is_empty());
    // A missing pixel size for an uncalibrated matrix is refused clearly.
    std::fs::write(&pts, "0,0,-1,5e-7\n").unwrap();
    let o = run(&[
        "probe",
        field.to_str().unwrap(),
        "--points",
        pts.to_str().unwrap(),
        "--model",
        "bogus",
    ]);
    assert_eq!(o.status.code(), Some(1));
    std::fs::remove_dir_all(&dir).ok();
}

/// `sunbeam-eval probe ... | head`: when stdout's reader leaves, the tool
/// ends quietly with the shell's status for SIGPIPE (141), not as an
/// internal error. 20000 points print about 400 KB, more than a pipe holds,
/// so the write fails whatever the timing.
#[test]
fn a_closed_pipe_ends_quietly() {
    let dir = tmpdir("probe-pipe");
    let field = dir.join("f.txt");
    write_ascii(&field, 2, 2, &[0.0, 1e-7, 2e-7, 0.0]);
    let pts = dir.join("p.csv");
    std::fs::write(&pts, "0,0,-1,5e-7\n".repeat(20_000)).unwrap();
    let o = std::process::Command::new("bash")
        .arg("-c")
        .arg(r#""$0" probe "$1" --points "$2" --pixel-size 50nm | true; echo "${PIPESTATUS[0]}""#)
        .args([bin(), field.to_str().unwrap(), pts.to_str().unwrap()])
        .output()
        .unwrap();
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert_eq!(out.trim(), "141", "status; stderr: {err}");
    assert!(err.is_empty(), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
