//! Text helpers for the instrument headers read by nid, mi, wsxm and mdt:
//! legacy 8-bit encodings, C-style `atol`, and Gwyddion's title fall-back.

/// Bytes as text: UTF-8 when valid, else ISO-8859-1 (every byte one char),
/// as Gwyddion converts these headers.
pub fn latin1_or_utf8(b: &[u8]) -> String {
    match std::str::from_utf8(b) {
        Ok(s) => s.to_string(),
        Err(_) => b.iter().map(|&c| c as char).collect(),
    }
}

/// Windows-1251 (Cyrillic) bytes as text (NT-MDT titles); UTF-8 when valid.
pub fn cp1251_or_utf8(b: &[u8]) -> String {
    if let Ok(s) = std::str::from_utf8(b) {
        return s.to_string();
    }
    // 0x80..0xBF; 0xC0..0xFF are U+0410..U+044F.
    const HI: [u16; 64] = [
        0x0402, 0x0403, 0x201A, 0x0453, 0x201E, 0x2026, 0x2020, 0x2021, 0x20AC, 0x2030, 0x0409,
        0x2039, 0x040A, 0x040C, 0x040B, 0x040F, 0x0452, 0x2018, 0x2019, 0x201C, 0x201D, 0x2022,
        0x2013, 0x2014, 0xFFFD, 0x2122, 0x0459, 0x203A, 0x045A, 0x045C, 0x045B, 0x045F, 0x00A0,
        0x040E, 0x045E, 0x0408, 0x00A4, 0x0490, 0x00A6, 0x00A7, 0x0401, 0x00A9, 0x0404, 0x00AB,
        0x00AC, 0x00AD, 0x00AE, 0x0407, 0x00B0, 0x00B1, 0x0406, 0x0456, 0x0491, 0x00B5, 0x00B6,
        0x00B7, 0x0451, 0x2116, 0x0454, 0x00BB, 0x0458, 0x0405, 0x0455, 0x0457,
    ];
    b.iter()
        .map(|&c| match c {
            0..=0x7F => c as char,
            0x80..=0xBF => char::from_u32(HI[(c - 0x80) as usize] as u32).unwrap_or('\u{FFFD}'),
            _ => char::from_u32(0x0410 + (c - 0xC0) as u32).unwrap_or('\u{FFFD}'),
        })
        .collect()
}

/// C's `atol`: optional spaces and sign, then digits; 0 when none.
/// Saturates instead of overflowing.
pub fn atol(s: &str) -> i64 {
    let t = s.trim_start();
    let (neg, d) = match t.as_bytes().first() {
        Some(b'-') => (true, &t[1..]),
        Some(b'+') => (false, &t[1..]),
        _ => (false, t),
    };
    let mut v: i64 = 0;
    for c in d.bytes().take_while(|c| c.is_ascii_digit()) {
        v = v.saturating_mul(10).saturating_add((c - b'0') as i64);
    }
    if neg {
        -v
    } else {
        v
    }
}

/// Gwyddion's title for a channel without one (`gwy_app_channel_title_fall_back`):
/// by the value unit, else "Unknown channel N" (N = channel index + 1).
pub fn fallback_title(z_unit: &str, index: usize) -> String {
    match z_unit {
        "m" => "Topography".into(),
        "A" => "Current".into(),
        "V" => "Voltage".into(),
        "deg" => "Phase".into(),
        "N" => "Force".into(),
        _ => format!("Unknown channel {}", index + 1),
    }
}

/// Lines of a header with their byte offsets: (start, end without the line
/// terminator, start of the next line).
pub fn lines_with_offsets(b: &[u8]) -> impl Iterator<Item = (usize, usize, usize)> + '_ {
    let mut pos = 0usize;
    std::iter::from_fn(move || {
        if pos >= b.len() {
            return None;
        }
        let start = pos;
        let end = b[pos..]
            .iter()
            .position(|&c| c == b'\n')
            .map(|i| pos + i)
            .unwrap_or(b.len());
        pos = end + 1;
        let mut e = end;
        if e > start && b[e - 1] == b'\r' {
            e -= 1;
        }
        Some((start, e, end + 1))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atol_like_c() {
        assert_eq!(atol(" 256 "), 256);
        assert_eq!(atol("-12x"), -12);
        assert_eq!(atol("x"), 0);
        assert_eq!(atol("99999999999999999999999"), i64::MAX);
    }

    #[test]
    fn cp1251() {
        assert_eq!(cp1251_or_utf8(&[0xC2, 0xFB, 0xF1]), "Выс");
        assert_eq!(cp1251_or_utf8(b"nA"), "nA");
        assert_eq!(latin1_or_utf8(&[0xB5, b'm']), "µm");
    }

    #[test]
    fn lines() {
        let v: Vec<_> = lines_with_offsets(b"ab\r\ncd\nef").collect();
        assert_eq!(v, vec![(0, 2, 4), (4, 6, 7), (7, 9, 10)]);
    }
}
