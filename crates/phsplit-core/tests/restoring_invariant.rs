//! The restoring invariant `c = mu − G Qᵀe3` (docs/model.md §3.6).
//!
//! The true equilibrium of the paper's vessel under its controller is upright: nothing in the
//! model applies a heeling or trimming moment at rest (the controller acts in surge, sway and
//! yaw at the centre of gravity). So after the transient, roll and pitch must be 0 to round-off
//! and the roll/pitch integral states must stop growing. Without the projection the split
//! leaves `c ≠ 0` behind and the vessel comes to rest tilted (the test checks that too, so it
//! can tell the two apart).
use nalgebra::Vector3;
use phsplit_core::model::vessel::{Vessel, VesselState, VesselSystem};
use phsplit_core::settings::Settings;
use phsplit_core::solve::{run, Model, Status};

fn final_state(method: &str, h: f64, t1: f64, project: bool) -> (VesselState, VesselState) {
    let v = Vessel::paper();
    let sys = VesselSystem::new(&v, Some(0.0)).with_projection(project);
    let s = Settings {
        t_span: (0.0, t1),
        h,
        method: method.parse().unwrap(),
        control_start: Some(0.0),
        save_every: ((t1 / 2.0) / h).round() as usize, // saves t1/2 and t1
        ledger: false,
        ..Settings::default()
    };
    let opts = s.options().unwrap();
    let traj = run(&sys, &s.method, v.initial_state(), &opts).unwrap();
    assert_eq!(traj.status, Status::Completed, "{method} h={h}");
    let n = traj.states.len();
    (traj.states[n - 2].clone(), traj.states[n - 1].clone())
}

fn invariant(v: &Vessel, s: &VesselState) -> Vector3<f64> {
    // G from the vessel file, written out here: diag(mv g GM_L, mv g GM_T, 0).
    let p = &v.params["vessel"];
    let f = |k: &str| p[k].as_float().unwrap();
    let w = f("mass") * f("gravity");
    let g = Vector3::new(w * f("gm_longitudinal"), w * f("gm_transverse"), 0.0);
    s.mu - g.component_mul(&(s.q.transpose() * Vector3::z()))
}

#[test]
fn at_rest_the_vessel_is_upright_for_every_method_and_step() {
    let v = Vessel::paper();
    // (method, steps): every registered method at steps where it is stable on this vessel.
    let cases: [(&str, &[f64]); 8] = [
        ("lie", &[0.25, 1.0, 4.0]),
        ("sp2", &[0.2, 1.0, 4.0]),
        ("mcl2", &[0.25, 1.0, 4.0]),
        ("sp4", &[0.5, 2.0]),
        ("sp6", &[0.5, 1.0]),
        ("rk4", &[0.25, 1.0]),
        ("heun", &[0.25]),
        ("euler", &[0.01]), // at 0.05 s its growth factor nearly cancels the roll damping: not at rest by 3600 s
    ];
    assert_eq!(
        cases.len(),
        phsplit_core::methods::REGISTRY.len(),
        "every registered method"
    );
    for (method, hs) in cases {
        for &h in hs {
            let (mid, end) = final_state(method, h, 3600.0, true);
            let e = end.euler();
            assert!(
                e.x.abs() <= 1e-12 && e.y.abs() <= 1e-12,
                "{method} h={h}: roll {:.3e}, pitch {:.3e} rad at t = 3600 s",
                e.x,
                e.y
            );
            assert!(
                invariant(&v, &end).norm() <= 1e-9 * invariant_scale(&v),
                "{method} h={h}"
            );
            // The roll/pitch integral states have stopped: they moved by less than 1e-9 rad s
            // over the second half hour.
            let d = end.phi_th - mid.phi_th;
            assert!(
                d.x.abs() < 1e-9 && d.y.abs() < 1e-9,
                "{method} h={h}: integral drift {d:?}"
            );
        }
    }
}

fn invariant_scale(v: &Vessel) -> f64 {
    let p = &v.params["vessel"];
    p["mass"].as_float().unwrap()
        * p["gravity"].as_float().unwrap()
        * p["gm_longitudinal"].as_float().unwrap()
}

