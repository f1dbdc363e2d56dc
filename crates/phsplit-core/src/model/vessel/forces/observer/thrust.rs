//! The controller on the observer's estimates through thrusters (`observer.rs`; docs/
//! explanation/components/observer.md, "With thrusters").
//!
//! The observer's rows keep the controller's demand `τ_c = Tx x + tc` (surge, sway, yaw; body
//! frame) affine in its states: on the hull and in the low-frequency velocity estimate ν̂. The
//! thrusters deliver `τ_d`, their allocation of `τ_c` within their limits (a 6-DOF wrench: the
//! arms' heel and trim moments too), and a forcing of flow S2 carries the difference:
//! - on the hull: the delivered wrench less the demand's surge, sway and yaw already in the
//!   rows (booked to the controller's account, `thrusters`);
//! - on ν̂: `M⁻¹(τ_d − τ_c)`, so that the observer's model is driven by the thrust actually
//!   applied (Fossen 2021, §13.5: τ in `M ν̂' = −D ν̂ + Rᵀ b̂ + τ + Rᵀ K₄ ỹ`);
//! - with back-calculation anti-windup (Åström and Hägglund, *Advanced PID Control*, 2006,
//!   §3.5; `anti_windup.rs`) on the integral states `q`: the controller's command in the
//!   coordinates of the error is `Y = Kp e + Ki q + Kd R ν̂ = −R τ`, so the integral term
//!   `I = Ki q` follows `I' = Ki e + (v − u)/T_t` with `v − u = −R (τ_d − τ_c)`:
//!   `q' = e − diag(1/(Ki T_t)) R (τ_d − τ_c)` on the axes with `Ki > 0`.
//!
//! Inside the thrusters' capacity `τ_d = τ_c` in surge, sway and yaw, and the forcing is only the
//! arms' heel and trim moments (nothing at all for thrusters in the plane of the origin).

use super::super::thrusters::Thrusters;
use super::super::{Forcing, Frozen, Sys};
use super::{rot, Observer, ETA, INT, N, NU};
use nalgebra::Vector3;

impl Observer {
    /// The measured heading the rows are built at ([`Observer::rows_at`]).
    fn measured_heading(&self, fr: &Frozen) -> f64 {
        match (&self.sensors, &fr.held) {
            (Some(_), Some(h)) => h[2],
            _ => fr.euler.z,
        }
    }

    /// The controller's demand `τ_c = −Rᵀ(Kp e + Ki q) − Rᵀ Kd R ν̂` (surge, sway, yaw; body
    /// frame) at the observer's states `x`, as its rows give it; zero while the controller is off.
    pub fn demand(&self, fr: &Frozen, x: &[f64]) -> Vector3<f64> {
        if !fr.control_on || x.len() < N {
            return Vector3::zeros();
        }
        let r = rot(self.measured_heading(fr));
        let at = |k: usize| Vector3::new(x[k], x[k + 1], x[k + 2]);
        let y = self.kp.component_mul(&(at(ETA) - self.reference))
            + self.ki.component_mul(&at(INT))
            + self.kd.component_mul(&(r * at(NU)));
        -(r.transpose() * y)
    }

    /// The forcing of the thrusters `all` at time `t` and the observer's states `x` (module
    /// documentation); `back`: the back-calculation gains `1/(Ki T_t)` in (x, y, ψ), if any.
    pub fn add_thrust_forcing(
        &self,
        fr: &Frozen,
        t: f64,
        x: &[f64],
        all: &Thrusters,
        back: Option<&Vector3<f64>>,
        g: &mut Forcing,
    ) {
        if !fr.control_on || x.len() < N {
            return;
        }
        let tau = self.demand(fr, x);
        let (force, moment) = all.at(t).wrench(&tau);
        g.force(Sys::Trans, Some(0), force - Vector3::new(tau.x, tau.y, 0.0));
        g.force(Sys::Rot, Some(0), moment - Vector3::new(0.0, 0.0, tau.z));
        let d = Vector3::new(force.x - tau.x, force.y - tau.y, moment.z - tau.z);
        let nu = self.minv * d;
        for i in 0..3 {
            g.rate_own(NU + i, nu[i]);
        }
        if let Some(k) = back {
            let pull = -(rot(self.measured_heading(fr)) * d).component_mul(k);
            for i in 0..3 {
                g.rate_own(INT + i, pull[i]);
            }
        }
    }
}
