//! The PID dynamic-positioning controller (paper §3.4, eqs. 29–33; docs/model.md §2, §5).
//!
//! Translation: `τ_t = −Qᵀ(Kp (x − x_ref) + Kd Q v + Ki phi_x)`, `phi_x' = x − x_ref`.
//! Rotation: `τ_r = −Wᵀ(Kp θ_e + Kd W w + Ki phi_th)`, `phi_th' = θ_e = θ − θ_ref`, with
//! `W = Pi_e(θ)⁻¹ Q` and θ the ZYX Euler angles (eq. 21). Gains are diagonal and ≥ 0.
//!
//! Ledger: the P and I terms are the port, booked as `control` (supplied); the D terms are
//! dissipation added to D, booked as `control_damping` (`νᵀ D_c ν ≥ 0`). The controller acts
//! on the steps that start at or after the run's `control_start`. Flow S2.

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::lie::so3;
use crate::model::vessel::params::{Params, Range};
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
    Ok(Some(Arc::new(Pid {
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
