//! Flow S2 of the vessel over a sub-step (paper §3.4.2; docs/model.md §3.3, §3.5, §3.7): the
//! exact flow of the two block systems (matrix exponential, ledger by the Van Loan Gramian) and
//! their Gauss collocation (the structured 3×3 solve, ledger by Gauss quadrature); S2 as one
//! coupled 18-dimensional system, where the mass matrix or a force couples translation and
//! rotation (docs/model.md §5.14), and the Gauss collocation of S2 with a forcing part
//! (time-dependent or non-affine components), coupled or not, are `s2/coupled.rs`'s; the
//! forcing's fixed point is here. A solve that gives up (a singular stage system, a fixed point
//! that does not converge) yields NaN and records why ([`GaveUp`]), which the run's failure
//! message says. The assembly of S2 from the components is `system.rs`'s.

// Stage loops index the Butcher tableau `a_ij`, `b_i` and the blocks as the formulas write them.
#![allow(clippy::needless_range_loop)]

use super::super::forces::{Rows, S2Builder, Sys};
use super::super::state::VesselState;
use super::{LinearFlow, VesselSystem};
use crate::flows::affine;
use crate::flows::collocation::{self as gauss, Blocks, Z3};
use crate::solve::Work;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Most fixed-point passes over the forcing of flow S2 in one sub-step.
const FORCED_MAX_ITERATIONS: usize = 200;

mod coupled;
pub(super) use coupled::augmented;

