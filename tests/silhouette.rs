//! The player against the CPU reference over **all** lit pixels of a point-lit
//! sphere, silhouettes included (issue 25): a front-lit sphere whose diameter
//! is a third of the frame, shaded with synthetic ridge packs of 5 to 82 um,
//! both renderers drawn at 2x and box-filtered (the player with its 4x MSAA
//! and footprint filter, the reference with `--samples 16`), compared in linear
//! light (CIEDE2000 over the reference's lit pixels) before any display
//! transform. Reported over all lit pixels, over the two-pixel ring at the
//! silhouette (lit pixels with an unlit pixel within 2 px) and over the
//! interior; asserted over all lit pixels (p99) and the ring (max).
//!
//! `SUNBEAM_SILHOUETTE_SIZE=192` measures the 192 x 192 frame (the
//! tests' frames are 64, 96 at 8 um: the same sphere at fewer pixels, for CI);
//! `SUNBEAM_SILHOUETTE_OUT=DIR` keeps both 1x frames as EXR;
//! `SUNBEAM_SILHOUETTE_REF=DIR` reads the references from such a folder
//! instead of rendering them (to compare versions of the player).

mod gpu;

use gpu::{gpu, ridge_pack};
use sunbeam_frame::{linear, LinearImage, Prepared};
use sunbeam_raster::Options;
use sunbeam_render::Settings;

fn frame_size() -> Option<u32> {
    std::env::var("SUNBEAM_SILHOUETTE_SIZE")
        .ok()
        .and_then(|s| s.parse().ok())
}

/// The scene of issue 25 at `size` pixels: the sphere seen from 4.8 units
/// (its diameter a third of the frame).
fn scene(pack: sunbeam_pack::Pack, size: u32) -> Prepared {
    gpu::ridge_sphere(pack, 4.8, size)
}

/// Lit pixels of `reference` split into the ring (an unlit pixel within 2 px,
/// the frame's border counting as unlit) and the interior.
fn ring_and_interior(reference: &LinearImage) -> (Vec<usize>, Vec<usize>) {
    let (w, h) = (reference.width as i64, reference.height as i64);
    let lit = |x: i64, y: i64| {
        x >= 0
            && y >= 0
            && x < w
            && y < h
            && linear::luminance(reference.rgb[(y * w + x) as usize]) >= linear::LIT_Y
    };
    let (mut ring, mut interior) = (Vec::new(), Vec::new());
    for y in 0..h {
        for x in 0..w {
            if !lit(x, y) {
                continue;
            }
            let edge = (-2..=2).any(|dy| (-2..=2).any(|dx| !lit(x + dx, y + dy)));
            let i = (y * w + x) as usize;
            if edge {
                ring.push(i);
            } else {
                interior.push(i);
            }
        }
    }
    (ring, interior)
}

fn delta_e(a: &LinearImage, b: &LinearImage, i: usize) -> f64 {
    use sunbeam_optics::colour;
    colour::ciede2000_xyz(
        colour::linear_srgb_to_xyz(a.rgb[i].map(|v| f64::from(v).max(0.0))),
        colour::linear_srgb_to_xyz(b.rgb[i].map(|v| f64::from(v).max(0.0))),
    )
}

struct Figures {
    all: sunbeam_frame::ColourDiff,
    ring: sunbeam_frame::ColourDiff,
    interior: sunbeam_frame::ColourDiff,
}

fn measure(player: &LinearImage, reference: &LinearImage) -> Figures {
    let (ring, interior) = ring_and_interior(reference);
    let over = |px: &[usize]| {
        let mut d: Vec<f64> = px.iter().map(|&i| delta_e(player, reference, i)).collect();
        sunbeam_frame::diff::stats(&mut d)
    };
    let mut all: Vec<usize> = ring.iter().chain(&interior).copied().collect();
    all.sort_unstable();
    Figures {
        all: over(&all),
        ring: over(&ring),
        interior: over(&interior),
    }
}

/// Stops added to the scene's exposure for the printed bright figures: the base's grey
/// at the sphere's centre near Y = 0.2 and the limb's colours visible (at the
/// scene's own exposure the ring's pixels are darker than Y = 0.01, where
/// CIEDE2000 sees little).
const BRIGHT_EV: f32 = 6.0;

