//! Build time of the extended-light maps against the point map (a benchmark
//! that prints):
//!
//!     cargo bench -p sunbeam-response --bench build

use sunbeam_light::{sky::Sky, Environment};
use sunbeam_pack::build::{BuildOptions, FieldRef};
use sunbeam_response::env::build_env;
use sunbeam_response::Options;

fn sky() -> Environment {
    Environment::Sky(Box::new(Sky::new(40.0, 30.0, 3.0, 1.0)))
}

/// Build time of the extended-light maps against the point map for the
/// demo-sized pack (synthetic Xenopeltis, 256 x 25 nm = 6.4 um), sky with the
/// sun (4 weight sets in one pass); and, in the same run, what the window's
/// grazing term costs: the same point map and weight sets built with `R`
/// (`build::build_sets_r`, the maps before PHYSICS.md 2b) against `R_U`
/// (`build::build_sets`, what the maps hold), each the best of three.
fn main() {
    use sunbeam_response::build::{auto_grid, build_sets, build_sets_r, wavelength_weights};
    use sunbeam_response::env::env_weights;
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
    let g = auto_grid(&pack, o.budget_bytes);
    let lw = wavelength_weights(o.lambda_samples);
    let point_ws = sunbeam_response::build::WeightSets {
        lambdas: lw.iter().map(|l| l.0).collect(),
        sets: vec![lw.iter().map(|l| l.1).collect()],
    };
    let env_ws = env_weights(&pack, &sky(), o.lambda_samples);
    let best = |f: &dyn Fn() -> Vec<Vec<f32>>| {
        (0..3)
            .map(|_| {
                let t = std::time::Instant::now();
                std::hint::black_box(f());
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    for (name, ws) in [("point map", &point_ws), ("env sets (3 + sun)", &env_ws)] {
        let a = best(&|| build_sets_r(&pack, &g, ws));
        let b = best(&|| build_sets(&pack, &g, ws));
        eprintln!(
            "{name}: R {a:.3} s, R_U {b:.3} s (x{:.2}), {} threads",
            b / a,
            rayon::current_num_threads()
        );
    }
}
