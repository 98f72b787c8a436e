//! `sunbeam-eval probe`: R at given points, one value per line (docs/EVAL.md;
//! the points file and the evaluation: `sunbeam_analysis::probe`).

use std::io::Write;
use std::path::Path;
use sunbeam_analysis::{probe, Source};
use sunbeam_common::{Error, Result};

pub fn run(src: &Source, points_path: &Path) -> Result<()> {
    let text = std::fs::read_to_string(points_path)
        .map_err(|e| Error::input_file(points_path, format!("cannot read: {e}")))?;
    let pts = probe::parse_points(points_path, &text)?;
    let r = probe::reflectances(src, &pts);
    let mut out = String::with_capacity(pts.len() * 24);
    for v in r {
        out.push_str(&format!("{v:e}\n"));
    }
    let stdout = std::io::stdout();
    let mut lock = stdout.lock();
    lock.write_all(out.as_bytes()).map_err(Error::stdout)?;
    Ok(())
}
