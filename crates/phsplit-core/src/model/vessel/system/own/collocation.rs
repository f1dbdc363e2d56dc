//! The Gauss collocation of flow S2 with the components' own states (`own.rs`): the dense
//! stage system solved once per sub-step, the forcing (on the block states and on the own
//! states) iterated to a fixed point, and the ledger by Gauss quadrature.

// Stage loops index the Butcher tableau `a_ij`, `b_i` and the stages as the formulas write them.
#![allow(clippy::needless_range_loop)]

use super::super::super::forces::{Forcing, Frozen, S2Builder};
use super::super::{GaveUp, VesselSystem};
use super::MAX_PASSES;
use crate::flows::collocation as gauss;
use crate::solve::Work;
use nalgebra::{DMatrix, DVector};

impl VesselSystem<'_> {
    /// Gauss collocation with `s` stages on the balanced dense system, the forcing iterated to a
    /// fixed point; the ledger by Gauss quadrature.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn dense_collocation(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        a: &DMatrix<f64>,
        w0: &DVector<f64>,
        h: f64,
        t: f64,
        s: usize,
    ) -> (DVector<f64>, Work) {
        let n = self.dim();
        let nan = (DVector::from_element(n, f64::NAN), Work::default());
        let sc = self.dense_balance(b, a);
        let ab = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * sc[j] / sc[i]);
        let wb = w0.component_div(&sc);
        let (ta, bw) = gauss::tableau(s);
        let nodes: Vec<f64> = (0..s).map(|i| ta[i].iter().sum()).collect();
        // (I − h 𝒜 ⊗ Ã) Y = 1 ⊗ w̃0 + h (𝒜 ⊗ I) g̃.
        let mut m = DMatrix::identity(s * n, s * n);
        for i in 0..s {
            for j in 0..s {
                let mut blk = m.view_mut((i * n, j * n), (n, n));
                blk -= &ab * (h * ta[i][j]);
            }
        }
        let lu = m.lu();
        let zero_g = || DVector::zeros(n);
        let mut gt: Vec<DVector<f64>> = (0..s).map(|_| zero_g()).collect();
        let mut forcings: Vec<Forcing> = (0..s).map(|_| Forcing::new()).collect();
        let mut ys: Vec<DVector<f64>> = vec![wb.clone(); s];
        let unscale = |y: &DVector<f64>| y.component_mul(&sc);
        let mut last_change = f64::INFINITY;
        let own0 = vec![0.0; self.own_dim];
        for pass in 0..MAX_PASSES {
            if self.forced {
                for i in 0..s {
                    // The stage's own states (the linear ones; a forcing reads its component's).
                    let (z, x) = self.unpack(&unscale(&ys[i]), &own0);
                    forcings[i].clear();
                    self.add_forcing_of(fr, t + nodes[i] * h, &z, &x, None, &mut forcings[i]);
                    let g = &forcings[i].g;
                    let mut v = zero_g();
                    for k in 0..2 {
                        for c in 0..3 {
                            for r in 0..3 {
                                let idx = 9 * k + 3 * c + r;
                                v[idx] = g[k][c][r] / sc[idx];
                            }
                        }
                    }
                    // Its part on the own states, at their columns.
                    for (cols, own) in self.own_columns() {
                        for (c, k) in cols.zip(own) {
                            v[c] = forcings[i].own_part(k) / sc[c];
                        }
                    }
                    gt[i] = v;
                }
            }
            let mut rhs = DVector::zeros(s * n);
            for i in 0..s {
                let mut r = wb.clone();
                for j in 0..s {
                    r += &gt[j] * (h * ta[i][j]);
                }
                rhs.rows_mut(i * n, n).copy_from(&r);
            }
            let Some(y) = lu.solve(&rhs) else {
                self.give_up(GaveUp::Singular);
                return nan;
            };
            let mut change: f64 = 0.0;
            for i in 0..s {
                let yi = y.rows(i * n, n).into_owned();
                let size = yi.amax().max(f64::MIN_POSITIVE);
                change = change.max((&yi - &ys[i]).amax() / size);
                ys[i] = yi;
            }
            if !self.forced || change <= 4.0 * f64::EPSILON {
                break;
            }
            if pass > 3 && change >= last_change {
                // Stalled at round-off.
                if change <= 1e-12 {
                    break;
                }
                self.give_up(GaveUp::Forcing);
                return nan;
            }
            if pass + 1 == MAX_PASSES {
                self.give_up(GaveUp::Forcing);
                return nan;
            }
            last_change = change;
        }
        let mut w1 = wb.clone();
        for i in 0..s {
            w1 += (&ab * &ys[i] + &gt[i]) * (h * bw[i]);
        }
        let w1 = unscale(&w1);
        let mut work = Work::default();
        if b.booked.is_some() {
            let forms = self.power_forms(fr, b);
            for i in 0..s {
                let y = unscale(&ys[i]);
                let p = Work::from_fn(self.accounts.len(), |acc| y.dot(&(&forms[acc] * &y)));
                let mut p = p;
                if self.forced {
                    let (z, _) = self.unpack(&y, &[]);
                    p += self.forcing_power(&[&forcings[i]], &z);
                }
                work += p.scaled(h * bw[i]);
            }
        }
        if !w1.iter().all(|v| v.is_finite()) {
            return nan;
        }
        (w1, work)
    }
}
