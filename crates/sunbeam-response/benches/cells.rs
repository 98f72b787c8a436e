//! The first-frame cells against the reference's quadrature at single
//! shading points (docs/LIGHTING.md "The first frame"): CIEDE2000 over random
//! frames and views for several cell counts. Prints; asserts nothing. Also
//! prints how much of each environment's energy its brightest texels hold,
//! and the top cut's spread.
//!
//! `cargo bench -p sunbeam-response --bench cells [-- elaphe]`, and in the
//! environment:
//!
//! - `CELLS_CFG=TOP:DEPTH,..`: the cell counts;
//! - `PACK=FILE`: a pack file (e.g. a 20 um synthetic scan) instead of the
//!   thesis patch;
//! - `ENVS=sky,studio,white`: the environments (`white`: a constant map, so
//!   only the factors `G / cos` and the layers vary across a cell);
//! - `HOT=THRESHOLD:MAX`: the hot spots pulled out as lights first
//!   (`sunbeam_light::hotspots`, through `sunbeam_response::hotspots`);
//! - `LAMBDA=N`: the player's maps with `N` wavelength samples (the reference
//!   keeps its 160);
//! - `SWEEP=AZIMUTH`: instead of random points, 400 views along one azimuth
//!   (degrees), `cos` from 0.95 to 0.3, in a fixed frame, each printed as
//!   `SW cos Y_est Y_ref Z_est Z_ref` (steps of the estimate as the view
//!   moves);
//! - `RATIO=1`: print each point's view cosine, estimate over reference in
//!   X, Y and Z, and its CIEDE2000 (which channel a model loses);
//! - `YONLY=1`: the error of luminance alone (the estimate's Y with the
//!   reference's chromaticity);
//! - `TEXELS=1`: also every texel as its own cell at its centre, the
//!   environment read unfiltered there (no horizon band: the floor of a
//!   midpoint rule on the maps' own grid);
//! - `MASK=1`: Smith masking from the pack's rms slope, for the reference,
//!   the cells, the hot spots and the sun alike (default: off);
//! - `GRAZE=LO:HI`: the views' `cos` to the normal drawn in `[LO, HI]`
//!   (default `0.02:1`), to look at grazing or near-normal views alone;
//! - `NOPRE=1`, `OMS=X`: the environment read at the centroid unfiltered, or
//!   its solid angle scaled by `X`; `WORST=1`: print the worst points;
//! - `QUAD=L`: a control variate: the environment's coefficients (after the
//!   hot spots) fitted by a polynomial of degree `L` in the direction, its
//!   part integrated by the reference's quadrature (what per-view tables of
//!   the maps' moments would hold), the cells on the residual only;
//!   `QUAD_ONLY=1`: the polynomial's part alone; `HORIZON=1`: the fit over
//!   the upper hemisphere only and the ground below the horizon taken
//!   exactly, and with it `TILT=N`, the horizon's direction in the local
//!   frame read from an N x N grid (what a table over it would hold; slow:
//!   four quadrature tables per point); `CUT=1` (with `CELLS_CFG=1:DEPTH`): the cells only where the
//!   world's horizon or the ground is, a cut per view from the root,
//!   `SBELOW=S` the largest spread kept below the horizon, `CUT_W=X` the
//!   weight of the rows below the horizon in the fit; `STEP=1`: the fit
//!   over the whole sphere with the ground's indicator as one more
//!   function, a constant step below the horizon (docs/LIGHTING.md
//!   "A polynomial control variate"). Each configuration prints the nodes
//!   visited per point.

