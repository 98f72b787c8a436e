//! `sunbeam-eval probe`: `R` at given points. The points file (docs/EVAL.md)
//! and the evaluation; the tool reads the file and prints the values.

use crate::source::{par_map, Source};
use std::path::Path;
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

/// `R(u, v, w, lambda)` of `src` at each point, in order.
pub fn reflectances(src: &Source, pts: &[[f64; 4]]) -> Vec<f64> {
    par_map(pts.len(), |i| {
        let p = pts[i];
        src.reflectance(p[0], p[1], p[2], p[3])
    })
}

#[cfg(test)]
mod tests {
    use super::parse_points;
    use std::path::Path;

    #[test]
    fn points_file() {
        let p = Path::new("p.csv");
        let text = "# comment\nu,v,w,lambda_m\n\n1e5, 0 -2.5e6,5e-7\n0\t0\t-2\t6.5e-7\n";
        assert_eq!(
            parse_points(p, text).unwrap(),
            vec![[1e5, 0.0, -2.5e6, 5e-7], [0.0, 0.0, -2.0, 6.5e-7]]
        );
        // A header is only the first line; later words are errors naming the line.
        let e = parse_points(p, "0,0,-2,5e-7\nu,v,w,l\n").unwrap_err();
        assert!(
            e.to_string().contains("line 2: u 'u' is not a number"),
            "{e}"
        );
        let e = parse_points(p, "0,0,-2\n").unwrap_err();
        assert!(e.to_string().contains("line 1: expected 4 values"), "{e}");
        let e = parse_points(p, "0,0,-2,500\n").unwrap_err();
        assert!(e.to_string().contains("not a wavelength in metres"), "{e}");
        let e = parse_points(p, "0,0,inf,5e-7\n").unwrap_err();
        assert!(e.to_string().contains("w is not finite"), "{e}");
        assert!(parse_points(p, "").unwrap().is_empty());
    }
}
