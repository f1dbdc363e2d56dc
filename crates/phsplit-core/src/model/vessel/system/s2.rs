//! Flow S2 of the vessel over a sub-step (paper §3.4.2; docs/model.md §3.3, §3.5, §3.7): the
//! exact flow of the two block systems (matrix exponential, ledger by the Van Loan Gramian),
//! their Gauss collocation (the structured 3×3 solve, ledger by Gauss quadrature), and the
//! Gauss collocation of S2 with a forcing part (time-dependent or non-affine components); and
//! the same three for S2 as one coupled 18-dimensional system, where the mass matrix or a force
//! couples translation and rotation (docs/model.md §5.14). A solve that gives up (a singular
//! stage system, a fixed point that does not converge) yields NaN and records why
//! ([`GaveUp`]), which the run's failure message says. The assembly of S2 from the components
//! is `system.rs`'s.

// Stage loops index the Butcher tableau `a_ij`, `b_i` and the blocks as the formulas write them.
#![allow(clippy::needless_range_loop)]

use super::super::forces::{Forcing, Frozen, Rows, S2Builder, Sys};
use super::super::state::VesselState;
use super::{GaveUp, LinearFlow, VesselSystem};
use crate::flows::affine;
use crate::flows::collocation::{self as gauss, Blocks, Z3};
use crate::solve::Work;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// Most fixed-point passes over the forcing of flow S2 in one sub-step.
const FORCED_MAX_ITERATIONS: usize = 200;

mod coupled;
pub(super) use coupled::augmented;

