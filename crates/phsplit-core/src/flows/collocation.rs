//! Gauss–Legendre collocation with `s` stages (`s = 1, 2, 3`; orders 2, 4, 6), on a linear
//! system: its update is the diagonal `(s, s)` Padé approximant of the exponential, and for a
//! port-Hamiltonian linear system it conserves the storage exactly where the system does and
//! dissipates it where the system does (algebraic stability; paper Remark 2.3).

use nalgebra::{Complex, ComplexField, Matrix3, Vector3};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use std::sync::OnceLock;

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

/// `M x = r` for a 3×3 `M` (real or complex) by Gaussian elimination with partial
/// pivoting; `None` if a pivot vanishes or the result is not finite.
pub fn solve3<T>(m: &Matrix3<T>, r: &Vector3<T>) -> Option<Vector3<T>>
where
    T: ComplexField<RealField = f64> + Copy,
{
    let (mut m, mut r) = (*m, *r);
    for k in 0..3 {
        let mut p = k;
        for i in k + 1..3 {
            if m[(i, k)].norm1() > m[(p, k)].norm1() {
                p = i;
            }
        }
        if !(m[(p, k)].norm1() > 0.0) {
            return None;
        }
        if p != k {
            m.swap_rows(p, k);
            r.swap_rows(p, k);
        }
        let inv = T::one() / m[(k, k)];
        for i in k + 1..3 {
            let f = m[(i, k)] * inv;
            for j in k + 1..3 {
                let mkj = m[(k, j)];
                m[(i, j)] -= f * mkj;
            }
            let rk = r[k];
            r[i] -= f * rk;
        }
    }
    let mut x = Vector3::<T>::zeros();
    for k in (0..3).rev() {
        let mut acc = r[k];
        for j in k + 1..3 {
            acc -= m[(k, j)] * x[j];
        }
        x[k] = acc / m[(k, k)];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// An affine system in 3-blocks with the structure of the vessel's flow S2 (paper eq. 41),
/// state `z = (u, v, w)`:
/// `u' = A_uu u + A_uv v + A_uw w + c_u`, `v' = A_vu u`, `w' = A_wv v + c_w`.
/// Translation: `(p, x − x_o, phi_x)` (`x_o` the controller's set point `x_ref` when there is
/// a controller, else 0); rotation: `(m, mu, phi_th)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Blocks {
    pub auu: Matrix3<f64>,
    pub auv: Matrix3<f64>,
    pub auw: Matrix3<f64>,
    pub cu: Vector3<f64>,
    pub avu: Matrix3<f64>,
    pub awv: Matrix3<f64>,
    pub cw: Vector3<f64>,
}

/// A state `(u, v, w)` of a [`Blocks`] system.
pub type Z3 = [Vector3<f64>; 3];

impl Blocks {
    /// The vector field at `z`.
    pub fn field(&self, z: &Z3) -> Z3 {
        let [u, v, w] = z;
        [
            self.auu * u + self.auv * v + self.auw * w + self.cu,
            self.avu * u,
            self.awv * v + self.cw,
        ]
    }

    /// The system in the coordinates `z = d ∘ z_b` (`d` over `(u, v, w, 1)`): the blocks of
    /// `diag(d)⁻¹ Ā diag(d)`, with the forcing scaled by the constant's `d[9]`.
    pub fn scaled(&self, d: &SVector<f64, 10>) -> Self {
        let part = |o: usize| Vector3::new(d[o], d[o + 1], d[o + 2]);
        let (du, dv, dw) = (part(0), part(3), part(6));
        let (iu, iv, iw) = (
            du.map(|x| 1.0 / x),
            dv.map(|x| 1.0 / x),
            dw.map(|x| 1.0 / x),
        );
        let sim = |m: &Matrix3<f64>, rows: &Vector3<f64>, cols: &Vector3<f64>| {
            Matrix3::from_fn(|r, c| m[(r, c)] * cols[c] * rows[r])
        };
        Self {
            auu: sim(&self.auu, &iu, &du),
            auv: sim(&self.auv, &iu, &dv),
            auw: sim(&self.auw, &iu, &dw),
            cu: self.cu.component_mul(&iu) * d[9],
            avu: sim(&self.avu, &iv, &du),
            awv: sim(&self.awv, &iw, &dv),
            cw: self.cw.component_mul(&iw) * d[9],
        }
    }

    /// `‖A‖₁` of the system without its forcing: the largest column sum of `|A|` over the
    /// columns of `u`, `v` and `w`.
    pub fn dynamics_norm1(&self) -> f64 {
        let col =
            |m: &[&Matrix3<f64>], c: usize| m.iter().map(|b| b.column(c).abs().sum()).sum::<f64>();
        (0..3)
            .map(|c| {
                col(&[&self.auu, &self.avu], c)
                    .max(col(&[&self.auv, &self.awv], c))
                    .max(col(&[&self.auw], c))
            })
            .fold(0.0, f64::max)
    }

    /// `c Ā z̄` on the augmented state `z̄ = (u, v, w, 1)`: the nonzero 3×3 products only (45
    /// multiplications where the dense 10×10 matrix has 100).
    #[inline]
    pub fn apply_augmented(&self, z: &SVector<f64, 10>, c: f64) -> SVector<f64, 10> {
        let u = z.fixed_rows::<3>(0);
        let v = z.fixed_rows::<3>(3);
        let w = z.fixed_rows::<3>(6);
        let one = z[9];
        let mut out = SVector::<f64, 10>::zeros();
        out.fixed_rows_mut::<3>(0)
            .copy_from(&((self.auu * u + self.auv * v + self.auw * w + self.cu * one) * c));
        out.fixed_rows_mut::<3>(3).copy_from(&((self.avu * u) * c));
        out.fixed_rows_mut::<3>(6)
            .copy_from(&((self.awv * v + self.cw * one) * c));
        out
    }

    /// The same system as a 10×10 augmented matrix `Ā` acting on `(u, v, w, 1)`.
    pub fn augmented(&self) -> SMatrix<f64, 10, 10> {
        let mut a = SMatrix::<f64, 10, 10>::zeros();
        a.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.auu);
        a.fixed_view_mut::<3, 3>(0, 3).copy_from(&self.auv);
        a.fixed_view_mut::<3, 3>(0, 6).copy_from(&self.auw);
        a.fixed_view_mut::<3, 1>(0, 9).copy_from(&self.cu);
        a.fixed_view_mut::<3, 3>(3, 0).copy_from(&self.avu);
        a.fixed_view_mut::<3, 3>(6, 3).copy_from(&self.awv);
        a.fixed_view_mut::<3, 1>(6, 9).copy_from(&self.cw);
        a
    }

    /// The blocks of a 10×10 augmented matrix, if it has this structure (the other
    /// entries zero).
    pub fn from_augmented(a: &SMatrix<f64, 10, 10>) -> Option<Self> {
        let blk = |r: usize, c: usize| -> Matrix3<f64> { a.fixed_view::<3, 3>(r, c).into_owned() };
        let col = |r: usize| -> Vector3<f64> { a.fixed_view::<3, 1>(r, 9).into_owned() };
        let zero3 = |m: Matrix3<f64>| m.iter().all(|v| *v == 0.0);
        let ok = zero3(blk(3, 3))
            && zero3(blk(3, 6))
            && col(3).iter().all(|v| *v == 0.0)
            && zero3(blk(6, 0))
            && zero3(blk(6, 6))
            && a.row(9).iter().all(|v| *v == 0.0);
        ok.then(|| Self {
            auu: blk(0, 0),
            auv: blk(0, 3),
            auw: blk(0, 6),
            cu: col(0),
            avu: blk(3, 0),
            awv: blk(6, 3),
            cw: col(6),
        })
    }
}

