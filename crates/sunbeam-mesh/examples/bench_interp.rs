//! Benchmark (not a test): interpolate scattered axial samples at every vertex
//! UV of a ~1M-vertex mesh, single-threaded, with spade natural-neighbour and
//! linear interpolation. Writes the inputs and results for the scipy side
//! (tools/sunbeam-bake/bench/bench_scipy.py) into OUT_DIR.
//!
//! cargo run --release -p sunbeam-mesh --example bench_interp -- OUT_DIR [DETAIL] [SAMPLES]

use std::io::Write;
use std::time::Instant;
use sunbeam_mesh::orient::{AxialField, AxialValue, Interp};
use sunbeam_mesh::snake::{self, SnakeParams};

fn field(u: f64, v: f64) -> f64 {
    0.8 * (2.5 * u).sin() + 0.6 * (6.0 * v + 0.3).cos() * u
}

fn write_f64(path: &std::path::Path, v: &[f64]) {
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    for x in v {
        f.write_all(&x.to_le_bytes()).unwrap();
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = std::path::PathBuf::from(args.get(1).expect("OUT_DIR"));
    let detail: f64 = args.get(2).map_or(5.85, |s| s.parse().unwrap());
    let nsamp: usize = args.get(3).map_or(10_000, |s| s.parse().unwrap());
    std::fs::create_dir_all(&out).unwrap();
    let p = SnakeParams::with_detail(detail);
    let doc = snake::generate(&p);
    let prim = sunbeam_mesh::nodes::read_primitive(&doc, 0, 0, 0)
        .unwrap()
        .unwrap();
    let uv = prim.uvs.unwrap();
    eprintln!("mesh: {} vertices", uv.len());
    let mut s = 0x2545F4914F6CDD1Du64;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let samples: Vec<(usize, [f64; 2], f64)> = (0..nsamp)
        .map(|k| {
            let q = [rnd(), rnd()];
            (k, q, field(q[0], q[1]))
        })
        .collect();
    let mut csv = String::from("u,v,angle_deg\n");
    for (_, q, a) in &samples {
        csv += &format!("{:.17e},{:.17e},{:.17e}\n", q[0], q[1], a.to_degrees());
    }
    std::fs::write(out.join("samples.csv"), csv).unwrap();
    write_f64(
        &out.join("uv.f64"),
        &uv.iter().flatten().copied().collect::<Vec<_>>(),
    );
    let mut rep = serde_json::Map::new();
    rep.insert("vertices".into(), uv.len().into());
    rep.insert("samples".into(), nsamp.into());
    for (name, interp) in [
        ("natural", Interp::Natural),
        ("sibson", Interp::SibsonC1),
        ("linear", Interp::Linear),
    ] {
        let mut best_build = f64::INFINITY;
        let mut best_eval = f64::INFINITY;
        let mut res = Vec::new();
        for _ in 0..3 {
            let t0 = Instant::now();
            let f = AxialField::new(&samples, interp).unwrap();
            let t1 = Instant::now();
            let mut e = f.evaluator();
            res = uv
                .iter()
                .map(|q| match e.eval(*q) {
                    AxialValue::Angle {
                        angle,
                        extrapolated: false,
                    } => angle,
                    _ => f64::NAN,
                })
                .collect::<Vec<f64>>();
            let t2 = Instant::now();
            best_build = best_build.min((t1 - t0).as_secs_f64());
            best_eval = best_eval.min((t2 - t1).as_secs_f64());
        }
        let truth: Vec<f64> = uv.iter().map(|q| field(q[0], q[1])).collect();
        let mut errs: Vec<f64> = res
            .iter()
            .zip(&truth)
            .filter(|(r, _)| r.is_finite())
            .map(|(r, t)| {
                let d = (r - t).rem_euclid(std::f64::consts::PI);
                d.min(std::f64::consts::PI - d)
            })
            .collect();
        errs.sort_by(|a, b| a.total_cmp(b));
        let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
        write_f64(&out.join(format!("rust_{name}.f64")), &res);
        rep.insert(
            name.into(),
            serde_json::json!({"build_s": best_build, "eval_s": best_eval, "inside_hull": errs.len(),
                "rms_err_rad": rms, "p99_err_rad": errs[errs.len() * 99 / 100], "max_err_rad": errs.last()}),
        );
        eprintln!("{name}: build {best_build:.3} s, eval {best_eval:.3} s, rms err {rms:.2e} rad");
    }
    std::fs::write(
        out.join("rust.json"),
        serde_json::to_string_pretty(&rep).unwrap(),
    )
    .unwrap();
    // The 1M-vertex mesh itself, for the end-to-end CLI timing.
    let mut d = doc;
    std::fs::write(out.join("snake1m.glb"), d.to_glb()).unwrap();
}
