//! Edge refinement of a headless frame: the pixels whose sub-pixels disagree
//! (a silhouette's coverage, the limb's sheen, a scale's border) rendered
//! again at `m x m` positions each.
//!
//! A supersampled frame is a midpoint rule over each pixel; where the
//! pixel's content is smooth at the sub-pixels' scale it is already close,
//! and where a sharp feature crosses it (the object's outline against what
//! is behind, a lamp's sheen at the limb thinner than a sub-pixel) it needs
//! many more positions than the rest of the frame (docs/LIGHTING.md "Edge
//! refinement"). So the frame flags those pixels from its own sub-pixels
//! ([`flag_pixels`]) and renders the tiles of the image that hold them
//! through a camera narrowed to the tile ([`sunbeam_scene::Camera::window`]):
//! the same renderer, each tile a frame of its own (the cells' pre-passes,
//! the footprints and MSAA at the tile's sub-pixels), whose `m x m` box
//! replaces the flagged pixels. The cost follows the tiles that hold a
//! flagged pixel, not the frame's area; each tile shades its unflagged
//! pixels too (4.7 times the flagged ones on a 512 x 512 sphere: a stencil
//! of the flagged pixels would save that, not built). A tile's frame has
//! `sub_pixel` = `m` ([`FrameState`]): its cells' grid serves its grazing
//! views too, so a limb pixel's `m x m` positions mix from the grid instead
//! of each walking the cells (the sphere's M = 8 refinement: 83 s, 488 s
//! with each walking).

use crate::{FrameState, Gpu, Offscreen, Renderer};
use sunbeam_common::{Error, Result};
use sunbeam_frame::linear::{luminance, LinearImage, LIT_Y};

/// Tiles' side in texels that [`tile_pixels`] aims at: on lavapipe a frame
/// under 128 texels a side costs more per position (its fixed work, and a
/// rasteriser that shares its work out in 64-pixel tiles: at 16 positions
/// a side, tiles of 4 / 8 / 16 pixels took 115 / 65 / 59 s on the same
/// 416 pixels), and larger ones shade more unflagged pixels.
pub const TILE_TEXELS: u32 = 256;

/// Tiles' side in pixels at `m` positions per pixel side: about
/// [`TILE_TEXELS`] texels, 4 to 16 pixels (the image's side where smaller).
pub fn tile_pixels(m: u32) -> u32 {
    (TILE_TEXELS / m.max(1)).clamp(4, 16)
}

/// Positions per pixel side the refinement may take.
pub const MAX_POSITIONS: u32 = 64;

/// The default bend of the light, in the pixel's mean luminance, that flags
/// a pixel (see [`flag_pixels`]).
pub const DEFAULT_THRESHOLD: f64 = 0.05;

/// What [`refine`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refined {
    /// Pixels replaced.
    pub pixels: usize,
    /// Tiles rendered.
    pub tiles: usize,
    /// Per pixel of the image: replaced, and its `m x m` positions still
    /// unsettled ([`unsettled`]): the pixels a next level at `2 m` takes.
    /// None where `m` is odd.
    pub unsettled: Vec<bool>,
}

/// Whether the `m x m` positions of the pixel whose block starts at
/// (`x0`, `y0`) in `sub` are unsettled: `m` even, and one of its four
/// interleaved quarter-lattices (every other position along each axis,
/// `(m / 2)^2` each: the same pixel at half the positions per side, four
/// ways) has a mean luminance off the block's by more than `threshold`
/// times the block's mean (plus [`LIT_Y`]). At a sharp feature the
/// midpoint rule's error falls as `1 / m`, so the block's own error is
/// about half that spread: what is left after `m` is measured by the
/// positions already taken, and a next level is spent only where it shows.
pub fn unsettled(sub: &LinearImage, m: u32, x0: u32, y0: u32, threshold: f64) -> bool {
    if m < 2 || m % 2 == 1 {
        return false;
    }
    let mut lattice = [0.0f64; 4];
    for j in 0..m {
        for i in 0..m {
            let p = sub.rgb[((y0 + j) * sub.width + x0 + i) as usize];
            lattice[((j % 2) * 2 + i % 2) as usize] += luminance(p);
        }
    }
    let quarter = f64::from(m * m / 4);
    let lattice = lattice.map(|v| v / quarter);
    let mean = lattice.iter().sum::<f64>() / 4.0;
    lattice
        .iter()
        .any(|&l| (l - mean).abs() > threshold * (mean + LIT_Y))
}

