//! The rotation group SO(3) and unit quaternions.
//!
//! Convention (stated once, used everywhere): an attitude `Q ∈ SO(3)` maps body-frame vectors
//! to spatial vectors, and the kinematics are right-multiplied, `Q' = Q hat(w)` with `w` the
//! body angular velocity (paper eq. 39). `exp` and `log` are the group exponential and its
//! principal inverse; `hat(w) u = w × u`.
//!
//! Euler angles are ZYX (roll `phi`, pitch `theta`, yaw `psi`), `Q = Rz(psi) Ry(theta) Rx(phi)`
//! (paper eq. 21). Quaternions are `q = (q0, q1, q2, q3)`, scalar first, with the
//! Euler–Rodrigues map `E(q) = I + 2 q0 hat(qv) + 2 hat(qv)^2` (paper Appendix A).

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3, Vector4};

/// `hat(w)`: the skew matrix with `hat(w) u = w × u`.
#[inline]
pub fn hat(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// `vee(S)`: inverse of [`hat`] on the skew part, `vee(S) = ((S32 − S23), (S13 − S31), (S21 − S12)) / 2`.
#[inline]
pub fn vee(s: &Matrix3<f64>) -> Vector3<f64> {
    Vector3::new(
        0.5 * (s[(2, 1)] - s[(1, 2)]),
        0.5 * (s[(0, 2)] - s[(2, 0)]),
        0.5 * (s[(1, 0)] - s[(0, 1)]),
    )
}

/// The SO(3) exponential `exp(hat(w))` by the Rodrigues formula,
/// `I + sin|w|/|w| hat(w) + (1 − cos|w|)/|w|^2 hat(w)^2`.
///
/// The coefficients are evaluated in cancellation-free form (`1 − cos θ = 2 sin²(θ/2)`), and by
/// their Taylor series when `|w| < 1e-4`, so the result is accurate to round-off for tiny angles.
pub fn exp(w: &Vector3<f64>) -> Matrix3<f64> {
    let (a, b) = rodrigues_coefficients(w.norm());
    let k = hat(w);
    Matrix3::identity() + k * a + (k * k) * b
}

/// `(sin θ/θ, (1 − cos θ)/θ²)` with small-angle series.
#[inline]
fn rodrigues_coefficients(theta: f64) -> (f64, f64) {
    if theta < 1e-4 {
        let t2 = theta * theta;
        // Taylor series; next terms are O(θ^6) ≈ 1e-24, below round-off.
        (
            1.0 - t2 / 6.0 + t2 * t2 / 120.0,
            0.5 - t2 / 24.0 + t2 * t2 / 720.0,
        )
    } else {
        let s = (0.5 * theta).sin() / theta;
        (theta.sin() / theta, 2.0 * s * s)
    }
}

/// The principal SO(3) logarithm: `w` with `exp(w) = R` and `|w| ≤ π`.
///
/// The angle is `atan2(|vee(R − Rᵀ)|, (tr R − 1)/2)`, accurate at every angle (an `acos` of the
/// trace loses half the digits near 0 and π). Near π, where `R − Rᵀ` vanishes, the axis is read
/// from the symmetric part `(R + Rᵀ)/2 − cos θ I = (1 − cos θ) n nᵀ` whenever `θ > π/2`.
pub fn log(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = vee(r); // = sin θ n
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let theta = s.atan2(c);
    if theta < 1e-4 {
        // θ/sin θ = 1 + θ²/6 + 7θ⁴/360
        let t2 = theta * theta;
        return v * (1.0 + t2 / 6.0 + 7.0 * t2 * t2 / 360.0);
    }
    if c >= 0.0 {
        return v * (theta / s);
    }
    // θ > π/2: |v| = sin θ shrinks towards π, so read the axis from the symmetric part,
    // n nᵀ = (sym(R) − c I) / (1 − c); take the largest diagonal for the axis, then fix
    // its sign with the (small but reliable) skew part.
    let b = ((r + r.transpose()) * 0.5 - Matrix3::identity() * c) / (1.0 - c);
    let i = (0..3)
        .max_by(|&i, &j| b[(i, i)].total_cmp(&b[(j, j)]))
        .unwrap_or(0);
    let mut n: Vector3<f64> = b.column(i).into();
    n /= n.norm();
    if n.dot(&v) < 0.0 {
        n = -n;
    }
    n * theta
}

/// Elementary rotations about x, y, z.
fn rx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn ry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// `Q = Rz(psi) Ry(theta) Rx(phi)` from ZYX Euler angles `(phi, theta, psi)` (paper eq. 21).
pub fn from_euler_zyx(e: &Vector3<f64>) -> Matrix3<f64> {
    rz(e.z) * ry(e.y) * rx(e.x)
}

/// ZYX Euler angles `(phi, theta, psi)` of `Q` (paper eq. 21), with `theta ∈ [−π/2, π/2]`,
/// `phi, psi ∈ (−π, π]`.
///
/// Read directly from the entries of `Q`, so a matrix that is only nearly orthogonal (an explicit
/// Runge–Kutta attitude) still gets angles. The pitch uses `atan2` on `−Q31` against
/// `ρ = |(Q11, Q21)| = cos θ`, which stays accurate near ±π/2 where `asin` would not; the yaw is
/// `atan2(Q21, Q11)`; the roll is `atan2(Q32, Q33)` while `ρ ≥ |Q31|/2` (`|θ| ≤ 63°`). Beyond, `Q32 = cos θ sin φ`
/// and `Q33 = cos θ cos φ` shrink with `ρ` while their round-off does not, and the roll is read
/// from the second row of `Rz(ψ)ᵀ Q = Ry(θ) Rx(φ)`, `(0, cos φ, −sin φ)`, that is
/// `atan2(Q21 Q13 − Q11 Q23, Q11 Q22 − Q21 Q12)` (for a rotation these are the cofactors of
/// `Q32, Q33`): it keeps the roll consistent with whatever yaw the round-off of `(Q11, Q21)`
/// gives, and the angles rebuild `Q` to round-off at every pitch.
///
/// **Gimbal lock** (`ρ ≤ 4 ε`, the pitch within round-off of ±π/2): `Q` depends on `ψ ∓ φ`
/// only, and the direction of `(Q11, Q21)` is round-off. The roll is then set to 0 (scipy's
/// convention: the third angle of its `"ZYX"` sequence) and the yaw read from
/// `Rz(ψ) Ry(±π/2)`: `ψ = atan2(−Q12, Q22)`.
pub fn euler_zyx(q: &Matrix3<f64>) -> Vector3<f64> {
    let rho = (q[(0, 0)] * q[(0, 0)] + q[(1, 0)] * q[(1, 0)]).sqrt();
    euler_zyx_with(q, rho)
}

/// [`euler_zyx`] given `rho = |(Q11, Q21)|` (shared with `W` by [`euler_and_w`]).
/// `atan2` is musl's (the `libm` crate, within 1 ulp).
fn euler_zyx_with(q: &Matrix3<f64>, rho: f64) -> Vector3<f64> {
    let theta = libm::atan2(-q[(2, 0)], rho);
    let (q00, q10, q20) = (q[(0, 0)], q[(1, 0)], q[(2, 0)].abs());
    let psi = libm::atan2(q10, q00);
    if rho >= 0.5 * q20 {
        // |θ| ≤ 63°: Q32, Q33 are at least half of (sin φ, cos φ), as good as the cofactors.
        return Vector3::new(libm::atan2(q[(2, 1)], q[(2, 2)]), theta, psi);
    }
    if rho <= GIMBAL_LOCK * q20 {
        // gimbal lock: roll 0, the yaw from Rz(ψ) Ry(±π/2)
        return Vector3::new(0.0, theta, libm::atan2(-q[(0, 1)], q[(1, 1)]));
    }
    let phi = libm::atan2(
        q10 * q[(0, 2)] - q00 * q[(1, 2)],
        q00 * q[(1, 1)] - q10 * q[(0, 1)],
    );
    Vector3::new(phi, theta, psi)
}

/// `cos θ` at and below which [`euler_zyx`] treats the pitch as ±π/2 (gimbal lock): 4 ε, about
/// the round-off of the entries of a rotation built by a few products. Setting the roll to 0
/// there moves the rebuilt matrix by at most about `2ρ ≤ 8 ε`.
pub const GIMBAL_LOCK: f64 = 4.0 * f64::EPSILON;

/// The ZYX Euler angles of `q` and `W = Pi_e(theta)⁻¹ q` (the controller's map from body
/// angular velocity to Euler-angle rates), with the trigonometric functions of the angles
/// read off the entries of `q`: `cos ψ = Q11/ρ, sin ψ = Q21/ρ, ρ = |(Q11, Q21)|`,
/// `cos θ = ρ/r, sin θ = −Q31/r`, `r` = the norm of the first column. Rows of `W`, with `r_i` the rows of
/// `q`: `W_0 = sec θ (cos ψ r_0 + sin ψ r_1)`, `W_1 = cos ψ r_1 − sin ψ r_0`,
/// `W_2 = tan θ (cos ψ r_0 + sin ψ r_1) + r_2`.
pub fn euler_and_w(q: &Matrix3<f64>) -> (Vector3<f64>, Matrix3<f64>) {
    let (q00, q10, q20) = (q[(0, 0)], q[(1, 0)], q[(2, 0)]);
    let rho2 = q00 * q00 + q10 * q10;
    let rho = rho2.sqrt();
    let r = (rho2 + q20 * q20).sqrt();
    let inv = 1.0 / rho;
    let (cp, sp) = (q00 * inv, q10 * inv);
    let (tt, sec) = (-q20 * inv, r * inv);
    let (r0, r1, r2) = (q.row(0), q.row(1), q.row(2));
    let a = r0 * cp + r1 * sp;
    let mut w = Matrix3::zeros();
    w.set_row(0, &(a * sec));
    w.set_row(1, &(r1 * cp - r0 * sp));
    w.set_row(2, &(a * tt + r2));
    (euler_zyx_with(q, rho), w)
}

/// `Pi_e(theta)`: maps ZYX Euler-angle rates to the spatial angular velocity,
/// `Q w = Pi_e(theta) theta'` (paper §3; docs/model.md §2).
pub fn pi_e(e: &Vector3<f64>) -> Matrix3<f64> {
    let (st, ct) = e.y.sin_cos();
    let (sp, cp) = e.z.sin_cos();
    Matrix3::new(ct * cp, -sp, 0.0, ct * sp, cp, 0.0, -st, 0.0, 1.0)
}

/// `Pi_e(theta)^{-1}` in closed form (singular at `cos theta = 0`, the gimbal lock of ZYX angles).
pub fn pi_e_inv(e: &Vector3<f64>) -> Matrix3<f64> {
    let (st, ct) = e.y.sin_cos();
    let (sp, cp) = e.z.sin_cos();
    Matrix3::new(
        cp / ct,
        sp / ct,
        0.0,
        -sp,
        cp,
        0.0,
        cp * st / ct,
        sp * st / ct,
        1.0,
    )
}

/// Euler–Rodrigues map `E(q) = I + 2 q0 hat(qv) + 2 hat(qv)^2` for a unit quaternion
/// `q = (q0, qv)` (paper Appendix A).
pub fn rodrigues(q: &Vector4<f64>) -> Matrix3<f64> {
    let qv = Vector3::new(q[1], q[2], q[3]);
    let k = hat(&qv);
    Matrix3::identity() + k * (2.0 * q[0]) + (k * k) * 2.0
}

/// The unit quaternion `(q0, q1, q2, q3)` (scalar first) of a rotation matrix, with the sign
/// chosen so that `q0 ≥ 0`. A matrix further than 1e-10 from orthogonal is first projected to
/// the nearest rotation ([`orthonormalize`]); a rotation to round-off is converted as it is
/// (projection would only add round-off). A non-finite matrix gives NaNs.
pub fn quaternion(q: &Matrix3<f64>) -> Vector4<f64> {
    let defect = orthogonality_defect(q);
    let r = if defect.is_finite() && defect < 1e-10 {
        *q
    } else {
        orthonormalize(q)
    };
    if !r.iter().all(|v| v.is_finite()) {
        return Vector4::from_element(f64::NAN);
    }
    let uq = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let c = uq.quaternion().coords; // nalgebra stores (i, j, k, w)
    let mut out = Vector4::new(c[3], c[0], c[1], c[2]);
    if out[0] < 0.0 {
        out = -out;
    }
    out
}

/// Quaternion product `a ∘ b`, scalar first.
pub fn quat_mul(a: &Vector4<f64>, b: &Vector4<f64>) -> Vector4<f64> {
    let qa = Quaternion::new(a[0], a[1], a[2], a[3]);
    let qb = Quaternion::new(b[0], b[1], b[2], b[3]);
    let p = qa * qb;
    Vector4::new(p.w, p.i, p.j, p.k)
}

/// The nearest rotation to `q` in the Frobenius norm: the orthogonal polar factor `U Vᵀ` of the
/// SVD `q = U Σ Vᵀ`, with the sign of the smallest singular direction flipped when `det q < 0`
/// (Higham, *Functions of Matrices*, §8.1). Scale-invariant and finite-time for any input: a
/// non-finite matrix gives NaNs. (nalgebra's iterative `Rotation3::from_matrix_eps` does not
/// terminate on matrices of very large norm, such as a diverging Runge–Kutta attitude.)
pub fn orthonormalize(q: &Matrix3<f64>) -> Matrix3<f64> {
    let scale = q.amax();
    if !scale.is_finite() || scale == 0.0 {
        return Matrix3::from_element(f64::NAN);
    }
    let svd = (q / scale).svd(true, true);
    let (Some(mut u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Matrix3::from_element(f64::NAN);
    };
    if (u * v_t).determinant() < 0.0 {
        // nalgebra sorts singular values in decreasing order: flip the smallest direction.
        let i = (0..3)
            .min_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b]))
            .unwrap_or(2);
        let mut col = u.column_mut(i);
        col *= -1.0;
    }
    u * v_t
}

