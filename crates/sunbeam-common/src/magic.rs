//! File signatures, defined once: the readers that sniff content use these.

/// OpenEXR: the first four bytes of every EXR file.
pub const EXR: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// KTX 2.0: the 12-byte file identifier «KTX 20»\r\n\x1A\n.
pub const KTX2: [u8; 12] = [
    0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A,
];

/// Whether `bytes` start like an OpenEXR file.
pub fn is_exr(bytes: &[u8]) -> bool {
    bytes.starts_with(&EXR)
}

/// Whether `bytes` start like a KTX2 file.
pub fn is_ktx2(bytes: &[u8]) -> bool {
    bytes.starts_with(&KTX2)
}

/// The head of a KTX2 file: its header, level index, data format descriptor
/// and key/value data, without the level data (what a reader needs to know
/// what a file holds without reading its texels). `None` when the file is not
/// KTX2; errors name the file.
pub fn read_ktx2_head(path: &std::path::Path) -> crate::Result<Option<Vec<u8>>> {
    use std::io::Read;
    let err = |e: std::io::Error| crate::Error::input_file(path, format!("cannot read: {e}"));
    let mut f = std::fs::File::open(path).map_err(err)?;
    let mut head = vec![0u8; 80];
    let n = f.read(&mut head).map_err(err)?;
    head.truncate(n);
    if !is_ktx2(&head) {
        return Ok(None);
    }
    if head.len() < 80 {
        return Err(crate::Error::input_file(path, "KTX2 header truncated"));
    }
    let at = |o: usize| u32::from_le_bytes(head[o..o + 4].try_into().expect("4 bytes")) as u64;
    // kvdByteOffset + kvdByteLength; the DFD and the level index come before it.
    let end = (at(56) + at(60)).max(at(48) + at(52)).max(80);
    if end > 64 << 20 {
        return Err(crate::Error::input_file(
            path,
            format!("KTX2 header claims {end} bytes of metadata"),
        ));
    }
    let mut rest = Vec::new();
    f.take(end - 80).read_to_end(&mut rest).map_err(err)?;
    head.extend_from_slice(&rest);
    Ok(Some(head))
}

#[cfg(test)]
mod tests {
    #[test]
    fn ktx2_identifier_is_the_spec_string() {
        assert_eq!(&super::KTX2, b"\xABKTX 20\xBB\r\n\x1A\n");
    }
}
