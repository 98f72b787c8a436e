//! Benchmark driver (not a test): build an M x M synthetic pack with N terms and
//! write it as KTX2. `pack_bench M N OUT.ktx2 [threads]`; prints one JSON line.
//! Run by tools/sunbeam-pack/bench/run.sh next to the numpy/scipy baseline.

use std::time::Instant;
use sunbeam_pack::build::{self, BuildOptions, FieldRef};
use sunbeam_pack::formats::{write_pack, OutputKind};

/// The synthetic field both implementations use (same formula in bench_numpy.py).
pub fn height(c: usize, r: usize, dx: f64) -> f64 {
    let (x, y) = (c as f64 * dx, r as f64 * dx);
    let tau = std::f64::consts::TAU;
    200e-9 * (tau * x / 1.1e-6).sin() * (0.5 + 0.5 * (tau * y / 3.7e-6).cos())
        + 80e-9 * (tau * (x + 0.6 * y) / 0.83e-6).sin()
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        eprintln!("usage: pack_bench M N OUT.ktx2 [threads]");
        std::process::exit(1);
    }
    let m: usize = a[1].parse().expect("M");
    let n: usize = a[2].parse().expect("N");
    let out = std::path::PathBuf::from(&a[3]);
    let threads: usize = a.get(4).map(|s| s.parse().expect("threads")).unwrap_or(2);
    let dx = 30e-9;
    let data: Vec<f64> = (0..m * m).map(|i| height(i % m, i / m, dx)).collect();
    let t0 = Instant::now();
    let f = FieldRef {
        width: m,
        height: m,
        dx,
        dy: dx,
        data: &data,
    };
    let o = BuildOptions {
        terms: Some(n),
        threads,
        ..BuildOptions::default()
    };
    let pack = build::build(f, &o, &mut |_, _| {}).expect("build");
    let t_build = t0.elapsed().as_secs_f64();
    let files = write_pack(&pack, &out, OutputKind::Ktx2).expect("write");
    let t_all = t0.elapsed().as_secs_f64();
    println!(
        "{{\"impl\":\"rust\",\"M\":{m},\"N\":{n},\"crop\":{},\"build_s\":{t_build:.3},\"total_s\":{t_all:.3},\"bytes\":{}}}",
        pack.manifest.crop.width, files[0].1
    );
}
