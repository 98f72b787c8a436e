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

#[cfg(test)]
mod tests {
    #[test]
    fn ktx2_identifier_is_the_spec_string() {
        assert_eq!(&super::KTX2, b"\xABKTX 20\xBB\r\n\x1A\n");
    }
}
