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
        let (mut last_change, mut last_parts) = (f64::INFINITY, f64::INFINITY);
        // Aitken's relaxation of the fixed point (B. M. Irons, R. C. Tuck, Int. J. Numer. Meth.
        // Eng. 1 (1969) 275–277; in the form of U. Küttler, W. A. Wall, Comput. Mech. 43 (2008)
        // 61–72, eq. 44): x ← x + ω r with r = G(x) − x and ω ← −ω r_oldᵀ(r − r_old)/|r − r_old|².
        // A dissipative forcing (quadratic damping at long steps) makes the plain iteration
        // oscillate with a rate that can pass 1; the relaxation damps that, and leaves a
        // quickly converging iteration as it was (ω ≈ 1).
        let mut omega = 1.0;
        let mut prev_r: Option<[[SVector<f64, 10>; 3]; 2]> = None;
        for it in 0..FORCED_MAX_ITERATIONS {
            for i in 0..s {
                g[i] = fixed[i];
                if stateful {
                    g[i].add(&self.forcing_of(fr, t + nodes[i] * h, &stage_z[i], Some(true)));
                }
            }
            let (mut change, mut parts): (f64, f64) = (0.0, 0.0);
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
                let (mut num, mut den) = (0.0, 0.0);
                for k in 0..2 {
                    for i in 0..s {
                        let d = r[k][i] - pr[k][i];
                        num += pr[k][i].dot(&d);
                        den += d.norm_squared();
                    }
                }
                if den > 0.0 && num.is_finite() {
                    omega = (-omega * num / den).clamp(0.05, 2.0);
                }
            }
            // Convergence is judged on the residual `G(x) − x` itself, not on the relaxed step
            // (Aitken's steps do not shrink steadily); a NaN anywhere makes it NaN.
            for k in 0..2 {
                for i in 0..s {
                    let yi = ys[k][i] + r[k][i] * omega;
                    let (res, part) = relative_change(r[k][i].as_slice(), yi.as_slice(), 9);
                    change = if res.is_nan() || change.is_nan() {
                        f64::NAN
                    } else {
                        change.max(res)
                    };
                    parts = parts.max(part);
                    ys[k][i] = yi;
                    stage_z[i][k] = unpack(&yi, k);
                }
            }
            prev_r = Some(r);
            if !change.is_finite() {
                // The fixed point diverged (or a stage overflowed).
                self.give_up(GaveUp::Forcing);
                return nan;
            }
            // Converged: the stages no longer move, every part of them (a forcing independent of
            // the state converges at the second pass), or, at round-off of the whole, their parts
            // stopped improving.
            if it > 0
                && (parts <= 4.0 * f64::EPSILON
                    || (change < 1e-12 && change >= last_change && parts >= last_parts))
            {
                break;
            }
            if it + 1 == FORCED_MAX_ITERATIONS && change > 1e-10 {
                self.give_up(GaveUp::Forcing);
                return nan;
            }
            // Without a state-dependent forcing the first pass is the solution.
            if !stateful {
                break;
            }
            (last_change, last_parts) = (change, parts);
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

/// The state of the coupled system: `z̄ = (u_t, v_t, w_t, u_r, v_r, w_r, 1)`.
type Full = SMatrix<f64, 19, 19>;
type FullVector = SVector<f64, 19>;

/// Flow S2 as one augmented matrix `Ā` on `z̄ = (u_t, v_t, w_t, u_r, v_r, w_r, 1)`: the two
/// block systems on the diagonal and, when they are coupled, what each takes from the other's
/// momentum.
pub(super) fn augmented(b: &S2Builder) -> Full {
    let mut a = Full::zeros();
    for k in 0..2 {
        let o = 9 * k;
        let blk = b.sys[k].augmented();
        a.fixed_view_mut::<9, 9>(o, o)
            .copy_from(&blk.fixed_view::<9, 9>(0, 0));
        a.fixed_view_mut::<9, 1>(o, 18)
            .copy_from(&blk.fixed_view::<9, 1>(0, 9));
        if let Some(c) = &b.cross {
            let l = 9 * (1 - k);
            a.fixed_view_mut::<3, 3>(o, l).copy_from(&c[k][0]);
            a.fixed_view_mut::<3, 3>(o + 3, l).copy_from(&c[k][1]);
            a.fixed_view_mut::<3, 3>(o, l + 3).copy_from(&c[k][2]);
        }
    }
    a
}

fn pack_full(z: &[Z3; 2], one: f64) -> FullVector {
    let mut y = FullVector::zeros();
    for k in 0..2 {
        for i in 0..3 {
            y.fixed_rows_mut::<3>(9 * k + 3 * i).copy_from(&z[k][i]);
        }
    }
    y[18] = one;
    y
}

fn unpack_full(y: &FullVector) -> [Z3; 2] {
    std::array::from_fn(|k| std::array::from_fn(|i| y.fixed_rows::<3>(9 * k + 3 * i).into_owned()))
}