impl VesselSystem<'_> {
    /// Flow S2 over `h` from time `t` (paper §3.4.2): the two block systems at the frozen
    /// attitude, by the matrix exponential or by Gauss collocation with `stages` stages
    /// ([`LinearFlow`]; always collocation when S2 has a forcing part). With `ledger`, also
    /// the energy booked per account over the sub-step, exactly (Van Loan Gramian, or Gauss
    /// quadrature of the quadratic power).
    pub fn flow_s2(
        &self,
        s: &mut VesselState,
        h: f64,
        t: f64,
        on: bool,
        ledger: bool,
        stages: usize,
    ) -> Work {
        if self.own_linear_dim > 0 {
            return self.flow_s2_own(s, h, t, on, ledger, stages);
        }
        let z0 = self.blocks_of(s);
        let (z1, work) = self.with_s2(s, on, ledger, false, |fr, b| {
            // A forcing part is collocated with the coupled system's solver whether or not the
            // systems are coupled (their blocks of six are then block-diagonal).
            if b.cross.is_some() || self.forced {
                self.coupled_s2(fr, b, &z0, h, t, stages)
            } else {
                match self.linear {
                    LinearFlow::Exact => self.exact_s2(b, &z0, h, fr.control_on),
                    _ => self.gauss_s2(b, &z0, h, stages),
                }
            }
        });
        self.set_blocks(s, &z1);
        work
    }

    /// Gauss collocation on the block systems; the ledger by the Gauss quadrature of the
    /// power at the stages (exact for the collocation polynomial's quadratic storage:
    /// `H(z1) − H(z0) = h Σ b_i Ḣ(Z_i)`). A singular stage system (impossible for a dissipative
    /// system, but checked) yields a non-finite state.
    pub(super) fn gauss_s2(
        &self,
        b: &S2Builder,
        z0: &[Z3; 2],
        h: f64,
        s: usize,
    ) -> ([Z3; 2], Work) {
        let nan = [[Vector3::from_element(f64::NAN); 3]; 2];
        if s == 1 {
            // The implicit midpoint rule (SP2's S2), without the stage arrays of more stages.
            let (Some((zt1, st)), Some((zr1, sr))) = (
                gauss::midpoint_step(&b.sys[0], &z0[0], h),
                gauss::midpoint_step(&b.sys[1], &z0[1], h),
            ) else {
                return (nan, Work::default());
            };
            let mut work = Work::default();
            if b.booked.is_some() {
                // Gauss's weight for one stage is 1 (added to zero, as the general path does:
                // no account's work comes back as -0).
                work += self.power_at(b, &[st, sr]).scaled(h);
            }
            return ([zt1, zr1], work);
        }
        let (Some((zt1, st)), Some((zr1, sr))) = (
            gauss::blocks_step(&b.sys[0], &z0[0], h, s),
            gauss::blocks_step(&b.sys[1], &z0[1], h, s),
        ) else {
            return (nan, Work::default());
        };
        let mut work = Work::default();
        if b.booked.is_some() {
            let w = gauss::weights(s);
            for i in 0..s {
                work += self.power_at(b, &[st[i], sr[i]]).scaled(h * w[i]);
            }
        }
        ([zt1, zr1], work)
    }

    /// The balance of the exact flow's block systems beyond [`balance`]'s structural one, per
    /// controller state (`[on][system]`): Osborne's balance ([`affine::balance`]) of the blocks
    /// at the upright attitude, as factors on the structural scale. It depends on the vessel
    /// alone, so it is computed once, and a run does not depend on which sub-steps came before.
    /// At other attitudes the same factors are a similarity still (exact), and only the Taylor
    /// sum's degree can change.
    pub(super) fn exact_balance(&self) -> &[[SVector<f64, 10>; 2]; 2] {
        self.exact_balance.get_or_init(|| {
            let minv = self.minv();
            std::array::from_fn(|on| {
                let b = self.s2_at(&Matrix3::identity(), on == 1, false);
                std::array::from_fn(|k| {
                    let structural = balance(&b.sys[k], &minv[k]);
                    let inv = structural.map(|v| 1.0 / v);
                    let abar = b.sys[k].augmented();
                    let mut a = SMatrix::<f64, 10, 10>::from_fn(|i, j| {
                        abar[(i, j)] * structural[j] * inv[i]
                    });
                    let mut factors = SVector::<f64, 10>::from_element(1.0);
                    affine::balance(&mut a, &mut factors);
                    factors
                })
            })
        })
    }

    /// The exact flow of both block systems, balanced; with the ledger, each account's energy
    /// from one Gramian per system.
    pub(super) fn exact_s2(
        &self,
        b: &S2Builder,
        z0: &[Z3; 2],
        h: f64,
        on: bool,
    ) -> ([Z3; 2], Work) {
        let on = on as usize;
        let minv = self.minv();
        let mut z1 = [[Vector3::zeros(); 3]; 2];
        // The ledger's weights of each system's Gramian ([`power_weights`]).
        let mut weights = [None; 2];
        for sys in [Sys::Trans, Sys::Rot] {
            let k = sys as usize;
            let blocks = &b.sys[k];
            let mut scale = balance(blocks, &minv[k]).component_mul(&self.exact_balance()[on][k]);
            let mut zz = SVector::<f64, 10>::zeros();
            for (i, v) in z0[k].iter().enumerate() {
                zz.fixed_rows_mut::<3>(3 * i).copy_from(v);
            }
            zz[9] = 1.0;
            if let Some(f) = affine::constant_factor(&scale, &zz) {
                scale[9] *= f;
            }
            let zb = zz.component_div(&scale);
            // The balanced system in its blocks: the products, the norm, and the dense matrix
            // only for the fallback.
            let bal = blocks.scaled(&scale);
            let norm1 = bal.dynamics_norm1();
            let apply = |x: &SVector<f64, 10>, c: f64| bal.apply_augmented(x, c);
            let dense = || bal.augmented();
            let zb1 = match &b.booked {
                Some(_) => {
                    let (zb1, gram) = affine::flow_action_and_gramian_rows_by::<10, 3, 20>(
                        norm1,
                        apply,
                        dense,
                        &zb,
                        h,
                        &[0, 1, 2],
                    );
                    weights[k] = Some(power_weights(&gram, &scale, &minv[k]));
                    zb1
                }
                None => affine::flow_action_by(norm1, apply, dense, &zb, h),
            };
            let z = zb1.component_mul(&scale);
            z1[k] = [
                z.fixed_rows::<3>(0).into_owned(),
                z.fixed_rows::<3>(3).into_owned(),
                z.fixed_rows::<3>(6).into_owned(),
            ];
        }
        let work = match (&b.booked, weights) {
            (Some(booked), [Some(wt), Some(wr)]) => Work::from_fn(self.accounts.len(), |acc| {
                self.sign(acc) * (energy(&booked[acc][0], &wt, 0) + energy(&booked[acc][1], &wr, 1))
            }),
            _ => Work::default(),
        };
        (z1, work)
    }
}

