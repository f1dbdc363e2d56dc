//! The hull as a rigid body in a fluid: its 6×6 mass matrix `M = M_RB + M_A` (paper eq. 1;
//! docs/model.md §5.14), read from `[vessel]`.
//!
//! ```text
//! M_RB = [[ m I,       −m S(r_g)            ],
//!         [ m S(r_g),   I_g − m S(r_g)²     ]]
//! ```
//!
//! with `S(r)` the cross-product matrix, `r_g` the centre of gravity in the body frame and `I_g`
//! the inertia about it (T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion
//! Control*, 2nd ed., Wiley 2021, eq. 3.44 with the parallel-axis theorem, eq. 3.37), and `M_A`
//! the added mass at zero speed (symmetric; Fossen 2021, §6.3). The body-frame momenta are
//! `u = (p, m) = M ν`, the kinetic energy `½ uᵀ M⁻¹ u`.
//!
//! The paper's vessel is the special case `M = diag(mv, mv, mv, T1, T2, T3)`: the centre of
//! gravity at the origin, no added mass. For it (and for any `M` of that form) flow S1 is the
//! free rigid body with `p` carried along, solved exactly by Jacobi's elliptic functions
//! (`flows/rigid_body.rs`); any other `M` has flow S1 by Kirchhoff's equations
//! (`flows/kirchhoff.rs`, docs/model.md §3.8).

use super::params::{physical, Params, Range};
use super::state::VesselState;
use crate::error::{Error, Result};
use crate::flows::kirchhoff::Kirchhoff;
use crate::flows::rigid_body::FreeRigidBody;
use crate::lie::so3;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

pub type M6 = SMatrix<f64, 6, 6>;
pub type V6 = SVector<f64, 6>;

/// The rigid body in the fluid (keys `vessel.mass`, `vessel.inertia`,
/// `vessel.center_of_gravity`, `vessel.added_mass`).
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The rigid body's mass `mv`, kg (its weight is `mv g`).
    pub mass: f64,
    /// Principal inertias about the centre of gravity `I_g = diag(T1, T2, T3)` (roll, pitch,
    /// yaw), kg m².
    pub inertia: Vector3<f64>,
    /// The centre of gravity `r_g`, body frame (x forward, y to port, z up), m.
    pub center_of_gravity: Vector3<f64>,
    /// `M = M_RB + M_A`.
    pub mass_matrix: M6,
    /// `M⁻¹` (symmetrised).
    pub minv: M6,
    /// `M⁻¹` in 3×3 blocks: `[[tt, tr], [rt, rr]]`.
    pub minv_blocks: [[Matrix3<f64>; 2]; 2],
    /// The free rigid body of flow S1 when `M = diag(a, a, a, b, c, d)`: inertias `(b, c, d)`.
    pub free: FreeRigidBody,
    /// The translational mass `a` of that case (`mv` for the paper's vessel).
    pub free_mass: f64,
    /// Kirchhoff's flow S1 for any other `M` (`None` when the exact elliptic flow applies).
    pub kirchhoff: Option<Kirchhoff>,
}

/// The largest condition number of `M` accepted.
const MAX_CONDITION: f64 = 1e12;

/// The 3×3 block `(i, j)` of a 6×6 matrix.
pub fn block(m: &M6, i: usize, j: usize) -> Matrix3<f64> {
    m.fixed_view::<3, 3>(3 * i, 3 * j).into_owned()
}

impl Body {
    pub(crate) fn read(p: &mut Params) -> Result<Self> {
        const T: &str = "vessel";
        let mass = p.f64(T, "mass", "kg", Range::Physical(&physical::MASS))?;
        let inertia: Vector3<f64> = p
            .vec3(
                T,
                "inertia",
                None,
                "kg m^2",
                Range::Physical(&physical::INERTIA),
            )?
            .into();
        let rg: Vector3<f64> = p
            .vec3(T, "center_of_gravity", Some([0.0; 3]), "m", Range::Finite)?
            .into();
        if let Some(i) = (0..3).find(|&i| rg[i].abs() > 1000.0) {
            return Err(Error::InvalidInput(format!(
                "vessel.center_of_gravity[{i}] must lie within ±1000 m of the body origin (m, body frame), got {}",
                rg[i]
            )));
        }
        let added = match p.rows(
            T,
            "added_mass",
            6,
            "kg, kg m and kg m^2 blocks",
            Range::Finite,
        )? {
            None => M6::zeros(),
            Some(rows) => {
                if rows.len() != 6 {
                    return Err(Error::InvalidInput(format!(
                        "vessel.added_mass must be 6 rows of 6 numbers (kg, kg m and kg m^2 blocks), got {} rows",
                        rows.len()
                    )));
                }
                let a = M6::from_fn(|i, j| rows[i][j]);
                check_symmetric(&a, "vessel.added_mass")?;
                a
            }
        };
        Self::new(mass, inertia, rg, &added)
    }

