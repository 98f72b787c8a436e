//! OpenEXR packs, three layouts (docs/PACK_FORMAT.md "EXR"):
//! - `layers`: one file, channels `Pack.nNN.R` / `Pack.nNN.G` (Blender: layer `Pack`, pass `nNN`);
//! - `split`: one file per term `STEM.nNN.exr` with plain `R` / `G` channels (Godot);
//! - `atlas`: one file, plain `R` / `G`, the terms in a grid of cells (Unity flipbooks).
//!
//! Every file carries the manifest in the header attribute `sunbeam.manifest`
//! (JSON, ASCII) and either `sunbeam.layout` (`layers`, `atlas`) or, in split
//! files, `sunbeam.term` (the term number).

use crate::manifest::{Manifest, Precision, MANIFEST_KEY};
use crate::pack::Pack;
use exr::prelude::*;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};

pub const LAYOUT_KEY: &str = "sunbeam.layout";
pub const TERM_KEY: &str = "sunbeam.term";

/// The EXR layout of a pack.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    Layers,
    Split,
    Atlas,
}

impl Layout {
    fn name(self) -> &'static str {
        match self {
            Layout::Layers => "layers",
            Layout::Split => "split",
            Layout::Atlas => "atlas",
        }
    }
}

/// Atlas grid: `cols = ceil(sqrt(N))`, `rows = ceil(N / cols)`; term n in cell
/// (n % cols, n / cols), cells left to right, top to bottom.
pub fn atlas_grid(terms: usize) -> (usize, usize) {
    let mut cols = (terms as f64).sqrt().ceil() as usize;
    while cols * cols < terms {
        cols += 1;
    }
    let cols = cols.max(1);
    (cols, terms.div_ceil(cols))
}

/// JSON with every non-ASCII character escaped (EXR text attributes are bytes).
pub fn ascii_json(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for ch in s.chars() {
        if ch.is_ascii() {
            o.push(ch);
        } else {
            let mut buf = [0u16; 2];
            for u in ch.encode_utf16(&mut buf) {
                o.push_str(&format!("\\u{:04x}", u));
            }
        }
    }
    o
}

/// The file name of term `n` of a split pack written as `path`: `STEM.nNN.exr`.
pub fn split_path(path: &Path, n: usize) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "pack".into());
    path.with_file_name(format!("{stem}.{}.exr", term_name(n)))
}

/// `n00`, `n01`, ... (three digits from 100 on).
pub fn term_name(n: usize) -> String {
    format!("n{n:02}")
}

fn samples(values: Vec<f32>, precision: Precision) -> FlatSamples {
    match precision {
        Precision::F32 => FlatSamples::F32(values),
        Precision::F16 => FlatSamples::F16(values.into_iter().map(f16::from_f32).collect()),
    }
}

/// Write one single-part image. The manifest goes into the layer's attributes and the
/// layout (or the split term) into the image's: each map holds one entry, so the
/// header is written in a fixed order (the exr crate keeps these maps as HashMaps).
fn write_image(
    channels: Vec<AnyChannel<FlatSamples>>,
    size: (usize, usize),
    manifest: &str,
    extra: (&str, String),
) -> Result<Vec<u8>> {
    let mut la = LayerAttributes::default();
    la.other.insert(
        Text::new_or_panic(MANIFEST_KEY),
        AttributeValue::Text(Text::new_or_panic(ascii_json(manifest))),
    );
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        size,
        la,
        encoding,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut image = Image::from_layer(layer);
    image.attributes.other.insert(
        Text::new_or_panic(extra.0),
        AttributeValue::Text(Text::new_or_panic(ascii_json(&extra.1))),
    );
    let mut out = Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut out)
        .map_err(|e| Error::internal(format!("EXR encode: {e}")))?;
    Ok(out.into_inner())
}

fn plane(pack: &Pack, n: usize, comp: usize) -> Vec<f32> {
    let lt = pack.manifest.layer_texels();
    pack.terms[2 * n * lt..2 * (n + 1) * lt]
        .iter()
        .skip(comp)
        .step_by(2)
        .copied()
        .collect()
}