/// The fixed point of the forcing in a Gauss collocation of flow S2 (the block systems' and the
/// coupled system's): Aitken's relaxation and the stopping rule.
///
/// Aitken's relaxation (B. M. Irons, R. C. Tuck, Int. J. Numer. Meth. Eng. 1 (1969) 275–277; in
/// the form of U. Küttler, W. A. Wall, Comput. Mech. 43 (2008) 61–72, eq. 44): `x ← x + ω r`
/// with `r = G(x) − x` and `ω ← −ω r_oldᵀ(r − r_old)/|r − r_old|²`, clamped to `[0.05, 2]`. A
/// dissipative forcing (quadratic damping at long steps) makes the plain iteration oscillate with
/// a rate that can pass 1; the relaxation damps that, and leaves a quickly converging iteration
/// as it was (`ω ≈ 1`). Convergence is judged on the residual `G(x) − x` itself, not on the
/// relaxed step (Aitken's steps do not shrink steadily), whole and part by part
/// ([`relative_change`]); a NaN anywhere makes it NaN.
///
/// The residuals shrink by a factor `θ` a pass; the iterate after a pass whose residual is `r`
/// is then within about `θ/(1 − θ) |r|` of the fixed point. Where that estimate is at round-off
/// of every part, the iteration stops without a further pass that would only show it: the
/// stopping criterion of the Newton iterations of implicit Runge–Kutta methods (E. Hairer,
/// G. Wanner, *Solving Ordinary Differential Equations II*, 2nd ed., Springer 1996, §IV.8), with
/// the same round-off tolerance as the residual's own test, and `θ` the larger of the last two
/// observed ratios (the first pass's ratio, from the starting guess, is not trusted alone).
struct FixedPoint {
    omega: f64,
    /// `r_oldᵀ(r − r_old)` and `|r − r_old|²` of this pass.
    num: f64,
    den: f64,
    /// This pass's residual, whole and by parts, and the previous pass's.
    change: f64,
    parts: f64,
    last_change: f64,
    last_parts: f64,
    /// The previous pass's contraction ratio (0 before the second).
    last_theta: f64,
}

/// What a pass of the fixed point concluded.
enum Verdict {
    Continue,
    Converged,
    /// Diverged, overflowed, or still above 1e-10 after [`FORCED_MAX_ITERATIONS`] passes.
    Failed,
}

