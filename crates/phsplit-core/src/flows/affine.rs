//! Exact flows of affine linear systems `y' = A y + b`, and exact integrals of quadratic forms
//! along them.
//!
//! With the augmented state `z = (y, 1)` the system is `z' = Ā z`, `Ā = [[A, b], [0, 0]]`, and
//! its flow over `h` is the matrix exponential `exp(Ā h)` (the last column carries the constant
//! forcing; the φ-function form of the variation-of-constants formula is the same thing).
//!
//! Flow S2 needs the flow's action on one state, not the matrix: [`flow_action`] sums the
//! exponential's Taylor series on the vector, over pieces short enough that a degree fixed in
//! advance by the norm bound reaches the unit round-off (the truncated-Taylor action of A. H.
//! Al-Mohy, N. J. Higham, *Computing the action of the matrix exponential*, SIAM J. Sci. Comput.
//! 33 (2011) 488–511, with its pieces and degree chosen from the 1-norm alone). Where that would
//! take more than [`MAX_PIECES`] pieces (long, strongly damped sub-steps), the matrix exponential
//! (nalgebra's scaling-and-squaring Padé approximant, Higham 2005) is used instead.
//!
//! The energy ledger needs `∫₀^h z(s)ᵀ M z(s) ds` for a few symmetric `M`, that is the state
//! Gramian `Z = ∫₀^h z zᵀ ds` ([`flow_action_and_gramian_rows`]). On a piece of length `τ` the summed
//! series is a polynomial, `z(στ) = Σₖ bₖ σᵏ` with `bₖ = (τĀ)ᵏ z₀ / k!`, so its Gramian is exact:
//! `∫₀^τ z zᵀ ds = τ Σⱼₖ bⱼ bₖᵀ / (j + k + 1) = τ B H Bᵀ`, with `H` the Hilbert matrix. The pieces'
//! Gramians add up. A power `νᵀ F z` reads `ν` from a few entries of `z`, so only those rows of
//! the Gramian are formed. The fallback is Van Loan's block exponential (C. F. Van Loan, *Computing
//! integrals involving the matrix exponential*, IEEE TAC 23 (1978) 395–404): for
//! `C = [[−Āᵀ, M], [0, Ā]]`, `exp(C h) = [[F₁₁, F₁₂], [0, F₂₂]]` with `F₂₂ = exp(Ā h)` and
//! `∫₀^h exp(Āᵀs) M exp(Ā s) ds = F₂₂ᵀ F₁₂`; [`flow_and_gramian`] takes the equivalent state
//! Gramian, one `2N×2N` exponential for any number of forms. The two ways are tested against
//! each other and against quadrature of the trajectory.

use nalgebra::{Const, DimMin, SMatrix, SVector};

/// The flow `exp(Ā h)` of the augmented system.
pub fn flow<const M: usize>(abar: &SMatrix<f64, M, M>, h: f64) -> SMatrix<f64, M, M>
where
    Const<M>: DimMin<Const<M>, Output = Const<M>>,
{
    (abar * h).exp()
}

/// Each piece of a Taylor sum has `ρ = ‖Ā τ‖₁ ≤ RHO_MAX`: its terms then stay below `e^ρ ≈ 7.4`
/// times the state and the sum is at least `e^{−ρ}` times it, so summing them loses no more than
/// a few units of round-off to cancellation, even where `Ā` damps. (Al-Mohy and Higham allow
/// pieces up to `ρ ≈ 10` by a backward-error argument; a short piece keeps the bound simple.)
const RHO_MAX: f64 = 2.0;
/// Entries of the sum below this fraction of its 1-norm are summed to the norm's round-off; the
/// others to their own (see [`taylor_piece`]).
const COMPONENT_FLOOR: f64 = 1.0 / (1u64 << 26) as f64;
/// Highest Taylor degree of a piece. With `ρ ≤ 2` the remainder bound of [`taylor_piece`] is
/// below the round-off by degree 24 whatever the state (`2²⁴/24! · 2/23 < 2⁻⁵³ e⁻²`).
const MAX_DEGREE: usize = 30;
/// Most pieces of a Taylor sum before the matrix exponential is cheaper (measured on the
/// vessel's 10- and 19-dimensional systems: a piece with its Gramian rows costs well under a
/// tenth of the Van Loan exponential).
pub const MAX_PIECES: usize = 8;

