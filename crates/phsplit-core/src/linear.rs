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
//! `∫₀^h exp(Āᵀs) M exp(Ā s) ds = F₂₂ᵀ F₁₂`. Several forms share one exponential of
//! `[[−Āᵀ, 0, M₁], [0, −Āᵀ, M₂], [0, 0, Ā]]`, whose top-right blocks are the `F₁₂` of each.

use nalgebra::{Const, DMatrix, DimMin, SMatrix};

/// The flow `exp(Ā h)` of the augmented system.
pub fn flow<const M: usize>(abar: &SMatrix<f64, M, M>, h: f64) -> SMatrix<f64, M, M>
where
    Const<M>: DimMin<Const<M>, Output = Const<M>>,
{
    (abar * h).exp()
}

/// The flow `exp(Ā h)` and the Gram integrals `∫₀^h exp(Āᵀs) Mᵢ exp(Ā s) ds` of `K` forms.
pub fn flow_with_integrals<const M: usize, const K: usize>(
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{SMatrix, SVector};

    type M3 = SMatrix<f64, 3, 3>;

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
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
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
