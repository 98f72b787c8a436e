//! What an environment map costs before the first frame (issue 26 item 2:
//! "prefiltered environments built once per environment, under 0.5 s for a
//! 2k map"): the stages the player's first-frame estimator and
//! `sunbeam-play --export-environment` run per map, timed one by one.
//!
//! `cargo bench -p sunbeam-light --bench env_tables` times the shared
//! studio.exr (1024 x 512, DWAB, as distributed) and the same map repeated to
//! 2048 x 1024 and 4096 x 2048 (written as lossless OpenEXR into the target's
//! scratch directory); `MAPS=a.exr,b.hdr` times other files. `RUNS` (default
//! 3) runs per map, the median printed per stage, in milliseconds:
//!
//! - `load`: decoding the file and `EnvMap::new` (the negatives' check and
//!   the importance sampler's tables);
//! - `table`: `Environment::coefficient_table` (the basis coefficients at the
//!   map's own size, rotation baked in);
//! - `hot`: `hotspots::split` with the default options (the hot spots as
//!   lights, the residual);
//! - `chain`: `prefilter::Prefiltered::new` on the residual (the mip chain of
//!   solid-angle means the cells read);
//! - `irradiance`: `Irradiance::pair` (the plain and the skin-transmitted
//!   irradiance tables);
//! - `built`: table + hot + chain + irradiance, what is made from the loaded
//!   map (the goal's "prefiltered environment").

use std::path::{Path, PathBuf};
use std::time::Instant;
use sunbeam_light::{hotspots, io, irradiance::Irradiance, prefilter::Prefiltered, Environment};

const STAGES: [&str; 6] = ["load", "table", "hot", "chain", "irradiance", "built"];

fn main() {
    let runs: usize = std::env::var("RUNS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3)
        .max(1);
    // Without MAPS, the shared studio.exr and its repeats (none, with a SKIP
    // line, where the shared data is missing).
    let maps: Vec<PathBuf> = match std::env::var("MAPS") {
        Ok(v) => v.split(',').map(PathBuf::from).collect(),
        Err(_) => default_maps(),
    };
    println!("map,size,{}", STAGES.map(|s| format!("{s}_ms")).join(","));
    for path in &maps {
        let mut times: Vec<[f64; 6]> = Vec::new();
        let mut size = (0, 0);
        for _ in 0..runs {
            let (t, s) = time_stages(path);
            times.push(t);
            size = s;
        }
        let median: Vec<String> = (0..STAGES.len())
            .map(|k| {
                let mut v: Vec<f64> = times.iter().map(|t| t[k]).collect();
                v.sort_by(f64::total_cmp);
                format!("{:.0}", v[v.len() / 2])
            })
            .collect();
        println!(
            "{},{}x{},{}",
            path.file_name().unwrap_or_default().to_string_lossy(),
            size.0,
            size.1,
            median.join(",")
        );
    }
}

/// One run over `path`: the stages' times (ms) and the map's size.
fn time_stages(path: &Path) -> ([f64; 6], (usize, usize)) {
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let map = io::load(path, 0.0, 1.0).unwrap_or_else(|e| panic!("{e}"));
    let load = ms(t);
    let size = (map.width(), map.height());
    let env = Environment::Map(map);
    let t = Instant::now();
    let (w, h, table) = env.coefficient_table(256);
    let table_ms = ms(t);
    let t = Instant::now();
    let split = hotspots::split(w, h, &table, hotspots::SplitOptions::default());
    let hot = ms(t);
    let t = Instant::now();
    let chain = Prefiltered::new(w, h, split.residual);
    let chain_ms = ms(t);
    let t = Instant::now();
    let (plain, skin) = Irradiance::pair(&env, 1.5);
    let irr = ms(t);
    assert!(!chain.levels.is_empty());
    assert!(plain.at([0.0, 1.0, 0.0])[1] > 0.0 && skin.at([0.0, 1.0, 0.0])[1] > 0.0);
    (
        [
            load,
            table_ms,
            hot,
            chain_ms,
            irr,
            table_ms + hot + chain_ms + irr,
        ],
        size,
    )
}

/// The shared studio.exr and its 2x and 4x repeats (each texel `k x k`
/// times), written once into the target's scratch directory.
fn default_maps() -> Vec<PathBuf> {
    let Some(studio) = sunbeam_common::testdata::shared_file("hdri/studio.exr") else {
        return Vec::new();
    };
    let map = io::load(&studio, 0.0, 1.0).unwrap_or_else(|e| panic!("{e}"));
    let (w, h) = (map.width(), map.height());
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("env-tables");
    std::fs::create_dir_all(&dir).unwrap();
    let mut out = vec![studio.clone()];
    for k in [2usize, 4] {
        let p = dir.join(format!("studio-x{k}.exr"));
        if !p.is_file() {
            let texels = map.texels();
            exr::prelude::write_rgb_file(&p, w * k, h * k, |x, y| {
                let c = texels[(y / k) * w + x / k];
                (c[0], c[1], c[2])
            })
            .unwrap();
        }
        out.push(p);
    }
    out
}