/// The Hilbert matrix `1/(j + k + 1)`: the integrals `∫₀¹ σʲ σᵏ dσ`.
const HILBERT: [[f64; MAX_DEGREE + 1]; MAX_DEGREE + 1] = {
    let mut h = [[0.0; MAX_DEGREE + 1]; MAX_DEGREE + 1];
    let mut j = 0;
    while j <= MAX_DEGREE {
        let mut k = 0;
        while k <= MAX_DEGREE {
            h[j][k] = 1.0 / ((j + k + 1) as f64);
            k += 1;
        }
        j += 1;
    }
    h
};

/// The number of pieces of the Taylor sum of `exp(Ā h) z` with `θ = ‖Ā‖₁ |h|`:
/// `⌈θ / RHO_MAX⌉`, or `None` when that is more than [`MAX_PIECES`] or `θ` is not finite.
pub fn taylor_pieces(theta: f64) -> Option<usize> {
    if !theta.is_finite() {
        return None;
    }
    let pieces = (theta / RHO_MAX).ceil().max(1.0);
    (pieces <= MAX_PIECES as f64).then_some(pieces as usize)
}

/// Whether `Ā` is augmented: its last row (the constant coordinate's rate) is zero.
fn is_augmented<const N: usize>(abar: &SMatrix<f64, N, N>) -> bool {
    abar.row(N - 1).iter().all(|v| *v == 0.0)
}

