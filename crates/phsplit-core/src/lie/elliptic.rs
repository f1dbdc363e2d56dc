//! Jacobi elliptic functions and elliptic integrals of the first kind, parameter convention
//! `m = k²`.
//!
//! * `K(m)` and Carlson's `R_F` come from the `ellip` crate (maintained, Boost-derived, tested
//!   against high-precision values); `F(φ | m)` is assembled here from `R_F` in a form that stays
//!   accurate as `m → 1` (see [`ellipf`]).
//! * `sn, cn, dn` are written here: no maintained Rust crate provides them. They use the
//!   arithmetic–geometric mean / descending Landen scheme (DLMF §22.20(ii); Abramowitz & Stegun
//!   16.4), with the exact limits `m = 0` (sin, cos, 1) and `m = 1` (tanh, sech, sech), and the
//!   first-order expansion about `m = 1` (DLMF 22.10(ii)) where the AGM loses digits.
//!   `dn` is taken as `sqrt(m₁ + m cn²)` with `m₁ = 1 − m`, a sum of non-negative terms that keeps
//!   full relative accuracy as `m → 1`, where `sqrt(1 − m sn²)` would cancel.
//!
//! Accuracy against mpmath over `m ∈ [0, 1]` and `|u| ≤ 50` is checked by
//! `tests/elliptic_mpmath.rs` on the table written by `scripts/gen_elliptic_refs.py`.

use crate::error::Error;

/// Complete elliptic integral of the first kind `K(m)`, `m ≤ 1` (`K(1) = ∞`).
pub fn ellipk(m: f64) -> Result<f64, Error> {
    if m == 1.0 {
        return Ok(f64::INFINITY);
    }
    ellip::ellipk(m).map_err(|e| Error::Domain(format!("K(m) at m = {m}: {e}")))
}

/// Incomplete elliptic integral of the first kind `F(φ | m) = ∫₀^φ dθ / sqrt(1 − m sin²θ)`,
/// `m ≤ 1`.
///
/// Defined for every real `φ` when `m < 1`; for `m = 1` only for `|φ| < π/2`. With
/// `φ = r + jπ`, `|r| ≤ π/2`: `F(φ | m) = 2jK(m) + sin r · R_F(cos²r, cos²r + m₁ sin²r, 1)`
/// (DLMF 19.25.5 and 19.2.10), `m₁ = 1 − m`. The second argument is written as a sum of
/// non-negative terms rather than `1 − m sin²r`: near `m → 1, r → π/2` the difference form
/// (used by `ellip::ellipf`) loses up to five digits.
pub fn ellipf(phi: f64, m: f64) -> Result<f64, Error> {
    use std::f64::consts::{FRAC_PI_2, PI};
    if !phi.is_finite() || !(m <= 1.0) {
        return Err(Error::Domain(format!(
            "F(φ|m) needs a finite φ and m ≤ 1, got φ = {phi}, m = {m}"
        )));
    }
    if m == 1.0 && phi.abs() >= FRAC_PI_2 {
        return Err(Error::Domain(format!(
            "F(φ|1) is infinite for |φ| ≥ π/2, got φ = {phi}"
        )));
    }
    let j = (phi / PI).round();
    let r = phi - j * PI;
    let (s, c) = r.sin_cos();
    let m1 = 1.0 - m;
    let rf = ellip::elliprf(c * c, c * c + m1 * s * s, 1.0)
        .map_err(|e| Error::Domain(format!("R_F in F(φ|m) at φ = {phi}, m = {m}: {e}")))?;
    let base = s * rf;
    Ok(if j == 0.0 {
        base
    } else {
        base + 2.0 * j * ellipk(m)?
    })
}

/// Jacobi elliptic functions `(sn, cn, dn)(u | m)` for `0 ≤ m ≤ 1`.
///
/// Returns NaNs for `m` outside `[0, 1]` or a non-finite `u` (use [`try_jacobi`] for an error).
pub fn jacobi(u: f64, m: f64) -> (f64, f64, f64) {
    try_jacobi(u, m).unwrap_or((f64::NAN, f64::NAN, f64::NAN))
}