/// The pixels of a `k`-times supersampled frame `sub` (`k` sub-pixels per
/// pixel side; `coverage` its sub-pixels' coverage by the meshes, 0..1) to
/// refine: those where
/// - a mesh's outline crosses the pixel's sub-pixels or the ring of
///   sub-pixels around them (the neighbours' nearest: so `k = 1` compares a
///   pixel with its eight neighbours): some covered, some not, a coverage
///   sampled as coarsely as the frame's positions; or
/// - the light on the surface bends at the sub-pixels' scale: a covered
///   sub-pixel of the pixel (its four neighbours covered too) differs from
///   their mean by more than `threshold` times the pixel's mean luminance
///   (plus [`LIT_Y`], so that near-black noise does not count). That is
///   the midpoint rule's error term: a gradient, however steep, is
///   integrated exactly and is not flagged; a step of `4 threshold` times
///   the mean, a sheen, an order's edge are;
///
/// and the eight neighbours of a flagged pixel that the meshes touch (a
/// sheen beside an outline can fall between every sub-pixel of its own
/// pixel). What is behind the meshes alone is never flagged: the
/// background's pass already averages each pixel.
pub fn flag_pixels(sub: &LinearImage, coverage: &[f32], k: u32, threshold: f64) -> Vec<bool> {
    // a sub-pixel counts as covered, or as not, within this of 1 or 0 (the
    // coverage is the mean of 4 MSAA samples in half floats)
    const FULL: f32 = 0.99;
    const NONE: f32 = 0.01;
    let k = k.max(1) as i64;
    let (w, h) = (sub.width as i64 / k, sub.height as i64 / k);
    let (sw, sh) = (sub.width as i64, sub.height as i64);
    let y: Vec<f64> = sub.rgb.iter().map(|&p| luminance(p)).collect();
    let at = |x: i64, y: i64| (x >= 0 && y >= 0 && x < sw && y < sh).then(|| (y * sw + x) as usize);
    // how far sub-pixel i bends from its covered neighbours' mean along
    // each axis where it has both (0 where one of them is not covered: the
    // outline's test takes those)
    let bend = |x: i64, yy: i64| -> f64 {
        let i = at(x, yy).expect("inside");
        if coverage[i] < FULL {
            return 0.0;
        }
        let (mut sum, mut n) = (0.0, 0.0);
        for (dx, dy) in [(1, 0), (0, 1)] {
            let (Some(a), Some(b)) = (at(x - dx, yy - dy), at(x + dx, yy + dy)) else {
                continue;
            };
            if coverage[a] < FULL || coverage[b] < FULL {
                return 0.0;
            }
            sum += 0.5 * (y[a] + y[b]);
            n += 1.0;
        }
        if n > 0.0 {
            (y[i] - sum / n).abs()
        } else {
            0.0
        }
    };
    let mut own = vec![false; (w * h) as usize];
    let mut touched = vec![false; (w * h) as usize];
    for py in 0..h {
        for px in 0..w {
            let (mut some, mut all) = (false, true);
            for sy in (py * k - 1)..=((py + 1) * k) {
                for sx in (px * k - 1)..=((px + 1) * k) {
                    if let Some(i) = at(sx, sy) {
                        some |= coverage[i] > NONE;
                        all &= coverage[i] >= FULL;
                    }
                }
            }
            let p = (py * w + px) as usize;
            touched[p] = some;
            if !some {
                continue;
            }
            if !all {
                own[p] = true;
                continue;
            }
            let cells = || {
                (py * k..(py + 1) * k)
                    .flat_map(move |sy| (px * k..(px + 1) * k).map(move |sx| (sx, sy)))
            };
            let mean = cells()
                .map(|(sx, sy)| y[(sy * sw + sx) as usize])
                .sum::<f64>()
                / (k * k) as f64;
            own[p] = cells().any(|(sx, sy)| bend(sx, sy) > threshold * (mean + LIT_Y));
        }
    }
    let mut out = vec![false; own.len()];
    for py in 0..h {
        for px in 0..w {
            let p = (py * w + px) as usize;
            out[p] = touched[p]
                && (-1..=1).any(|dy| {
                    (-1..=1).any(|dx| {
                        let (x, y) = (px + dx, py + dy);
                        x >= 0 && y >= 0 && x < w && y < h && own[(y * w + x) as usize]
                    })
                });
        }
    }
    out
}

