//! Formats without a Gwyddion reference in ../shared/data: the thesis' 8-bit
//! snake patches (PNG RGBA grey, BMP 8-bit palette and 24-bit), ASCII matrices
//! and XYZ points against closed forms.

use sunbeam_afm::{detect, read_bytes, read_file, Format, ReadOptions};
use sunbeam_common::{testdata, ExitCode};

fn snake_opts() -> ReadOptions {
    ReadOptions {
        pixel_size: Some((65e-9, 65e-9)),
        z_range: Some(375e-9),
        ..Default::default()
    }
}

#[test]
fn snake_png_rgba_grey() {
    let Some(p) = testdata::shared_file("snake/Elaph100x100.png") else {
        return;
    };
    let b = std::fs::read(&p).unwrap();
    assert_eq!(detect(&b), Some(Format::Png));
    let c = &read_file(&p, &snake_opts()).unwrap()[0];
    assert_eq!((c.field.width, c.field.height), (100, 100));
    assert_eq!((c.field.dx, c.field.dy), (65e-9, 65e-9));
    assert!(c.is_height && c.z_unit == "m");
    let (lo, hi) = c.field.finite_range().unwrap();
    assert!(
        lo >= 0.0 && hi <= 375e-9 + 1e-18 && hi - lo > 100e-9,
        "{lo} {hi}"
    );
    // every value is k/255 of the range
    for &v in &c.field.data {
        let k = v / 375e-9 * 255.0;
        assert!((k - k.round()).abs() < 1e-9, "{k}");
    }
}

/// BMP rows are stored bottom first: the last stored row is our row 0.
#[test]
fn snake_bmp_orientation_and_palette() {
    let Some(p) = testdata::shared_file("snake/BlazingBump.bmp") else {
        return;
    };
    let b = std::fs::read(&p).unwrap();
    assert_eq!(detect(&b), Some(Format::Bmp));
    let c = &read_file(
        &p,
        &ReadOptions {
            z_range: Some(246.23e-9),
            ..snake_opts()
        },
    )
    .unwrap()[0];
    assert_eq!((c.field.width, c.field.height), (100, 100));
    // 8-bit, palette at 54 (grey: R=G=B), pixels at 1078, rows of 100 bytes, bottom first.
    let off = u32::from_le_bytes(b[10..14].try_into().unwrap()) as usize;
    for (r, c_) in [(0usize, 0usize), (0, 57), (99, 3), (42, 99)] {
        let idx = b[off + (99 - r) * 100 + c_] as usize;
        let grey = b[54 + 4 * idx] as f64;
        assert_eq!(b[54 + 4 * idx], b[54 + 4 * idx + 1]);
        let want = grey / 255.0 * 246.23e-9;
        assert!((c.field.at(r, c_) - want).abs() < 1e-20, "({r},{c_})");
    }
    // A blazed grating: one sawtooth period across x, so most steps along a row go one way.
    let row = &c.field.data[..100];
    let ups = row.windows(2).filter(|w| w[1] > w[0]).count();
    let downs = row.windows(2).filter(|w| w[1] < w[0]).count();
    assert!(
        ups.max(downs) > 10 * ups.min(downs).max(1),
        "ups {ups} downs {downs}"
    );

    let Some(p) = testdata::shared_file("snake/SingleFingerElaphIdeal.bmp") else {
        return;
    };
    let c = &read_file(&p, &snake_opts()).unwrap()[0];
    assert_eq!((c.field.width, c.field.height), (72, 28));
}

#[test]
fn ascii_matrix_with_gwyddion_header() {
    let txt = "# Channel: Height\n# Width: 2.000 µm\n# Height: 1.000 µm\n# Value units: m\n\
               1e-9\t2e-9\t3e-9\t4e-9\n5e-9\t6e-9\t7e-9\t8e-9\n";
    assert_eq!(detect(txt.as_bytes()), Some(Format::Ascii));
    let c = &read_bytes(txt.as_bytes(), &ReadOptions::default()).unwrap()[0];
    assert_eq!((c.field.width, c.field.height), (4, 2));
    assert!((c.field.size_x() - 2e-6).abs() < 1e-18 && (c.field.size_y() - 1e-6).abs() < 1e-18);
    assert_eq!((c.name.as_str(), c.z_unit.as_str()), ("Height", "m"));
    assert_eq!(c.field.at(0, 0), 1e-9);
    assert_eq!(c.field.at(1, 3), 8e-9);
    // Without a header: --pixel-size is required, --z-scale applies.
    // Three columns read as x y z points; --format ascii reads them as a matrix.
    let bare = "1 2 3\n4 5 6\n7 8 9\n1 1 1\n";
    assert_eq!(detect(bare.as_bytes()), Some(Format::Xyz));
    let o = ReadOptions {
        format: Some(Format::Ascii),
        pixel_size: Some((1e-9, 1e-9)),
        ..Default::default()
    };
    assert_eq!(read_bytes(bare.as_bytes(), &o).unwrap()[0].field.height, 4);
    let e = read_bytes(b"1, 2\n3, 4\n", &ReadOptions::default()).unwrap_err();
    assert_eq!(e.code, ExitCode::Input);
    assert!(e.message.contains("--pixel-size"), "{e}");
    let o = ReadOptions {
        pixel_size: Some((1e-9, 2e-9)),
        z_scale: Some(1e-9),
        ..Default::default()
    };
    let c = &read_bytes(b"1, 2\n3, 4\n", &o).unwrap()[0];
    assert_eq!((c.field.dx, c.field.dy), (1e-9, 2e-9));
    for (a, b) in c.field.data.iter().zip([1e-9, 2e-9, 3e-9, 4e-9]) {
        assert!((a - b).abs() < 1e-24);
    }
    let e = read_bytes(b"1 2\n3\n", &o).unwrap_err();
    assert!(e.message.contains("line 2"), "{e}");
}

