//! The stage equations of Gauss collocation on an affine system in three blocks of size `D`
//! (the structure of the vessel's flow S2, paper eq. 41, with `D = 3` for one block system and
//! `D = 6` for translation and rotation coupled; docs/model.md §5.14), for any right-hand side:
//! what a collocation with a forcing iterated to a fixed point solves once per pass.
//!
//! The system's linear part is `u' = A_uu u + A_uv v + A_uw w`, `v' = A_vu u`, `w' = A_wv v`.
//! The stage increments `ΔY_i = (ΔU_i, ΔV_i, ΔW_i)`, `i = 1..s`, solve
//! `ΔY_i − h Σ_j a_ij B ΔY_j = R_i` (`B` the linear part, `a_ij` the Gauss matrix `𝒜`). Under
//! the eigenvectors of `𝒜ᵀ` (Butcher's transformation: E. Hairer, G. Wanner, *Solving Ordinary
//! Differential Equations II*, 2nd ed., Springer 1996, §IV.8) they decouple into one system
//! `(I − μB) ŷ = r̂` per eigenvalue `λ`, `μ = hλ`, and in it `v̂ = r̂_v + μ A_vu û`,
//! `ŵ = r̂_w + μ A_wv v̂` leave for `û` the `D × D` system
//!
//! ```text
//! (I − μ A_uu − μ² A_uv A_vu − μ³ A_uw A_wv A_vu) û = r̂_u + μ A_uv r̂_v + μ A_uw (r̂_w + μ A_wv r̂_v)
//! ```
//!
//! one real system for `s = 1`, one complex for `s = 2` (a conjugate pair stands for both), one
//! real and one complex for `s = 3`, each factorised once per sub-step (LU with partial
//! pivoting) and solved once per pass. Against the dense `(3Ds) × (3Ds)` stage matrix this is
//! `O(D³)` once and `O(D²)` per pass instead of `O((3Ds)³)` and `O((3Ds)²)`.
//!
//! The elimination is exact algebra; where `μA_vu` or `μA_wv` are large it can lose the digits
//! of the small increments to cancellation, so callers balance the system first (a diagonal
//! similarity that keeps the block structure) and solve for increments, not for the stages.

// Stage loops index the transformation's vectors and the stages as the formulas write them.
#![allow(clippy::needless_range_loop)]

use super::collocation::transformed;
use nalgebra::linalg::LU;
use nalgebra::{Complex, ComplexField, Const, DimMin, SMatrix, SVector};

/// The linear part of an affine system in three blocks of size `D`:
/// `u' = A_uu u + A_uv v + A_uw w`, `v' = A_vu u`, `w' = A_wv v`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Structure<const D: usize> {
    pub auu: SMatrix<f64, D, D>,
    pub auv: SMatrix<f64, D, D>,
    pub auw: SMatrix<f64, D, D>,
    pub avu: SMatrix<f64, D, D>,
    pub awv: SMatrix<f64, D, D>,
}

/// A state or a right-hand side `(u, v, w)` in the blocks of a [`Structure`].
pub type Parts<T, const D: usize> = [SVector<T, D>; 3];

impl<const D: usize> Structure<D> {
    /// `B z`.
    pub fn apply(&self, z: &Parts<f64, D>) -> Parts<f64, D> {
        [
            self.auu * z[0] + self.auv * z[1] + self.auw * z[2],
            self.avu * z[0],
            self.awv * z[1],
        ]
    }
}

/// The factorised reduced system `S(μ) = I − μ A_uu − μ² P₂ − μ³ P₃` of one eigenvalue of the
/// Gauss matrix, `μ = hλ`, in its scalar type (`f64` for a real eigenvalue, `Complex<f64>` for
/// a conjugate pair).
#[derive(Debug, Clone)]
struct Reduced<T: ComplexField, const D: usize>
where
    Const<D>: DimMin<Const<D>, Output = Const<D>>,
{
    mu: T,
    lu: LU<T, Const<D>, Const<D>>,
}

/// The stage equations `ΔY_i − h Σ_j a_ij B ΔY_j = R_i` of `s`-stage Gauss collocation
/// (`s = 1, 2, 3`) on a [`Structure`], factorised for one step `h`.
#[derive(Debug, Clone)]
pub struct StageSolver<const D: usize>
where
    Const<D>: DimMin<Const<D>, Output = Const<D>>,
{
    st: Structure<D>,
    s: usize,
    real: Option<(Reduced<f64, D>, usize)>,
    pair: Option<(Reduced<Complex<f64>, D>, usize)>,
}