/// Render the tiles of `image` that hold a flagged pixel at `m x m`
/// positions per pixel and replace the flagged pixels with their box.
/// `state` is the frame's state (its camera the full image's); each tile is
/// one frame of `r`, alone (the progressive sum started again). The
/// replaced pixels whose positions are still [`unsettled`] at `threshold`
/// come back in [`Refined::unsettled`].
pub fn refine(
    gpu: &Gpu,
    r: &Renderer,
    state: &FrameState,
    image: &mut LinearImage,
    flags: &[bool],
    m: u32,
    threshold: f64,
) -> Result<Refined> {
    let (w, h) = (image.width, image.height);
    if flags.len() != (w * h) as usize {
        return Err(Error::internal(format!(
            "edge refinement: {} flags for a {w} x {h} frame",
            flags.len()
        )));
    }
    if !(1..=MAX_POSITIONS).contains(&m) {
        return Err(Error::usage(format!(
            "the edge refinement's positions per pixel side must be 1..{MAX_POSITIONS}, not {m}"
        )));
    }
    let tile = tile_pixels(m);
    let (tw, th) = (tile.min(w), tile.min(h));
    let mut done = Refined {
        pixels: 0,
        tiles: 0,
        unsettled: vec![false; flags.len()],
    };
    let mut target: Option<Offscreen> = None;
    for ty in (0..h).step_by(th as usize) {
        for tx in (0..w).step_by(tw as usize) {
            // the last row and column of tiles end at the image's edge
            let (x0, y0) = (tx.min(w - tw), ty.min(h - th));
            let flagged = |x: u32, y: u32| flags[(y * w + x) as usize];
            let any = (y0..y0 + th).any(|y| (x0..x0 + tw).any(|x| flagged(x, y)));
            if !any {
                continue;
            }
            if target.is_none() {
                target = Some(Offscreen::new(gpu, r, tw * m, th * m)?);
            }
            let t = target.as_mut().expect("made above");
            let st = FrameState {
                camera: state
                    .camera
                    .window(w, h, [x0 as f64, y0 as f64, tw as f64, th as f64]),
                sub_pixel: m,
                ..state.clone()
            };
            t.reset();
            let sub = t.render_frames_linear(gpu, r, &st, 1)?;
            let tile = sub.downsample(m);
            for y in y0..y0 + th {
                for x in x0..x0 + tw {
                    if flagged(x, y) {
                        let p = (y * w + x) as usize;
                        image.rgb[p] = tile.rgb[((y - y0) * tw + (x - x0)) as usize];
                        done.unsettled[p] =
                            unsettled(&sub, m, (x - x0) * m, (y - y0) * m, threshold);
                        done.pixels += 1;
                    }
                }
            }
            done.tiles += 1;
        }
    }
    Ok(done)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(w: u32, h: u32, f: impl Fn(u32, u32) -> f32) -> LinearImage {
        let mut im = LinearImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let v = f(x, y);
                im.rgb[(y * w + x) as usize] = [v, v, v];
            }
        }
        im
    }

    /// A gradient flags nothing, however steep; a step on the surface flags the
    /// pixels it crosses and their neighbours, whatever `k`; so does an
    /// outline, but not the background beyond its neighbours; a sub-pixel
    /// sheen flags its pixel and its neighbours.
    #[test]
    fn flags_follow_the_outline_and_the_light_that_bends() {
        let all = |im: &LinearImage| vec![1.0f32; im.rgb.len()];
        for k in [1u32, 4] {
            // 25 % of the mean a pixel along x
            let ramp = frame(16 * k, 8 * k, |x, y| {
                0.2 + (0.05 * x as f32 + 0.02 * y as f32) / k as f32
            });
            assert!(
                flag_pixels(&ramp, &all(&ramp), k, 0.05).iter().all(|&f| !f),
                "k {k}"
            );
            // a step inside pixel column 5 (k > 1) or between 5 and 6 (k = 1)
            let edge = if k == 1 { 6 } else { 5 * k + k / 2 };
            let step = frame(16 * k, 8 * k, |x, _| if x < edge { 0.02 } else { 0.5 });
            // k = 1: pixels 5 and 6 see the step, then their neighbours;
            // k = 4: pixel 5 holds it
            let want = |x: u32| {
                if k == 1 {
                    (4..=7).contains(&x)
                } else {
                    (4..=6).contains(&x)
                }
            };
            let f = flag_pixels(&step, &all(&step), k, 0.1);
            for y in 0..8 {
                for x in 0..16u32 {
                    assert_eq!(f[(y * 16 + x) as usize], want(x), "k {k} x {x} y {y}");
                }
            }
            // the same step as an outline: the mesh left of it, a textured
            // background right of it (flagged at the outline only)
            let bg = frame(16 * k, 8 * k, |x, y| {
                if x < edge {
                    0.2
                } else {
                    0.1 + 0.5 * ((x + y) % 2) as f32
                }
            });
            let cov: Vec<f32> = (0..bg.rgb.len())
                .map(|i| {
                    if (i as u32 % (16 * k)) < edge {
                        1.0
                    } else {
                        0.0
                    }
                })
                .collect();
            let f = flag_pixels(&bg, &cov, k, 0.1);
            for y in 0..8 {
                for x in 0..16u32 {
                    // pixels whose block touches the mesh: up to 6 (k = 1), 5 (k = 4)
                    let touched = if k == 1 { x <= 6 } else { x <= 5 };
                    assert_eq!(
                        f[(y * 16 + x) as usize],
                        want(x) && touched,
                        "outline k {k} x {x} y {y}"
                    );
                }
            }
        }
        let sheen = frame(32, 32, |x, y| if x == 17 && y == 9 { 4.0 } else { 0.1 });
        let f = flag_pixels(&sheen, &all(&sheen), 4, 0.1);
        let n = f.iter().filter(|&&b| b).count();
        // pixel (4, 2) holds the sheen (no other pixel's ring reaches it):
        // it and its eight neighbours
        assert!(f[2 * 8 + 4] && f[2 * 8 + 5] && n == 9, "{n}");
    }

    /// A block whose light is smooth at its positions is settled, however
    /// steep; a sheen on one row of positions (half the quarter-lattices
    /// see it) or a step between positions is not; odd `m` never is (no
    /// quarter-lattices); the block is found at its offset in a larger image.
    #[test]
    fn unsettled_where_the_quarter_lattices_disagree() {
        let m = 8;
        let at = |f: &dyn Fn(u32, u32) -> f32| frame(3 * m, 2 * m, f);
        // the block of pixel (1, 1): x 8..16, y 8..16
        let ramp = at(&|x, y| 0.2 + 0.01 * x as f32 + 0.02 * y as f32);
        assert!(!unsettled(&ramp, m, m, m, 0.05));
        let sheen = at(&|_, y| if y == m + 3 { 2.0 } else { 0.2 });
        assert!(unsettled(&sheen, m, m, m, 0.05));
        // the same sheen in another pixel's block leaves this one settled
        assert!(!unsettled(&sheen, m, m, 0, 0.05));
        // a step between two columns of positions: the lattices see it alike
        let step = at(&|x, _| if x < m + 4 { 0.1 } else { 0.5 });
        assert!(!unsettled(&step, m, m, m, 0.05));
        // a step that falls on every other column: they do not
        let comb = at(&|x, _| if x % 2 == 0 { 0.1 } else { 0.5 });
        assert!(unsettled(&comb, m, m, m, 0.05));
        assert!(!unsettled(&comb, 7, m, m, 0.05));
    }
}