use std::time::Instant;
use sunbeam_common::rng::SplitMix64;
use sunbeam_frame::fixtures;
use sunbeam_light::prefilter::Prefiltered;
use sunbeam_light::{sky::Sky, Environment};
use sunbeam_optics::colour;
use sunbeam_optics::gain::Material;
use sunbeam_optics::masking::Masking;
use sunbeam_pack::build::BuildOptions;
use sunbeam_response::cells::Cells;
use sunbeam_response::env::build_env;
use sunbeam_response::quadrature::{EnvQuadrature, Query};
use sunbeam_response::Options;

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/snake");
    let which = std::env::args().nth(1).unwrap_or_else(|| "xeno".into());
    let patch = if which == "elaphe" {
        fixtures::ELAPHE
    } else {
        fixtures::XENO
    };
    // PACK=path: a pack file (e.g. a 20 um synthetic scan) instead of the thesis patch
    let pack = match std::env::var("PACK") {
        Ok(p) => sunbeam_pack::Pack::read(std::path::Path::new(&p)).expect("PACK"),
        Err(_) => fixtures::pack(&patch, &dir, &BuildOptions::default()).expect("pack"),
    };
    let envs: Vec<(&str, Environment)> = vec![
        (
            "sky",
            Environment::Sky(Box::new(Sky::new(40.0, 30.0, 3.0, 1.0))),
        ),
        (
            "studio",
            Environment::Map(
                sunbeam_light::io::load(
                    &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                        .join("../../../shared/data/hdri/studio.exr"),
                    0.0,
                    1.0,
                )
                .expect("hdri"),
            ),
        ),
    ];
    // ENVS=white: a constant white map (the factors G / cos and the layers
    // alone, no environment gradient); ENVS=sky,studio,white picks
    let mut envs = envs;
    envs.push((
        "white",
        Environment::Map(
            sunbeam_light::EnvMap::new(64, 32, vec![[1.0; 3]; 64 * 32], 0.0, 1.0).expect("white"),
        ),
    ));
    let pick = std::env::var("ENVS").unwrap_or_else(|_| "sky,studio".into());
    envs.retain(|(n, _)| pick.split(',').any(|p| p == *n));
    for (name, env) in &envs {
        let t0 = Instant::now();
        // LAMBDA=N: the player's maps with N wavelength samples (default 96;
        // the reference's 160)
        let opts = match std::env::var("LAMBDA") {
            Ok(n) => Options {
                lambda_samples: n.parse().expect("LAMBDA"),
                ..Options::default()
            },
            Err(_) => Options::default(),
        };
        let er = build_env(&pack, env, &opts);
        let t_env = t0.elapsed();
        let t0 = Instant::now();
        let quad = EnvQuadrature::build(&pack, env, &EnvQuadrature::reference_options());
        let t_quad = t0.elapsed();
        let (w, h, table) = env.coefficient_table(256);
        let t0 = Instant::now();
        {
            let mut e: Vec<(f64, f64)> = (0..w * h)
                .map(|t| {
                    let j = t / w;
                    let om = ((std::f64::consts::PI * j as f64 / h as f64).cos()
                        - (std::f64::consts::PI * (j + 1) as f64 / h as f64).cos())
                        * std::f64::consts::TAU
                        / w as f64;
                    let y = table[4 * t] as f64 + table[4 * t + 1] as f64 + table[4 * t + 2] as f64;
                    (y * om, om)
                })
                .collect();
            let tot: f64 = e.iter().map(|x| x.0).sum();
            e.sort_by(|a, b| (b.0 / b.1).total_cmp(&(a.0 / a.1)));
            let mut acc = 0.0;
            let mut om = 0.0;
            for (q, x) in e.iter().enumerate() {
                acc += x.0;
                om += x.1;
                if [10, 100, 1000, 10000, 50000].contains(&(q + 1)) {
                    eprintln!(
                        "  top {} texels: {:.1}% of the energy in {:.4} sr",
                        q + 1,
                        100.0 * acc / tot,
                        om
                    );
                }
            }
        }
        let hot: Option<sunbeam_light::hotspots::SplitOptions> =
            std::env::var("HOT").ok().map(|v| {
                let mut it = v.split(':');
                sunbeam_light::hotspots::SplitOptions {
                    threshold: it.next().unwrap().parse().unwrap(),
                    max_lights: it.next().unwrap_or("16").parse().unwrap(),
                }
            });
        let (table, lights) = match hot {
            Some(o) => {
                let s = sunbeam_light::hotspots::split(w, h, &table, o);
                eprintln!(
                    "  hot spots: {} lights, {:.1}% of the energy",
                    s.lights.len(),
                    100.0 * s.share
                );
                (s.residual, s.lights)
            }
            None => (table, Vec::new()),
        };
        // QUAD=L: the environment's coefficients (after the hot spots) fitted
        // by a polynomial of degree L in the direction (the span of the
        // spherical harmonics to order L), least squares over the table with
        // solid-angle weights; its part integrated by the reference's
        // quadrature (what tables over the view would hold), the cells on
        // the residual only. QUAD_ONLY=1: no cells.
        let horizon = std::env::var("HORIZON").is_ok();
        // CUT=1 (with QUAD=L): the polynomial fitted over the upper hemisphere
        // and taken exactly over the whole sphere; the cells carry what is
        // left below the world's horizon only, through a per-view cut of a
        // tree from the root (CELLS_CFG=1:DEPTH) that skips the nodes wholly
        // above it (their residual, the fit's error, is left out)
        let cut_walk = std::env::var("CUT").is_ok();
        // TILT=N (with HORIZON=1): the horizon's direction in the local frame
        // from an N x N grid, bilinear (what a table over it would hold)
        let tilt_n: Option<usize> = std::env::var("TILT")
            .ok()
            .map(|v| v.parse().expect("TILT=N"));
        let cut_w: f64 = std::env::var("CUT_W")
            .ok()
            .map(|v| v.parse().expect("CUT_W=WEIGHT"))
            .unwrap_or(1.0);
        let s_below: f64 = std::env::var("SBELOW")
            .ok()
            .map(|v| v.parse().expect("SBELOW=SPREAD"))
            .unwrap_or(1.0);
        // STEP=1 (with QUAD=L): the fit over the whole sphere with one more
        // function, the indicator of the ground (below the world's horizon):
        // the polynomial plus a constant step there
        let step = std::env::var("STEP").is_ok();
        let ground = env.coefficients([0.0, -1.0, 0.0]);
        // the part taken exactly: the polynomial, and with HORIZON the ground
        // below the horizon instead
        let exact_part = |deg: u32, q: &[[f64; 3]], d: [f64; 3]| {
            if horizon && d[1] < 0.0 {
                ground
            } else if step && d[1] < 0.0 {
                let p = poly_eval(deg, q, d);
                let c = q[q.len() - 1];
                [p[0] + c[0], p[1] + c[1], p[2] + c[2]]
            } else {
                poly_eval(deg, q, d)
            }
        };
        let quad_deg: Option<u32> = std::env::var("QUAD")
            .ok()
            .map(|v| v.parse().expect("QUAD=DEGREE"));
        let quad_fit: Option<Vec<[f64; 3]>> = quad_deg.map(|deg| {
            let nb = poly_basis(deg, [0.0, 0.0, 1.0]).len() + usize::from(step);
            let mut ata = vec![vec![0.0f64; nb]; nb];
            let mut atb = vec![[0.0f64; 3]; nb];
            // HORIZON=1: the fit over the upper hemisphere only; the part
            // below the horizon is the ground's, exact (a half-space term)
            // CUT=1: over the whole sphere, below the horizon towards the
            // horizon's own value at the same azimuth (a continuation without
            // the ground's step, which the cells carry)
            let rows = if horizon { h / 2 } else { h };
            for j in 0..rows {
                let th0 = std::f64::consts::PI * j as f64 / h as f64;
                let th1 = std::f64::consts::PI * (j + 1) as f64 / h as f64;
                let mut om = (th0.cos() - th1.cos()) * std::f64::consts::TAU / w as f64;
                // CUT_W=X: the rows below the horizon weigh X (a tame
                // extrapolation, the fit above nearly the upper one's)
                if cut_walk && j >= h / 2 {
                    om *= cut_w;
                }
                let theta = (j as f64 + 0.5) / h as f64 * std::f64::consts::PI;
                for i in 0..w {
                    let phi = (i as f64 + 0.5) / w as f64 * std::f64::consts::TAU;
                    let d = sunbeam_light::direction(theta.cos(), phi);
                    let mut f = poly_basis(deg, d);
                    if step {
                        f.push(if d[1] < 0.0 { 1.0 } else { 0.0 });
                    }
                    let jt = if cut_walk { j.min(h / 2 - 1) } else { j };
                    let t = 4 * (jt * w + i);
                    for a in 0..nb {
                        for b in 0..nb {
                            ata[a][b] += om * f[a] * f[b];
                        }
                        for c in 0..3 {
                            atb[a][c] += om * f[a] * table[t + c] as f64;
                        }
                    }
                }
            }
            solve(ata, atb)
        });
        let pre = Prefiltered::new(w, h, table);
        let t_pre = t0.elapsed();
        eprintln!(
            "{name}: maps {t_env:.2?}, reference {t_quad:.2?}, prefilter {:.2?} ({w} x {h})",
            t_pre
        );
        let skin = Material::default();
        let mask = if std::env::var("MASK").is_ok() {
            Masking::smith(pack.manifest.rms_slope.expect("rms_slope"))
        } else {
            Masking::Off
        };
        eprintln!("  masking {mask:?}");
        let (glo, ghi) = std::env::var("GRAZE")
            .ok()
            .map(|v| {
                let mut it = v.split(':').map(|x| x.parse::<f64>().expect("GRAZE=LO:HI"));
                (
                    it.next().expect("GRAZE=LO:HI"),
                    it.next().expect("GRAZE=LO:HI"),
                )
            })
            .unwrap_or((0.02, 1.0));
        let mut rng = SplitMix64::new(7);
        let mut pts = Vec::new();
        for _ in 0..600 {
            // a random frame and a view with cos theta_r uniform in (0.02, 1)
            let z = 2.0 * rng.unit() - 1.0;
            let ph = std::f64::consts::TAU * rng.unit();
            let s = (1.0 - z * z).sqrt();
            let n = [s * ph.cos(), z, s * ph.sin()];
            let a = if n[1].abs() < 0.9 {
                [0.0, 1.0, 0.0]
            } else {
                [1.0, 0.0, 0.0]
            };
            let cross = |a: [f64; 3], b: [f64; 3]| {
                [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ]
            };
            let norm = |v: [f64; 3]| {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                v.map(|x| x / l)
            };
            let t = norm(cross(a, n));
            let b = cross(n, t);
            let cr = glo + (ghi - glo) * rng.unit();
            let pr = std::f64::consts::TAU * rng.unit();
            let sr = (1.0 - cr * cr).sqrt();
            pts.push(((t, b, n), [sr * pr.cos(), sr * pr.sin(), cr]));
        }
        if let Ok(az) = std::env::var("SWEEP") {
            // views along one azimuth (degrees), cos from 0.95 to 0.3, in a fixed frame
            let az: f64 = az.parse::<f64>().expect("SWEEP=AZIMUTH").to_radians();
            pts.clear();
            for k in 0..400 {
                let cr = 0.95 - 0.65 * k as f64 / 399.0;
                let sr = (1.0 - cr * cr).sqrt();
                pts.push((
                    ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
                    [sr * az.cos(), sr * az.sin(), cr],
                ));
            }
        }
        let sun_u = [0.5, 0.5];
        let integrate = |q: &EnvQuadrature, frame, wr| {
            q.integrate_many(
                env,
                &[Query {
                    frame,
                    wr,
                    sun_u,
                    masking: mask,
                    skin,
                }],
                (0, 1),
            )[0]
        };
        let refs: Vec<[f64; 3]> = pts
            .iter()
            .map(|(f, wr)| integrate(&quad, *f, *wr))
            .collect();
        let quad_q = quad_fit.as_ref().map(|q| {
            let deg = quad_deg.unwrap();
            let t0 = Instant::now();
            let qq = quad.with_coefficients(&|d| exact_part(deg, q, d));
            // the fit's own error: rms over the sphere relative to the mean
            let (mut e2, mut m2) = (0.0, 0.0);
            let mut rng = SplitMix64::new(3);
            for _ in 0..20000 {
                let z = 2.0 * rng.unit() - 1.0;
                let ph = std::f64::consts::TAU * rng.unit();
                let d = sunbeam_light::direction(z, ph);
                let c = pre.lookup(d, 1e-6);
                let p = exact_part(deg, q, d);
                e2 += (c[0] - p[0]).powi(2);
                m2 += c[0].powi(2);
            }
            eprintln!(
                "  degree {deg} fit ({} functions): residual rms / rms of c_0 {:.3}, table {:.2?}",
                q.len(),
                (e2 / m2).sqrt(),
                t0.elapsed()
            );
            qq
        });
        let mut ys: Vec<f64> = refs.iter().map(|x| x[1]).collect();
        ys.sort_by(f64::total_cmp);
        let white = ys[ys.len() * 9 / 10] * 2.0;
        let cfgs: Vec<(usize, usize)> = std::env::var("CELLS_CFG")
            .unwrap_or_else(|_| "16:0,64:0,64:3,64:5,256:0,1024:0".into())
            .split(',')
            .map(|c| {
                let mut it = c.split(':');
                (
                    it.next().unwrap().parse().unwrap(),
                    it.next().unwrap().parse().unwrap(),
                )
            })
            .collect();
        if std::env::var("TEXELS").is_ok() {
            // every texel its own cell, at its centre: what the cells approximate
            let g = er.basis[0].info.grid;
            let (nt, nr, ns) = (g.n_theta, g.n_rho, g.n_s);
            let mut de = Vec::new();
            for ((f, wr), r) in pts.iter().zip(&refs) {
                let (t, b, n) = *f;
                let mut x = [0.0; 3];
                for j in 0..nr {
                    let a = g.texel_extent(j).2;
                    let rr = g.r_at(j);
                    for i in 0..nt {
                        let th = g.theta_at(i);
                        let (wx, wy) = (-rr * th.cos() - wr[0], -rr * th.sin() - wr[1]);
                        let l2 = wx * wx + wy * wy;
                        if l2 >= 1.0 {
                            continue;
                        }
                        let wi = [wx, wy, (1.0 - l2).sqrt()];
                        let sv =
                            ((wi[2] + wr[2]) / (4.0 - rr * rr).max(1e-12).sqrt()).clamp(0.0, 1.0);
                        let sc = sv * (ns - 1) as f64;
                        let k0 = (sc.floor() as usize).min(ns - 2);
                        let fr = sc - k0 as f64;
                        let gg = sunbeam_optics::gain::g(wi, *wr, skin) / wi[2] * a;
                        let d = [0, 1, 2].map(|k| wi[0] * t[k] + wi[1] * b[k] + wi[2] * n[k]);
                        let ck = env.coefficients(d);
                        for (bb, m) in er.basis.iter().enumerate() {
                            let e0 = m.texel(i, j, k0);
                            let e1 = m.texel(i, j, k0 + 1);
                            for c in 0..3 {
                                x[c] += gg * ck[bb] * (e0[c] * (1.0 - fr) + e1[c] * fr);
                            }
                        }
                    }
                }
                let sc = |v: [f64; 3]| v.map(|c| (c / white).max(0.0));
                de.push(colour::ciede2000_xyz(sc(x), sc(*r)));
            }
            de.sort_by(f64::total_cmp);
            eprintln!(
                "  texels at their centres: dE mean {:.3} p99 {:.3} max {:.3}",
                de.iter().sum::<f64>() / de.len() as f64,
                de[de.len() * 99 / 100],
                de[de.len() - 1]
            );
        }
        for (n_top, depth) in cfgs {
            let cells = Cells::build(&er.basis, n_top, depth);
            {
                // the top cut's spread, mass-weighted (Y of E_0 summed over layers)
                let (mut sw, mut sm, mut sp) = (0.0, 0.0, Vec::new());
                for c in &cells.nodes[..cells.n_top] {
                    let m: f64 = c.mass.iter().map(|l| l[1].abs()).sum();
                    sw += m * c.spread;
                    sm += m;
                    sp.push(c.spread);
                }
                sp.sort_by(f64::total_cmp);
                let g = cells.grid;
                eprintln!(
                    "  grid {} x {} x {}, r0 {:.4}; top spread mass-weighted {:.4}, median {:.4}, p90 {:.4}",
                    g.n_theta,
                    g.n_rho,
                    g.n_s,
                    g.r0,
                    sw / sm,
                    sp[sp.len() / 2],
                    sp[sp.len() * 9 / 10]
                );
            }
            let t0 = Instant::now();
            let mut visits = 0usize;
            let mut de = Vec::new();
            let mut bins: Vec<Vec<f64>> = vec![Vec::new(); 5];
            for ((f, wr), r) in pts.iter().zip(&refs) {
                let coeffs = |d: [f64; 3], om: f64| {
                    if std::env::var("NOPRE").is_ok() {
                        env.coefficients(d)
                    } else {
                        pre.lookup(
                            d,
                            om * std::env::var("OMS")
                                .ok()
                                .and_then(|s| s.parse::<f64>().ok())
                                .unwrap_or(1.0),
                        )
                    }
                };
                let mut x = match &quad_fit {
                    Some(q) => {
                        let res = |d: [f64; 3], om: f64| {
                            let c = coeffs(d, om);
                            let qd = exact_part(quad_deg.unwrap(), q, d);
                            [c[0] - qd[0], c[1] - qd[1], c[2] - qd[2]]
                        };
                        let mut x = if std::env::var("QUAD_ONLY").is_ok() {
                            [0.0; 3]
                        } else if cut_walk {
                            let (cut, walked) = horizon_cut(&cells, *f, *wr, s_below);
                            let (x, v) = cells.estimate_from(&cut, *f, *wr, mask, skin, &res);
                            visits += walked + v;
                            x
                        } else {
                            cells.estimate(*f, *wr, mask, skin, &res)
                        };
                        let qx = match tilt_n {
                            // the horizon's tilt in the local frame read from
                            // an N x N octahedral grid, bilinear
                            Some(nt) if horizon => {
                                let (t, b, n) = *f;
                                let deg = quad_deg.unwrap();
                                let mut acc = [0.0; 3];
                                for (qd, wgt) in oct_corners([t[1], b[1], n[1]], nt) {
                                    let half = |d: [f64; 3]| {
                                        let dot =
                                            |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
                                        let wi = [dot(t), dot(b), dot(n)];
                                        if wi[0] * qd[0] + wi[1] * qd[1] + wi[2] * qd[2] < 0.0 {
                                            ground
                                        } else {
                                            poly_eval(deg, q, d)
                                        }
                                    };
                                    let v = integrate(&quad.with_coefficients(&half), *f, *wr);
                                    for a in 0..3 {
                                        acc[a] += wgt * v[a];
                                    }
                                }
                                acc
                            }
                            _ => integrate(quad_q.as_ref().unwrap(), *f, *wr),
                        };
                        for a in 0..3 {
                            x[a] += qx[a];
                        }
                        x
                    }
                    None => {
                        let top: Vec<u32> = (0..cells.n_top as u32).collect();
                        let (x, v) = cells.estimate_from(&top, *f, *wr, mask, skin, &coeffs);
                        visits += v;
                        x
                    }
                };
                // the hot spots: each a small light through the basis maps
                let hx =
                    sunbeam_response::hotspots::estimate(&lights, &er.basis, *f, *wr, mask, skin);
                for a in 0..3 {
                    x[a] += hx[a];
                }
                // the sun as the player: its map at the disc's point
                if let (Some(sky), Some(es)) = (env.sun(), &er.sun) {
                    let (d, _) = sky.sample_sun(sun_u[0], sun_u[1]).unwrap();
                    let (t, b, n) = *f;
                    let dot = |a: [f64; 3]| a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
                    let wi = [dot(t), dot(b), dot(n)];
                    if wi[2] > 0.0 {
                        let g = mask.gain(wi, *wr, skin);
                        let e = es.lookup(-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
                        for a in 0..3 {
                            x[a] += g * e[a];
                        }
                    }
                }
                let sc = |v: [f64; 3]| v.map(|c| (c / white).max(0.0));
                de.push(colour::ciede2000_xyz(sc(x), sc(*r)));
                if std::env::var("SWEEP").is_ok() {
                    eprintln!(
                        "SW {:.5} {:.6} {:.6} {:.6} {:.6}",
                        wr[2], x[1], r[1], x[2], r[2]
                    );
                }
                if std::env::var("RATIO").is_ok() {
                    eprintln!(
                        "RATIO {:.4} {:.4} {:.4} {:.4} de {:.2}",
                        wr[2],
                        x[0] / r[0],
                        x[1] / r[1],
                        x[2] / r[2],
                        de.last().unwrap()
                    );
                }
                if std::env::var("YONLY").is_ok() {
                    // the same chromaticity as the reference: luminance's share
                    let k = x[1] / r[1].max(1e-30);
                    let y_only = r.map(|c| c * k);
                    *de.last_mut().unwrap() = colour::ciede2000_xyz(sc(y_only), sc(*r));
                }
                if std::env::var("WORST").is_ok() && *de.last().unwrap() > 8.0 {
                    eprintln!(
                        "    dE {:.1} cos_r {:.3} est {:?} ref {:?}",
                        de.last().unwrap(),
                        wr[2],
                        sc(x).map(|v| (v * 1000.0).round() / 1000.0),
                        sc(*r).map(|v| (v * 1000.0).round() / 1000.0)
                    );
                }
                let bin = ((wr[2] * 5.0) as usize).min(4);
                bins[bin].push(*de.last().unwrap());
            }
            let dt = t0.elapsed();
            de.sort_by(f64::total_cmp);
            let binned: Vec<String> = bins
                .iter_mut()
                .map(|b| {
                    b.sort_by(f64::total_cmp);
                    format!(
                        "{:.1}/{:.1}",
                        b.iter().sum::<f64>() / b.len().max(1) as f64,
                        b.get(b.len() * 95 / 100).copied().unwrap_or(0.0)
                    )
                })
                .collect();
            eprintln!("    by cos_r fifths (mean/p95): {}", binned.join("  "));
            eprintln!(
                "    nodes visited per point (with CUT: the cut's walk and the sum): {:.1}",
                visits as f64 / pts.len() as f64
            );
            let mean = de.iter().sum::<f64>() / de.len() as f64;
            eprintln!(
                "  cells {n_top:5} depth {depth}: nodes {:6}  dE mean {mean:.3} p99 {:.3} max {:.3}  {:.1} us/point",
                cells.nodes.len(),
                de[de.len() * 99 / 100],
                de[de.len() - 1],
                dt.as_secs_f64() * 1e6 / pts.len() as f64
            );
        }
    }
}

