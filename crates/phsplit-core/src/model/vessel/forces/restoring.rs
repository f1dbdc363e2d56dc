//! Hydrostatic restoring forces in the paper's energy-consistent form (paper §3.4, eqs. 35–39;
//! docs/model.md §2, §5).
//!
//! Heave: the force `−Qᵀ Λ x`, `Λ = diag(0, 0, c)`, `c = g ρ A_wp`. Roll and pitch: the moment
//! `−mu × q3` with the restoring variable `mu` (= `G Qᵀe3` on exact solutions),
//! `mu' = −G (w × q3)`, `G = mv g diag(GM_L, GM_T, 0)`. Both are conservative exchanges between
//! the kinetic energy and the stored energy `½ muᵀG⁺mu + ½ c x_z²`, which this component adds
//! to H: nothing is booked in the ledger. Flow S2.
//!
//! With the centre of flotation at `x_F` (`vessel.flotation_center_x`, default 0) the heave
//! spring acts there: `V = ½ c (z + x_F q3_x)² + ½ q3ᵀ G q3` (for small angles Fossen's
//! `G33 = c`, `G35 = −x_F c`, `G55 = mv g GM_L + x_F² c`; Fossen 2021, §4.2, the restoring matrix
//! moved from the centre of flotation). In the energy-consistent form (docs/model.md §5.15)
//! `mu = G' q3 − k z e1` with `G' = G + diag(x_F² c, 0, 0)` and `k = −x_F c`; the store is
//! `½ c' z² + ½ muᵀG'⁺mu` with `c' = c − k²/G'_11 > 0`, the heave force
//! `−q3 (c' z − (k/G'_11) mu_x)`, and `mu' = G' hat(q3) ω − k e1 q3ᵀ v`: the coupling joins the
//! translation and rotation of flow S2 (one coupled system).

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::lie::so3;
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::VesselState;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct Restoring {
    /// Diagonal of `G`, N m.
    pub g: Vector3<f64>,
    /// Diagonal of `G⁺`.
    pub g_plus: Vector3<f64>,
    /// Heave stiffness `c = g ρ A_wp`, N/m.
    pub heave: f64,
    /// The heave–pitch coupling `k = −x_F c` (N) of `mu = G q3 − k z e1`.
    pub coupling: f64,
    /// The heave stiffness of the store, `c' = c − k²/G_11` (`= c` without coupling), N/m.
    pub heave_store: f64,
}

/// Keys `vessel.gm_transverse`, `gm_longitudinal` (m), `gravity` (m/s²), `water_density`
/// (kg/m³), `waterplane_area` (m²): all required, > 0.
pub fn build(p: &mut Params, body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    let gm_t = p.f64("vessel", "gm_transverse", "m", Range::Positive)?;
    let gm_l = p.f64("vessel", "gm_longitudinal", "m", Range::Positive)?;
    let gravity = p.f64("vessel", "gravity", "m/s^2", Range::Positive)?;
    let rho = p.f64("vessel", "water_density", "kg/m^3", Range::Positive)?;
    let awp = p.f64("vessel", "waterplane_area", "m^2", Range::Positive)?;
    let xf = p
        .opt_f64("vessel", "flotation_center_x", "m", Range::Finite)?
        .unwrap_or(0.0);
    if xf.abs() > 1000.0 {
        return Err(crate::error::Error::InvalidInput(format!(
            "vessel.flotation_center_x must lie within ±1000 m of the body origin (m, body frame), got {xf}"
        )));
    }
    let w = body.mass * gravity;
    let c = gravity * rho * awp;
    let g = Vector3::new(w * gm_l + xf * xf * c, w * gm_t, 0.0);
    let k = -xf * c;
    Ok(Some(Arc::new(Restoring {
        g,
        g_plus: g.map(|v| if v == 0.0 { 0.0 } else { 1.0 / v }),
        heave: c,
        coupling: k,
        // c − k²/G11 = c w GM_L / (w GM_L + x_F² c) > 0.
        heave_store: if k == 0.0 { c } else { c * (w * gm_l) / g.x },
    })))
}

impl Force for Restoring {
    fn name(&self) -> &'static str {
        "restoring"
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        // Heave, in v = x − x_o: −c (v_z + x_o,z) Qᵀe3.
        let col = fr.qt.column(2).into_owned();
        let mut fv = Matrix3::zeros();
        fv.set_column(2, &(col * -self.heave_store));
        let c = col * (-self.heave_store * fr.origin.z);
        b.force(
            Sys::Trans,
            None,
            &Rows {
                fv,
                c,
                ..Rows::ZERO
            },
        );
        // Roll and pitch: −mu × q3 = hat(q3) mu; mu' = G hat(q3) ω.
        let hq3 = so3::hat(&fr.q3);
        b.force(
            Sys::Rot,
            None,
            &Rows {
                fv: hq3,
                ..Rows::ZERO
            },
        );
        b.rate_v(Sys::Rot, Sys::Rot, &(Matrix3::from_diagonal(&self.g) * hq3));
        if self.coupling != 0.0 {
            // The heave force's part (k/G11) mu_x q3, and mu_x' = … − k q3ᵀv.
            let k = self.coupling;
            b.force_from_other_v(
                Sys::Trans,
                &(fr.q3 * Vector3::x().transpose() * (k / self.g.x)),
            );
            b.rate_v(
                Sys::Rot,
                Sys::Trans,
                &(Vector3::x() * fr.q3.transpose() * -k),
            );
        }
    }
    fn storage(&self, s: &VesselState) -> f64 {
        0.5 * s.mu.component_mul(&s.mu).dot(&self.g_plus) + 0.5 * self.heave_store * s.x.z * s.x.z
    }
    fn init_state(&self, s: &mut VesselState) {
        s.mu = self.g.component_mul(&(s.q.transpose() * Vector3::z()))
            - Vector3::x() * (self.coupling * s.x.z);
    }
    /// The invariant `c = mu − G Qᵀe3` (zero from a consistent start) is kept by the exact flow
    /// and by every Runge–Kutta method (it is linear in the Runge–Kutta variables), but not by
    /// the split: S1 turns `Q` without `mu`, S2 moves `mu` at frozen `Q`. Its drift leaves the
    /// vessel at rest with a false heel and trim (docs/model.md §3.6). The projection turns the
    /// attitude by the smallest rotation `E` that gives `G Qᵀe3 = mu` again (`Q ← Q E`, `E t =
    /// q3` with `t = (mu₁/G₁, mu₂/G₂, ±√(1 − ·))`), and leaves `mu` alone: H does not depend on
    /// `Q`, so the projection neither creates nor removes energy and the ledger books nothing.
    /// Beyond 90° of heel (no such `t`) it does nothing.
    fn project(&self, s: &mut VesselState) {
        let (g0, g1) = (self.g.x, self.g.y);
        if !(g0 > 0.0 && g1 > 0.0) {
            return;
        }
        let q3 = s.q.transpose() * Vector3::z();
        // G q3 = mu + k z e1 on the invariant.
        let (t0, t1) = ((s.mu.x + self.coupling * s.x.z) / g0, s.mu.y / g1);
        let r2 = t0 * t0 + t1 * t1;
        if !(r2 < 1.0) {
            return;
        }
        let t = Vector3::new(t0, t1, (1.0 - r2).sqrt().copysign(q3.z));
        let axis = t.cross(&q3);
        let sin = axis.norm();
        if sin == 0.0 {
            return;
        }
        s.q *= so3::exp(&(axis * (sin.atan2(t.dot(&q3)) / sin)));
    }
}
