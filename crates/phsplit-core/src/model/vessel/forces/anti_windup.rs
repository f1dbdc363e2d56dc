//! Anti-windup of the PID controller's integral states when thrusters saturate: back-calculation
//! (K. J. Åström and T. Hägglund, *Advanced PID Control*, ISA 2006, §3.5; Åström and Murray,
//! *Feedback Systems*, 2008, §10.4; docs/explanation/components/thrusters.md).
//!
//! With a command `u = K e + I` and a delivered `v = sat(u)`, back-calculation integrates
//! `I' = K_i e + (v − u)/T_t`: while the actuator delivers the command (`v = u`) nothing
//! changes; while it saturates, the integral is pulled back towards what is delivered with the
//! tracking time constant `T_t`. In phsplit's controller (docs/model.md §2.5) the integral term
//! is `K_i φ` in the spatial coordinates of the error (`τ_t = −Qᵀ(… + K_i φ_x)`,
//! `τ_r = −Wᵀ(… + K_i φ_θ)`), so the delivered force `f + d_t` (body frame; `d_t` its deficit
//! against the demand `f`) is the command `Y − Q d_t` in those coordinates, and the moment's
//! deficit `d_r` is `Y − W⁻ᵀ d_r`. The integral states' rates become
//!
//!   `φ_x' = x − x_ref − diag(1/(K_i T_t)) Q d_t`,   `φ_θ' = θ − θ_ref − diag(1/(K_i T_t)) W⁻ᵀ d_r`,
//!
//! on the axes with `K_i > 0` (the others have no integral to wind up). The deficits are in the
//! delivered degrees of freedom (surge, sway, yaw): zero inside the thrusters' capacity, so a run
//! whose limits never bind is the run without anti-windup to round-off.
//!
//! `T_t` is Åström and Hägglund's rule `T_t = √(T_i T_d)` per axis (`T_i = K_p/K_i`,
//! `T_d = K_d/K_p`, so `T_t = √(K_d/K_i)`), `T_i` where `K_d = 0`; or the key `tracking_time`
//! for every axis.
//!
//! Energy: the integral states store nothing of H (their P and I terms are the port, docs/model.md
//! §2.5), and with thrusters the ledger books what the thrusters deliver (`thrusters`,
//! supplied). Anti-windup changes only the controller's states, so that booking and the
//! passivity statement (Prop. 2.2 for positive-step methods) are those of the thrusters without
//! it; the rates are a forcing of flow S2 evaluated at the collocation stages.

use super::Frozen;
use crate::error::Error;
use crate::lie::so3;
use crate::model::vessel::params::{physical, Params, Range};
use nalgebra::Vector3;

/// The back-calculation gains `1/(K_i T_t)` per axis (zero where `K_i = 0`), translation and
/// rotation.
#[derive(Debug, Clone, PartialEq)]
pub struct AntiWindup {
    pub gain: [Vector3<f64>; 2],
}

/// The controller's gains the rule reads: `[kp, kd, ki]` for translation and for rotation.
pub struct PidGains<'a> {
    pub translational: [&'a Vector3<f64>; 3],
    pub rotational: [&'a Vector3<f64>; 3],
}

/// Keys `control.anti_windup` (`"none"`, the default, or `"back_calculation"`) and
/// `control.tracking_time` (s, optional). Refused where it cannot act: without thrusters (the
/// controller is then unlimited) or without any integral gain.
pub fn read(p: &mut Params, g: &PidGains, thrusters: bool) -> crate::Result<Option<AntiWindup>> {
    let kind = p.choice("control", "anti_windup", &["none", "back_calculation"])?;
    let tracking = p.opt_f64(
        "control",
        "tracking_time",
        "s",
        Range::Physical(&physical::TRACKING_TIME),
    )?;
    if kind == "none" {
        if tracking.is_some() {
            return Err(Error::InvalidInput(
                "control.tracking_time is the back-calculation's time constant: it needs control.anti_windup = \"back_calculation\"; set it, or remove tracking_time".into(),
            ));
        }
        return Ok(None);
    }
    if !thrusters {
        return Err(Error::InvalidInput(
            "control.anti_windup = \"back_calculation\" acts when thrusters saturate, and without [thrusters] the controller's force is unlimited: add [thrusters], or set anti_windup = \"none\"".into(),
        ));
    }
    let mut gain = [Vector3::zeros(); 2];
    let mut any = false;
    for (k, [kp, kd, ki]) in [g.translational, g.rotational].into_iter().enumerate() {
        for j in 0..3 {
            if ki[j] <= 0.0 {
                continue;
            }
            let rule = if kd[j] > 0.0 {
                (kd[j] / ki[j]).sqrt()
            } else {
                kp[j] / ki[j]
            };
            let tt = match tracking {
                Some(t) => t,
                None if rule > 0.0 && rule.is_finite() => rule,
                None => {
                    return Err(Error::InvalidInput(format!(
                        "control.anti_windup: the tracking time's rule √(kd/ki) (or kp/ki) gives no positive time on an axis with only an integral gain ({} {j}); set control.tracking_time (s, > 0)",
                        ["translational", "rotational"][k]
                    )))
                }
            };
            gain[k][j] = 1.0 / (ki[j] * tt);
            any = true;
        }
    }
    if !any {
        return Err(Error::InvalidInput(
            "control.anti_windup = \"back_calculation\" acts on the integral states, and every integral gain (ki_translational, ki_rotational) is zero: set anti_windup = \"none\"".into(),
        ));
    }
    Ok(Some(AntiWindup { gain }))
}

impl AntiWindup {
    /// What back-calculation adds to the integral states' rates (translation, rotation) for the
    /// delivered force and moment against the demand (body frame), in surge, sway and yaw.
    pub fn rates(
        &self,
        fr: &Frozen,
        demand: (&Vector3<f64>, &Vector3<f64>),
        delivered: (&Vector3<f64>, &Vector3<f64>),
    ) -> [Vector3<f64>; 2] {
        let d_t = Vector3::new(delivered.0.x - demand.0.x, delivered.0.y - demand.0.y, 0.0);
        let d_r = Vector3::new(0.0, 0.0, delivered.1.z - demand.1.z);
        let trans = -(fr.q * d_t).component_mul(&self.gain[0]);
        // W = Pi_e(θ)⁻¹ Q, so W⁻ᵀ = Pi_e(θ)ᵀ Q in closed form (finite at every attitude).
        let rot = -(so3::pi_e(&fr.euler).transpose() * (fr.q * d_r)).component_mul(&self.gain[1]);
        [trans, rot]
    }
}
