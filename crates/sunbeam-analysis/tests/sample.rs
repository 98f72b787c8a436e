//! `sample::scatter_points`: every point is `-(wi + wr)` of two unit vectors
//! inside the cone, within the `|w|` bound and the wavelength range; the seed
//! fixes the sequence; the rejection of `|w| > max_w` does not change how many
//! points come back.

use sunbeam_analysis::sample::scatter_points;

#[test]
fn scatter_points_stay_in_their_domain() {
    let (n, min_cos, lambda) = (2000, 0.05, (380e-9, 780e-9));
    for max_w in [f64::INFINITY, 1.2] {
        let pts = scatter_points(n, 7, min_cos, max_w, lambda);
        assert_eq!(pts.len(), n);
        for p in &pts {
            let [u, v, w, l] = *p;
            // wi_z + wr_z in [2 min_cos, 2], so w in [-2, -2 min_cos].
            assert!((-2.0..=-2.0 * min_cos + 1e-12).contains(&w), "w {w}");
            assert!(w.abs() <= max_w, "w {w} beyond {max_w}");
            // |wi + wr| <= 2.
            assert!(u * u + v * v + w * w <= 4.0 + 1e-12, "{p:?}");
            assert!((lambda.0..lambda.1).contains(&l), "lambda {l}");
        }
        if max_w.is_finite() {
            assert!(pts.iter().any(|p| p[2].abs() > 1.0), "bound reached");
        } else {
            // Unbounded: some points need |w| > 1.2 (both directions steep).
            assert!(pts.iter().any(|p| p[2].abs() > 1.2));
        }
    }
    assert_eq!(
        scatter_points(50, 3, min_cos, 1.5, lambda),
        scatter_points(50, 3, min_cos, 1.5, lambda)
    );
    assert_ne!(
        scatter_points(50, 3, min_cos, 1.5, lambda),
        scatter_points(50, 4, min_cos, 1.5, lambda)
    );
}
