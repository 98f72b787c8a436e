//! Nanosurf `.nid` (and `.ezd`): an INI-style text header starting with
//! `[DataSet]`, then `#!` and the binary images, as Gwyddion's `ezdfile`
//! module reads them.
//!
//! `[DataSet]` has `GroupCount` and per group `GrI-Count` and the channels
//! `GrI-ChJ=<section>`; the images follow `#!` in (group, channel) order.
//! Each channel section: `Points` x `Lines`, `SaveBits` 8/16/32,
//! `SaveSign=Signed`, `SaveOrder=Intel`, `Dim0Range`/`Dim1Range` (+ units)
//! the physical size, `Dim2Name`, `Dim2Unit`, `Dim2Min`, `Dim2Range`:
//! z = (raw + 2^(bits-1)) / 2^bits * range + min. Stored bottom row first
//! (whatever `Scan direction` says, as Gwyddion does); backward scans are not
//! mirrored. 1-D data (`Lines` below 2) is skipped.

use std::collections::HashMap;

use sunbeam_common::Result;

use crate::text::{atol, latin1_or_utf8};
use crate::util::{bail, channel, check_dims, decode, flip_rows, leading_f64, parse_unit};
use crate::util::{Endian, Sample};
use crate::{Channel, Format};

/// Content detection: the header starts with `[DataSet]` on its own line.
pub fn detect(b: &[u8]) -> bool {
    b.starts_with(b"[DataSet]\r\n") || b.starts_with(b"[DataSet]\n")
}

struct Section {
    name: String,
    keys: HashMap<String, String>,
}

