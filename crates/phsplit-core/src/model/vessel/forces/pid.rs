//! The PID dynamic-positioning controller (paper §3.4, eqs. 29–33; docs/model.md §2, §5).
//!
//! Translation: `τ_t = −Qᵀ(Kp (x − x_ref) + Kd Q v + Ki phi_x)`, `phi_x' = x − x_ref`.
//! Rotation: `τ_r = −Wᵀ(Kp θ_e + Kd W w + Ki phi_th)`, `phi_th' = θ_e = θ − θ_ref`, with
//! `W = Pi_e(θ)⁻¹ Q` and θ the ZYX Euler angles (eq. 21). Gains are diagonal and ≥ 0. The
//! heading component of `θ_e` is taken the short way round, in (−π, π] (phsplit's addition:
//! the paper's runs never come near ±π, where the unwrapped error would jump by 2π).
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
//! - `positions` (rows of 3 numbers, m, spatial) and optionally `headings` (rad, yaw, within ±2π: `physical::ANGLE_RAD`), one per
//!   row (each turns the short way from the one before: a turn of more than half a circle
//!   needs rows in between), with either `times` (s, increasing) or `speed` (m/s, > 0, the rows are waypoints
//!   passed at this speed from `start_time`, s, default 0);
//! - `interpolation`: `"linear"` (the set point moves at constant speed between rows; the
//!   default) or `"step"` (it jumps at each row's time).
//!
//! The time-varying part (what differs from the fixed set point `control.position_reference`,
//! `control.euler_reference`) is a forcing of flow S2, evaluated at the collocation stages'
//! times. It is booked with the P and I terms as `control` (the `Kd x_d'` term too: it is a
//! port term, not dissipation).

