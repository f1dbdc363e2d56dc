//! Flow S2 with the components' own states (a linear port-Hamiltonian subsystem's; forces/
//! port_hamiltonian.rs): one dense linear system `w' = A w (+ forcing)` on
//! `w = (z̄₁…₁₈, x, 1)`, the body's two block systems (`z̄` as in `s2/coupled.rs`), the own
//! states `x` ([`VesselState::own`]) and the constant. The own states' rows and their force on
//! the momenta are the components' [`OwnLinear`], with `ν = M⁻¹u` through the full `M⁻¹`.
//!
//! The exact flow is the matrix exponential (nalgebra's Padé scaling and squaring, Higham,
//! SIAM J. Matrix Anal. Appl. 26 (2005) 1179–1193) of the balanced system, and the ledger the
//! Gramian `∫ w wᵀ dt` over the sub-step by Van Loan's block exponential (C. F. Van Loan, IEEE
//! Trans. Autom. Control 23 (1978) 395–404): every account's energy is a quadratic form in
//! `w`, so its integral is exact along the flow. Gauss collocation (with a forcing part,
//! iterated to a fixed point; or with [`LinearFlow::Gauss`](super::LinearFlow::Gauss)) solves the dense stage system
//! once per sub-step and books each account's power at the stages with the Gauss weights,
//! exact for the collocation polynomial of a quadratic storage (Hairer, Lubich, Wanner,
//! *Geometric Numerical Integration*, §IV.2). Both are energy-dissipative for a dissipative S2,
//! so the composition keeps the paper's Prop. 2.2 (and Remark 2.3 for the collocation).

use super::super::forces::{Frozen, OwnLinear, S2Builder};
use super::super::state::VesselState;
use super::s2::augmented;
use super::{GaveUp, VesselSystem};
use crate::flows::collocation::Z3;
use crate::solve::Work;
use nalgebra::{DMatrix, DVector, Vector3};
use std::borrow::Cow;
type Span = std::ops::Range<usize>;

mod collocation;

/// The momentum entries `u_t`, `u_r` of `w` (as of `z̄`).
const MOMENTA: [usize; 6] = [0, 1, 2, 9, 10, 11];

/// Most fixed-point passes over the forcing in one sub-step.
const MAX_PASSES: usize = 200;

/// Each component of `vessel` whose own states evolve linearly in flow S2 ([`OwnLinear`]): its
/// index among the components, its range in [`VesselState::own`], and where its columns start
/// in the dense system's `w` (after the 18 block states; the states of components with a flow
/// of their own are not in it: flow S2 leaves them alone).
pub(super) fn parts_of(vessel: &super::Vessel) -> Vec<(usize, std::ops::Range<usize>, usize)> {
    let mut off = 0;
    let mut col = 18;
    let mut parts = Vec::new();
    for (i, f) in vessel.forces.iter().enumerate() {
        let n = f.own_states().len();
        if n > 0 && f.own_linear().is_some() {
            parts.push((i, off..off + n, col));
            col += n;
        }
        off += n;
    }
    parts
}

/// Each component with a flow of its own ([`super::super::forces::Force::own_flow`]): its index
/// among the components and its range in [`VesselState::own`].
pub(super) fn flowing_of(vessel: &super::Vessel) -> Vec<(usize, std::ops::Range<usize>)> {
    let mut off = 0;
    let mut parts = Vec::new();
    for (i, f) in vessel.forces.iter().enumerate() {
        let n = f.own_states().len();
        if n > 0 && f.has_own_flow() {
            parts.push((i, off..off + n));
        }
        off += n;
    }
    parts
}

/// A linear own-state component in flow S2: its account, rows, columns in `w`, range in `own`.
pub(super) struct LinearPart<'a> {
    pub account: usize,
    pub rows: Cow<'a, OwnLinear>,
    pub cols: std::ops::Range<usize>,
    pub own: std::ops::Range<usize>,
}

