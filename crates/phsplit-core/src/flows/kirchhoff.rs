//! Flow S1 of a rigid body in an ideal fluid with a general mass matrix (docs/model.md
//! §3.8): Kirchhoff's equations on se(3)*, with the attitude on SO(3).
//!
//! With body-frame momenta `u = (p, m) = M ν`, `ν = (v, ω)`, `M = M_RB + M_A` symmetric positive
//! definite (rigid-body mass with its centre of gravity anywhere, plus added mass, any coupling),
//! the conservative part of the motion is
//!
//! ```text
//! p' = p × ω,     m' = m × ω + p × v,     Q' = Q ω̂,     ν = M⁻¹ u
//! ```
//!
//! (G. Kirchhoff 1869; the Lie–Poisson equations of se(3)*, e.g. J. E. Marsden, T. S. Ratiu,
//! *Introduction to Mechanics and Symmetry*, 2nd ed., Springer 1999, §1.4; Fossen's `C(ν)ν`
//! derived from `M`, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed., 2021,
//! §3.3 and §6.3). It conserves the kinetic energy `H = ½ uᵀM⁻¹u` and the Casimirs `|p|²` and
//! `p·m`. With the paper's `M = diag(mv I, T)` the term `p × v` vanishes and the momentum flow is
//! the free rigid body's, which `rigid_body.rs` solves exactly; a general `M` has no such closed
//! form.
//!
//! **The method.** The momenta by Gauss collocation with `s` stages (order `2s`), which keeps
//! every quadratic first integral exactly (E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical
//! Integration*, 2nd ed., Springer 2006, Theorem IV.2.2): `H` and both Casimirs, to the solve's
//! tolerance and round-off. The stage equations are solved by Newton's method with the exact
//! Jacobian (the field is quadratic in `u`), kept factorised while the iteration contracts by 10
//! or more a pass; a slow rotation (`h|ω|` small) is left to functional iteration while that
//! contracts by 10 a pass. The attitude by the Runge–Kutta–Munthe-Kaas method
//! with the same Gauss coefficients (H. Munthe-Kaas, *BIT* 38 (1998) 92–111), on the body
//! angular velocities of the stages: `Q1 = Q0 exp(Ω̂)` with
//! `Ω_i = h Σ_j a_ij dexp⁻¹_{−Ω_j}(ω_j)`, `Ω = h Σ_j b_j dexp⁻¹_{−Ω_j}(ω_j)` and the closed form
//! of `dexp⁻¹` on so(3); order `2s`, and `Q` stays on SO(3) to round-off.

// Stage loops index the Butcher tableau `a_ij`, `b_i` as the formulas above write them.
#![allow(clippy::needless_range_loop)]

use crate::error::{Error, Result};
use crate::flows::collocation::tableau;
use crate::lie::so3;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

type V6 = SVector<f64, 6>;
type M6 = SMatrix<f64, 6, 6>;

/// Most Newton iterations (and fixed-point passes of the attitude) per step. Newton's method
/// converges for `h|ω|` up to about 1; longer steps give `None`.
const MAX_NEWTON: usize = 30;

/// Kirchhoff's equations for a mass matrix `M` (stored as `M⁻¹`).
#[derive(Debug, Clone, PartialEq)]
pub struct Kirchhoff {
    pub minv: M6,
}

impl Kirchhoff {
    /// The flow of a body with the mass matrix `m` (symmetric positive definite, checked:
    /// symmetric to 1e-12 relative, and the smallest eigenvalue positive).
    pub fn new(m: &M6) -> Result<Self> {
        let scale = m.amax();
        if !m.iter().all(|x| x.is_finite())
            || scale <= 0.0
            || (m - m.transpose()).amax() > 1e-12 * scale
        {
            return Err(Error::InvalidInput(
                "the mass matrix M must be symmetric and finite".into(),
            ));
        }
        let ev = m.symmetric_eigenvalues();
        let min = ev.min();
        if min <= 0.0 {
            return Err(Error::InvalidInput(format!(
                "the mass matrix M must be positive definite; its smallest eigenvalue is {min:e}"
            )));
        }
        let minv = m
            .try_inverse()
            .ok_or_else(|| Error::InvalidInput("the mass matrix M is singular".into()))?;
        Ok(Self {
            minv: (minv + minv.transpose()) * 0.5,
        })
    }

