//! The environment's maps on disk (`sunbeam_response::env_file`,
//! docs/PACK_FORMAT.md "Environment maps file"): what a file holds equals what
//! `build_env` builds in memory for the same pack, bit for bit, for a sky and
//! for a map; it refuses another pack, sun or wavelength count; a damaged file
//! is an input error, never a panic.

mod common;

use common::{opts, pack};
use sunbeam_light::{sky::Sky, EnvMap, Environment};
use sunbeam_response::env::{build_env, EnvResponse};
use sunbeam_response::env_file;

fn sky(elevation: f64) -> Sky {
    Sky::new(elevation, 120.0, 3.0, 1.0)
}

/// Every texel's bits, the sun's and the proposal's equal.
fn assert_same(a: &EnvResponse, b: &EnvResponse) {
    assert_eq!(a.grid, b.grid);
    assert_eq!(a.basis.len(), 3);
    assert_eq!(a.basis, b.basis, "basis maps differ");
    assert_eq!(a.sun, b.sun, "sun maps differ");
    assert_eq!(a.proposal, b.proposal, "proposals differ");
}

#[test]
fn read_maps_equal_the_in_memory_build_for_a_sky_and_a_map() {
    let p = pack("xenopeltis");
    let s = sky(35.0);
    let file = env_file::build(&p, Some(&s), &opts());
    assert_eq!(file.maps.len(), 7, "3 sky + 3 map + the sun");
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("env-file-roundtrip");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("p.env-response.ktx2");
    env_file::write(&file, &path).unwrap();
    let read = env_file::read(&path).unwrap();
    assert_eq!(read, file, "the file decodes to what was encoded");

    let sky_env = Environment::Sky(Box::new(s));
    let want = build_env(&p, &sky_env, &opts());
    assert!(want.sun.is_some());
    let got = read
        .clone()
        .response_for(&p.manifest, &sky_env, &opts())
        .unwrap();
    assert_same(&got, &want);
    let got = env_file::read_for(&path, &p.manifest, &sky_env, &opts())
        .unwrap()
        .unwrap();
    assert_same(&got, &want);
    // Only what a reader needs: the first frame under the sky with its cells
    // from the pipeline reads the sun's map alone, no proposal.
    let needs = |basis, proposal| env_file::Needs { basis, proposal };
    let sun_only = env_file::read_needed(&path, &p.manifest, &sky_env, &opts(), needs(false, true))
        .unwrap()
        .unwrap();
    assert!(sun_only.basis.is_empty() && sun_only.proposal.levels() == 0);
    assert_eq!(sun_only.sun, want.sun, "the sun's map alone");
    assert_eq!(sun_only.grid, want.grid);
    let no_proposal =
        env_file::read_needed(&path, &p.manifest, &sky_env, &opts(), needs(true, false))
            .unwrap()
            .unwrap();
    assert_eq!(no_proposal.basis, want.basis);
    assert_eq!(no_proposal.sun, want.sun);
    assert_eq!(no_proposal.proposal.levels(), 0);

    // A map: any map, the basis does not depend on it.
    let map_env = Environment::Map(EnvMap::constant([0.3, 0.5, 0.9]));
    let want = build_env(&p, &map_env, &opts());
    let got = env_file::read_for(&path, &p.manifest, &map_env, &opts())
        .unwrap()
        .unwrap();
    assert_same(&got, &want);
}

#[test]
fn another_pack_sun_or_wavelength_count_is_refused() {
    let p = pack("xenopeltis");
    let file = env_file::build(&p, Some(&sky(35.0)), &opts());
    let other_sun = Environment::Sky(Box::new(sky(20.0)));
    let why = file
        .clone()
        .response_for(&p.manifest, &other_sun, &opts())
        .unwrap_err();
    assert!(why.contains("sun"), "{why}");
    let q = pack("elaphe");
    let why = file
        .clone()
        .response_for(&q.manifest, &other_sun, &opts())
        .unwrap_err();
    assert!(why.contains("another pack"), "{why}");
    let mut o = opts();
    o.lambda_samples = 12;
    let same_sun = Environment::Sky(Box::new(sky(35.0)));
    assert!(file
        .clone()
        .response_for(&p.manifest, &same_sun, &o)
        .is_err());
    // Without a sky, no sun map: a sunny sky is refused, a map still served.
    let no_sun = env_file::build(&p, None, &opts());
    assert_eq!(no_sun.maps.len(), 6);
    assert!(no_sun
        .clone()
        .response_for(&p.manifest, &same_sun, &opts())
        .is_err());
    let map_env = Environment::Map(EnvMap::constant([1.0; 3]));
    assert!(no_sun.response_for(&p.manifest, &map_env, &opts()).is_ok());
}

#[test]
fn damaged_files_are_input_errors() {
    let p = pack("xenopeltis");
    let bytes = env_file::encode(&env_file::build(&p, None, &opts()));
    let n = bytes.len();
    let mut cases: Vec<Vec<u8>> = vec![
        bytes[..n / 2].to_vec(),
        bytes[..100].to_vec(),
        bytes[..12].to_vec(),
        Vec::new(),
    ];
    // The JSON's first brace, the texture's depth, a texel set to NaN.
    let brace = bytes.windows(9).position(|w| w == b"{\"format\"").unwrap();
    let mut b = bytes.clone();
    b[brace] = b'[';
    cases.push(b);
    let mut b = bytes.clone();
    b[28] ^= 0x01;
    cases.push(b);
    let mut b = bytes.clone();
    b[n - 8..n - 6].copy_from_slice(&0x7e00u16.to_le_bytes());
    cases.push(b);
    for (k, c) in cases.iter().enumerate() {
        let e = env_file::decode(c).expect_err(&format!("case {k} decodes"));
        assert_eq!(e.exit_code(), 2, "case {k}: {e}");
    }
    // Through read_for, naming the file.
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("env-file-damaged");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cut.env-response.ktx2");
    std::fs::write(&path, &bytes[..n - 1000]).unwrap();
    let env = Environment::Map(EnvMap::constant([1.0; 3]));
    let e = env_file::read_for(&path, &p.manifest, &env, &opts()).unwrap_err();
    assert_eq!(e.exit_code(), 2, "{e}");
    assert!(e.to_string().contains("cut.env-response.ktx2"), "{e}");
}