/// One eigenpair of the transposed Gauss matrix, `𝒜ᵀ t = λ t`, with `τ` the matching row
/// of `T⁻¹` (`T` the matrix of eigenvectors); `pair` when `λ` stands for itself and its
/// conjugate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mode {
    pub(crate) lam: Complex<f64>,
    pub(crate) t: [Complex<f64>; 3],
    pub(crate) tau: [Complex<f64>; 3],
    pub(crate) pair: bool,
}

/// The `s`-stage Gauss tableau with what the transformed stage solve needs, computed once.
#[derive(Debug)]
pub(crate) struct Transformed {
    pub(crate) a: [[f64; 3]; 3],
    /// `𝒜1, 𝒜²1, 𝒜³1` (the first is the nodes).
    pub(crate) pow1: [[f64; 3]; 3],
    /// `bᵀ𝒜⁻¹`: the update is `z1 = z0 + Σ d_i (Z_i − z0)`.
    pub(crate) d: [f64; 3],
    pub(crate) modes: [Mode; 2],
    pub(crate) n_modes: usize,
}

pub(crate) fn transformed(s: usize) -> &'static Transformed {
    static CACHE: [OnceLock<Transformed>; 3] = [const { OnceLock::new() }; 3];
    CACHE[s - 1].get_or_init(|| build_transformed(s))
}