    /// The kinetic energy `½ uᵀM⁻¹u`.
    pub fn energy(&self, u: &V6) -> f64 {
        0.5 * u.dot(&(self.minv * u))
    }

    /// The field `u' = (p × ω, m × ω + p × v)`.
    pub fn field(&self, u: &V6) -> V6 {
        let nu = self.minv * u;
        let (p, m) = (u.fixed_rows::<3>(0), u.fixed_rows::<3>(3));
        let (v, w) = (nu.fixed_rows::<3>(0), nu.fixed_rows::<3>(3));
        let mut f = V6::zeros();
        f.fixed_rows_mut::<3>(0).copy_from(&p.cross(&w));
        f.fixed_rows_mut::<3>(3)
            .copy_from(&(m.cross(&w) + p.cross(&v)));
        f
    }

    /// The Jacobian of [`Self::field`] at `u`.
    fn jacobian(&self, u: &V6) -> M6 {
        let nu = self.minv * u;
        let p: Vector3<f64> = u.fixed_rows::<3>(0).into_owned();
        let m: Vector3<f64> = u.fixed_rows::<3>(3).into_owned();
        let v: Vector3<f64> = nu.fixed_rows::<3>(0).into_owned();
        let w: Vector3<f64> = nu.fixed_rows::<3>(3).into_owned();
        // d(p × ω) = −ω̂ dp + p̂ dω;  d(m × ω + p × v) = −ω̂ dm − v̂ dp + m̂ dω + p̂ dv.
        let mut direct = M6::zeros();
        direct
            .fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&-so3::hat(&w));
        direct
            .fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&-so3::hat(&v));
        direct
            .fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&-so3::hat(&w));
        let mut through = M6::zeros();
        through
            .fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&so3::hat(&p));
        through
            .fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&so3::hat(&p));
        through
            .fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&so3::hat(&m));
        direct + through * self.minv
    }

    /// The stages `Y_i = u0 + h Σ_j a_ij f(Y_j)` by Newton's method with the exact Jacobian
    /// (`NS = 6s`), or `None` if it does not converge.
    fn stages<const NS: usize>(
        &self,
        u0: &V6,
        h: f64,
        s: usize,
        a: &[[f64; 3]; 3],
    ) -> Option<[V6; 3]>
    where
        nalgebra::Const<NS>: nalgebra::DimMin<nalgebra::Const<NS>, Output = nalgebra::Const<NS>>,
    {
        let mut y = [*u0; 3];
        let mut lu: Option<nalgebra::linalg::LU<f64, nalgebra::Const<NS>, nalgebra::Const<NS>>> =
            None;
        let mut last_step = f64::INFINITY;
        // Functional iteration while it contracts by 10 a pass (a slow rotation: its rate is
        // about h|ω|), then Newton's method.
        let mut newton = false;
        for _ in 0..MAX_NEWTON {
            let f: [V6; 3] = std::array::from_fn(|i| {
                if i < s {
                    self.field(&y[i])
                } else {
                    V6::zeros()
                }
            });
            if !newton {
                let mut size: f64 = 0.0;
                let mut step: f64 = 0.0;
                for i in 0..s {
                    let mut yi = *u0;
                    for j in 0..s {
                        yi += f[j] * (h * a[i][j]);
                    }
                    step = step.max((yi - y[i]).amax());
                    size = size.max(yi.amax());
                    y[i] = yi;
                }
                if !step.is_finite() {
                    return None;
                }
                if step <= 2.0 * f64::EPSILON * size.max(f64::MIN_POSITIVE) {
                    return Some(y);
                }
                newton = step > 0.1 * last_step;
                last_step = step;
                continue;
            }
            let mut res = SVector::<f64, NS>::zeros();
            for i in 0..s {
                let mut r = y[i] - u0;
                for j in 0..s {
                    r -= f[j] * (h * a[i][j]);
                }
                res.fixed_rows_mut::<6>(6 * i).copy_from(&r);
            }
            // The Jacobian is refactorised only when the iteration does not contract fast
            // (simplified Newton otherwise: E. Hairer, G. Wanner, *Solving ODEs II*, §IV.8).
            if lu.is_none() {
                let mut jac = SMatrix::<f64, NS, NS>::identity();
                for j in 0..s {
                    let jf = self.jacobian(&y[j]);
                    for i in 0..s {
                        let mut blk = jac.fixed_view_mut::<6, 6>(6 * i, 6 * j);
                        blk -= jf * (h * a[i][j]);
                    }
                }
                lu = Some(jac.lu());
            }
            let dy = lu.as_ref()?.solve(&res)?;
            let mut size: f64 = 0.0;
            let mut step: f64 = 0.0;
            for i in 0..s {
                let d = dy.fixed_rows::<6>(6 * i);
                y[i] -= d;
                size = size.max(y[i].amax());
                step = step.max(d.amax());
            }
            // f64::max drops NaN: check the update itself.
            if !dy.iter().all(|x| x.is_finite()) {
                return None;
            }
            if step <= 2.0 * f64::EPSILON * size.max(f64::MIN_POSITIVE) {
                return Some(y);
            }
            if step > 0.1 * last_step {
                lu = None;
            }
            last_step = step;
        }
        None
    }

    /// One step of length `h` with `s` Gauss stages (1 to 3; order `2s`): the momenta `u` and
    /// the attitude `q`. `None` if Newton's method does not converge (a step far too long).
    pub fn flow(&self, u0: &V6, q0: &Matrix3<f64>, h: f64, s: usize) -> Option<(V6, Matrix3<f64>)> {
        if !(1..=3).contains(&s) || !u0.iter().all(|x| x.is_finite()) || !h.is_finite() {
            return None;
        }
        let (a, b) = tableau(s);
        // Stages Y_i, from u0, by Newton's method on a stage system sized to the stages.
        let y = match s {
            1 => self.stages::<6>(u0, h, 1, &a)?,
            2 => self.stages::<12>(u0, h, 2, &a)?,
            _ => self.stages::<18>(u0, h, 3, &a)?,
        };
        let f: [V6; 3] = std::array::from_fn(|i| {
            if i < s {
                self.field(&y[i])
            } else {
                V6::zeros()
            }
        });
        let mut u1 = *u0;
        for i in 0..s {
            u1 += f[i] * (h * b[i]);
        }
        // The attitude: RKMK with the stages' body angular velocities.
        let w: [Vector3<f64>; 3] = std::array::from_fn(|i| {
            if i < s {
                (self.minv * y[i]).fixed_rows::<3>(3).into_owned()
            } else {
                Vector3::zeros()
            }
        });
        let mut om = [Vector3::zeros(); 3];
        for i in 0..s {
            for j in 0..s {
                om[i] += w[j] * (h * a[i][j]);
            }
        }
        let mut attitude_converged = false;
        for _ in 0..MAX_NEWTON {
            let d: [Vector3<f64>; 3] = std::array::from_fn(|j| dexpinv_neg(&om[j], &w[j]));
            let mut change: f64 = 0.0;
            let mut size: f64 = 0.0;
            for i in 0..s {
                let mut o = Vector3::zeros();
                for j in 0..s {
                    o += d[j] * (h * a[i][j]);
                }
                change = change.max((o - om[i]).amax());
                size = size.max(o.amax());
                om[i] = o;
            }
            if change <= 2.0 * f64::EPSILON * size.max(f64::MIN_POSITIVE) {
                attitude_converged = true;
                break;
            }
        }
        // The attitude's stage equations contract at the rate `h|ω|/2`: a step too long for
        // them is refused, not returned unconverged.
        if !attitude_converged {
            return None;
        }
        let mut omega = Vector3::zeros();
        for j in 0..s {
            omega += dexpinv_neg(&om[j], &w[j]) * (h * b[j]);
        }
        let q1 = q0 * so3::exp(&omega);
        Some((u1, q1))
    }
}

