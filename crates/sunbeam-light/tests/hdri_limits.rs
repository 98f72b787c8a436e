//! Item 4's contract for real HDR images (docs/SCENE.md "environment"): a
//! value below zero by more than `NEGATIVE_TEXEL_LIMIT` times the map's mean
//! luminance is an input error naming the file and the texel; an 8192 x 4096
//! equirectangular map loads within a peak memory bound (about 20 s and 1 GB;
//! `--nocapture` prints the figures of docs/bench/hdri.md).

use std::path::PathBuf;
use sunbeam_light::io;

fn scratch(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("hdri-limits");
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

/// A 64 x 32 grey map (0.5 everywhere) with `value` in the red of texel
/// (column 5, row 3), written as an OpenEXR file.
fn write_map(name: &str, value: f32) -> PathBuf {
    let p = scratch(name);
    exr::prelude::write_rgb_file(&p, 64, 32, |x, y| {
        let r = if (x, y) == (5, 3) { value } else { 0.5 };
        (r, 0.5f32, 0.5f32)
    })
    .unwrap();
    p
}

#[test]
fn a_negative_beyond_the_bound_names_the_file_and_the_texel() {
    // Mean luminance 0.5 (one texel's red aside): the bound is 0.05.
    let p = write_map("deep.exr", -0.2);
    let e = io::load(&p, 0.0, 1.0).unwrap_err();
    let msg = e.to_string();
    assert_eq!(e.exit_code(), 2, "{msg}");
    assert!(msg.contains("deep.exr"), "{msg}");
    // Texel (5, 3) of a 64-wide map: index 3 * 64 + 5.
    assert!(msg.contains("pixel 197 "), "{msg}");
    // Just inside the bound: loaded, one value set to 0.
    let p = write_map("shallow.exr", -0.04);
    let m = io::load(&p, 0.0, 1.0).unwrap();
    assert_eq!((m.clamped().values, m.clamped().texels), (1, 1));
}

/// Peak resident memory of this process (Linux `VmHWM`), in MiB.
fn peak_rss_mib() -> f64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap();
    let kb: f64 = s
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|v| v.parse().ok())
        .unwrap();
    kb / 1024.0
}

#[test]
fn an_8k_map_loads_and_its_peak_memory_is_measured() {
    let (w, h) = (8192usize, 4096usize);
    let p = scratch("8k.exr");
    // Written from a closure, texel by texel: the writer holds no image.
    exr::prelude::write_rgb_file(&p, w, h, |x, y| {
        let v = 0.2 + (x as f32 / w as f32) * (y as f32 / h as f32);
        let r = if (x * 7 + y * 13) % 9973 == 0 {
            -1e-4
        } else {
            v
        };
        (r, v, 0.5 * v)
    })
    .unwrap();
    let before = peak_rss_mib();
    let t = std::time::Instant::now();
    let m = io::load(&p, 0.0, 1.0).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let after = peak_rss_mib();
    let file_mib = std::fs::metadata(&p).unwrap().len() as f64 / (1 << 20) as f64;
    let texels_mib = (w * h * 12) as f64 / (1 << 20) as f64;
    eprintln!(
        "8192 x 4096: file {file_mib:.0} MiB, load {secs:.1} s, peak RSS {before:.0} MiB before, \
         {after:.0} MiB after (texels alone {texels_mib:.0} MiB); {} values set to 0",
        m.clamped().values
    );
    assert_eq!((m.width(), m.height()), (w, h));
    assert!(m.clamped().values > 0);
    // The loaded map: RGB f32 (384 MiB) and the sampler's f64 CDF (256 MiB),
    // plus the file's bytes; well under 2 GiB.
    assert!(after < 2048.0, "peak RSS {after:.0} MiB");
}
