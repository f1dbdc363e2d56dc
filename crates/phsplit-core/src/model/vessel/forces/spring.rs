//! A linear spring from a fairlead on the hull to an anchor (docs/model.md §5.16): the axial
//! stiffness of a taut line, linearised, with its moment about the body origin.
//!
//! Table `[spring]` (optional): `fairlead` (m, body frame, from the body origin, within
//! [`MAX_ARM`] of it), `anchor` (m, spatial frame, z up) and `stiffness` (N/m, > 0). The spatial
//! force on the hull at the fairlead is `F = −k (x + Q r − a)`, a linear spring of zero rest
//! length (a line's pretension is `k |x + Q r − a|` where the run starts); in the body frame
//! `f_b = QᵀF = −k Qᵀ(x − x_o) − k (Qᵀ(x_o − a) + r)` and `m_b = r × f_b`.
//!
//! At frozen attitude (flow S2, paper eq. 41) both are affine in the translational block's
//! position `x − x_o`: the force as rows on the translation's own second state, the moment as
//! rows on the other system's (`S2Builder::force_from_other_v`, booked), a coupling of translation and rotation. They
//! stay in the linear flow S2, exact or collocated, with no forcing: the spring's work on the
//! hull `v·f_b + ω·m_b` is booked as the port `spring` (supplied), exactly along the exact flow
//! (the Gramian) and by Gauss quadrature along the collocated one.
//!
//! **Energy statement.** The spring is a port of the vessel, not a store of its `H`: with the
//! attitude frozen, the moment's work `ω·m_b` changes the kinetic energy while the spring's
//! potential `½k|x + Q r − a|²` would change only through `x`; splitting the spring's store from
//! its moment would book the difference nowhere. Booked as the work of a port, the ledger closes
//! per step (`ΔH = supplied − dissipated`), and every positive-step splitting method keeps
//! `H_n ≤ H_0 + Σ supplied` (paper Prop. 2.2, with the spring among the ports).

use super::{Force, Frozen, Output, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::lie::so3;
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::VesselState;
use crate::solve::Account;
use nalgebra::Vector3;
use std::sync::Arc;

/// Largest distance of the fairlead from the body origin (m): further out it is not on a hull.
pub const MAX_ARM: f64 = 1000.0;

#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// The fairlead `r` (body frame, m), the anchor `a` (spatial, m), the stiffness `k` (N/m).
    pub fairlead: Vector3<f64>,
    pub anchor: Vector3<f64>,
    pub stiffness: f64,
}

pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "spring";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let fairlead = p.vec3(T, "fairlead", None, "m, body frame", Range::Finite)?;
    let anchor = p.vec3(T, "anchor", None, "m, spatial frame", Range::Finite)?;
    let stiffness = p.f64(T, "stiffness", "N/m", Range::Positive)?;
    for (i, r) in fairlead.iter().enumerate() {
        if r.abs() > MAX_ARM {
            return Err(Error::InvalidInput(format!(
                "spring.fairlead[{i}] must lie within {MAX_ARM} m of the body origin (m, body frame), got {r}"
            )));
        }
    }
    Ok(Some(Arc::new(Spring {
        fairlead: fairlead.into(),
        anchor: anchor.into(),
        stiffness,
    })))
}

const ACCOUNTS: [Account; 1] = [Account::supplied("spring")];

impl Spring {
    /// The spatial force on the hull at position `x` and attitude `q`.
    pub fn spatial_force(&self, x: &Vector3<f64>, q: &nalgebra::Matrix3<f64>) -> Vector3<f64> {
        -self.stiffness * (x + q * self.fairlead - self.anchor)
    }
}

