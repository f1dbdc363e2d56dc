//! Cross-flow drag: the nonlinear sway and yaw damping of a hull by strip theory
//! (docs/model.md §5.12). T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion
//! Control*, 2nd ed., Wiley 2021, §6.4.3 (after Faltinsen 1990):
//!
//! ```text
//! Y = −½ ρ ∫ T C_d |v_r + x r| (v_r + x r) dx,     N = −½ ρ ∫ x T C_d |v_r + x r| (v_r + x r) dx
//! ```
//!
//! over the hull's length `x ∈ [x_aft, x_fore]` (body frame, from the body origin), with the
//! draught `T` and the 2-D drag coefficient `C_d` constant along it (Fossen takes `C_d` from
//! Hoerner's curve of `B/(2T)`; give the value), `v_r` the sway velocity relative to the water.
//!
//! Table `[crossflow_drag]` (optional): `draft` (m, in (0, 40], `params::physical::DRAFT`), `drag_coefficient` (> 0, ≤ 5),
//! `x_aft`, `x_fore` (m, body x of the hull's ends, `x_aft < x_fore`, within ±1000 m). The water
//! density is the vessel's (`vessel.water_density`).
//!
//! **The integrals are exact.** With `s(x) = a + b x` (`a = v_r`, `b = r`), `|s| s` is `±s²` on
//! each side of its zero, so each integral is a sum of polynomial integrals over at most two
//! pieces: no quadrature error, no cancellation near `r = 0` (tested against a fine midpoint sum).
//!
//! **Energy.** The power of the drag on the body's own velocity, `v Y + r N = −½ρ T C_d ∫ |s|³ dx
//! ≤ 0`, is booked as the dissipation `crossflow_drag`. With a current the drag acts on the
//! relative velocity; the difference from the drag on the body's own velocity is booked as the
//! current's work through this hull, the port `crossflow_current` (supplied; either sign).
//!
//! **In flow S2** it is a forcing (Gauss collocation at the stages, §3.7, whose energy balance
//! is exact for the quadratic `H`, the dissipation booked `≥ 0` at the stages). Its Jacobian at
//! the sub-step's start, `−2k ∫|s| [1, x; x, x²] dx` (symmetric, negative semidefinite: a linear
//! damping), is put in the implicit rows and taken out of the forcing (their sum is the force),
//! which keeps the fixed point contractive at long steps and leaves it only the drag's
//! second-order remainder. Its sway–yaw terms join translation and rotation (flow S2 is then
//! one coupled system, docs/model.md §5.14, which a forced S2 is solved as anyway).

