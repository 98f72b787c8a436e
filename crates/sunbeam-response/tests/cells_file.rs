//! The first-frame cells on disk (`sunbeam_response::cells_file`,
//! docs/PACK_FORMAT.md "Cells file"): a file holds, bit for bit, what
//! `Cells::build` clusters from the same maps, for the sky's basis and a
//! map's, at each count asked for; it refuses another pack, other maps or a
//! count it does not hold, naming the flag that writes it; a damaged file is
//! an input error, never a panic.

mod common;

use common::{opts, pack};
use sunbeam_light::{sky::Sky, EnvMap, Environment};
use sunbeam_response::cells::{Cells, DEFAULT_DEPTH};
use sunbeam_response::env::build_env;
use sunbeam_response::{cells_file, env_file};

#[test]
fn the_file_holds_the_clustering_of_either_basis_at_each_count() {
    let p = pack("xenopeltis");
    let sky = Sky::new(35.0, 60.0, 3.0, 1.0);
    let ef = env_file::build(&p, Some(&sky), &opts());
    let counts = [(16, DEFAULT_DEPTH), (64, 2)];
    let bytes = cells_file::encode(&cells_file::build(&ef, &counts));
    let f = cells_file::decode(&bytes).unwrap();
    assert_eq!(f.info.sets.len(), 4, "sky and map at two counts");
    let envs = [
        Environment::Sky(Box::new(sky)),
        Environment::Map(EnvMap::constant([1.0; 3])),
    ];
    for env in &envs {
        // The maps as the player gets them (the in-memory build, not the file).
        let er = build_env(&p, env, &opts());
        let lambdas = er.basis[0].info.lambda_samples;
        for &c in &counts {
            let want = Cells::build(&er.basis, c.0, c.1).gpu();
            let got = f
                .get(&p.manifest, &er.grid, lambdas, cells_file::basis_of(env), c)
                .unwrap();
            assert_eq!(got.n_top, want.n_top, "{c:?}");
            assert_eq!(got.nodes, want.nodes, "{c:?}");
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got.data), bits(&want.data), "{c:?}: the floats' bits");
        }
        // A count the file does not hold: the flag that writes it.
        let why = f
            .get(
                &p.manifest,
                &er.grid,
                lambdas,
                cells_file::basis_of(env),
                (512, DEFAULT_DEPTH),
            )
            .unwrap_err();
        assert!(why.contains("--response-cells 512"), "{why}");
        assert!(why.contains("16, 64"), "{why}");
        // Another pack, another grid, other wavelength samples.
        let other = pack("elaphe");
        assert!(f
            .get(&other.manifest, &er.grid, lambdas, "sky", counts[0])
            .unwrap_err()
            .contains("another pack"));
        let mut g = er.grid;
        g.n_s += 1;
        assert!(f
            .get(&p.manifest, &g, lambdas, "sky", counts[0])
            .unwrap_err()
            .contains("other environment maps"));
        assert!(f
            .get(&p.manifest, &er.grid, lambdas + 1, "sky", counts[0])
            .is_err());
    }
    // From disk, reading one set: the same cells, the same refusals.
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cells-file-sets");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("x.env-cells.ktx2");
    std::fs::write(&path, &bytes).unwrap();
    let er = build_env(&p, &envs[0], &opts());
    let lambdas = er.basis[0].info.lambda_samples;
    for &c in &counts {
        let read = cells_file::read_set(&path, &p.manifest, &er.grid, lambdas, "sky", c)
            .unwrap()
            .unwrap();
        let whole = f.get(&p.manifest, &er.grid, lambdas, "sky", c).unwrap();
        assert_eq!(
            (read.n_top, read.nodes),
            (whole.n_top, whole.nodes),
            "{c:?}"
        );
        assert!(
            read.data
                .iter()
                .map(|x| x.to_bits())
                .eq(whole.data.iter().map(|x| x.to_bits())),
            "{c:?}: one set read differs from the whole file's"
        );
    }
    let why = cells_file::read_set(&path, &p.manifest, &er.grid, lambdas, "map", (8, 1))
        .unwrap()
        .unwrap_err();
    assert!(why.contains("--response-cells 8"), "{why}");
    // Deterministic.
    assert_eq!(
        bytes,
        cells_file::encode(&cells_file::build(&ef, &[(64, 2), (16, DEFAULT_DEPTH)]))
    );
}

#[test]
fn damaged_files_are_input_errors() {
    let p = pack("xenopeltis");
    let ef = env_file::build(&p, None, &opts());
    let bytes = cells_file::encode(&cells_file::build(&ef, &[(16, DEFAULT_DEPTH)]));
    let n = bytes.len();
    let mut cases: Vec<Vec<u8>> = vec![
        bytes[..n / 2].to_vec(),
        bytes[..100].to_vec(),
        bytes[..12].to_vec(),
        Vec::new(),
    ];
    let json_at = |b: &[u8], s: &[u8]| b.windows(s.len()).position(|w| w == s).unwrap();
    // The JSON's first brace; the vkFormat; a set's length; its row.
    let mut b = bytes.clone();
    b[json_at(&bytes, b"{\"format\"")] = b'[';
    cases.push(b);
    let mut b = bytes.clone();
    b[12] ^= 0x01;
    cases.push(b);
    let mut b = bytes.clone();
    let at = json_at(&bytes, b"\"len\":") + 6;
    b[at] = if b[at] == b'9' { b'1' } else { b'9' };
    cases.push(b);
    let mut b = bytes.clone();
    let at = json_at(&bytes, b"\"row\":0") + 6;
    b[at] = b'7';
    cases.push(b);
    // A child link past the last node: the first node's `first` field.
    let f = cells_file::decode(&bytes).unwrap();
    let lv = n - f.bits.len() * 4;
    let mut b = bytes.clone();
    b[lv + 12..lv + 16].copy_from_slice(&0x00ff_ffffu32.to_le_bytes());
    cases.push(b);
    for (k, c) in cases.iter().enumerate() {
        let e = cells_file::decode(c).expect_err(&format!("case {k} decodes"));
        assert_eq!(e.exit_code(), 2, "case {k}: {e}");
    }
    // Through read, naming the file.
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("cells-file-damaged");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("cut.env-cells.ktx2");
    std::fs::write(&path, &bytes[..n - 1000]).unwrap();
    let e = cells_file::read(&path).unwrap_err();
    assert_eq!(e.exit_code(), 2, "{e}");
    assert!(e.to_string().contains("cut.env-cells.ktx2"), "{e}");
    let er = build_env(&p, &Environment::Map(EnvMap::constant([1.0; 3])), &opts());
    let lambdas = er.basis[0].info.lambda_samples;
    let cells = (16, DEFAULT_DEPTH);
    let e = cells_file::read_set(&path, &p.manifest, &er.grid, lambdas, "map", cells).unwrap_err();
    assert_eq!(e.exit_code(), 2, "{e}");
    assert!(e.to_string().contains("cut.env-cells.ktx2"), "{e}");
    // A link past the last node, read as one set.
    std::fs::write(&path, cases.last().unwrap()).unwrap();
    let e = cells_file::read_set(&path, &p.manifest, &er.grid, lambdas, "sky", cells).unwrap_err();
    assert_eq!(e.exit_code(), 2, "{e}");
    assert!(e.to_string().contains("links to node"), "{e}");
}