/// A basis of the polynomials of degree `deg` on the sphere (the span of
/// the spherical harmonics to order `deg`): `x^a y^b z^c` with `c <= 1`,
/// `a + b + c <= deg` (`z^2 = 1 - x^2 - y^2` reduces the rest), `(deg + 1)^2`
/// functions.
fn poly_basis(deg: u32, d: [f64; 3]) -> Vec<f64> {
    let [x, y, z] = d;
    let mut out = Vec::new();
    for c in 0..=1u32.min(deg) {
        for a in 0..=deg - c {
            for b in 0..=deg - c - a {
                out.push(x.powi(a as i32) * y.powi(b as i32) * z.powi(c as i32));
            }
        }
    }
    out
}

fn poly_eval(deg: u32, q: &[[f64; 3]], d: [f64; 3]) -> [f64; 3] {
    let f = poly_basis(deg, d);
    let mut out = [0.0; 3];
    for (fa, qa) in f.iter().zip(q) {
        for c in 0..3 {
            out[c] += qa[c] * fa;
        }
    }
    out
}

/// Gaussian elimination with partial pivoting, three right sides.
fn solve(mut a: Vec<Vec<f64>>, mut b: Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    let n = a.len();
    for k in 0..n {
        let p = (k..n)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap();
        a.swap(k, p);
        b.swap(k, p);
        let (ak, bk) = (a[k].clone(), b[k]);
        for (ai, bi) in a.iter_mut().zip(b.iter_mut()).skip(k + 1) {
            let f = ai[k] / ak[k];
            for (x, y) in ai.iter_mut().zip(&ak).skip(k) {
                *x -= f * y;
            }
            for (x, y) in bi.iter_mut().zip(&bk) {
                *x -= f * y;
            }
        }
    }
    let mut x = vec![[0.0; 3]; n];
    for k in (0..n).rev() {
        for c in 0..3 {
            let mut v = b[k][c];
            for j in k + 1..n {
                v -= a[k][j] * x[j][c];
            }
            x[k][c] = v / a[k][k];
        }
    }
    x
}

