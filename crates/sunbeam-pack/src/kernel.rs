//! Interpolation kernels (docs/PACK_FORMAT.md "Evaluation").
//!
//! Window model: the Kaiser-Bessel kernel of the non-uniform FFT, normalised so
//! that its Fourier transform is 1 at zero frequency:
//!
//! ```text
//! phi(x)    = beta / (W sinh beta) * I0(beta sqrt(1 - (2x/W)^2))   for |x| < W/2, else 0
//! phihat(nu)= beta sinh(sqrt(beta^2 - (pi W nu)^2)) / (sinh(beta) sqrt(beta^2 - (pi W nu)^2))
//! ```
//! (`phihat(nu) = int phi(x) exp(2 pi i x nu) dx`; for `pi W |nu| > beta` the sinh/sqrt becomes sin/sqrt.)
//!
//! Tiled model: `phi(d) = exp(-d^2 / (2 sigma^2))` in bins (the coherence Gaussian on the power).

/// Kaiser-Bessel beta for oversampling 2 (Beatty et al. 2005):
/// `beta = pi sqrt(W^2/4 (2 - 1/2)^2 - 0.8)`.
pub fn kb_beta(taps: usize) -> f64 {
    let w = taps as f64;
    std::f64::consts::PI * (w * w / 4.0 * 2.25 - 0.8).sqrt()
}

/// Modified Bessel function I0 by its power series `sum_k ((x/2)^2)^k / (k!)^2`
/// (all terms positive: no cancellation; stops when a term is below 1e-17 of the sum).
pub fn bessel_i0(x: f64) -> f64 {
    let q = x * x / 4.0;
    let mut term = 1.0;
    let mut sum = 1.0;
    let mut k = 1.0;
    while term > 1e-17 * sum && k < 500.0 {
        term *= q / (k * k);
        sum += term;
        k += 1.0;
    }
    sum
}

/// The normalised Kaiser-Bessel kernel at offset `x` (in bins).
pub fn kb(x: f64, taps: usize, beta: f64) -> f64 {
    let w = taps as f64;
    let r = 2.0 * x / w;
    if r.abs() >= 1.0 {
        return 0.0;
    }
    beta / (w * beta.sinh()) * bessel_i0(beta * (1.0 - r * r).sqrt())
}

/// `d kb / dx` at offset `x` (bins): what the amplitude's derivative along
/// the frequency needs (PHYSICS.md 2b). `d/dx I0(beta sqrt(1 - r^2)) =
/// -beta^2 (2 r / W) I1(z)/z` with `I1(z)/z = 1/2 sum_k (z^2/4)^k / (k! (k+1)!)`:
/// a series of positive terms, smooth up to the support's edge.
pub fn kb_derivative(x: f64, taps: usize, beta: f64) -> f64 {
    let w = taps as f64;
    let r = 2.0 * x / w;
    if r.abs() >= 1.0 {
        return 0.0;
    }
    let q = beta * beta * (1.0 - r * r) / 4.0;
    let (mut term, mut sum, mut k) = (1.0f64, 1.0f64, 1.0f64);
    while term > 1e-17 * sum && k < 500.0 {
        term *= q / (k * (k + 1.0));
        sum += term;
        k += 1.0;
    }
    -beta / (w * beta.sinh()) * beta * beta * (2.0 * r / w) * 0.5 * sum
}

/// Its Fourier transform at `nu` (cycles per bin), 1 at 0.
pub fn kb_hat(nu: f64, taps: usize, beta: f64) -> f64 {
    let w = taps as f64;
    let z = beta * beta - (std::f64::consts::PI * w * nu).powi(2);
    let v = if z > 0.0 {
        let r = z.sqrt();
        r.sinh() / r
    } else if z < 0.0 {
        let r = (-z).sqrt();
        r.sin() / r
    } else {
        1.0
    };
    beta * v / beta.sinh()
}

/// The tiled model's Gaussian in bins.
pub fn gauss(d: f64, sigma_bins: f64) -> f64 {
    (-d * d / (2.0 * sigma_bins * sigma_bins)).exp()
}

/// Taps per axis for the tiled model's Gaussian: `W = 2 (ceil(5 sigma) + 1)`, so that
/// the taps `floor(kappa) - W/2 + 1 .. floor(kappa) + W/2` reach at least 5 sigma on
/// both sides (weights beyond are below 4e-6); at most 64.
pub fn gauss_taps(sigma_bins: f64) -> usize {
    let half = (5.0 * sigma_bins).ceil().max(0.0) as usize + 1;
    (2 * half).min(64)
}

/// First tap `k0 = floor(kappa) - W/2 + 1` of a W-tap kernel at `kappa`.
#[inline]
pub fn first_tap(kappa: f64, taps: usize) -> i64 {
    kappa.floor() as i64 - taps as i64 / 2 + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kb_hat_is_the_transform_of_kb() {
        let taps = 6;
        let beta = kb_beta(taps);
        for &nu in &[0.0, 0.1, 0.25, 0.6, 0.9] {
            // Midpoint quadrature of int phi(x) cos(2 pi x nu) dx over [-W/2, W/2].
            let m = 200_000;
            let h = taps as f64 / m as f64;
            let mut s = 0.0;
            for i in 0..m {
                let x = -(taps as f64) / 2.0 + (i as f64 + 0.5) * h;
                s += kb(x, taps, beta) * (2.0 * std::f64::consts::PI * x * nu).cos();
            }
            s *= h;
            assert!(
                (s - kb_hat(nu, taps, beta)).abs() < 1e-7,
                "nu={nu}: {s} vs {}",
                kb_hat(nu, taps, beta)
            );
        }
        assert!((kb_hat(0.0, taps, beta) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn i0_known_values() {
        // Abramowitz & Stegun table 9.8: I0(1) = 1.266065878, I0(5) = 27.23987182, I0(10) = 2815.716628.
        assert!((bessel_i0(1.0) - 1.266_065_878).abs() < 1e-8);
        assert!((bessel_i0(5.0) / 27.239_871_82 - 1.0).abs() < 1e-8);
        assert!((bessel_i0(10.0) / 2_815.716_628 - 1.0).abs() < 1e-8);
    }

    /// The derivative against a central difference of the kernel itself.
    #[test]
    fn kb_derivative_matches_central_difference() {
        for taps in [4usize, 6, 8] {
            let beta = kb_beta(taps);
            for i in 0..40 {
                let x = -(taps as f64) / 2.0 + 0.05 + i as f64 * (taps as f64 - 0.1) / 40.0;
                let h = 1e-5;
                let fd = (kb(x + h, taps, beta) - kb(x - h, taps, beta)) / (2.0 * h);
                let d = kb_derivative(x, taps, beta);
                assert!(
                    (d - fd).abs() < 1e-7 * (1.0 + fd.abs()),
                    "{taps} {x}: {d} vs {fd}"
                );
            }
        }
    }
}