/// Diagonalise `𝒜ᵀ` (Butcher's transformation, as in implementations of implicit
/// Runge–Kutta methods: E. Hairer, G. Wanner, *Solving ODEs II*, §IV.8). The Gauss matrix has
/// distinct eigenvalues (the reciprocals of the roots of the Padé denominator): `1/2` for
/// `s = 1`, one complex pair for `s = 2`, one real value and one pair for `s = 3`.
fn build_transformed(s: usize) -> Transformed {
    let (ta, tb) = tableau(s);
    let mut am = Matrix3::<f64>::identity(); // padded with the identity beyond s
    for i in 0..s {
        for j in 0..s {
            am[(i, j)] = ta[i][j];
        }
    }
    let one = Vector3::from_fn(|i, _| if i < s { 1.0 } else { 0.0 });
    let p1 = am * one;
    let p2 = am * p1;
    let p3 = am * p2;
    let ainv = am.try_inverse().expect("the Gauss matrix is invertible");
    let bv = Vector3::from(tb);
    let d = ainv.transpose() * bv;
    let at = am.transpose().map(Complex::from);
    // Eigenvectors of 𝒜ᵀ in the leading s×s block; beyond s, the unit vectors.
    let mut tm = Matrix3::<Complex<f64>>::identity();
    let mut lams = Vec::new();
    // The padded eigenvalue 1 belongs to the identity block; take the first s eigenvalues
    // of the leading block.
    let lead: Vec<Complex<f64>> = match s {
        1 => vec![Complex::from(0.5)],
        2 => {
            let x = nalgebra::Matrix2::new(ta[0][0], ta[0][1], ta[1][0], ta[1][1]);
            x.complex_eigenvalues().iter().copied().collect()
        }
        _ => am.complex_eigenvalues().iter().copied().collect(),
    };
    for (k, lam) in lead.iter().enumerate() {
        let mut m = at - Matrix3::<Complex<f64>>::identity() * *lam;
        for i in s..3 {
            for j in 0..3 {
                m[(i, j)] = Complex::from(0.0);
                m[(j, i)] = Complex::from(0.0);
            }
        }
        let t: Vector3<Complex<f64>> = match s {
            1 => Vector3::new(Complex::from(1.0), Complex::from(0.0), Complex::from(0.0)),
            2 => Vector3::new(-m[(0, 1)], m[(0, 0)], Complex::from(0.0)),
            _ => {
                let (r0, r1) = (m.row(0).transpose(), m.row(1).transpose());
                Vector3::new(
                    r0[1] * r1[2] - r0[2] * r1[1],
                    r0[2] * r1[0] - r0[0] * r1[2],
                    r0[0] * r1[1] - r0[1] * r1[0],
                )
            }
        };
        tm.set_column(k, &t);
        lams.push(*lam);
    }
    let tinv = tm
        .try_inverse()
        .expect("the Gauss matrix is diagonalisable");
    let mut modes = [Mode {
        lam: Complex::from(0.0),
        t: [Complex::from(0.0); 3],
        tau: [Complex::from(0.0); 3],
        pair: false,
    }; 2];
    let mut n_modes = 0;
    for (k, lam) in lams.iter().enumerate() {
        let real = lam.im.abs() < 1e-12;
        if !real && lam.im < 0.0 {
            continue; // represented by its conjugate
        }
        let mut mode = Mode {
            lam: *lam,
            t: [tm[(0, k)], tm[(1, k)], tm[(2, k)]],
            tau: [tinv[(k, 0)], tinv[(k, 1)], tinv[(k, 2)]],
            pair: !real,
        };
        if real {
            mode.lam.im = 0.0;
            for z in mode.t.iter_mut().chain(mode.tau.iter_mut()) {
                z.im = 0.0;
            }
        }
        modes[n_modes] = mode;
        n_modes += 1;
    }
    let arr = |v: Vector3<f64>| [v[0], v[1], v[2]];
    Transformed {
        a: ta,
        pow1: [arr(p1), arr(p2), arr(p3)],
        d: arr(d),
        modes,
        n_modes,
    }
}

