//! The camera transform both renderers use (wgpu conventions): right-handed view
//! space looking down -z, clip depth in [0, 1], NDC y up, pixel (i, j) with j
//! counted from the top row and its centre at (i + 0.5, j + 0.5).
//!
//! The lens shift (`camera.shift`, Blender's convention) moves the image window
//! in the image plane by `shift` times the image's larger side: NDC
//! `(x, y)` of the unshifted projection become `(x - 2 sx m / w, y - 2 sy m / h)`,
//! `m = max(w, h)` (see [`Camera::shift_ndc`]).
//!
//! Near and far planes are not in the scene file: they are `0.01 d` and `100 d`
//! with `d` the eye-target distance, so both renderers clip identically.

use crate::Camera;

/// Column-major 4x4 matrix (`m[col][row]`), as WGSL's `mat4x4<f32>` expects.
pub type Mat4 = [[f64; 4]; 4];

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    if l > 0.0 {
        [a[0] / l, a[1] / l, a[2] / l]
    } else {
        a
    }
}

/// Matrix product `a * b` (column-major).
pub fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut o = [[0.0; 4]; 4];
    for (c, oc) in o.iter_mut().enumerate() {
        for (r, v) in oc.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    o
}

/// `m * (x, y, z, w)`.
pub fn transform(m: &Mat4, p: [f64; 4]) -> [f64; 4] {
    let mut o = [0.0; 4];
    for (r, v) in o.iter_mut().enumerate() {
        *v = (0..4).map(|k| m[k][r] * p[k]).sum();
    }
    o
}

impl Camera {
    /// Near and far clip distances (see the module doc).
    pub fn near_far(&self) -> (f64, f64) {
        let d = dot(sub(self.eye, self.target), sub(self.eye, self.target))
            .sqrt()
            .max(1e-9);
        (0.01 * d, 100.0 * d)
    }

    /// World -> view (right-handed, camera looks down -z).
    pub fn view(&self) -> Mat4 {
        let f = normalize(sub(self.target, self.eye));
        let mut up = normalize(self.up);
        if dot(f, up).abs() > 0.999_999 {
            // up parallel to the view direction: pick any perpendicular one
            up = if f[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            };
        }
        let s = normalize(cross(f, up));
        let u = cross(s, f);
        let e = self.eye;
        [
            [s[0], u[0], -f[0], 0.0],
            [s[1], u[1], -f[1], 0.0],
            [s[2], u[2], -f[2], 0.0],
            [-dot(s, e), -dot(u, e), dot(f, e), 1.0],
        ]
    }

    /// The lens shift in NDC for an image of aspect `w / h`: `(2 sx m / w,
    /// 2 sy m / h)` with `m = max(w, h)`, what the shift subtracts from the
    /// unshifted NDC of a point.
    pub fn shift_ndc(&self, aspect: f64) -> [f64; 2] {
        let [sx, sy] = self.shift;
        // m / w = max(1, 1 / aspect), m / h = max(aspect, 1)
        [
            2.0 * sx * (1.0 / aspect).max(1.0),
            2.0 * sy * aspect.max(1.0),
        ]
    }

    /// View -> clip, perspective, depth 0 at near and 1 at far, with the lens
    /// shift (an off-axis frustum).
    pub fn projection(&self, aspect: f64) -> Mat4 {
        let (n, fa) = self.near_far();
        let t = 1.0 / (self.fov_y_deg.to_radians() / 2.0).tan();
        // clip.xy -= shift_ndc * clip.w, clip.w = -z_view
        let [dx, dy] = self.shift_ndc(aspect);
        [
            [t / aspect, 0.0, 0.0, 0.0],
            [0.0, t, 0.0, 0.0],
            [dx, dy, fa / (n - fa), -1.0],
            [0.0, 0.0, n * fa / (n - fa), 0.0],
        ]
    }

