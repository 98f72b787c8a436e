mod common;
use common::*;
use sunbeam_optics::truth::{Params, Truth};
use sunbeam_pack::build::BuildOptions;

#[test]
fn smoke_against_truth() {
    let f = rough(40, 36, 25e-9, 25e-9, 300e-9, 7);
    let o = BuildOptions::default();
    let p = build(&f, &o);
    eprintln!("terms {} crop {}x{}", p.manifest.terms, p.manifest.crop.width, p.manifest.crop.height);
    let t = Truth::new(&f, &Params::default()).unwrap();
    let mut rng = Rng(3);
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let (u, v, w, l) = random_query(&mut rng, 80.0);
        let a = p.reflectance(u, v, w, l);
        let b = t.reflectance(u, v, w, l);
        worst = worst.max((a - b).abs());
    }
    eprintln!("worst {worst}");
    eprintln!("spec flat-ish {} {}", p.reflectance(0.0, 0.0, -2.0, 500e-9), t.reflectance(0.0, 0.0, -2.0, 500e-9));
    assert!(worst < 1e-3);
}
