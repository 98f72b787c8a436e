//! A glTF 2.0 document kept as its JSON tree plus the bytes of its buffers.
//!
//! Keeping the JSON as a `serde_json::Value` is what lets the writer keep
//! everything the input had (materials, textures, extras, extensions it does
//! not know about): the baker only appends buffer views and accessors and
//! points primitive attributes at them.

use base64::Engine;
use serde_json::{json, Map, Value};
use std::path::{Path, PathBuf};
use sunbeam_common::{Error, Result};

/// Component types (glTF 2.0, 3.6.2.2).
pub const BYTE: u64 = 5120;
pub const UNSIGNED_BYTE: u64 = 5121;
pub const SHORT: u64 = 5122;
pub const UNSIGNED_SHORT: u64 = 5123;
pub const UNSIGNED_INT: u64 = 5125;
pub const FLOAT: u64 = 5126;

/// Extensions whose data we cannot decode: refused with a clear message.
const UNSUPPORTED_REQUIRED: &[&str] = &[
    "KHR_draco_mesh_compression",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// A loaded glTF document.
#[derive(Debug, Clone)]
pub struct Document {
    /// The JSON tree, as read.
    pub json: Value,
    /// The bytes of each entry of `buffers` (same order).
    pub buffers: Vec<Vec<u8>>,
    /// Folder that relative URIs resolve against (None for generated documents).
    pub base_dir: Option<PathBuf>,
    /// Source file (for messages).
    pub source: PathBuf,
    /// Every file read besides `source` (external buffers and images), for depfiles.
    pub extra_inputs: Vec<PathBuf>,
}

pub(crate) fn bad(path: &Path, msg: impl std::fmt::Display) -> Error {
    Error::input_file(path, msg)
}

impl Document {
    /// Load `.gltf` or `.glb` (decided from the content: a GLB starts with `glTF`).
    pub fn load(path: &Path) -> Result<Document> {
        let bytes = std::fs::read(path).map_err(|e| bad(path, format!("cannot read: {e}")))?;
        Self::from_bytes(&bytes, path)
    }

    /// Parse bytes that came from `path` (used to resolve relative URIs and name errors).
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Document> {
        let base_dir = path.parent().map(|p| {
            if p.as_os_str().is_empty() {
                PathBuf::from(".")
            } else {
                p.to_path_buf()
            }
        });
        let (json_bytes, bin) = if bytes.len() >= 4 && &bytes[0..4] == b"glTF" {
            parse_glb(bytes, path)?
        } else {
            (bytes, None)
        };
        let json: Value = serde_json::from_slice(json_bytes)
            .map_err(|e| bad(path, format!("not valid glTF JSON: {e}")))?;
        if !json.is_object() {
            return Err(bad(path, "glTF JSON is not an object"));
        }
        let version = json
            .pointer("/asset/version")
            .and_then(Value::as_str)
            .unwrap_or("");
        if !version.starts_with("2.") {
            return Err(bad(
                path,
                format!("asset.version is {version:?}; only glTF 2.x is supported"),
            ));
        }
        if let Some(req) = json.get("extensionsRequired").and_then(Value::as_array) {
            for e in req.iter().filter_map(Value::as_str) {
                if UNSUPPORTED_REQUIRED.contains(&e) {
                    return Err(bad(
                        path,
                        format!("uses the compression extension {e}, which sunbeam-mesh cannot decode (decompress first, e.g. `gltf-transform copy in.glb out.glb`)"),
                    ));
                }
            }
        }
        let mut doc = Document {
            json,
            buffers: Vec::new(),
            base_dir,
            source: path.to_path_buf(),
            extra_inputs: Vec::new(),
        };
        let bufs = doc
            .json
            .get("buffers")
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default();
        let mut bin = bin;
        for (i, b) in bufs.iter().enumerate() {
            let len = b
                .get("byteLength")
                .and_then(Value::as_u64)
                .ok_or_else(|| bad(path, format!("buffers[{i}].byteLength missing")))?
                as usize;
            let data = match b.get("uri").and_then(Value::as_str) {
                None => {
                    if i != 0 {
                        return Err(bad(
                            path,
                            format!("buffers[{i}] has no uri (only buffer 0 of a GLB may)"),
                        ));
                    }
                    bin.take()
                        .ok_or_else(|| {
                            bad(path, "buffers[0] has no uri and there is no GLB BIN chunk")
                        })?
                        .to_vec()
                }
                Some(uri) => doc.read_uri(uri, &format!("buffers[{i}]"))?.0,
            };
            if data.len() < len {
                return Err(bad(
                    path,
                    format!(
                        "buffers[{i}] holds {} bytes, byteLength says {len}",
                        data.len()
                    ),
                ));
            }
            let mut data = data;
            data.truncate(len);
            doc.buffers.push(data);
        }
        Ok(doc)
    }

    /// Read a URI (data: or a relative file). Returns the bytes and a MIME type if the URI had one.
    pub fn read_uri(&mut self, uri: &str, what: &str) -> Result<(Vec<u8>, Option<String>)> {
        if let Some(rest) = uri.strip_prefix("data:") {
            let (meta, data) = rest
                .split_once(',')
                .ok_or_else(|| bad(&self.source, format!("{what}: malformed data URI")))?;
            let mime = meta
                .split(';')
                .next()
                .filter(|m| !m.is_empty())
                .map(str::to_string);
            if !meta.ends_with(";base64") {
                return Err(bad(&self.source, format!("{what}: data URI is not base64")));
            }
            let bytes = base64::engine::general_purpose::STANDARD
                .decode(data.trim())
                .map_err(|e| bad(&self.source, format!("{what}: bad base64 in data URI: {e}")))?;
            return Ok((bytes, mime));
        }
        let rel = percent_decode(uri);
        if rel.contains("://") {
            return Err(bad(
                &self.source,
                format!("{what}: URI {uri:?} is not a relative file"),
            ));
        }
        let base = self.base_dir.clone().unwrap_or_else(|| PathBuf::from("."));
        let p = base.join(&rel);
        let bytes = std::fs::read(&p).map_err(|e| {
            bad(
                &self.source,
                format!("{what}: cannot read {}: {e}", p.display()),
            )
        })?;
        self.extra_inputs.push(p);
        Ok((bytes, None))
    }

    pub fn array(&self, key: &str) -> &[Value] {
        self.json
            .get(key)
            .and_then(Value::as_array)
            .map(|v| v.as_slice())
            .unwrap_or(&[])
    }

    fn err(&self, msg: impl std::fmt::Display) -> Error {
        bad(&self.source, msg)
    }

    /// Read accessor `idx` as f64 elements (normalized integers are mapped to
    /// [0,1] / [-1,1]); returns (flat values, component count).
    pub fn read_accessor(&self, idx: usize) -> Result<(Vec<f64>, usize)> {
        let acc = self
            .array("accessors")
            .get(idx)
            .ok_or_else(|| self.err(format!("accessors[{idx}] does not exist")))?;
        let what = format!("accessors[{idx}]");
        let count = acc
            .get("count")
            .and_then(Value::as_u64)
            .ok_or_else(|| self.err(format!("{what}.count missing")))? as usize;
        let ctype = acc
            .get("componentType")
            .and_then(Value::as_u64)
            .ok_or_else(|| self.err(format!("{what}.componentType missing")))?;
        let ncomp = match acc.get("type").and_then(Value::as_str) {
            Some("SCALAR") => 1,
            Some("VEC2") => 2,
            Some("VEC3") => 3,
            Some("VEC4") => 4,
            Some("MAT2") => 4,
            Some("MAT3") => 9,
            Some("MAT4") => 16,
            t => return Err(self.err(format!("{what}.type {t:?} is not valid"))),
        };
        let csize = comp_size(ctype)
            .ok_or_else(|| self.err(format!("{what}.componentType {ctype} is not valid")))?;
        let normalized = acc
            .get("normalized")
            .and_then(Value::as_bool)
            .unwrap_or(false);
        let total = count
            .checked_mul(ncomp)
            .filter(|&t| t <= 1 << 30)
            .ok_or_else(|| self.err(format!("{what}.count {count} too large")))?;
        let mut out = Vec::new();
        if let Some(bv) = acc.get("bufferView").and_then(Value::as_u64) {
            let off = acc.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
            let (data, stride) = self.view_bytes(bv as usize, &what)?;
            let elem = csize * ncomp;
            let stride = stride.unwrap_or(elem);
            if count > 0 {
                let need = off
                    .checked_add(
                        (count - 1)
                            .checked_mul(stride)
                            .ok_or_else(|| self.err(format!("{what} too large")))?,
                    )
                    .and_then(|x| x.checked_add(elem))
                    .ok_or_else(|| self.err(format!("{what} too large")))?;
                if need > data.len() {
                    return Err(self.err(format!(
                        "{what} needs {need} bytes of bufferView {bv}, which has {}",
                        data.len()
                    )));
                }
            }
            out = vec![0.0f64; total];
            for i in 0..count {
                let base = off + i * stride;
                for c in 0..ncomp {
                    out[i * ncomp + c] = read_comp(&data[base + c * csize..], ctype, normalized);
                }
            }
        }
        if out.is_empty() {
            // No buffer view: zeros (count checked above; a sparse part may follow).
            out = vec![0.0f64; total];
        }
        if let Some(sp) = acc.get("sparse") {
            let n = sp.get("count").and_then(Value::as_u64).unwrap_or(0) as usize;
            let ind = sp
                .get("indices")
                .ok_or_else(|| self.err(format!("{what}.sparse.indices missing")))?;
            let val = sp
                .get("values")
                .ok_or_else(|| self.err(format!("{what}.sparse.values missing")))?;
            let ibv = ind
                .get("bufferView")
                .and_then(Value::as_u64)
                .ok_or_else(|| self.err(format!("{what}.sparse.indices.bufferView missing")))?;
            let ict = ind
                .get("componentType")
                .and_then(Value::as_u64)
                .unwrap_or(UNSIGNED_INT);
            let ioff = ind.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
            let vbv = val
                .get("bufferView")
                .and_then(Value::as_u64)
                .ok_or_else(|| self.err(format!("{what}.sparse.values.bufferView missing")))?;
            let voff = val.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
            let (idata, _) = self.view_bytes(ibv as usize, &what)?;
            let (vdata, _) = self.view_bytes(vbv as usize, &what)?;
            let isz = comp_size(ict)
                .ok_or_else(|| self.err(format!("{what}.sparse.indices.componentType invalid")))?;
            if ioff + n * isz > idata.len() || voff + n * ncomp * csize > vdata.len() {
                return Err(self.err(format!("{what}.sparse runs past its buffer views")));
            }
            for k in 0..n {
                let i = read_comp(&idata[ioff + k * isz..], ict, false) as usize;
                if i >= count {
                    return Err(self.err(format!("{what}.sparse index {i} >= count {count}")));
                }
                for c in 0..ncomp {
                    out[i * ncomp + c] =
                        read_comp(&vdata[voff + (k * ncomp + c) * csize..], ctype, normalized);
                }
            }
        }
        if out.iter().any(|x| !x.is_finite()) {
            return Err(self.err(format!("{what} holds NaN or infinite values")));
        }
        Ok((out, ncomp))
    }

    /// The bytes of a buffer view and its stride.
    pub fn view_bytes(&self, bv: usize, what: &str) -> Result<(&[u8], Option<usize>)> {
        let v = self
            .array("bufferViews")
            .get(bv)
            .ok_or_else(|| self.err(format!("{what}: bufferViews[{bv}] does not exist")))?;
        let b = v
            .get("buffer")
            .and_then(Value::as_u64)
            .ok_or_else(|| self.err(format!("bufferViews[{bv}].buffer missing")))?
            as usize;
        let off = v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
        let len = v
            .get("byteLength")
            .and_then(Value::as_u64)
            .ok_or_else(|| self.err(format!("bufferViews[{bv}].byteLength missing")))?
            as usize;
        let buf = self
            .buffers
            .get(b)
            .ok_or_else(|| self.err(format!("bufferViews[{bv}].buffer {b} does not exist")))?;
        let end = off
            .checked_add(len)
            .filter(|&e| e <= buf.len())
            .ok_or_else(|| {
                self.err(format!(
                    "bufferViews[{bv}] runs past the end of buffers[{b}]"
                ))
            })?;
        let stride = v
            .get("byteStride")
            .and_then(Value::as_u64)
            .map(|s| s as usize)
            .filter(|&s| s > 0);
        Ok((&buf[off..end], stride))
    }

    /// Append a tightly packed float accessor (VEC2/VEC3/VEC4) in a new buffer view of
    /// buffer 0 (call only on a document whose buffers were merged by [`Document::to_glb`]'s
    /// preparation, or on a generated one). Returns the accessor index.
    pub fn push_f32_accessor(&mut self, data: &[f32], ncomp: usize, with_bounds: bool) -> usize {
        if self.buffers.is_empty() {
            self.buffers.push(Vec::new());
            let arr = self.json_array_mut("buffers");
            arr.push(json!({"byteLength": 0}));
        }
        let buf = &mut self.buffers[0];
        buf.resize(buf.len().next_multiple_of(4), 0);
        let off = buf.len();
        for x in data {
            buf.extend_from_slice(&x.to_le_bytes());
        }
        let len = buf.len() - off;
        let bv = {
            let views = self.json_array_mut("bufferViews");
            views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": len, "target": 34962}));
            views.len() - 1
        };
        self.sync_len();
        let ty = ["SCALAR", "VEC2", "VEC3", "VEC4"][ncomp - 1];
        let mut acc = json!({"bufferView": bv, "componentType": FLOAT, "count": data.len() / ncomp, "type": ty});
        if with_bounds {
            let mut mn = vec![f32::INFINITY; ncomp];
            let mut mx = vec![f32::NEG_INFINITY; ncomp];
            for ch in data.chunks(ncomp) {
                for c in 0..ncomp {
                    mn[c] = mn[c].min(ch[c]);
                    mx[c] = mx[c].max(ch[c]);
                }
            }
            acc["min"] = json!(mn);
            acc["max"] = json!(mx);
        }
        let accs = self.json_array_mut("accessors");
        accs.push(acc);
        accs.len() - 1
    }

    /// Append an index accessor (u32, or u16 when it fits).
    pub fn push_index_accessor(&mut self, idx: &[u32]) -> usize {
        if self.buffers.is_empty() {
            self.buffers.push(Vec::new());
            self.json_array_mut("buffers")
                .push(json!({"byteLength": 0}));
        }
        let small = idx.iter().all(|&i| i < 65535);
        let buf = &mut self.buffers[0];
        buf.resize(buf.len().next_multiple_of(4), 0);
        let off = buf.len();
        for &i in idx {
            if small {
                buf.extend_from_slice(&(i as u16).to_le_bytes());
            } else {
                buf.extend_from_slice(&i.to_le_bytes());
            }
        }
        let len = buf.len() - off;
        self.sync_len();
        let views = self.json_array_mut("bufferViews");
        views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": len, "target": 34963}));
        let bv = views.len() - 1;
        let accs = self.json_array_mut("accessors");
        accs.push(json!({"bufferView": bv, "componentType": if small { UNSIGNED_SHORT } else { UNSIGNED_INT }, "count": idx.len(), "type": "SCALAR"}));
        accs.len() - 1
    }

    /// Append raw bytes as a buffer view (no target), e.g. an image. Returns the view index.
    pub fn push_bytes_view(&mut self, bytes: &[u8]) -> usize {
        if self.buffers.is_empty() {
            self.buffers.push(Vec::new());
            self.json_array_mut("buffers")
                .push(json!({"byteLength": 0}));
        }
        let buf = &mut self.buffers[0];
        buf.resize(buf.len().next_multiple_of(4), 0);
        let off = buf.len();
        buf.extend_from_slice(bytes);
        self.sync_len();
        let views = self.json_array_mut("bufferViews");
        views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": bytes.len()}));
        views.len() - 1
    }

    /// Keep `buffers[0].byteLength` equal to the bytes held.
    fn sync_len(&mut self) {
        let len = self.buffers.first().map_or(0, |b| b.len());
        if let Some(b0) = self
            .json_array_mut("buffers")
            .first_mut()
            .and_then(Value::as_object_mut)
        {
            b0.insert("byteLength".into(), json!(len));
        }
    }

    pub fn json_array_mut(&mut self, key: &str) -> &mut Vec<Value> {
        let obj = self
            .json
            .as_object_mut()
            .expect("glTF root is an object (checked on load)");
        let e = obj
            .entry(key.to_string())
            .or_insert_with(|| Value::Array(Vec::new()));
        if !e.is_array() {
            *e = Value::Array(Vec::new());
        }
        e.as_array_mut().expect("just made an array")
    }

    /// Merge every buffer into buffer 0 and embed every external or data-URI
    /// image into it, so the document can be written as one self-contained GLB.
    pub fn merge_buffers(&mut self) -> Result<()> {
        let mut merged: Vec<u8> = Vec::new();
        let mut bases = Vec::with_capacity(self.buffers.len());
        for b in &self.buffers {
            merged.resize(merged.len().next_multiple_of(16), 0);
            bases.push(merged.len());
            merged.extend_from_slice(b);
        }
        let nbuf = self.buffers.len();
        let views = self.json_array_mut("bufferViews");
        for (i, v) in views.iter_mut().enumerate() {
            let b = v.get("buffer").and_then(Value::as_u64).unwrap_or(u64::MAX) as usize;
            if b >= nbuf {
                return Err(Error::input_file(
                    &self.source,
                    format!("bufferViews[{i}].buffer {b} does not exist"),
                ));
            }
            let off = v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize + bases[b];
            let Some(o) = v.as_object_mut() else {
                return Err(Error::input_file(
                    &self.source,
                    format!("bufferViews[{i}] is not an object"),
                ));
            };
            o.insert("buffer".into(), json!(0));
            o.insert("byteOffset".into(), json!(off));
        }
        // Buffer 0 keeps its name/extras, loses its uri.
        let mut b0 = self
            .array("buffers")
            .first()
            .cloned()
            .unwrap_or_else(|| json!({}));
        if let Some(o) = b0.as_object_mut() {
            o.remove("uri");
        }
        self.buffers = vec![merged];
        *self.json_array_mut("buffers") = vec![b0];
        // Images with a uri: embed.
        let images = self.array("images").to_vec();
        for (i, img) in images.iter().enumerate() {
            if let Some(uri) = img.get("uri").and_then(Value::as_str) {
                let (bytes, mime) = self.read_uri(uri, &format!("images[{i}]"))?;
                let mime = img
                    .get("mimeType")
                    .and_then(Value::as_str)
                    .map(str::to_string)
                    .or(mime)
                    .or_else(|| sniff_mime(&bytes).map(str::to_string))
                    .ok_or_else(|| {
                        Error::input_file(
                            &self.source,
                            format!("images[{i}]: cannot tell the image type of {uri:?}"),
                        )
                    })?;
                let bv = self.push_bytes_view(&bytes);
                let im = &mut self.json_array_mut("images")[i];
                if let Some(o) = im.as_object_mut() {
                    o.remove("uri");
                    o.insert("bufferView".into(), json!(bv));
                    o.insert("mimeType".into(), json!(mime));
                }
            }
        }
        Ok(())
    }

    /// Serialise as GLB (call [`Document::merge_buffers`] first when the document was loaded).
    pub fn to_glb(&mut self) -> Vec<u8> {
        if self.buffers.is_empty() {
            // A document without geometry: no buffers at all.
        } else {
            self.sync_len();
        }
        // Empty top-level arrays are invalid glTF ("must have at least 1 item").
        if let Some(o) = self.json.as_object_mut() {
            let empty: Vec<String> = o
                .iter()
                .filter(|(_, v)| v.as_array().is_some_and(|a| a.is_empty()))
                .map(|(k, _)| k.clone())
                .collect();
            for k in empty {
                o.remove(&k);
            }
        }
        let mut js = serde_json::to_vec(&self.json).expect("a JSON value always serialises");
        js.resize(js.len().next_multiple_of(4), b' ');
        let mut bin = self.buffers.first().cloned().unwrap_or_default();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12
            + 8
            + js.len()
            + if self.buffers.is_empty() {
                0
            } else {
                8 + bin.len()
            };
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&(total as u32).to_le_bytes());
        out.extend_from_slice(&(js.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&js);
        if !self.buffers.is_empty() {
            out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&bin);
        }
        out
    }

    /// A new empty document (asset only).
    pub fn new_empty(source: &Path) -> Document {
        let mut asset = Map::new();
        asset.insert("version".into(), json!("2.0"));
        asset.insert(
            "generator".into(),
            json!(concat!("sunbeam-mesh ", env!("CARGO_PKG_VERSION"))),
        );
        Document {
            json: json!({ "asset": Value::Object(asset) }),
            buffers: Vec::new(),
            base_dir: None,
            source: source.to_path_buf(),
            extra_inputs: Vec::new(),
        }
    }
}

