//! What the kernels ask of the vessel beyond its flows: the error norm of adaptive steps
//! (`solve/adaptive.rs`) and why Runge–Kutta methods cannot integrate it.

use super::super::state::VesselState;
use super::VesselSystem;
use crate::lie::so3;
use nalgebra::Vector3;

impl VesselSystem<'_> {
    /// The scaled root-mean-square difference of two states in the units a user sets a
    /// tolerance in: the position (m), the attitude (the rotation vector of `Q_bᵀQ_a`, rad),
    /// the body velocities `ν = M⁻¹u` (m/s, rad/s) and the controller's integrals (m s, rad s),
    /// each component divided by `atol + rtol·max(|c_i|, |a_i|)` (the attitude's by `atol`
    /// alone: its difference is a small rotation, not a difference of angles). The restoring
    /// variable `μ` follows the attitude; the components' own states (memory, observer, pipe)
    /// act on the motion and are not weighed themselves.
    pub(super) fn motion_error(
        &self,
        a: &VesselState,
        b: &VesselState,
        c: &VesselState,
        rtol: f64,
        atol: f64,
    ) -> f64 {
        let body = &self.vessel.body;
        let (va, vb, vc) = (
            body.velocity(&a.p, &a.m),
            body.velocity(&b.p, &b.m),
            body.velocity(&c.p, &c.m),
        );
        let mut sum = 0.0;
        let mut n = 0usize;
        let mut add = |da: &Vector3<f64>, db: &Vector3<f64>, dc: &Vector3<f64>| {
            for i in 0..3 {
                let sc = atol + rtol * dc[i].abs().max(da[i].abs());
                sum += ((da[i] - db[i]) / sc).powi(2);
            }
            n += 3;
        };
        add(&a.x, &b.x, &c.x);
        add(&va[0], &vb[0], &vc[0]);
        add(&va[1], &vb[1], &vc[1]);
        add(&a.phi_x, &b.phi_x, &c.phi_x);
        add(&a.phi_th, &b.phi_th, &c.phi_th);
        let turn = so3::log(&(b.q.transpose() * a.q)) / atol;
        sum += turn.norm_squared();
        n += 3;
        (sum / n as f64).sqrt()
    }

    /// Why Runge–Kutta methods cannot integrate this vessel ([`crate::solve::Model::runge_kutta_refused`]).
    pub(super) fn runge_kutta_refusal(&self) -> Option<String> {
        if self.own_dim > 0 {
            // Each component with states of its own, by the name its states are reported under
            // (`tank_eta` is the subsystem `tank` of `port_hamiltonian`).
            let names: Vec<String> = self
                .vessel
                .own_layout()
                .map(|(f, _)| {
                    let first = f.own_states().first().map_or("", |o| o.name.as_str());
                    match f.accounts().first() {
                        _ if first.starts_with("observer_") => format!(
                            "{} (its observer, control.feedback = \"observer\")",
                            f.name()
                        ),
                        Some(a) if a.name != f.name() && first.starts_with(a.name) => {
                            format!("{} (the subsystem {})", f.name(), a.name)
                        }
                        _ => f.name().to_string(),
                    }
                })
                .collect();
            let (what, verb) = if names.len() == 1 {
                ("the component", "keeps states of its own")
            } else {
                ("the components", "keep states of their own")
            };
            return Some(format!(
                "{what} {} {verb}, which the splitting methods integrate in flow S2 with the momenta and the Runge–Kutta kernel does not carry: use a splitting method (lie, sp2, sp4, ...)",
                names.join(", ")
            ));
        }
        (self.actuators > 0).then(|| {
            "rate-limited thrusters (thrusters.unit[*].thrust_rate, turn_rate) and stuck ones (stuck_at) keep a memory from step to step that the Runge–Kutta kernel does not carry: use a splitting method (lie, sp2, sp4, ...), or remove them".into()
        })
    }
}
