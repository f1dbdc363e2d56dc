//! Linear hydrodynamic damping (paper §3.4, eq. 39: `Dt v`, `Dr w`; docs/model.md §2, §5, §5.13).
//!
//! The damping force is `−D ν` in the body frame, with `D` symmetric positive semidefinite:
//! - the paper's diagonal form, `vessel.damping_translational` (Dt: surge, sway, heave, kg/s) and
//!   `vessel.damping_rotational` (Dr: roll, pitch, yaw, kg m²/s), or
//! - a full 6×6 matrix `vessel.damping_matrix` (rows of 6; Fossen's `D_L`, e.g. with the
//!   sway–yaw couplings `Y_r`, `N_v` of a real hull), checked symmetric (to 1e-12) and positive
//!   semidefinite (its smallest eigenvalue `≥ −1e-12 max|D|`, else refused naming that eigenvalue).
//!
//! Dissipative: the ledger books `νᵀDν ≥ 0` to the account `damping`. In flow S2 all four blocks
//! are linear rows on the velocities; the couplings between translation and rotation (`D_tr ω`
//! on the force, `D_rt v` on the moment), when nonzero, make flow S2 one coupled linear system
//! (docs/model.md §5.14), still solved exactly or by Gauss collocation, and the account stays
//! `∫ νᵀDν ≥ 0` (exactly, or `h Σ b_i ν_iᵀ D ν_i ≥ 0` at the Gauss stages).

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::model::vessel::params::{Params, Range};
use crate::solve::Account;
use nalgebra::{Matrix3, SMatrix};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct Damping {
    /// `D`, 6×6, body frame: `[[D_tt, D_tr], [D_rt, D_rr]]` on `ν = (v, ω)`.
    pub matrix: SMatrix<f64, 6, 6>,
}

impl Damping {
    /// `D_tt`, `D_tr`, `D_rt`, `D_rr`.
    pub fn blocks(&self) -> [Matrix3<f64>; 4] {
        let b = |i, j| self.matrix.fixed_view::<3, 3>(i, j).into_owned();
        [b(0, 0), b(0, 3), b(3, 0), b(3, 3)]
    }
}

/// The vessel's linear damping matrix from its file: the diagonal keys or `damping_matrix`
/// (also read by `current.rs`, whose force is the damping's on the current's velocity).
pub fn read_matrix(p: &mut Params) -> crate::Result<SMatrix<f64, 6, 6>> {
    const T: &str = "vessel";
    const UNIT: &str = "kg/s, kg m/s and kg m^2/s blocks";
    let full = p.rows(T, "damping_matrix", 6, UNIT, Range::Finite)?;
    let has_diag = p.take_raw(T, "damping_translational")?.is_some()
        || p.take_raw(T, "damping_rotational")?.is_some();
    match full {
        Some(rows) => {
            if has_diag {
                return Err(Error::InvalidInput(
                    "[vessel] takes either damping_matrix (6×6) or damping_translational and damping_rotational (its diagonal), not both".into(),
                ));
            }
            if rows.len() != 6 {
                return Err(Error::InvalidInput(format!(
                    "vessel.damping_matrix must be 6 rows of 6 numbers ({UNIT}), got {} rows",
                    rows.len()
                )));
            }
            let d = SMatrix::<f64, 6, 6>::from_fn(|i, j| rows[i][j]);
            check_psd(&d, "vessel.damping_matrix")?;
            Ok(d)
        }
        None => {
            let t = p.vec3(T, "damping_translational", None, "kg/s", Range::NonNegative)?;
            let r = p.vec3(
                T,
                "damping_rotational",
                None,
                "kg m^2/s",
                Range::NonNegative,
            )?;
            let mut d = SMatrix::<f64, 6, 6>::zeros();
            for i in 0..3 {
                d[(i, i)] = t[i];
                d[(i + 3, i + 3)] = r[i];
            }
            Ok(d)
        }
    }
}

/// Symmetric (to 1e-12 of its largest entry) and positive semidefinite (smallest eigenvalue
/// `≥ −1e-12` of its largest entry); the message names the matrix and the failing value.
pub fn check_psd(d: &SMatrix<f64, 6, 6>, name: &str) -> crate::Result<()> {
    let scale = d.amax();
    crate::model::vessel::body::check_symmetric(d, name)?;
    let min = d.symmetric_eigenvalues().min();
    if min < -1e-12 * scale {
        return Err(Error::InvalidInput(format!(
            "{name} must be positive semidefinite (a damping dissipates); its smallest eigenvalue is {min:e}"
        )));
    }
    Ok(())
}

/// Keys `vessel.damping_translational` and `vessel.damping_rotational` (≥ 0), or
/// `vessel.damping_matrix` (6×6, symmetric positive semidefinite).
pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    let matrix = read_matrix(p)?;
    Ok(Some(Arc::new(Damping { matrix })))
}

const ACCOUNTS: [Account; 1] = [Account::dissipated("damping")];

impl Force for Damping {
    fn name(&self) -> &'static str {
        "damping"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, _fr: &Frozen, b: &mut S2Builder) {
        // −D ν: −D_tt v − D_tr ω on the force, −D_rt v − D_rr ω on the moment.
        let [dtt, dtr, drt, drr] = self.blocks();
        for (sys, [a, b_]) in [(Sys::Trans, [dtt, dtr]), (Sys::Rot, [drt, drr])] {
            let rows = Rows {
                fnu: [-a, -b_],
                ..Rows::ZERO
            };
            b.force(sys, Some(0), &rows);
        }
    }
}
