//! Pack files: the one place that knows the containers. Reading dispatches on
//! the content (KTX2 identifier or EXR magic, `sunbeam_common::magic`), writing
//! on [`OutputKind`] (from the output name). A new container is a new
//! submodule here plus a branch in [`Pack::from_bytes`] and [`write_pack`]
//! (docs/dev/ARCHITECTURE.md).

pub mod exr_io;
pub mod ktx2;

use crate::pack::Pack;
use std::path::{Path, PathBuf};
use sunbeam_common::magic;
use sunbeam_common::output::{write_atomic, write_atomic_with};
use sunbeam_common::{Error, Result};

impl Pack {
    /// Read a pack (KTX2 or EXR, detected from the content).
    pub fn read(path: &Path) -> Result<Pack> {
        let bytes = std::fs::read(path).map_err(|e| Error::input_file(path, e))?;
        if magic::is_exr(&bytes) {
            return exr_io::read_path(path, &bytes);
        }
        Self::from_bytes(&bytes).map_err(|e| e.context(path.display()))
    }

    /// Only a pack's manifest: from a KTX2 file's head (the term data is not
    /// read), from an EXR by reading it whole.
    pub fn read_manifest(path: &Path) -> Result<crate::manifest::Manifest> {
        match magic::read_ktx2_head(path)? {
            Some(head) => Ok(ktx2::decode_head(&head)
                .map_err(|e| e.context(path.display()))?
                .0),
            None => Ok(Self::read(path)?.manifest),
        }
    }

    /// Parse a pack from bytes (KTX2 or single-file EXR).
    pub fn from_bytes(bytes: &[u8]) -> Result<Pack> {
        if magic::is_ktx2(bytes) {
            ktx2::decode(bytes)
        } else if magic::is_exr(bytes) {
            exr_io::decode(bytes)
        } else {
            Err(Error::input("not a KTX2 or EXR pack"))
        }
    }
}

/// Whether a file is a pack: a KTX2 file, or an EXR whose header carries the
/// manifest attribute. Reads at most the first 64 KiB.
pub fn is_pack(path: &Path) -> Result<bool> {
    use std::io::Read;
    let mut f = std::fs::File::open(path)
        .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    let mut head = Vec::with_capacity(1 << 16);
    f.by_ref()
        .take(1 << 16)
        .read_to_end(&mut head)
        .map_err(|e| Error::input_file(path, format!("cannot read: {e}")))?;
    if magic::is_ktx2(&head) {
        return Ok(true);
    }
    if magic::is_exr(&head) {
        let key = crate::manifest::MANIFEST_KEY.as_bytes();
        return Ok(head.windows(key.len()).any(|w| w == key));
    }
    Ok(false)
}

/// Output container and layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    Ktx2,
    ExrLayers,
    ExrSplit,
    ExrAtlas,
}

impl OutputKind {
    /// From the output name and the --split/--atlas flags.
    pub fn from_path(path: &Path, split: bool, atlas: bool) -> Result<OutputKind> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        match ext.as_str() {
            "ktx2" => {
                if split || atlas {
                    return Err(Error::usage("--split and --atlas apply to .exr outputs"));
                }
                Ok(OutputKind::Ktx2)
            }
            "exr" => match (split, atlas) {
                (true, true) => Err(Error::usage("--split and --atlas exclude each other")),
                (true, false) => Ok(OutputKind::ExrSplit),
                (false, true) => Ok(OutputKind::ExrAtlas),
                _ => Ok(OutputKind::ExrLayers),
            },
            _ => Err(Error::usage(format!(
                "{}: output must end in .ktx2 or .exr",
                path.display()
            ))),
        }
    }
}

/// Write the pack; returns the files written with their sizes.
pub fn write_pack(pack: &Pack, path: &Path, kind: OutputKind) -> Result<Vec<(PathBuf, u64)>> {
    let writer = pack.manifest.generator.clone();
    match kind {
        OutputKind::Ktx2 => {
            let mut n = 0;
            write_atomic_with(path, |f| {
                let mut w = std::io::BufWriter::new(f);
                n = ktx2::write_to(pack, &writer, &mut w)?;
                use std::io::Write;
                w.flush()
            })?;
            Ok(vec![(path.to_path_buf(), n)])
        }
        OutputKind::ExrLayers => {
            let b = exr_io::encode_layers(pack)?;
            write_atomic(path, &b)?;
            Ok(vec![(path.to_path_buf(), b.len() as u64)])
        }
        OutputKind::ExrAtlas => {
            let b = exr_io::encode_atlas(pack)?;
            write_atomic(path, &b)?;
            Ok(vec![(path.to_path_buf(), b.len() as u64)])
        }
        OutputKind::ExrSplit => {
            let mut out = vec![];
            for n in 0..pack.manifest.terms {
                let p = exr_io::split_path(path, n);
                let b = exr_io::encode_split_term(pack, n)?;
                write_atomic(&p, &b)?;
                out.push((p, b.len() as u64));
            }
            Ok(out)
        }
    }
}