fn plane(x: f64, y: f64) -> f64 {
    3e-3 * x - 2e-3 * y + 5e-9
}

#[test]
fn xyz_regular_grid_is_a_grid() {
    // 5 x 4 nodes, 10 nm apart, listed in a shuffled order; y up (row 0 = largest y).
    let mut s = String::from("# x y z\n");
    let mut nodes = Vec::new();
    for j in 0..4 {
        for i in 0..5 {
            nodes.push((i, j));
        }
    }
    nodes.sort_by_key(|&(i, j)| (i * 7 + j * 3) % 20);
    for (i, j) in nodes {
        let (x, y) = (1e-6 + i as f64 * 10e-9, 2e-6 + j as f64 * 10e-9);
        s += &format!("{x:e} {y:e} {:e}\n", plane(x, y));
    }
    assert_eq!(detect(s.as_bytes()), Some(Format::Xyz));
    let c = &read_bytes(s.as_bytes(), &ReadOptions::default()).unwrap()[0];
    assert_eq!((c.field.width, c.field.height), (5, 4));
    assert!((c.field.dx - 10e-9).abs() < 1e-20 && (c.field.dy - 10e-9).abs() < 1e-20);
    for r in 0..4 {
        for i in 0..5 {
            let (x, y) = (1e-6 + i as f64 * 10e-9, 2e-6 + (3 - r) as f64 * 10e-9);
            assert!((c.field.at(r, i) - plane(x, y)).abs() < 1e-20, "({r},{i})");
        }
    }
}

/// Scattered points of a plane: linear interpolation on the Delaunay
/// triangulation reproduces the plane exactly inside the hull.
#[test]
fn xyz_scattered_points_are_triangulated() {
    let mut s = String::new();
    let mut rng = sunbeam_common::rng::SplitMix64::new(12345);
    let mut rnd = || rng.unit();
    // corners so the hull is the square, then random points
    let mut pts = vec![(0.0, 0.0), (1e-6, 0.0), (0.0, 1e-6), (1e-6, 1e-6)];
    for _ in 0..400 {
        pts.push((rnd() * 1e-6, rnd() * 1e-6));
    }
    for (x, y) in &pts {
        s += &format!("{x:e}\t{y:e}\t{:e}\n", plane(*x, *y));
    }
    assert_eq!(detect(s.as_bytes()), Some(Format::Xyz));
    let c = &read_bytes(s.as_bytes(), &ReadOptions::default()).unwrap()[0];
    // grid: sqrt(area / N) = 1 um / sqrt(404) ~ 49.75 nm -> 21 x 21 nodes
    assert_eq!((c.field.width, c.field.height), (21, 21));
    let d = c.field.dx;
    assert!((d - 1e-6 / (404f64).sqrt()).abs() < 1e-15);
    let mut finite = 0;
    for r in 0..c.field.height {
        for i in 0..c.field.width {
            let v = c.field.at(r, i);
            if v.is_finite() {
                let (x, y) = (i as f64 * d, 1e-6 - r as f64 * d);
                assert!(
                    (v - plane(x, y)).abs() < 1e-15,
                    "({r},{i}) {v} vs {}",
                    plane(x, y)
                );
                finite += 1;
            }
        }
    }
    assert_eq!(
        finite,
        21 * 21,
        "all nodes lie inside the hull of the square"
    );
    // a user pixel size
    let o = ReadOptions {
        pixel_size: Some((0.1e-6, 0.1e-6)),
        ..Default::default()
    };
    let c = &read_bytes(s.as_bytes(), &o).unwrap()[0];
    assert_eq!((c.field.width, c.field.height), (11, 11));
    // collinear points are refused
    let e = read_bytes(b"0 0 1\n1 1 2\n2 2 3\n3 3 4\n", &ReadOptions::default()).unwrap_err();
    assert_eq!(e.code, ExitCode::Input);
}

#[test]
fn format_names_round_trip() {
    for f in Format::ALL {
        assert_eq!(f.name().parse::<Format>().unwrap(), f);
    }
    assert!("nonsense".parse::<Format>().is_err());
}