/// Gauss collocation with `s` stages on a [`Blocks`] system: returns the update and the
/// stages `Z_1..Z_s` (beyond `s`, zeros).
///
/// The stages of `v` and `w` are eliminated in closed form,
/// `V = 1⊗v0 + h(𝒜⊗A_vu)U`, `W = 1⊗w0 + h(𝒜1)⊗c_w + h(𝒜⊗A_wv)V`, which leaves for the stage
/// increments `ΔU = U − 1⊗u0` one `3s × 3s` system with blocks
/// `δ_ij I − h 𝒜_ij A_uu − h² (𝒜²)_ij P₂ − h³ (𝒜³)_ij P₃`, `P₂ = A_uv A_vu`,
/// `P₃ = A_uw A_wv A_vu`. Written as `ΔU − A_uu ΔU (h𝒜)ᵀ − … = R`, it decouples under the
/// eigenvectors of `𝒜ᵀ` into one 3×3 system per eigenvalue `λ`:
/// `(I − hλ A_uu − h²λ² P₂ − h³λ³ P₃) û = R t`: one real solve for `s = 1`, one complex
/// solve for `s = 2`, one real and one complex for `s = 3`. The update is
/// `z1 = z0 + Σ_i d_i ΔZ_i` with `d = bᵀ𝒜⁻¹`, which needs no further field evaluations.
/// `None` if a reduced system is singular (impossible for a dissipative system: Gauss
/// collocation is A-stable) or the result is not finite.
pub fn blocks_step(sys: &Blocks, z0: &Z3, h: f64, s: usize) -> Option<(Z3, [Z3; 3])> {
    if s == 1 {
        let zero = [Vector3::zeros(); 3];
        return midpoint_step(sys, z0, h).map(|(z1, st)| (z1, [st, zero, zero]));
    }
    general_step(sys, z0, h, s)
}

