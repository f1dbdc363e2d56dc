//! Quadratic (nonlinear) hydrodynamic damping: the diagonal part of Fossen's `D_n(ν)ν`
//! (T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed., Wiley
//! 2021, §6.4: `D_n(ν) = −diag(X_|u|u |u|, Y_|v|v |v|, Z_|w|w |w|, K_|p|p |p|, M_|q|q |q|,
//! N_|r|r |r|)`), docs/model.md §5.11.
//!
//! Table `[damping_quadratic]` (optional): `coefficients`, six numbers ≥ 0 (surge, sway, heave in
//! kg/m; roll, pitch, yaw in kg m²), Fossen's `−X_|u|u, …` (his derivatives are ≤ 0). The force
//! is `−c_i |ν_i| ν_i` on each degree of freedom (body frame); its power `Σ c_i |ν_i| ν_i² ≥ 0`
//! is booked as the dissipation `damping_quadratic`. With a current, the component `current`
//! adds the difference to the relative velocity and books it as the current's work (as for the
//! linear damping).
//!
//! **In flow S2** the force is not affine. Its derivative at the sub-step's start,
//! `−2c ∘ |ν₀| ∘ ν` (a linear damping with the coefficients `2 c_i |ν_i(0)| ≥ 0`), is put in the
//! implicit rows, and the rest, `−c ∘ (|ν| − 2|ν₀|) ∘ ν`, in the forcing. The two add up to the
//! force at every state, so the vector field and the collocation solution are the force's own;
//! the split only keeps the fixed-point iteration of the forcing contractive at long steps (the
//! rest's derivative is `2c ∘ (|ν| − |ν₀|)`, zero at the start and small over a sub-step). Flow S2 is then Gauss collocation
//! (docs/model.md §3.7), whose energy balance is exact for the quadratic `H`:
//! `H(1) − H(0) = h Σ b_i P(Y_i)`, with the booked dissipation `h Σ b_i Σ_j c_j |ν_j| ν_j² ≥ 0`
//! at the stages (positive weights). So flow S2 stays dissipative, and the split keeps its
//! guarantee: exact passivity for positive-coefficient compositions (Prop. 2.2), Prop. 2.5's
//! condition for SP4/SP6.

use super::{Force, Forcing, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::vessel::params::{Params, Range};
use crate::solve::Account;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct QuadraticDamping {
    /// Surge, sway, heave (kg/m).
    pub translational: Vector3<f64>,
    /// Roll, pitch, yaw (kg m²).
    pub rotational: Vector3<f64>,
}

/// Table `[damping_quadratic]`, key `coefficients` (6 numbers ≥ 0).
pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "damping_quadratic";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let c = coefficients(p)?.expect("the table is present");
    Ok(Some(Arc::new(QuadraticDamping {
        translational: c.0,
        rotational: c.1,
    })))
}

/// The coefficients of `[damping_quadratic]`, if the table is present (also read by `current`).
pub fn coefficients(p: &mut Params) -> crate::Result<Option<(Vector3<f64>, Vector3<f64>)>> {
    const T: &str = "damping_quadratic";
    if !p.has(T) {
        return Ok(None);
    }
    const UNIT: &str = "surge, sway, heave kg/m; roll, pitch, yaw kg m^2";
    let c: Vec<f64> = match p.rows(T, "coefficients", 1, UNIT, Range::NonNegative)? {
        Some(rows) if rows.len() == 6 => rows.into_iter().map(|r| r[0]).collect(),
        Some(rows) => {
            return Err(Error::InvalidInput(format!(
                "damping_quadratic.coefficients must be 6 numbers ≥ 0 ({UNIT}), got {}",
                rows.len()
            )))
        }
        None => return Err(p.missing(T, "coefficients", &format!("6 numbers ≥ 0: {UNIT}"))),
    };
    Ok(Some((
        Vector3::new(c[0], c[1], c[2]),
        Vector3::new(c[3], c[4], c[5]),
    )))
}

const ACCOUNTS: [Account; 1] = [Account::dissipated("damping_quadratic")];

impl QuadraticDamping {
    /// The coefficients of each block system: translation, rotation.
    fn of(&self, sys: usize) -> &Vector3<f64> {
        if sys == 0 {
            &self.translational
        } else {
            &self.rotational
        }
    }
}

impl Force for QuadraticDamping {
    fn name(&self) -> &'static str {
        "damping_quadratic"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    /// The derivative at the sub-step's start, `−2c ∘ |ν₀| ∘ ν`, with `ν = M⁻¹u`.
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        for (k, sys) in [Sys::Trans, Sys::Rot].into_iter().enumerate() {
            let d = self.of(k).component_mul(&fr.velocity[k].abs()) * 2.0;
            b.force(
                sys,
                Some(0),
                &Rows::on_velocity(sys, Matrix3::from_diagonal(&(-d))),
            );
        }
    }
    fn forced(&self) -> bool {
        true
    }
    /// The rest, `−c ∘ (|ν| − 2|ν₀|) ∘ ν`.
    fn add_forcing(&self, fr: &Frozen, _t: f64, z: &[Z3; 2], g: &mut Forcing) {
        let nu = fr.nu(z);
        for (k, sys) in [Sys::Trans, Sys::Rot].into_iter().enumerate() {
            let rest = (nu[k].abs() - fr.velocity[k].abs() * 2.0).component_mul(&nu[k]);
            g.force(sys, Some(0), -self.of(k).component_mul(&rest));
        }
    }
}
