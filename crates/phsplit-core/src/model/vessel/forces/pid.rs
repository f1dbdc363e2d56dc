//! The PID dynamic-positioning controller (paper §3.4, eqs. 29–33; docs/model.md §2, §5).
//!
//! Translation: `τ_t = −Qᵀ(Kp (x − x_ref) + Kd Q v + Ki phi_x)`, `phi_x' = x − x_ref`.
//! Rotation: `τ_r = −Wᵀ(Kp θ_e + Kd W w + Ki phi_th)`, `phi_th' = θ_e = θ − θ_ref`, with
//! `W = Pi_e(θ)⁻¹ Q` and θ the ZYX Euler angles (eq. 21). Gains are diagonal and ≥ 0.
//!
//! Ledger: the P and I terms are the port, booked as `control` (supplied); the D terms are
//! dissipation added to D, booked as `control_damping` (`νᵀ D_c ν ≥ 0`). The controller acts
//! on the steps that start at or after the run's `control_start`. Flow S2.
//!
//! **Moving set point** (table `[setpoint]`, optional; docs/model.md §5.7): the set point
//! `(x_ref, θ_ref)` is replaced by the output `(x_d(t), θ_d(t))` of Fossen's third-order
//! reference model ([`crate::model::reference`]) driven by a table of set points, and the D
//! terms act on the velocity error: `τ_t = −Qᵀ(Kp (x − x_d) + Kd (Q v − x_d') + Ki phi_x)`,
//! `phi_x' = x − x_d`, and likewise for the angles with `θ_d`, `θ_d'` (roll and pitch stay at
//! `control.euler_reference`; the table moves the position and the heading). Keys:
//! - `natural_frequency` ω (rad/s, > 0) and `relative_damping` ζ (> 0, default 1: critically
//!   damped, the filter's step response does not overshoot);
//! - `positions` (rows of 3 numbers, m, spatial) and optionally `headings` (rad, yaw), one per
//!   row, with either `times` (s, increasing) or `speed` (m/s, > 0, the rows are waypoints
//!   passed at this speed from `start_time`, s, default 0);
//! - `interpolation`: `"linear"` (the set point moves at constant speed between rows; the
//!   default) or `"step"` (it jumps at each row's time).
//!
//! The time-varying part (what differs from the fixed set point `control.position_reference`,
//! `control.euler_reference`) is a forcing of flow S2, evaluated at the collocation stages'
//! times. It is booked with the P and I terms as `control` (the `Kd x_d'` term too: it is a
//! port term, not dissipation).

use super::{Force, Forcing, Frozen, Output, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::lie::so3;
use crate::model::reference::{Interpolation, Reference, CHANNELS};
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::VesselState;
use crate::solve::{Account, AccountKind};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct Pid {
    pub kp_translational: Vector3<f64>,
    pub kd_translational: Vector3<f64>,
    pub ki_translational: Vector3<f64>,
    pub kp_rotational: Vector3<f64>,
    pub kd_rotational: Vector3<f64>,
    pub ki_rotational: Vector3<f64>,
    /// `θ_ref`: roll, pitch, yaw set point, rad.
    pub euler_reference: Vector3<f64>,
    /// `x_ref`, m.
    pub position_reference: Vector3<f64>,
    /// The moving set point, if any.
    pub setpoint: Option<Reference>,
}

/// Table `[control]`: the six gain vectors (≥ 0, SI) and the set point (finite); all required.
pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    let mut gain = |k: &str| -> crate::Result<Vector3<f64>> {
        Ok(p.vec3("control", k, None, "SI", Range::NonNegative)?.into())
    };
    let kp_translational = gain("kp_translational")?;
    let kd_translational = gain("kd_translational")?;
    let ki_translational = gain("ki_translational")?;
    let kp_rotational = gain("kp_rotational")?;
    let kd_rotational = gain("kd_rotational")?;
    let ki_rotational = gain("ki_rotational")?;
    let euler_reference = p.vec3("control", "euler_reference", None, "rad", Range::Finite)?;
    let position_reference = p.vec3("control", "position_reference", None, "m", Range::Finite)?;
    let setpoint = setpoint(p, &euler_reference)?;
    Ok(Some(Arc::new(Pid {
        setpoint,
        kp_translational,
        kd_translational,
        ki_translational,
        kp_rotational,
        kd_rotational,
        ki_rotational,
        euler_reference: euler_reference.into(),
        position_reference: position_reference.into(),
    })))
}