impl<'a> VesselSystem<'a> {
    /// The components whose own states are linear in flow S2 (the layout found once, in
    /// [`VesselSystem::new`]), with their rows at the frozen view `fr`.
    fn own_parts<'s>(&'s self, fr: &'s Frozen) -> impl Iterator<Item = LinearPart<'a>> + 's {
        self.own_parts.iter().filter_map(move |(i, r, col)| {
            let f = &self.vessel.forces[*i];
            let l = match f.own_linear_at(fr) {
                Some(l) => Cow::Owned(l),
                None => Cow::Borrowed(f.own_linear()?),
            };
            Some(LinearPart {
                account: self.bases[*i] + l.account,
                rows: l,
                cols: *col..*col + r.len(),
                own: r.clone(),
            })
        })
    }

    /// The components' own flows over `h` at the attitude of `s` (each advancing its own
    /// states and the body's momenta), with their accounts' energy.
    pub(super) fn own_flows(&self, s: &mut VesselState, h: f64, on: bool) -> Work {
        let mut work = Work::default();
        if h == 0.0 {
            return work;
        }
        let fr = self.frozen(s, on);
        let mut u = [s.p, s.m];
        for (i, r) in &self.own_flowing {
            let f = &self.vessel.forces[*i];
            let mut booked = vec![0.0; f.accounts().len()];
            let mut x = s.own[r.clone()].to_vec();
            if !f.own_flow(&fr, s, h, &mut x, &mut u, &mut booked) {
                self.give_up(GaveUp::OwnFlow);
                s.p = Vector3::from_element(f64::NAN);
                return work;
            }
            s.own[r.clone()].copy_from_slice(&x);
            for (k, e) in booked.into_iter().enumerate() {
                work.add(self.bases[*i] + k, e);
            }
        }
        s.p = u[0];
        s.m = u[1];
        work
    }

    /// The rates of the own states of the components with a flow of their own, added to
    /// `rates` (indexed as [`VesselState::own`]), and their force on the hull, at `s`.
    pub(super) fn own_flow_field(
        &self,
        fr: &Frozen,
        s: &VesselState,
        rates: &mut [f64],
    ) -> Vec<(usize, [Vector3<f64>; 2])> {
        let nu = self.vessel.body.velocity(&s.p, &s.m);
        self.own_flowing
            .iter()
            .map(|(i, r)| {
                let f = &self.vessel.forces[*i];
                let tau = f.own_rates(fr, &s.own[r.clone()], &nu, &mut rates[r.clone()]);
                let acc = self.bases[*i] + f.own_hull_account().unwrap_or(0);
                (acc, tau)
            })
            .collect()
    }
}

