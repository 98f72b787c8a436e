//! KTX2 structural rules (the KTX 2.0 spec, ../shared/notes/validators-and-engines.md),
//! EXR layouts, byte-identical output.

mod common;
use common::*;
use sunbeam_pack::build::BuildOptions;
use sunbeam_pack::formats::{write_pack, OutputKind};
use sunbeam_pack::{exr_io, ktx2, Pack, Precision};

fn u32at(b: &[u8], o: usize) -> u32 {
    u32::from_le_bytes(b[o..o + 4].try_into().unwrap())
}
fn u64at(b: &[u8], o: usize) -> u64 {
    u64::from_le_bytes(b[o..o + 8].try_into().unwrap())
}

fn sample_pack(precision: Precision) -> Pack {
    let f = rough(21, 17, 25e-9, 25e-9, 250e-9, 42);
    build(
        &f,
        &BuildOptions {
            precision,
            ..BuildOptions::default()
        },
    )
}

/// Check every rule a KTX2 writer gets wrong, by reading the bytes directly.
fn check_ktx2_rules(b: &[u8], p: &Pack) {
    let m = &p.manifest;
    let (vk, ts, texel, bits) = match m.precision {
        Precision::F32 => (103u32, 4u32, 8u64, 32u32),
        Precision::F16 => (83, 2, 4, 16),
    };
    assert_eq!(
        &b[..12],
        &[0xAB, 0x4B, 0x54, 0x58, 0x20, 0x32, 0x30, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A]
    );
    assert_eq!(u32at(b, 12), vk, "vkFormat");
    assert_eq!(u32at(b, 16), ts, "typeSize");
    assert_eq!(u32at(b, 20) as usize, m.crop.width);
    assert_eq!(u32at(b, 24) as usize, m.crop.height);
    assert_eq!(u32at(b, 28), 0, "pixelDepth");
    assert_eq!(u32at(b, 32) as usize, m.terms, "layerCount");
    assert_eq!(u32at(b, 36), 1, "faceCount");
    assert_eq!(u32at(b, 40), 1, "levelCount");
    assert_eq!(u32at(b, 44), 0, "supercompressionScheme");
    let (dfd_off, dfd_len, kvd_off, kvd_len) =
        (u32at(b, 48), u32at(b, 52), u32at(b, 56), u32at(b, 60));
    assert_eq!(u64at(b, 64), 0, "sgdByteOffset");
    assert_eq!(u64at(b, 72), 0, "sgdByteLength");
    // Level index directly after the header, DFD directly after the level index.
    assert_eq!(dfd_off, 80 + 24);
    // DFD: total size, basic block for two float channels.
    let d = &b[dfd_off as usize..(dfd_off + dfd_len) as usize];
    assert_eq!(dfd_len, 4 + 24 + 16 * 2);
    assert_eq!(u32at(d, 0), dfd_len, "dfdTotalSize");
    assert_eq!(u32at(d, 4), 0, "vendorId 0, descriptorType 0");
    assert_eq!(u32at(d, 8) & 0xffff, 2, "versionNumber 2");
    assert_eq!(u32at(d, 8) >> 16, 24 + 32, "descriptorBlockSize");
    assert_eq!(d[12], 1, "colorModel RGBSDA");
    assert!(d[13] == 0 || d[13] == 1, "colorPrimaries");
    assert_eq!(d[14], 1, "transferFunction LINEAR");
    assert_eq!(d[15], 0, "flags");
    assert_eq!(&d[16..20], &[0, 0, 0, 0], "texelBlockDimension");
    assert_eq!(d[20] as u64, texel, "bytesPlane0");
    assert_eq!(&d[21..28], &[0; 7], "bytesPlane1..7");
    for ch in 0..2u32 {
        let s = &d[28 + 16 * ch as usize..];
        let w0 = u32at(s, 0);
        assert_eq!(w0 & 0xffff, ch * bits, "bitOffset");
        assert_eq!((w0 >> 16) & 0xff, bits - 1, "bitLength");
        assert_eq!(w0 >> 24, ch | 0x40 | 0x80, "channelType: id, signed, float");
        assert_eq!(u32at(s, 4), 0, "samplePosition");
        assert_eq!(f32::from_bits(u32at(s, 8)), -1.0, "sampleLower");
        assert_eq!(f32::from_bits(u32at(s, 12)), 1.0, "sampleUpper");
    }
    // Key/value data: right after the DFD, sorted, no duplicates, KTX-reserved keys known, 4-byte padded with zeros.
    assert_eq!(kvd_off, dfd_off + dfd_len);
    let kv = &b[kvd_off as usize..(kvd_off + kvd_len) as usize];
    let mut keys: Vec<Vec<u8>> = vec![];
    let mut pos = 0usize;
    while pos < kv.len() {
        let n = u32at(kv, pos) as usize;
        let body = &kv[pos + 4..pos + 4 + n];
        let nul = body.iter().position(|&c| c == 0).unwrap();
        let key = body[..nul].to_vec();
        if key.starts_with(b"KTX") {
            assert!(
                key == b"KTXwriter" || key == b"KTXorientation",
                "reserved key {key:?}"
            );
        }
        if key == b"KTXwriter" {
            let v = &body[nul + 1..];
            assert_eq!(*v.last().unwrap(), 0, "KTXwriter NUL-terminated");
            let s = std::str::from_utf8(&v[..v.len() - 1]).unwrap();
            assert!(
                s.starts_with("sunbeam-pack") || s == "test",
                "KTXwriter {s}"
            );
            assert!(
                !s.chars().any(|c| c == ':'),
                "no timestamp in KTXwriter: {s}"
            );
        }
        keys.push(key);
        let end = pos + 4 + n;
        let padded = end.div_ceil(4) * 4;
        assert!(
            kv[end..padded].iter().all(|&c| c == 0),
            "value padding must be zero"
        );
        pos = padded;
    }
    assert_eq!(pos, kv.len());
    let mut sorted = keys.clone();
    sorted.sort();
    sorted.dedup();
    assert_eq!(keys, sorted, "keys sorted by bytes, no duplicates");
    assert!(keys.iter().any(|k| k == b"sunbeam.manifest"));
    // Level data: aligned to lcm(texel size, 4), zero padding before it, lengths consistent.
    let (lo, ll, lu) = (u64at(b, 80), u64at(b, 88), u64at(b, 96));
    let align = if texel % 4 == 0 { texel } else { 4 * texel };
    assert_eq!(lo % align, 0, "level offset alignment");
    let kv_end = (kvd_off + kvd_len) as u64;
    assert_eq!(
        lo,
        kv_end.div_ceil(align) * align,
        "smallest aligned offset"
    );
    assert!(
        b[kv_end as usize..lo as usize].iter().all(|&c| c == 0),
        "zero padding before level data"
    );
    assert_eq!(ll, lu, "byteLength = uncompressedByteLength");
    assert_eq!(
        ll,
        m.crop.width as u64 * m.crop.height as u64 * m.terms as u64 * texel
    );
    assert_eq!(lo + ll, b.len() as u64, "file ends with the level data");
}

