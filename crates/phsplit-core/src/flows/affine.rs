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

use nalgebra::{Const, DimMin, SMatrix, SVector};

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
pub fn flow_and_gramian<const N: usize, const N2: usize>(
    abar: &SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>)
where
    Const<N2>: DimMin<Const<N2>, Output = Const<N2>>,
{
    assert_eq!(
        N2,
        2 * N,
        "the Van Loan exponential is twice the system's size"
    );
    let norm1 = (0..N)
        .map(|j| abar.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
        * h.abs();
    let k = if norm1 > 1.0 {
        norm1.log2().ceil().min(60.0) as i32
    } else {
        0
    };
    let tau = h / 2f64.powi(k);
    let mut c = SMatrix::<f64, N2, N2>::zeros();
    c.fixed_view_mut::<N, N>(0, 0).copy_from(&(abar * tau));
    c.fixed_view_mut::<N, N>(0, N)
        .copy_from(&(z0 * z0.transpose() * tau));
    c.fixed_view_mut::<N, N>(N, N)
        .copy_from(&(-abar.transpose() * tau));
    let e = c.exp();
    let mut phi: SMatrix<f64, N, N> = e.fixed_view::<N, N>(0, 0).into_owned();
    let f12: SMatrix<f64, N, N> = e.fixed_view::<N, N>(0, N).into_owned();
    let mut z = f12 * phi.transpose();
    for _ in 0..k {
        z += phi * z * phi.transpose();
        phi *= phi;
    }
    (phi, z)
}

/// `tr(M Z)` for symmetric `M`: the integral `∫ zᵀ M z ds` given the Gramian `Z`.
pub fn trace_product<const N: usize>(m: &SMatrix<f64, N, N>, z: &SMatrix<f64, N, N>) -> f64 {
    m.component_mul(z).sum()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use nalgebra::{DMatrix, SMatrix, SVector};

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

    pub(crate) fn example10() -> SMatrix<f64, 10, 10> {
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
        let (f, z) = flow_and_gramian::<10, 20>(&a, &z0, h);
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
        let (f, z) = flow_and_gramian::<10, 20>(&a, &z0, h);
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