#[test]
fn without_the_projection_the_split_comes_to_rest_tilted() {
    // The defect the projection removes (measured: 7.9e-5 rad of pitch for SP2 at
    // h = 0.2 s), and Runge–Kutta, which keeps the linear invariant by itself.
    let (_, sp2) = final_state("sp2", 0.2, 3600.0, false);
    assert!(sp2.euler().y.abs() > 1e-6, "pitch {:.3e}", sp2.euler().y);
    let (_, rk4) = final_state("rk4", 0.2, 3600.0, false);
    assert!(
        rk4.euler().x.abs() < 1e-12 && rk4.euler().y.abs() < 1e-12,
        "{:?}",
        rk4.euler()
    );
}

#[test]
fn the_projection_changes_no_energy_and_keeps_the_ledger_closed() {
    let v = Vessel::paper();
    let sys = VesselSystem::new(&v, Some(0.0));
    let mut s = v.initial_state();
    // Off the invariant manifold: mu moved as S2 would move it without Q turning.
    s.mu += Vector3::new(3e6, -2e5, 0.0);
    let h0 = sys.energy(&s);
    let booked = sys.project(&mut s);
    assert_eq!(
        sys.energy(&s),
        h0,
        "H depends only on p, m, mu, x: the projection must not change it"
    );
    assert!(booked.iter().all(|w| w == 0.0));
    assert!(
        invariant(&v, &s).norm() <= 1e-15 * invariant_scale(&v),
        "{:?}",
        invariant(&v, &s)
    );
    assert!((s.q.transpose() * s.q - nalgebra::Matrix3::identity()).norm() < 1e-15);
    // and in a run with the ledger on, every step closes (SP2, the positive-step method)
    let st = Settings {
        t_span: (0.0, 300.0),
        h: 1.0,
        method: "sp2".parse().unwrap(),
        control_start: Some(0.0),
        ..Settings::default()
    };
    let traj = run(&sys, &st.method, v.initial_state(), &st.options().unwrap()).unwrap();
    for k in 1..traj.t.len() {
        let dh = traj.energy[k] - traj.energy[k - 1];
        let bal = traj.supplied[k] - traj.dissipated[k];
        let scale = traj.energy[k - 1].abs() + traj.supplied[k].abs() + traj.dissipated[k].abs();
        assert!(
            (dh - bal).abs() <= 1e-10 * scale,
            "step {k}: dH {dh:e}, balance {bal:e}"
        );
    }
}

/// The paper vessel's `(G11, G22)` from its file, written out here (`diag(mv g GM_L, mv g GM_T)`).
fn g_diag(v: &Vessel) -> (f64, f64) {
    let p = &v.params["vessel"];
    let f = |k: &str| p[k].as_float().unwrap();
    let w = f("mass") * f("gravity");
    (w * f("gm_longitudinal"), w * f("gm_transverse"))
}