/// One Björck (Newton–Schulz) step towards the orthogonal polar factor,
/// `Q ← Q (3I − QᵀQ)/2` (Björck & Bowie, SIAM J. Numer. Anal. 8 (1971) 358–364). It leaves an
/// orthogonal matrix unchanged and squares a small defect `‖QᵀQ − I‖`, so applied after each
/// group update it keeps round-off from accumulating over millions of steps.
#[inline]
pub fn bjorck_step(q: &Matrix3<f64>) -> Matrix3<f64> {
    q * (Matrix3::identity() * 3.0 - q.transpose() * q) * 0.5
}

/// `‖QᵀQ − I‖_F`, the distance of `Q` from the orthogonal group.
pub fn orthogonality_defect(q: &Matrix3<f64>) -> f64 {
    (q.transpose() * q - Matrix3::identity()).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v3() -> impl Strategy<Value = Vector3<f64>> {
        (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0).prop_map(|(a, b, c)| Vector3::new(a, b, c))
    }

    #[test]
    fn hat_is_cross_product_and_vee_inverts_it() {
        let w = Vector3::new(0.3, -1.2, 2.5);
        let u = Vector3::new(-0.7, 0.1, 0.4);
        assert!((hat(&w) * u - w.cross(&u)).norm() < 1e-15);
        assert_eq!(vee(&hat(&w)), w);
    }

    #[test]
    fn exp_matches_nalgebra_axis_angle() {
        // nalgebra builds the rotation through a quaternion: an independent path.
        for w in [
            Vector3::new(0.3, -1.2, 2.5),
            Vector3::new(1e-9, 2e-9, -1e-9),
            Vector3::new(0.0, 0.0, 3.1),
        ] {
            let r = Rotation3::from_scaled_axis(w).into_inner();
            assert!((exp(&w) - r).norm() < 4e-16 * 9.0, "{w}");
        }
    }

    #[test]
    fn log_small_and_near_pi() {
        let w = Vector3::new(3e-9, -1e-9, 2e-9);
        assert!((log(&exp(&w)) - w).norm() < 1e-24);
        let n = Vector3::new(1.0, 2.0, -2.0) / 3.0;
        for th in [
            std::f64::consts::PI - 1e-9,
            std::f64::consts::PI - 2e-3,
            3.0,
        ] {
            let w = n * th;
            let back = log(&exp(&w));
            assert!((back - w).norm() < 1e-7, "{th}: {back} vs {w}");
            assert!((exp(&back) - exp(&w)).norm() < 1e-14);
        }
    }

    #[test]
    fn euler_roundtrip_and_pi_e() {
        let e = Vector3::new(0.05, -0.02, 0.10);
        let q = from_euler_zyx(&e);
        assert!((euler_zyx(&q) - e).norm() < 1e-15);
        // Pi_e maps Euler rates to the spatial angular velocity: check by finite differences of Q.
        let ed = Vector3::new(0.3, -0.2, 0.7);
        let dt = 1e-6;
        let qd = (from_euler_zyx(&(e + ed * dt)) - from_euler_zyx(&(e - ed * dt))) / (2.0 * dt);
        let omega_spatial = vee(&(qd * q.transpose()));
        assert!((pi_e(&e) * ed - omega_spatial).norm() < 1e-9);
        assert!((pi_e(&e) * pi_e_inv(&e) - Matrix3::identity()).norm() < 1e-15);
        // The trig-free W agrees, also for a matrix that is only nearly orthogonal.
        assert!((euler_and_w(&q).1 - pi_e_inv(&e) * q).norm() < 1e-15);
        let mut nq = q * 1.001;
        nq[(2, 0)] += 1e-4;
        assert!((euler_and_w(&nq).1 - pi_e_inv(&euler_zyx(&nq)) * nq).norm() < 1e-14);
        // The fused angles-and-W equals its parts, for rotations across the chart and the
        // nearly orthogonal matrix.
        for (i, m) in [
            q,
            nq,
            exp(&Vector3::new(1.2, -0.7, 2.9)),
            exp(&Vector3::new(-0.3, 1.1, -2.5)),
        ]
        .iter()
        .enumerate()
        {
            let (ang, w) = euler_and_w(m);
            assert!((ang - euler_zyx(m)).norm() < 1e-15, "case {i}");
            let want = pi_e_inv(&euler_zyx(m)) * m;
            assert!((w - want).norm() < 1e-14 * want.norm(), "case {i}");
        }
    }

    /// At gimbal lock the entries Q11, Q21, Q32, Q33 are round-off, and
    /// reading roll and yaw from them gave (0, 1.5708, −0.98279), which rebuilds a matrix 0.385
    /// away. The matrix is scipy's `Rotation.from_euler("ZYX", [−1.1, fl(π/2), 0.3])`, entry
    /// for entry (its round-off included); scipy returns (0, π/2, −1.4) for it.
    #[test]
    fn gimbal_lock_gets_its_own_branch_and_rebuilds_the_matrix() {
        let q = Matrix3::new(
            1.1102230246251565e-16,
            0.9854497299884601,
            0.16996714290024073,
            -1.6653345369377348e-16,
            0.1699671429002408,
            -0.98544972998846,
            -0.9999999999999998,
            0.0,
            2.7755575615628914e-16,
        );
        let e = euler_zyx(&q);
        assert_eq!(e.x, 0.0);
        assert!((e.y - std::f64::consts::FRAC_PI_2).abs() < 1e-15, "{e}");
        assert!((e.z + 1.4).abs() < 1e-15, "{e}");
        assert!(
            (from_euler_zyx(&e) - q).norm() < 1e-15,
            "{}",
            (from_euler_zyx(&e) - q).norm()
        );
        // Around it: both signs of the pitch, every roll and yaw, the matrices built here and
        // through quaternions, and pitches 1e-17 ... 1e-3 away from ±π/2.
        for sign in [1.0, -1.0] {
            for off in [0.0, 1e-17, 1e-15, 1e-13, 1e-10, 1e-7, 1e-3] {
                for (phi, psi) in [(0.3, -1.1), (-2.9, 3.0), (1.0, 1.0), (0.0, 0.5)] {
                    let th = sign * (std::f64::consts::FRAC_PI_2 - off);
                    let r = from_euler_zyx(&Vector3::new(phi, th, psi));
                    let via_quaternion = rodrigues(&quaternion(&r));
                    for m in [r, via_quaternion] {
                        let e = euler_zyx(&m);
                        let back = from_euler_zyx(&e);
                        assert!((back - m).norm() < 4e-15, "{sign} {off} {phi} {psi}: {e}");
                        assert!(e.y.abs() <= std::f64::consts::FRAC_PI_2);
                    }
                }
            }
        }
        // A pitch of exactly ±π/2 (entries 0, no round-off at all).
        let exact = Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0); // Ry(π/2)
        let e = euler_zyx(&exact);
        assert!((from_euler_zyx(&e) - exact).norm() < 1e-15, "{e}");
    }

    #[test]
    fn bjorck_step_squares_the_defect() {
        let r = exp(&Vector3::new(0.3, -0.2, 0.9));
        let noisy = r
            * (Matrix3::identity()
                + Matrix3::new(1e-7, 2e-7, 0.0, 0.0, -1e-7, 3e-7, 1e-7, 0.0, 2e-7));
        let d0 = orthogonality_defect(&noisy);
        let d1 = orthogonality_defect(&bjorck_step(&noisy));
        assert!(d0 > 1e-7 && d1 < 10.0 * d0 * d0 + 1e-15, "{d0} -> {d1}");
        assert!((bjorck_step(&r) - r).norm() < 1e-15);
    }

    #[test]
    fn projection_terminates_on_huge_and_non_finite_matrices() {
        let huge = Matrix3::new(
            1e200, 3e199, -2e200, 5e199, 1e200, 7e199, -1e199, 2e200, 9e199,
        );
        let r = orthonormalize(&huge);
        assert!(orthogonality_defect(&r) < 1e-14 && (r.determinant() - 1.0).abs() < 1e-14);
        assert!(quaternion(&huge).iter().all(|v| v.is_finite()));
        let mut bad = Matrix3::identity();
        bad[(0, 1)] = f64::INFINITY;
        assert!(quaternion(&bad).iter().all(|v| v.is_nan()));
        assert!(quaternion(&Matrix3::zeros()).iter().all(|v| v.is_nan()));
        // A reflection is mapped to a proper rotation.
        let refl = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0))
            * exp(&Vector3::new(0.1, 0.2, 0.3));
        assert!((orthonormalize(&refl).determinant() - 1.0).abs() < 1e-14);
    }

    proptest! {
        #[test]
        fn projection_is_the_nearest_rotation(w in v3().prop_map(|v| v * 3.0), e in proptest::array::uniform9(-1e-3f64..1e-3)) {
            let r = exp(&w);
            let noisy = r + Matrix3::from_column_slice(&e);
            let p = orthonormalize(&noisy);
            prop_assert!(orthogonality_defect(&p) < 1e-14);
            // The projection of a rotation is itself, and a perturbed one moves by O(noise).
            prop_assert!((orthonormalize(&r) - r).norm() < 1e-14);
            prop_assert!((p - r).norm() < 3e-3);
            // Nearest: no closer than the original rotation to the noisy matrix.
            prop_assert!((noisy - p).norm() <= (noisy - r).norm() + 1e-15);
        }

        #[test]
        fn exp_is_orthogonal_and_log_inverts(w in v3().prop_map(|v| v * 3.0)) {
            let r = exp(&w);
            prop_assert!(orthogonality_defect(&r) < 1e-14);
            prop_assert!((r.determinant() - 1.0).abs() < 1e-14);
            prop_assert!((exp(&log(&r)) - r).norm() < 1e-14);
            if w.norm() < 3.0 {
                prop_assert!((log(&r) - w).norm() < 1e-12);
            }
        }

        #[test]
        fn quaternion_and_matrix_paths_agree(w in v3().prop_map(|v| v * 3.0), u in v3().prop_map(|v| v * 3.0)) {
            let (ra, rb) = (exp(&w), exp(&u));
            let (qa, qb) = (quaternion(&ra), quaternion(&rb));
            prop_assert!((qa.norm() - 1.0).abs() < 1e-15 * 4.0);
            prop_assert!((rodrigues(&qa) - ra).norm() < 1e-14);
            // The product of quaternions represents the product of matrices.
            prop_assert!((rodrigues(&quat_mul(&qa, &qb)) - ra * rb).norm() < 1e-14);
        }

        #[test]
        fn euler_angles_roundtrip(phi in -3.0f64..3.0, th in -1.5f64..1.5, psi in -3.0f64..3.0) {
            let e = Vector3::new(phi, th, psi);
            prop_assert!((euler_zyx(&from_euler_zyx(&e)) - e).norm() < 1e-13);
        }

        #[test]
        fn euler_angles_rebuild_every_rotation(w in v3().prop_map(|v| v * 3.1)) {
            // Pinocchio-style round trip over all of SO(3), gimbal lock included.
            let r = exp(&w);
            let e = euler_zyx(&r);
            prop_assert!((from_euler_zyx(&e) - r).norm() < 4e-15);
            prop_assert!(e.y.abs() <= std::f64::consts::FRAC_PI_2 && e.x.abs() <= std::f64::consts::PI);
        }
    }
}