use super::current::Current;
use super::{Force, Forcing, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::vessel::params::{physical, Params, Range};
use crate::solve::Account;
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct CrossflowDrag {
    /// `½ ρ T C_d`, kg/m².
    pub k: f64,
    pub x_aft: f64,
    pub x_fore: f64,
    /// The current, if the vessel has one (the drag acts on the relative velocity).
    pub current: Option<Current>,
}

/// Largest hull coordinate accepted (m).
const MAX_X: f64 = 1000.0;

pub fn build(p: &mut Params, body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "crossflow_drag";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let draft = p.f64(T, "draft", "m", Range::Physical(&physical::DRAFT))?;
    let cd = p.f64(
        T,
        "drag_coefficient",
        "2-D cross-flow drag coefficient",
        Range::Positive,
    )?;
    if cd > 5.0 {
        return Err(Error::InvalidInput(format!(
            "crossflow_drag.drag_coefficient must be at most 5 (Hoerner's 2-D coefficients are 0.5 to 2), got {cd}"
        )));
    }
    let x_aft = p.f64(T, "x_aft", "m, body frame", Range::Finite)?;
    let x_fore = p.f64(T, "x_fore", "m, body frame", Range::Finite)?;
    if x_aft >= x_fore || x_aft.abs() > MAX_X || x_fore.abs() > MAX_X {
        return Err(Error::InvalidInput(format!(
            "crossflow_drag.x_aft and x_fore must satisfy x_aft < x_fore and lie within ±{MAX_X} m of the body origin (m, body frame), got x_aft = {x_aft}, x_fore = {x_fore}"
        )));
    }
    let rho = p.f64("vessel", "water_density", "kg/m^3", Range::Positive)?;
    let current = super::current::read(p, body)?;
    Ok(Some(Arc::new(CrossflowDrag {
        k: 0.5 * rho * draft * cd,
        x_aft,
        x_fore,
        current,
    })))
}

const ACCOUNTS: [Account; 2] = [
    Account::dissipated("crossflow_drag"),
    Account::supplied("crossflow_current"),
];

/// On one piece `[x1, x2]` where `s = a + b x` keeps its sign: `(∫s², ∫x s², ∫s, ∫x² s, ∫x s)`,
/// expanded in the moments `m_e = (x2^e − x1^e)/e` (exact polynomial integrals, no division by
/// `b`: no cancellation as `b → 0`).
fn piece(a: f64, b: f64, x1: f64, x2: f64) -> [f64; 5] {
    let (p1, q1) = (x1, x2);
    let (p2, q2) = (p1 * x1, q1 * x2);
    let (p3, q3) = (p2 * x1, q2 * x2);
    let (p4, q4) = (p3 * x1, q3 * x2);
    let m = [q1 - p1, (q2 - p2) / 2.0, (q3 - p3) / 3.0, (q4 - p4) / 4.0];
    let (aa, ab, bb) = (a * a, 2.0 * a * b, b * b);
    [
        aa * m[0] + ab * m[1] + bb * m[2],
        aa * m[1] + ab * m[2] + bb * m[3],
        a * m[0] + b * m[1],
        a * m[2] + b * m[3],
        a * m[1] + b * m[2],
    ]
}

/// The strip integrals of `s = a + b x` over `[x1, x2]`:
/// `(∫|s|s, ∫x|s|s, ∫|s|, ∫x²|s|, ∫x|s|)`, exact: `|s|s = ±s²` and `|s| = ±s` on each side of the
/// zero `x0 = −a/b`, so the interval is split there.
pub fn strip_integrals(a: f64, b: f64, x1: f64, x2: f64) -> [f64; 5] {
    let x0 = if b != 0.0 { -a / b } else { f64::NAN };
    let split = x0 > x1 && x0 < x2;
    let cuts = if split { [x1, x0, x2] } else { [x1, x2, x2] };
    let mut out = [0.0; 5];
    for w in cuts.windows(2).take(if split { 2 } else { 1 }) {
        let mid = 0.5 * (w[0] + w[1]);
        let sign = (a + b * mid).signum();
        let p = piece(a, b, w[0], w[1]);
        for (o, v) in out.iter_mut().zip(p) {
            *o += sign * v;
        }
    }
    out
}

impl CrossflowDrag {
    /// Sway force and yaw moment (N, N m) at the sway velocity `v` and yaw rate `r`.
    pub fn load(&self, v: f64, r: f64) -> (f64, f64) {
        let i = strip_integrals(v, r, self.x_aft, self.x_fore);
        (-self.k * i[0], -self.k * i[1])
    }

    /// The Jacobian of `(Y, N)` in `(v, r)`, `−2k ∫ |s| [1, x; x, x²] dx`: symmetric and
    /// negative semidefinite (minus a Gram matrix), as `(∂Y/∂v, ∂Y/∂r = ∂N/∂v, ∂N/∂r)`.
    fn jacobian(&self, v: f64, r: f64) -> (f64, f64, f64) {
        let i = strip_integrals(v, r, self.x_aft, self.x_fore);
        let c = -2.0 * self.k;
        (c * i[2], c * i[4], c * i[3])
    }

    /// The sway velocity of the water in the body frame at time `t`.
    fn water_sway(&self, fr: &Frozen, t: f64) -> f64 {
        self.current
            .as_ref()
            .map_or(0.0, |c| (fr.qt * c.velocity_at(t)).y)
    }
}

impl Force for CrossflowDrag {
    fn name(&self) -> &'static str {
        "crossflow_drag"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    /// The drag's Jacobian at the sub-step's start, as implicit rows: a symmetric positive
    /// semidefinite linear damping on `(v, r)` (its sway–yaw terms join translation and rotation).
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        let (dv, dvr, dr) = self.jacobian(fr.velocity[0].y, fr.velocity[1].z);
        let at = |i: usize, j: usize, x: f64| {
            let mut m = Matrix3::zeros();
            m[(i, j)] = x;
            m
        };
        let rows = |t: Matrix3<f64>, r: Matrix3<f64>| Rows {
            fnu: [t, r],
            ..Rows::ZERO
        };
        b.force(Sys::Trans, Some(0), &rows(at(1, 1, dv), at(1, 2, dvr)));
        b.force(Sys::Rot, Some(0), &rows(at(2, 1, dvr), at(2, 2, dr)));
    }
    fn forced(&self) -> bool {
        true
    }
    /// The rest: the drag on the body's own velocity less the implicit rows (account 0), and the
    /// current's part, drag on the relative velocity less that (account 1).
    fn add_forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], g: &mut Forcing) {
        let nu = fr.nu(z);
        let (v, r) = (nu[0].y, nu[1].z);
        let (dv, dvr, dr) = self.jacobian(fr.velocity[0].y, fr.velocity[1].z);
        let (y, n) = self.load(v, r);
        g.force(
            Sys::Trans,
            Some(0),
            Vector3::new(0.0, y - dv * v - dvr * r, 0.0),
        );
        g.force(
            Sys::Rot,
            Some(0),
            Vector3::new(0.0, 0.0, n - dvr * v - dr * r),
        );
        if self.current.is_some() {
            let (yr, nr) = self.load(v - self.water_sway(fr, t), r);
            g.force(Sys::Trans, Some(1), Vector3::new(0.0, yr - y, 0.0));
            g.force(Sys::Rot, Some(1), Vector3::new(0.0, 0.0, nr - n));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact strip integrals against a midpoint sum on 2·10^5 strips.
    #[test]
    fn the_strip_integrals_are_exact() {
        let cases = [
            (0.7, 0.0, -40.0, 36.0),
            (0.0, 0.02, -40.0, 36.0),
            (0.3, -0.02, -40.0, 36.0),  // the zero at x = 15 inside
            (-0.5, 0.004, -40.0, 36.0), // inside at 125: outside the hull
            (1e-9, 1e-3, -40.0, 36.0),
            (0.4, 1e-12, -40.0, 36.0),
        ];
        for (a, b, x1, x2) in cases {
            let n = 200_000;
            let dx = (x2 - x1) / n as f64;
            let mut want = [0.0; 5];
            for i in 0..n {
                let x = x1 + (i as f64 + 0.5) * dx;
                let s: f64 = a + b * x;
                want[0] += s.abs() * s * dx;
                want[1] += x * s.abs() * s * dx;
                want[2] += s.abs() * dx;
                want[3] += x * x * s.abs() * dx;
                want[4] += x * s.abs() * dx;
            }
            let got = strip_integrals(a, b, x1, x2);
            for k in 0..5 {
                let scale = want[k].abs().max(1e-300);
                // the midpoint rule's own error at the kink and of order dx²
                assert!(
                    (got[k] - want[k]).abs() <= 1e-7 * scale + 1e-12,
                    "{a} {b}: {k}: {} vs {}",
                    got[k],
                    want[k]
                );
            }
        }
    }

    /// Drag on a 76 m hull (x from −40 to 36 m) of 5 m draught in sea water, with drag
    /// coefficient `cd`, in still water.
    fn drag(cd: f64) -> CrossflowDrag {
        CrossflowDrag {
            k: 0.5 * 1025.0 * 5.0 * cd,
            x_aft: -40.0,
            x_fore: 36.0,
            current: None,
        }
    }

    /// Pure sway: `Y = −k |v| v L`, `N = −k |v| v (x_f² − x_a²)/2`; and the drag dissipates.
    #[test]
    fn closed_forms_and_dissipation() {
        let d = drag(1.0);
        let (y, n) = d.load(0.8, 0.0);
        assert!((y + d.k * 0.64 * 76.0).abs() < 1e-9 * y.abs());
        assert!(
            (n + d.k * 0.64 * (36.0f64.powi(2) - 40.0f64.powi(2)) / 2.0).abs() < 1e-9 * n.abs()
        );
        for (v, r) in [(0.3, -0.02), (-1.0, 0.05), (0.0, 0.01), (0.5, 0.0)] {
            let (y, n) = d.load(v, r);
            assert!(v * y + r * n <= 0.0);
        }
    }

    /// The Jacobian against central differences of the loads, and symmetric negative
    /// semidefinite.
    #[test]
    fn the_jacobian_is_the_loads_derivative() {
        let d = drag(0.7);
        for (v, r) in [(0.3, -0.02), (-1.0, 0.05), (0.2, 0.0), (0.0, 0.01)] {
            let (dv, dvr, dr) = d.jacobian(v, r);
            let (ev, er) = (1e-6, 1e-8);
            let (yp, np) = d.load(v + ev, r);
            let (ym, nm) = d.load(v - ev, r);
            let (yq, nq) = d.load(v, r + er);
            let (yn, nn) = d.load(v, r - er);
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * a.abs().max(b.abs()).max(1.0);
            assert!(close(dv, (yp - ym) / (2.0 * ev)), "{v} {r}");
            assert!(close(dvr, (yq - yn) / (2.0 * er)), "{v} {r}");
            assert!(close(dvr, (np - nm) / (2.0 * ev)), "{v} {r}");
            assert!(close(dr, (nq - nn) / (2.0 * er)), "{v} {r}");
            assert!(dv <= 0.0 && dr <= 0.0 && dv * dr >= dvr * dvr * (1.0 - 1e-12));
        }
    }
}