/// [`blocks_step`] with one stage, the implicit midpoint rule, written out: the general path's
/// arithmetic with `λ = 𝒜 = 1/2`, `𝒜²1 = 1/4`, `𝒜³1 = 1/8`, `d = 2` and the eigenvector `1`,
/// without its loops over stages and modes (SP2's S2, the most frequent sub-flow of long runs).
/// Returns the update and the stage; `None` as [`blocks_step`].
pub fn midpoint_step(sys: &Blocks, z0: &Z3, h: f64) -> Option<(Z3, Z3)> {
    let [u0, v0, w0] = z0;
    let (h1, h2, h3) = (h * 0.5, h * h * 0.25, h * h * h * 0.125);
    let cubic = sys.awv.iter().any(|v| *v != 0.0);
    let avu_u0 = sys.avu * u0;
    let fw0 = if cubic { sys.cw + sys.awv * v0 } else { sys.cw };
    let g1 = sys.auu * u0 + sys.auv * v0 + sys.auw * w0 + sys.cu;
    let g2 = sys.auw * fw0 + sys.auv * avu_u0;
    let mut r = g1 * h1 + g2 * h2;
    let mut m = Matrix3::identity() - sys.auu * h1 - (sys.auv * sys.avu) * h2;
    if cubic {
        r += (sys.auw * (sys.awv * avu_u0)) * h3;
        m -= (sys.auw * (sys.awv * sys.avu)) * h3;
    }
    let du = solve3(&m, &r)?;
    let dv = (avu_u0 * 0.5 + (sys.avu * du) * 0.5) * h;
    let dw = if cubic {
        (fw0 * 0.5 + (sys.awv * dv) * 0.5) * h
    } else {
        (fw0 * 0.5) * h
    };
    let z1 = [u0 + du * 2.0, v0 + dv * 2.0, w0 + dw * 2.0];
    z1.iter()
        .flat_map(|v| v.iter())
        .all(|x| x.is_finite())
        .then_some((z1, [u0 + du, v0 + dv, w0 + dw]))
}

/// [`blocks_step`] by the transformation for any `s` in `1..=3`.
fn general_step(sys: &Blocks, z0: &Z3, h: f64, s: usize) -> Option<(Z3, [Z3; 3])> {
    if !(1..=3).contains(&s) {
        return None;
    }
    let tr = transformed(s);
    let [u0, v0, w0] = z0;
    let p2 = sys.auv * sys.avu;
    let avu_u0 = sys.avu * u0;
    // A_wv = 0 (the rotation: phi_th grows at a constant rate) leaves out the cubic terms.
    let cubic = sys.awv.iter().any(|v| *v != 0.0);
    let awv_avu_u0 = if cubic {
        sys.awv * avu_u0
    } else {
        Vector3::zeros()
    };
    let fw0 = if cubic { sys.cw + sys.awv * v0 } else { sys.cw };
    // Right-hand side R_i = hα_i f_u(z0) + h²(𝒜²1)_i g₂ + h³(𝒜³1)_i g₃.
    let g1 = sys.auu * u0 + sys.auv * v0 + sys.auw * w0 + sys.cu;
    let g2 = sys.auw * fw0 + sys.auv * avu_u0;
    let g3 = sys.auw * awv_avu_u0;
    let (h2, h3) = (h * h, h * h * h);
    let rhs =
        |i: usize| g1 * (h * tr.pow1[0][i]) + g2 * (h2 * tr.pow1[1][i]) + g3 * (h3 * tr.pow1[2][i]);
    let r = [rhs(0), rhs(1), rhs(2)];
    let p3 = if cubic {
        sys.auw * (sys.awv * sys.avu)
    } else {
        Matrix3::zeros()
    };
    let mut du = [Vector3::zeros(); 3];
    for mode in &tr.modes[..tr.n_modes] {
        let (l1, l2, l3) = (
            mode.lam * h,
            mode.lam * mode.lam * h2,
            mode.lam * mode.lam * mode.lam * h3,
        );
        if !mode.pair {
            let m = Matrix3::identity() - sys.auu * l1.re - p2 * l2.re - p3 * l3.re;
            let mut rh = Vector3::zeros();
            for i in 0..s {
                rh += r[i] * mode.t[i].re;
            }
            let x = solve3(&m, &rh)?;
            for i in 0..s {
                du[i] += x * mode.tau[i].re;
            }
        } else {
            let re = Matrix3::identity() - sys.auu * l1.re - p2 * l2.re - p3 * l3.re;
            let im = -(sys.auu * l1.im + p2 * l2.im + p3 * l3.im);
            let m = re.zip_map(&im, Complex::new);
            let mut rh = Vector3::<Complex<f64>>::zeros();
            for i in 0..s {
                rh += r[i].map(Complex::from) * mode.t[i];
            }
            let x = solve3(&m, &rh)?;
            for i in 0..s {
                // The conjugate eigenvalue contributes the conjugate term.
                du[i] += (x * mode.tau[i]).map(|z| 2.0 * z.re);
            }
        }
    }
    // ΔV_i = hα_i A_vu u0 + h Σ_j 𝒜_ij A_vu ΔU_j;  ΔW_i = hα_i (c_w + A_wv v0) + h Σ_j 𝒜_ij A_wv ΔV_j.
    let avu_du = [sys.avu * du[0], sys.avu * du[1], sys.avu * du[2]];
    let mut dv = [Vector3::zeros(); 3];
    for i in 0..s {
        let mut acc = avu_u0 * tr.pow1[0][i];
        for j in 0..s {
            acc += avu_du[j] * tr.a[i][j];
        }
        dv[i] = acc * h;
    }
    let awv_dv = if cubic {
        [sys.awv * dv[0], sys.awv * dv[1], sys.awv * dv[2]]
    } else {
        [Vector3::zeros(); 3]
    };
    let mut dw = [Vector3::zeros(); 3];
    for i in 0..s {
        let mut acc = fw0 * tr.pow1[0][i];
        for j in 0..s {
            acc += awv_dv[j] * tr.a[i][j];
        }
        dw[i] = acc * h;
    }
    let (mut u1, mut v1, mut w1) = (*u0, *v0, *w0);
    let mut stages = [[Vector3::zeros(); 3]; 3];
    for i in 0..s {
        u1 += du[i] * tr.d[i];
        v1 += dv[i] * tr.d[i];
        w1 += dw[i] * tr.d[i];
        stages[i] = [u0 + du[i], v0 + dv[i], w0 + dw[i]];
    }
    let z1 = [u1, v1, w1];
    z1.iter()
        .flat_map(|v| v.iter())
        .all(|x| x.is_finite())
        .then_some((z1, stages))
}

