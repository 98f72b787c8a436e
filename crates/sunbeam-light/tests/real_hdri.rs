//! Real HDRIs as a public library distributes them (../shared/data/hdri: 1024 x
//! 512 OpenEXR, DWAB-compressed) load: the texels lossy compression pushed
//! below zero are set to 0 and counted. The expected counts and minimum come
//! from the data's README (measured outside this code), not from the loader.

use sunbeam_common::testdata::shared_file;
use sunbeam_light::io;

fn load(name: &str) -> Option<sunbeam_light::EnvMap> {
    let path = shared_file(&format!("hdri/{name}"))?;
    Some(io::load(&path, 0.0, 1.0).unwrap_or_else(|e| panic!("{name}: {e}")))
}

#[test]
fn studio_loads_with_its_three_negative_texels_set_to_zero() {
    let Some(m) = load("studio.exr") else { return };
    assert_eq!((m.width(), m.height()), (1024, 512));
    assert_eq!(m.clamped().texels, 3);
    assert!(m.clamped().min < 0.0 && m.clamped().min > -0.01);
}

#[test]
fn night_loads_with_its_negative_texels_set_to_zero() {
    let Some(m) = load("night.exr") else { return };
    assert_eq!((m.width(), m.height()), (1024, 512));
    assert_eq!((m.clamped().texels, m.clamped().values), (596, 829));
    // "829 texels down to -0.0033"
    assert!(
        (m.clamped().min + 0.0033).abs() < 5e-5,
        "min {}",
        m.clamped().min
    );
    // Every direction reads a finite, non-negative radiance, and the sampler
    // works on what is kept.
    for k in 0..2000 {
        let t = k as f64 / 2000.0;
        let d = sunbeam_light::direction(1.0 - 2.0 * t, 37.0 * t);
        assert!(m.lookup(d).iter().all(|v| v.is_finite() && *v >= 0.0));
        let (d, pdf) = m.sample(t, (t * 7.3).fract()).expect("a lit map");
        assert!(pdf > 0.0 && pdf.is_finite(), "pdf {pdf} at {d:?}");
    }
}
