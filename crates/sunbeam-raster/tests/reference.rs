//! The CPU reference against independent truths: closed forms for geometry and
//! Lambert shading, and a direct float64 Kirchhoff sum (`R_U`, PHYSICS.md 2b;
//! its `R` checked against sunbeam-optics' ground truth; no pack code) for
//! the diffraction colour of rendered pixels.

mod common;

use std::sync::Arc;
use sunbeam_optics::colour;
use sunbeam_optics::truth::{Params, Truth};
use sunbeam_raster::{fixtures, raster, shade, Mesh, Options};

#[test]
fn lambert_quad_centre_and_coverage() {
    let (mut scene, mesh) = fixtures::quad_scene([64, 64]);
    scene.meshes[0].pack = None;
    scene.meshes[0].base_color = [0.5, 0.25, 0.125];
    let p = fixtures::prepared(scene.clone(), mesh, None);
    let img = sunbeam_raster::render_prepared(&p, &Options::default());
    // Centre pixel: base * cos(theta_i) with the light at 30 degrees from the normal.
    let l = scene.lights[0].direction;
    let cos_i = l[2] / (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]).sqrt();
    let want = [0.5 * cos_i, 0.25 * cos_i, 0.125 * cos_i].map(colour::srgb_oetf);
    let got = img.pixel(32, 32);
    for k in 0..3 {
        assert!(
            (got[k] as f64 - want[k]).abs() < 1e-6,
            "{got:?} vs {want:?}"
        );
    }
    // Coverage: the quad's projected area in pixels (square, centred) within one pixel row/column.
    let mut p = p;
    p.scene.camera.eye = [0.0, 0.0, 2.5];
    let g = raster::rasterise(&p, 64, 64);
    let covered = g.iter().filter(|f| f.mesh.is_some()).count() as f64;
    let d = (p.scene.camera.eye[2] - 0.0).abs();
    let half = 0.5 / d / (scene.camera.fov_y_deg.to_radians() / 2.0).tan() * 32.0; // half side in pixels
    let side = 2.0 * half;
    assert!(
        (covered - side * side).abs() <= 2.0 * side + 2.0,
        "{covered} px vs {}",
        side * side
    );
    // Symmetric about the centre lines.
    for j in 0..64 {
        for i in 0..64 {
            assert_eq!(
                g[j * 64 + i].mesh.is_some(),
                g[j * 64 + 63 - i].mesh.is_some()
            );
            assert_eq!(
                g[j * 64 + i].mesh.is_some(),
                g[(63 - j) * 64 + i].mesh.is_some()
            );
        }
    }
}

/// The environment path's sub-pixel samples are jittered in their pixels by
/// the seed: over seeds, a quad's covered sample count converges to its exact
/// projected area, which the pixel centres miss (its edges fall at 0.05 px).
#[test]
fn jittered_samples_cover_the_exact_area() {
    let (scene, mesh) = fixtures::quad_scene([16, 16]);
    let mut p = fixtures::prepared(scene.clone(), mesh, None);
    // Square quad of side 1 centred on the axis: half side in pixels.
    let half_px = 5.05;
    let t = (scene.camera.fov_y_deg.to_radians() / 2.0).tan();
    p.scene.camera.eye = [0.0, 0.0, 0.5 * 8.0 / (half_px * t)];
    let area = (2.0 * half_px) * (2.0 * half_px);
    let count = |g: &[sunbeam_raster::raster::Fragment]| {
        g.iter().filter(|f| f.mesh.is_some()).count() as f64
    };
    let centres = count(&raster::rasterise(&p, 16, 16));
    assert!((centres - area).abs() > 2.0, "{centres} vs {area}");
    let n = 400;
    let mut sum = 0.0;
    for seed in 0..n {
        let at = raster::Positions::Jittered(seed);
        sum += count(&raster::rasterise_rows_at(&p, 16, 16, 0..16, at));
    }
    let mean = sum / n as f64;
    // One seed's count varies by about 3 (the 40 edge pixels' Bernoulli
    // coverage): 0.15 for the mean of 400.
    assert!((mean - area).abs() < 0.6, "{mean} vs {area}");
}