/// `dexp⁻¹_{−X}(Y) = Y + ½ X × Y + c(θ) X × (X × Y)`, `c(θ) = (1 − (θ/2) cot(θ/2)) / θ²`,
/// `θ = |X|`: the right-trivialised inverse derivative of the exponential on so(3), for
/// `Q = Q0 exp(X̂)` with `Q' = Q ω̂` (`X' = dexp⁻¹_{−X}(ω)`).
fn dexpinv_neg(x: &Vector3<f64>, y: &Vector3<f64>) -> Vector3<f64> {
    let t2 = x.norm_squared();
    let c = if t2 < 1e-4 {
        // the series 1/12 + θ²/720 + θ⁴/30240 (next term θ⁶/1209600 < 1e-18)
        1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
    } else {
        let t = t2.sqrt();
        (1.0 - 0.5 * t / (0.5 * t).tan()) / t2
    };
    let xy = x.cross(y);
    y + xy * 0.5 + x.cross(&xy) * c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flows::rigid_body::{FreeRigidBody, MagnusOrder};

    /// A mass matrix with every coupling: a body with its centre of gravity off the origin
    /// (`M_RB` of Fossen's eq. 3.44) plus a symmetric positive definite added mass.
    pub(crate) fn coupled_mass() -> M6 {
        let mass = 6.0e6;
        let rg = Vector3::new(-2.0, 0.5, 1.5);
        let ig = Matrix3::new(
            3.0e8, 1.0e6, -2.0e6, 1.0e6, 2.8e9, 3.0e6, -2.0e6, 3.0e6, 2.9e9,
        );
        let s = so3::hat(&rg);
        let mut m = M6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * mass));
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-s * mass));
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(s * mass));
        m.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(ig - s * s * mass));
        // Added mass: diagonal plus a sway–yaw, surge–pitch and heave–pitch coupling.
        let mut ma = M6::from_diagonal(&V6::new(3.0e5, 4.0e6, 8.0e6, 5.0e7, 1.5e9, 1.0e9));
        for (i, j, x) in [(1, 5, -2.0e7), (0, 4, 1.0e6), (2, 4, 3.0e7)] {
            ma[(i, j)] = x;
            ma[(j, i)] = x;
        }
        m + ma
    }

    fn start() -> (V6, Matrix3<f64>) {
        let u = V6::new(3.0e6, -2.0e6, 5.0e5, 4.0e7, -6.0e7, 9.0e7);
        (u, so3::from_euler_zyx(&Vector3::new(0.1, -0.05, 0.7)))
    }

    /// RK4 on `(u, Q)` with the field written out here, at a tiny step: the reference.
    fn reference(
        k: &Kirchhoff,
        u0: &V6,
        q0: &Matrix3<f64>,
        t: f64,
        n: usize,
    ) -> (V6, Matrix3<f64>) {
        let f = |u: &V6, q: &Matrix3<f64>| -> (V6, Matrix3<f64>) {
            let nu = k.minv * u;
            let p = Vector3::new(u[0], u[1], u[2]);
            let m = Vector3::new(u[3], u[4], u[5]);
            let v = Vector3::new(nu[0], nu[1], nu[2]);
            let w = Vector3::new(nu[3], nu[4], nu[5]);
            let dp = p.cross(&w);
            let dm = m.cross(&w) + p.cross(&v);
            (
                V6::new(dp.x, dp.y, dp.z, dm.x, dm.y, dm.z),
                q * so3::hat(&w),
            )
        };
        let h = t / n as f64;
        let (mut u, mut q) = (*u0, *q0);
        for _ in 0..n {
            let (k1, l1) = f(&u, &q);
            let (k2, l2) = f(&(u + k1 * (h / 2.0)), &(q + l1 * (h / 2.0)));
            let (k3, l3) = f(&(u + k2 * (h / 2.0)), &(q + l2 * (h / 2.0)));
            let (k4, l4) = f(&(u + k3 * h), &(q + l3 * h));
            u += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
            q += (l1 + l2 * 2.0 + l3 * 2.0 + l4) * (h / 6.0);
        }
        (u, q)
    }

    #[test]
    fn converges_at_order_2s_against_a_fine_reference() {
        let k = Kirchhoff::new(&coupled_mass()).unwrap();
        let (u0, q0) = start();
        let t = 8.0;
        let (ur, qr) = reference(&k, &u0, &q0, t, 40_000);
        for s in 1..=3 {
            let mut errs = Vec::new();
            let hs = [2.0, 1.0, 0.5, 0.25];
            for h in hs {
                let (mut u, mut q) = (u0, q0);
                for _ in 0..(t / h) as usize {
                    (u, q) = k.flow(&u, &q, h, s).unwrap();
                }
                let e = ((u - ur).norm() / ur.norm()).max((q - qr).norm());
                errs.push(e);
            }
            let slope = (errs[1].ln() - errs[3].ln()) / 2f64.ln() / 2.0;
            let want = 2.0 * s as f64;
            if errs[3] > 1e-12 {
                assert!(
                    (slope - want).abs() < 0.25,
                    "s = {s}: slope {slope}, errors {errs:?}"
                );
            } else {
                let slope = (errs[0].ln() - errs[2].ln()) / 2f64.ln() / 2.0;
                assert!(
                    (slope - want).abs() < 0.4,
                    "s = {s}: slope {slope}, errors {errs:?}"
                );
            }
        }
    }

    /// `H` and the Casimirs to 1e-13 relative over 10^5 steps of 1 s (measured: `H` 5.6e-14,
    /// `|p|²` 3.1e-14, a random walk of round-off), and `Q` on SO(3).
    #[test]
    fn conserves_energy_and_casimirs_and_stays_on_so3() {
        let k = Kirchhoff::new(&coupled_mass()).unwrap();
        let (mut u, mut q) = start();
        let (h0, c1, c2) = (
            k.energy(&u),
            u.fixed_rows::<3>(0).norm_squared(),
            u.fixed_rows::<3>(0).dot(&u.fixed_rows::<3>(3)),
        );
        // The measure of the requirement: 10^5 steps of h = 1 s.
        for _ in 0..100_000 {
            (u, q) = k.flow(&u, &q, 1.0, 2).unwrap();
        }
        let p = u.fixed_rows::<3>(0);
        assert!(
            (k.energy(&u) - h0).abs() <= 1e-13 * h0,
            "{}",
            (k.energy(&u) - h0) / h0
        );
        assert!((p.norm_squared() - c1).abs() <= 1e-13 * c1);
        assert!(
            (p.dot(&u.fixed_rows::<3>(3)) - c2).abs()
                <= 1e-12 * c1.sqrt() * u.fixed_rows::<3>(3).norm()
        );
        assert!(so3::orthogonality_defect(&q) < 1e-13);
    }

    /// With the paper's mass matrix `diag(mv I, T)` the flow is the free rigid body's, which
    /// rigid_body.rs solves exactly: the two agree at the method's order.
    #[test]
    fn with_an_isotropic_mass_it_is_the_free_rigid_body() {
        let (mass, inertia) = (6.3622085e6, Vector3::new(2.873071e8, 2.726143e9, 2.9e9));
        let mut m = M6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * mass));
        m.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&Matrix3::from_diagonal(&inertia));
        let k = Kirchhoff::new(&m).unwrap();
        let frb = FreeRigidBody::new(inertia).unwrap();
        let (u0, q0) = start();
        let m0 = Vector3::new(u0[3], u0[4], u0[5]);
        let p0 = Vector3::new(u0[0], u0[1], u0[2]);
        let t = 6.0;
        let (mut me, mut qe) = (m0, q0);
        for _ in 0..600 {
            (me, qe) = frb.flow(&me, &qe, 0.01, MagnusOrder::Six);
        }
        let pe = qe.transpose() * (q0 * p0);
        let mut last = f64::INFINITY;
        for n in [6usize, 12, 24] {
            let h = t / n as f64;
            let (mut u, mut q) = (u0, q0);
            for _ in 0..n {
                (u, q) = k.flow(&u, &q, h, 3).unwrap();
            }
            let e = (Vector3::new(u[3], u[4], u[5]) - me).norm() / me.norm()
                + (Vector3::new(u[0], u[1], u[2]) - pe).norm() / pe.norm()
                + (q - qe).norm();
            assert!(e < last / 30.0 || e < 1e-12, "n = {n}: {e} after {last}");
            last = e;
        }
    }

    #[test]
    fn non_finite_inputs_and_steps_too_long_give_none() {
        let k = Kirchhoff::new(&coupled_mass()).unwrap();
        let (u0, q0) = start();
        let mut bad = u0;
        bad[2] = f64::NAN;
        assert!(k.flow(&bad, &q0, 0.5, 2).is_none());
        assert!(k.flow(&u0, &q0, 0.5, 4).is_none());
        // Far beyond h|ω| ~ 1: refused rather than returned unconverged.
        let fast = u0 * 200.0;
        assert!(k.flow(&fast, &q0, 50.0, 2).is_none());
        let mut m = coupled_mass();
        m[(0, 0)] = f64::NAN;
        assert!(Kirchhoff::new(&m).is_err());
    }

    #[test]
    fn bad_mass_matrices_are_refused_with_the_eigenvalue() {
        let mut m = coupled_mass();
        m[(1, 5)] += 1.0e6;
        assert!(Kirchhoff::new(&m)
            .unwrap_err()
            .to_string()
            .contains("symmetric"));
        let mut m = coupled_mass();
        m[(2, 2)] = -1.0;
        let e = Kirchhoff::new(&m).unwrap_err().to_string();
        assert!(
            e.contains("positive definite") && e.contains("smallest eigenvalue"),
            "{e}"
        );
    }
}