impl<const D: usize> StageSolver<D>
where
    Const<D>: DimMin<Const<D>, Output = Const<D>>,
{
    /// Factorise the reduced systems for step `h` with `s` stages.
    pub fn new(st: &Structure<D>, h: f64, s: usize) -> Self {
        assert!(
            (1..=3).contains(&s),
            "Gauss collocation is provided with 1, 2 or 3 stages, not {s}"
        );
        let tr = transformed(s);
        let p2 = st.auv * st.avu;
        // A_wv = 0 (nothing integrates the middle block) leaves out the cubic terms.
        let p3 = st
            .awv
            .iter()
            .any(|v| *v != 0.0)
            .then(|| st.auw * (st.awv * st.avu));
        // Re and Im of S(μ), from the real blocks.
        let real_part = |mu: Complex<f64>| {
            let (m2, m3) = (mu * mu, mu * mu * mu);
            let mut re = SMatrix::<f64, D, D>::identity() - st.auu * mu.re - p2 * m2.re;
            if let Some(p3) = &p3 {
                re -= p3 * m3.re;
            }
            re
        };
        let parts = |mu: Complex<f64>| {
            let (m2, m3) = (mu * mu, mu * mu * mu);
            let mut im = -(st.auu * mu.im + p2 * m2.im);
            if let Some(p3) = &p3 {
                im -= p3 * m3.im;
            }
            (real_part(mu), im)
        };
        let mut real = None;
        let mut pair = None;
        for (k, mode) in tr.modes[..tr.n_modes].iter().enumerate() {
            let mu = mode.lam * h;
            if mode.pair {
                let (re, im) = parts(mu);
                let lu = re.zip_map(&im, Complex::new).lu();
                pair = Some((Reduced { mu, lu }, k));
            } else {
                let lu = real_part(Complex::from(mu.re)).lu();
                real = Some((Reduced { mu: mu.re, lu }, k));
            }
        }
        Self {
            st: *st,
            s,
            real,
            pair,
        }
    }

    /// `ŷ` from `r̂` for a real eigenvalue.
    fn reduced_real(&self, red: &Reduced<f64, D>, r: &Parts<f64, D>) -> Option<Parts<f64, D>> {
        let (st, mu) = (&self.st, red.mu);
        let rw = r[2] + st.awv * r[1] * mu;
        let u = red.lu.solve(&(r[0] + (st.auv * r[1] + st.auw * rw) * mu))?;
        let v = r[1] + st.avu * u * mu;
        let w = r[2] + st.awv * v * mu;
        Some([u, v, w])
    }

    /// `ŷ` from `r̂` for a conjugate pair, the real blocks applied to the real and imaginary
    /// parts.
    fn reduced_pair(
        &self,
        red: &Reduced<Complex<f64>, D>,
        r: &Parts<Complex<f64>, D>,
    ) -> Option<Parts<Complex<f64>, D>> {
        let (st, mu) = (&self.st, red.mu);
        let mul = |m: &SMatrix<f64, D, D>, v: &SVector<Complex<f64>, D>| {
            let re = m * v.map(|z| z.re);
            let im = m * v.map(|z| z.im);
            re.zip_map(&im, Complex::new)
        };
        let rw = r[2] + mul(&st.awv, &r[1]) * mu;
        let u = red
            .lu
            .solve(&(r[0] + (mul(&st.auv, &r[1]) + mul(&st.auw, &rw)) * mu))?;
        let v = r[1] + mul(&st.avu, &u) * mu;
        let w = r[2] + mul(&st.awv, &v) * mu;
        Some([u, v, w])
    }

    /// The stage increments `ΔY_1..ΔY_s` (beyond `s`, zeros) for the right-hand sides
    /// `R_1..R_s`; `None` if a reduced system is singular (impossible for a dissipative system:
    /// Gauss collocation is A-stable). A right-hand side that is not finite gives increments that
    /// are not: the caller judges them (a diverging fixed point is not a singular system).
    pub fn solve(&self, r: &[Parts<f64, D>; 3]) -> Option<[Parts<f64, D>; 3]> {
        let s = self.s;
        let modes = &transformed(s).modes;
        let mut dy = [[SVector::<f64, D>::zeros(); 3]; 3];
        if let Some((red, k)) = &self.real {
            let mode = &modes[*k];
            let mut rh = [SVector::<f64, D>::zeros(); 3];
            for i in 0..s {
                for c in 0..3 {
                    rh[c] += r[i][c] * mode.t[i].re;
                }
            }
            let y = self.reduced_real(red, &rh)?;
            for i in 0..s {
                for c in 0..3 {
                    dy[i][c] += y[c] * mode.tau[i].re;
                }
            }
        }
        if let Some((red, k)) = &self.pair {
            let mode = &modes[*k];
            let mut rh = [SVector::<Complex<f64>, D>::zeros(); 3];
            for i in 0..s {
                for c in 0..3 {
                    rh[c] += r[i][c].map(Complex::from) * mode.t[i];
                }
            }
            let y = self.reduced_pair(red, &rh)?;
            for i in 0..s {
                for c in 0..3 {
                    // The conjugate eigenvalue contributes the conjugate term.
                    dy[i][c] += (y[c] * mode.tau[i]).map(|z| 2.0 * z.re);
                }
            }
        }
        Some(dy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flows::collocation::tableau;
    use nalgebra::DMatrix;

    /// A structured system with couplings everywhere the structure allows, its entries spread
    /// over orders of magnitude as a vessel's are (after balancing they are not; here the
    /// solver must cope unbalanced).
    fn example<const D: usize>(cubic: bool) -> Structure<D> {
        let f = |seed: f64| {
            SMatrix::<f64, D, D>::from_fn(|i, j| {
                ((i * 7 + j * 3) as f64 * 0.37 + seed).sin() * if i == j { 2.0 } else { 0.6 }
            })
        };
        let mut auu = f(0.1);
        for i in 0..D {
            auu[(i, i)] = -1.5 - i as f64 * 0.2; // dissipative diagonal
        }
        Structure {
            auu,
            auv: f(1.3) * 0.8,
            auw: f(2.1) * 0.3,
            avu: f(0.7),
            awv: if cubic {
                f(3.3) * 0.5
            } else {
                SMatrix::zeros()
            },
        }
    }

    /// The dense stage system `(I − h 𝒜 ⊗ B) ΔY = R`, assembled and solved by a full LU, is
    /// the independent reference.
    fn dense<const D: usize>(
        st: &Structure<D>,
        h: f64,
        s: usize,
        r: &[Parts<f64, D>; 3],
    ) -> [Parts<f64, D>; 3] {
        let n = 3 * D;
        let mut b = DMatrix::<f64>::zeros(n, n);
        let put = |b: &mut DMatrix<f64>, bi: usize, bj: usize, m: &SMatrix<f64, D, D>| {
            b.view_mut((bi * D, bj * D), (D, D)).copy_from(m);
        };
        put(&mut b, 0, 0, &st.auu);
        put(&mut b, 0, 1, &st.auv);
        put(&mut b, 0, 2, &st.auw);
        put(&mut b, 1, 0, &st.avu);
        put(&mut b, 2, 1, &st.awv);
        let (a, _) = tableau(s);
        let mut m = DMatrix::<f64>::identity(n * s, n * s);
        let mut rhs = nalgebra::DVector::<f64>::zeros(n * s);
        for i in 0..s {
            for j in 0..s {
                let mut v = m.view_mut((n * i, n * j), (n, n));
                v -= &b * (h * a[i][j]);
            }
            for c in 0..3 {
                rhs.rows_mut(n * i + c * D, D).copy_from(&r[i][c]);
            }
        }
        let y = m.lu().solve(&rhs).unwrap();
        std::array::from_fn(|i| {
            std::array::from_fn(|c| {
                if i < s {
                    SVector::<f64, D>::from_iterator(y.rows(n * i + c * D, D).iter().copied())
                } else {
                    SVector::zeros()
                }
            })
        })
    }

    fn check<const D: usize>()
    where
        Const<D>: DimMin<Const<D>, Output = Const<D>>,
    {
        for cubic in [false, true] {
            let st = example::<D>(cubic);
            let r: [Parts<f64, D>; 3] = std::array::from_fn(|i| {
                std::array::from_fn(|c| {
                    SVector::<f64, D>::from_fn(|j, _| ((i * 5 + c * 3 + j) as f64 * 1.1).cos())
                })
            });
            for s in 1..=3 {
                for h in [0.01, 0.3, 2.0, 40.0] {
                    let got = StageSolver::new(&st, h, s).solve(&r).unwrap();
                    let want = dense(&st, h, s, &r);
                    let scale = want.iter().flatten().map(|v| v.amax()).fold(0.0, f64::max);
                    for i in 0..3 {
                        for c in 0..3 {
                            let err = (got[i][c] - want[i][c]).amax();
                            assert!(
                                err <= 1e-11 * scale,
                                "D = {D}, cubic = {cubic}, s = {s}, h = {h}, stage {i}, block {c}: {err:e} (scale {scale:e})"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn the_transformed_solve_equals_the_dense_stage_solve() {
        check::<3>();
        check::<6>();
    }

    #[test]
    fn apply_is_the_linear_part() {
        let st = example::<3>(true);
        let z: Parts<f64, 3> = [
            SVector::from([1.0, 2.0, 3.0]),
            SVector::from([-1.0, 0.5, 0.0]),
            SVector::from([0.2, 0.0, -4.0]),
        ];
        let f = st.apply(&z);
        assert_eq!(f[0], st.auu * z[0] + st.auv * z[1] + st.auw * z[2]);
        assert_eq!(f[1], st.avu * z[0]);
        assert_eq!(f[2], st.awv * z[1]);
    }
}