fn parse_header(head: &str) -> Result<Vec<Section>> {
    let mut secs: Vec<Section> = Vec::new();
    for (lineno, line) in head.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        if t.len() >= 2 && t.starts_with('[') && t.ends_with(']') {
            secs.push(Section {
                name: t[1..t.len() - 1].to_string(),
                keys: HashMap::new(),
            });
            continue;
        }
        let Some(sec) = secs.last_mut() else {
            bail!(
                "Nanosurf NID header: text before the first [section] (line {})",
                lineno + 1
            )
        };
        if t.starts_with("--") {
            continue; // comment
        }
        let Some((k, v)) = t.split_once('=') else {
            bail!(
                "Nanosurf NID header: line {} in [{}] is not `key=value` ({:?})",
                lineno + 1,
                sec.name,
                t.chars().take(60).collect::<String>()
            )
        };
        sec.keys.insert(k.trim().to_string(), v.trim().to_string());
    }
    Ok(secs)
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !detect(b) {
        bail!("not a Nanosurf NID file (no [DataSet] at the start)");
    }
    let Some(marker) = b.windows(2).position(|w| w == b"#!") else {
        bail!("Nanosurf NID: no `#!` marker after the header (truncated?)")
    };
    let data_start = marker + 2;
    let head = latin1_or_utf8(&b[..marker]);
    let secs = parse_header(&head)?;
    let Some(first) = secs.first() else {
        bail!("Nanosurf NID: the header has no [DataSet] section")
    };
    if first.name != "DataSet" {
        bail!(
            "Nanosurf NID: the first section is [{}], not [DataSet]",
            first.name
        );
    }
    let ds = &first.keys;
    let ngroups = match ds.get("GroupCount") {
        Some(v) if atol(v) > 0 => atol(v),
        Some(v) => bail!("Nanosurf NID [DataSet]: GroupCount {v:?} is not a positive number"),
        None => bail!("Nanosurf NID [DataSet]: missing GroupCount"),
    };
    // The channels GrI-ChJ in (I, J) order, I < GroupCount, J < GrI-Count.
    // (Collected from the keys present, so absurd counts cost nothing.)
    let mut chans: Vec<(i64, i64, &str)> = Vec::new();
    for (k, v) in ds {
        let Some(rest) = k.strip_prefix("Gr") else {
            continue;
        };
        let Some((gi, cj)) = rest.split_once("-Ch") else {
            continue;
        };
        let (Ok(i), Ok(j)) = (gi.parse::<i64>(), cj.parse::<i64>()) else {
            continue;
        };
        if i < 0 || i >= ngroups || j < 0 || *k != format!("Gr{i}-Ch{j}") {
            continue; // (Gwyddion looks up exactly `GrI-ChJ`: no `Gr01-Ch1`)
        }
        let count = ds
            .get(&format!("Gr{i}-Count"))
            .map(|c| atol(c))
            .unwrap_or(0);
        if j < count {
            chans.push((i, j, v.as_str()));
        }
    }
    chans.sort();
    let mut out = Vec::new();
    let mut off = data_start;
    for (i, j, secname) in chans {
        let key = format!("Gr{i}-Ch{j}");
        let Some(sec) = secs[1..].iter().find(|s| s.name == secname) else {
            bail!(
                "Nanosurf NID [DataSet]: {key}={secname} names a section the header does not have"
            )
        };
        let s = &sec.keys;
        let what = format!("Nanosurf NID [{secname}]");
        let lines = s.get("Lines").map(|v| atol(v)).unwrap_or(0);
        if lines < 2 {
            continue; // 1-D data (a line or a spectrum), as Gwyddion skips it
        }
        let points = s.get("Points").map(|v| atol(v)).unwrap_or(0);
        let (xres, yres) = check_dims(points, lines, &format!("{what} Points x Lines"))?;
        let bits = s.get("SaveBits").map(|v| atol(v)).unwrap_or(0);
        let sample = match bits {
            8 => Sample::I8,
            16 => Sample::I16,
            32 => Sample::I32,
            _ => bail!(
                "{what}: SaveBits {:?} is not supported (8, 16 or 32)",
                s.get("SaveBits").map(String::as_str).unwrap_or("")
            ),
        };
        for (k, want) in [
            ("SaveMode", "Binary"),
            ("SaveSign", "Signed"),
            ("SaveOrder", "Intel"),
        ] {
            if let Some(v) = s.get(k) {
                if v != want {
                    bail!("{what}: {k}={v} is not supported (only {want})");
                }
            }
        }
        let num = |k: &str| -> f64 {
            s.get(k)
                .and_then(|v| leading_f64(v))
                .map(|(x, _)| x)
                .unwrap_or(0.0)
        };
        let unit = |k: &str| parse_unit(s.get(k).map(String::as_str).unwrap_or(""));
        let (mz, zunit) = unit("Dim2Unit");
        let (mx, xyunit) = unit("Dim0Unit");
        let (my, _) = unit("Dim1Unit");
        let xreal = mx * num("Dim0Range");
        let yreal = my * num("Dim1Range");
        let n = xres * yres;
        let mut data = decode(
            b,
            off,
            n,
            sample,
            Endian::Little,
            &format!("{what} data ({key})"),
        )?;
        off += n * sample.size();
        let q = (1u64 << bits) as f64;
        let (scale, zmin) = (mz * num("Dim2Range"), mz * num("Dim2Min"));
        for v in &mut data {
            *v = (*v + q / 2.0) / q * scale + zmin;
        }
        flip_rows(&mut data, xres, yres);
        let suffix = match s.get("Frame").map(String::as_str) {
            Some("Scan forward") => " forward",
            Some("Scan backward") => " backward",
            _ => "",
        };
        let name = match s.get("Dim2Name") {
            Some(nm) => format!("{nm}{suffix}"),
            None => format!("Unknown channel {}", out.len() + 1),
        };
        if out.len() >= 1024 {
            bail!("Nanosurf NID: more than 1024 images");
        }
        out.push(channel(
            Format::Nid,
            &name,
            &zunit,
            &xyunit,
            xres,
            yres,
            xreal,
            yreal,
            data,
        )?);
    }
    if out.is_empty() {
        bail!("Nanosurf NID: [DataSet] lists no 2-D image (GrI-ChJ entries)");
    }
    Ok(out)
}
