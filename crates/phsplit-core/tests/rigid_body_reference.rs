//! The exact free-rigid-body momentum against mpmath: random bodies, near-symmetric
//! bodies (relative inertia gaps 1e-6 … 1e-14), states next to the separatrix and next to the
//! middle axis, t up to 1,000.
//!
//! Table: `tests/data/rigid_body_ref.csv`, written by `scripts/gen_rigid_body_refs.py` (closed
//! form of Landau–Lifshitz §37 at 50 digits, checked against mpmath's ODE solver at 30 digits).
//! Each row carries the problem's own sensitivity: how far m(t) moves when one input (an
//! inertia, a component of m0, or t) moves one ulp. The bound is a small multiple of it, with a
//! floor of the round-off of |m0| itself:
//! `|m − m_ref| ≤ 4 max(sensitivity, ε |m0|)`.
use nalgebra::{Matrix3, Vector3};
use phsplit_core::flows::rigid_body::{FreeRigidBody, MagnusOrder};

struct Row {
    case: String,
    inertia: Vector3<f64>,
    m0: Vector3<f64>,
    t: f64,
    want: Vector3<f64>,
    sens: f64,
}

fn rows() -> Vec<Row> {
    let p = |s: &str| -> f64 { s.parse().unwrap_or_else(|_| panic!("not a number: {s}")) };
    include_str!("data/rigid_body_ref.csv")
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            Row {
                case: c[0].to_string(),
                inertia: Vector3::new(p(c[1]), p(c[2]), p(c[3])),
                m0: Vector3::new(p(c[4]), p(c[5]), p(c[6])),
                t: p(c[7]),
                want: Vector3::new(p(c[8]), p(c[9]), p(c[10])),
                sens: p(c[11]),
            }
        })
        .collect()
}

/// Error over the allowance (≤ 1 passes) and error over the sensitivity.
fn score(got: &Vector3<f64>, r: &Row) -> (f64, f64) {
    let e = (got - r.want).norm();
    let floor = f64::EPSILON * r.m0.norm();
    (e / (4.0 * r.sens.max(floor)), e / r.sens.max(floor))
}

#[test]
fn exact_momentum_within_a_small_multiple_of_the_problems_sensitivity() {
    let rows = rows();
    assert!(rows.len() >= 100, "{} rows", rows.len());
    let mut worst = (0.0f64, 0.0f64, String::new());
    let mut failures = Vec::new();
    for r in &rows {
        let body = FreeRigidBody::new(r.inertia).unwrap();
        let orbit = body.orbit(&r.m0);
        for (path, got) in [
            ("addition theorem", orbit.momentum(r.t)),
            ("direct phase", orbit.momentum_direct(r.t)),
        ] {
            let (s, x) = score(&got, r);
            let what = format!("{} t={} ({path}): {got:?} vs {:?}", r.case, r.t, r.want);
            if s > worst.0 {
                worst = (s, x, what.clone());
            }
            if s.is_nan() || s > 1.0 {
                failures.push(format!("score {s:.2}: {what}"));
            }
        }
    }
    println!(
        "worst: {:.3} of the allowance ({:.2} x the sensitivity): {}",
        worst.0, worst.1, worst.2
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn one_flow_step_lands_on_the_exact_momentum() {
    // The flow's end point comes from the addition of two symmetric Magnus nodes: the same
    // bound, for steps up to t = 50 (longer single steps are no use to a Magnus attitude).
    let mut worst = 0.0f64;
    for r in rows().iter().filter(|r| r.t <= 50.0) {
        let body = FreeRigidBody::new(r.inertia).unwrap();
        for order in [MagnusOrder::Two, MagnusOrder::Four, MagnusOrder::Six] {
            let (m, _) = body.flow(&r.m0, &Matrix3::identity(), r.t, order);
            let (s, _) = score(&m, r);
            worst = worst.max(s);
            assert!(
                s <= 1.0,
                "{} t={} {order:?}: {m:?} vs {:?}",
                r.case,
                r.t,
                r.want
            );
        }
    }
    println!("worst flow end point: {worst:.3} of the allowance");
}