/// The nodes from the roots down whose part of the disc may lie below the
/// world's horizon (`y < 0`) for view `wr` in `frame`: a node wholly above it
/// is left out, one that straddles it (its centroid's direction within its
/// angular reach, 3 spreads over `cos(theta_i)`) or whose spread exceeds
/// `s_below` is split; with the number of nodes visited.
fn horizon_cut(
    cells: &Cells,
    frame: ([f64; 3], [f64; 3], [f64; 3]),
    wr: [f64; 3],
    s_below: f64,
) -> (Vec<u32>, usize) {
    let (t, b, n) = frame;
    let mut cut = Vec::new();
    let mut visits = 0;
    let mut stack: Vec<u32> = (0..cells.n_top as u32).rev().collect();
    while let Some(id) = stack.pop() {
        visits += 1;
        let c = &cells.nodes[id as usize];
        let wxy = [-c.uv[0] - wr[0], -c.uv[1] - wr[1]];
        let l = wxy[0].hypot(wxy[1]);
        if l > 1.05 + 3.0 * c.spread {
            continue;
        }
        let k = if l > 0.999 { 0.999 / l } else { 1.0 };
        let wi = [wxy[0] * k, wxy[1] * k];
        let wz = (1.0 - wi[0] * wi[0] - wi[1] * wi[1]).max(0.0).sqrt();
        let y = wi[0] * t[1] + wi[1] * b[1] + wz * n[1];
        let reach = (3.0 * c.spread / wz.max(0.05))
            .min(std::f64::consts::FRAC_PI_2)
            .sin();
        if y > reach {
            continue;
        }
        match c.children {
            Some([a, bb]) if y > -reach || c.spread > s_below => {
                stack.push(bb);
                stack.push(a);
            }
            _ => cut.push(id),
        }
    }
    (cut, visits)
}