#[test]
fn forced_format_on_wrong_content_is_an_input_error() {
    let Some(p) = testdata::shared_file("afm/samples/pySPM_test.sxm") else {
        return;
    };
    let b = std::fs::read(p).unwrap();
    for f in Format::ALL {
        if f == Format::Sxm {
            continue;
        }
        let o = ReadOptions {
            format: Some(f),
            pixel_size: Some((1e-9, 1e-9)),
            z_range: Some(1e-9),
            ..Default::default()
        };
        if let Err(e) = read_bytes(&b, &o) {
            assert_eq!(e.code, ExitCode::Input, "{f}: {e}");
        } else {
            panic!("{f} read an sxm file");
        }
    }
}

/// Height fields written by sunbeam-field (EXR, GSF) read back through the same entry point.
#[test]
fn sunbeam_exr_and_gsf_round_trip() {
    use sunbeam_field::HeightField;
    let (w, h) = (7, 5);
    let data: Vec<f64> = (0..w * h).map(|i| (i as f64 * 0.37).sin() * 1e-7).collect();
    let mut f = HeightField::new(w, h, 20e-9, 30e-9, data.clone()).unwrap();
    f.provenance.channel = "Height".into();
    for kind in [sunbeam_field::io::Kind::Exr, sunbeam_field::io::Kind::Gsf] {
        let bytes = sunbeam_field::io::encode(kind, &f).unwrap();
        let want = if kind == sunbeam_field::io::Kind::Exr {
            Format::Exr
        } else {
            Format::Gsf
        };
        assert_eq!(detect(&bytes), Some(want));
        let c = &read_bytes(&bytes, &ReadOptions::default()).unwrap()[0];
        assert_eq!((c.field.width, c.field.height), (w, h), "{want}");
        assert!(
            (c.field.dx - 20e-9).abs() < 1e-20 && (c.field.dy - 30e-9).abs() < 1e-20,
            "{want}"
        );
        assert!(c.is_height && c.z_unit == "m", "{want}: {c:?}");
        for (a, b) in c.field.data.iter().zip(&data) {
            assert!((a - b).abs() <= 1e-7 * 1e-6, "{want}: {a} vs {b}");
        }
        let cut = read_bytes(&bytes[..bytes.len() / 2], &ReadOptions::default()).unwrap_err();
        assert_eq!(cut.code, ExitCode::Input);
    }
}

/// A v4.3-style Nanoscope header (`@Z scale` without `@2:`, one-number scan
/// size in nm, CR LF lines) against the closed form z = raw/65536 * Z scale * sens.
#[test]
fn nanoscope_v43_header_closed_form() {
    let mut hdr = String::from(
        "\\*File list\r\n\\Version: 0x04320003\r\n\\Data length: HLEN\r\n\\*Scanner list\r\n\
         \\@Sens. Zscan: V 12.50000 nm/V\r\n\\*Ciao scan list\r\n\\Scan size: 1769.08 nm\r\n\\Samps/line: 4\r\n\\Lines: 2\r\n\
         \\*Ciao image list\r\n\\Data offset: HLEN\r\n\\Data length: 16\r\n\\Bytes/pixel: 2\r\n\\Samps/line: 4\r\n\
         \\Number of lines: 2\r\n\\Scan size: 1769.08 nm\r\n\\Image data: Height\r\n\
         \\@Z scale: V [Sens. Zscan] (0.006713867 V/LSB) 20.00000 V\r\n\\*File list end\r\n",
    );
    let len = hdr.len() + 4 + (64 - (hdr.len() + 4) % 64);
    hdr = hdr.replace("HLEN", &format!("{len:<4}"));
    let mut b = hdr.into_bytes();
    b.resize(len, 0);
    let raw: [i16; 8] = [0, 1, -1, 32767, -32768, 100, 200, 300];
    for r in raw {
        b.extend_from_slice(&r.to_le_bytes());
    }
    assert_eq!(detect(&b), Some(Format::Nanoscope));
    let c = &read_bytes(&b, &ReadOptions::default()).unwrap()[0];
    assert_eq!(
        (c.name.as_str(), c.field.width, c.field.height),
        ("Height", 4, 2)
    );
    assert!(c.is_height && c.z_unit == "m");
    assert!((c.field.size_x() - 1769.08e-9).abs() < 1e-15);
    // 2 lines of 4 samples: the slow axis is half as long (square pixels).
    assert!((c.field.size_y() - 1769.08e-9 / 2.0).abs() < 1e-15);
    let q = 20.0 * 12.5e-9 / 65536.0;
    // stored bottom row first: file row 1 is our row 0
    for (k, r) in raw.iter().enumerate() {
        let (fr, col) = (k / 4, k % 4);
        let v = c.field.at(1 - fr, col);
        assert!((v - *r as f64 * q).abs() <= 1e-12 * q * 32768.0, "{k}: {v}");
    }
}