    /// A body from its rigid-body data and added mass, `M` checked symmetric positive definite.
    pub fn new(mass: f64, inertia: Vector3<f64>, rg: Vector3<f64>, added: &M6) -> Result<Self> {
        let s = so3::hat(&rg);
        let mut m = M6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(Matrix3::identity() * mass));
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-s * mass));
        m.fixed_view_mut::<3, 3>(3, 0).copy_from(&(s * mass));
        m.fixed_view_mut::<3, 3>(3, 3)
            .copy_from(&(Matrix3::from_diagonal(&inertia) - s * s * mass));
        m += added;
        // Symmetric by construction up to the added mass's round-off.
        let m = (m + m.transpose()) * 0.5;
        let ev = m.symmetric_eigenvalues();
        let (min, max) = (ev.min(), ev.max());
        // Written so that a NaN eigenvalue is refused too.
        #[allow(clippy::neg_cmp_op_on_partial_ord)]
        if !(min > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the mass matrix M = M_RB + M_A (vessel.mass, vessel.inertia, vessel.center_of_gravity, vessel.added_mass) must be positive definite; its smallest eigenvalue is {min:e}"
            )));
        }
        // A vessel's M has a condition number of 1e2 to 1e4 (the OSV's: 1.1e3); beyond 1e12 its
        // inverse, and every velocity, loses most of its digits.
        if max / min > MAX_CONDITION {
            return Err(Error::InvalidInput(format!(
                "the mass matrix M = M_RB + M_A is nearly singular: its eigenvalues span {min:e} to {max:e} (condition number {:.1e} > {MAX_CONDITION:.0e}); check vessel.added_mass and vessel.center_of_gravity",
                max / min
            )));
        }
        let paper_form = {
            let a = m[(0, 0)];
            (0..6).all(|i| (0..6).all(|j| i == j || m[(i, j)] == 0.0))
                && m[(1, 1)] == a
                && m[(2, 2)] == a
        };
        let minv = if paper_form {
            M6::from_diagonal(&m.diagonal().map(|x| 1.0 / x))
        } else {
            let minv = m.try_inverse().ok_or_else(|| {
                Error::InvalidInput("the mass matrix M = M_RB + M_A is singular".into())
            })?;
            (minv + minv.transpose()) * 0.5
        };
        let (free, free_mass, kirchhoff) = if paper_form {
            let d = Vector3::new(m[(3, 3)], m[(4, 4)], m[(5, 5)]);
            (FreeRigidBody::new(d)?, m[(0, 0)], None)
        } else {
            (
                FreeRigidBody::new(inertia)?,
                mass,
                Some(Kirchhoff::new(&m)?),
            )
        };
        Ok(Self {
            mass,
            inertia,
            center_of_gravity: rg,
            mass_matrix: m,
            minv,
            minv_blocks: [
                [block(&minv, 0, 0), block(&minv, 0, 1)],
                [block(&minv, 1, 0), block(&minv, 1, 1)],
            ],
            free,
            free_mass,
            kirchhoff,
        })
    }

    /// Whether `M` is of the paper's form `diag(a, a, a, b, c, d)` (flow S1 exact by elliptic
    /// functions) rather than general (flow S1 by Kirchhoff's equations).
    pub fn is_diagonal(&self) -> bool {
        self.kirchhoff.is_none()
    }

    /// The body velocities `ν = M⁻¹u`: linear (m/s) and angular (rad/s).
    pub fn velocity(&self, p: &Vector3<f64>, m: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let b = &self.minv_blocks;
        [b[0][0] * p + b[0][1] * m, b[1][0] * p + b[1][1] * m]
    }

    /// The momenta `u = M ν`.
    pub fn momentum(&self, v: &Vector3<f64>, w: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let mut nu = V6::zeros();
        nu.fixed_rows_mut::<3>(0).copy_from(v);
        nu.fixed_rows_mut::<3>(3).copy_from(w);
        let u = self.mass_matrix * nu;
        [
            u.fixed_rows::<3>(0).into_owned(),
            u.fixed_rows::<3>(3).into_owned(),
        ]
    }

    /// Kinetic energy `½ uᵀ M⁻¹ u`, J.
    pub fn kinetic_energy(&self, s: &VesselState) -> f64 {
        if self.kirchhoff.is_none() {
            return self.free.kinetic_energy(&s.m) + 0.5 * s.p.norm_squared() / self.free_mass;
        }
        let [v, w] = self.velocity(&s.p, &s.m);
        0.5 * (s.p.dot(&v) + s.m.dot(&w))
    }
}

