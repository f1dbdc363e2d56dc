//! Hydrostatic restoring forces in the paper's energy-consistent form (paper §3.4, eqs. 35–39;
//! docs/model.md §2, §5).
//!
//! Heave: the force `−Qᵀ Λ x`, `Λ = diag(0, 0, c)`, `c = g ρ A_wp`. Roll and pitch: the moment
//! `−mu × q3` with the restoring variable `mu` (= `G Qᵀe3` on exact solutions),
//! `mu' = −G (w × q3)`, `G = mv g diag(GM_L, GM_T, 0)`. Both are conservative exchanges between
//! the kinetic energy and the stored energy `½ muᵀG⁺mu + ½ c x_z²`, which this component adds
//! to H: nothing is booked in the ledger. Flow S2.
//!
//! With the centre of flotation at `r_F = (x_F, y_F, 0)` (`vessel.flotation_center_x`,
//! `flotation_center_y`, default 0) the heave spring acts there: `V = ½ c (z + r_F·q3)² +
//! ½ q3ᵀ G q3`. For small angles this is Fossen's restoring matrix moved from the centre of
//! flotation, `G_CO = H(r_F)ᵀ G_CF H(r_F)` (Fossen 2021, §4.2): in phsplit's z-up frame
//! `G33 = c`, `G34 = y_F c`, `G35 = −x_F c`, `G44 = mv g GM_T + y_F² c`, `G45 = −x_F y_F c`,
//! `G55 = mv g GM_L + x_F² c`; `y_F ≠ 0` is a hull that is not port–starboard symmetric. In the
//! energy-consistent form (docs/model.md §5.15) `mu = G' q3 + z c r_F` with
//! `G' = G + c r_F r_Fᵀ` (its roll–pitch block full when `x_F y_F ≠ 0`); the store is
//! `½ c' z² + ½ muᵀG'⁺mu` with `c' = c − c² r_Fᵀ G'⁺ r_F > 0`, the heave force
//! `−q3 (c' z + c r_Fᵀ G'⁺ mu)`, and `mu' = G' hat(q3) ω + c r_F q3ᵀ v`: the coupling joins the
//! translation and rotation of flow S2 (one coupled system).

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::lie::so3;
use crate::model::vessel::params::{physical, Params, Range};
use crate::model::vessel::state::VesselState;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// The smallest turn of the attitude the projection onto the restoring invariant makes (rad,
/// as `sin θ`): `4 ε`. The entries of `q3 = Qᵀe3` carry absolute round-off of a few `ε` from
/// every update of `Q` (flow S1, the projection itself), so a smaller turn corrects nothing that
/// `Q` holds. Below it the projection leaves `Q` alone: the invariant then holds to `4 ε` in
/// `q3`, i.e. `|c| ≤ 4 ε ‖G‖` (docs/model.md §3.6).
pub const PROJECTION_FLOOR: f64 = 4.0 * f64::EPSILON;

#[derive(Debug, Clone, PartialEq)]
pub struct Restoring {
    /// `G' = G + c r_F r_Fᵀ` (roll–pitch block; row and column 3 zero), N m.
    pub g: Matrix3<f64>,
    /// Its pseudo-inverse (the inverse of the roll–pitch block).
    pub g_plus: Matrix3<f64>,
    /// Heave stiffness `c = g ρ A_wp`, N/m.
    pub heave: f64,
    /// `c r_F` (N): the heave spring's lever at the centre of flotation, in `mu = G' q3 + z c r_F`.
    pub coupling: Vector3<f64>,
    /// The heave stiffness of the store, `c' = c − (c r_F)ᵀ G'⁺ (c r_F)` (`= c` without a
    /// coupling), N/m.
    pub heave_store: f64,
}