/// The four texel centres of an `n` x `n` octahedral grid over the sphere
/// (`z` up) around unit vector `u`, with their bilinear weights.
fn oct_corners(u: [f64; 3], n: usize) -> Vec<([f64; 3], f64)> {
    let l1 = u[0].abs() + u[1].abs() + u[2].abs();
    let (mut x, mut y) = (u[0] / l1, u[1] / l1);
    if u[2] < 0.0 {
        (x, y) = ((1.0 - y.abs()) * x.signum(), (1.0 - x.abs()) * y.signum());
    }
    let nf = n as f64;
    let fx = ((x + 1.0) * 0.5 * nf - 0.5).clamp(0.0, nf - 1.0);
    let fy = ((y + 1.0) * 0.5 * nf - 0.5).clamp(0.0, nf - 1.0);
    let (i0, j0) = ((fx as usize).min(n - 2), (fy as usize).min(n - 2));
    let (tx, ty) = (fx - i0 as f64, fy - j0 as f64);
    let dir = |i: usize, j: usize| {
        let a = 2.0 * (i as f64 + 0.5) / nf - 1.0;
        let b = 2.0 * (j as f64 + 0.5) / nf - 1.0;
        let z = 1.0 - a.abs() - b.abs();
        let (a, b) = if z < 0.0 {
            ((1.0 - b.abs()) * a.signum(), (1.0 - a.abs()) * b.signum())
        } else {
            (a, b)
        };
        let l = (a * a + b * b + z * z).sqrt();
        [a / l, b / l, z / l]
    };
    vec![
        (dir(i0, j0), (1.0 - tx) * (1.0 - ty)),
        (dir(i0 + 1, j0), tx * (1.0 - ty)),
        (dir(i0, j0 + 1), (1.0 - tx) * ty),
        (dir(i0 + 1, j0 + 1), tx * ty),
    ]
}