/// Refuse a matrix that is not symmetric, naming the worst entry pair.
pub fn check_symmetric(d: &M6, name: &str) -> Result<()> {
    let scale = d.amax();
    let (mut bi, mut bj, mut worst) = (0, 0, 0.0);
    for i in 0..6 {
        for j in 0..6 {
            let x = (d[(i, j)] - d[(j, i)]).abs();
            if x > worst {
                (bi, bj, worst) = (i, j, x);
            }
        }
    }
    if worst > 1e-12 * scale {
        return Err(Error::InvalidInput(format!(
            "{name} must be symmetric: entry [{bi}][{bj}] = {} but [{bj}][{bi}] = {}",
            d[(bi, bj)],
            d[(bj, bi)]
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `M_RB` against its definition by the kinetic energy of the mass distribution: for a
    /// body of point masses `m_k` at `r_k` (centre of gravity `r_g`, inertia `I_g` about it),
    /// `½ νᵀ M_RB ν = ½ Σ m_k |v + ω × r_k|²` for any `ν`.
    #[test]
    fn rigid_body_mass_matrix_is_the_kinetic_energy_of_the_masses() {
        // Six point masses placed symmetrically about r_g along the axes: principal axes.
        let rg = Vector3::new(-4.0, 0.5, 1.5);
        let (mk, d) = ([1e5, 2e5, 3e5], [10.0, 4.0, 2.0]);
        let mut pts = Vec::new();
        for a in 0..3 {
            for s in [-1.0, 1.0] {
                let mut r = rg;
                r[a] += s * d[a];
                pts.push((mk[a], r));
            }
        }
        let mass: f64 = pts.iter().map(|(m, _)| m).sum();
        let ig = Vector3::from_fn(|i, _| {
            pts.iter()
                .map(|(m, r)| {
                    let x = r - rg;
                    m * (x.norm_squared() - x[i] * x[i])
                })
                .sum()
        });
        let b = Body::new(mass, ig, rg, &M6::zeros()).unwrap();
        assert!(!b.is_diagonal());
        for k in 0..5 {
            let v = Vector3::new(1.0 + k as f64, -0.3, 0.2 * k as f64);
            let w = Vector3::new(0.01, -0.02 * k as f64, 0.05);
            let exact: f64 = pts
                .iter()
                .map(|(m, r)| 0.5 * m * (v + w.cross(r)).norm_squared())
                .sum();
            let mut nu = V6::zeros();
            nu.fixed_rows_mut::<3>(0).copy_from(&v);
            nu.fixed_rows_mut::<3>(3).copy_from(&w);
            let got = 0.5 * nu.dot(&(b.mass_matrix * nu));
            assert!((got - exact).abs() <= 1e-12 * exact, "{got} vs {exact}");
            // The momenta and back.
            let [p, m] = b.momentum(&v, &w);
            let [v1, w1] = b.velocity(&p, &m);
            assert!((v1 - v).norm() < 1e-12 * v.norm() && (w1 - w).norm() < 1e-12 * w.norm());
        }
    }

    #[test]
    fn the_paper_form_keeps_the_elliptic_flow_and_bad_matrices_are_refused() {
        let t = Vector3::new(2.8e8, 2.7e9, 2.9e9);
        let b = Body::new(6.3e6, t, Vector3::zeros(), &M6::zeros()).unwrap();
        assert!(b.is_diagonal() && b.free_mass == 6.3e6);
        // A diagonal added mass that keeps the translational mass isotropic: still elliptic.
        let a = M6::from_diagonal(&V6::from_column_slice(&[1e6, 1e6, 1e6, 1e7, 2e8, 3e8]));
        let b = Body::new(6.3e6, t, Vector3::zeros(), &a).unwrap();
        assert!(b.is_diagonal() && b.free_mass == 7.3e6);
        assert!((b.free.inertia() - (t + Vector3::new(1e7, 2e8, 3e8))).norm() == 0.0);
        // Surge added mass only: not isotropic, Kirchhoff.
        let a = M6::from_diagonal(&V6::from_column_slice(&[1e6, 0.0, 0.0, 0.0, 0.0, 0.0]));
        assert!(!Body::new(6.3e6, t, Vector3::zeros(), &a)
            .unwrap()
            .is_diagonal());
        // Nearly singular: an added mass that leaves almost nothing of the sway mass.
        let a = M6::from_diagonal(&V6::from_column_slice(&[
            0.0,
            -6.3e6 * (1.0 - 1e-14),
            0.0,
            0.0,
            0.0,
            0.0,
        ]));
        let e = Body::new(6.3e6, t, Vector3::zeros(), &a)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("nearly singular") && e.contains("condition number"),
            "{e}"
        );
        // A negative added mass larger than the body's: not positive definite.
        let a = M6::from_diagonal(&V6::from_column_slice(&[0.0, -7e6, 0.0, 0.0, 0.0, 0.0]));
        let e = Body::new(6.3e6, t, Vector3::zeros(), &a)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("positive definite") && e.contains("smallest eigenvalue is -7"),
            "{e}"
        );
        let mut a = M6::zeros();
        a[(1, 5)] = 1e6;
        let e = check_symmetric(&a, "vessel.added_mass")
            .unwrap_err()
            .to_string();
        assert!(e.contains("entry [1][5] = 1000000 but [5][1] = 0"), "{e}");
    }
}