/// Keys `vessel.gm_transverse`, `gm_longitudinal` (m), `gravity` (m/s²), `water_density`
/// (kg/m³), `waterplane_area` (m²): all required, > 0; `flotation_center_x`,
/// `flotation_center_y` (m, body frame, default 0, within ±1000 m).
pub fn build(p: &mut Params, body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    let gm = Range::Physical(&physical::METACENTRIC_HEIGHT);
    let gm_t = p.f64("vessel", "gm_transverse", "m", gm)?;
    let gm_l = p.f64("vessel", "gm_longitudinal", "m", gm)?;
    let gravity = p.f64(
        "vessel",
        "gravity",
        "m/s^2",
        Range::Physical(&physical::GRAVITY),
    )?;
    let rho = p.f64(
        "vessel",
        "water_density",
        "kg/m^3",
        Range::Physical(&physical::WATER_DENSITY),
    )?;
    let awp = p.f64("vessel", "waterplane_area", "m^2", Range::Positive)?;
    let mut rf = Vector3::zeros();
    for (i, key) in ["flotation_center_x", "flotation_center_y"]
        .iter()
        .enumerate()
    {
        let v = p.opt_f64("vessel", key, "m", Range::Finite)?.unwrap_or(0.0);
        if v.abs() > 1000.0 {
            return Err(crate::error::Error::InvalidInput(format!(
                "vessel.{key} must lie within ±1000 m of the body origin (m, body frame), got {v}"
            )));
        }
        rf[i] = v;
    }
    let w = body.mass * gravity;
    let c = gravity * rho * awp;
    let g =
        Matrix3::from_diagonal(&Vector3::new(w * gm_l, w * gm_t, 0.0)) + rf * rf.transpose() * c;
    // The inverse of the roll–pitch block [[a, b], [b, d]] (positive definite for positive
    // metacentric heights), written out so that a diagonal block gives exactly 1/a and 1/d.
    let (a, b, d) = (g[(0, 0)], g[(0, 1)], g[(1, 1)]);
    let det = a * d - b * b;
    if !(a > 0.0 && d > 0.0 && det > 0.0 && (d / det).is_finite() && (a / det).is_finite()) {
        return Err(crate::error::Error::InvalidInput(format!(
            "vessel.gm_longitudinal, gm_transverse and flotation_center_x, flotation_center_y give a roll–pitch restoring matrix that is singular to working precision (G'11 = {a:e}, G'12 = {b:e}, G'22 = {d:e} N m); give metacentric heights of a floating hull (centimetres to hundreds of metres)"
        )));
    }
    let mut g_plus = Matrix3::zeros();
    if b == 0.0 {
        (g_plus[(0, 0)], g_plus[(1, 1)]) = (1.0 / a, 1.0 / d);
    } else {
        (g_plus[(0, 0)], g_plus[(1, 1)]) = (d / det, a / det);
        (g_plus[(0, 1)], g_plus[(1, 0)]) = (-b / det, -b / det);
    }
    let coupling = rf * c;
    Ok(Some(Arc::new(Restoring {
        g,
        g_plus,
        heave: c,
        coupling,
        // c − c² r_Fᵀ G'⁻¹ r_F > 0 (with G' = G + c r r_Fᵀ, by the Sherman–Morrison formula
        // c / (1 + c r_Fᵀ G⁻¹ r_F)).
        heave_store: c - coupling.dot(&(g_plus * coupling)),
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
        b.rate_v(Sys::Rot, Sys::Rot, &(self.g * hq3));
        if self.coupling != Vector3::zeros() {
            // The heave force's part −q3 (c r_F)ᵀ G'⁺ mu, and mu' = … + c r_F q3ᵀ v.
            let lever = self.g_plus * self.coupling;
            b.force_from_other_v(Sys::Trans, None, &(fr.q3 * lever.transpose() * -1.0));
            b.rate_v(Sys::Rot, Sys::Trans, &(self.coupling * fr.q3.transpose()));
        }
    }
    fn storage(&self, s: &VesselState) -> f64 {
        let (gp, mu) = (&self.g_plus, &s.mu);
        let quad = mu.component_mul(mu).dot(&gp.diagonal()) + 2.0 * mu.x * mu.y * gp[(0, 1)];
        0.5 * quad + 0.5 * self.heave_store * s.x.z * s.x.z
    }
    fn init_state(&self, s: &mut VesselState) {
        s.mu = self.g * (s.q.transpose() * Vector3::z()) + self.coupling * s.x.z;
    }
    /// The invariant `c = mu − G Qᵀe3` (zero from a consistent start) is kept by the exact flow
    /// and by every Runge–Kutta method (it is linear in the Runge–Kutta variables), but not by
    /// the split: S1 turns `Q` without `mu`, S2 moves `mu` at frozen `Q`. Its drift leaves the
    /// vessel at rest with a false heel and trim (docs/model.md §3.6). The projection turns the
    /// attitude by the smallest rotation `E` that gives `G' Qᵀe3 = mu − z c r_F` again
    /// (`Q ← Q E`, `E t = q3` with `(t₁, t₂) = G'⁺(mu − z c r_F)`, `t₃ = ±√(1 − t₁² − t₂²)`), and
    /// leaves `mu` alone: H does not depend on `Q`, so the projection neither creates nor removes
    /// energy and the ledger books nothing. Beyond 90° of heel (no such `t`) it does nothing.
    fn project(&self, s: &mut VesselState) {
        if !(self.g[(0, 0)] > 0.0 && self.g[(1, 1)] > 0.0) {
            return;
        }
        let q3 = s.q.transpose() * Vector3::z();
        let r = s.mu - self.coupling * s.x.z;
        let (t0, t1) = if self.g[(0, 1)] == 0.0 {
            (r.x / self.g[(0, 0)], r.y / self.g[(1, 1)])
        } else {
            let txy = self.g_plus * r;
            (txy.x, txy.y)
        };
        let r2 = t0 * t0 + t1 * t1;
        if !(r2 < 1.0) {
            return;
        }
        let t = Vector3::new(t0, t1, (1.0 - r2).sqrt().copysign(q3.z));
        // `E` turns `t` into `q3`: about `t × q3 = sin θ k` by `θ`.
        let axis = t.cross(&q3);
        let (sin, cos) = (axis.norm(), t.dot(&q3));
        if sin == 0.0 || (sin <= PROJECTION_FLOOR && cos > 0.0) {
            // Within the round-off of `q3` itself: the turn would only stir the last bits of
            // `Q` (and make the next step assemble flow S2 anew for nothing). `sin = 0` with
            // `cos < 0` (`t = −q3`) has no axis; it cannot occur (`t₃` takes `q3`'s sign), and
            // is left alone, as before the floor, rather than turned by 0·π/0.
            return;
        }
        s.q *= if cos > -0.5 {
            // Rodrigues' formula on the unit axis–sine `v/n` and cosine `cos/n`, with
            // `n = |t||q3| = √(sin² + cos²)`: `E = I + [v]×/n + [v]×²/(n(n + cos θ))`, no angle
            // and no trigonometry (well conditioned below 120°). Dividing by `n` keeps `E` a
            // rotation although `q3` is unit only to `Q`'s round-off; without it each turn
            // multiplied that error by `2/(1 + cos θ)`, and large turns (steps far beyond
            // stability, a tumbling vessel) drove `Q` off the rotations (found by a review).
            let n = (sin * sin + cos * cos).sqrt();
            let v = so3::hat(&axis);
            Matrix3::identity() + v / n + v * v / (n * (n + cos))
        } else {
            so3::exp(&(axis * (sin.atan2(cos) / sin)))
        };
    }
}