fn parse_glb<'a>(bytes: &'a [u8], path: &Path) -> Result<(&'a [u8], Option<&'a [u8]>)> {
    let u32at = |o: usize| -> Option<u32> {
        bytes
            .get(o..o + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    if bytes.len() < 20 {
        return Err(bad(
            path,
            "GLB shorter than its 12-byte header and first chunk header",
        ));
    }
    let version = u32at(4).unwrap_or(0);
    if version != 2 {
        return Err(bad(
            path,
            format!("GLB version {version}; only 2 is supported"),
        ));
    }
    let total = u32at(8).unwrap_or(0) as usize;
    if total > bytes.len() {
        return Err(bad(
            path,
            format!(
                "GLB header says {total} bytes, the file has {} (truncated?)",
                bytes.len()
            ),
        ));
    }
    let mut off = 12;
    let mut json = None;
    let mut bin = None;
    while off + 8 <= total {
        let len = u32at(off).unwrap_or(0) as usize;
        let ty = u32at(off + 4).unwrap_or(0);
        let start = off + 8;
        let end = start
            .checked_add(len)
            .filter(|&e| e <= total)
            .ok_or_else(|| {
                bad(
                    path,
                    format!("GLB chunk at byte {off} runs past the end of the file"),
                )
            })?;
        match ty {
            0x4E4F534A if json.is_none() => json = Some(&bytes[start..end]),
            0x004E4942 if bin.is_none() => bin = Some(&bytes[start..end]),
            _ => {}
        }
        off = end;
    }
    let json = json.ok_or_else(|| bad(path, "GLB has no JSON chunk"))?;
    Ok((json, bin))
}

fn comp_size(ctype: u64) -> Option<usize> {
    match ctype {
        BYTE | UNSIGNED_BYTE => Some(1),
        SHORT | UNSIGNED_SHORT => Some(2),
        UNSIGNED_INT | FLOAT => Some(4),
        _ => None,
    }
}

fn read_comp(b: &[u8], ctype: u64, normalized: bool) -> f64 {
    match ctype {
        BYTE => {
            let v = b[0] as i8 as f64;
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        UNSIGNED_BYTE => {
            let v = b[0] as f64;
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        SHORT => {
            let v = i16::from_le_bytes([b[0], b[1]]) as f64;
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        UNSIGNED_SHORT => {
            let v = u16::from_le_bytes([b[0], b[1]]) as f64;
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
        UNSIGNED_INT => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
        _ => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
    }
}

fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' && i + 2 < b.len() {
            if let Some(v) = std::str::from_utf8(&b[i + 1..i + 3])
                .ok()
                .and_then(|h| u8::from_str_radix(h, 16).ok())
            {
                out.push(v);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

pub(crate) fn sniff_mime(b: &[u8]) -> Option<&'static str> {
    if b.starts_with(&[0x89, b'P', b'N', b'G']) {
        Some("image/png")
    } else if b.starts_with(&[0xFF, 0xD8]) {
        Some("image/jpeg")
    } else if b.len() > 12 && &b[0..4] == b"RIFF" && &b[8..12] == b"WEBP" {
        Some("image/webp")
    } else if sunbeam_common::magic::is_ktx2(b) {
        Some("image/ktx2")
    } else {
        None
    }
}
