//! `sunbeam-eval diff`: which pixels count (lit in the reference), the split
//! into interior and edge (`sunbeam_frame::linear::interior_pixels`: all nine
//! of a pixel's 3 x 3 block lit), the heat map and bad input.

mod common;
use common::*;
use sunbeam_optics::colour;
use sunbeam_raster::LinearImage;

const GREY: [f32; 3] = [0.5, 0.5, 0.5];
const RED: [f32; 3] = [0.5, 0.2, 0.2];

/// 5 x 5, grey, pixel (0, 0) black: 24 lit pixels, of which the 3 x 3 block
/// (1..=3, 1..=3) without (1, 1) (next to the dark corner) is interior (8).
fn reference() -> LinearImage {
    let mut r = LinearImage::new(5, 5);
    r.rgb.iter_mut().for_each(|p| *p = GREY);
    r.rgb[0] = [0.0; 3];
    r
}

fn stats(v: &serde_json::Value, part: &str) -> (f64, f64, f64, u64) {
    let s = &v[part];
    (
        s["mean"].as_f64().unwrap(),
        s["p99"].as_f64().unwrap(),
        s["max"].as_f64().unwrap(),
        s["pixels"].as_u64().unwrap(),
    )
}

#[test]
fn diff_counts_lit_pixels_and_splits_interior_and_edge() {
    let d = tmpdir("diff");
    let (a, r, heat) = (d.join("a.exr"), d.join("r.exr"), d.join("heat.png"));
    reference().write_exr(&r).unwrap();
    let mut im = reference();
    im.rgb[2 * 5 + 2] = RED; // interior
    im.rgb[0] = [9.0, 9.0, 9.0]; // unlit in the reference: not counted
    im.write_exr(&a).unwrap();
    let de = colour::ciede2000_xyz(
        colour::linear_srgb_to_xyz(RED.map(f64::from)),
        colour::linear_srgb_to_xyz(GREY.map(f64::from)),
    );
    assert!(de > 10.0, "{de}");
    let out = ok(&[
        "diff",
        a.to_str().unwrap(),
        r.to_str().unwrap(),
        "--json",
        "--heatmap",
        heat.to_str().unwrap(),
        "--scale",
        "5",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (mean, _, max, n) = stats(&v, "all");
    assert_eq!(n, 24);
    assert!((max - de).abs() < 1e-9 && (mean - de / 24.0).abs() < 1e-9);
    let (mean, p99, max, n) = stats(&v, "interior");
    assert_eq!(n, 8);
    assert!((max - de).abs() < 1e-9 && (p99 - de).abs() < 1e-9 && (mean - de / 8.0).abs() < 1e-9);
    let (mean, _, max, n) = stats(&v, "edge");
    assert_eq!((n, mean, max), (16, 0.0, 0.0));

    // The heat map: the changed pixel at the top of the scale (yellow), the
    // others black, the unlit corner dark blue.
    let dec = png::Decoder::new(std::fs::File::open(&heat).unwrap());
    let mut reader = dec.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height), (5, 5));
    let ch = info.color_type.samples();
    let px = |i: usize| &buf[i * ch..i * ch + 3];
    assert_eq!(px(12), [255, 255, 0]);
    assert_eq!(px(0)[..2], [0, 0]);
    assert!(px(0)[2] > 0);
    assert_eq!(px(6), [0, 0, 0]);

    // Text report: three lines.
    let text = ok(&["diff", a.to_str().unwrap(), r.to_str().unwrap()]);
    assert_eq!(text.lines().count(), 3, "{text}");
    assert!(
        text.contains("over 24 px") && text.contains("over 8 px"),
        "{text}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn diff_refuses_different_sizes_and_missing_files() {
    let d = tmpdir("diff-bad");
    let (a, r, heat) = (d.join("a.exr"), d.join("r.exr"), d.join("heat.png"));
    reference().write_exr(&r).unwrap();
    LinearImage::new(4, 5).write_exr(&a).unwrap();
    let o = run(&[
        "diff",
        a.to_str().unwrap(),
        r.to_str().unwrap(),
        "--heatmap",
        heat.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("a.exr") && err.contains("4x5"), "{err}");
    assert!(!heat.exists(), "no output on error");
    let o = run(&[
        "diff",
        d.join("none.exr").to_str().unwrap(),
        r.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("none.exr"));
    let o = run(&[
        "diff",
        a.to_str().unwrap(),
        r.to_str().unwrap(),
        "--scale",
        "0",
    ]);
    assert_eq!(o.status.code(), Some(1), "a usage error");
    std::fs::remove_dir_all(&d).ok();
}

/// `--mask`: only the pixels lit in the mask count, and the interior comes
/// from the mask's lit area; a mask of another size exits 2 naming it.
#[test]
fn diff_judges_only_the_masks_pixels() {
    let d = tmpdir("diff-mask");
    let (a, r, m) = (d.join("a.exr"), d.join("r.exr"), d.join("m.exr"));
    // Every pixel of the reference lit (a background drawn behind).
    let mut full = LinearImage::new(5, 5);
    full.rgb.iter_mut().for_each(|p| *p = GREY);
    full.write_exr(&r).unwrap();
    // The object: the 4 x 4 block from (1, 1); its interior (2..=3, 2..=3).
    let mut mask = LinearImage::new(5, 5);
    for y in 1..5 {
        for x in 1..5 {
            mask.rgb[y * 5 + x] = GREY;
        }
    }
    mask.write_exr(&m).unwrap();
    let mut im = full.clone();
    im.rgb[0] = RED; // the background: not judged
    im.rgb[2 * 5 + 2] = RED; // the object's interior
    im.write_exr(&a).unwrap();
    let out = ok(&[
        "diff",
        a.to_str().unwrap(),
        r.to_str().unwrap(),
        "--mask",
        m.to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(stats(&v, "all").3, 16);
    let (_, _, max, n) = stats(&v, "interior");
    assert_eq!(n, 4);
    assert!(max > 10.0, "{max}");
    assert_eq!(stats(&v, "edge").2, 0.0);
    // Without the mask the background's pixel counts.
    let out = ok(&["diff", a.to_str().unwrap(), r.to_str().unwrap(), "--json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(stats(&v, "all").3, 25);
    assert!(stats(&v, "edge").2 > 10.0);

    LinearImage::new(4, 5).write_exr(&m).unwrap();
    let o = run(&[
        "diff",
        a.to_str().unwrap(),
        r.to_str().unwrap(),
        "--mask",
        m.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("m.exr") && err.contains("4x5"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}