impl VesselSystem<'_> {
    /// Flow S2 over `h` from time `t` for a vessel whose components keep states of their own:
    /// the body's block states and the own states together (module documentation).
    pub(super) fn flow_s2_own(
        &self,
        s: &mut VesselState,
        h: f64,
        t: f64,
        on: bool,
        ledger: bool,
        stages: usize,
    ) -> Work {
        let z0 = self.blocks_of(s);
        let w0 = self.pack(&z0, &s.own);
        let (w1, work) = self.with_s2(s, on, ledger, false, |fr, b| {
            let a = self.dense(fr, b);
            if self.forced || self.linear.is_gauss() {
                self.dense_collocation(fr, b, &a, &w0, h, t, stages)
            } else {
                self.dense_exact(fr, b, &a, &w0, h)
            }
        });
        let (z1, x1) = self.unpack(&w1, &s.own);
        self.set_blocks(s, &z1);
        s.own = x1;
        work
    }

    /// Each linear own-state component's columns in `w` and its range in [`VesselState::own`].
    fn own_columns(&self) -> impl Iterator<Item = (Span, Span)> + '_ {
        let span = |(_, r, col): &(usize, Span, usize)| (*col..*col + r.len(), r.clone());
        self.own_parts.iter().map(span)
    }

    fn dim(&self) -> usize {
        19 + self.own_linear_dim
    }

    fn pack(&self, z: &[Z3; 2], x: &[f64]) -> DVector<f64> {
        let mut w = DVector::zeros(self.dim());
        for k in 0..2 {
            for i in 0..3 {
                w.rows_mut(9 * k + 3 * i, 3).copy_from(&z[k][i]);
            }
        }
        for (cols, own) in self.own_columns() {
            w.rows_mut(cols.start, cols.len()).copy_from_slice(&x[own]);
        }
        w[self.dim() - 1] = 1.0;
        w
    }

    /// The block states of `w`, and the own states: those of `x` with the linear ones from `w`.
    fn unpack(&self, w: &DVector<f64>, x: &[f64]) -> ([Z3; 2], Vec<f64>) {
        let z = std::array::from_fn(|k| {
            std::array::from_fn(|i| Vector3::from_column_slice(&w.as_slice()[9 * k + 3 * i..][..3]))
        });
        let mut own = x.to_vec();
        if !own.is_empty() {
            for (cols, own_range) in self.own_columns() {
                own[own_range].copy_from_slice(&w.as_slice()[cols]);
            }
        }
        (z, own)
    }

    /// `ν = E w` (6 × N), through the full `M⁻¹`.
    fn velocity_map(&self) -> DMatrix<f64> {
        let mi = &self.vessel.body.minv_blocks;
        let mut e = DMatrix::zeros(6, self.dim());
        for j in 0..2 {
            for l in 0..2 {
                for r in 0..3 {
                    for c in 0..3 {
                        e[(3 * j + r, 9 * l + c)] = mi[j][l][(r, c)];
                    }
                }
            }
        }
        e
    }

    /// The own states' rates and their generalised force on the hull (body frame) at the block
    /// states `z` and own states `x` (flow S2's field, eq. 41, for them).
    pub(super) fn own_field(
        &self,
        fr: &Frozen,
        z: &[Z3; 2],
        x: &[f64],
    ) -> (Vec<f64>, [Vector3<f64>; 2]) {
        let nu = self.vessel.body.velocity(&z[0][0], &z[1][0]);
        let nu = DVector::from_iterator(6, nu[0].iter().chain(nu[1].iter()).cloned());
        let v = DVector::from_column_slice(z[0][1].as_slice());
        let mut rates = vec![0.0; x.len()];
        let mut tau = DVector::<f64>::zeros(6);
        for p in self.own_parts(fr) {
            let l = &p.rows;
            let xi = DVector::from_column_slice(&x[p.own.clone()]);
            let d = &l.axx * &xi + &l.axnu * &nu + &l.axv * &v + &l.axc;
            rates[p.own].copy_from_slice(d.as_slice());
            tau += &l.fx * &xi + &l.fnu * &nu + &l.fc;
        }
        (
            rates,
            [
                Vector3::new(tau[0], tau[1], tau[2]),
                Vector3::new(tau[3], tau[4], tau[5]),
            ],
        )
    }

    /// Each own-state component's account with its force and moment on the hull (body frame).
    pub(super) fn own_wrenches(
        &self,
        fr: &Frozen,
        z: &[Z3; 2],
        x: &[f64],
    ) -> Vec<(usize, [Vector3<f64>; 2])> {
        let nu = self.vessel.body.velocity(&z[0][0], &z[1][0]);
        let nu = DVector::from_iterator(6, nu[0].iter().chain(nu[1].iter()).cloned());
        self.own_parts(fr)
            .map(|p| {
                let l = &p.rows;
                let xi = DVector::from_column_slice(&x[p.own]);
                let tau = &l.fx * &xi + &l.fnu * &nu + &l.fc;
                (
                    p.account,
                    [
                        Vector3::new(tau[0], tau[1], tau[2]),
                        Vector3::new(tau[3], tau[4], tau[5]),
                    ],
                )
            })
            .collect()
    }

    /// The dense matrix `A` of flow S2 with the own states.
    fn dense(&self, fr: &Frozen, b: &S2Builder) -> DMatrix<f64> {
        let n = self.dim();
        let c = n - 1;
        let full = augmented(b);
        let mut a = DMatrix::zeros(n, n);
        for i in 0..18 {
            for j in 0..18 {
                a[(i, j)] = full[(i, j)];
            }
            a[(i, c)] = full[(i, 18)];
        }
        let e = self.velocity_map();
        for p in self.own_parts(fr) {
            let (l, r) = (&p.rows, p.cols);
            let m = r.len();
            let mut rows = a.view_mut((r.start, r.start), (m, m));
            rows += &l.axx;
            // The rates on the position v = x − x_o (w's entries 3..6) and the constant.
            for i in 0..m {
                for j in 0..3 {
                    a[(r.start + i, 3 + j)] += l.axv[(i, j)];
                }
                a[(r.start + i, c)] += l.axc[i];
            }
            for (i, &mi) in MOMENTA.iter().enumerate() {
                a[(mi, c)] += l.fc[i];
            }
            let xnu = &l.axnu * &e;
            let mut rows = a.rows_mut(r.start, m);
            rows += &xnu;
            let fnu = &l.fnu * &e;
            for (i, &mi) in MOMENTA.iter().enumerate() {
                for j in 0..m {
                    a[(mi, r.start + j)] += l.fx[(i, j)];
                }
                for j in 0..n {
                    a[(mi, j)] += fnu[(i, j)];
                }
            }
        }
        a
    }

    /// Each account's power as a quadratic form `wᵀ W w` (one `W` per account, not symmetric).
    fn power_forms(&self, fr: &Frozen, b: &S2Builder) -> Vec<DMatrix<f64>> {
        let n = self.dim();
        let c = n - 1;
        let col = |j: usize| if j == 18 { c } else { j };
        let mut out = vec![DMatrix::zeros(n, n); self.accounts.len()];
        if let Some(booked) = &b.booked {
            for (acc, w) in out.iter_mut().enumerate() {
                let r = self.power_rows_full(&booked[acc], acc, b);
                let sign = self.sign(acc);
                for i in 0..6 {
                    for j in 0..19 {
                        w[(MOMENTA[i], col(j))] += sign * r[(i, j)];
                    }
                }
            }
        }
        let e = self.velocity_map();
        for p in self.own_parts(fr) {
            let (acc, l, r) = (p.account, &p.rows, p.cols);
            // [x; ν] = T w; the dissipation is booked as a positive number.
            let m = r.len();
            let mut t = DMatrix::zeros(m + 6, n);
            for i in 0..m {
                t[(i, r.start + i)] = 1.0;
            }
            t.rows_mut(m, 6).copy_from(&e);
            out[acc] += t.transpose() * &l.diss * &t;
            if l.port {
                // A port's power ν·τ, τ = F w (F: fx on the own states, fnu ν, fc on the
                // constant).
                let mut f = &l.fnu * &e;
                for i in 0..6 {
                    for j in 0..m {
                        f[(i, r.start + j)] += l.fx[(i, j)];
                    }
                    f[(i, c)] += l.fc[i];
                }
                out[acc] += (e.transpose() * f) * self.sign(acc);
            }
        }
        out
    }

    /// The balancing `w = S w̃`: the block systems' structural one, then Osborne's iteration
    /// by powers of two (exact in floating point), as for the coupled system.
    fn dense_balance(&self, b: &S2Builder, a: &DMatrix<f64>) -> DVector<f64> {
        let n = self.dim();
        let md = self.vessel.body.mass_matrix.diagonal();
        let mut sc = DVector::from_element(n, 1.0);
        for k in 0..2 {
            let minv = Vector3::from_fn(|i, _| 1.0 / md[3 * k + i]);
            let sk = super::s2::balance(&b.sys[k], &minv);
            for i in 0..9 {
                sc[9 * k + i] = sk[i];
            }
        }
        let mut m = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * sc[j] / sc[i]);
        for _ in 0..20 {
            let mut done = true;
            for i in 0..n - 1 {
                let (mut r, mut col) = (0.0, 0.0);
                for j in 0..n {
                    if j != i {
                        r += m[(i, j)].abs();
                        col += m[(j, i)].abs();
                    }
                }
                if r == 0.0 || col == 0.0 {
                    continue;
                }
                let f = crate::flows::affine::nearest_power_of_two((r / col).sqrt());
                if f != 1.0 && (col * f + r / f) < 0.95 * (col + r) {
                    done = false;
                    sc[i] *= f;
                    for j in 0..n {
                        m[(i, j)] /= f;
                        m[(j, i)] *= f;
                    }
                }
            }
            if done {
                break;
            }
        }
        sc
    }

    /// The dense matrix of `b` balanced, `S⁻¹ A S`, with the balance `S`.
    pub(super) fn dense_balanced(
        &self,
        fr: &Frozen,
        b: &S2Builder,
    ) -> (DMatrix<f64>, DVector<f64>) {
        let a = self.dense(fr, b);
        let sc = self.dense_balance(b, &a);
        let n = a.nrows();
        (DMatrix::from_fn(n, n, |i, j| a[(i, j)] * sc[j] / sc[i]), sc)
    }

    /// The exact flow and, with the ledger, each account's energy from the Gramian.
    fn dense_exact(
        &self,
        fr: &Frozen,
        b: &S2Builder,
        a: &DMatrix<f64>,
        w0: &DVector<f64>,
        h: f64,
    ) -> (DVector<f64>, Work) {
        let n = self.dim();
        let sc = self.dense_balance(b, a);
        let ab = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * sc[j] / sc[i]);
        let wb = w0.component_div(&sc);
        if b.booked.is_none() {
            let e = (&ab * h).exp();
            return ((e * wb).component_mul(&sc), Work::default());
        }
        // Van Loan on a piece τ = h/2^k short enough that e^{−Ãτ} stays bounded (a stiff
        // subsystem would overflow it over the whole h): exp([[−Ã, w̃w̃ᵀ], [0, Ãᵀ]] τ) =
        // [[·, F12], [0, F22]], F22 = e^{Ãᵀτ}, X(τ) = ∫₀^τ e^{Ãs} w̃w̃ᵀ e^{Ãᵀs} ds = F22ᵀ F12; then
        // doubled, X(2τ) = X(τ) + e^{Ãτ} X(τ) e^{Ãᵀτ}, which only ever multiplies by the flow.
        let norm = (0..n)
            .map(|j| ab.column(j).iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
            * h.abs();
        let k = if norm > 1.0 {
            norm.log2().ceil() as i32
        } else {
            0
        };
        let tau = h / 2f64.powi(k);
        let mut big = DMatrix::zeros(2 * n, 2 * n);
        big.view_mut((0, 0), (n, n)).copy_from(&(-&ab * tau));
        big.view_mut((0, n), (n, n))
            .copy_from(&(&wb * wb.transpose() * tau));
        big.view_mut((n, n), (n, n))
            .copy_from(&(ab.transpose() * tau));
        let f = big.exp();
        let mut e = f.view((n, n), (n, n)).transpose();
        let mut gram = &e * f.view((0, n), (n, n));
        for _ in 0..k {
            gram = &gram + &e * &gram * e.transpose();
            e = &e * &e;
        }
        let w1 = (&e * &wb).component_mul(&sc);
        let forms = self.power_forms(fr, b);
        let work = Work::from_fn(self.accounts.len(), |acc| {
            let w = &forms[acc];
            let mut e = 0.0;
            for i in 0..n {
                for j in 0..n {
                    if w[(i, j)] != 0.0 {
                        e += w[(i, j)] * gram[(i, j)] * sc[i] * sc[j];
                    }
                }
            }
            e
        });
        (w1, work)
    }
}
