//! Build time of the extended-light maps against the point map (a benchmark,
//! not run by `cargo test`: `test = false` in Cargo.toml):
//!
//!     cargo test --release -p sunbeam-response --test bench_build -- --nocapture

use sunbeam_light::{sky::Sky, Environment};
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_response::env::build_env;
use sunbeam_response::Options;

fn sky() -> Environment {
    Environment::Sky(Box::new(Sky::new(40.0, 30.0, 3.0, 1.0)))
}

/// Build time of the extended-light maps against the point map for the
/// demo-sized pack (synthetic Xenopeltis, 256 x 25 nm = 6.4 um), sky with the
/// sun (4 weight sets in one pass).
#[test]
fn build_time_demo_pack() {
    let f = sunbeam_synth::preset("xenopeltis", 256, 25e-9).unwrap();
    let r = FieldRef {
        width: f.width,
        height: f.height,
        dx: f.dx,
        dy: f.dy,
        data: &f.data,
    };
    let pack = sunbeam_pack::build(r, &BuildOptions::default(), &mut |_, _| {}).unwrap();
    let o = Options::default();
    let t0 = std::time::Instant::now();
    let point = sunbeam_response::build(&pack, &o);
    let t1 = std::time::Instant::now();
    let e = build_env(&pack, &sky(), &o);
    let t2 = std::time::Instant::now();
    eprintln!(
        "grid {:?}: point map {:.2} s, env maps (3 + sun) + proposal {:.2} s, proposal {} floats",
        point.info.grid,
        (t1 - t0).as_secs_f64(),
        (t2 - t1).as_secs_f64(),
        e.proposal.data.len()
    );
}
