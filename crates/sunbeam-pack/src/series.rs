//! The series `exp(i t s) = sum_n c_n(t) B_n(s)` (PHYSICS.md 3): the
//! coefficients `c_n(t)` exactly as the player computes them, Bessel functions
//! by Miller's backward recurrence, and the a-priori truncation bounds.

use crate::manifest::Basis;

/// Below this |t| the Bessel functions come from their leading power term
/// `J_n(t) = (t/2)^n / n!` (relative error below (t/2)^2 / (n+1) < 3e-9).
pub const SMALL_T: f64 = 1e-4;

/// Miller's starting order for orders `0..n_count` at argument `a = |t|`:
/// the even number `2 * ceil((max(n_count, a) + 16 + sqrt(40 max(n_count, a))) / 2)`.
pub fn miller_start(n_count: usize, a: f64) -> usize {
    let m = (n_count as f64).max(a);
    let start = m + 16.0 + (40.0 * m).sqrt();
    2 * ((start / 2.0).ceil() as usize)
}

macro_rules! bessel_impl {
    ($name:ident, $t:ty) => {
        /// `out[n] = J_n(t)` for `n = 0 .. out.len()-1`, by Miller's backward recurrence
        /// `J_{k-1} = (2k/a) J_k - J_{k+1}` from `J_{m+1} = 0, J_m = 1`, rescaled by 1e-10 whenever
        /// |J| exceeds 1e10, normalised with `J_0 + 2 sum_{k>=1} J_{2k} = 1`; `J_n(-t) = (-1)^n J_n(t)`.
        pub fn $name(t: $t, out: &mut [$t]) {
            let nc = out.len();
            if nc == 0 {
                return;
            }
            let a = t.abs();
            if !(a.is_finite()) {
                out.iter_mut().for_each(|v| *v = 0.0);
                return;
            }
            if (a as f64) < SMALL_T {
                // Leading term of the power series.
                let half = t / 2.0;
                let mut term: $t = 1.0;
                for (n, o) in out.iter_mut().enumerate() {
                    if n > 0 {
                        term = term * half / (n as $t);
                    }
                    *o = term;
                }
                return;
            }
            out.iter_mut().for_each(|v| *v = 0.0);
            let m = miller_start(nc, a as f64);
            let mut jp1: $t = 0.0; // J_{k+1}
            let mut j: $t = 1.0; // J_k, k = m
            let mut sum: $t = if m % 2 == 0 { 2.0 * j } else { 0.0 };
            let mut k = m;
            while k >= 1 {
                let jm1 = (2.0 * k as $t / a) * j - jp1; // J_{k-1}
                let n = k - 1;
                if n < nc {
                    out[n] = jm1;
                }
                if n == 0 {
                    sum += jm1;
                } else if n % 2 == 0 {
                    sum += 2.0 * jm1;
                }
                jp1 = j;
                j = jm1;
                if j.abs() > 1e10 {
                    j *= 1e-10;
                    jp1 *= 1e-10;
                    sum *= 1e-10;
                    for o in out.iter_mut().skip(n) {
                        *o *= 1e-10;
                    }
                }
                k -= 1;
            }
            let inv = 1.0 / sum;
            for (n, o) in out.iter_mut().enumerate() {
                *o *= inv;
                if t < 0.0 && n % 2 == 1 {
                    *o = -*o;
                }
            }
        }
    };
}

bessel_impl!(bessel_j_f64, f64);
bessel_impl!(bessel_j_f32, f32);