    /// The view rays of a `width x height` image: `(o, rx, ry)` with the
    /// (unnormalised) world direction through NDC `(x, y)` equal to
    /// `o + x rx + y ry` (`o` the view direction, `rx`, `ry` the image's axes
    /// scaled by the projection; the inverse of [`Camera::view_proj`]).
    pub fn ray_basis(&self, width: u32, height: u32) -> ([f64; 3], [f64; 3], [f64; 3]) {
        let aspect = width.max(1) as f64 / height.max(1) as f64;
        let v = self.view();
        let t = 1.0 / (self.fov_y_deg.to_radians() / 2.0).tan();
        // rows of the view matrix: s, u, -f
        let s = [v[0][0], v[1][0], v[2][0]];
        let u = [v[0][1], v[1][1], v[2][1]];
        let f = [-v[0][2], -v[1][2], -v[2][2]];
        let (rx, ry) = (s.map(|c| c * aspect / t), u.map(|c| c / t));
        // NDC (x, y) of the shifted image is (x + dx, y + dy) of the unshifted one
        let [dx, dy] = self.shift_ndc(aspect);
        (
            std::array::from_fn(|k| f[k] + dx * rx[k] + dy * ry[k]),
            rx,
            ry,
        )
    }

    /// Unit world direction of the view ray through pixel position `(x, y)`
    /// (pixels, y down, `(i + 0.5, j + 0.5)` the centre of pixel `(i, j)`).
    pub fn ray(&self, width: u32, height: u32, x: f64, y: f64) -> [f64; 3] {
        let (o, rx, ry) = self.ray_basis(width, height);
        let nx = 2.0 * x / width.max(1) as f64 - 1.0;
        let ny = 1.0 - 2.0 * y / height.max(1) as f64;
        normalize(std::array::from_fn(|k| o[k] + nx * rx[k] + ny * ry[k]))
    }

    /// The camera whose image is the rectangle `[x0, x0 + w) x [y0, y0 + h)`
    /// (pixels, y down) of this camera's `width x height` image: the field of
    /// view narrowed to the rectangle's height and the lens shift moved to its
    /// centre. An image of aspect `w / h` from it, `m` times the rectangle's
    /// size, has each of the rectangle's pixels as `m x m` sub-pixels at
    /// exactly their places in the full image (what a tile of a supersampled
    /// frame is: the player's edge refinement renders tiles through it).
    pub fn window(&self, width: u32, height: u32, rect: [f64; 4]) -> Camera {
        let [x0, y0, w, h] = rect;
        let (fw, fh) = (width.max(1) as f64, height.max(1) as f64);
        let [dx, dy] = self.shift_ndc(fw / fh);
        // the rectangle's centre (shifted NDC) and half extent (NDC units)
        let (cx, cy) = (
            2.0 * (x0 + 0.5 * w) / fw - 1.0,
            1.0 - 2.0 * (y0 + 0.5 * h) / fh,
        );
        let (sx, sy) = (w / fw, h / fh);
        let half = (self.fov_y_deg.to_radians() / 2.0).tan() * sy;
        // the window's NDC is the full one's, centred on the rectangle and
        // scaled by 1 / (sx, sy): its shift in NDC is (dx + cx) / sx, ...
        let aspect = w / h;
        let (ndx, ndy) = ((dx + cx) / sx, (dy + cy) / sy);
        Camera {
            fov_y_deg: 2.0 * half.atan().to_degrees(),
            shift: [
                ndx / (2.0 * (1.0 / aspect).max(1.0)),
                ndy / (2.0 * aspect.max(1.0)),
            ],
            ..self.clone()
        }
    }

    /// World -> clip for an image of `width x height` pixels.
    pub fn view_proj(&self, width: u32, height: u32) -> Mat4 {
        let aspect = width.max(1) as f64 / height.max(1) as f64;
        mul(&self.projection(aspect), &self.view())
    }
}