/// The `[setpoint]` table, if present (see the module documentation).
fn setpoint(p: &mut Params, euler_reference: &[f64; 3]) -> crate::Result<Option<Reference>> {
    const T: &str = "setpoint";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let omega = p.f64(T, "natural_frequency", "rad/s", Range::Positive)?;
    let zeta = p
        .opt_f64(T, "relative_damping", "dimensionless", Range::Positive)?
        .unwrap_or(1.0);
    let interpolation = match p.choice(T, "interpolation", &["linear", "step"])? {
        "step" => Interpolation::Step,
        _ => Interpolation::Linear,
    };
    let positions = p
        .rows(T, "positions", 3, "m, spatial", Range::Finite)?
        .ok_or_else(|| {
            Error::Parse("missing field `positions` in [setpoint] (rows of 3 numbers, m, spatial: the set points)".into())
        })?;
    if positions.is_empty() {
        return Err(Error::InvalidInput(
            "setpoint.positions must have at least one row (m, spatial)".into(),
        ));
    }
    let headings = p.rows(T, "headings", 1, "rad", Range::Finite)?;
    if let Some(hd) = &headings {
        if hd.len() != positions.len() {
            return Err(Error::InvalidInput(format!(
                "setpoint.headings must have one value per row of setpoint.positions ({} rows), got {}",
                positions.len(),
                hd.len()
            )));
        }
    }
    let times = p.rows(T, "times", 1, "s", Range::Finite)?;
    let speed = p.opt_f64(T, "speed", "m/s", Range::Positive)?;
    let start = p.opt_f64(T, "start_time", "s", Range::Finite)?;
    let times: Vec<f64> = match (times, speed) {
        (Some(t), None) => {
            if start.is_some() {
                return Err(Error::InvalidInput(
                    "setpoint.start_time goes with setpoint.speed (waypoints); with setpoint.times each row has its own time".into(),
                ));
            }
            if t.len() != positions.len() {
                return Err(Error::InvalidInput(format!(
                    "setpoint.times must have one value per row of setpoint.positions ({} rows), got {}",
                    positions.len(),
                    t.len()
                )));
            }
            t.into_iter().map(|r| r[0]).collect()
        }
        (None, Some(v)) => {
            let mut t = vec![start.unwrap_or(0.0)];
            for k in 1..positions.len() {
                let d: f64 = (0..3)
                    .map(|i| (positions[k][i] - positions[k - 1][i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if d == 0.0 {
                    return Err(Error::InvalidInput(format!(
                        "setpoint.positions[{k}] repeats the waypoint before it: waypoints passed at a speed must differ"
                    )));
                }
                t.push(t[k - 1] + d / v);
            }
            t
        }
        (Some(_), Some(_)) => {
            return Err(Error::InvalidInput(
                "[setpoint] takes either times (s, one per row) or speed (m/s, waypoints), not both".into(),
            ))
        }
        (None, None) => {
            return Err(Error::InvalidInput(
                "[setpoint] needs times (s, one per row of positions) or speed (m/s, the rows are waypoints)".into(),
            ))
        }
    };
    let values: Vec<[f64; CHANNELS]> = positions
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let yaw = headings.as_ref().map_or(euler_reference[2], |h| h[k][0]);
            [
                r[0],
                r[1],
                r[2],
                euler_reference[0],
                euler_reference[1],
                yaw,
            ]
        })
        .collect();
    Reference::new(omega, zeta, times, values, interpolation).map(Some)
}

const ACCOUNTS: [Account; 2] = [
    Account {
        name: "control",
        kind: AccountKind::Supplied,
    },
    Account {
        name: "control_damping",
        kind: AccountKind::Dissipated,
    },
];

/// `M diag(g)`: column j of `M` times `g_j` (diagonal gains as scalings).
fn times_diag(m: &Matrix3<f64>, g: &Vector3<f64>) -> Matrix3<f64> {
    let mut out = *m;
    for j in 0..3 {
        out.column_mut(j).scale_mut(g[j]);
    }
    out
}

impl Force for Pid {
    fn name(&self) -> &'static str {
        "pid"
    }
    fn forced(&self) -> bool {
        self.setpoint.is_some()
    }
    /// With a moving set point: the reference model's desired position and heading, and the
    /// vessel's horizontal distance from the desired position.
    fn outputs(&self, s: &VesselState, t: f64, out: &mut Vec<Output>) {
        let Some(r) = &self.setpoint else {
            return;
        };
        let d = r.at(t);
        let off = (s.x.x - d.value[0]).hypot(s.x.y - d.value[1]);
        for (name, unit, long_name, value) in [
            (
                "setpoint_x",
                "m",
                "desired position x from the reference model (spatial)",
                d.value[0],
            ),
            (
                "setpoint_y",
                "m",
                "desired position y from the reference model (spatial)",
                d.value[1],
            ),
            (
                "setpoint_heading",
                "rad",
                "desired heading (yaw) from the reference model",
                d.value[5],
            ),
            (
                "setpoint_offset",
                "m",
                "horizontal distance of the vessel from the desired position",
                off,
            ),
        ] {
            out.push(Output {
                name,
                unit,
                long_name,
                value,
            });
        }
    }
    /// The moving set point's part: what `(x_d(t), θ_d(t))` and their rates change in the
    /// controller's force and in the integral states' rates, against the fixed set point.
    fn add_forcing(&self, fr: &Frozen, t: f64, _z: &[Z3; 2], g: &mut Forcing) {
        let (Some(r), true) = (&self.setpoint, fr.control_on) else {
            return;
        };
        let d = r.at(t);
        let xd = Vector3::new(d.value[0], d.value[1], d.value[2]);
        let vd = Vector3::new(d.rate[0], d.rate[1], d.rate[2]);
        let th = Vector3::new(d.value[3], d.value[4], d.value[5]);
        let thd = Vector3::new(d.rate[3], d.rate[4], d.rate[5]);
        let dx = xd - self.position_reference;
        let f = fr.qt
            * (self.kp_translational.component_mul(&dx) + self.kd_translational.component_mul(&vd));
        g.force(Sys::Trans, Some(0), f);
        g.rate_w(Sys::Trans, -dx);
        let (_, wm) = so3::euler_and_w(&fr.q);
        let dth = th - self.euler_reference;
        let m = wm.transpose()
            * (self.kp_rotational.component_mul(&dth) + self.kd_rotational.component_mul(&thd));
        g.force(Sys::Rot, Some(0), m);
        g.rate_w(Sys::Rot, -dth);
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn position_origin(&self) -> Option<Vector3<f64>> {
        Some(self.position_reference)
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        if !fr.control_on {
            return;
        }
        let (port, damp) = (Some(0), Some(1));
        // Translation, in v = x − x_o: x − x_ref = v + (x_o − x_ref).
        let qt_kp = times_diag(&fr.qt, &self.kp_translational);
        let offset = fr.origin - self.position_reference;
        let pi = Rows {
            fv: -qt_kp,
            fw: -times_diag(&fr.qt, &self.ki_translational),
            c: -(qt_kp * offset),
            ..Rows::ZERO
        };
        b.force(Sys::Trans, port, &pi);
        let d_t = times_diag(&fr.qt, &self.kd_translational) * fr.q;
        b.force(
            Sys::Trans,
            damp,
            &Rows {
                fu: d_t * (-1.0 / fr.body.mass),
                ..Rows::ZERO
            },
        );
        let t = b.rows(Sys::Trans);
        t.awv += Matrix3::identity();
        t.cw += offset;
        // Rotation.
        let (theta, wm) = so3::euler_and_w(&fr.q);
        let theta_err = theta - self.euler_reference;
        let wt = wm.transpose();
        let pi = Rows {
            fw: -times_diag(&wt, &self.ki_rotational),
            c: -(wt * self.kp_rotational.component_mul(&theta_err)),
            ..Rows::ZERO
        };
        b.force(Sys::Rot, port, &pi);
        let d_r = times_diag(&wt, &self.kd_rotational) * wm;
        b.force(
            Sys::Rot,
            damp,
            &Rows {
                fu: -times_diag(&d_r, &fr.body.inertia_inv),
                ..Rows::ZERO
            },
        );
        b.rows(Sys::Rot).cw += theta_err;
    }
}
