//! Exact flows of affine linear systems `y' = A y + b`, and exact integrals of quadratic forms
//! along them.
//!
//! With the augmented state `z = (y, 1)` the system is `z' = Ā z`, `Ā = [[A, b], [0, 0]]`, and
//! its flow over `h` is the matrix exponential `exp(Ā h)` (the last column carries the constant
//! forcing; the φ-function form of the variation-of-constants formula is the same thing). The
//! exponential is nalgebra's scaling-and-squaring Padé approximant (Higham 2005).
//!
//! The energy ledger needs `∫₀^h z(s)ᵀ M z(s) ds` for a few symmetric `M`. Van Loan's block
//! exponential (C. F. Van Loan, *Computing integrals involving the matrix exponential*, IEEE
//! TAC 23 (1978) 395–404) gives it exactly: for `C = [[−Āᵀ, M], [0, Ā]]`,
//! `exp(C h) = [[F₁₁, F₁₂], [0, F₂₂]]` with `F₂₂ = exp(Ā h)` and
//! `∫₀^h exp(Āᵀs) M exp(Ā s) ds = F₂₂ᵀ F₁₂`. The ledger uses the equivalent state Gramian
//! ([`flow_and_gramian`]), one 20×20 exponential for any number of forms; the form-by-form
//! version is kept in the tests as its cross-check.

use nalgebra::{Const, DMatrix, DVector, DimMin, SMatrix, SVector};

/// The flow `exp(Ā h)` of the augmented system.
pub fn flow<const M: usize>(abar: &SMatrix<f64, M, M>, h: f64) -> SMatrix<f64, M, M>
where
    Const<M>: DimMin<Const<M>, Output = Const<M>>,
{
    (abar * h).exp()
}