/// `d = bᵀ𝒜⁻¹` of the `s`-stage Gauss method: where the stages solve their equations,
/// `z1 = z0 + Σ_i d_i (Z_i − z0)` (for `s = 1`, `d = 2`: `z1 = 2 Z − z0`).
pub fn update_weights(s: usize) -> [f64; 3] {
    transformed(s).d
}

/// The weights `b` of the `s`-stage Gauss method.
pub fn weights(s: usize) -> [f64; 3] {
    tableau(s).1
}

/// [`blocks_step`] on a 10×10 augmented matrix with the block structure of
/// [`Blocks::from_augmented`]: returns the update, the stages and the weights (equal to
/// [`stages`] to round-off), or `None` if the structure does not hold or the system is
/// singular.
pub fn structured(
    a: &SMatrix<f64, 10, 10>,
    z0: &SVector<f64, 10>,
    h: f64,
    s: usize,
) -> Option<(SVector<f64, 10>, [SVector<f64, 10>; 3], [f64; 3])> {
    let sys = Blocks::from_augmented(a)?;
    if z0[9] != 1.0 {
        return None;
    }
    let z = [
        z0.fixed_rows::<3>(0).into_owned(),
        z0.fixed_rows::<3>(3).into_owned(),
        z0.fixed_rows::<3>(6).into_owned(),
    ];
    let (z1, st) = blocks_step(&sys, &z, h, s)?;
    let pack = |z: &Z3| {
        let mut out = SVector::<f64, 10>::zeros();
        out.fixed_rows_mut::<3>(0).copy_from(&z[0]);
        out.fixed_rows_mut::<3>(3).copy_from(&z[1]);
        out.fixed_rows_mut::<3>(6).copy_from(&z[2]);
        out[9] = 1.0;
        out
    };
    Some((
        pack(&z1),
        [pack(&st[0]), pack(&st[1]), pack(&st[2])],
        weights(s),
    ))
}
#[cfg(test)]
mod tests {
    use super::*;
    use crate::flows::affine::{flow, tests::example10};

