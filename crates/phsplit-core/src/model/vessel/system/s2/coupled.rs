//! Flow S2 as one coupled 18-dimensional system, where the mass matrix or a force couples
//! translation and rotation (docs/model.md §5.14): its exact flow with the ledger by the Van
//! Loan Gramian, and its Gauss collocation with the forcing iterated (the fixed point and the
//! balancing are the block systems', `s2.rs`).

// Stage loops index the Butcher tableau `a_ij`, `b_i` and the blocks as the formulas write them.
#![allow(clippy::needless_range_loop)]

use super::super::super::forces::{Forcing, Frozen, Rows, S2Builder};
use super::super::{GaveUp, LinearFlow, VesselSystem};
use super::{balance, FixedPoint, Verdict, FORCED_MAX_ITERATIONS};
use crate::flows::affine;
use crate::flows::collocation::{self as gauss, Z3};
use crate::solve::Work;
use nalgebra::{SMatrix, SVector, Vector3};

/// The state of the coupled system: `z̄ = (u_t, v_t, w_t, u_r, v_r, w_r, 1)`.
type Full = SMatrix<f64, 19, 19>;
type FullVector = SVector<f64, 19>;

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
        let mut fp = FixedPoint::new();
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
                for i in 0..s {
                    fp.compare(r[i].as_slice(), pr[i].as_slice());
                }
            }
            let omega = fp.relax();
            for i in 0..s {
                let yi = ys[i] + r[i] * omega;
                fp.measure(r[i].as_slice(), yi.as_slice(), 18);
                ys[i] = yi;
                stage_z[i] = unpack_full(&yi.component_mul(scale));
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