impl FixedPoint {
    fn new() -> Self {
        Self {
            omega: 1.0,
            num: 0.0,
            den: 0.0,
            change: 0.0,
            parts: 0.0,
            last_change: f64::INFINITY,
            last_parts: f64::INFINITY,
            last_theta: 0.0,
        }
    }
    /// One stage's residual `r` against the previous pass's `r_old`, for Aitken's factor.
    fn compare(&mut self, r: &[f64], r_old: &[f64]) {
        for (a, b) in r.iter().zip(r_old) {
            let d = a - b;
            self.num += b * d;
            self.den += d * d;
        }
    }
    /// Aitken's factor for this pass (1 on the first), from what [`Self::compare`] gathered.
    fn relax(&mut self) -> f64 {
        if self.den > 0.0 && self.num.is_finite() {
            self.omega = (-self.omega * self.num / self.den).clamp(0.05, 2.0);
        }
        (self.num, self.den, self.change, self.parts) = (0.0, 0.0, 0.0, 0.0);
        self.omega
    }
    /// One stage's residual `r` at its relaxed iterate `y` (its first `n` entries the states).
    fn measure(&mut self, r: &[f64], y: &[f64], n: usize) {
        let (res, part) = relative_change(r, y, n);
        self.change = if res.is_nan() || self.change.is_nan() {
            f64::NAN
        } else {
            self.change.max(res)
        };
        self.parts = self.parts.max(part);
    }
    /// After pass `it`: converged when every part of the stages has stopped moving (a forcing
    /// independent of the state, `stateful` false, at the first pass), when from the third pass
    /// on the contraction puts the new iterate within round-off of every part (the estimate of
    /// the type documentation, `θ < 1/2`), or when the whole is at round-off (below 1e-12) and
    /// neither measure improves any more.
    fn verdict(&mut self, it: usize, stateful: bool) -> Verdict {
        let (change, parts) = (self.change, self.parts);
        if !change.is_finite() {
            return Verdict::Failed;
        }
        let ratio = (change / self.last_change).max(parts / self.last_parts);
        let theta = ratio.max(self.last_theta);
        let settled = it >= 2 && theta < 0.5 && parts * theta / (1.0 - theta) <= 4.0 * f64::EPSILON;
        if !stateful
            || (it > 0
                && (parts <= 4.0 * f64::EPSILON
                    || settled
                    || (change < 1e-12 && change >= self.last_change && parts >= self.last_parts)))
        {
            return Verdict::Converged;
        }
        if it + 1 == FORCED_MAX_ITERATIONS && change > 1e-10 {
            return Verdict::Failed;
        }
        (self.last_change, self.last_parts) = (change, parts);
        self.last_theta = if ratio.is_nan() { 1.0 } else { ratio };
        Verdict::Continue
    }
}

/// The size of a fixed-point update `r` at the iterate `y` (the first `n` entries: momenta,
/// positions or `mu`, integral states, in 3-vectors): relative to the whole vector, and the
/// largest relative to each 3-vector (floored at 1e-12 of the whole). The first says when round-off
/// is reached; the second that a small part (the velocities, when an integral state is large)
/// has converged too, since the ledger books its power.
fn relative_change(r: &[f64], y: &[f64], n: usize) -> (f64, f64) {
    let amax = |v: &[f64]| {
        v.iter().fold(0.0f64, |m, x| {
            if x.abs() > m || x.is_nan() {
                x.abs()
            } else {
                m
            }
        })
    };
    let size = amax(&y[..n]).max(f64::MIN_POSITIVE);
    let whole = amax(r) / size;
    let mut parts: f64 = 0.0;
    for g in 0..n / 3 {
        let (rg, yg) = (&r[3 * g..3 * g + 3], &y[3 * g..3 * g + 3]);
        parts = parts.max(amax(rg) / amax(yg).max(size * 1e-12));
    }
    if whole.is_nan() || parts.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    (whole, parts)
}

