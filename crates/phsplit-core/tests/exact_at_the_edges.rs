//! Exact at the edges of the domain: Jacobi's elliptic functions at large arguments next to
//! m = 1, the free rigid body's momentum next to the middle (unstable) axis, and the Euler
//! angles at gimbal lock, at the inputs where each once failed and around them, through the
//! public API only.
//!
//! References: mpmath (50 digits for the elliptic functions; its ODE solver at 30 digits for the
//! rigid body, agreeing with the closed form at 50 digits to 1e-31), and scipy's answer at gimbal
//! lock. The wider reference tests are `elliptic_reference.rs` and `rigid_body_reference.rs`.
use nalgebra::{Matrix3, Vector3};
use phsplit_core::flows::rigid_body::FreeRigidBody;
use phsplit_core::lie::elliptic::jacobi;
use phsplit_core::lie::so3::{euler_zyx, from_euler_zyx};

const EPS: f64 = f64::EPSILON;

/// sn, cn, dn for large |u| next to m = 1 (the branch used when 1 − m < 1e-3).
#[test]
fn jacobi_functions_at_large_arguments_next_to_m_equal_one() {
    // (u, m, mpmath's (sn, cn, dn))
    let cases: [(f64, f64, [f64; 3]); 4] = [
        // was (−1.00025, 1.23e39, 1.23e39)
        (
            709.0,
            0.9990000000000001,
            [
                -0.9757020098565539,
                -0.21910177535082018,
                0.2212636038166225,
            ],
        ),
        // u = fl(101 K): sn was −1.0000250017 (|sn| > 1)
        (
            605.1505233912122,
            0.9999,
            [1.0, -3.4965345357560577e-16, 0.009999999999999449],
        ),
        // sn error was 8.9e-8
        (
            375.0,
            0.9999,
            [
                -0.9982789455314796,
                -0.05864424019933449,
                0.05948783904182747,
            ],
        ),
        // sn error was 1.2e-6
        (
            625.0,
            0.9999999999999999,
            [
                -0.9999987685408324,
                0.0015693682865438497,
                0.0015693682865792213,
            ],
        ),
    ];
    for (u, m, want) in cases {
        let (s, c, d) = jacobi(u, m);
        for (g, w) in [s, c, d].into_iter().zip(want) {
            // the bound: 8 ulp, or 4 ε |u| where the argument reduction limits it
            assert!(
                (g - w).abs() <= (8.0 * EPS * w.abs()).max(4.0 * EPS * u.abs()),
                "({u}, {m}): ({s}, {c}, {d}) vs {want:?}"
            );
        }
    }
    // From |u| ≈ 711 (up to 1e15) every m in (1 − 1e-3, 1) gave NaN.
    for m in [
        0.9990000000000001,
        0.9995,
        0.9999,
        1.0 - 1e-6,
        1.0 - 1e-12,
        1.0 - 2f64.powi(-53),
    ] {
        for u in [711.0, 712.5, 1e3, 1e5, 1e10, 1e15, -1e15] {
            let (s, c, d) = jacobi(u, m);
            assert!(
                s.abs() <= 1.0 && c.abs() <= 1.0 && d > 0.0 && d <= 1.0,
                "({u}, {m}): ({s}, {c}, {d})"
            );
            assert!((s * s + c * c - 1.0).abs() <= 8.0 * EPS, "({u}, {m})");
        }
    }
}

/// The exact momentum orbit next to the middle (unstable) axis: I = (1, 2, 3),
/// m0 = (1e-7, 1, 2e-7), k² = 0.9999999999999867. The error was 2.3e-11 |m| at t = 0.5,
/// 4.5e-11 at t = 5 and 1.9e-5 at t = 50, while one ulp in any input moves the solution by
/// 2.2e-16 |m| (t = 0.5, 5) and 2.4e-16 |m| (t = 50).
#[test]
fn momentum_next_to_the_middle_axis_is_as_accurate_as_the_problem_allows() {
    let body = FreeRigidBody::new(Vector3::new(1.0, 2.0, 3.0)).unwrap();
    let m0 = Vector3::new(1e-7, 1.0, 2e-7);
    let orbit = body.orbit(&m0);
    for (t, want) in [
        (
            0.5,
            [
                8.431887902349233e-8,
                1.0000000000000058,
                1.7700005672127622e-7,
            ],
        ),
        (
            5.0,
            [
                -7.318189973321318e-9,
                1.00000000000002,
                1.0080013746745022e-7,
            ],
        ),
        (
            50.0,
            [
                -0.014350705855544625,
                0.9995880296231195,
                0.02485615166648064,
            ],
        ),
    ] {
        let m = orbit.momentum(t);
        let err = (m - Vector3::from(want)).norm() / m0.norm();
        assert!(err <= 4.0 * EPS, "t = {t}: {m:?}, error {err:e} of |m0|");
    }
    // Around it: the mirror image, a start further from the axis, and the period (4K/λ with
    // K from 1 − k² = 1.3333333333332621e-14; mpmath: 240.55482298770716).
    let mirror = body.orbit(&Vector3::new(-1e-7, 1.0, -2e-7)).momentum(50.0);
    let want = Vector3::new(
        0.014350705855544625,
        0.9995880296231195,
        -0.02485615166648064,
    );
    assert!((mirror - want).norm() <= 4.0 * EPS, "{mirror:?}");
    let period = orbit.period().unwrap();
    assert!(
        (period - 240.55482298770716).abs() <= 4.0 * EPS * period,
        "period {period}"
    );
}

/// Euler angles at gimbal lock: euler_zyx of the matrix scipy builds for
/// from_euler_zyx(0.3, fl(π/2), −1.1) returned (0, 1.5708, −0.98279), 0.385 away when rebuilt.
#[test]
fn euler_angles_at_gimbal_lock_rebuild_the_matrix() {
    // scipy.spatial.transform.Rotation.from_euler("ZYX", [-1.1, pi/2, 0.3]).as_matrix()
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
    assert!(
        (from_euler_zyx(&e) - q).norm() < 1e-15,
        "{e:?} rebuilds {}",
        (from_euler_zyx(&e) - q).norm()
    );
    // scipy's answer: roll 0, pitch π/2, yaw ψ − φ = −1.4
    assert!(
        (e - Vector3::new(0.0, std::f64::consts::FRAC_PI_2, -1.4)).norm() < 1e-15,
        "{e:?}"
    );
    // Around it: pitches a few ulp to 1e-6 from ±π/2 whose small entries are round-off.
    for sign in [1.0, -1.0] {
        for k in 0..8 {
            let th =
                sign * (std::f64::consts::FRAC_PI_2 - f64::from(k) * 1e-16 * 10f64.powi(k / 2));
            let r = from_euler_zyx(&Vector3::new(0.3, th, -1.1));
            let mut noisy = r;
            noisy[(0, 0)] += 1.1e-16; // round-off of a different construction
            noisy[(1, 0)] -= 1.7e-16;
            for m in [r, noisy] {
                let back = from_euler_zyx(&euler_zyx(&m));
                assert!((back - m).norm() < 4e-15, "θ = {th}: {}", (back - m).norm());
            }
        }
    }
}
