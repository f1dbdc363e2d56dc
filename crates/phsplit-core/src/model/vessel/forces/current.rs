//! A constant, uniform ocean current (issue 11, its first part; docs/model.md §5.5).
//!
//! Table `[current]` (optional): `velocity` (m/s, spatial frame, z up; the direction the water
//! flows towards), each component within ±10 m/s. The hydrodynamic damping then acts on the
//! velocity relative to the water, `−D_t (v − v_c)` with `v_c = Qᵀ V_c` in the body frame
//! (T. I. Fossen, "How to incorporate wind, waves and ocean currents in the marine craft
//! equations of motion", IFAC MCMC 2012: relative velocity in the damping; for a vessel without
//! added mass, as the paper's, that is the whole load of a constant irrotational current). The
//! rotational damping is unchanged (an irrotational current).
//!
//! The damping component keeps its force `−D_t v` and its account (dissipated, `vᵀD_t v`);
//! this component adds the rest, `+D_t Qᵀ V_c`. At frozen attitude that is constant, so it
//! enters flow S2 as an affine term, exactly solvable, and its power `v·D_t Qᵀ V_c` is booked
//! as the work of the port `current` (supplied; it is negative when the vessel moves against
//! the current faster than the current would carry it). The ledger closes as before.

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::model::vessel::params::{Params, Range};
use crate::solve::{Account, AccountKind};
use nalgebra::Vector3;
use std::sync::Arc;

/// The largest current component accepted (m/s): ocean currents stay below about 3 m/s.
pub const MAX_SPEED: f64 = 10.0;

#[derive(Debug, Clone, PartialEq)]
pub struct Current {
    /// `V_c`, spatial frame, m/s.
    pub velocity: Vector3<f64>,
    /// Diagonal of the translational damping `D_t` (kg/s), the vessel's.
    pub damping: Vector3<f64>,
}

pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "current";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let velocity = p.vec3(
        T,
        "velocity",
        Some([0.0; 3]),
        "m/s, spatial frame",
        Range::Finite,
    )?;
    for (i, v) in velocity.iter().enumerate() {
        if v.abs() > MAX_SPEED {
            return Err(Error::InvalidInput(format!(
                "current.velocity[{i}] must be within ±{MAX_SPEED} m/s (m/s, spatial frame), got {v}"
            )));
        }
    }
    let damping = p.vec3(
        "vessel",
        "damping_translational",
        None,
        "kg/s",
        Range::NonNegative,
    )?;
    Ok(Some(Arc::new(Current {
        velocity: velocity.into(),
        damping: damping.into(),
    })))
}

const ACCOUNTS: [Account; 1] = [Account {
    name: "current",
    kind: AccountKind::Supplied,
}];

impl Current {
    /// The body-frame force of the current at attitude `Qᵀ = qt`: `D_t Qᵀ V_c`.
    pub fn body_force(&self, qt: &nalgebra::Matrix3<f64>) -> Vector3<f64> {
        self.damping.component_mul(&(qt * self.velocity))
    }
}

impl Force for Current {
    fn name(&self) -> &'static str {
        "current"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        b.force(
            Sys::Trans,
            Some(0),
            &Rows::constant(self.body_force(&fr.qt)),
        );
    }
}
