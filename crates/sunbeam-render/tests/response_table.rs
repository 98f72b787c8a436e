//! The response table of `--mode table` (`sunbeam_render::table`) against the
//! pack's own float64 evaluator, `Pack::shading_reflectance` (a different code
//! path: per-point coefficients, taps and sums, the window's grazing term from
//! its own kernel-derivative taps), summed over the same wavelength samples:
//! at grid nodes the table must hold that spectral integral: `R_U` (PHYSICS.md
//! 2b) for a window-model pack with a window, `R` for the tiled model and for
//! a window-model pack without one.

use sunbeam_frame::spectral::Samples;
use sunbeam_pack::{BuildOptions, FieldRef, Model, Pack};
use sunbeam_render::table::{self, Dims, ResponseTable};

/// A small crossed grating with an oblique third component (64 x 64 pixels
/// of 30 nm, heights within +-110 nm): orders along `u`, along `v` and off
/// both axes.
fn field() -> (usize, f64, Vec<f64>) {
    let (n, dx) = (64usize, 30e-9);
    let l = n as f64 * dx;
    let tau = 2.0 * std::f64::consts::PI;
    let data = (0..n * n)
        .map(|i| {
            let (x, y) = ((i % n) as f64 * dx, (i / n) as f64 * dx);
            60e-9 * (tau * 3.0 * x / l).sin()
                + 35e-9 * (tau * 2.0 * y / l).cos()
                + 15e-9 * (tau * (x + 2.0 * y) / l).sin()
        })
        .collect();
    (n, dx, data)
}

/// The pack of [`field`]; the tiled model with a 1 um coherence length, so
/// that its Gaussian spans a few bins and the table's nodes see its lobes.
fn pack(model: Model) -> Pack {
    let (n, dx, data) = field();
    let f = FieldRef {
        width: n,
        height: n,
        dx,
        dy: dx,
        data: &data,
    };
    let o = BuildOptions {
        model,
        coherence_m: if model == Model::Tiled { 1e-6 } else { 65e-6 },
        threads: 1,
        ..Default::default()
    };
    sunbeam_pack::build(f, &o, &mut |_, _| {}).unwrap()
}

/// A small xorshift generator (no dependency).
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
}

/// The grid nodes to check: 300 at random, the grazing layer `w = 0` and the
/// next one, and the corners.
fn nodes(d: Dims, seed: u64) -> Vec<[usize; 3]> {
    let mut rng = Rng(seed);
    let mut out: Vec<[usize; 3]> = (0..300)
        .map(|_| [rng.below(d.nu), rng.below(d.nv), rng.below(d.nw)])
        .collect();
    for iw in [d.nw - 1, d.nw - 2] {
        for _ in 0..60 {
            out.push([rng.below(d.nu), rng.below(d.nv), iw]);
        }
    }
    for iu in [0, d.nu / 2, d.nu - 1] {
        for iv in [0, d.nv / 2, d.nv - 1] {
            for iw in [0, d.nw - 1] {
                out.push([iu, iv, iw]);
            }
        }
    }
    out
}

/// The node's `(u, v, w)` from the table's definition (`-2 + i 4 / (n - 1)`,
/// `w = -2 + i 2 / (n - 1)`), written out here.
fn node_uvw(d: Dims, [iu, iv, iw]: [usize; 3]) -> [f64; 3] {
    [
        -2.0 + iu as f64 * 4.0 / (d.nu - 1) as f64,
        -2.0 + iv as f64 * 4.0 / (d.nv - 1) as f64,
        -2.0 + iw as f64 * 2.0 / (d.nw - 1) as f64,
    ]
}

/// The largest relative error of the table against `want` at `nodes`, where
/// `want` is above 1e-6 of the table's peak, and how many values were checked.
fn worst(
    t: &ResponseTable,
    nodes: &[[usize; 3]],
    want: impl Fn([f64; 3]) -> [f64; 3],
) -> (f64, usize) {
    let d = t.dims;
    let peak = t
        .data
        .iter()
        .flat_map(|c| c[..3].iter().map(|v| v.abs() as f64))
        .fold(0.0, f64::max);
    assert!(peak > 1e-3, "the table sees no light (peak {peak})");
    let (mut e, mut n) = (0.0f64, 0usize);
    for &node in nodes {
        let [iu, iv, iw] = node;
        let got = t.data[(iw * d.nv + iv) * d.nu + iu];
        let w = want(node_uvw(d, node));
        for c in 0..3 {
            if w[c].abs() > 1e-6 * peak {
                e = e.max((got[c] as f64 - w[c]).abs() / w[c].abs());
                n += 1;
            }
        }
    }
    (e, n)
}

const DIMS: Dims = Dims {
    nu: 41,
    nv: 37,
    nw: 11,
};

/// Samples: 24 midpoints over 380..780 nm (the player's rule, fewer of them).
fn samples() -> Samples {
    Samples::uniform(24, (380, 780))
}

fn table_of(pack: &Pack) -> ResponseTable {
    table::build(pack, &samples(), DIMS, &|_| usize::MAX)
}

/// The window model with its window: the table holds `R_U`, within 1e-4
/// relative of `Pack::shading_reflectance`'s spectral integral; `R` (what the
/// table held before PHYSICS.md 2b) is more than 1 % away at the same nodes,
/// so the check tells the two apart.
#[test]
fn window_table_holds_r_u() {
    let pack = pack(Model::Window);
    assert!(pack.manifest.window_sigma_m > 0.0);
    let s = samples();
    let t = table_of(&pack);
    assert_eq!(t.dims, DIMS);
    let nodes = nodes(DIMS, 0x5eed_0001);
    let shading = |[u, v, w]: [f64; 3]| s.integrate(|l| pack.shading_reflectance(u, v, w, l));
    let (e, n) = worst(&t, &nodes, shading);
    eprintln!("window R_U: worst relative {e:.2e} over {n} values");
    assert!(n > 300, "only {n} values above 1e-6 of the peak");
    assert!(e < 1e-4, "table vs shading_reflectance: relative {e:.3e}");
    let r = |[u, v, w]: [f64; 3]| s.integrate(|l| pack.reflectance(u, v, w, l));
    let (e_r, _) = worst(&t, &nodes, r);
    eprintln!("window R_U against R: worst relative {e_r:.2e}");
    assert!(e_r > 1e-2, "R_U and R agree at these nodes ({e_r:.2e})");
}

/// Without a window (`window_sigma_m` 0) the window model keeps `R`, and so
/// does the tiled model.
#[test]
fn tiled_and_windowless_tables_hold_r() {
    let mut windowless = pack(Model::Window);
    windowless.manifest.window_sigma_m = 0.0;
    let s = samples();
    for (name, pack) in [("tiled", pack(Model::Tiled)), ("windowless", windowless)] {
        let t = table_of(&pack);
        let nodes = nodes(DIMS, 0x5eed_0002);
        let (e, n) = worst(&t, &nodes, |[u, v, w]| {
            s.integrate(|l| pack.shading_reflectance(u, v, w, l))
        });
        eprintln!("{name}: worst relative {e:.2e} over {n} values");
        assert!(n > 300, "{name}: only {n} values above 1e-6 of the peak");
        assert!(e < 1e-4, "{name}: table vs the pack: relative {e:.3e}");
        let (e_r, _) = worst(&t, &nodes, |[u, v, w]| {
            s.integrate(|l| pack.reflectance(u, v, w, l))
        });
        assert!(e_r < 1e-4, "{name}: table vs R: relative {e_r:.3e}");
    }
}