/// The series coefficients `c_n(t)` as (re, im), f64.
///
/// Chebyshev: `c_n = i^n eps_n J_n(t)` (eps_0 = 1, eps_n = 2).
/// Taylor: `c_0 = 1, c_n = c_{n-1} (i t) / n`.
pub fn coefficients_f64(basis: Basis, t: f64, n: usize) -> Vec<[f64; 2]> {
    let mut out = vec![[0.0; 2]; n];
    match basis {
        Basis::Chebyshev => {
            let mut j = vec![0.0; n];
            bessel_j_f64(t, &mut j);
            for (k, o) in out.iter_mut().enumerate() {
                let e = if k == 0 { 1.0 } else { 2.0 } * j[k];
                *o = match k % 4 {
                    0 => [e, 0.0],
                    1 => [0.0, e],
                    2 => [-e, 0.0],
                    _ => [0.0, -e],
                };
            }
        }
        Basis::Taylor => {
            let mut c = [1.0, 0.0];
            for (k, o) in out.iter_mut().enumerate() {
                if k > 0 {
                    // c * (i t / k)
                    let s = t / k as f64;
                    c = [-c[1] * s, c[0] * s];
                }
                *o = c;
            }
        }
    }
    out
}

/// The same in float32 (what a shader computes).
pub fn coefficients_f32(basis: Basis, t: f32, n: usize) -> Vec<[f32; 2]> {
    let mut out = vec![[0.0f32; 2]; n];
    match basis {
        Basis::Chebyshev => {
            let mut j = vec![0.0f32; n];
            bessel_j_f32(t, &mut j);
            for (k, o) in out.iter_mut().enumerate() {
                let e = if k == 0 { 1.0 } else { 2.0 } * j[k];
                *o = match k % 4 {
                    0 => [e, 0.0],
                    1 => [0.0, e],
                    2 => [-e, 0.0],
                    _ => [0.0, -e],
                };
            }
        }
        Basis::Taylor => {
            let mut c = [1.0f32, 0.0];
            for (k, o) in out.iter_mut().enumerate() {
                if k > 0 {
                    let s = t / k as f32;
                    c = [-c[1] * s, c[0] * s];
                }
                *o = c;
            }
        }
    }
    out
}

/// `2 sum_{n >= n_terms} |c_n(t)|` (bound on |dR| from keeping terms 0..n_terms-1,
/// since |B_n(s)| <= 1 and |F_n| <= 1).
pub fn tail_bound(basis: Basis, t: f64, n_terms: usize) -> f64 {
    let a = t.abs();
    match basis {
        Basis::Chebyshev => {
            let upto = n_terms.max(a.ceil() as usize) + 60;
            let mut j = vec![0.0; upto];
            bessel_j_f64(a, &mut j);
            let s: f64 = (n_terms..upto)
                .map(|n| if n == 0 { 1.0 } else { 2.0 } * j[n].abs())
                .sum();
            2.0 * s
        }
        Basis::Taylor => {
            // |t|^n / n! summed from n_terms on, in logs to avoid overflow.
            let mut s = 0.0;
            let mut log_term = 0.0f64; // log(|t|^n / n!)
            let upto = n_terms.max(a.ceil() as usize) * 2 + 60;
            for n in 0..upto {
                if n > 0 {
                    log_term += a.ln() - (n as f64).ln();
                }
                if n >= n_terms {
                    s += log_term.exp();
                }
            }
            if a == 0.0 {
                s = if n_terms == 0 { 1.0 } else { 0.0 };
            }
            2.0 * s
        }
    }
}

/// The bound over all `|t| <= t_max` (sampled densely, plus t_max itself).
pub fn tail_bound_upto(basis: Basis, t_max: f64, n_terms: usize) -> f64 {
    let a = t_max.abs();
    let steps = 64;
    (0..=steps)
        .map(|i| tail_bound(basis, a * i as f64 / steps as f64, n_terms))
        .fold(0.0, f64::max)
}

/// Smallest term count whose bound over `|t| <= t_max` is below `tol`.
pub fn terms_for_tolerance(basis: Basis, t_max: f64, tol: f64) -> usize {
    let mut n = 1;
    while n < 4096 {
        if tail_bound_upto(basis, t_max, n) < tol {
            return n;
        }
        n += 1;
    }
    n
}

