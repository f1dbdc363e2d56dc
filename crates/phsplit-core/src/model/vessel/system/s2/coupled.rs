//! Flow S2 as one coupled 18-dimensional system, where the mass matrix or a force couples
//! translation and rotation (docs/model.md §5.14): its exact flow with the ledger by the Van
//! Loan Gramian; and the Gauss collocation of S2 with a forcing part, coupled or not, by the
//! structured stage solver in blocks of six with the forcing iterated (the fixed point and the
//! balancing are `s2.rs`'s).

// Stage loops index the Butcher tableau `a_ij`, `b_i` and the blocks as the formulas write them.
#![allow(clippy::needless_range_loop)]

use super::super::super::forces::{Forcing, Frozen, Rows, S2Builder};
use super::super::{GaveUp, LinearFlow, VesselSystem};
use super::{balance, FixedPoint, Verdict, FORCED_MAX_ITERATIONS};
use crate::flows::affine;
use crate::flows::collocation::{self as gauss, Z3};
use crate::flows::stage_solve::{Parts, StageSolver, Structure};
use crate::solve::Work;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

/// The state of the coupled system: `z̄ = (u_t, v_t, w_t, u_r, v_r, w_r, 1)`.
type Full = SMatrix<f64, 19, 19>;
type FullVector = SVector<f64, 19>;

/// The momentum entries `u_t`, `u_r` of `z̄`.
const MOMENTA: [usize; 6] = [0, 1, 2, 9, 10, 11];

