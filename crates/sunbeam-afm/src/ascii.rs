//! ASCII matrices: one image row per line (row 0 at the top), numbers separated
//! by whitespace, commas or semicolons; optionally with Gwyddion's text-export
//! header (`# Channel:`, `# Width: 1.769 µm`, `# Height:`, `# Value units: m`).
//! Without that header the pixel size comes from `--pixel-size` and the values
//! are multiplied by `--z-scale` (default 1: metres).

use sunbeam_common::Result;

use crate::util::{bail, channel, check_dims, leading_f64, parse_unit};
use crate::{Channel, Format, ReadOptions};

/// Is this plain text (first 4 KiB), with a numeric line?
pub fn is_text(b: &[u8]) -> bool {
    let head = &b[..b.len().min(4096)];
    let text = match std::str::from_utf8(head) {
        Ok(t) => t,
        Err(e) if e.valid_up_to() + 4 > head.len() => {
            std::str::from_utf8(&head[..e.valid_up_to()]).unwrap_or("")
        }
        Err(_) => return false,
    };
    !text.is_empty()
        && text
            .chars()
            .all(|c| !c.is_control() || matches!(c, '\n' | '\r' | '\t'))
}

pub fn split_numbers(line: &str) -> Option<Vec<f64>> {
    let mut v = Vec::new();
    for tok in line
        .split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .filter(|t| !t.is_empty())
    {
        v.push(tok.parse::<f64>().ok()?);
    }
    Some(v)
}

fn is_comment(l: &str) -> bool {
    let t = l.trim_start();
    t.is_empty() || t.starts_with('#') || t.starts_with('%') || t.starts_with("//")
}

pub fn detect(b: &[u8]) -> bool {
    if !is_text(b) {
        return false;
    }
    let head = String::from_utf8_lossy(&b[..b.len().min(4096)]);
    head.lines()
        .find(|l| !is_comment(l))
        .and_then(split_numbers)
        .is_some_and(|v| !v.is_empty())
}

/// "1.769 µm" -> metres (and the base unit).
fn length(v: &str) -> Option<(f64, String)> {
    let (x, rest) = leading_f64(v)?;
    let (m, base) = parse_unit(rest.trim());
    Some((x * m, base))
}

pub fn read(b: &[u8], opts: &ReadOptions) -> Result<Vec<Channel>> {
    if !is_text(b) {
        bail!("ASCII matrix: the file is not text");
    }
    let text = String::from_utf8_lossy(b);
    let mut name = "Data".to_string();
    let (mut width, mut height, mut zunit) = (None, None, None);
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for (ln, line) in text.lines().enumerate() {
        if is_comment(line) {
            if let Some(h) = line.trim_start().strip_prefix('#') {
                if let Some((k, v)) = h.split_once(':') {
                    let (k, v) = (k.trim().to_ascii_lowercase(), v.trim());
                    match k.as_str() {
                        "channel" => name = v.to_string(),
                        "width" => width = length(v),
                        "height" => height = length(v),
                        "value units" => zunit = Some(v.to_string()),
                        _ => {}
                    }
                }
            }
            continue;
        }
        let Some(v) = split_numbers(line) else {
            bail!(
                "ASCII matrix line {}: not a list of numbers ({:?})",
                ln + 1,
                line.chars().take(40).collect::<String>()
            )
        };
        if let Some(first) = rows.first() {
            if v.len() != first.len() {
                bail!(
                    "ASCII matrix line {}: {} values, the first row has {}",
                    ln + 1,
                    v.len(),
                    first.len()
                );
            }
        }
        rows.push(v);
    }
    let yres = rows.len();
    let xres = rows.first().map_or(0, |r| r.len());
    let (xres, yres) = check_dims(xres as i64, yres as i64, "ASCII matrix columns x rows")?;
    let (xreal, yreal, xy_unit) = match (width, height, opts.pixel_size) {
        (Some((w, u)), Some((h, _)), _) => (w, h, u),
        (Some((w, u)), None, _) => (w, w * yres as f64 / xres as f64, u),
        (None, _, Some((dx, dy))) => (dx * xres as f64, dy * yres as f64, "m".to_string()),
        (None, _, None) => bail!("ASCII matrix {xres}x{yres} has no header with its size: give --pixel-size (and --z-scale if the values are not metres)"),
    };
    let (zm, zbase) = match &zunit {
        Some(u) => parse_unit(u),
        None => (opts.z_scale.unwrap_or(1.0), "m".to_string()),
    };
    let data: Vec<f64> = rows.into_iter().flatten().map(|v| v * zm).collect();
    let mut ch = channel(
        Format::Ascii,
        &name,
        &zbase,
        &xy_unit,
        xres,
        yres,
        xreal,
        yreal,
        data,
    )?;
    if zunit.is_none() {
        ch.is_height = true;
    }
    Ok(vec![ch])
}
