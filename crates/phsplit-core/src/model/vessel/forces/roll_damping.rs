//! Viscous roll damping, linear plus quadratic, docs/model.md §5.19.
//!
//! Roll is the motion whose potential (wave-radiation) damping is small, so the viscous part —
//! skin friction, eddies at the bilges, lift, bilge keels — sets its resonance. The usual model
//! is the roll moment `K = −B₁ p − B₂ |p| p` on the roll rate `p` (ITTC Recommended Procedure
//! 7.5-02-07-04.5, *Numerical Estimation of Roll Damping*, 2011, §2: `B(φ') = B₁ φ' + B₂ |φ'| φ'`;
//! Y. Himeno, *Prediction of Ship Roll Damping — State of the Art*, Univ. of Michigan report 239,
//! 1981), with `B₁` and `B₂` from a roll-decay test or from Ikeda's component method; or the
//! linear part as a fraction of critical damping, the common design value (MSS's `Dmtrx.m`
//! takes `ζ₄` so). Table `[roll_damping]`, the user's choice of:
//! - `linear` `B₁` (N m s, ≥ 0), or `critical_fraction` `ζ` (`0 ≤ ζ < 1`), which sets
//!   `B₁ = 2 ζ √(M₄₄ C₄₄)` with `M₄₄` the roll entry of the vessel's mass matrix (its rigid
//!   body and added mass, about the body origin) and `C₄₄ = m g GM_T + y_F² ρ g A_wp` its roll
//!   stiffness (`restoring.rs`): the uncoupled roll oscillator's `ζ`;
//! - `quadratic` `B₂` (N m s², i.e. kg m², ≥ 0; default 0).
//!
//! This is added to the vessel's linear damping (whose roll entry stays as given). The moment
//! acts about the body's x axis on the body angular velocity's first component; its power
//! `B₁ p² + B₂ |p|³ ≥ 0` is booked as the dissipation `roll_damping`.
//!
//! **In flow S2** the linear part is a row on the angular velocity (exact or collocated, as the
//! linear damping). The quadratic part is split as `damping_quadratic.rs`'s: its derivative at
//! the sub-step's start, `−2B₂|p₀| p`, in the implicit rows, the rest `−B₂(|p| − 2|p₀|) p` in
//! the forcing, so flow S2 is Gauss collocation, whose booked dissipation
//! `h Σ bᵢ (B₁ pᵢ² + B₂ |pᵢ|³) ≥ 0` at the stages closes the balance of the quadratic `H`
//! exactly: the split stays passive (Prop. 2.2; Prop. 2.5's condition for SP4/SP6).

use super::{Force, Forcing, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::vessel::params::{Params, Range};
use crate::solve::Account;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct RollDamping {
    /// `B₁`, N m s.
    pub linear: f64,
    /// `B₂`, N m s².
    pub quadratic: f64,
}

const T: &str = "roll_damping";

/// Table `[roll_damping]`: `linear` or `critical_fraction`, and `quadratic`.
pub fn build(p: &mut Params, body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let linear = p.opt_f64(T, "linear", "N m s", Range::NonNegative)?;
    let zeta = p.opt_f64(
        T,
        "critical_fraction",
        "a fraction of critical damping, in [0, 1)",
        Range::NonNegative,
    )?;
    let quadratic = p
        .opt_f64(T, "quadratic", "N m s^2", Range::NonNegative)?
        .unwrap_or(0.0);
    let linear = match (linear, zeta) {
        (Some(_), Some(_)) => {
            return Err(Error::InvalidInput(
                "[roll_damping] takes either linear (B1, N m s) or critical_fraction (zeta, 0 <= zeta < 1), not both".into(),
            ))
        }
        (Some(b), None) => b,
        (None, Some(z)) => {
            if z >= 1.0 {
                return Err(Error::InvalidInput(format!(
                    "roll_damping.critical_fraction must be in [0, 1) (a fraction of critical damping), got {z}"
                )));
            }
            2.0 * z * (body.mass_matrix[(3, 3)] * roll_stiffness(p, body)?).sqrt()
        }
        // Neither: a misspelling of one is named as such (else the table says what it needs).
        (None, None) if quadratic == 0.0 => {
            if let Some(e) = ["linear", "critical_fraction"]
                .into_iter()
                .find_map(|key| p.misspelling(T, key))
            {
                return Err(e);
            }
            0.0
        }
        (None, None) => 0.0,
    };
    // Far above any hull's (a 300 m ship's critical roll damping is about 1e11 N m s): a slip of
    // units or digits, refused before it stalls the run.
    for (key, v, max) in [("linear", linear, 1e14), ("quadratic", quadratic, 1e16)] {
        if v > max {
            return Err(Error::InvalidInput(format!(
                "roll_damping.{key} must be at most {max:e} (N m s or N m s^2; a large ship's critical roll damping is about 1e11 N m s), got {v:e}"
            )));
        }
    }
    if linear == 0.0 && quadratic == 0.0 {
        return Err(Error::InvalidInput(
            "[roll_damping] needs linear (N m s) or critical_fraction (0 <= zeta < 1), and/or quadratic (N m s^2), one of them > 0".into(),
        ));
    }
    Ok(Some(Arc::new(RollDamping { linear, quadratic })))
}

/// `C₄₄ = m g GM_T + y_F² ρ g A_wp` (N m/rad), the restoring's roll entry about upright.
fn roll_stiffness(p: &mut Params, body: &super::Body) -> crate::Result<f64> {
    let gm_t = p.f64("vessel", "gm_transverse", "m", Range::Positive)?;
    let g = p.f64("vessel", "gravity", "m/s^2", Range::Positive)?;
    let rho = p.f64("vessel", "water_density", "kg/m^3", Range::Positive)?;
    let awp = p.f64("vessel", "waterplane_area", "m^2", Range::Positive)?;
    let yf = p
        .opt_f64("vessel", "flotation_center_y", "m", Range::Finite)?
        .unwrap_or(0.0);
    Ok(body.mass * g * gm_t + yf * yf * rho * g * awp)
}

const ACCOUNTS: [Account; 1] = [Account::dissipated("roll_damping")];

impl Force for RollDamping {
    fn name(&self) -> &'static str {
        "roll_damping"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    /// `−(B₁ + 2B₂|p₀|) p` on the roll moment.
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        let d = self.linear + 2.0 * self.quadratic * fr.velocity[1][0].abs();
        let f = Matrix3::from_diagonal(&Vector3::new(-d, 0.0, 0.0));
        b.force(Sys::Rot, Some(0), &Rows::on_velocity(Sys::Rot, f));
    }
    fn forced(&self) -> bool {
        self.quadratic > 0.0
    }
    /// The rest of the quadratic part, `−B₂(|p| − 2|p₀|) p`.
    fn add_forcing(&self, fr: &Frozen, _t: f64, z: &[Z3; 2], g: &mut Forcing) {
        if self.quadratic == 0.0 {
            return;
        }
        let p = fr.nu(z)[1][0];
        let rest = (p.abs() - 2.0 * fr.velocity[1][0].abs()) * p;
        g.force(
            Sys::Rot,
            Some(0),
            Vector3::new(-self.quadratic * rest, 0.0, 0.0),
        );
    }
}
