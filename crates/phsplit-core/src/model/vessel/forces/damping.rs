//! Linear hydrodynamic damping (paper §3.4, eq. 39: `Dt v`, `Dr w`; docs/model.md §2, §5).
//!
//! Diagonal damping `D = diag(Dt, Dr)` ≥ 0 in the body frame: the force `−Dt v` and the
//! moment `−Dr w`. Dissipative: the ledger books `νᵀDν ≥ 0` to the account `damping`.
//! Flow S2.

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::model::vessel::params::{Params, Range};
use crate::solve::{Account, AccountKind};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct Damping {
    /// `Dt`: surge, sway, heave, kg/s.
    pub translational: Vector3<f64>,
    /// `Dr`: roll, pitch, yaw, kg m²/s.
    pub rotational: Vector3<f64>,
}

/// Keys `vessel.damping_translational`, `vessel.damping_rotational` (both required, ≥ 0).
pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    let t = p.vec3(
        "vessel",
        "damping_translational",
        None,
        "kg/s",
        Range::NonNegative,
    )?;
    let r = p.vec3(
        "vessel",
        "damping_rotational",
        None,
        "kg m^2/s",
        Range::NonNegative,
    )?;
    Ok(Some(Arc::new(Damping {
        translational: t.into(),
        rotational: r.into(),
    })))
}

const ACCOUNTS: [Account; 1] = [Account {
    name: "damping",
    kind: AccountKind::Dissipated,
}];

impl Force for Damping {
    fn name(&self) -> &'static str {
        "damping"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        // −D ν with ν = M⁻¹ u: −Dt/mv on p, −Dr T⁻¹ on m.
        let fu_t = Matrix3::from_diagonal(&(self.translational * (-1.0 / fr.body.mass)));
        let fu_r = Matrix3::from_diagonal(&(-self.rotational.component_mul(&fr.body.inertia_inv)));
        b.force(
            Sys::Trans,
            Some(0),
            &Rows {
                fu: fu_t,
                ..Rows::ZERO
            },
        );
        b.force(
            Sys::Rot,
            Some(0),
            &Rows {
                fu: fu_r,
                ..Rows::ZERO
            },
        );
    }
}