/// The largest absolute column sum over the first `cols` columns.
fn max_column_sum<const N: usize>(abar: &SMatrix<f64, N, N>, cols: usize) -> f64 {
    (0..cols)
        .map(|j| abar.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// The binary exponent `e` of a positive normal `x` (`2^e ≤ x < 2^(e+1)`), from its bits.
fn binary_exponent(x: f64) -> i64 {
    ((x.to_bits() >> 52) & 0x7ff) as i64 - 1023
}

/// `2^e` for `−1022 ≤ e ≤ 1023`, exactly, from its bits.
fn power_of_two(e: i64) -> f64 {
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// `ρ = ‖A‖₁ |h|` for the Taylor sum of an augmented `Ā = [[A, b], [0, 0]]`: the largest column
/// sum of `A`'s columns. The forcing column does not count: every Taylor term after the first
/// has a zero constant entry, so `Ā` acts on them as `A`, and the remainder bound and the
/// cancellation in the sum depend on `A` alone. A matrix whose last row is not zero (not
/// augmented) counts all its columns.
pub fn taylor_norm1_times<const N: usize>(abar: &SMatrix<f64, N, N>, h: f64) -> f64 {
    let cols = if is_augmented(abar) { N - 1 } else { N };
    max_column_sum(abar, cols) * h.abs()
}

/// For an augmented system balanced by `scale` (`z = scale ∘ z_b`), rescales its constant
/// coordinate so that the balanced state `z` gives it within a factor of two of the largest of
/// its other entries, and `Ā`'s forcing column with it (a similarity by a power of two, exact).
/// The Taylor sum's stopping test is relative to the balanced state's 1-norm; a constant entry
/// of 1 beside a state of `10⁻²` would make it relative to the constant instead.
pub fn balance_constant<const N: usize>(
    abar: &mut SMatrix<f64, N, N>,
    scale: &mut SVector<f64, N>,
    z: &SVector<f64, N>,
) {
    if let Some(f) = constant_factor(scale, z) {
        abar.column_mut(N - 1).scale_mut(f);
        scale[N - 1] *= f;
    }
}

/// The power of two [`balance_constant`] multiplies the constant coordinate's scale (and the
/// forcing column) by, if any.
pub fn constant_factor<const N: usize>(
    scale: &SVector<f64, N>,
    z: &SVector<f64, N>,
) -> Option<f64> {
    let gamma = (0..N - 1)
        .map(|i| (z[i] / scale[i]).abs())
        .fold(0.0, f64::max);
    let g = (z[N - 1] / scale[N - 1]).abs() / gamma;
    if !(g.is_normal() && gamma.is_normal()) {
        return None;
    }
    Some(power_of_two(binary_exponent(g)))
}

/// For the matrix-exponential fallback: an augmented system whose constant coordinate holds
/// `c ≠ 1` (a balance of the constant, [`balance_constant`]) written again with that coordinate
/// at 1 (the forcing column times `c`): `(Ā', z', c)`. Scaling and squaring sizes its steps by
/// the whole matrix's norm, so a forcing column scaled up to a small state would make it drown
/// the dynamics in rounding. A system that is not augmented, or whose constant is 0 or not
/// finite, is returned as it is (`c = 1`).
fn unit_constant<const N: usize>(
    mut abar: SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
) -> (SMatrix<f64, N, N>, SVector<f64, N>, f64) {
    let c = z0[N - 1];
    if !is_augmented(&abar) || !c.is_normal() {
        return (abar, *z0, 1.0);
    }
    abar.column_mut(N - 1).scale_mut(c);
    let mut z = *z0;
    z[N - 1] = 1.0;
    (abar, z, c)
}

/// `‖Ā‖₁ |h|`: the largest column sum.
fn norm1_times<const N: usize>(abar: &SMatrix<f64, N, N>, h: f64) -> f64 {
    max_column_sum(abar, N) * h.abs()
}

/// `c A x`, column by column.
#[inline(always)]
pub fn matvec<const N: usize>(
    a: &SMatrix<f64, N, N>,
    x: &SVector<f64, N>,
    c: f64,
) -> SVector<f64, N> {
    let mut y = [0.0; N];
    for (j, col) in a.as_slice().chunks_exact(N).enumerate() {
        let xj = x[j] * c;
        for (yi, aij) in y.iter_mut().zip(col) {
            *yi += aij * xj;
        }
    }
    SVector::from(y)
}

/// One piece: the Taylor terms `bₖ = (τĀ)ᵏ z / k!` into `b` and their sum, and the degree `m`
/// reached; `apply(x, c)` is `c Ā x`. The sum stops at the first `m` whose remainder bound is
/// below the unit round-off of the sum, `‖b_m‖₁ ρ/(m + 1 − ρ) ≤ 2⁻⁵³ ‖Σ bₖ‖₁` with `ρ = ‖τĀ‖₁`:
/// every later term is at most `ρ/(m+1)` times the one before (`b_{m+j} = (τĀ)ʲ b_m m!/(m+j)!`),
/// so the rest of the series is below that geometric sum, on the whole piece (`Σ bₖ σᵏ`,
/// `0 ≤ σ ≤ 1`). This is the stopping test of Al-Mohy and Higham (2011, §3) made a bound.
fn taylor_piece<const N: usize>(
    apply: &impl Fn(&SVector<f64, N>, f64) -> SVector<f64, N>,
    tau: f64,
    rho: f64,
    z: &SVector<f64, N>,
    b: &mut [SVector<f64, N>; MAX_DEGREE + 1],
) -> (SVector<f64, N>, usize) {
    b[0] = *z;
    let mut sum = *z;
    let mut m = 0;
    while m < MAX_DEGREE {
        m += 1;
        b[m] = apply(&b[m - 1], tau / m as f64);
        sum += b[m];
        let factor = rho / (m as f64 + 1.0 - rho);
        let norm = sum.lp_norm(1);
        let tail = b[m].lp_norm(1) * factor;
        let floor = COMPONENT_FLOOR * norm;
        if tail <= 0.5 * f64::EPSILON * norm
            && b[m]
                .iter()
                .zip(sum.iter())
                .all(|(bi, si)| bi.abs() * factor <= 0.5 * f64::EPSILON * si.abs().max(floor))
        {
            break;
        }
    }
    (sum, m)
}

/// The flow's action `exp(Ā h) z0`: the Taylor sum over [`taylor_pieces`]'s pieces, or the
/// matrix exponential where that would take too many.
pub fn flow_action<const N: usize>(
    abar: &SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    let norm1 = taylor_norm1_times(abar, 1.0);
    flow_action_by(norm1, |x, c| matvec(abar, x, c), || *abar, z0, h)
}

/// [`flow_action`] with the operator given by the caller: `apply(x, c) = c Ā x` (a structured
/// product), `norm1 = ‖A‖₁` as [`taylor_norm1_times`] measures it (per unit time), and `dense`,
/// which builds `Ā` only for the fallback.
pub fn flow_action_by<const N: usize>(
    norm1: f64,
    apply: impl Fn(&SVector<f64, N>, f64) -> SVector<f64, N>,
    dense: impl FnOnce() -> SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    let theta = norm1 * h.abs();
    let Some(pieces) = taylor_pieces(theta) else {
        return flow_action_dense(dense(), z0, h);
    };
    let tau = h / pieces as f64;
    let rho = theta / pieces as f64;
    let mut b = [SVector::<f64, N>::zeros(); MAX_DEGREE + 1];
    let mut z = *z0;
    for _ in 0..pieces {
        z = taylor_piece(&apply, tau, rho, &z, &mut b).0;
    }
    z
}

/// The flow's action `z(h) = exp(Ā h) z0` and the rows `rows` of the Gramian
/// `Z = ∫₀^h z(s) z(s)ᵀ ds` of the trajectory (signed: a negative `h` integrates backwards),
/// `Y[r, :] = Z[rows[r], :]`. By the Taylor sum over [`taylor_pieces`]'s pieces, each piece's
/// Gramian `τ B H Bᵀ` exact for its polynomial; or, where that would take too many pieces, by
/// Van Loan's exponential ([`flow_and_gramian`], `N2 = 2N`). A quadratic form whose matrix is
/// zero outside the rows `rows` (a power `νᵀ F z` with `ν` read from those entries) has
/// `∫ zᵀ R z ds = Σ R ∘ Y` over those rows.
pub fn flow_action_and_gramian_rows<const N: usize, const R: usize, const N2: usize>(
    abar: &SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
    rows: &[usize; R],
) -> (SVector<f64, N>, SMatrix<f64, R, N>)
where
    Const<N2>: DimMin<Const<N2>, Output = Const<N2>>,
{
    let norm1 = taylor_norm1_times(abar, 1.0);
    flow_action_and_gramian_rows_by::<N, R, N2>(
        norm1,
        |x, c| matvec(abar, x, c),
        || *abar,
        z0,
        h,
        rows,
    )
}

/// [`flow_action_and_gramian_rows`] with the operator given by the caller, as for
/// [`flow_action_by`].
pub fn flow_action_and_gramian_rows_by<const N: usize, const R: usize, const N2: usize>(
    norm1: f64,
    apply: impl Fn(&SVector<f64, N>, f64) -> SVector<f64, N>,
    dense: impl FnOnce() -> SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
    rows: &[usize; R],
) -> (SVector<f64, N>, SMatrix<f64, R, N>)
where
    Const<N2>: DimMin<Const<N2>, Output = Const<N2>>,
{
    let theta = norm1 * h.abs();
    let Some(pieces) = taylor_pieces(theta) else {
        return flow_action_and_gramian_rows_dense::<N, R, N2>(dense(), z0, h, rows);
    };
    let tau = h / pieces as f64;
    let rho = theta / pieces as f64;
    let mut b = [SVector::<f64, N>::zeros(); MAX_DEGREE + 1];
    let mut y = SMatrix::<f64, R, N>::zeros();
    let mut z = *z0;
    for _ in 0..pieces {
        let (next, m) = taylor_piece(&apply, tau, rho, &z, &mut b);
        // Y += τ Σ_k v_k b_kᵀ with v_k = Σ_j H_jk b_j[rows] (j outermost, so that the sums
        // over k are independent of each other).
        // By row r, each v_r contiguous in k (the inner loop runs along a row of H).
        let mut v = [[0.0; MAX_DEGREE + 1]; R];
        for j in 0..=m {
            for (vr, &row) in v.iter_mut().zip(rows) {
                let bjr = b[j][row] * tau;
                for (vrk, hjk) in vr[..=m].iter_mut().zip(&HILBERT[j]) {
                    *vrk += hjk * bjr;
                }
            }
        }
        for k in 0..=m {
            let vk = SVector::<f64, R>::from_fn(|r, _| v[r][k]);
            y.ger(1.0, &vk, &b[k], 1.0);
        }
        z = next;
    }
    (z, y)
}

/// [`flow_action_by`]'s fallback, the dense exponential, out of line: its matrices' frame
/// (tens of kilobytes with Van Loan's) would otherwise be the caller's on every call, probed
/// page by page, although the Taylor sum serves nearly every sub-step.
#[cold]
#[inline(never)]
fn flow_action_dense<const N: usize>(
    abar: SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    let (abar, z, c) = unit_constant(abar, z0);
    let mut z1 = flow(&abar, h) * z;
    z1[N - 1] *= c;
    z1
}

/// [`flow_action_and_gramian_rows_by`]'s fallback, Van Loan's exponential, out of line (as
/// [`flow_action_dense`]).
#[cold]
#[inline(never)]
fn flow_action_and_gramian_rows_dense<const N: usize, const R: usize, const N2: usize>(
    abar: SMatrix<f64, N, N>,
    z0: &SVector<f64, N>,
    h: f64,
    rows: &[usize; R],
) -> (SVector<f64, N>, SMatrix<f64, R, N>)
where
    Const<N2>: DimMin<Const<N2>, Output = Const<N2>>,
{
    let (abar, z, c) = unit_constant(abar, z0);
    let (f, gram) = flow_and_gramian::<N, N2>(&abar, &z, h);
    let mut z1 = f * z;
    z1[N - 1] *= c;
    // Back to the caller's constant coordinate: Z = D Z' D with D = diag(1, …, 1, c).
    let d = |i: usize| if i == N - 1 { c } else { 1.0 };
    (
        z1,
        SMatrix::from_fn(|r, j| gram[(rows[r], j)] * d(rows[r]) * d(j)),
    )
}

/// `2^round(log2 x)` for a positive normal `x`, from its bits: `2^e` or `2^(e+1)` as its
/// mantissa is below or above √2 (no `log2`, `round` or `powi`).
pub fn nearest_power_of_two(x: f64) -> f64 {
    let e = binary_exponent(x);
    let mantissa = x / power_of_two(e);
    power_of_two(if mantissa >= std::f64::consts::SQRT_2 {
        e + 1
    } else {
        e
    })
}

/// Most sweeps of [`balance`] (it stops at the first sweep that changes nothing; the vessel's
/// blocks take two or three).
const SWEEPS: usize = 16;

/// Balances `a` in place by a diagonal similarity in powers of two, `a ← D⁻¹ a D`, and
/// multiplies `scale` by `D` (so a state `z` of the original system is `scale ∘ z_b`): the
/// iteration of E. E. Osborne, *On pre-conditioning of matrices*, J. ACM 7 (1960) 338–345, in the
/// form of B. N. Parlett, C. Reinsch, *Balancing a matrix for calculation of eigenvalues and
/// eigenvectors*, Numer. Math. 13 (1969) 293–304 (LAPACK's `gebal`). Each index's off-diagonal
/// column and row sums are brought within a factor of two of each other while that lowers their
/// total by 5 %, for at most [`SWEEPS`] sweeps over the indices. Powers of two keep the
/// similarity exact, so only the 1-norm changes, and with it the Taylor degree and the
/// cancellation in the sum: a restoring spring of `2·10⁹ N/m` on a mass of `10⁷ kg` has entries
/// `30` and `0.016` whose product, the squared frequency, is what the flow sees.
pub fn balance<const N: usize>(a: &mut SMatrix<f64, N, N>, scale: &mut SVector<f64, N>) {
    // The off-diagonal magnitudes (column-major, as `a`) and their column sums `c` and row sums
    // `r`, kept up to date as indices are scaled: no sum is a chain of dependent adds.
    // An augmented matrix (last row zero) is balanced on its dynamics alone: the forcing column
    // has no fixed size (the constant coordinate's scale is chosen per state, balance_constant)
    // and must not steer the other indices' factors.
    let augmented = is_augmented(a);
    let s = a.as_mut_slice();
    let mut m = [[0.0; N]; N];
    for (j, col) in m.iter_mut().enumerate() {
        for (i, v) in col.iter_mut().enumerate() {
            let outside = i == j || (augmented && (i == N - 1 || j == N - 1));
            *v = if outside { 0.0 } else { s[j * N + i].abs() };
        }
    }
    let mut c = [0.0; N];
    let mut r = [0.0; N];
    for i in 0..N {
        for (cj, col) in c.iter_mut().zip(&m) {
            *cj += col[i];
        }
    }
    for col in &m {
        for (ri, v) in r.iter_mut().zip(col) {
            *ri += v;
        }
    }
    for _ in 0..SWEEPS {
        let mut changed = false;
        for i in 0..N {
            let q = r[i] / c[i];
            if !(q.is_normal() && q > 0.0) {
                continue;
            }
            // A power of two within √2 of √q, from q's binary exponent e: 2^⌈e/2⌉.
            let f = power_of_two((binary_exponent(q) + 1).div_euclid(2));
            if c[i] * f + r[i] / f < 0.95 * (c[i] + r[i]) {
                // Column i grows by f and row i shrinks by f, and with them the other rows'
                // and columns' sums that hold their entries.
                for k in 0..N {
                    r[k] += m[i][k] * (f - 1.0);
                    c[k] += m[k][i] * (1.0 / f - 1.0);
                    m[i][k] *= f;
                    m[k][i] /= f;
                    s[i * N + k] *= f;
                    s[k * N + i] /= f;
                }
                // (The diagonal entry was multiplied and divided by f: unchanged, and zero in m.)
                c[i] *= f;
                r[i] /= f;
                scale[i] *= f;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
}

/// The flow `exp(Ā h)` of an `N`-dimensional augmented system and the Gramian
/// `Z = ∫₀^h z(s) z(s)ᵀ ds` of its trajectory from `z0`, from one `2N×2N` exponential
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
    let norm1 = norm1_times(abar, h);
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
    use crate::lie::double_double::Dd;

    /// The reference action `exp(Ā h) z0` in double-double arithmetic (about 32 digits),
    /// written apart from the code under test: the plain Taylor series with 60 terms on `2^k`
    /// pieces of `‖Ā τ‖₁ ≤ 1/4` (remainder below `4⁻⁶¹/61!`), `τ = h/2^k` exact.
    pub(crate) fn reference_action<const N: usize>(
        a: &SMatrix<f64, N, N>,
        z0: &SVector<f64, N>,
        h: f64,
    ) -> [Dd; N] {
        let norm = (0..N)
            .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let mut k = 0;
        while norm * h.abs() / 2f64.powi(k) > 0.25 {
            k += 1;
        }
        let tau = h / 2f64.powi(k);
        let mut z: [Dd; N] = std::array::from_fn(|i| Dd::new(z0[i]));
        for _ in 0..(1u64 << k) {
            let mut term = z;
            let mut sum = z;
            for m in 1..=60 {
                // a[(i, j)] τ is taken in double-double too.
                let next: [Dd; N] = std::array::from_fn(|i| {
                    (0..N).fold(Dd::new(0.0), |acc, j| {
                        acc.add(term[j].mul(Dd::new(a[(i, j)]).mul(Dd::new(tau))))
                    })
                });
                term = std::array::from_fn(|i| next[i].div(Dd::new(m as f64)));
                sum = std::array::from_fn(|i| sum[i].add(term[i]));
            }
            z = sum;
        }
        z
    }

    /// A vessel-like augmented system, unbalanced as flow S2 assembles it: a slow large
    /// position, a heave oscillator whose state is 10⁴ times smaller, a roll spring with entries
    /// 30 and 0.016, damping, an integral state and a constant forcing.
    fn vessel_like() -> SMatrix<f64, 10, 10> {
        let mut a = SMatrix::<f64, 10, 10>::zeros();
        a[(0, 0)] = -0.63;
        a[(0, 3)] = -0.02;
        a[(0, 6)] = -1e-4;
        a[(1, 1)] = -0.05;
        a[(1, 4)] = -29.85;
        a[(1, 7)] = -2e-3;
        a[(2, 2)] = -0.23;
        a[(2, 5)] = -2.18;
        a[(3, 0)] = 0.99;
        a[(3, 1)] = 0.1;
        a[(4, 1)] = 0.0156;
        a[(5, 2)] = 0.998;
        a[(5, 0)] = 0.02;
        a[(6, 3)] = 1.0;
        a[(7, 4)] = 1.0;
        a[(8, 5)] = 1.0;
        a[(0, 9)] = 0.05;
        a[(8, 9)] = -0.44;
        a
    }

    fn vessel_like_state() -> SVector<f64, 10> {
        SVector::from_column_slice(&[
            6.8, 0.8, -4.8e-4, -110.0, -0.02, 5.2e-4, -89.0, -0.16, 6.2e-4, 1.0,
        ])
    }

    /// Each entry of `z` against the reference: within `tol` of itself, or of `floor` times the
    /// reference's largest entry for entries below that.
    fn assert_componentwise<const N: usize>(
        z: &SVector<f64, N>,
        r: &[Dd; N],
        tol: f64,
        floor: f64,
        what: &str,
    ) {
        let big = r.iter().map(|v| v.hi.abs()).fold(0.0, f64::max);
        for i in 0..N {
            let err = (Dd::new(z[i]).add(r[i].neg())).hi.abs();
            let size = r[i].hi.abs().max(floor * big);
            assert!(
                err <= tol * size,
                "{what}: entry {i}: {} vs {} (error {err:.2e})",
                z[i],
                r[i].hi
            );
        }
    }

    #[test]
    fn the_taylor_action_matches_the_double_double_series_entry_by_entry() {
        let mut a = vessel_like();
        let mut scale = SVector::<f64, 10>::from_element(1.0);
        balance(&mut a, &mut scale);
        let z = vessel_like_state();
        balance_constant(&mut a, &mut scale, &z);
        let zb = z.component_div(&scale);
        for h in [0.0, 0.05, 0.5, -0.7, 2.0, 6.0, 40.0] {
            let r = reference_action(&a, &zb, h);
            // Every case a Taylor sum but the last, the Padé fallback.
            let pieces = taylor_pieces(taylor_norm1_times(&a, h));
            assert_eq!(pieces.is_none(), h == 40.0, "h = {h}: {pieces:?}");
            // The Padé fallback (nalgebra's scaling and squaring, 40 s: 20 squarings) is
            // accurate in norm, not entry by entry (5.7e-14 on the roll entry).
            let tol = if pieces.is_some() { 8e-15 } else { 1e-12 };
            assert_componentwise(
                &flow_action(&a, &zb, h),
                &r,
                tol,
                1e-8,
                &format!("vessel-like, h = {h}"),
            );
            let (z1, _) = flow_action_and_gramian_rows::<10, 3, 20>(&a, &zb, h, &[0, 1, 2]);
            assert_componentwise(
                &z1,
                &r,
                tol,
                1e-8,
                &format!("vessel-like with Gramian, h = {h}"),
            );
        }
        // In the chain every entry is a sum of its neighbours' of order 1, so an entry near
        // zero carries their rounding: the check is relative to the largest entry there.
        let a = example10();
        let z0 = SVector::<f64, 10>::from_fn(|i, _| if i == 9 { 1.0 } else { (i as f64).sin() });
        for h in [0.1, 0.8, -1.3, 7.5] {
            let r = reference_action(&a, &z0, h);
            let z1 = flow_action(&a, &z0, h);
            assert_componentwise(&z1, &r, 8e-15, 1.0, &format!("chain, h = {h}"));
        }
    }

    #[test]
    fn the_gramian_rows_match_van_loan_and_the_quadrature_of_the_trajectory() {
        let mut a = vessel_like();
        let mut scale = SVector::<f64, 10>::from_element(1.0);
        balance(&mut a, &mut scale);
        let z0 = vessel_like_state().component_div(&scale);
        let rows = [0, 1, 2, 5];
        // One piece, several, backwards, and the Van Loan fallback itself.
        for h in [0.05, 0.5, 3.0, -0.9, 12.0, 40.0] {
            let (z1, y) = flow_action_and_gramian_rows::<10, 4, 20>(&a, &z0, h, &rows);
            let (f, gram) = flow_and_gramian::<10, 20>(&a, &z0, h);
            assert!((z1 - f * z0).norm() <= 1e-13 * z1.norm(), "h = {h}");
            for (r, &i) in rows.iter().enumerate() {
                let row = gram.row(i);
                let err = (y.row(r) - row).norm();
                assert!(
                    err <= 1e-12 * row.norm(),
                    "h = {h}, row {i}: {err:.2e} of {:.2e}",
                    row.norm()
                );
            }
            // Simpson on the trajectory from the reference flow (n = 2000 intervals).
            if h.abs() <= 3.0 {
                let n = 2000;
                let step = flow(&a, h / n as f64);
                let mut zz = z0;
                let mut acc = SMatrix::<f64, 4, 10>::zeros();
                for k in 0..=n {
                    let w = simpson_weight(k, n) * h / (3.0 * n as f64);
                    let zr = SVector::<f64, 4>::from_fn(|r, _| zz[rows[r]]);
                    acc += zr * zz.transpose() * w;
                    zz = step * zz;
                }
                assert!((y - acc).norm() <= 1e-10 * acc.norm(), "h = {h}: Simpson");
            }
        }
    }

    #[test]
    fn balancing_is_an_exact_similarity_that_brings_a_spring_pair_together() {
        let a0 = vessel_like();
        let mut a = a0;
        let mut scale = SVector::<f64, 10>::from_element(1.0);
        balance(&mut a, &mut scale);
        for i in 0..10 {
            assert_eq!(
                scale[i],
                2f64.powi(scale[i].log2().round() as i32),
                "a power of two"
            );
            for j in 0..10 {
                assert_eq!(
                    a[(i, j)],
                    a0[(i, j)] * scale[j] / scale[i],
                    "exact similarity"
                );
            }
        }
        // The roll spring's entries 29.85 and 0.0156 end within a factor 8 of their geometric
        // mean 0.68, and the 1-norm of the dynamics falls.
        let g = (29.85f64 * 0.0156).sqrt();
        assert!(
            a[(1, 4)].abs() / g < 8.0 && g / a[(4, 1)].abs() < 8.0,
            "{} {}",
            a[(1, 4)],
            a[(4, 1)]
        );
        assert!(taylor_norm1_times(&a, 1.0) < 0.2 * taylor_norm1_times(&a0, 1.0));
        // The constant coordinate ends within a factor 2 of the state's largest entry.
        let z = vessel_like_state();
        balance_constant(&mut a, &mut scale, &z);
        let zb = z.component_div(&scale);
        let big = zb.rows(0, 9).amax();
        assert!(
            zb[9] >= 0.5 * big && zb[9] <= 2.0 * big,
            "{} vs {big}",
            zb[9]
        );
        // A similarity: the flow of the balanced system is the flow of the original.
        let r = flow(&a0, 0.5) * z;
        let zt = flow_action(&a, &zb, 0.5).component_mul(&scale);
        assert!((zt - r).norm() <= 1e-13 * r.norm());
    }

    #[test]
    fn the_nearest_power_of_two_rounds_the_logarithm() {
        for x in [1.0, 1.4, 1.42, 3.0, 1e-300, 2.9e9, 6.1e-5, 1e300, 0.7] {
            assert_eq!(
                nearest_power_of_two(x),
                2f64.powi(x.log2().round() as i32),
                "{x}"
            );
        }
    }

    #[test]
    fn the_taylor_pieces_follow_the_norm() {
        assert_eq!(taylor_pieces(0.0), Some(1));
        assert_eq!(taylor_pieces(2.0), Some(1));
        assert_eq!(taylor_pieces(2.5), Some(2));
        assert_eq!(taylor_pieces(16.0), Some(8));
        assert_eq!(taylor_pieces(16.5), None);
        assert_eq!(taylor_pieces(f64::NAN), None);
        assert_eq!(taylor_pieces(f64::INFINITY), None);
    }
}
