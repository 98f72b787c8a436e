//! Gwyddion native `.gwy` files (GWYP serialisation): every `/N/data` data
//! field of the top-level container, with its `/N/data/title`.

use sunbeam_common::Result;

use crate::util::{bail, channel, check_dims, decode, Endian, Sample};
use crate::{Channel, Format};

/// A deserialised component value (arrays stay as byte slices until needed).
enum Val<'a> {
    Num(f64),
    Str(String),
    Obj(Obj<'a>),
    Doubles(&'a [u8]),
    Other,
}

struct Obj<'a> {
    type_name: String,
    comps: Vec<(String, Val<'a>)>,
}

impl<'a> Obj<'a> {
    fn get(&self, k: &str) -> Option<&Val<'a>> {
        self.comps.iter().find(|(n, _)| n == k).map(|(_, v)| v)
    }
    fn num(&self, k: &str) -> Option<f64> {
        match self.get(k) {
            Some(Val::Num(x)) => Some(*x),
            _ => None,
        }
    }
}

struct P<'a> {
    b: &'a [u8],
    pos: usize,
}

const MAX_DEPTH: usize = 32;

impl<'a> P<'a> {
    fn cstr(&mut self, what: &str) -> Result<String> {
        let rest = &self.b[self.pos.min(self.b.len())..];
        let Some(n) = rest.iter().position(|&c| c == 0) else {
            bail!(
                "Gwyddion file: {what} is not NUL-terminated (truncated?) at byte {}",
                self.pos
            )
        };
        let s = String::from_utf8_lossy(&rest[..n]).into_owned();
        self.pos += n + 1;
        Ok(s)
    }
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.b.len());
        let Some(end) = end else {
            bail!(
                "Gwyddion file: {what} needs {n} bytes at byte {} but only {} remain (truncated?)",
                self.pos,
                self.b.len().saturating_sub(self.pos)
            )
        };
        let s = &self.b[self.pos..end];
        self.pos = end;
        Ok(s)
    }
    fn u32(&mut self, what: &str) -> Result<usize> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]) as usize)
    }

    fn object(&mut self, depth: usize) -> Result<Obj<'a>> {
        if depth > MAX_DEPTH {
            bail!("Gwyddion file: objects nested deeper than {MAX_DEPTH}");
        }
        let type_name = self.cstr("object type name")?;
        let size = self.u32(&format!("size of object {type_name}"))?;
        let body_end = self.pos.checked_add(size).filter(|&e| e <= self.b.len());
        let Some(body_end) = body_end else {
            bail!(
                "Gwyddion file: object {type_name} declares {size} bytes but only {} remain (truncated?)",
                self.b.len().saturating_sub(self.pos)
            )
        };
        let mut comps = Vec::new();
        while self.pos < body_end {
            let name = self.cstr("component name")?;
            let t = self.take(1, &format!("type of component {name}"))?[0];
            let what = format!("component {type_name}.{name}");
            let v = match t {
                b'b' | b'c' => Val::Num(self.take(1, &what)?[0] as f64),
                b'i' => {
                    let s = self.take(4, &what)?;
                    Val::Num(i32::from_le_bytes([s[0], s[1], s[2], s[3]]) as f64)
                }
                b'q' => {
                    let s = self.take(8, &what)?;
                    let mut a = [0u8; 8];
                    a.copy_from_slice(s);
                    Val::Num(i64::from_le_bytes(a) as f64)
                }
                b'd' => {
                    let s = self.take(8, &what)?;
                    let mut a = [0u8; 8];
                    a.copy_from_slice(s);
                    Val::Num(f64::from_le_bytes(a))
                }
                b's' => Val::Str(self.cstr(&what)?),
                b'o' => Val::Obj(self.object(depth + 1)?),
                b'C' | b'I' | b'Q' | b'D' => {
                    let n = self.u32(&format!("length of {what}"))?;
                    let sz = match t {
                        b'C' => 1,
                        b'I' => 4,
                        _ => 8,
                    };
                    let Some(len) = n.checked_mul(sz) else {
                        bail!("Gwyddion file: {what} length overflows")
                    };
                    let s = self.take(len, &what)?;
                    if t == b'D' {
                        Val::Doubles(s)
                    } else {
                        Val::Other
                    }
                }
                b'S' => {
                    let n = self.u32(&format!("length of {what}"))?;
                    if n > body_end.saturating_sub(self.pos) {
                        bail!("Gwyddion file: {what} declares {n} strings, more than the object holds");
                    }
                    for _ in 0..n {
                        self.cstr(&what)?;
                    }
                    Val::Other
                }
                b'O' => {
                    let n = self.u32(&format!("length of {what}"))?;
                    if n > body_end.saturating_sub(self.pos) {
                        bail!("Gwyddion file: {what} declares {n} objects, more than the object holds");
                    }
                    for _ in 0..n {
                        self.object(depth + 1)?;
                    }
                    Val::Other
                }
                other => bail!("Gwyddion file: {what} has unknown type '{}'", other as char),
            };
            if self.pos > body_end {
                bail!(
                    "Gwyddion file: component {type_name}.{name} runs past the end of its object"
                );
            }
            comps.push((name, v));
        }
        Ok(Obj { type_name, comps })
    }
}