impl Force for Spring {
    fn name(&self) -> &'static str {
        "spring"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        let k = self.stiffness;
        // f_b = −k Qᵀ v − k (Qᵀ(x_o − a) + r), v = x − x_o.
        let fv = -k * fr.qt;
        let c = -k * (fr.qt * (fr.origin - self.anchor) + self.fairlead);
        b.force(
            Sys::Trans,
            Some(0),
            &Rows {
                fv,
                c,
                ..Rows::ZERO
            },
        );
        // m_b = r × f_b: on the translation's position, a row of the other system.
        let r = so3::hat(&self.fairlead);
        b.force(Sys::Rot, Some(0), &Rows::constant(r * c));
        b.force_from_other_v(Sys::Rot, Some(0), &(r * fv));
    }
    fn outputs(&self, fr: &Frozen, _z: &[Z3; 2], s: &VesselState, _t: f64, out: &mut Vec<Output>) {
        out.push(Output::new(
            "spring_tension",
            "N",
            "tension of the fairlead spring, k |x + Q r - a|",
            self.spatial_force(&s.x, &fr.q).norm(),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::Method;
    use crate::model::vessel::{LinearFlow, Vessel, VesselSystem, PAPER_VESSEL_TOML};
    use crate::solve::{run, AccountKind, Model, Options};
    use nalgebra::Rotation3;

    /// The paper's vessel moored by a spring from a point off its centreline (a lever arm in
    /// all three axes) to an anchor off its set point.
    pub(crate) fn moored() -> Vessel {
        let text = format!(
            "{PAPER_VESSEL_TOML}\n[spring]\nfairlead = [30.0, -8.0, 2.0]\nanchor = [700.0, -20.0, -5.0]\nstiffness = 4.0e4\n"
        );
        Vessel::from_toml_str(&text).unwrap()
    }

    fn state(v: &Vessel) -> VesselState {
        v.state_from(
            Vector3::new(0.05, -0.03, 0.6),
            Vector3::new(760.0, 15.0, 0.4),
            Vector3::new(0.5, -0.3, 0.1),
            Vector3::new(0.01, -0.02, 0.005),
        )
    }

    /// The force and moment the spring books equal `F = −k (x + Q r − a)` written out, turned
    /// to the body frame, and `r × f_b`.
    #[test]
    fn the_booked_wrench_is_the_spring_written_out() {
        let v = moored();
        let sys = VesselSystem::new(&v, Some(0.0));
        let k = sys
            .accounts()
            .iter()
            .position(|a| a.name == "spring")
            .unwrap();
        for q in [
            Rotation3::from_euler_angles(0.05, -0.03, 0.6),
            Rotation3::from_euler_angles(-0.4, 0.3, 2.5),
        ] {
            let mut s = state(&v);
            s.q = q.into_inner();
            let (f, m) = sys.account_wrenches(&s, 0.0, true)[k];
            let (r, a) = (
                Vector3::new(30.0, -8.0, 2.0),
                Vector3::new(700.0, -20.0, -5.0),
            );
            let fb = s.q.transpose() * (-4.0e4 * (s.x + s.q * r - a));
            assert!((f - fb).norm() <= 1e-12 * fb.norm(), "{f} vs {fb}");
            assert!((m - r.cross(&fb)).norm() <= 1e-12 * fb.norm() * r.norm());
        }
    }

    /// The spring's moment from the position couples translation and rotation within the
    /// linear flow S2: no forcing, so `linear_flow = "exact"` takes the exact coupled flow; and
    /// the ledger closes over every step with the spring booked, with the exact and the
    /// collocated S2, SP2 and SP4, at steps from 0.5 to 20 s.
    #[test]
    fn the_spring_keeps_the_exact_flow_and_the_ledger_closes() {
        let v = moored();
        let y0 = state(&v);
        for lf in [LinearFlow::Exact, LinearFlow::Gauss] {
            let sys = VesselSystem::new(&v, Some(0.0)).with_linear_flow(lf);
            assert!(!sys.is_forced() && sys.s2_solver() == lf);
            assert!(sys.s2_at(&y0.q, true, false).cross.is_some(), "coupled");
            for (name, h) in [("sp2", 0.5), ("sp4", 2.0), ("sp2", 20.0)] {
                let method: Method = name.parse().unwrap();
                let n = (600.0 / h) as usize;
                let opts = Options {
                    t0: 0.0,
                    h,
                    n_steps: n,
                    last_h: h,
                    save_every: 1,
                    outer: crate::methods::Outer::Dissipative,
                    ledger: true,
                    tolerance: None,
                };
                let tr = run(&sys, &method, y0.clone(), &opts).unwrap();
                let ks = tr.accounts.iter().position(|a| a.name == "spring").unwrap();
                assert!(tr.booked.iter().skip(1).any(|w| w.get(ks) != 0.0));
                for i in 1..tr.t.len() {
                    let dh = tr.energy[i] - tr.energy[i - 1];
                    let w = &tr.booked[i];
                    let net = w.total(&tr.accounts, AccountKind::Supplied)
                        - w.total(&tr.accounts, AccountKind::Dissipated);
                    let scale =
                        dh.abs() + w.iter().map(f64::abs).sum::<f64>() + 1e-4 * tr.energy[i].abs();
                    assert!(
                        (dh - net).abs() <= 1e-10 * scale,
                        "{lf:?} {name} h {h} step {i}: dH {dh} net {net}"
                    );
                    assert!(w.total(&tr.accounts, AccountKind::Dissipated) >= 0.0);
                }
            }
        }
    }
}
