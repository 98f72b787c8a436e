//! Time `read_bytes` on files (debugging aid):
//! `cargo run --release -p sunbeam-afm --example afm_time -- FILE...`

use std::time::Instant;

use sunbeam_afm::{read_bytes, ReadOptions};

fn main() {
    let opts = ReadOptions {
        pixel_size: Some((1e-9, 1e-9)),
        z_range: Some(1e-6),
        ..Default::default()
    };
    for a in std::env::args().skip(1) {
        let b = std::fs::read(&a).expect("readable file");
        let n = 20;
        let t = Instant::now();
        for _ in 0..n {
            let _ = read_bytes(&b, &opts);
        }
        let full = t.elapsed().as_secs_f64() * 1e3 / n as f64;
        let t = Instant::now();
        for _ in 0..n {
            let _ = sunbeam_afm::list_channels_bytes(&b, &opts);
        }
        let head = t.elapsed().as_secs_f64() * 1e3 / n as f64;
        let t = Instant::now();
        for _ in 0..n {
            let _ = sunbeam_afm::detect(&b);
        }
        let det = t.elapsed().as_secs_f64() * 1e3 / n as f64;
        println!(
            "{a}: read {full:.3} ms, list {head:.3} ms, detect {det:.3} ms ({} bytes)",
            b.len()
        );
    }
}
