//! Height-field files: single-channel float32 OpenEXR and Gwyddion Simple Field
//! (`.gsf`). Both writers are deterministic: the same field gives the same bytes.

pub mod exr;
pub mod gsf;

use crate::HeightField;
use std::path::Path;
use sunbeam_common::output::write_atomic;
use sunbeam_common::{Error, Result};

/// The file kinds this module writes, chosen from the output file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Exr,
    Gsf,
}

impl Kind {
    /// `.exr` or `.gsf` (case-insensitive); anything else is a usage error.
    pub fn from_path(path: &Path) -> Result<Kind> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "exr" => Ok(Kind::Exr),
            "gsf" => Ok(Kind::Gsf),
            _ => Err(Error::usage(format!(
                "{}: unknown output type '.{ext}' (use .exr or .gsf)",
                path.display()
            ))),
        }
    }

    /// Guess from content (magic bytes).
    pub fn sniff(bytes: &[u8]) -> Option<Kind> {
        if bytes.starts_with(&exr::MAGIC) {
            Some(Kind::Exr)
        } else if bytes.starts_with(gsf::MAGIC.as_bytes()) {
            Some(Kind::Gsf)
        } else {
            None
        }
    }
}

/// Encode a field in the given kind.
pub fn encode(kind: Kind, field: &HeightField) -> Result<Vec<u8>> {
    match kind {
        Kind::Exr => exr::encode(field),
        Kind::Gsf => gsf::encode(field),
    }
}

/// Write `field` to `path` (kind from the extension), atomically.
pub fn write(path: &Path, field: &HeightField) -> Result<()> {
    let kind = Kind::from_path(path)?;
    let bytes = encode(kind, field)?;
    write_atomic(path, &bytes)
}

/// Decode a height-field file from memory (kind from its content).
/// Errors are `Error::input` without a file name.
pub fn decode(bytes: &[u8]) -> Result<HeightField> {
    match Kind::sniff(bytes) {
        Some(Kind::Exr) => exr::decode(bytes),
        Some(Kind::Gsf) => gsf::decode(bytes),
        None => Err(Error::input(
            "not an OpenEXR or Gwyddion Simple Field file (unknown magic bytes)",
        )),
    }
}

/// Read a height field written by [`write`] (or by Gwyddion / any EXR tool).
/// Messages are prefixed with the file name.
pub fn read(path: &Path) -> Result<HeightField> {
    let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e))?;
    decode(&bytes).map_err(|e| e.context(path.display()))
}