/// The stage system of at most three Gauss stages of one 10-dimensional block system.
type Stages = SMatrix<f64, 30, 30>;
type StageVector = SVector<f64, 30>;

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
        let fr = self.frozen(s, on);
        let b = self.s2_of(&fr, ledger);
        let z0 = self.blocks_of(s);
        let (z1, work) = if b.cross.is_some() {
            self.coupled_s2(&fr, &b, &z0, h, t, stages)
        } else if self.forced {
            self.forced_gauss_s2(&fr, &b, &z0, h, t, stages)
        } else {
            match self.linear {
                LinearFlow::Gauss => self.gauss_s2(&b, &z0, h, stages),
                LinearFlow::Exact => self.exact_s2(&b, &z0, h),
            }
        };
        self.set_blocks(s, &z1);
        work
    }

    /// Gauss collocation with `s` stages of flow S2 with a forcing part:
    /// `z' = Ā z + g(t, z)` on both block systems, `Z_i = z0 + h Σ_j a_ij (Ā Z_j + g(t + c_j h, Z_j))`,
    /// `z1 = z0 + h Σ_i b_i (Ā Z_i + g_i)`. The linear part is implicit (one LU of the
    /// balanced `10s × 10s` stage matrix per system), the forcing is iterated to a fixed point
    /// (it converges at the rate `h² |∂g/∂x| / m`, tiny for the forces of a hull). The ledger
    /// books each account's power at the stages with the weights `h b_i`, which is exact for
    /// the collocation polynomial of a quadratic storage (Hairer–Lubich–Wanner, *Geometric
    /// Numerical Integration*, §IV.2). A system that does not converge, or a singular stage
    /// matrix, yields a non-finite state (the run then fails with what it had).
    fn forced_gauss_s2(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        z0: &[Z3; 2],
        h: f64,
        t: f64,
        s: usize,
    ) -> ([Z3; 2], Work) {
        let nan = ([[Vector3::from_element(f64::NAN); 3]; 2], Work::default());
        let (a, bw) = gauss::tableau(s);
        let nodes: [f64; 3] = std::array::from_fn(|i| a[i].iter().sum());
        let minv = self.minv();
        let mut mats = [SMatrix::<f64, 10, 10>::zeros(); 2];
        let mut scales = [SVector::<f64, 10>::zeros(); 2];
        // The stage matrices I − h 𝒜⊗Ã, on the stack: three stages at most, the unused ones
        // left as identity rows (their stages come out zero and are not read).
        let lus = std::array::from_fn::<_, 2, _>(|k| {
            let scale = balance(&b.sys[k], &minv[k]);
            let abar = b.sys[k].augmented();
            let at = SMatrix::<f64, 10, 10>::from_fn(|i, j| abar[(i, j)] * scale[j] / scale[i]);
            let mut m = Stages::identity();
            for i in 0..s {
                for j in 0..s {
                    let mut v = m.fixed_view_mut::<10, 10>(10 * i, 10 * j);
                    v -= at * (h * a[i][j]);
                }
            }
            mats[k] = at;
            scales[k] = scale;
            m.lu()
        });
        let pack = |z: &Z3, k: usize, one: f64| {
            let mut out = SVector::<f64, 10>::zeros();
            for (i, v) in z.iter().enumerate() {
                out.fixed_rows_mut::<3>(3 * i).copy_from(v);
            }
            out[9] = one;
            out.component_div(&scales[k])
        };
        let unpack = |y: &SVector<f64, 10>, k: usize| -> Z3 {
            let z = y.component_mul(&scales[k]);
            [
                z.fixed_rows::<3>(0).into_owned(),
                z.fixed_rows::<3>(3).into_owned(),
                z.fixed_rows::<3>(6).into_owned(),
            ]
        };
        let z0t = [pack(&z0[0], 0, 1.0), pack(&z0[1], 1, 1.0)];
        let mut stage_z = [*z0; 3];
        // The stage iterates, balanced, starting from z0 (as stage_z does).
        let mut ys: [[SVector<f64, 10>; 3]; 2] = std::array::from_fn(|k| {
            std::array::from_fn(|i| if i < s { z0t[k] } else { SVector::zeros() })
        });
        let mut g = [Forcing::new(); 3];
        // The parts that depend on time only, once per stage; the rest per pass.
        let fixed: [Forcing; 3] = std::array::from_fn(|i| {
            if i < s {
                self.forcing_of(fr, t + nodes[i] * h, &stage_z[i], Some(false))
            } else {
                Forcing::new()
            }
        });
        let stateful = self.forced_stateful;
        let mut fp = FixedPoint::new();
        let mut prev_r: Option<[[SVector<f64, 10>; 3]; 2]> = None;
        for it in 0..FORCED_MAX_ITERATIONS {
            for i in 0..s {
                g[i] = fixed[i];
                if stateful {
                    g[i].add(&self.forcing_of(fr, t + nodes[i] * h, &stage_z[i], Some(true)));
                }
            }
            let mut r = [[SVector::<f64, 10>::zeros(); 3]; 2];
            for k in 0..2 {
                let gt: [SVector<f64, 10>; 3] = std::array::from_fn(|j| {
                    if j < s {
                        pack(&g[j].g[k], k, 0.0)
                    } else {
                        SVector::zeros()
                    }
                });
                let mut rhs = StageVector::zeros();
                for i in 0..s {
                    let mut r = z0t[k];
                    for j in 0..s {
                        r += gt[j] * (h * a[i][j]);
                    }
                    rhs.fixed_rows_mut::<10>(10 * i).copy_from(&r);
                }
                let Some(y) = lus[k].solve(&rhs) else {
                    self.give_up(GaveUp::Singular);
                    return nan;
                };
                for i in 0..s {
                    r[k][i] = y.fixed_rows::<10>(10 * i) - ys[k][i];
                }
            }
            if let Some(pr) = &prev_r {
                for k in 0..2 {
                    for i in 0..s {
                        fp.compare(r[k][i].as_slice(), pr[k][i].as_slice());
                    }
                }
            }
            let omega = fp.relax();
            for k in 0..2 {
                for i in 0..s {
                    let yi = ys[k][i] + r[k][i] * omega;
                    fp.measure(r[k][i].as_slice(), yi.as_slice(), 9);
                    ys[k][i] = yi;
                    stage_z[i][k] = unpack(&yi, k);
                }
            }
            prev_r = Some(r);
            match fp.verdict(it, stateful) {
                Verdict::Continue => {}
                Verdict::Converged => break,
                Verdict::Failed => {
                    self.give_up(GaveUp::Forcing);
                    return nan;
                }
            }
        }
        for i in 0..s {
            g[i] = fixed[i];
            if stateful {
                g[i].add(&self.forcing_of(fr, t + nodes[i] * h, &stage_z[i], Some(true)));
            }
        }
        let mut z1 = [[Vector3::zeros(); 3]; 2];
        for k in 0..2 {
            let mut y1 = z0t[k];
            for i in 0..s {
                y1 += (mats[k] * ys[k][i] + pack(&g[i].g[k], k, 0.0)) * (h * bw[i]);
            }
            z1[k] = unpack(&y1, k);
        }
        let mut work = Work::default();
        if let Some(booked) = &b.booked {
            for i in 0..s {
                let mut p = self.power_at(booked, &stage_z[i]);
                p += self.forcing_power(&g[i], &stage_z[i]);
                work += p.scaled(h * bw[i]);
            }
        }
        let finite = z1.iter().flatten().all(|v| v.iter().all(|x| x.is_finite()));
        if !finite {
            return nan;
        }
        (z1, work)
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
        let (Some((zt1, st)), Some((zr1, sr))) = (
            gauss::blocks_step(&b.sys[0], &z0[0], h, s),
            gauss::blocks_step(&b.sys[1], &z0[1], h, s),
        ) else {
            return (nan, Work::default());
        };
        let mut work = Work::default();
        if let Some(booked) = &b.booked {
            let w = gauss::weights(s);
            for i in 0..s {
                work += self.power_at(booked, &[st[i], sr[i]]).scaled(h * w[i]);
            }
        }
        ([zt1, zr1], work)
    }

    /// The exact flow of both block systems, balanced; with the ledger, each account's energy
    /// from one Gramian per system.
    pub(super) fn exact_s2(&self, b: &S2Builder, z0: &[Z3; 2], h: f64) -> ([Z3; 2], Work) {
        let minv = self.minv();
        let mut z1 = [[Vector3::zeros(); 3]; 2];
        let mut work = Work::default();
        for sys in [Sys::Trans, Sys::Rot] {
            let k = sys as usize;
            let blocks = &b.sys[k];
            let scale = balance(blocks, &minv[k]);
            let inv = scale.map(|v| 1.0 / v);
            let abar = blocks.augmented();
            let a = SMatrix::<f64, 10, 10>::from_fn(|i, j| abar[(i, j)] * scale[j] * inv[i]);
            let mut zz = SVector::<f64, 10>::zeros();
            for (i, v) in z0[k].iter().enumerate() {
                zz.fixed_rows_mut::<3>(3 * i).copy_from(v);
            }
            zz[9] = 1.0;
            let zb = zz.component_div(&scale);
            let zb1 = match &b.booked {
                Some(booked) => {
                    let (f, gram) = affine::flow_and_gramian::<10, 20>(&a, &zb, h);
                    for acc in 0..self.accounts.len() {
                        let m = power_form(&booked[acc][k], &minv[k], k);
                        let mb =
                            SMatrix::<f64, 10, 10>::from_fn(|i, j| m[(i, j)] * scale[i] * scale[j]);
                        work.0[acc] += self.sign(acc) * affine::trace_product(&mb, &gram);
                    }
                    f * zb
                }
                None => affine::flow(&a, h) * zb,
            };
            let z = zb1.component_mul(&scale);
            z1[k] = [
                z.fixed_rows::<3>(0).into_owned(),
                z.fixed_rows::<3>(3).into_owned(),
                z.fixed_rows::<3>(6).into_owned(),
            ];
        }
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
    /// independent of the state, `stateful` false, at the first pass), or when the whole is at
    /// round-off (below 1e-12) and neither measure improves any more.
    fn verdict(&mut self, it: usize, stateful: bool) -> Verdict {
        let (change, parts) = (self.change, self.parts);
        if !change.is_finite() {
            return Verdict::Failed;
        }
        if !stateful
            || (it > 0
                && (parts <= 4.0 * f64::EPSILON
                    || (change < 1e-12 && change >= self.last_change && parts >= self.last_parts)))
        {
            return Verdict::Converged;
        }
        if it + 1 == FORCED_MAX_ITERATIONS && change > 1e-10 {
            return Verdict::Failed;
        }
        (self.last_change, self.last_parts) = (change, parts);
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
fn balance(b: &Blocks, minv: &Vector3<f64>) -> SVector<f64, 10> {
    let su = minv.map(|v| 1.0 / v);
    let avu_m = b.avu * Matrix3::from_diagonal(&su);
    let norm = (0..3)
        .map(|i| avu_m.row(i).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let sv = if norm > 0.0 && norm.is_finite() {
        2f64.powi(norm.log2().round() as i32)
    } else {
        1.0
    };
    SVector::<f64, 10>::from_fn(|i, _| match i {
        0..=2 => su[i],
        3..=5 => sv,
        _ => 1.0,
    })
}

/// The quadratic form of the power of a force: `νᵀ F z̄`, symmetrised, on `z̄ = (u, v, w, 1)`
/// of system `k`, with `ν = M⁻¹u` (`M` of the paper's form: diagonal `minv` on this system).
fn power_form(f: &Rows, minv: &Vector3<f64>, k: usize) -> SMatrix<f64, 10, 10> {
    let mut r = SMatrix::<f64, 3, 10>::zeros();
    r.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(f.fnu[k] * Matrix3::from_diagonal(minv)));
    r.fixed_view_mut::<3, 3>(0, 3).copy_from(&f.fv);
    r.fixed_view_mut::<3, 3>(0, 6).copy_from(&f.fw);
    r.fixed_view_mut::<3, 1>(0, 9).copy_from(&f.c);
    for i in 0..3 {
        r.row_mut(i).scale_mut(minv[i]);
    }
    let mut m = SMatrix::<f64, 10, 10>::zeros();
    m.fixed_view_mut::<3, 10>(0, 0).copy_from(&(r * 0.5));
    let mt = m.transpose();
    m + mt
}
