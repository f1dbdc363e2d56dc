//! The natural periods of the vessel's linearised flow S2 (docs/model.md §4): the eigenvalues of
//! the two block systems and what couples them, or of the dense system with the components' own
//! states.

use super::super::forces::{Frozen, S2Builder};
use super::s2;
use super::VesselSystem;
use nalgebra::{DMatrix, Matrix3};

/// The periods `2π/|λ|` of the oscillating eigenvalues of `a` (times `scale`), ascending.
fn periods_of(ev: impl Iterator<Item = nalgebra::Complex<f64>>, scale: f64) -> Vec<f64> {
    let mut out = Vec::new();
    for l in ev {
        let (re, im) = (l.re * scale, l.im * scale);
        let r = re.hypot(im);
        // A zero mode (surge, sway, yaw without damping) comes out as round-off with a
        // round-off imaginary part: not an oscillation.
        if im > 1e-9 * r && r > 1e-12 * scale {
            out.push(2.0 * std::f64::consts::PI / r);
        }
    }
    out.sort_by(|x, y| x.total_cmp(y));
    out
}

/// A diagonal similarity `D⁻¹ A D` (powers of two, so exact) that brings each row's and
/// column's off-diagonal norms close (Parlett & Reinsch, *Numer. Math.* 13, 1969, as LAPACK's
/// `gebal` without its permutations): the eigenvalues are `a`'s, computed far more accurately
/// when its entries span many decades (the momenta's kg against the angles' radians).
fn balanced(mut a: DMatrix<f64>) -> DMatrix<f64> {
    let n = a.nrows();
    for _ in 0..100 {
        let mut done = true;
        for i in 0..n {
            let c: f64 = (0..n).filter(|&j| j != i).map(|j| a[(j, i)].abs()).sum();
            let r: f64 = (0..n).filter(|&j| j != i).map(|j| a[(i, j)].abs()).sum();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let (mut cc, mut rr) = (c, r);
            while cc < rr / 2.0 {
                cc *= 2.0;
                rr /= 2.0;
                f *= 2.0;
            }
            while cc >= rr * 2.0 {
                cc /= 2.0;
                rr *= 2.0;
                f /= 2.0;
            }
            if (cc + rr) < 0.95 * (c + r) {
                done = false;
                for j in 0..n {
                    a[(i, j)] /= f;
                    a[(j, i)] *= f;
                }
            }
        }
        if done {
            break;
        }
    }
    a
}

/// The oscillating periods of `a`'s eigenvalues, `a` balanced first.
fn periods(a: DMatrix<f64>) -> Vec<f64> {
    let a = balanced(a);
    let scale = a.amax().max(f64::MIN_POSITIVE);
    match (a / scale)
        .try_schur(1e-15, 10_000)
        .map(|s| s.complex_eigenvalues())
    {
        Some(ev) => periods_of(ev.iter().cloned(), scale),
        None => Vec::new(),
    }
}

impl VesselSystem<'_> {
    /// The natural periods (s) of the oscillating modes of flow S2 linearised at the attitude
    /// `q`, with the controller `on` or off, ascending: `2π/|λ|` for each eigenvalue pair
    /// `λ, λ̄` of the two 9×9 block systems (`u' = A_uu u + A_uv v + A_uw w`, `v' = A_vu u`,
    /// `w' = A_wv v`) with `Im λ ≠ 0`. For a damped oscillator `|λ|` is its undamped natural
    /// frequency, so the periods do not depend on the damping. Paper vessel, upright, controller
    /// off: heave `2π √(mv/c)` = 4.25 s, pitch `2π √(T2/(mv g GM_L))` = 4.08 s, roll 9.21 s.
    /// A step far beyond the shortest of them cannot resolve the motion (docs/model.md §4).
    /// With components that keep states of their own, the modes are those of the coupled system
    /// (the hull with its subsystems: a tuned tank splits the roll mode in two).
    pub fn natural_periods(&self, q: &Matrix3<f64>, on: bool) -> Vec<f64> {
        let b = self.s2_at(q, on, false);
        if self.own_linear_dim > 0 {
            return self.natural_periods_own(&self.frozen_at(q, on), &b);
        }
        // The 18×18 system (the two block systems and what couples them), without the
        // constant column.
        let full = s2::augmented(&b);
        periods(DMatrix::from_fn(18, 18, |i, j| full[(i, j)]))
    }

    /// [`Self::natural_periods`] of the dense system with the components' own states, balanced
    /// (a similarity: the eigenvalues are the system's).
    fn natural_periods_own(&self, fr: &Frozen, b: &S2Builder) -> Vec<f64> {
        let (a, _) = self.dense_balanced(fr, b);
        let n = a.nrows() - 1;
        periods(a.view((0, 0), (n, n)).into_owned())
    }
}