#[test]
fn sphere_back_faces_are_hidden_and_depth_is_front_most() {
    let (scene, mesh) = fixtures::sphere_scene([48, 48]);
    let p = fixtures::prepared(scene.clone(), mesh, None);
    let g = raster::rasterise(&p, 48, 48);
    let eye = scene.camera.eye;
    for f in g.iter().filter(|f| f.mesh.is_some()) {
        // every visible point faces the camera (front hemisphere)
        let v = [eye[0] - f.pos[0], eye[1] - f.pos[1], eye[2] - f.pos[2]];
        assert!(
            v[0] * f.pos[0] + v[1] * f.pos[1] + v[2] * f.pos[2] > -1e-3,
            "{:?}",
            f.pos
        );
        let r = (f.pos[0].powi(2) + f.pos[1].powi(2) + f.pos[2].powi(2)).sqrt();
        assert!((r - 0.5).abs() < 2e-3);
    }
}

/// Diffraction colour of rendered pixels against the ground truth of PHYSICS.md
/// 2 and 2b (a direct float64 sum of the window's amplitude and its
/// derivatives, 1 nm, no pack code; its `|P|^2` is the float64 truth's `R`):
/// the frame, the sign of (u, v, w), the grazing term and the gain must all
/// agree for this to hold. The skin is set to the relative normalisation, so
/// that CIEDE2000 is taken at the luminance the bound was set at (the
/// absolute colours are 0.04 of these; the normalisation itself is checked in
/// sunbeam-optics and by the furnace tests).
#[test]
fn blazed_quad_pixels_match_ground_truth() {
    let Some(dir) = sunbeam_common::testdata::shared_file("snake/BlazingBump.bmp") else {
        return;
    };
    let dir = dir.parent().unwrap().to_path_buf();
    let opts = sunbeam_pack::build::BuildOptions::default();
    let pack = Arc::new(fixtures::pack(&fixtures::BLAZED, &dir, &opts).unwrap());
    let (scene, mesh) = fixtures::quad_scene([40, 40]);
    let mut p = fixtures::prepared(scene.clone(), mesh, Some(pack));
    p.meshes[0].1.skin = sunbeam_optics::gain::Material::RELATIVE;
    let g = raster::rasterise(&p, 40, 40);
    let sh = shade::Shader::new(&p, &Options::default());
    let (w, h, data) = fixtures::heights(&fixtures::BLAZED, &dir).unwrap();
    let px = fixtures::BLAZED.pixel_m;
    let kirchhoff = common::Kirchhoff::new(w, h, px, px, &data, Params::default().coherence_m);
    let field = sunbeam_field::HeightField::new(w, h, px, px, data).unwrap();
    let truth = Truth::new(&field, &Params::default()).unwrap();
    // The direct sum's R is the truth's.
    for (u, v, ww, l) in [(0.1, -0.05, -1.8, 450e-9), (-0.3, 0.2, -1.2, 620e-9)] {
        let r = kirchhoff.r_u(&kirchhoff.phasors(ww, l), u, v, ww, l).0;
        let t = truth.reflectance(u, v, ww, l);
        assert!((r - t).abs() <= 1e-9 * t.max(1e-6), "R {r} vs truth {t}");
    }
    let norm = sunbeam_optics::cie::d65_y_norm(sunbeam_optics::cie::DEFAULT_RANGE_NM);
    let colour_u = |wi: [f64; 3], wr: [f64; 3]| {
        let (u, v, ww) = (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
        let mut xyz = [0.0; 3];
        for nm in 380..=780u32 {
            let l = nm as f64 * 1e-9;
            let r = kirchhoff.r_u(&kirchhoff.phasors(ww, l), u, v, ww, l).1;
            let (s, c) = (
                sunbeam_optics::cie::d65_nm(nm),
                sunbeam_optics::cie::cmf_nm(nm),
            );
            for k in 0..3 {
                xyz[k] += r * s * c[k] / norm;
            }
        }
        let gg = sunbeam_optics::gain::g(wi, wr, sunbeam_optics::gain::Material::RELATIVE);
        xyz.map(|c| c * gg)
    };
    let mut worst: f64 = 0.0;
    let mut bright = 0;
    for &(i, j) in &[
        (20usize, 20usize),
        (5, 20),
        (35, 20),
        (12, 19),
        (28, 21),
        (20, 8),
        (8, 30),
    ] {
        let f = &g[j * 40 + i];
        assert!(f.mesh.is_some());
        let (t, b, n) = shade::frame(f.normal, f.tangent).unwrap();
        let e = scene.camera.eye;
        let wr = norm3([e[0] - f.pos[0], e[1] - f.pos[1], e[2] - f.pos[2]]);
        let wi = norm3(scene.lights[0].direction);
        let loc = |d: [f64; 3]| [dot(d, t), dot(d, b), dot(d, n)];
        let ours = sh.diffraction_xyz(0, loc(wi), loc(wr));
        let want = colour_u(loc(wi), loc(wr));
        if want[1] > 0.01 {
            bright += 1;
        }
        let de = colour::ciede2000_xyz(ours, want);
        eprintln!(
            "({i},{j}) wi {:?} wr {:?}: ours {ours:?} truth {want:?} dE {de:.3}",
            loc(wi),
            loc(wr)
        );
        worst = worst.max(de);
        assert!(
            de < 1.0 || want[1] < 1e-4,
            "pixel ({i},{j}): {ours:?} vs truth {want:?}, dE {de}"
        );
    }
    assert!(
        bright >= 3,
        "the test scene should show the grating's orders"
    );
    eprintln!("worst CIEDE2000 against the ground truth: {worst:.3}");
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm3(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    a.map(|v| v / l)
}

#[test]
fn images_round_trip_png_and_compare() {
    let mut a = sunbeam_raster::Image::new(4, 3);
    a.rgb[5] = [0.2, 0.5, 0.9];
    let dir = std::env::temp_dir().join(format!("sb-raster-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("a.png");
    a.write_png(&f).unwrap();
    let b = sunbeam_raster::Image::read_png(&f).unwrap();
    let d = sunbeam_raster::compare(&a, &b).unwrap();
    assert!(d.max < 0.3, "{d}");
    let _ = Mesh::quad();
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `camera.shift` (docs/SCENE.md, Blender's lens shift): the reference's
/// fragments, of the quad and of the background, project back to their pixel
/// centres under a pinhole model with the shift written here independently
/// (the image window moves by `shift x max(w, h)` pixels, right and up), and
/// the quad's centre lands where that model puts it.
#[test]
fn lens_shift_matches_a_pinhole_model() {
    let (w, h) = (48u32, 32u32);
    let (mut scene, mesh) = fixtures::quad_scene([w, h]);
    scene.meshes[0].pack = None;
    // the view axis along -z: view coordinates are world ones minus the eye
    scene.camera.eye = [0.3, -0.2, 4.0];
    scene.camera.target = [0.3, -0.2, 0.0];
    scene.camera.fov_y_deg = 30.0;
    scene.camera.shift = [0.2, 0.15];
    let p = fixtures::prepared(scene.clone(), mesh, None);
    let g = raster::rasterise(&p, w, h);
    let t = (30f64.to_radians() / 2.0).tan();
    let m = w.max(h) as f64;
    let eye = scene.camera.eye;
    let project = |q: [f64; 3]| {
        let (x, y, z) = (q[0] - eye[0], q[1] - eye[1], eye[2] - q[2]);
        let f = h as f64 / 2.0 / t; // pixels per unit of tangent
        [
            w as f64 / 2.0 + x / z * f - 0.2 * m,
            h as f64 / 2.0 - y / z * f + 0.15 * m,
        ]
    };
    let mut covered = 0;
    let mut worst: f64 = 0.0;
    for j in 0..h as usize {
        for i in 0..w as usize {
            let f = &g[j * w as usize + i];
            covered += usize::from(f.mesh.is_some());
            let q = project(f.pos);
            worst = worst
                .max((q[0] - (i as f64 + 0.5)).abs())
                .max((q[1] - (j as f64 + 0.5)).abs());
        }
    }
    // (the rasteriser snaps vertices to 1/256 pixel: measured 0.001 px)
    eprintln!("worst fragment {worst:.2e} px off its pixel centre");
    assert!(worst < 0.01, "a fragment projects {worst} px off its pixel");
    // the quad (side 1): its centre at the model's pixel, its pixels around it
    let c = project([0.0; 3]);
    assert!(
        c[0] > 8.0 && c[0] < 12.0 && c[1] > 18.0 && c[1] < 24.0,
        "{c:?}"
    );
    let (mut sx, mut sy) = (0.0, 0.0);
    for (k, f) in g.iter().enumerate() {
        if f.mesh.is_some() {
            sx += (k % w as usize) as f64 + 0.5;
            sy += (k / w as usize) as f64 + 0.5;
        }
    }
    let side = 1.0 / 4.0 * h as f64 / 2.0 / t;
    assert!(
        (covered as f64 - side * side).abs() < 2.0 * side + 2.0,
        "{covered} vs {}",
        side * side
    );
    let centroid = [sx / covered as f64, sy / covered as f64];
    eprintln!("quad centre {c:?}, its pixels' centroid {centroid:?}, {covered} px");
    assert!(
        (centroid[0] - c[0]).abs() < 0.5 && (centroid[1] - c[1]).abs() < 0.5,
        "{centroid:?} vs {c:?}"
    );
}

/// The reference's adaptive wavelength step (`shade::wavelength_step_nm`,
/// docs/EVAL.md "Wavelength step") against the 1 nm sum
/// (`Options::lambda_step_nm = Some(1)`) on a 5 um ridge patch like snake
/// skin, both models, at views over the hemisphere (first orders, grazing
/// and the mirror direction): CIEDE2000 < 0.05 wherever the colour is
/// visible, and the window model's step is more than 3 nm on average, or it
/// would save little (the tiled model keeps 1 nm).
#[test]
fn adaptive_wavelength_step_matches_the_1nm_sum() {
    use sunbeam_pack::Model;
    let (n, dx) = (256usize, 20e-9);
    let data: Vec<f64> = (0..n * n)
        .map(|k| {
            let (i, j) = ((k % n) as f64, (k / n) as f64);
            let x = 2.0 * std::f64::consts::PI * i * dx / 0.7e-6 + 0.3 * (0.05 * j).sin();
            150e-9 * (1.0 + x.sin())
        })
        .collect();
    let (scene, mesh) = fixtures::quad_scene([4, 4]);
    let mut worst: f64 = 0.0;
    let (mut steps, mut points) = (0u64, 0u64);
    for model in [Model::Window, Model::Tiled] {
        let pack = common::pack_of(n, dx, &data, model);
        let mut p = fixtures::prepared(scene.clone(), mesh.clone(), Some(pack.clone()));
        p.meshes[0].1.skin = sunbeam_optics::gain::Material::RELATIVE;
        let adaptive = shade::Shader::new(&p, &Options::default());
        let exact = shade::Shader::new(
            &p,
            &Options {
                lambda_step_nm: Some(1),
                ..Options::default()
            },
        );
        let dir = |theta: f64, phi: f64| {
            let (t, f) = (theta.to_radians(), phi.to_radians());
            [t.sin() * f.cos(), t.sin() * f.sin(), t.cos()]
        };
        for ti in [0.0, 20.0, 45.0, 70.0, 85.0] {
            for pi in [0.0, 30.0, 90.0, 180.0] {
                for tr in [0.0, 10.0, 25.0, 40.0, 55.0, 70.0, 85.0] {
                    for pr in [0.0, 5.0, 180.0, 200.0, 270.0] {
                        let (wi, wr) = (dir(ti, pi), dir(tr, pr));
                        let want = exact.diffraction_xyz(0, wi, wr);
                        let got = adaptive.diffraction_xyz(0, wi, wr);
                        let (u, v, w) = (-wi[0] - wr[0], -wi[1] - wr[1], -wi[2] - wr[2]);
                        if model == Model::Window {
                            steps += shade::wavelength_step_nm(&pack.manifest, u, v, w) as u64;
                            points += 1;
                        }
                        if want[1] < 1e-4 {
                            continue;
                        }
                        let de = colour::ciede2000_xyz(got, want);
                        assert!(
                            de < 0.05,
                            "{model:?} wi {wi:?} wr {wr:?}: {got:?} vs 1 nm {want:?}, dE {de}"
                        );
                        worst = worst.max(de);
                    }
                }
            }
        }
    }
    let mean_step = steps as f64 / points as f64;
    eprintln!("adaptive step: worst CIEDE2000 {worst:.4}, mean step {mean_step:.2} nm over {points} views");
    assert!(mean_step > 3.0, "mean step {mean_step} nm");
}