#[test]
fn the_projection_is_the_smallest_turn_and_leaves_round_off_alone() {
    use nalgebra::{Rotation3, Unit};
    let v = Vessel::paper();
    let sys = VesselSystem::new(&v, Some(0.0));
    let (g1, g2) = g_diag(&v);
    let eps = f64::EPSILON;
    let mut checked = (0, 0);
    for (k, turn) in [3e-2, 1e-5, 1e-9, 1e-13, 3e-15, 2.0 * eps, 0.5 * eps]
        .into_iter()
        .enumerate()
    {
        // A tilted attitude, and `mu` of an attitude turned by `turn` about a horizontal-ish
        // axis: the state is off the invariant by that much.
        let q0 = Rotation3::from_euler_angles(0.03 + 0.01 * k as f64, -0.02, 0.7 + k as f64);
        let axis = Unit::new_normalize(Vector3::new(0.3, -1.0, 0.2 * k as f64));
        let target = q0 * Rotation3::from_axis_angle(&axis, turn);
        let t_true = target.inverse() * Vector3::z();
        let mut s = v.initial_state();
        s.q = q0.into_inner();
        s.mu = Vector3::new(g1 * t_true.x, g2 * t_true.y, 0.0);
        let before = s.clone();
        sys.project(&mut s);
        let q3 = before.q.transpose() * Vector3::z();
        // The attitude's vertical the invariant asks for, from mu (independently of the code).
        let (a, b) = (s.mu.x / g1, s.mu.y / g2);
        let t = Vector3::new(a, b, (1.0 - a * a - b * b).sqrt());
        let needed = t.cross(&q3).norm();
        if needed <= 4.0 * eps {
            assert_eq!(
                s.q, before.q,
                "turn {turn:e}: below the floor, Q must stay as it was"
            );
            checked.0 += 1;
        } else {
            // The smallest rotation taking t to q3 (Q ← Q E with E t = q3), by nalgebra's
            // axis–angle with the angle by atan2 (its `rotation_between` takes the angle by
            // acos, 1e-11 off at a turn of 1e-5).
            let w = t.cross(&q3);
            let e = Rotation3::from_axis_angle(&Unit::new_normalize(w), w.norm().atan2(t.dot(&q3)));
            let want = before.q * e.into_inner();
            assert!(
                (s.q - want).norm() <= 32.0 * eps,
                "turn {turn:e}: {:e}",
                (s.q - want).norm()
            );
            checked.1 += 1;
        }
        // Either way the invariant holds to the floor (relative to G).
        assert!(
            invariant(&v, &s).norm() <= 8.0 * eps * invariant_scale(&v),
            "turn {turn:e}: c = {:?}",
            invariant(&v, &s)
        );
        assert!((s.q.transpose() * s.q - nalgebra::Matrix3::identity()).norm() < 1e-15);
    }
    assert!(checked.0 >= 1 && checked.1 >= 4, "{checked:?}");
}

#[test]
fn after_every_step_the_invariant_holds_to_the_projection_floor() {
    let v = Vessel::paper();
    for (method, h) in [("sp2", 0.5), ("sp4", 1.0), ("lie", 0.25)] {
        let sys = VesselSystem::new(&v, Some(0.0));
        let st = Settings {
            t_span: (0.0, 600.0),
            h,
            method: method.parse().unwrap(),
            control_start: Some(0.0),
            ledger: false,
            ..Settings::default()
        };
        let traj = run(&sys, &st.method, v.initial_state(), &st.options().unwrap()).unwrap();
        let worst = traj
            .states
            .iter()
            .map(|s| invariant(&v, s).norm() / invariant_scale(&v))
            .fold(0.0, f64::max);
        assert!(
            worst <= 8.0 * f64::EPSILON,
            "{method} h={h}: |c|/G = {worst:e}"
        );
    }
}

#[test]
fn repeated_large_turns_keep_the_attitude_a_rotation() {
    // A tumbling vessel at a step far beyond stability asks for large turns step after step.
    // `q3` is unit only to the attitude's round-off; a turn that is a rotation only for unit
    // vectors multiplied that error by up to 4 per turn (a review measured ‖QᵀQ − I‖ → inf
    // after 3e5 turns of up to 60°; so3::exp, before the Rodrigues form, stayed at 2e-13).
    let v = Vessel::paper();
    let sys = VesselSystem::new(&v, Some(0.0));
    let (g1, g2) = g_diag(&v);
    let mut s = v.initial_state();
    // Start a little off the rotations, as a long run's attitude is.
    s.q += nalgebra::Matrix3::new(1.0, -2.0, 0.5, 0.3, 1.0, -1.0, 2.0, 0.1, -0.7) * 1e-14;
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut uniform = || {
        seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let defect =
        |q: &nalgebra::Matrix3<f64>| (q.transpose() * q - nalgebra::Matrix3::identity()).norm();
    let mut worst: f64 = 0.0;
    for _ in 0..300_000 {
        // A vertical for mu up to 60° from the current one, on the upper hemisphere.
        let (theta, phi) = (uniform() * 1.0, uniform() * std::f64::consts::TAU);
        let t = Vector3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        );
        s.mu = Vector3::new(g1 * t.x, g2 * t.y, 0.0);
        sys.project(&mut s);
        worst = worst.max(defect(&s.q));
    }
    assert!(worst < 1e-11, "max ‖QᵀQ − I‖ = {worst:e}");
}