/// Encode as one multi-layer EXR (`Pack.nNN.R/G`).
pub fn encode_layers(pack: &Pack) -> Result<Vec<u8>> {
    let m = &pack.manifest;
    let mut ch = Vec::with_capacity(2 * m.terms);
    for n in 0..m.terms {
        for (c, name) in ["R", "G"].iter().enumerate() {
            ch.push(AnyChannel::new(
                Text::new_or_panic(format!("Pack.{}.{name}", term_name(n))),
                samples(plane(pack, n, c), m.precision),
            ));
        }
    }
    write_image(
        ch,
        (m.crop.width, m.crop.height),
        &m.to_json(),
        (LAYOUT_KEY, Layout::Layers.name().into()),
    )
}

/// Encode term `n` as its own EXR with plain R/G channels.
pub fn encode_split_term(pack: &Pack, n: usize) -> Result<Vec<u8>> {
    let m = &pack.manifest;
    let ch = vec![
        AnyChannel::new("R", samples(plane(pack, n, 0), m.precision)),
        AnyChannel::new("G", samples(plane(pack, n, 1), m.precision)),
    ];
    write_image(
        ch,
        (m.crop.width, m.crop.height),
        &m.to_json(),
        (TERM_KEY, n.to_string()),
    )
}

/// Encode as a grid atlas with plain R/G channels.
pub fn encode_atlas(pack: &Pack) -> Result<Vec<u8>> {
    let m = &pack.manifest;
    let (cols, rows) = atlas_grid(m.terms);
    let (w, h) = (m.crop.width, m.crop.height);
    let aw = cols * w;
    let mut r = vec![0.0f32; aw * rows * h];
    let mut g = vec![0.0f32; aw * rows * h];
    for n in 0..m.terms {
        let (cx, cy) = (n % cols, n / cols);
        for ty in 0..h {
            for tx in 0..w {
                let v = pack.texel(n, tx, ty);
                let i = (cy * h + ty) * aw + cx * w + tx;
                r[i] = v[0];
                g[i] = v[1];
            }
        }
    }
    let ch = vec![
        AnyChannel::new("R", samples(r, m.precision)),
        AnyChannel::new("G", samples(g, m.precision)),
    ];
    write_image(
        ch,
        (aw, rows * h),
        &m.to_json(),
        (LAYOUT_KEY, Layout::Atlas.name().into()),
    )
}

/// What one EXR file holds.
pub struct Decoded {
    pub manifest: Manifest,
    pub layout: Layout,
    /// Split files: the term this file holds.
    pub term: Option<usize>,
    /// (channel name, values) in file order.
    channels: Vec<(String, Vec<f32>)>,
    size: (usize, usize),
}

fn text_attr(
    l: &Layer<AnyChannels<FlatSamples>>,
    img: &ImageAttributes,
    key: &str,
) -> Option<String> {
    let k = Text::new_or_panic(key);
    let v = l.attributes.other.get(&k).or_else(|| img.other.get(&k))?;
    match v {
        AttributeValue::Text(t) => Some(String::from_utf8_lossy(t.as_slice()).into_owned()),
        _ => None,
    }
}

/// Parse one EXR file of a pack.
pub fn decode_file(bytes: &[u8]) -> Result<Decoded> {
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .all_layers()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| Error::input(format!("EXR: {e}")))?;
    let layer = image
        .layer_data
        .first()
        .ok_or_else(|| Error::input("EXR: no layers"))?;
    let text = text_attr(layer, &image.attributes, MANIFEST_KEY).ok_or_else(|| {
        Error::input(format!(
            "EXR: no '{MANIFEST_KEY}' attribute: not a sunbeam pack"
        ))
    })?;
    let manifest = Manifest::from_json(&text)?;
    let term_attr = text_attr(layer, &image.attributes, TERM_KEY);
    let layout = match text_attr(layer, &image.attributes, LAYOUT_KEY).as_deref() {
        _ if term_attr.is_some() => Layout::Split,
        Some("layers") | None => Layout::Layers,
        Some("split") => Layout::Split,
        Some("atlas") => Layout::Atlas,
        Some(o) => return Err(Error::input(format!("EXR: unknown {LAYOUT_KEY} '{o}'"))),
    };
    let term = match term_attr {
        Some(t) => Some(
            t.trim()
                .parse::<usize>()
                .map_err(|_| Error::input(format!("EXR: bad {TERM_KEY} '{t}'")))?,
        ),
        None => None,
    };
    let size = (layer.size.width(), layer.size.height());
    let channels = layer
        .channel_data
        .list
        .iter()
        .map(|c| {
            (
                String::from_utf8_lossy(c.name.as_slice()).into_owned(),
                c.sample_data.values_as_f32().collect(),
            )
        })
        .collect();
    Ok(Decoded {
        manifest,
        layout,
        term,
        channels,
        size,
    })
}

