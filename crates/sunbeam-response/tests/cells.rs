//! The cells' masses (`Cells::build`) against direct sums over the maps'
//! texels, on the thesis' Xenopeltis patch under the built-in sky: the top
//! cut and the leaves each partition the texels that carry mass, so each
//! set's masses, summed, are the maps' integrals `sum area x E_b` layer by
//! layer; a parent's mass is its children's; each node's centroid lies
//! inside the disc its texels fill.

use sunbeam_frame::fixtures;
use sunbeam_light::{sky::Sky, Environment};
use sunbeam_pack::build::BuildOptions;
use sunbeam_response::cells::{Cells, DEFAULT_DEPTH};
use sunbeam_response::env::build_env;
use sunbeam_response::Options;

/// Relative difference of `a` and `b` against the scale `s`.
fn close(a: f64, b: f64, s: f64) -> bool {
    (a - b).abs() <= 1e-9 * s.max(1e-30)
}

#[test]
fn the_cells_masses_are_the_maps_integrals() {
    let Some(snake) = sunbeam_common::testdata::shared_file("snake/Xeno100x100.png") else {
        return;
    };
    let dir = snake.parent().unwrap();
    let pack = fixtures::pack(&fixtures::XENO, dir, &BuildOptions::default()).unwrap();
    let env = Environment::Sky(Box::new(Sky::new(40.0, 30.0, 3.0, 1.0)));
    let er = build_env(&pack, &env, &Options::default());
    let g = er.grid;
    let (nt, nr, ns) = (g.n_theta, g.n_rho, g.n_s);
    // The direct integral over the texels the cells cluster: those whose |Y|
    // summed over the layers and maps is positive.
    let mut total = vec![[0.0f64; 9]; ns];
    let mut scale = 0.0f64;
    for j in 0..nr {
        let area = g.texel_extent(j).2;
        for i in 0..nt {
            let y: f64 = (0..ns)
                .flat_map(|k| er.basis.iter().map(move |m| m.texel(i, j, k)[1].abs()))
                .sum();
            if y <= 0.0 {
                continue;
            }
            for (k, tk) in total.iter_mut().enumerate() {
                for (b, m) in er.basis.iter().enumerate() {
                    let e = m.texel(i, j, k);
                    for c in 0..3 {
                        tk[3 * b + c] += area * e[c];
                        scale = scale.max((area * e[c]).abs());
                    }
                }
            }
        }
    }
    let scale = scale * (nt * nr) as f64;
    for top in [64, 512] {
        let cells = Cells::build(&er.basis, top, DEFAULT_DEPTH);
        assert_eq!(cells.n_top, top, "{top} top cells");
        assert!(
            cells.nodes.len() > top,
            "the tree has levels below the top cut"
        );
        let sum_of = |ids: &mut dyn Iterator<Item = usize>| {
            let mut s = vec![[0.0f64; 9]; ns];
            for id in ids {
                for (sk, mk) in s.iter_mut().zip(&cells.nodes[id].mass) {
                    for (x, m) in sk.iter_mut().zip(mk) {
                        *x += m;
                    }
                }
            }
            s
        };
        let tops = sum_of(&mut (0..cells.n_top));
        let leaves =
            sum_of(&mut (0..cells.nodes.len()).filter(|&i| cells.nodes[i].children.is_none()));
        for k in 0..ns {
            for c in 0..9 {
                assert!(
                    close(tops[k][c], total[k][c], scale),
                    "top cut, layer {k}, entry {c}: {} vs {}",
                    tops[k][c],
                    total[k][c]
                );
                assert!(
                    close(leaves[k][c], total[k][c], scale),
                    "leaves, layer {k}, entry {c}: {} vs {}",
                    leaves[k][c],
                    total[k][c]
                );
            }
        }
        for (id, n) in cells.nodes.iter().enumerate() {
            assert!(
                n.uv[0].hypot(n.uv[1]) <= g.r_at(nr - 1) + 1e-9,
                "node {id}: centroid {:?}",
                n.uv
            );
            assert_eq!(n.mass.len(), ns, "node {id}");
            if let Some([a, b]) = n.children {
                for k in 0..ns {
                    for c in 0..9 {
                        let s =
                            cells.nodes[a as usize].mass[k][c] + cells.nodes[b as usize].mass[k][c];
                        assert!(
                            close(n.mass[k][c], s, scale),
                            "node {id}, layer {k}, entry {c}"
                        );
                    }
                }
            }
        }
    }
}