fn scaled(im: &LinearImage, ev: f32) -> LinearImage {
    let mut im = im.clone();
    for c in &mut im.rgb {
        *c = c.map(|v| v * ev.exp2());
    }
    im
}

/// What one pack must meet at the scene's exposure: p99 over all lit pixels
/// below `all_p99` (the target: 1) and max over the ring below `ring_max`.
/// The `BRIGHT_EV` figures are printed, not asserted: there the ring is
/// bounded by sampling, the reference's own included (docs/bench/play.md
/// "Silhouettes under a point light").
struct Bounds {
    all_p99: f64,
    ring_max: f64,
}

/// Renders both, prints the figures, asserts `b`.
fn silhouette(name: &str, n: usize, pixel: f64, size: u32, bounds: Bounds) {
    let Some(gpu) = gpu() else { return };
    let size = frame_size().unwrap_or(size);
    let t = std::time::Instant::now();
    let p = scene(ridge_pack(n, pixel), size);
    let t_pack = t.elapsed();
    let t = std::time::Instant::now();
    let cached = std::env::var("SUNBEAM_SILHOUETTE_REF")
        .map(|d| std::path::Path::new(&d).join(format!("{name}-{size}-ref.exr")))
        .ok()
        .filter(|f| f.exists());
    let reference = match cached {
        Some(f) => LinearImage::read_exr(&f).unwrap(),
        None => sunbeam_raster::render_prepared_linear(
            &p,
            &Options {
                samples: 16,
                size: Some([2 * size, 2 * size]),
                ..Default::default()
            },
        )
        .unwrap()
        .downsample(2),
    };
    let t_cpu = t.elapsed();
    let t = std::time::Instant::now();
    let player =
        sunbeam_render::render_headless_linear(&gpu, &p, &Settings::default(), None, 1, 2).unwrap();
    let t_gpu = t.elapsed();
    if let Ok(dir) = std::env::var("SUNBEAM_SILHOUETTE_OUT") {
        let dir = std::path::PathBuf::from(dir);
        std::fs::create_dir_all(&dir).unwrap();
        reference
            .write_exr(&dir.join(format!("{name}-{size}-ref.exr")))
            .unwrap();
        player
            .write_exr(&dir.join(format!("{name}-{size}-play.exr")))
            .unwrap();
    }
    let f = measure(&player, &reference);
    let b = measure(&scaled(&player, BRIGHT_EV), &scaled(&reference, BRIGHT_EV));
    eprintln!(
        "{name} ({size}^2, 2x both): all {}; ring {}; interior {}\n  +{BRIGHT_EV} EV: all {}; ring {}; interior {}\n  (pack {t_pack:.2?}, reference {t_cpu:.2?}, player {t_gpu:.2?})",
        f.all, f.ring, f.interior, b.all, b.ring, b.interior
    );
    assert!(
        f.interior.pixels > f.ring.pixels / 2,
        "{name}: the sphere shows little: {} interior, {} ring pixels",
        f.interior.pixels,
        f.ring.pixels
    );
    assert!(
        f.all.p99 < bounds.all_p99 && f.ring.max < bounds.ring_max,
        "{name}: over all lit pixels {} (ring {}, interior {})",
        f.all,
        f.ring,
        f.interior
    );
}

const TARGET: Bounds = Bounds {
    all_p99: 1.0,
    ring_max: 1.0,
};

#[test]
fn silhouette_5um() {
    silhouette("ring-5um", 160, 31e-9, 64, TARGET);
}

/// At 96 x 96, not 64: at 64 a pixel spans 1.5 times the normals and the
/// 8 um patch's narrow lobes put the interior (not the ring) at p99 3.1. The
/// ring's max is what the player's silhouette shading changed here: 1.42
/// with the pixel centre's extrapolated attributes, 0.42 now.
#[test]
fn silhouette_8um() {
    silhouette("ring-8um", 256, 31e-9, 96, TARGET);
}

#[test]
fn silhouette_20um() {
    silhouette("ring-20um", 640, 31e-9, 64, TARGET);
}

#[test]
fn silhouette_41um() {
    silhouette("ring-41um", 1312, 31e-9, 64, TARGET);
}

#[test]
fn silhouette_82um() {
    silhouette("ring-82um", 2624, 31e-9, 64, TARGET);
}