/// Estimate of the float32 rounding error of the series sum in a shader:
/// `2 * 2^-24 * max_t sum_n |c_n(t)|` (the largest magnitudes that must cancel).
pub fn f32_rounding_estimate(basis: Basis, t_max: f64, n_terms: usize) -> f64 {
    let a = t_max.abs();
    let steps = 16;
    let mut worst: f64 = 0.0;
    for i in 0..=steps {
        let t = a * i as f64 / steps as f64;
        let c = coefficients_f64(basis, t, n_terms);
        let s: f64 = c.iter().map(|v| v[0].abs() + v[1].abs()).sum();
        worst = worst.max(s);
    }
    2.0 * worst * (2.0f64).powi(-24)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// J_n(t) from its integral (1/pi) int_0^pi cos(n tau - t sin tau) d tau (trapezoid, exact for
    /// periodic integrands with enough points): independent of the recurrence.
    fn bessel_quad(n: usize, t: f64) -> f64 {
        let m = 4096;
        let mut s = 0.0;
        for k in 0..m {
            let tau = std::f64::consts::PI * 2.0 * (k as f64 + 0.5) / m as f64;
            s += (n as f64 * tau - t * tau.sin()).cos();
        }
        s / m as f64
    }

    #[test]
    fn miller_matches_integral_f64_and_f32() {
        for &t in &[1e-6f64, 1e-3, 0.1, 1.0, 5.0, 9.0, 16.5, 30.0, 60.0, -7.3] {
            let n = (t.abs() as usize) + 30;
            let mut j = vec![0.0; n];
            bessel_j_f64(t, &mut j);
            let mut j32 = vec![0.0f32; n];
            bessel_j_f32(t as f32, &mut j32);
            for k in 0..n {
                let q = bessel_quad(k, t);
                assert!((j[k] - q).abs() < 1e-12, "J_{k}({t}) = {} vs {q}", j[k]);
                let tol32 = if t.abs() <= 30.0 { 2e-7 } else { 1e-6 };
                assert!(
                    (j32[k] as f64 - q).abs() < tol32,
                    "f32 J_{k}({t}) = {} vs {q}",
                    j32[k]
                );
            }
        }
    }

    #[test]
    fn jacobi_anger_sums_to_exponential() {
        for &t in &[0.5, 9.0, -12.0] {
            let n = terms_for_tolerance(Basis::Chebyshev, t, 1e-12);
            let c = coefficients_f64(Basis::Chebyshev, t, n);
            for &s in &[-1.0, -0.3, 0.0, 0.77, 1.0] {
                let (mut tp, mut tc) = (1.0, s);
                let mut acc = [0.0, 0.0];
                for (k, ck) in c.iter().enumerate() {
                    let tk = if k == 0 {
                        1.0
                    } else if k == 1 {
                        s
                    } else {
                        let tn = 2.0 * s * tc - tp;
                        tp = tc;
                        tc = tn;
                        tn
                    };
                    acc[0] += ck[0] * tk;
                    acc[1] += ck[1] * tk;
                }
                let (re, im) = ((t * s).cos(), (t * s).sin());
                assert!(
                    (acc[0] - re).abs() < 1e-11 && (acc[1] - im).abs() < 1e-11,
                    "t={t} s={s}"
                );
            }
        }
    }

    #[test]
    fn term_counts_match_physics_md() {
        // PHYSICS.md 3: Chebyshev about |t| + 3.2 |t|^(1/3) + 2 (16 at t = 9, 29 at 16.5); Taylor ~ e|t|.
        let c9 = terms_for_tolerance(Basis::Chebyshev, 9.0, 1e-4);
        let c16 = terms_for_tolerance(Basis::Chebyshev, 16.5, 1e-4);
        assert!((15..=19).contains(&c9), "{c9}");
        assert!((27..=32).contains(&c16), "{c16}");
        let t9 = terms_for_tolerance(Basis::Taylor, 9.0, 1e-4);
        assert!((29..=37).contains(&t9), "{t9}");
    }
}
