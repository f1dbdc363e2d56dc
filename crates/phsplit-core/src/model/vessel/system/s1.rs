//! Flow S1 of the vessel (paper §3.4.1, eq. 40; docs/model.md §3.2, §3.8): the free rigid body
//! for `M` of the paper's form, Kirchhoff's equations for a general `M`. No force acts in it.

use super::super::state::VesselState;
use super::{GaveUp, VesselSystem};
use crate::flows::kirchhoff::Kirchhoff;
use crate::flows::rigid_body::MagnusOrder;
use nalgebra::{Matrix3, SVector, Vector3};

/// Most halvings of a Kirchhoff step whose Newton iteration does not converge (1024 sub-steps).
const MAX_S1_HALVINGS: usize = 10;

impl VesselSystem<'_> {
    /// Flow S1's momentum rates and the angular velocity: Kirchhoff's `p' = p × ω`,
    /// `m' = m × ω + p × v` (docs/model.md §3.8), which for `M` of the paper's form is the free
    /// rigid body's `m' = m × ω` with `p` carried along (`p × v = 0`).
    pub(super) fn s1_rates(&self, s: &VesselState) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let body = &self.vessel.body;
        if body.is_diagonal() {
            let w = body.free.omega(&s.m);
            return (-w.cross(&s.p), -w.cross(&s.m), w);
        }
        let [v, w] = body.velocity(&s.p, &s.m);
        (s.p.cross(&w), s.m.cross(&w) + s.p.cross(&v), w)
    }

    /// Flow S1 over `h` (paper §3.4.1; docs/model.md §3.8); `mu, x, phi` unchanged. For `M` of
    /// the paper's form, exact: the free rigid body with a Magnus attitude of the given order,
    /// `p(h) = Q(h)ᵀ Q0 p0`. For a general `M`, Kirchhoff's equations by Gauss collocation of the
    /// same order (H kept to round-off) with the attitude by Runge–Kutta–Munthe-Kaas; a step too
    /// long for its Newton iteration (`h|ω| ≳ 1`) is taken in 2, 4, … up to 1024 equal sub-steps;
    /// beyond that the state becomes NaN and the run stops with what it had.
    pub fn flow_s1(&self, s: &mut VesselState, h: f64, order: MagnusOrder) {
        if let Some(k) = &self.vessel.body.kirchhoff {
            let stages = match order {
                MagnusOrder::Two => 1,
                MagnusOrder::Four => 2,
                MagnusOrder::Six => 3,
            };
            let mut u = SVector::<f64, 6>::zeros();
            u.fixed_rows_mut::<3>(0).copy_from(&s.p);
            u.fixed_rows_mut::<3>(3).copy_from(&s.m);
            if let Some((u1, q1)) = kirchhoff_steps(k, &u, &s.q, h, stages) {
                s.p = u1.fixed_rows::<3>(0).into_owned();
                s.m = u1.fixed_rows::<3>(3).into_owned();
                s.q = q1;
            } else {
                self.give_up(GaveUp::Kirchhoff);
                s.p = Vector3::from_element(f64::NAN);
                s.m = s.p;
            }
            return;
        }
        let (m1, q1) = self.vessel.body.free.flow(&s.m, &s.q, h, order);
        s.p = q1.transpose() * (s.q * s.p);
        s.m = m1;
        s.q = q1;
    }
}

/// Kirchhoff's flow over `h` with `stages` Gauss stages, taken as 2, 4, … equal sub-steps when
/// Newton's method on the stages does not converge (it does for `h|ω|` up to about 1); each
/// sub-step keeps H, so the flow still does. `None` beyond [`MAX_S1_HALVINGS`] halvings.
fn kirchhoff_steps(
    k: &Kirchhoff,
    u: &SVector<f64, 6>,
    q: &Matrix3<f64>,
    h: f64,
    stages: usize,
) -> Option<(SVector<f64, 6>, Matrix3<f64>)> {
    (0..=MAX_S1_HALVINGS).find_map(|halvings| {
        let n = 1usize << halvings;
        let dt = h / n as f64;
        (0..n).try_fold((*u, *q), |(u, q), _| k.flow(&u, &q, dt, stages))
    })
}
