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

#[cfg(test)]
mod tests {
    use super::super::super::{Forcing, Frozen};
    use crate::lie::so3;
    use crate::model::vessel::{Vessel, PAPER_VESSEL_TOML};
    use nalgebra::{DVector, Rotation3, Vector3};

    /// The demand the forcing allocates (reported as `commanded_*`) is the one the observer's
    /// rows put on the hull, at headings all round and arbitrary estimates; thrusters in the
    /// plane of the origin that never bind deliver it, so the forcing adds only round-off to the
    /// hull, the velocity estimate and the integral states.
    #[test]
    fn the_allocated_demand_is_the_rows_and_never_binding_thrusters_add_nothing() {
        let unit = |kind: &str, x: f64, y: f64| {
            format!("[[thrusters.unit]]\nkind = \"{kind}\"\nposition = [{x}, {y}, 0.0]\nmax_thrust = 1e12\n")
        };
        let thrusters = format!(
            "[thrusters]\nhull_length = 83.0\nhull_beam = 18.0\n{}{}{}",
            unit("tunnel", 37.0, 0.0),
            unit("azimuth", -41.5, 7.0),
            unit("azimuth", -41.5, -7.0)
        );
        let text = PAPER_VESSEL_TOML.replacen(
            "[control]\n",
            &format!("[observer]\nwave_frequency = 0.7\ndamping = [3.5e4, 1.2e5, 3.2e8]\n\n{thrusters}\n[control]\nfeedback = \"observer\"\nanti_windup = \"back_calculation\"\n"),
            1,
        );
        let v = Vessel::from_toml_str(&text).unwrap();
        let pid = v.forces.iter().find(|f| f.name() == "pid").unwrap();
        assert!(pid.forced() && pid.forcing_uses_state());
        assert_eq!(pid.accounts()[0].name, "thrusters");
        let z = [[Vector3::zeros(); 3]; 2];
        for (k, psi) in [-3.1, -0.4, 0.54, 1.7, 3.1].into_iter().enumerate() {
            let q = Rotation3::from_euler_angles(0.03, -0.02, psi).into_inner();
            let (euler, w) = so3::euler_and_w(&q);
            let fr = Frozen {
                q,
                qt: q.transpose(),
                q3: q.transpose().column(2).into_owned(),
                euler,
                w,
                origin: Vector3::new(780.0, 20.0, 0.0),
                control_on: true,
                body: &v.body,
                velocity: [Vector3::zeros(); 2],
                actuators: Default::default(),
                held: None,
            };
            let x: Vec<f64> = (0..super::N)
                .map(|i| 10.0 * (0.37 * i as f64 + k as f64).sin())
                .collect();
            let rows = pid.own_linear_at(&fr).unwrap();
            let tau = &rows.fx * DVector::from_column_slice(&x) + &rows.fc;
            let size = tau.amax();
            let mut out = Vec::new();
            pid.own_outputs(&fr, &z, &x, 0.0, &mut out);
            let get = |n: &str| out.iter().find(|o| o.name == n).unwrap().value;
            for (name, i) in [
                ("commanded_surge", 0),
                ("commanded_sway", 1),
                ("commanded_yaw", 5),
            ] {
                assert!(
                    (get(name) - tau[i]).abs() <= 1e-13 * size,
                    "{psi}: {name} {} against the rows' {}",
                    get(name),
                    tau[i]
                );
            }
            let mut g = Forcing::new();
            pid.add_forcing_own(&fr, 0.0, &z, &x, &mut g);
            let hull = g.g[0][0].amax().max(g.g[1][0].amax());
            assert!(hull <= 1e-12 * size, "{psi}: hull {hull} of {size}");
            let own = g.own.iter().fold(0.0f64, |m, r| m.max(r.abs()));
            assert!(own <= 1e-12 * size / 6e6, "{psi}: own states {own}");
            assert!(g.own.len() == super::INT + 3, "{}", g.own.len());
        }
    }
}