/// Diagonal balancing `z = S z̃` of a block system for the exponential: momenta become
/// velocities (`S_u = M`), the second block is scaled by the power of two nearest to the size
/// of `A_vu M` (exact in floating point), the rest by 1. The entries of `S⁻¹ Ā S` are then of
/// comparable size, instead of spanning fifteen orders of magnitude; without it the ledger
/// closed only to about 1e-6 J.
pub(super) fn balance(b: &Blocks, minv: &Vector3<f64>) -> SVector<f64, 10> {
    let su = minv.map(|v| 1.0 / v);
    let avu_m = b.avu * Matrix3::from_diagonal(&su);
    let norm = (0..3)
        .map(|i| avu_m.row(i).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let sv = if norm.is_normal() {
        affine::nearest_power_of_two(norm)
    } else {
        1.0
    };
    SVector::<f64, 10>::from_fn(|i, _| match i {
        0..=2 => su[i],
        3..=5 => sv,
        _ => 1.0,
    })
}

/// The power of a force, `νᵀ F z̄ = Σ R ∘ (ū z̄ᵀ)`, is linear in the rows
/// `R = diag(M⁻¹) [F_k M⁻¹ | F_v | F_w | c]` on `z̄ = (u, v, w, 1)` of system `k`, with `ν = M⁻¹u`
/// (`M` of the paper's form: diagonal `minv` on this system). Its integral along S2 is
/// `Σ R ∘ Y` with `Y` the momentum rows of the Gramian, i.e. `Σ [F_k | F_v | F_w | c] ∘ W`
/// with the weights `W_ij = Y_ij minv_i (minv_j for the velocity columns j < 3)`: the Gramian's
/// rows `gram` of the balanced system, in the vessel's coordinates (`Y_ij = gram_ij s_i s_j`),
/// weighted once for every account.
fn power_weights(
    gram: &SMatrix<f64, 3, 10>,
    scale: &SVector<f64, 10>,
    minv: &Vector3<f64>,
) -> SMatrix<f64, 3, 10> {
    SMatrix::<f64, 3, 10>::from_fn(|i, j| {
        let y = gram[(i, j)] * scale[i] * scale[j] * minv[i];
        if j < 3 {
            y * minv[j]
        } else {
            y
        }
    })
}

/// The energy a force with rows `f` books over the sub-step, `Σ [F_k | F_v | F_w | c] ∘ W`
/// with the weights of [`power_weights`].
fn energy(f: &Rows, w: &SMatrix<f64, 3, 10>, k: usize) -> f64 {
    f.fnu[k].component_mul(&w.fixed_view::<3, 3>(0, 0)).sum()
        + f.fv.component_mul(&w.fixed_view::<3, 3>(0, 3)).sum()
        + f.fw.component_mul(&w.fixed_view::<3, 3>(0, 6)).sum()
        + f.c.dot(&w.column(9))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feed the fixed point's measures a residual of `change` (whole) and `parts` (by parts)
    /// per pass, and return the pass at which it stops.
    fn stops_at(passes: &[(f64, f64)]) -> Option<usize> {
        let mut fp = FixedPoint::new();
        for (it, &(change, parts)) in passes.iter().enumerate() {
            fp.relax();
            (fp.change, fp.parts) = (change, parts);
            match fp.verdict(it, true) {
                Verdict::Continue => {}
                Verdict::Converged => return Some(it),
                Verdict::Failed => return None,
            }
        }
        None
    }

    /// The residuals of the vessel in the mean wind (measured): a contraction of 5e-5 a pass.
    /// The estimate stops the iteration where the next pass's residual would be at round-off of
    /// every part, one pass before the residual shows it; a first ratio that is small alone, or
    /// a slow contraction, does not stop it.
    #[test]
    fn the_contraction_estimate_stops_only_at_round_off() {
        let wind = [
            (1.2e-3, 1.0e-1),
            (1.9e-9, 2.7e-7),
            (9.5e-14, 1.35e-11),
            (5.0e-18, 7.0e-16),
            (0.0, 0.0),
        ];
        assert_eq!(stops_at(&wind), Some(2));
        // The same at the third pass with a residual by parts 6e-11: the estimate 3e-15 is not
        // round-off; the next pass's residual is.
        let mut later = wind;
        later[2].1 = 6.0e-11;
        later[3].1 = 3.0e-15;
        assert_eq!(stops_at(&later), Some(3));
        // The first ratio (from the starting guess) alone stops nothing, even where its estimate
        // would be round-off.
        assert_eq!(stops_at(&[(1e-3, 1e-3), (1e-13, 1e-13)]), None);
        // A contraction of 0.6 stops only when the residual itself is at round-off.
        let slow: Vec<(f64, f64)> = (0..80).map(|k| (0.6f64.powi(k), 0.6f64.powi(k))).collect();
        let k = stops_at(&slow).unwrap();
        assert!(0.6f64.powi(k as i32) <= 4.0 * f64::EPSILON, "{k}");
    }
}