/// Convert a column-major f64 matrix to the f32 layout a GPU uniform takes.
pub fn to_f32(m: &Mat4) -> [[f32; 4]; 4] {
    m.map(|c| c.map(|v| v as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_projects_to_centre_and_depth_is_in_range() {
        let cam = Camera {
            eye: [1.0, 2.0, 5.0],
            target: [0.5, -0.3, 0.2],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 40.0,
            shift: [0.0; 2],
        };
        let m = cam.view_proj(200, 100);
        let c = transform(&m, [0.5, -0.3, 0.2, 1.0]);
        assert!((c[0] / c[3]).abs() < 1e-12 && (c[1] / c[3]).abs() < 1e-12);
        let z = c[2] / c[3];
        assert!(z > 0.0 && z < 1.0);
        // a point up by tan(fov/2)*d on the view's up axis lands on the top edge
        let d = 5.0f64.hypot(0.0); // not used; check via the view matrix instead
        let _ = d;
        let v = cam.view();
        let e = transform(&v, [1.0, 2.0, 5.0, 1.0]);
        assert!(e[0].abs() < 1e-12 && e[1].abs() < 1e-12 && e[2].abs() < 1e-12);
    }

    /// A window's image is its rectangle of the full image, `m` sub-pixels
    /// per pixel: every point lands at `(p - (x0, y0)) m`, and the
    /// background's rays agree.
    #[test]
    fn a_window_is_its_rectangle_of_the_full_image() {
        for (w, h, shift) in [(200u32, 100u32, [0.0, 0.0]), (90, 160, [0.07, -0.11])] {
            let cam = Camera {
                eye: [0.3, 0.2, 4.0],
                target: [0.0, 0.0, 0.0],
                up: [0.1, 1.0, 0.0],
                fov_y_deg: 35.0,
                shift,
            };
            let px = |cam: &Camera, w: u32, h: u32, p: [f64; 4]| {
                let c = transform(&cam.view_proj(w, h), p);
                [
                    (c[0] / c[3] * 0.5 + 0.5) * w as f64,
                    (0.5 - c[1] / c[3] * 0.5) * h as f64,
                ]
            };
            for (rect, m) in [([10.0, 20.0, 8.0, 8.0], 16u32), ([33.0, 5.0, 12.0, 4.0], 5)] {
                let win = cam.window(w, h, rect);
                let (ww, wh) = ((rect[2] * m as f64) as u32, (rect[3] * m as f64) as u32);
                for p in [
                    [0.4, -0.25, 0.3, 1.0],
                    [-0.2, 0.5, -0.1, 1.0],
                    [0.0, 0.0, 0.0, 1.0],
                ] {
                    let a = px(&cam, w, h, p);
                    let b = px(&win, ww, wh, p);
                    for k in 0..2 {
                        let want = (a[k] - rect[k]) * m as f64;
                        assert!(
                            (b[k] - want).abs() < 1e-6 * m as f64,
                            "{a:?} {b:?} {rect:?}"
                        );
                    }
                }
                // the ray through a window pixel is the full image's ray there
                let (x, y) = (3.5, 1.5);
                let d = win.ray(ww, wh, x, y);
                let e = cam.ray(w, h, rect[0] + x / m as f64, rect[1] + y / m as f64);
                assert!(dot(d, e) > 1.0 - 1e-12, "{d:?} {e:?}");
            }
        }
    }

    /// The lens shift moves the image by `shift x max(w, h)` pixels (right,
    /// up), whatever the aspect; the view ray through a pixel goes back to
    /// the point that projects there.
    #[test]
    fn shift_moves_the_image_by_fractions_of_the_larger_side() {
        for (w, h) in [(200u32, 100u32), (90, 160)] {
            let mut cam = Camera {
                eye: [0.3, 0.2, 4.0],
                target: [0.0, 0.0, 0.0],
                up: [0.1, 1.0, 0.0],
                fov_y_deg: 35.0,
                shift: [0.0; 2],
            };
            let p = [0.4, -0.25, 0.3, 1.0];
            let px = |cam: &Camera| {
                let c = transform(&cam.view_proj(w, h), p);
                [
                    (c[0] / c[3] * 0.5 + 0.5) * w as f64,
                    (0.5 - c[1] / c[3] * 0.5) * h as f64,
                ]
            };
            let a = px(&cam);
            cam.shift = [0.125, -0.0625];
            let b = px(&cam);
            let m = w.max(h) as f64;
            // the window moves right and down: the point moves left and up
            assert!((a[0] - b[0] - 0.125 * m).abs() < 1e-9, "{a:?} {b:?}");
            assert!((a[1] - b[1] - 0.0625 * m).abs() < 1e-9, "{a:?} {b:?}");
            let d = cam.ray(w, h, b[0], b[1]);
            let e = normalize(sub([p[0], p[1], p[2]], cam.eye));
            assert!(dot(d, e) > 1.0 - 1e-12, "{d:?} {e:?}");
        }
    }
}