fn unit_of(o: &Obj, k: &str) -> String {
    match o.get(k) {
        Some(Val::Obj(u)) => match u.get("unitstr") {
            Some(Val::Str(s)) => s.clone(),
            _ => String::new(),
        },
        _ => String::new(),
    }
}

pub fn read(b: &[u8]) -> Result<Vec<Channel>> {
    if !b.starts_with(b"GWYP") {
        bail!("not a Gwyddion file (magic is not GWYP)");
    }
    let mut p = P { b, pos: 4 };
    let top = p.object(0)?;
    if top.type_name != "GwyContainer" {
        bail!(
            "Gwyddion file: top-level object is {}, not GwyContainer",
            top.type_name
        );
    }
    let mut fields: Vec<(u64, &Obj)> = Vec::new();
    for (name, v) in &top.comps {
        let Some(id) = name.strip_prefix('/').and_then(|r| r.strip_suffix("/data")) else {
            continue;
        };
        let Ok(id) = id.parse::<u64>() else { continue };
        if let Val::Obj(o) = v {
            if o.type_name == "GwyDataField" {
                fields.push((id, o));
            }
        }
    }
    fields.sort_by_key(|f| f.0);
    let mut titles = std::collections::HashMap::new();
    for (name, v) in &top.comps {
        let Some(id) = name
            .strip_prefix('/')
            .and_then(|r| r.strip_suffix("/data/title"))
        else {
            continue;
        };
        if let (Ok(id), Val::Str(t)) = (id.parse::<u64>(), v) {
            titles.entry(id).or_insert_with(|| t.clone());
        }
    }
    let mut out = Vec::new();
    for (id, f) in fields {
        let ctx = format!("Gwyddion data field /{id}/data");
        let xres = f.num("xres").unwrap_or(0.0);
        let yres = f.num("yres").unwrap_or(0.0);
        let (xres, yres) = check_dims(xres as i64, yres as i64, &format!("{ctx}: xres x yres"))?;
        let xreal = f.num("xreal").unwrap_or(1.0);
        let yreal = f.num("yreal").unwrap_or(1.0);
        let Some(Val::Doubles(raw)) = f.get("data") else {
            bail!("{ctx}: missing component `data`")
        };
        if raw.len() != xres * yres * 8 {
            bail!(
                "{ctx}: `data` holds {} values for {xres}x{yres} pixels",
                raw.len() / 8
            );
        }
        let data = decode(raw, 0, xres * yres, Sample::F64, Endian::Little, &ctx)?;
        let title = titles
            .get(&id)
            .cloned()
            .unwrap_or_else(|| format!("Channel {id}"));
        let mut ch = channel(
            Format::Gwy,
            &title,
            &unit_of(f, "si_unit_z"),
            &unit_of(f, "si_unit_xy"),
            xres,
            yres,
            xreal,
            yreal,
            data,
        )
        .map_err(|e| e.context(&ctx))?;
        ch.offset = (f.num("xoff").unwrap_or(0.0), f.num("yoff").unwrap_or(0.0));
        out.push(ch);
    }
    if out.is_empty() {
        bail!("Gwyddion file has no image data field (/N/data)");
    }
    Ok(out)
}
