//! `sunbeam-eval probe`: R at given points, one value per line (docs/EVAL.md).

use std::io::Write;
use std::path::Path;
use sunbeam_analysis::{par_map, Source};
use sunbeam_common::{Error, Result};

/// Parse a points file: lines `u,v,w,lambda_m`; `#` comments and blank lines
/// are skipped; the first non-comment line may be a header (it is skipped
/// when it does not start with a number). Separators: commas and/or whitespace.
pub fn parse_points(path: &Path, text: &str) -> Result<Vec<[f64; 4]>> {
    let mut pts = Vec::new();
    let mut first = true;
    for (ln, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        let was_first = first;
        first = false;
        if was_first && fields.first().is_some_and(|s| s.parse::<f64>().is_err()) {
            continue; // header
        }
        if fields.len() != 4 {
            return Err(Error::input_file(
                path,
                format!(
                    "line {}: expected 4 values u,v,w,lambda_m, found {}",
                    ln + 1,
                    fields.len()
                ),
            ));
        }
        let mut p = [0.0; 4];
        for (i, (s, name)) in fields.iter().zip(["u", "v", "w", "lambda_m"]).enumerate() {
            let v: f64 = s.parse().map_err(|_| {
                Error::input_file(
                    path,
                    format!("line {}: {name} '{s}' is not a number", ln + 1),
                )
            })?;
            if !v.is_finite() {
                return Err(Error::input_file(
                    path,
                    format!("line {}: {name} is not finite", ln + 1),
                ));
            }
            p[i] = v;
        }
        if p[3] <= 0.0 || p[3] > 1e-3 {
            return Err(Error::input_file(
                path,
                format!(
                    "line {}: lambda_m = {} is not a wavelength in metres",
                    ln + 1,
                    p[3]
                ),
            ));
        }
        pts.push(p);
    }
    Ok(pts)
}

pub fn run(src: &Source, points_path: &Path) -> Result<()> {
    let text = std::fs::read_to_string(points_path)
        .map_err(|e| Error::input_file(points_path, format!("cannot read: {e}")))?;
    let pts = parse_points(points_path, &text)?;
    let r = par_map(pts.len(), |i| {
        let p = pts[i];
        src.reflectance(p[0], p[1], p[2], p[3])
    });
    let mut out = String::with_capacity(pts.len() * 24);
    for v in r {
        out.push_str(&format!("{v:e}\n"));
    }
    let stdout = std::io::stdout();
    let mut lock = stdout.lock();
    lock.write_all(out.as_bytes())
        .map_err(|e| Error::output(format!("stdout: {e}")))?;
    Ok(())
}