impl VesselSystem<'_> {
    /// The balancing of the coupled system: each block system's as in [`balance`], with the
    /// diagonal of `M` as the momentum scale.
    fn balance_full(&self, b: &S2Builder) -> FullVector {
        let md = self.vessel.body.mass_matrix.diagonal();
        let mut out = FullVector::from_element(1.0);
        for k in 0..2 {
            let minv = Vector3::from_fn(|i, _| 1.0 / md[3 * k + i]);
            let sk = balance(&b.sys[k], &minv);
            out.fixed_rows_mut::<9>(9 * k)
                .copy_from(&sk.fixed_rows::<9>(0));
        }
        out
    }

    /// The quadratic form of an account's power `Σ_k ν_kᵀ f_k` on `z̄`, symmetrised, with
    /// `ν = M⁻¹u` through the full `M⁻¹`.
    fn power_form_full(&self, rows: &[Rows; 2]) -> Full {
        let mi = &self.vessel.body.minv_blocks;
        // ν = E z̄.
        let mut e = SMatrix::<f64, 6, 19>::zeros();
        for j in 0..2 {
            for l in 0..2 {
                e.fixed_view_mut::<3, 3>(3 * j, 9 * l).copy_from(&mi[j][l]);
            }
        }
        let mut r = SMatrix::<f64, 6, 19>::zeros();
        for (k, f) in rows.iter().enumerate() {
            let mut rk =
                f.fnu[0] * e.fixed_view::<3, 19>(0, 0) + f.fnu[1] * e.fixed_view::<3, 19>(3, 0);
            let mut fv = rk.fixed_view_mut::<3, 3>(0, 9 * k + 3);
            fv += f.fv;
            let mut fw = rk.fixed_view_mut::<3, 3>(0, 9 * k + 6);
            fw += f.fw;
            let mut c = rk.fixed_view_mut::<3, 1>(0, 18);
            c += f.c;
            r.fixed_view_mut::<3, 19>(3 * k, 0).copy_from(&rk);
        }
        let m = e.transpose() * r * 0.5;
        m + m.transpose()
    }

    /// Flow S2 where translation and rotation are coupled (a general mass matrix, or a force
    /// that couples them; docs/model.md §5.14): one 18-dimensional affine system, by its exact
    /// flow with the ledger by the Van Loan Gramian (one 38×38 exponential), or, with
    /// [`LinearFlow::Gauss`] or a forcing part, by Gauss collocation with `s` stages (the
    /// forcing iterated to a fixed point as in the block systems' collocation, with the same
    /// Aitken relaxation and stopping rule) and the ledger by the Gauss quadrature of the
    /// power, exact for the quadratic storage.
    pub(super) fn coupled_s2(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        z0: &[Z3; 2],
        h: f64,
        t: f64,
        s: usize,
    ) -> ([Z3; 2], Work) {
        let scale = self.balance_full(b);
        let inv = scale.map(|v| 1.0 / v);
        let abar = augmented(b);
        let a = Full::from_fn(|i, j| abar[(i, j)] * scale[j] * inv[i]);
        let zb0 = pack_full(z0, 1.0).component_mul(&inv);
        if !self.forced && self.linear == LinearFlow::Exact {
            let mut work = Work::default();
            let zb1 = match &b.booked {
                Some(booked) => {
                    let (f, gram) = affine::flow_and_gramian::<19, 38>(&a, &zb0, h);
                    for acc in 0..self.accounts.len() {
                        let m = self.power_form_full(&booked[acc]);
                        let mb = Full::from_fn(|i, j| m[(i, j)] * scale[i] * scale[j]);
                        work.0[acc] += self.sign(acc) * affine::trace_product(&mb, &gram);
                    }
                    f * zb0
                }
                None => affine::flow(&a, h) * zb0,
            };
            let z1 = unpack_full(&zb1.component_mul(&scale));
            return (z1, work);
        }
        match s {
            1 => self.coupled_collocation::<19>(fr, b, z0, &a, &scale, h, t, 1),
            2 => self.coupled_collocation::<38>(fr, b, z0, &a, &scale, h, t, 2),
            _ => self.coupled_collocation::<57>(fr, b, z0, &a, &scale, h, t, 3),
        }
    }

    /// The Gauss collocation of [`Self::coupled_s2`] with `s` stages, `NS = 19 s`, on the
    /// balanced system `a` (scaling `scale`).
    #[allow(clippy::too_many_arguments)]
    fn coupled_collocation<const NS: usize>(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        z0: &[Z3; 2],
        a: &Full,
        scale: &FullVector,
        h: f64,
        t: f64,
        s: usize,
    ) -> ([Z3; 2], Work)
    where
        nalgebra::Const<NS>: nalgebra::DimMin<nalgebra::Const<NS>, Output = nalgebra::Const<NS>>,
    {
        let nan = ([[Vector3::from_element(f64::NAN); 3]; 2], Work::default());
        let inv = scale.map(|v| 1.0 / v);
        let zb0 = pack_full(z0, 1.0).component_mul(&inv);
        let (ta, bw) = gauss::tableau(s);
        let nodes: [f64; 3] = std::array::from_fn(|i| ta[i].iter().sum());
        let mut m = SMatrix::<f64, NS, NS>::identity();
        for i in 0..s {
            for j in 0..s {
                let mut v = m.fixed_view_mut::<19, 19>(19 * i, 19 * j);
                v -= *a * (h * ta[i][j]);
            }
        }
        let lu = m.lu();
        let forcing_at = |i: usize, z: &[Z3; 2], uses: Option<bool>| {
            self.forcing_of(fr, t + nodes[i] * h, z, uses)
        };
        let mut stage_z = [*z0; 3];
        let mut ys: [FullVector; 3] =
            std::array::from_fn(|i| if i < s { zb0 } else { FullVector::zeros() });
        let fixed: [Forcing; 3] = std::array::from_fn(|i| {
            if i < s && self.forced {
                forcing_at(i, z0, Some(false))
            } else {
                Forcing::new()
            }
        });
        let stateful = self.forced_stateful;
        let total = |i: usize, z: &[Z3; 2]| {
            let mut g = fixed[i];
            if stateful {
                g.add(&forcing_at(i, z, Some(true)));
            }
            g
        };
        let (mut omega, mut last_change, mut last_parts) = (1.0, f64::INFINITY, f64::INFINITY);
        let mut prev_r: Option<[FullVector; 3]> = None;
        let mut g = [Forcing::new(); 3];
        for it in 0..FORCED_MAX_ITERATIONS {
            for i in 0..s {
                g[i] = total(i, &stage_z[i]);
            }
            let gt: [FullVector; 3] =
                std::array::from_fn(|j| pack_full(&g[j].g, 0.0).component_mul(&inv));
            let mut rhs = SVector::<f64, NS>::zeros();
            for i in 0..s {
                let mut r = zb0;
                for j in 0..s {
                    r += gt[j] * (h * ta[i][j]);
                }
                rhs.fixed_rows_mut::<19>(19 * i).copy_from(&r);
            }
            let Some(y) = lu.solve(&rhs) else {
                self.give_up(GaveUp::Singular);
                return nan;
            };
            let r: [FullVector; 3] = std::array::from_fn(|i| {
                if i < s {
                    y.fixed_rows::<19>(19 * i) - ys[i]
                } else {
                    FullVector::zeros()
                }
            });
            if let Some(pr) = &prev_r {
                let (mut num, mut den) = (0.0, 0.0);
                for i in 0..s {
                    let d = r[i] - pr[i];
                    num += pr[i].dot(&d);
                    den += d.norm_squared();
                }
                if den > 0.0 && num.is_finite() {
                    omega = (-omega * num / den).clamp(0.05, 2.0);
                }
            }
            let (mut change, mut parts): (f64, f64) = (0.0, 0.0);
            for i in 0..s {
                let yi = ys[i] + r[i] * omega;
                let (res, part) = relative_change(r[i].as_slice(), yi.as_slice(), 18);
                change = if res.is_nan() || change.is_nan() {
                    f64::NAN
                } else {
                    change.max(res)
                };
                parts = parts.max(part);
                ys[i] = yi;
                stage_z[i] = unpack_full(&yi.component_mul(scale));
            }
            prev_r = Some(r);
            if !change.is_finite() {
                // The fixed point diverged (or a stage overflowed).
                self.give_up(GaveUp::Forcing);
                return nan;
            }
            // As in the block systems' collocation.
            if !stateful
                || (it > 0
                    && (parts <= 4.0 * f64::EPSILON
                        || (change < 1e-12 && change >= last_change && parts >= last_parts)))
            {
                break;
            }
            if it + 1 == FORCED_MAX_ITERATIONS && change > 1e-10 {
                self.give_up(GaveUp::Forcing);
                return nan;
            }
            (last_change, last_parts) = (change, parts);
        }
        for i in 0..s {
            g[i] = total(i, &stage_z[i]);
        }
        let mut y1 = zb0;
        for i in 0..s {
            y1 += (*a * ys[i] + pack_full(&g[i].g, 0.0).component_mul(&inv)) * (h * bw[i]);
        }
        let z1 = unpack_full(&y1.component_mul(scale));
        let mut work = Work::default();
        if let Some(booked) = &b.booked {
            for i in 0..s {
                let mut p = self.power_at(booked, &stage_z[i]);
                p += self.forcing_power(&g[i], &stage_z[i]);
                work += p.scaled(h * bw[i]);
            }
        }
        if !z1.iter().flatten().all(|v| v.iter().all(|x| x.is_finite())) {
            return nan;
        }
        (z1, work)
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
