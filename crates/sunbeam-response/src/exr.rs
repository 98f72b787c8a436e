//! OpenEXR copy of a response map, for DCC tools (Blender, Nuke, Houdini) that
//! read EXR but not 3D KTX2: the 3D texture laid out as a 2D atlas, the `s`
//! slices stacked downwards (slice `k` in rows `k * n_rho .. (k + 1) * n_rho`,
//! angle along x), half-float channels `R`, `G`, `B` holding X, Y, Z, ZIP
//! compression, the [`Info`](crate::Info) JSON in the header attribute
//! `sunbeam.response` (one custom attribute, so the header is written in a fixed
//! order and the file is byte-identical between runs).

use crate::{Response, INFO_KEY};
use exr::prelude::*;
use sunbeam_common::{Error, Result};

/// Encode a map as EXR bytes.
pub fn encode(r: &Response) -> Result<Vec<u8>> {
    let g = r.info.grid;
    let (w, h) = (g.n_theta, g.n_rho * g.n_s);
    let channel = |c: usize| -> Vec<f16> {
        let mut v = Vec::with_capacity(w * h);
        for k in 0..g.n_s {
            for j in 0..g.n_rho {
                for i in 0..w {
                    v.push(f16::from_bits(r.data[4 * ((k * g.n_rho + j) * w + i) + c]));
                }
            }
        }
        v
    };
    let channels = vec![
        AnyChannel::new("B", FlatSamples::F16(channel(2))),
        AnyChannel::new("G", FlatSamples::F16(channel(1))),
        AnyChannel::new("R", FlatSamples::F16(channel(0))),
    ];
    let info = serde_json::to_string(&r.info).expect("info serialises");
    let mut la = LayerAttributes::default();
    la.other.insert(
        Text::new_or_panic(INFO_KEY),
        AttributeValue::Text(Text::new_or_panic(info.escape_default().to_string())),
    );
    let encoding = Encoding {
        compression: Compression::ZIP16,
        blocks: Blocks::ScanLines,
        line_order: LineOrder::Increasing,
    };
    let layer = Layer::new(
        (w, h),
        la,
        encoding,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let image = Image::from_layer(layer);
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write()
        .non_parallel()
        .to_buffered(&mut out)
        .map_err(|e| Error::internal(format!("OpenEXR encoding: {e}")))?;
    Ok(out.into_inner())
}

/// Write the EXR copy atomically.
pub fn write(r: &Response, path: &std::path::Path) -> Result<()> {
    sunbeam_common::output::write_atomic(path, &encode(r)?)
}