#[test]
fn ktx2_follows_the_spec_rules_and_round_trips() {
    for precision in [Precision::F32, Precision::F16] {
        let p = sample_pack(precision);
        let b = ktx2::encode(&p, &p.manifest.generator);
        check_ktx2_rules(&b, &p);
        let q = Pack::from_bytes(&b).unwrap();
        assert!(q == p, "round trip {precision:?}");
        // Layer n, row ty, column tx holds term n at bin (tx - kx, ty - ky), little-endian.
        let lo = u64at(&b, 80) as usize;
        let m = &p.manifest;
        let (n, tx, ty) = (m.terms - 1, m.crop.width / 3, m.crop.height - 2);
        let texel = if precision == Precision::F32 { 8 } else { 4 };
        let i = lo + ((n * m.crop.height + ty) * m.crop.width + tx) * texel;
        let re = if precision == Precision::F32 {
            f32::from_le_bytes(b[i..i + 4].try_into().unwrap())
        } else {
            half::f16::from_le_bytes(b[i..i + 2].try_into().unwrap()).to_f32()
        };
        assert_eq!(re, p.texel(n, tx, ty)[0]);
    }
}

#[test]
fn output_is_byte_identical_across_runs_and_thread_counts() {
    let f = rough(33, 29, 25e-9, 25e-9, 400e-9, 6);
    let a = build(
        &f,
        &BuildOptions {
            threads: 1,
            ..BuildOptions::default()
        },
    );
    let b = build(
        &f,
        &BuildOptions {
            threads: 3,
            ..BuildOptions::default()
        },
    );
    assert_eq!(ktx2::encode(&a, "x"), ktx2::encode(&b, "x"));
    assert_eq!(
        exr_io::encode_layers(&a).unwrap(),
        exr_io::encode_layers(&b).unwrap()
    );
}

#[test]
fn exr_layouts_round_trip_with_blender_names() {
    let dir = std::env::temp_dir().join(format!("sb-pack-exr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for precision in [Precision::F32, Precision::F16] {
        let p = sample_pack(precision);
        // layers
        let path = dir.join("p.exr");
        write_pack(&p, &path, OutputKind::ExrLayers).unwrap();
        assert!(Pack::read(&path).unwrap() == p);
        let d = exr_io::decode_file(&std::fs::read(&path).unwrap()).unwrap();
        assert_eq!(d.layout, exr_io::Layout::Layers);
        // Channel names as Blender/Nuke expect them (read back by the exr crate).
        let img = exr::prelude::read_all_data_from_file(&path).unwrap();
        let names: Vec<String> = img.layer_data[0]
            .channel_data
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert!(
            names.contains(&"Pack.n00.R".to_string()) && names.contains(&"Pack.n00.G".to_string()),
            "{names:?}"
        );
        assert_eq!(names.len(), 2 * p.manifest.terms);
        // atlas
        let path = dir.join("a.exr");
        write_pack(&p, &path, OutputKind::ExrAtlas).unwrap();
        assert!(Pack::read(&path).unwrap() == p);
        // split: one file per term, plain R/G; any one of them reads the whole pack.
        let path = dir.join("s.exr");
        let files = write_pack(&p, &path, OutputKind::ExrSplit).unwrap();
        assert_eq!(files.len(), p.manifest.terms);
        assert_eq!(files[0].0, dir.join("s.n00.exr"));
        assert!(Pack::read(&files[1].0).unwrap() == p);
        // KTX2 through the same path API.
        let path = dir.join("k.ktx2");
        write_pack(&p, &path, OutputKind::Ktx2).unwrap();
        assert!(Pack::read(&path).unwrap() == p);
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn atlas_grid_is_documented_shape() {
    assert_eq!(exr_io::atlas_grid(1), (1, 1));
    assert_eq!(exr_io::atlas_grid(14), (4, 4));
    assert_eq!(exr_io::atlas_grid(16), (4, 4));
    assert_eq!(exr_io::atlas_grid(17), (5, 4));
}
