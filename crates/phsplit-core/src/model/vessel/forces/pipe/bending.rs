//! The lumped-mass line's bending springs (docs/model.md §5.18) and the block-banded solver of
//! its Newton systems.
//!
//! A free node's rotational spring `(EI/l)(1 − cos θ)`, `θ` the turn between its segments (the
//! lumped-mass codes' bending, `≈ ½ EI θ²/l`), its gradient, its discrete gradient (Gonzalez,
//! J. Nonlinear Sci. 6 (1996) 449–467, in the node triple's nine coordinates) and the stencil
//! that stands for its Hessian in Newton's method.

use super::chain::Chain;
use nalgebra::{Matrix3, Vector3};

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

impl Chain {
    /// The bending spring's energy at a free node between its neighbours `a` and `c`.
    pub(super) fn bend(&self, a: &V3, b: &V3, c: &V3) -> f64 {
        let (u, v) = (b - a, c - b);
        let (nu, nv) = (u.norm(), v.norm());
        if nu == 0.0 || nv == 0.0 {
            return 0.0;
        }
        self.bending / self.rest * (1.0 - u.dot(&v) / (nu * nv))
    }
    /// Its gradient in `(a, b, c)`.
    pub(super) fn bend_gradient(&self, a: &V3, b: &V3, c: &V3) -> [V3; 3] {
        let (u, v) = (b - a, c - b);
        let (nu, nv) = (u.norm(), v.norm());
        if nu == 0.0 || nv == 0.0 {
            return [V3::zeros(); 3];
        }
        let k = self.bending / self.rest;
        let cos = u.dot(&v) / (nu * nv);
        let du = v / (nu * nv) - u * (cos / (nu * nu));
        let dv = u / (nu * nv) - v * (cos / (nv * nv));
        // V = k (1 − cos θ), u = b − a, v = c − b.
        [du * k, (dv - du) * k, -dv * k]
    }
    /// Gonzalez's discrete gradient of the bending spring at node `i` between the positions
    /// `p0` and `p1` (its three nodes' nine coordinates: `∇V(ȳ)` and the correction along
    /// `Δy` that makes it exact), and the blocks `(EI/l³) P ⊗ [1, −2, 1]ᵀ[1, −2, 1]` (`P` the
    /// projector across the line) that stand for its Hessian in Newton's method, scaled by
    /// `scale`.
    fn bend_dg(&self, p0: &[V3], p1: &[V3], i: usize, scale: f64) -> ([V3; 3], [[M3; 3]; 3]) {
        let mid: [V3; 3] = std::array::from_fn(|k| 0.5 * (p0[i - 1 + k] + p1[i - 1 + k]));
        let mut g = self.bend_gradient(&mid[0], &mid[1], &mid[2]);
        let d: [V3; 3] = std::array::from_fn(|k| p1[i - 1 + k] - p0[i - 1 + k]);
        let dd: f64 = d.iter().map(|x| x.norm_squared()).sum();
        if dd > 0.0 {
            let dv = self.bend(&p1[i - 1], &p1[i], &p1[i + 1])
                - self.bend(&p0[i - 1], &p0[i], &p0[i + 1]);
            let lin: f64 = (0..3).map(|k| g[k].dot(&d[k])).sum();
            let c = (dv - lin) / dd;
            for k in 0..3 {
                g[k] += d[k] * c;
            }
        }
        let t = Self::tangent(&mid[0], &mid[2]);
        let p = (M3::identity() - t * t.transpose()) * (scale * self.bending / self.rest.powi(3));
        let w = [1.0, -2.0, 1.0];
        (
            g,
            std::array::from_fn(|r| std::array::from_fn(|c| p * (w[r] * w[c]))),
        )
    }
    /// Add the bending springs' discrete gradients (forces `−∇̄V`) and Hessian blocks (scaled by
    /// `scale`) to the residual's parts: `off` the blocks `(k, k + 1)`, `far` `(k, k + 2)`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_bending(
        &self,
        p0: &[V3],
        p1: &[V3],
        scale: f64,
        f: &mut [V3],
        diag: &mut [M3],
        off: &mut [M3],
        far: &mut [M3],
    ) {
        if self.bending <= 0.0 {
            return;
        }
        let n = self.segments;
        for i in 1..n {
            let (g, hb) = self.bend_dg(p0, p1, i, scale);
            for k in 0..3 {
                let a = i - 1 + k;
                if a < n {
                    f[a] -= g[k];
                    diag[a] += hb[k][k];
                }
            }
            // Node i + 1 is the anchor (no unknown) when i = N − 1.
            off[i - 1] += hb[0][1];
            if i + 1 < n {
                off[i] += hb[1][2];
                far[i - 1] += hb[0][2];
            }
        }
    }
}

/// The block-banded system of the line's Newton iterations with diagonal blocks `d`,
/// off-diagonal blocks `o` (`o[k]` is both block `(k, k + 1)` and block `(k + 1, k)`: a segment's
/// `−K` in the rows of both its ends) and `far` (`far[k]` both `(k, k + 2)` and `(k + 2, k)`: a
/// bending spring's), solved by block Gaussian elimination in the band; its storage is kept
/// from one iteration to the next.
#[derive(Debug, Default)]
pub(super) struct Banded {
    /// Row k's blocks at columns k − 2 … k + 2.
    a: Vec<[M3; 5]>,
    b: Vec<V3>,
    inv: Vec<M3>,
}

impl Banded {
    /// Solve for right-hand side `g` into `x`; `false` if a pivot block is singular.
    pub(super) fn solve(&mut self, d: &[M3], o: &[M3], far: &[M3], g: &[V3], x: &mut [V3]) -> bool {
        let n = d.len();
        self.a.clear();
        self.a.extend((0..n).map(|k| {
            let get = |j: isize| -> M3 {
                let j = k as isize + j;
                if j < 0 || j >= n as isize {
                    return M3::zeros();
                }
                let (lo, dist) = ((j as usize).min(k), (j - k as isize).unsigned_abs());
                match dist {
                    0 => d[k],
                    1 => o[lo],
                    _ => far[lo],
                }
            };
            [get(-2), get(-1), get(0), get(1), get(2)]
        }));
        self.b.clear();
        self.b.extend_from_slice(g);
        self.inv.resize(n, M3::zeros());
        let (a, b, inv) = (&mut self.a, &mut self.b, &mut self.inv);
        for k in 0..n {
            let Some(p) = a[k][2].try_inverse() else {
                return false;
            };
            inv[k] = p;
            for r in k + 1..(k + 3).min(n) {
                // Column k sits at 2 + k − r in row r.
                let l = a[r][2 + k - r] * inv[k];
                for c in k + 1..(k + 3).min(n) {
                    let upper = a[k][2 + c - k];
                    a[r][2 + c - r] -= l * upper;
                }
                let bk = b[k];
                b[r] -= l * bk;
            }
        }
        for k in (0..n).rev() {
            let mut r = b[k];
            for c in k + 1..(k + 3).min(n) {
                r -= a[k][2 + c - k] * x[c];
            }
            x[k] = inv[k] * r;
        }
        true
    }
}