    #[test]
    fn gauss_pade_has_orders_2_4_6_and_matches_its_stages() {
        let a = example10();
        let z0 = SVector::<f64, 10>::from_fn(|i, _| if i == 9 { 1.0 } else { (i as f64).cos() });
        for s in 1..=3 {
            let mut errs = vec![];
            for h in [0.4, 0.2, 0.1] {
                let exact = flow(&a, h) * z0;
                let z = step(&a, &z0, h, s).unwrap();
                let (zs, _, _) = stages(&a, &z0, h, s).unwrap();
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
        // The elimination raises the reduced system to degree 3 in h‖A‖, which costs digits at
        // long steps: measured 5e-13 relative at h = 50 (h‖A‖ ≈ 75), where the dense solve
        // agrees with the Padé form to 1e-14. Far below the method's own error there.
        for (h, tol) in [(0.1, 1e-13), (1.0, 1e-13), (7.0, 1e-13), (50.0, 2e-12)] {
            let check = |z: SVector<f64, 10>, ys: &[SVector<f64, 10>], s: usize| {
                let (zd, yd, _) = stages(&a, &z0, h, s).unwrap();
                assert!(
                    (z - zd).norm() < tol * zd.norm(),
                    "s={s} h={h}: {}",
                    (z - zd).norm()
                );
                for (y, y2) in ys.iter().zip(&yd) {
                    assert!((y - y2).norm() < tol * y2.norm());
                }
            };
            for st in 1..=3 {
                let (z, ys, _) = structured(&a, &z0, h, st).unwrap();
                check(z, &ys[..st], st);
            }
        }
        // Not the structure: refused.
        let mut b = a;
        b[(4, 4)] = 1.0;
        assert!(structured(&b, &z0, 0.5, 1).is_none());
    }

    /// The implicit midpoint rule written out is the general path with one stage, to the bit,
    /// with the cubic terms (`A_wv ≠ 0`, the translation) and without (the rotation).
    #[test]
    fn the_midpoint_path_is_the_general_path_with_one_stage() {
        let mut a = SMatrix::<f64, 10, 10>::zeros();
        for i in 0..3 {
            for j in 0..3 {
                a[(i, j)] = -0.3 - 0.2 * (i * 3 + j) as f64 / 9.0;
                a[(i, 3 + j)] = if i == j { -2.5 } else { 0.3 };
                a[(i, 6 + j)] = if i == j { -0.4 } else { 0.05 };
                a[(3 + i, j)] = if i == j { 1.1 } else { -0.07 };
                a[(6 + i, 3 + j)] = if i == j { 1.0 } else { 0.0 };
            }
            a[(i, 9)] = 0.3 * i as f64 - 0.2;
            a[(6 + i, 9)] = -0.1 * i as f64;
        }
        let z0 = [
            Vector3::new(0.3, -1.2, 0.8),
            Vector3::new(2.0, 0.1, -0.4),
            Vector3::new(-0.5, 0.25, 1.5),
        ];
        let cubic = Blocks::from_augmented(&a).unwrap();
        let mut flat = cubic;
        flat.awv = Matrix3::zeros();
        for sys in [cubic, flat] {
            for h in [0.01, 0.5, 3.0, -0.2, 40.0] {
                let (z1, st) = midpoint_step(&sys, &z0, h).unwrap();
                let (g1, gs) = general_step(&sys, &z0, h, 1).unwrap();
                assert_eq!(z1, g1, "h = {h}");
                assert_eq!(st, gs[0], "h = {h}");
                assert_eq!(blocks_step(&sys, &z0, h, 1).unwrap(), (g1, gs));
            }
        }
        let mut nan = cubic;
        nan.cu.x = f64::NAN;
        assert!(midpoint_step(&nan, &z0, 0.5).is_none());
    }
}
