//! A minimal, bounds-checked classic TIFF directory reader (enough for Park
//! Systems and JPK private tags and uncompressed grey images).

use sunbeam_common::Result;

use crate::util::{bail, slice, u16_at, u32_at, Endian};
use crate::Format;

#[derive(Debug, Clone)]
pub struct Entry {
    pub tag: u16,
    pub typ: u16,
    pub count: u32,
    /// Absolute offset of the value bytes (inline or pointed to).
    pub off: usize,
}

#[derive(Debug, Clone, Default)]
pub struct Ifd {
    pub entries: Vec<Entry>,
}

pub struct Tiff<'a> {
    pub b: &'a [u8],
    pub e: Endian,
    pub ifds: Vec<Ifd>,
}

const MAX_IFDS: usize = 1024;
/// Entries over all directories (directories may overlap in a hostile file).
const MAX_ENTRIES: usize = 1 << 18;

fn type_size(t: u16) -> usize {
    match t {
        1 | 2 | 6 | 7 => 1,
        3 | 8 => 2,
        4 | 9 | 11 | 13 => 4,
        5 | 10 | 12 => 8,
        _ => 1,
    }
}

impl<'a> Tiff<'a> {
    pub fn parse(b: &'a [u8]) -> Result<Tiff<'a>> {
        let e = if b.starts_with(b"II*\0") {
            Endian::Little
        } else if b.starts_with(b"MM\0*") {
            Endian::Big
        } else {
            bail!("not a TIFF file (no II*/MM* magic)");
        };
        let mut off = u32_at(b, 4, e, "TIFF first IFD offset")? as usize;
        let mut ifds = Vec::new();
        let mut seen = std::collections::HashSet::new();
        let mut total = 0usize;
        while off != 0 {
            if !seen.insert(off) || ifds.len() >= MAX_IFDS {
                bail!("TIFF IFD chain loops or is longer than {MAX_IFDS}");
            }
            let n = u16_at(b, off, e, "TIFF IFD entry count")? as usize;
            slice(b, off + 2, n * 12 + 4, "TIFF IFD entries")?;
            total += n;
            if total > MAX_ENTRIES {
                bail!("TIFF directories hold more than {MAX_ENTRIES} entries");
            }
            let mut entries = Vec::with_capacity(n);
            for i in 0..n {
                let p = off + 2 + 12 * i;
                let tag = u16_at(b, p, e, "TIFF tag")?;
                let typ = u16_at(b, p + 2, e, "TIFF tag type")?;
                let count = u32_at(b, p + 4, e, "TIFF tag count")?;
                let size = (count as u64) * type_size(typ) as u64;
                let voff = if size <= 4 {
                    p + 8
                } else {
                    u32_at(b, p + 8, e, "TIFF tag offset")? as usize
                };
                entries.push(Entry {
                    tag,
                    typ,
                    count,
                    off: voff,
                });
            }
            ifds.push(Ifd { entries });
            off = u32_at(b, off + 2 + 12 * n, e, "TIFF next IFD offset")? as usize;
        }
        Ok(Tiff { b, e, ifds })
    }

    pub fn bytes(&self, en: &Entry) -> Result<&'a [u8]> {
        let len = en.count as usize * type_size(en.typ);
        slice(self.b, en.off, len, &format!("TIFF tag {} value", en.tag))
    }

    /// Unsigned integer values of a BYTE/SHORT/LONG tag (count checked against the file first).
    pub fn uints(&self, en: &Entry) -> Result<Vec<u64>> {
        let raw = self.bytes(en)?;
        let mut v = Vec::with_capacity(en.count as usize);
        match en.typ {
            1 | 7 => v.extend(raw.iter().map(|&x| x as u64)),
            3 => {
                for c in raw.chunks_exact(2) {
                    v.push(u16_at(c, 0, self.e, "")? as u64)
                }
            }
            4 | 13 => {
                for c in raw.chunks_exact(4) {
                    v.push(u32_at(c, 0, self.e, "")? as u64)
                }
            }
            t => bail!("TIFF tag {}: type {t} is not an unsigned integer", en.tag),
        }
        Ok(v)
    }