/// The flow `exp(Ā h)` of a 10-dimensional augmented system and the Gramian
/// `Z = ∫₀^h z(s) z(s)ᵀ ds` of its trajectory from `z0`, from one 20×20 exponential
/// (Van Loan 1978 with the state's outer product as the coupling block):
/// `exp([[Ā, z0 z0ᵀ], [0, −Āᵀ]] τ) = [[e^{Āτ}, F₁₂], [0, e^{−Āᵀτ}]]` and `Z(τ) = F₁₂ e^{Āᵀτ}`.
/// Then `∫ zᵀ M z ds = tr(M Z)` for any number of forms `M`.
///
/// The `e^{−Āᵀτ}` block grows where `Ā` dissipates, so for long steps the exponential is taken
/// over `τ = h/2^k` with `‖Ā τ‖₁ ≤ 1`, and doubled back up with `Z(2τ) = Z(τ) + Φ Z(τ) Φᵀ`,
/// `Φ(2τ) = Φ(τ)²` (the second half of the interval starts from `Φ z0`).
pub fn flow_and_gramian(
    abar: &SMatrix<f64, 10, 10>,
    z0: &SVector<f64, 10>,
    h: f64,
) -> (SMatrix<f64, 10, 10>, SMatrix<f64, 10, 10>) {
    let norm1 = (0..10)
        .map(|j| abar.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
        * h.abs();
    let k = if norm1 > 1.0 {
        norm1.log2().ceil().min(60.0) as i32
    } else {
        0
    };
    let tau = h / 2f64.powi(k);
    let mut c = SMatrix::<f64, 20, 20>::zeros();
    c.fixed_view_mut::<10, 10>(0, 0).copy_from(&(abar * tau));
    c.fixed_view_mut::<10, 10>(0, 10)
        .copy_from(&(z0 * z0.transpose() * tau));
    c.fixed_view_mut::<10, 10>(10, 10)
        .copy_from(&(-abar.transpose() * tau));
    let e = c.exp();
    let mut phi: SMatrix<f64, 10, 10> = e.fixed_view::<10, 10>(0, 0).into_owned();
    let f12: SMatrix<f64, 10, 10> = e.fixed_view::<10, 10>(0, 10).into_owned();
    let mut z = f12 * phi.transpose();
    for _ in 0..k {
        z += phi * z * phi.transpose();
        phi *= phi;
    }
    (phi, z)
}

/// `tr(M Z)` for symmetric `M`: the integral `∫ zᵀ M z ds` given the Gramian `Z`.
pub fn trace_product(m: &SMatrix<f64, 10, 10>, z: &SMatrix<f64, 10, 10>) -> f64 {
    m.component_mul(z).sum()
}

/// Gauss–Legendre collocation with `s` stages (`s = 1, 2, 3`; orders 2, 4, 6), on a linear
/// system: its update is the diagonal `(s, s)` Padé approximant of the exponential, and for a
/// port-Hamiltonian linear system it conserves the storage exactly where the system does and
/// dissipates it where the system does (algebraic stability; paper Remark 2.3).
pub mod gauss {
    use super::*;

    /// Butcher coefficients `(A, b)` of the `s`-stage Gauss method, in the leading `s × s`
    /// corner of fixed-size arrays (no allocation: this is called once per sub-step).
    pub fn tableau(s: usize) -> ([[f64; 3]; 3], [f64; 3]) {
        match s {
            1 => ([[0.5, 0.0, 0.0], [0.0; 3], [0.0; 3]], [1.0, 0.0, 0.0]),
            2 => {
                let r = 3f64.sqrt() / 6.0;
                (
                    [[0.25, 0.25 - r, 0.0], [0.25 + r, 0.25, 0.0], [0.0; 3]],
                    [0.5, 0.5, 0.0],
                )
            }
            3 => {
                let r = 15f64.sqrt();
                (
                    [
                        [5.0 / 36.0, 2.0 / 9.0 - r / 15.0, 5.0 / 36.0 - r / 30.0],
                        [5.0 / 36.0 + r / 24.0, 2.0 / 9.0, 5.0 / 36.0 - r / 24.0],
                        [5.0 / 36.0 + r / 30.0, 2.0 / 9.0 + r / 15.0, 5.0 / 36.0],
                    ],
                    [5.0 / 18.0, 4.0 / 9.0, 5.0 / 18.0],
                )
            }
            _ => panic!("Gauss collocation is provided with 1, 2 or 3 stages, not {s}"),
        }
    }

    /// `z(h) ≈ R_s(hĀ) z0` with `R_s` the `(s, s)` Padé approximant: `P(X) z0` by
    /// matrix–vector products, then one LU solve with `Q(X) = P(−X)`. Returns `None` if `Q(X)`
    /// is singular (it is not for a dissipative `Ā`: its eigenvalues have `Re ≤ 0`).
    pub fn step(
        abar: &SMatrix<f64, 10, 10>,
        z0: &SVector<f64, 10>,
        h: f64,
        s: usize,
    ) -> Option<SVector<f64, 10>> {
        let x = abar * h;
        let i = SMatrix::<f64, 10, 10>::identity();
        let v1 = x * z0;
        let (rhs, q) = match s {
            1 => (z0 + v1 * 0.5, i - x * 0.5),
            2 => {
                let x2 = x * x;
                (z0 + v1 * 0.5 + x * v1 / 12.0, i - x * 0.5 + x2 / 12.0)
            }
            3 => {
                let x2 = x * x;
                let x3 = x2 * x;
                let v2 = x * v1;
                (
                    z0 + v1 * 0.5 + v2 / 10.0 + x * v2 / 120.0,
                    i - x * 0.5 + x2 / 10.0 - x3 / 120.0,
                )
            }
            _ => panic!("Gauss collocation is provided with 1, 2 or 3 stages, not {s}"),
        };
        q.lu().solve(&rhs)
    }

    /// The collocation stages `Y_1..Y_s` and the update, from the `10s × 10s` stage equations
    /// `Y_i = z0 + h Σ_j a_ij Ā Y_j`; `z1 = z0 + h Σ b_i Ā Y_i`. Used with the energy ledger:
    /// for a quadratic storage, `H(z1) − H(z0) = h Σ b_i Ḣ(Y_i)` exactly.
    pub fn stages(
        abar: &SMatrix<f64, 10, 10>,
        z0: &SVector<f64, 10>,
        h: f64,
        s: usize,
    ) -> Option<(SVector<f64, 10>, Vec<SVector<f64, 10>>, Vec<f64>)> {
        let (a, b) = tableau(s);
        let b = b[..s].to_vec();
        let n = 10 * s;
        let mut m = DMatrix::<f64>::identity(n, n);
        let mut rhs = DVector::<f64>::zeros(n);
        for i in 0..s {
            for j in 0..s {
                let blk = abar * (-h * a[i][j]);
                let mut v = m.view_mut((10 * i, 10 * j), (10, 10));
                v += blk;
            }
            rhs.rows_mut(10 * i, 10).copy_from(z0);
        }
        let y = m.lu().solve(&rhs)?;
        let ys: Vec<SVector<f64, 10>> = (0..s)
            .map(|i| SVector::<f64, 10>::from_iterator(y.rows(10 * i, 10).iter().cloned()))
            .collect();
        let mut z1 = *z0;
        for i in 0..s {
            z1 += abar * ys[i] * (h * b[i]);
        }
        Some((z1, ys, b))
    }

    /// `M x = r` for a 3×3 `M` by the adjugate (Cramer's rule); `None` if `M` is singular to
    /// working precision.
    fn solve3(
        m: &nalgebra::Matrix3<f64>,
        r: &nalgebra::Vector3<f64>,
    ) -> Option<nalgebra::Vector3<f64>> {
        let (c0, c1, c2) = (m.column(0), m.column(1), m.column(2));
        let x01 = c0.cross(&c1);
        let det = x01.dot(&c2);
        let scale = c0.norm() * c1.norm() * c2.norm();
        if !(det.abs() > 1e-14 * scale) {
            return None;
        }
        let inv = 1.0 / det;
        // Rows of M⁻¹ are the cross products of pairs of columns over det.
        Some(nalgebra::Vector3::new(
            c1.cross(&c2).dot(r) * inv,
            c2.cross(&c0).dot(r) * inv,
            x01.dot(r) * inv,
        ))
    }

    /// Gauss collocation with `s` stages for an augmented 10×10 system with the block
    /// structure of the vessel's flow S2, `z = (u, v, w, 1)` in 3-blocks:
    /// `u' = A_uu u + A_uv v + A_uw w + c_u`, `v' = A_vu u`, `w' = A_wv v + c_w`
    /// (checked: the other entries must be zero). The stages of `v` and `w` are eliminated in
    /// closed form, `V = 1⊗v0 + h(𝒜⊗A_vu)U`, `W = 1⊗w0 + h(𝒜1)⊗c_w + h(𝒜⊗A_wv)V`, which leaves
    /// one `3s × 3s` system for the stages `U`, with blocks
    /// `δ_ij I − h a_ij A_uu − h² (𝒜²)_ij A_uv A_vu − h³ (𝒜³)_ij A_uw A_wv A_vu`.
    /// Returns the update, the stages and the weights (equal to [`stages`] to round-off), or
    /// `None` if the structure does not hold or the system is singular.
    pub fn structured(
        a: &SMatrix<f64, 10, 10>,
        z0: &SVector<f64, 10>,
        h: f64,
        s: usize,
    ) -> Option<(SVector<f64, 10>, [SVector<f64, 10>; 3], [f64; 3])> {
        use nalgebra::{Matrix3, Vector3};
        let blk = |r: usize, c: usize| -> Matrix3<f64> { a.fixed_view::<3, 3>(r, c).into_owned() };
        let col = |r: usize| -> Vector3<f64> { a.fixed_view::<3, 1>(r, 9).into_owned() };
        let zero3 = |m: Matrix3<f64>| m.iter().all(|v| *v == 0.0);
        if !(1..=3).contains(&s)
            || !(zero3(blk(3, 3)) && zero3(blk(3, 6)) && col(3).iter().all(|v| *v == 0.0))
            || !(zero3(blk(6, 0)) && zero3(blk(6, 6)))
            || a.row(9).iter().any(|v| *v != 0.0)
        {
            return None;
        }
        let (auu, auv, auw, cu) = (blk(0, 0), blk(0, 3), blk(0, 6), col(0));
        let avu = blk(3, 0);
        let (awv, cw) = (blk(6, 3), col(6));
        let (ta, tb) = tableau(s);
        let mut am = Matrix3::<f64>::zeros(); // the Gauss matrix in the leading s×s corner
        let mut b = [0.0; 3];
        for i in 0..s {
            b[i] = tb[i];
            for j in 0..s {
                am[(i, j)] = ta[i][j];
            }
        }
        let am2 = am * am;
        let am3 = am2 * am;
        let alpha = am * Vector3::new(1.0, 1.0, 1.0); // the nodes c_i (zero beyond s)
        let alpha2 = am * alpha;
        let p2 = auv * avu;
        let p3 = auw * awv * avu;
        let one = z0[9];
        let u0: Vector3<f64> = z0.fixed_rows::<3>(0).into();
        let v0: Vector3<f64> = z0.fixed_rows::<3>(3).into();
        let w0: Vector3<f64> = z0.fixed_rows::<3>(6).into();
        let g1 = (cu * one + auv * v0 + auw * w0) * h;
        let g2 = auw * (cw * one + awv * v0) * (h * h);
        let block = |i: usize, j: usize| -> Matrix3<f64> {
            let d = if i == j {
                Matrix3::identity()
            } else {
                Matrix3::zeros()
            };
            d - auu * (h * am[(i, j)]) - p2 * (h * h * am2[(i, j)]) - p3 * (h * h * h * am3[(i, j)])
        };
        let rhs_i = |i: usize| u0 + g1 * alpha[i] + g2 * alpha2[i];
        let mut ust = [Vector3::zeros(); 3];
        if s == 1 {
            ust[0] = solve3(&block(0, 0), &rhs_i(0))?;
        } else {
            // s = 2, 3: one 9×9 system, padded with the identity beyond 3s.
            let mut m = SMatrix::<f64, 9, 9>::identity();
            let mut rhs = SVector::<f64, 9>::zeros();
            for i in 0..s {
                for j in 0..s {
                    m.fixed_view_mut::<3, 3>(3 * i, 3 * j)
                        .copy_from(&block(i, j));
                }
                rhs.fixed_rows_mut::<3>(3 * i).copy_from(&rhs_i(i));
            }
            let x = m.lu().solve(&rhs)?;
            for (i, u) in ust.iter_mut().enumerate().take(s) {
                *u = x.fixed_rows::<3>(3 * i).into_owned();
            }
        }
        let mut vst = [Vector3::zeros(); 3];
        let mut wst = [Vector3::zeros(); 3];
        for i in 0..s {
            vst[i] = (0..s).fold(v0, |acc, j| acc + avu * ust[j] * (h * am[(i, j)]));
        }
        for i in 0..s {
            wst[i] = (0..s).fold(w0 + cw * (one * h * alpha[i]), |acc, j| {
                acc + awv * vst[j] * (h * am[(i, j)])
            });
        }
        let (mut u1, mut v1, mut w1) = (u0, v0, w0);
        for i in 0..s {
            u1 += (auu * ust[i] + auv * vst[i] + auw * wst[i] + cu * one) * (h * b[i]);
            v1 += avu * ust[i] * (h * b[i]);
            w1 += (awv * vst[i] + cw * one) * (h * b[i]);
        }
        let pack = |u: &Vector3<f64>, v: &Vector3<f64>, w: &Vector3<f64>| {
            let mut z = SVector::<f64, 10>::zeros();
            z.fixed_rows_mut::<3>(0).copy_from(u);
            z.fixed_rows_mut::<3>(3).copy_from(v);
            z.fixed_rows_mut::<3>(6).copy_from(w);
            z[9] = one;
            z
        };
        let stages = [
            pack(&ust[0], &vst[0], &wst[0]),
            pack(&ust[1], &vst[1], &wst[1]),
            pack(&ust[2], &vst[2], &wst[2]),
        ];
        Some((pack(&u1, &v1, &w1), stages, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, SVector};

    /// Reference for the tests (Van Loan with the forms in the coupling block, one
    /// `(K+1)M`-square exponential): the flow `exp(Ā h)` and the Gram integrals `∫₀^h exp(Āᵀs) Mᵢ exp(Ā s) ds` of `K` forms.
    fn flow_with_integrals<const M: usize, const K: usize>(
        abar: &SMatrix<f64, M, M>,
        forms: &[SMatrix<f64, M, M>; K],
        h: f64,
    ) -> (SMatrix<f64, M, M>, [SMatrix<f64, M, M>; K]) {
        let n = (K + 1) * M;
        let mut c = DMatrix::<f64>::zeros(n, n);
        let minus_at = -abar.transpose() * h;
        for (k, form) in forms.iter().enumerate() {
            c.view_mut((k * M, k * M), (M, M)).copy_from(&minus_at);
            c.view_mut((k * M, K * M), (M, M)).copy_from(&(form * h));
        }
        c.view_mut((K * M, K * M), (M, M)).copy_from(&(abar * h));
        let e = c.exp();
        let f22: SMatrix<f64, M, M> = e.fixed_view::<M, M>(K * M, K * M).into_owned();
        let f22t = f22.transpose();
        let ints = std::array::from_fn(|k| f22t * e.fixed_view::<M, M>(k * M, K * M));
        (f22, ints)
    }

    type M3 = SMatrix<f64, 3, 3>;

    /// Weight of node `i` of composite Simpson's rule on `n` (even) intervals, times 3/h.
    fn simpson_weight(i: usize, n: usize) -> f64 {
        if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        }
    }

    /// y' = −2 y + 3 (augmented as 2×2... padded to 3 with a second decoupled state y2' = y1).
    fn example() -> M3 {
        M3::new(-2.0, 0.0, 3.0, 1.0, -0.5, 0.0, 0.0, 0.0, 0.0)
    }

    #[test]
    fn affine_flow_matches_closed_form() {
        let h = 0.7;
        let e = flow(&example(), h);
        let y0 = 1.3;
        // y1(t) = 3/2 + (y0 − 3/2) e^{−2t}
        let y1 = 1.5 + (y0 - 1.5) * (-2.0 * h).exp();
        let z = e * SVector::<f64, 3>::new(y0, 0.0, 1.0);
        assert!((z[0] - y1).abs() < 1e-15);
        assert_eq!(z[2], 1.0);
    }

    fn example10() -> SMatrix<f64, 10, 10> {
        // A damped oscillator chain with forcing in the last column (augmented form).
        let mut a = SMatrix::<f64, 10, 10>::zeros();
        for i in 0..9 {
            a[(i, i)] = -0.1 * (i as f64 + 1.0);
            if i + 1 < 9 {
                a[(i, i + 1)] = 1.0;
                a[(i + 1, i)] = -1.0;
            }
            a[(i, 9)] = 0.05 * i as f64;
        }
        a
    }

    #[test]
    fn gramian_gives_the_same_integrals_as_van_loan() {
        let a = example10();
        let z0 = SVector::<f64, 10>::from_fn(|i, _| if i == 9 { 1.0 } else { (i as f64).sin() });
        let m = SMatrix::<f64, 10, 10>::from_fn(|i, j| 1.0 / (1.0 + i as f64 + j as f64));
        let h = 0.8;
        let (f, z) = flow_and_gramian(&a, &z0, h);
        let (f2, [g]) = flow_with_integrals(&a, &[m], h);
        assert!((f - f2).norm() < 1e-13);
        let via_gramian = trace_product(&m, &z);
        let via_van_loan = z0.dot(&(g * z0));
        assert!((via_gramian - via_van_loan).abs() < 1e-13 * via_van_loan.abs());
    }

    #[test]
    fn gramian_stays_accurate_for_long_strongly_damped_steps() {
        // Strong damping over a long step: the integral against Simpson on the exact trajectory.
        let a = example10() * 8.0;
        let z0 = SVector::<f64, 10>::from_fn(|i, _| if i == 9 { 1.0 } else { 1.0 + i as f64 });
        let m = SMatrix::<f64, 10, 10>::from_fn(|i, j| if i == j && i < 9 { 1.0 } else { 0.0 });
        let h = 20.0;
        let (f, z) = flow_and_gramian(&a, &z0, h);
        assert!((f - flow(&a, h)).norm() < 1e-12 * flow(&a, h).norm());
        let n = 40000;
        let step = flow(&a, h / n as f64);
        let (mut zz, mut acc) = (z0, 0.0);
        for i in 0..=n {
            let w = simpson_weight(i, n);
            acc += w * zz.dot(&(m * zz));
            zz = step * zz;
        }
        let quad = acc * h / (3.0 * n as f64);
        let exact = trace_product(&m, &z);
        assert!((exact - quad).abs() < 1e-9 * quad, "{exact} vs {quad}");
    }

    #[test]
    fn gauss_pade_has_orders_2_4_6_and_matches_its_stages() {
        let a = example10();
        let z0 = SVector::<f64, 10>::from_fn(|i, _| if i == 9 { 1.0 } else { (i as f64).cos() });
        for s in 1..=3 {
            let mut errs = vec![];
            for h in [0.4, 0.2, 0.1] {
                let exact = flow(&a, h) * z0;
                let z = gauss::step(&a, &z0, h, s).unwrap();
                let (zs, _, _) = gauss::stages(&a, &z0, h, s).unwrap();
                assert!(
                    (z - zs).norm() < 1e-14 * z.norm(),
                    "Padé and collocation agree"
                );
                errs.push((z - exact).norm());
            }
            // local error O(h^{2s+1})
            let slope = (errs[0] / errs[2]).ln() / 4f64.ln();
            assert!(
                (slope - (2 * s + 1) as f64).abs() < 0.25,
                "s={s}: slope {slope}, {errs:?}"
            );
        }
    }

    #[test]
    fn structured_gauss_equals_the_dense_stage_solve() {
        // A matrix with the vessel's S2 block structure.
        let mut a = SMatrix::<f64, 10, 10>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                a[(i, j)] = if i == j {
                    -0.4 - 0.1 * i as f64
                } else {
                    0.05 * (i as f64 - j as f64)
                };
                a[(i, 3 + j)] = if i == j { -1.5 } else { 0.1 };
                a[(i, 6 + j)] = if i == j { -0.2 } else { 0.0 };
                a[(3 + i, j)] = if i == j { 1.0 } else { 0.02 };
                a[(6 + i, 3 + j)] = if i == j { 1.0 } else { 0.0 };
            }
            a[(i, 9)] = 0.3 * i as f64;
            a[(6 + i, 9)] = -0.1;
        }
        let z0 =
            SVector::<f64, 10>::from_fn(|i, _| if i == 9 { 1.0 } else { (i as f64 * 0.7).sin() });
        for h in [0.1, 1.0, 7.0] {
            let check = |z: SVector<f64, 10>, ys: &[SVector<f64, 10>], s: usize| {
                let (zd, yd, _) = gauss::stages(&a, &z0, h, s).unwrap();
                assert!(
                    (z - zd).norm() < 1e-13 * zd.norm(),
                    "s={s} h={h}: {}",
                    (z - zd).norm()
                );
                for (y, y2) in ys.iter().zip(&yd) {
                    assert!((y - y2).norm() < 1e-13 * y2.norm());
                }
            };
            for st in 1..=3 {
                let (z, ys, _) = gauss::structured(&a, &z0, h, st).unwrap();
                check(z, &ys[..st], st);
            }
        }
        // Not the structure: refused.
        let mut b = a;
        b[(4, 4)] = 1.0;
        assert!(gauss::structured(&b, &z0, 0.5, 1).is_none());
    }

    #[test]
    fn van_loan_integrals_match_quadrature() {
        let a = example();
        let z0 = SVector::<f64, 3>::new(1.3, -0.4, 1.0);
        let m1 = M3::new(1.0, 0.2, 0.0, 0.2, 0.5, 0.1, 0.0, 0.1, 0.0);
        let m2 = M3::new(0.0, 0.0, 0.5, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0);
        let h = 1.1;
        let (f, [g1, g2]) = flow_with_integrals(&a, &[m1, m2], h);
        assert!((f - flow(&a, h)).norm() < 1e-14);
        // Composite Simpson on the exact trajectory.
        let n = 2000;
        let simpson = |m: &M3| {
            let mut s = 0.0;
            for i in 0..=n {
                let t = h * i as f64 / n as f64;
                let z = flow(&a, t) * z0;
                let w = simpson_weight(i, n);
                s += w * z.dot(&(m * z));
            }
            s * h / (3.0 * n as f64)
        };
        for (g, m) in [(g1, m1), (g2, m2)] {
            let exact = z0.dot(&(g * z0));
            let quad = simpson(&m);
            assert!(
                (exact - quad).abs() < 1e-11 * quad.abs(),
                "{exact} vs {quad}"
            );
        }
    }
}