/// [`jacobi`] with an error naming the argument out of range.
pub fn try_jacobi(u: f64, m: f64) -> Result<(f64, f64, f64), Error> {
    if !(0.0..=1.0).contains(&m) {
        return Err(Error::Domain(format!(
            "Jacobi elliptic functions need 0 ≤ m ≤ 1, got m = {m}"
        )));
    }
    if !u.is_finite() {
        return Err(Error::Domain(format!(
            "Jacobi elliptic functions need a finite argument, got u = {u}"
        )));
    }
    if m == 0.0 {
        let (s, c) = u.sin_cos();
        return Ok((s, c, 1.0));
    }
    let m1 = 1.0 - m;
    if m1 == 0.0 {
        let sech = 1.0 / u.cosh();
        return Ok((u.tanh(), sech, sech));
    }
    if m1 < 1e-3 {
        return Ok(jacobi_ascending(u, m1));
    }
    Ok(jacobi_agm(u, m, m1))
}

/// Next to `m = 1` the AGM's back-substitution takes `asin` of arguments next to 1 and loses
/// digits. There the ascending Landen transformation (DLMF 22.7(ii)) is used instead: with
/// `k = √m` it maps `(u, k)` to `(u / (1 + k₂'), k₂)`, `k₂' = (1 − k)/(1 + k) = m₁/(1 + k)²`, so that
/// the complementary parameter is squared (over 16) at each level, until the first-order
/// expansion about `m = 1` (DLMF 22.10.4–6) is exact to round-off (`m₁ cosh²u < 1e-8`, its
/// neglected term being `O((m₁ cosh²u)²)`). Then, going back up,
/// `sn = (1 + k₂') sn₂ cn₂ / dn₂`, `cn = (1 + k₂')/k₂² (dn₂² − k₂')/dn₂`,
/// `dn = (1 − k₂')/k₂² (dn₂² + k₂')/dn₂`.
fn jacobi_ascending(u: f64, m1: f64) -> (f64, f64, f64) {
    let mut kp = [0.0f64; 12];
    let mut levels = 0;
    let (mut u, mut m1) = (u, m1);
    loop {
        let ch = u.abs().cosh();
        if m1 * ch * ch < 1e-8 || m1 == 0.0 || levels == kp.len() {
            break;
        }
        let k = (1.0 - m1).sqrt();
        let k2p = m1 / ((1.0 + k) * (1.0 + k));
        kp[levels] = k2p;
        levels += 1;
        u /= 1.0 + k2p;
        m1 = k2p * k2p;
    }
    let (mut sn, mut cn, mut dn) = jacobi_near_one(u, m1);
    for &k2p in kp[..levels].iter().rev() {
        let k2sq = (1.0 - k2p) * (1.0 + k2p);
        let d2 = dn * dn;
        let (s1, c1, d1) = (
            (1.0 + k2p) * sn * cn / dn,
            (1.0 + k2p) / k2sq * (d2 - k2p) / dn,
            (1.0 - k2p) / k2sq * (d2 + k2p) / dn,
        );
        sn = s1;
        cn = c1;
        dn = d1;
    }
    (sn, cn, dn)
}

/// DLMF 22.10.4–6 in cancellation-free form, `t = tanh u`, `s = sech u`:
/// `sn = t + m₁/4 (t − u s²)`, `cn = s − m₁/4 t (sinh u − u s)`, `dn = s + m₁/4 t (sinh u + u s)`.
fn jacobi_near_one(u: f64, m1: f64) -> (f64, f64, f64) {
    let t = u.tanh();
    let s = 1.0 / u.cosh();
    let sh = u.sinh();
    let q = 0.25 * m1;
    (
        t + q * (t - u * s * s),
        s - q * t * (sh - u * s),
        s + q * t * (sh + u * s),
    )
}