    pub fn uint(&self, ifd: &Ifd, tag: u16) -> Result<Option<u64>> {
        match ifd.get(tag) {
            None => Ok(None),
            Some(en) => Ok(self.uints(en)?.first().copied()),
        }
    }

    /// A numeric tag as f64 (integer, float, double or rational).
    pub fn num(&self, ifd: &Ifd, tag: u16) -> Result<Option<f64>> {
        let Some(en) = ifd.get(tag) else {
            return Ok(None);
        };
        let raw = self.bytes(en)?;
        if raw.is_empty() {
            return Ok(None);
        }
        let e = self.e;
        let v = match en.typ {
            1 | 3 | 4 | 7 | 13 => self.uints(en)?[0] as f64,
            6 => raw[0] as i8 as f64,
            8 => u16_at(raw, 0, e, "")? as i16 as f64,
            9 => u32_at(raw, 0, e, "")? as i32 as f64,
            11 => f32::from_bits(u32_at(raw, 0, e, "")?) as f64,
            12 => crate::util::f64_at(raw, 0, e, "")?,
            5 => u32_at(raw, 0, e, "")? as f64 / u32_at(raw, 4, e, "")? as f64,
            10 => u32_at(raw, 0, e, "")? as i32 as f64 / u32_at(raw, 4, e, "")? as i32 as f64,
            _ => return Ok(None),
        };
        Ok(Some(v))
    }

    pub fn ascii(&self, ifd: &Ifd, tag: u16) -> Result<Option<String>> {
        let Some(en) = ifd.get(tag) else {
            return Ok(None);
        };
        let raw = self.bytes(en)?;
        let end = raw.iter().position(|&c| c == 0).unwrap_or(raw.len());
        Ok(Some(String::from_utf8_lossy(&raw[..end]).into_owned()))
    }

    /// The concatenated strips of an uncompressed image: exactly `need` bytes.
    pub fn strips(&self, ifd: &Ifd, need: usize, what: &str) -> Result<Vec<u8>> {
        let comp = self.uint(ifd, 259)?.unwrap_or(1);
        if comp != 1 {
            bail!("{what}: compressed TIFF (Compression = {comp}) is not supported; save it uncompressed or convert it with `gwyddion --convert-to-gwy`");
        }
        let (Some(offs), Some(cnts)) = (ifd.get(273), ifd.get(279)) else {
            bail!("{what}: missing StripOffsets/StripByteCounts (tiled TIFF is not supported)")
        };
        let offs = self.uints(offs)?;
        let cnts = self.uints(cnts)?;
        if offs.len() != cnts.len() {
            bail!(
                "{what}: {} StripOffsets but {} StripByteCounts",
                offs.len(),
                cnts.len()
            );
        }
        let total: u64 = cnts.iter().sum();
        if total < need as u64 {
            bail!("{what}: strips hold {total} bytes, the image needs {need}");
        }
        let mut out = Vec::with_capacity(need);
        for (&o, &c) in offs.iter().zip(&cnts) {
            if out.len() >= need {
                break;
            }
            let take = (c as usize).min(need - out.len());
            out.extend_from_slice(slice(self.b, o as usize, take, &format!("{what} strip"))?);
        }
        Ok(out)
    }
}

impl Ifd {
    pub fn get(&self, tag: u16) -> Option<&Entry> {
        self.entries.iter().find(|e| e.tag == tag)
    }
}

/// Park Systems, JPK, or a plain TIFF image.
pub fn classify(b: &[u8]) -> Format {
    match Tiff::parse(b) {
        Ok(t) => {
            let first = t.ifds.first();
            if first.is_some_and(|i| i.get(50432).is_some()) {
                Format::ParkTiff
            } else if first.is_some_and(|i| {
                i.get(32816).is_some() || i.get(32768).is_some() && i.get(32848).is_some()
            }) || t.ifds.iter().skip(1).any(|i| i.get(32848).is_some())
            {
                Format::Jpk
            } else {
                Format::Tiff
            }
        }
        Err(_) => Format::Tiff,
    }
}