impl Decoded {
    fn channel(&self, name: &str) -> Result<&[f32]> {
        self.channels
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
            .ok_or_else(|| Error::input(format!("EXR: channel '{name}' is missing")))
    }

    fn expect_size(&self, w: usize, h: usize) -> Result<()> {
        if self.size != (w, h) {
            return Err(Error::input(format!(
                "EXR: image is {}x{}, the manifest needs {w}x{h}",
                self.size.0, self.size.1
            )));
        }
        Ok(())
    }

    /// The whole pack from a `layers` or `atlas` file.
    pub fn into_pack(self) -> Result<Pack> {
        let m = self.manifest.clone();
        let (w, h) = (m.crop.width, m.crop.height);
        let lt = w * h;
        let mut terms = vec![0.0f32; 2 * lt * m.terms];
        match self.layout {
            Layout::Layers => {
                self.expect_size(w, h)?;
                for n in 0..m.terms {
                    for (c, name) in ["R", "G"].iter().enumerate() {
                        let v = self.channel(&format!("Pack.{}.{name}", term_name(n)))?;
                        for (i, x) in v.iter().enumerate() {
                            terms[2 * (n * lt + i) + c] = *x;
                        }
                    }
                }
            }
            Layout::Atlas => {
                let (cols, rows) = atlas_grid(m.terms);
                self.expect_size(cols * w, rows * h)?;
                let aw = cols * w;
                for (c, name) in ["R", "G"].iter().enumerate() {
                    let v = self.channel(name)?;
                    for n in 0..m.terms {
                        let (cx, cy) = (n % cols, n / cols);
                        for ty in 0..h {
                            for tx in 0..w {
                                terms[2 * (n * lt + ty * w + tx) + c] =
                                    v[(cy * h + ty) * aw + cx * w + tx];
                            }
                        }
                    }
                }
            }
            Layout::Split => {
                return Err(Error::input(
                    "EXR: one term of a split pack (read it by path)",
                ))
            }
        }
        Pack::new(m, terms)
    }
}

/// Decode a single-file EXR pack (layers or atlas).
pub fn decode(bytes: &[u8]) -> Result<Pack> {
    decode_file(bytes)?.into_pack()
}

/// Read a pack from an EXR path: layers, atlas, or any one file of a split pack
/// (its siblings `STEM.nNN.exr` are read too).
pub fn read_path(path: &Path, bytes: &[u8]) -> Result<Pack> {
    let d = decode_file(bytes).map_err(|e| e.context(path.display()))?;
    if d.layout != Layout::Split {
        return d.into_pack().map_err(|e| e.context(path.display()));
    }
    // STEM.nNN.exr -> the pack's own name STEM.exr, from which split_path derives siblings.
    let name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let base = name
        .strip_suffix(".exr")
        .and_then(|s| s.rsplit_once('.'))
        .map(|(stem, _)| format!("{stem}.exr"))
        .ok_or_else(|| Error::input_file(path, "split pack file is not named STEM.nNN.exr"))?;
    let base = path.with_file_name(base);
    let m = d.manifest.clone();
    let lt = m.layer_texels();
    let mut terms = vec![0.0f32; 2 * lt * m.terms];
    for n in 0..m.terms {
        let p = split_path(&base, n);
        let b = std::fs::read(&p).map_err(|e| Error::input_file(&p, e))?;
        let dn = decode_file(&b).map_err(|e| e.context(p.display()))?;
        if dn.manifest != m || dn.term != Some(n) {
            return Err(Error::input_file(
                &p,
                format!("not term {n} of the same split pack"),
            ));
        }
        dn.expect_size(m.crop.width, m.crop.height)
            .map_err(|e| e.context(p.display()))?;
        for (c, name) in ["R", "G"].iter().enumerate() {
            let v = dn.channel(name).map_err(|e| e.context(p.display()))?;
            for (i, x) in v.iter().enumerate() {
                terms[2 * (n * lt + i) + c] = *x;
            }
        }
    }
    Pack::new(m, terms).map_err(|e| e.context(path.display()))
}