/// The AGM (descending Landen) scheme of DLMF 22.20(ii):
/// `a₀ = 1, b₀ = √m₁, c₀ = √m`; `a_{n+1} = (aₙ + bₙ)/2, b_{n+1} = √(aₙ bₙ), c_{n+1} = (aₙ − bₙ)/2`
/// until `c_N` is negligible; then `φ_N = 2^N a_N u` and
/// `φ_{n−1} = (φₙ + asin((cₙ/aₙ) sin φₙ))/2`, and `sn = sin φ₀`, `cn = cos φ₀`.
fn jacobi_agm(u: f64, m: f64, m1: f64) -> (f64, f64, f64) {
    const NMAX: usize = 16; // quadratic convergence: m₁ down to 1e-300 needs about 12 steps
    let mut a = [0.0f64; NMAX + 1];
    let mut c = [0.0f64; NMAX + 1];
    a[0] = 1.0;
    let mut b = m1.sqrt();
    c[0] = m.sqrt();
    let mut n = 0;
    while n < NMAX {
        let an = a[n];
        a[n + 1] = 0.5 * (an + b);
        c[n + 1] = 0.5 * (an - b);
        b = (an * b).sqrt();
        n += 1;
        if c[n].abs() <= f64::EPSILON * a[n] {
            break;
        }
    }
    let mut phi = (1u64 << n) as f64 * a[n] * u;
    for j in (1..=n).rev() {
        let y = c[j] / a[j] * phi.sin();
        // asin y = y + y³/6 + …: below 1e-6 the cubic term (< 2e-19) is beneath the last bit
        // of φ, and the call is skipped (the last one or two levels of a quadratically
        // converging AGM).
        let asin_y = if y.abs() < 1e-6 { y } else { y.asin() };
        phi = 0.5 * (phi + asin_y);
    }
    let (sn, cn) = phi.sin_cos();
    let dn = (m1 + m * cn * cn).sqrt();
    (sn, cn, dn)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn limits_and_special_values() {
        let (s, c, d) = jacobi(0.7, 0.0);
        assert_eq!((s, c, d), (0.7f64.sin(), 0.7f64.cos(), 1.0));
        let (s, c, d) = jacobi(0.7, 1.0);
        assert_eq!(
            (s, c, d),
            (0.7f64.tanh(), 1.0 / 0.7f64.cosh(), 1.0 / 0.7f64.cosh())
        );
        // sn(K) = 1, cn(K) = 0, dn(K) = sqrt(1 − m).
        for m in [0.1, 0.5, 0.9, 0.999_999] {
            let k = ellipk(m).unwrap();
            let (s, c, d) = jacobi(k, m);
            assert!((s - 1.0).abs() < 4e-16, "m={m} sn(K)={s}");
            assert!(c.abs() < 4e-15 * k, "m={m} cn(K)={c}");
            assert!((d - (1.0 - m).sqrt()).abs() < 1e-14 * (1.0 - m).sqrt() + 1e-16 * k);
            // F inverts am: F(am(u), m) = u.
            let u = 0.37 * k;
            let (s, c, _) = jacobi(u, m);
            let back = ellipf(s.atan2(c), m).unwrap();
            assert!((back - u).abs() < 4e-16 * k, "m={m}: F(am u)={back}, u={u}");
        }
        assert!(try_jacobi(1.0, 1.5).is_err());
        assert!(try_jacobi(f64::NAN, 0.5).is_err());
        assert_eq!(ellipk(1.0).unwrap(), f64::INFINITY);
    }

    proptest! {
        #[test]
        fn identities_hold(u in -30.0f64..30.0, m in 0.0f64..1.0) {
            let (s, c, d) = jacobi(u, m);
            prop_assert!((s * s + c * c - 1.0).abs() < 1e-15 * 4.0);
            prop_assert!((d * d + m * s * s - 1.0).abs() < 1e-15 * 4.0);
            // d/du sn = cn dn, by a centred difference.
            let e = 1e-5;
            let ds = (jacobi(u + e, m).0 - jacobi(u - e, m).0) / (2.0 * e);
            prop_assert!((ds - c * d).abs() < 1e-8);
        }
    }
}