use super::anti_windup::{self, AntiWindup, PidGains};
mod outputs;
use super::observer::{self, Observer};
use super::thrusters::{self, Thrusters};
use super::{Force, Forcing, Frozen, Output, OwnLinear, OwnState, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::reference::Reference;
use crate::model::vessel::params::{physical, Params, Range};
use crate::model::vessel::state::{Actuators, VesselState};
use crate::solve::Account;
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
    /// The thrusters that deliver the controller's force, if any (else it acts unlimited, as
    /// in the paper).
    pub thrusters: Option<Thrusters>,
    /// Back-calculation of the integral states while the thrusters saturate, if asked for
    /// (`anti_windup.rs`).
    pub anti_windup: Option<AntiWindup>,
    /// With `feedback = "observer"`: the observer whose estimates the controller acts on
    /// (`observer.rs`); else it acts on the vessel's state.
    pub observer: Option<Observer>,
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
    let euler_reference = p.vec3(
        "control",
        "euler_reference",
        None,
        "rad",
        Range::Physical(&physical::ANGLE_RAD),
    )?;
    let position_reference = p.vec3(
        "control",
        "position_reference",
        None,
        "m",
        Range::Physical(&physical::POSITION),
    )?;
    let setpoint = super::setpoint::read(p, &euler_reference)?;
    let thrusters = thrusters::read(p)?;
    let anti_windup = anti_windup::read(
        p,
        &PidGains {
            translational: [&kp_translational, &kd_translational, &ki_translational],
            rotational: [&kp_rotational, &kd_rotational, &ki_rotational],
        },
        thrusters.is_some(),
    )?;
    p.declare("observer");
    let observer = match p.choice("control", "feedback", &["true_state", "observer"])? {
        "observer" => {
            if setpoint.is_some() {
                return Err(Error::InvalidInput(
                    "control.feedback = \"observer\" does not yet take [setpoint] (a moving set point): the controller on the observer's estimates holds a fixed set point (docs/model.md §5.20); remove [setpoint] or use feedback = \"true_state\"".into(),
                ));
            }
            if thrusters.as_ref().is_some_and(|th| th.has_memory()) {
                return Err(Error::InvalidInput(
                    "control.feedback = \"observer\" does not take thrusters that keep a memory (thrusters.unit[*].thrust_rate, turn_rate, stuck_at): their memory is kept from the demand on the vessel's state, not the observer's; remove them (a failure with the observer: lost_at) or use feedback = \"true_state\"".into(),
                ));
            }
            let gains = observer::Gains {
                kp: [kp_translational, kp_rotational],
                kd: [kd_translational, kd_rotational],
                ki: [ki_translational, ki_rotational],
                position_reference: position_reference.into(),
                euler_reference: euler_reference.into(),
            };
            Some(observer::read(p, _body, &gains)?)
        }
        _ if p.has("observer") => {
            return Err(Error::InvalidInput(
                "an [observer] table needs control.feedback = \"observer\" (the observer's estimates act through the controller); set it, or remove [observer] for the controller on the vessel's state".into(),
            ))
        }
        _ if p.has("sensors") => {
            return Err(Error::InvalidInput(
                "a [sensors] table needs control.feedback = \"observer\" with an [observer] table: the observer reads the sensors (the controller on the vessel's state reads no sensor); set them, or remove [sensors]".into(),
            ))
        }
        _ => None,
    };
    Ok(Some(Arc::new(Pid {
        setpoint,
        thrusters,
        anti_windup,
        observer,
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

const ACCOUNTS: [Account; 2] = [
    Account::supplied("control").control(),
    Account::dissipated("control_damping").control(),
];

/// On the observer's estimates, the controller's whole force is one port.
const OBSERVER_ACCOUNTS: [Account; 1] = [Account::supplied("control").control()];

/// With thrusters, the controller's whole force is what they deliver: one port.
const THRUSTER_ACCOUNTS: [Account; 1] = [Account::supplied("thrusters").control()];

/// The controller's rows at a frozen attitude: the P and I terms (the port) and the D terms
/// (the dissipation) of each block system, and the constant parts of the integral states'
/// rates.
struct PidRows {
    port: [Rows; 2],
    damping: [Rows; 2],
    /// `x_o − x_ref` (translation) and `θ − θ_ref` at the frozen attitude (rotation).
    rate: [Vector3<f64>; 2],
}

/// What a moving set point changes at time `t`: the force and moment it adds to the
/// controller's (booked with the P and I terms) and what it adds to the integral states' rates.
struct Moving {
    force: Vector3<f64>,
    moment: Vector3<f64>,
    rate: [Vector3<f64>; 2],
}

/// An angle in (−π, π].
pub(super) fn wrap_pi(a: f64) -> f64 {
    let w = (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if w == -std::f64::consts::PI {
        std::f64::consts::PI
    } else {
        w
    }
}

/// `M diag(g)`: column j of `M` times `g_j` (diagonal gains as scalings).
fn times_diag(m: &Matrix3<f64>, g: &Vector3<f64>) -> Matrix3<f64> {
    let mut out = *m;
    for j in 0..3 {
        out.column_mut(j).scale_mut(g[j]);
    }
    out
}

impl Pid {
    /// The controller's rows at the frozen attitude (paper eqs. 29–33).
    fn rows(&self, fr: &Frozen) -> PidRows {
        // Translation, in v = x − x_o: x − x_ref = v + (x_o − x_ref).
        let qt_kp = times_diag(&fr.qt, &self.kp_translational);
        let offset = fr.origin - self.position_reference;
        let port_t = Rows {
            fv: -qt_kp,
            fw: -times_diag(&fr.qt, &self.ki_translational),
            c: -(qt_kp * offset),
            ..Rows::ZERO
        };
        let d_t = times_diag(&fr.qt, &self.kd_translational) * fr.q;
        let damp_t = Rows::on_velocity(Sys::Trans, -d_t);
        // Rotation.
        let (theta, wm) = (fr.euler, fr.w);
        let mut theta_err = theta - self.euler_reference;
        // The heading error the short way round (a set point at 3.1 rad and a heading of
        // −3.1 rad differ by 0.08 rad, not 6.2); roll and pitch never come near ±π.
        theta_err.z = wrap_pi(theta_err.z);
        let wt = wm.transpose();
        let port_r = Rows {
            fw: -times_diag(&wt, &self.ki_rotational),
            c: -(wt * self.kp_rotational.component_mul(&theta_err)),
            ..Rows::ZERO
        };
        let d_r = times_diag(&wt, &self.kd_rotational) * wm;
        let damp_r = Rows::on_velocity(Sys::Rot, -d_r);
        PidRows {
            port: [port_t, port_r],
            damping: [damp_t, damp_r],
            rate: [offset, theta_err],
        }
    }

    /// The controller's surge and sway force rows and its yaw moment row (P, I and D together):
    /// what thrusters deliver exactly inside their capacity.
    fn allocated_rows(r: &PidRows) -> (Rows, Rows) {
        let keep = |rows: &Rows, k: &[usize]| {
            let mut out = Rows::ZERO;
            for &i in k {
                for j in 0..2 {
                    out.fnu[j].set_row(i, &(rows.fnu[j].row(i)));
                }
                out.fv.set_row(i, &(rows.fv.row(i)));
                out.fw.set_row(i, &(rows.fw.row(i)));
                out.c[i] = rows.c[i];
            }
            out
        };
        let sum = |a: &Rows, b: &Rows| Rows {
            fnu: [a.fnu[0] + b.fnu[0], a.fnu[1] + b.fnu[1]],
            fv: a.fv + b.fv,
            fw: a.fw + b.fw,
            c: a.c + b.c,
        };
        (
            keep(&sum(&r.port[0], &r.damping[0]), &[0, 1]),
            keep(&sum(&r.port[1], &r.damping[1]), &[2]),
        )
    }

    /// What the moving set point changes at `t` (none without one).
    fn moving(&self, fr: &Frozen, t: f64) -> Option<Moving> {
        let r = self.setpoint.as_ref()?;
        let d = r.at(t);
        let xd = Vector3::new(d.value[0], d.value[1], d.value[2]);
        let vd = Vector3::new(d.rate[0], d.rate[1], d.rate[2]);
        let th = Vector3::new(d.value[3], d.value[4], d.value[5]);
        let thd = Vector3::new(d.rate[3], d.rate[4], d.rate[5]);
        let dx = xd - self.position_reference;
        let force = fr.qt
            * (self.kp_translational.component_mul(&dx) + self.kd_translational.component_mul(&vd));
        let (theta, wm) = (fr.euler, fr.w);
        let mut dth = th - self.euler_reference;
        // With the affine part's heading error e0 = wrap(θ − θ_ref), the total error e0 − dth
        // is taken the short way round too: dth is shifted by whole turns so that it is.
        let e0 = wrap_pi(theta.z - self.euler_reference.z);
        dth.z = e0 - wrap_pi(e0 - dth.z);
        let moment = wm.transpose()
            * (self.kp_rotational.component_mul(&dth) + self.kd_rotational.component_mul(&thd));
        Some(Moving {
            force,
            moment,
            rate: [-dx, -dth],
        })
    }

    /// The controller's demand (force, moment; body frame) at block states `z` and time `t`.
    pub fn demand(&self, fr: &Frozen, t: f64, z: &[Z3; 2]) -> (Vector3<f64>, Vector3<f64>) {
        Self::demand_of(&self.rows(fr), self.moving(fr, t).as_ref(), &fr.nu(z), z)
    }

    /// The demand in surge, sway and yaw `(X, Y, N)` at block states `z` and time `t`, zero
    /// while the controller is off.
    fn demand_tau(&self, fr: &Frozen, t: f64, z: &[Z3; 2]) -> Vector3<f64> {
        if !fr.control_on {
            return Vector3::zeros();
        }
        let (f, m) = self.demand(fr, t, z);
        Vector3::new(f.x, f.y, m.z)
    }

    /// The demand from the rows and the moving set point's part, already evaluated.
    fn demand_of(
        r: &PidRows,
        mv: Option<&Moving>,
        nu: &[Vector3<f64>; 2],
        z: &[Z3; 2],
    ) -> (Vector3<f64>, Vector3<f64>) {
        let mut f = r.port[0].at(nu, &z[0]) + r.damping[0].at(nu, &z[0]);
        let mut m = r.port[1].at(nu, &z[1]) + r.damping[1].at(nu, &z[1]);
        if let Some(mv) = mv {
            f += mv.force;
            m += mv.moment;
        }
        (f, m)
    }
}

impl Force for Pid {
    fn name(&self) -> &'static str {
        "pid"
    }
    fn forced(&self) -> bool {
        self.setpoint.is_some() || self.thrusters.is_some()
    }
    /// The moving set point's part depends on time only; the thrusters' on the demand.
    fn forcing_uses_state(&self) -> bool {
        self.thrusters.is_some()
    }
    /// With a moving set point: the reference model's desired position and heading, and the
    /// vessel's horizontal distance from the desired position. With thrusters: the demand and
    /// what they deliver in surge, sway and yaw, each thruster's thrust and angle, and the
    /// utilisation.
    fn outputs(&self, fr: &Frozen, z: &[Z3; 2], s: &VesselState, t: f64, out: &mut Vec<Output>) {
        // On the observer's estimates the demand is read from its states (`own_outputs`).
        if self.observer.is_none() {
            self.thruster_outputs(fr, t, &self.demand_tau(fr, t, z), out);
        }
        self.setpoint_outputs(s, t, out);
    }
    /// The moving set point's part (what `(x_d(t), θ_d(t))` and their rates change in the
    /// controller's force and in the integral states' rates), and, with thrusters, the whole
    /// force as they deliver it.
    fn add_forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], g: &mut Forcing) {
        // On the observer's estimates the forcing reads its states (`add_forcing_own`).
        if !fr.control_on || self.observer.is_some() {
            return;
        }
        let mv = self.moving(fr, t);
        if let Some(m) = &mv {
            g.rate_w(Sys::Trans, m.rate[0]);
            g.rate_w(Sys::Rot, m.rate[1]);
        }
        match &self.thrusters {
            None => {
                if let Some(m) = mv {
                    g.force(Sys::Trans, Some(0), m.force);
                    g.force(Sys::Rot, Some(0), m.moment);
                }
            }
            Some(all) => {
                let th = all.at(t);
                let r = self.rows(fr);
                let nu = fr.nu(z);
                let (f, m) = Self::demand_of(&r, mv.as_ref(), &nu, z);
                let tau = Vector3::new(f.x, f.y, m.z);
                // Rate-limited thrusters deliver what they can reach from their memory.
                let (force, moment) = match fr.actuators.n {
                    0 => th.wrench(&tau),
                    _ => th.wrench_of(&th.delivered(&tau, &fr.actuators, t - fr.actuators.t)),
                };
                if let Some(aw) = &self.anti_windup {
                    let [rt, rr] = aw.rates(fr, (&f, &m), (&force, &moment));
                    g.rate_w(Sys::Trans, rt);
                    g.rate_w(Sys::Rot, rr);
                }
                // What the thrusters deliver, less the affine part already in flow S2.
                let (rt, rr) = Self::allocated_rows(&r);
                g.force(Sys::Trans, Some(0), force - rt.at(&nu, &z[0]));
                g.force(Sys::Rot, Some(0), moment - rr.at(&nu, &z[1]));
            }
        }
    }
    /// On the observer's estimates with thrusters: the thrusters' forcing from its states
    /// (`observer/thrust.rs`); otherwise [`Force::add_forcing`].
    fn add_forcing_own(&self, fr: &Frozen, t: f64, z: &[Z3; 2], x: &[f64], g: &mut Forcing) {
        match (&self.observer, &self.thrusters) {
            (Some(o), Some(all)) => {
                let back = self
                    .anti_windup
                    .as_ref()
                    .map(|a| Vector3::new(a.gain[0].x, a.gain[0].y, a.gain[1].z));
                o.add_thrust_forcing(fr, t, x, all, back.as_ref(), g);
            }
            _ => self.add_forcing(fr, t, z, g),
        }
    }
    fn accounts(&self) -> &'static [Account] {
        if self.thrusters.is_some() {
            &THRUSTER_ACCOUNTS
        } else if self.observer.is_some() {
            &OBSERVER_ACCOUNTS
        } else {
            &ACCOUNTS
        }
    }
    fn position_origin(&self) -> Option<Vector3<f64>> {
        Some(self.position_reference)
    }
    fn actuators(&self) -> usize {
        match &self.thrusters {
            Some(th) if th.has_memory() => th.units.len(),
            _ => 0,
        }
    }
    /// Rate-limited thrusters start delivering the demand at the run's start (none while the
    /// controller is off).
    fn begin_memory(&self, fr: &Frozen, t: f64, z: &[Z3; 2], act: &mut Actuators) {
        if let Some(th) = &self.thrusters {
            *act = th.at(t).memory_at(&self.demand_tau(fr, t, z), t);
        }
    }
    fn check_memory(&self, act: &Actuators, t0: f64) -> crate::error::Result<()> {
        match &self.thrusters {
            Some(th) => th.check_memory(act, t0),
            None => Ok(()),
        }
    }
    fn end_step(&self, fr: &Frozen, t: f64, z: &[Z3; 2], act: &mut Actuators) {
        if let Some(th) = &self.thrusters {
            *act = th
                .at(t)
                .delivered(&self.demand_tau(fr, t, z), act, t - act.t);
            act.t = t;
        }
    }
    fn own_states(&self) -> &[OwnState] {
        self.observer.as_ref().map_or(&[], |o| o.states())
    }
    fn own_linear(&self) -> Option<&OwnLinear> {
        self.observer.as_ref().map(|o| o.template())
    }
    fn own_linear_at(&self, fr: &Frozen) -> Option<OwnLinear> {
        self.observer.as_ref().map(|o| o.rows_at(fr))
    }
    fn init_own(&self, s: &VesselState, x: &mut [f64]) -> crate::error::Result<()> {
        if let Some(o) = &self.observer {
            o.init(&s.x, crate::lie::so3::euler_and_w(&s.q).0.z, x);
        }
        Ok(())
    }
    fn own_end_step(&self, t: f64, s: &VesselState, x: &mut [f64]) {
        if let Some(o) = &self.observer {
            o.end_step(t, &s.x, &s.q, x);
        }
    }
    fn held_states(&self) -> Option<std::ops::Range<usize>> {
        self.observer.as_ref().and_then(|o| o.held_states())
    }
    fn next_event(&self, t: f64) -> Option<f64> {
        let sample = self.observer.as_ref().and_then(|o| o.next_sample(t));
        let loss = self.thrusters.as_ref().and_then(|th| th.next_loss(t));
        sample.into_iter().chain(loss).reduce(f64::min)
    }
    fn own_outputs(&self, fr: &Frozen, z: &[Z3; 2], x: &[f64], t: f64, out: &mut Vec<Output>) {
        if let Some(o) = &self.observer {
            o.outputs(fr, z, x, out);
            // With thrusters: the demand from the estimates, and what they deliver.
            self.thruster_outputs(fr, t, &o.demand(fr, x), out);
        }
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        if !fr.control_on || self.observer.is_some() {
            return;
        }
        let r = self.rows(fr);
        if self.thrusters.is_none() {
            let (port, damp) = (Some(0), Some(1));
            for (k, sys) in [Sys::Trans, Sys::Rot].into_iter().enumerate() {
                b.force(sys, port, &r.port[k]);
                b.force(sys, damp, &r.damping[k]);
            }
        } else {
            // Inside their capacity the thrusters deliver the demand's surge, sway and yaw
            // exactly: that part stays affine (implicit in the collocation, so the fixed point
            // converges at any step the D term allows); the forcing carries the rest (the
            // moving set point, the heel and trim of the thrusters' arms, saturation).
            let (t, rot) = Self::allocated_rows(&r);
            b.force(Sys::Trans, Some(0), &t);
            b.force(Sys::Rot, Some(0), &rot);
        }
        let t = b.rows(Sys::Trans);
        t.awv += Matrix3::identity();
        t.cw += r.rate[0];
        b.rows(Sys::Rot).cw += r.rate[1];
    }
}