/// Flow S2 as one augmented matrix `Ā` on `z̄ = (u_t, v_t, w_t, u_r, v_r, w_r, 1)`: the two
/// block systems on the diagonal and, when they are coupled, what each takes from the other's
/// momentum.
pub(crate) fn augmented(b: &S2Builder) -> Full {
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

/// A state `(u, v, w)` in blocks of six: `u = (u_t, u_r)`, `v = (v_t, v_r)`, `w = (w_t, w_r)`.
type Six = Parts<f64, 6>;

/// The balancing `scale` (on `z̄`'s order) as blocks of six, and its reciprocal.
fn six_scales(scale: &FullVector) -> (Six, Six) {
    let sc: Six = std::array::from_fn(|c| {
        SVector::<f64, 6>::from_fn(|j, _| scale[9 * (j / 3) + 3 * c + j % 3])
    });
    (sc, sc.map(|v| v.map(|x| 1.0 / x)))
}

/// The coupled system in blocks of six, balanced (`sc`, its reciprocal `inv`): its linear part
/// and its constants `(c_u, 0, c_w)`. The rows of `v` read only the momenta and those of `w`
/// only their own system's `v` ([`augmented`]), which is [`Structure`]'s form.
fn six_blocks(b: &S2Builder, sc: &Six, inv: &Six) -> (Structure<6>, Six) {
    let m6 = |diag: [Matrix3<f64>; 2], cross: Option<[Matrix3<f64>; 2]>, r: usize, c: usize| {
        let mut m = SMatrix::<f64, 6, 6>::zeros();
        for k in 0..2 {
            m.fixed_view_mut::<3, 3>(3 * k, 3 * k).copy_from(&diag[k]);
            if let Some(x) = cross {
                m.fixed_view_mut::<3, 3>(3 * k, 3 * (1 - k))
                    .copy_from(&x[k]);
            }
        }
        SMatrix::<f64, 6, 6>::from_fn(|i, j| m[(i, j)] * sc[c][j] * inv[r][i])
    };
    let cross = |n: usize| b.cross.map(|x| [x[0][n], x[1][n]]);
    let (s0, s1) = (&b.sys[0], &b.sys[1]);
    let st = Structure {
        auu: m6([s0.auu, s1.auu], cross(0), 0, 0),
        auv: m6([s0.auv, s1.auv], cross(2), 0, 1),
        auw: m6([s0.auw, s1.auw], None, 0, 2),
        avu: m6([s0.avu, s1.avu], cross(1), 1, 0),
        awv: m6([s0.awv, s1.awv], None, 2, 1),
    };
    let c = to_six(&[
        [s0.cu, Vector3::zeros(), s0.cw],
        [s1.cu, Vector3::zeros(), s1.cw],
    ]);
    (st, mul6(&c, inv))
}

/// The stage solver of the system in blocks of six: where translation and rotation do not
/// couple (every block of the structure block-diagonal), the two systems' own `3 × 3` solvers,
/// whose reduced systems are the diagonal blocks of the `6 × 6` ones (the same numbers but for
/// the sign of a zero: the coupled products and eliminations add only exact zeros to them), at a
/// quarter of the factorisations' and products' cost and half the solves'.
// Made once per sub-step and kept on its stack: no box for the larger variant.
#[allow(clippy::large_enum_variant)]
enum SixSolver {
    Coupled(StageSolver<6>),
    Apart([StageSolver<3>; 2]),
}

impl SixSolver {
    fn new(st: &Structure<6>, h: f64, s: usize) -> Self {
        let blocks = [&st.auu, &st.auv, &st.auw, &st.avu, &st.awv];
        let apart = blocks.iter().all(|m| {
            m.fixed_view::<3, 3>(0, 3).iter().all(|v| *v == 0.0)
                && m.fixed_view::<3, 3>(3, 0).iter().all(|v| *v == 0.0)
        });
        if !apart {
            return Self::Coupled(StageSolver::new(st, h, s));
        }
        Self::Apart(std::array::from_fn(|k| {
            let d = |m: &SMatrix<f64, 6, 6>| m.fixed_view::<3, 3>(3 * k, 3 * k).into_owned();
            let part = Structure {
                auu: d(&st.auu),
                auv: d(&st.auv),
                auw: d(&st.auw),
                avu: d(&st.avu),
                awv: d(&st.awv),
            };
            StageSolver::new(&part, h, s)
        }))
    }

    /// [`StageSolver::solve`].
    fn solve(&self, r: &[Six; 3]) -> Option<[Six; 3]> {
        match self {
            Self::Coupled(solver) => solver.solve(r),
            Self::Apart(solvers) => {
                let mut dy = [[SVector::<f64, 6>::zeros(); 3]; 3];
                for (k, solver) in solvers.iter().enumerate() {
                    let rk: [Parts<f64, 3>; 3] = std::array::from_fn(|i| {
                        std::array::from_fn(|c| r[i][c].fixed_rows::<3>(3 * k).into_owned())
                    });
                    let yk = solver.solve(&rk)?;
                    for i in 0..3 {
                        for c in 0..3 {
                            dy[i][c].fixed_rows_mut::<3>(3 * k).copy_from(&yk[i][c]);
                        }
                    }
                }
                Some(dy)
            }
        }
    }
}

/// The block systems' `[Z3; 2]` as blocks of six.
fn to_six(z: &[Z3; 2]) -> Six {
    std::array::from_fn(|c| {
        let mut v = SVector::<f64, 6>::zeros();
        v.fixed_rows_mut::<3>(0).copy_from(&z[0][c]);
        v.fixed_rows_mut::<3>(3).copy_from(&z[1][c]);
        v
    })
}

/// The inverse of [`to_six`].
fn from_six(p: &Six) -> [Z3; 2] {
    std::array::from_fn(|k| std::array::from_fn(|c| p[c].fixed_rows::<3>(3 * k).into_owned()))
}

/// Entry by entry `a b`.
fn mul6(a: &Six, b: &Six) -> Six {
    std::array::from_fn(|c| a[c].component_mul(&b[c]))
}

/// `a + b t`, block by block.
fn axpy(a: &Six, b: &Six, t: f64) -> Six {
    std::array::from_fn(|c| a[c] + b[c] * t)
}

/// Whether the residual of the collocation equations, `h Σ_j a_ij (g_j − g_j,old)` for stage
/// `i`, is at round-off of every 3-vector part of the stage `ys_i` (relative to the part, floored
/// at 1e-12 of the stage's largest entry, as [`FixedPoint`]'s measure by parts).
fn at_round_off(
    ys: &[Six; 3],
    g: &[Six; 3],
    old: &[Six; 3],
    ta: &[[f64; 3]; 3],
    h: f64,
    s: usize,
) -> bool {
    (0..s).all(|i| {
        let y = flat(&ys[i]);
        let mut res = SVector::<f64, 18>::zeros();
        for j in 0..s {
            res += (flat(&g[j]) - flat(&old[j])) * (h * ta[i][j]);
        }
        let size = y.amax();
        (0..6).all(|k| {
            let part = y.fixed_rows::<3>(3 * k).amax().max(size * 1e-12);
            res.fixed_rows::<3>(3 * k).amax() <= f64::EPSILON * part
        })
    })
}

/// The 18 states of a [`Six`] in one vector (for the fixed point's measures, in 3-vectors).
fn flat(p: &Six) -> SVector<f64, 18> {
    let mut y = SVector::<f64, 18>::zeros();
    for c in 0..3 {
        y.fixed_rows_mut::<6>(6 * c).copy_from(&p[c]);
    }
    y
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

    /// An account's power `Σ_k ν_kᵀ f_k = Σ R ∘ (z̄_U z̄ᵀ)` as rows `R` on the momentum entries
    /// `U` ([`MOMENTA`]) of `z̄`, with `ν = M⁻¹u` through the full `M⁻¹`. Its integral along S2 is
    /// `Σ R ∘ Y` with `Y` the rows `U` of the Gramian.
    pub(crate) fn power_rows_full(
        &self,
        rows: &[Rows; 2],
        acc: usize,
        b: &S2Builder,
    ) -> SMatrix<f64, 6, 19> {
        let mi = &self.vessel.body.minv_blocks;
        // ν = E z̄ = E_U z̄_U.
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
        // The account's forces on the other system's second state.
        for (a, sys, f) in &b.cross_booked {
            if *a == acc {
                let k = *sys as usize;
                let mut fo = r.fixed_view_mut::<3, 3>(3 * k, 9 * (1 - k) + 3);
                fo += f;
            }
        }
        let e_u = SMatrix::<f64, 6, 6>::from_fn(|i, j| e[(i, MOMENTA[j])]);
        e_u.transpose() * r
    }

    /// Flow S2 where translation and rotation are coupled (a general mass matrix, or a force
    /// that couples them; docs/model.md §5.14): one 18-dimensional affine system, by its exact
    /// flow with the ledger by the Van Loan Gramian (one 38×38 exponential), or, with
    /// [`LinearFlow::Gauss`] or a forcing part, by Gauss collocation with `s` stages (the
    /// forcing iterated to a fixed point as in the block systems' collocation, with the same
    /// Aitken relaxation and stopping rule) and the ledger by the Gauss quadrature of the
    /// power, exact for the quadratic storage.
    pub(crate) fn coupled_s2(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        z0: &[Z3; 2],
        h: f64,
        t: f64,
        s: usize,
    ) -> ([Z3; 2], Work) {
        let scale = self.balance_full(b);
        if !self.forced && self.linear == LinearFlow::Exact {
            return self.coupled_exact(b, z0, &scale, h);
        }
        self.coupled_collocation(fr, b, z0, &scale, h, t, s)
    }

    /// The exact flow of [`Self::coupled_s2`], balanced by `scale` and then by Osborne's
    /// iteration ([`affine::balance`]), with each account's energy from the momentum rows of the
    /// Gramian ([`affine::flow_action_and_gramian_rows`]). Kept out of line: its fallback's 38×38
    /// temporaries would otherwise make every collocated sub-step pay for a stack frame of a few
    /// hundred kilobytes.
    #[inline(never)]
    fn coupled_exact(
        &self,
        b: &S2Builder,
        z0: &[Z3; 2],
        scale: &FullVector,
        h: f64,
    ) -> ([Z3; 2], Work) {
        let inv = scale.map(|v| 1.0 / v);
        let abar = augmented(b);
        let mut a = Full::from_fn(|i, j| abar[(i, j)] * scale[j] * inv[i]);
        let mut scale = *scale;
        affine::balance(&mut a, &mut scale);
        let z = pack_full(z0, 1.0);
        affine::balance_constant(&mut a, &mut scale, &z);
        let zb0 = z.component_div(&scale);
        let mut work = Work::default();
        let zb1 = match &b.booked {
            Some(booked) => {
                let (zb1, gram) =
                    affine::flow_action_and_gramian_rows::<19, 6, 38>(&a, &zb0, h, &MOMENTA);
                for acc in 0..self.accounts.len() {
                    let r = self.power_rows_full(&booked[acc], acc, b);
                    let energy = (0..19)
                        .map(|j| {
                            (0..6)
                                .map(|i| r[(i, j)] * scale[MOMENTA[i]] * gram[(i, j)])
                                .sum::<f64>()
                                * scale[j]
                        })
                        .sum::<f64>();
                    work.add(acc, self.sign(acc) * energy);
                }
                zb1
            }
            None => affine::flow_action(&a, &zb0, h),
        };
        (unpack_full(&zb1.component_mul(&scale)), work)
    }

    /// Gauss collocation with `s` stages of flow S2, coupled or not, with its forcing part:
    /// `z' = Ā z + g(t, z)`, `Z_i = z0 + h Σ_j a_ij (Ā Z_j + g(t + c_j h, Z_j))`,
    /// `z1 = z0 + h Σ_i b_i (Ā Z_i + g_i)`, balanced by `scale`. The linear part is implicit, the
    /// forcing is iterated to a fixed point ([`FixedPoint`]: it converges at the rate
    /// `h² |∂g/∂x| / m`, tiny for the forces of a hull, and the components put the stiff part of
    /// theirs in the implicit rows). The stage equations keep the block structure of flow S2 with
    /// blocks of six ([`six_blocks`]) and are solved for the stage increments by the
    /// transformed, reduced `6 × 6` systems of [`StageSolver`], factorised once per sub-step and
    /// solved once per pass. The ledger books each account's power at the stages with the
    /// weights `h b_i`, which is exact for the collocation polynomial of a quadratic storage
    /// (Hairer–Lubich–Wanner, *Geometric Numerical Integration*, §IV.2). A singular reduced
    /// system or a fixed point that does not converge yields a non-finite state (the run then
    /// fails with what it had, and says why).
    #[allow(clippy::too_many_arguments)]
    fn coupled_collocation(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        z0: &[Z3; 2],
        scale: &FullVector,
        h: f64,
        t: f64,
        s: usize,
    ) -> ([Z3; 2], Work) {
        let nan = ([[Vector3::from_element(f64::NAN); 3]; 2], Work::default());
        let (sc, inv) = six_scales(scale);
        let (st, cst) = six_blocks(b, &sc, &inv);
        let field = |y: &Six| {
            let f = st.apply(y);
            [f[0] + cst[0], f[1], f[2] + cst[2]]
        };
        let zb0 = mul6(&to_six(z0), &inv);
        let (ta, bw) = gauss::tableau(s);
        let nodes: [f64; 3] = std::array::from_fn(|i| ta[i].iter().sum());
        let solver = SixSolver::new(&st, h, s);
        // R_i = h c_i f(z0) + h Σ_j a_ij g_j.
        let f0 = field(&zb0);
        let forced = self.forced;
        let stateful = self.forced_stateful;
        // The parts of the forcing that depend on time only, once per stage (in `fixed`); the
        // parts that depend on the state per pass (in `g`). The stage's forcing is their sum.
        let mut fixed: [Forcing; 3] = std::array::from_fn(|_| Forcing::new());
        if self.forced_timed {
            for i in 0..s {
                self.add_forcing_of(fr, t + nodes[i] * h, z0, &[], Some(false), &mut fixed[i]);
            }
        }
        // `g[i].g` is the whole stage forcing (the fixed part's field, then the state's parts
        // added to it, in the order of the sum written out); `g[i]` books the state's parts only,
        // `fixed[i]` the rest.
        let mut g: [Forcing; 3] = std::array::from_fn(|_| Forcing::new());
        for i in 0..s {
            g[i].g = fixed[i].g;
        }
        let mut gt = [[SVector::<f64, 6>::zeros(); 3]; 3];
        let mut stage_z = [*z0; 3];
        let mut ys: [Six; 3] = [zb0; 3];
        let mut fp = FixedPoint::new();
        let mut prev_r: Option<[SVector<f64, 18>; 3]> = None;
        // Whether `g` is the forcing at the final stages (then the update needs no new one).
        let mut current = false;
        let mut omega = 1.0;
        for it in 0..FORCED_MAX_ITERATIONS {
            if forced {
                let old = gt;
                for i in 0..s {
                    if stateful {
                        g[i].clear();
                        g[i].g = fixed[i].g;
                        self.add_forcing_of(
                            fr,
                            t + nodes[i] * h,
                            &stage_z[i],
                            &[],
                            Some(true),
                            &mut g[i],
                        );
                    }
                    gt[i] = mul6(&to_six(&g[i].g), &inv);
                }
                // After an unrelaxed pass the stages solve the linear stage equations with the
                // previous forcing, so the residual of the collocation equations at them is
                // `h Σ_j a_ij (g_j − g_j,old)`: at round-off of every part of the stages they
                // are the solution, and another pass would not move them.
                if stateful && it > 0 && omega == 1.0 && at_round_off(&ys, &gt, &old, &ta, h, s) {
                    current = true;
                    break;
                }
            }
            let rhs: [Six; 3] = std::array::from_fn(|i| {
                let mut r = f0.map(|v| v * (h * nodes[i]));
                for j in 0..s {
                    r = axpy(&r, &gt[j], h * ta[i][j]);
                }
                r
            });
            let Some(dy) = solver.solve(&rhs) else {
                self.give_up(GaveUp::Singular);
                return nan;
            };
            if !stateful {
                // The stages do not feed back: this pass is the solution.
                for i in 0..s {
                    ys[i] = axpy(&zb0, &dy[i], 1.0);
                    stage_z[i] = from_six(&mul6(&ys[i], &sc));
                }
                break;
            }
            let r: [SVector<f64, 18>; 3] = std::array::from_fn(|i| {
                if i < s {
                    flat(&axpy(&axpy(&zb0, &dy[i], 1.0), &ys[i], -1.0))
                } else {
                    SVector::zeros()
                }
            });
            if let Some(pr) = &prev_r {
                for i in 0..s {
                    fp.compare(r[i].as_slice(), pr[i].as_slice());
                }
            }
            omega = fp.relax();
            for i in 0..s {
                let yi: Six =
                    std::array::from_fn(|c| ys[i][c] + r[i].fixed_rows::<6>(6 * c) * omega);
                fp.measure(r[i].as_slice(), flat(&yi).as_slice(), 18);
                ys[i] = yi;
                stage_z[i] = from_six(&mul6(&yi, &sc));
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
        let mut y1 = zb0;
        if stateful && !current {
            // The stages are converged to the fixed point's tolerance: the update takes the
            // field and the forcing at them.
            for i in 0..s {
                g[i].clear();
                g[i].g = fixed[i].g;
                self.add_forcing_of(
                    fr,
                    t + nodes[i] * h,
                    &stage_z[i],
                    &[],
                    Some(true),
                    &mut g[i],
                );
                gt[i] = mul6(&to_six(&g[i].g), &inv);
                y1 = axpy(&y1, &axpy(&field(&ys[i]), &gt[i], 1.0), h * bw[i]);
            }
        } else {
            // The stages solve the stage equations with the forcing `g` at them (to round-off):
            // `h Σ_j a_ij F_j = ΔY_i`, so `z1 = z0 + h Σ b_i F_i = z0 + Σ_i d_i ΔY_i` with
            // `d = bᵀ𝒜⁻¹`, without evaluating the field again.
            let d = gauss::update_weights(s);
            for i in 0..s {
                y1 = axpy(&y1, &axpy(&ys[i], &zb0, -1.0), d[i]);
            }
        }
        let z1 = from_six(&mul6(&y1, &sc));
        let mut work = Work::default();
        if b.booked.is_some() {
            for i in 0..s {
                let mut p = self.power_at(b, &stage_z[i]);
                if forced {
                    p += self.forcing_power(&[&fixed[i], &g[i]], &stage_z[i]);
                }
                work += p.scaled(h * bw[i]);
            }
        }
        if !z1.iter().flatten().all(|v| v.iter().all(|x| x.is_finite())) {
            return nan;
        }
        (z1, work)
    }
}
