//! What the solver needs of a model: the traits a model implements, and the ledger's units.
//!
//! The solver defines these and never imports a model; a model (the vessel, or a test's toy
//! system) implements them. A kernel sees a model only through [`SplitModel`] (two flows) or
//! [`FieldModel`] (one vector field), plus the energy and the ledger accounts of [`Model`].

use nalgebra::SVector;

/// Whether an account books energy that flowed in through a port or energy dissipated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AccountKind {
    /// Work done on the system through a port, `∫ ν·τ dt` (either sign).
    Supplied,
    /// Energy dissipated, `∫ νᵀDν dt` (≥ 0 for a dissipative component).
    Dissipated,
}

/// What an account's port is to the system, beyond its kind: the results and the probe group
/// accounts by it (the controller's force is the sum of its accounts), so no front end keeps a
/// list of names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Role {
    /// A load, a port to another system, or a dissipation of the model itself.
    #[default]
    Plant,
    /// A part of the controller's force (its P, I and D parts, or what its actuators deliver).
    Control,
}

/// One account of the energy ledger: the work of one port, or the dissipation of one component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Account {
    /// Name, unique within the model (`"control"`, `"damping"`, `"external"`, …).
    pub name: &'static str,
    pub kind: AccountKind,
    pub role: Role,
}

impl Account {
    /// The work of a port of the plant (a load, or a port to another system).
    pub const fn supplied(name: &'static str) -> Self {
        Self {
            name,
            kind: AccountKind::Supplied,
            role: Role::Plant,
        }
    }
    /// A dissipation of the plant.
    pub const fn dissipated(name: &'static str) -> Self {
        Self {
            name,
            kind: AccountKind::Dissipated,
            role: Role::Plant,
        }
    }
    /// The same account as a part of the controller's force.
    pub const fn control(self) -> Self {
        Self {
            role: Role::Control,
            ..self
        }
    }
}

/// Accounts whose values are kept inline, in a fixed array (the usual handful: the paper's
/// vessel has three, the OSV in a full sea nine); the values of any further accounts are kept
/// on the heap, so there is no ceiling on how many a model declares, and a model within the
/// inline ones pays for none.
pub const INLINE_ACCOUNTS: usize = 8;

/// Energy (J) or power (W) booked per account, in the order of [`Model::accounts`]; an account
/// never booked holds zero, so `Work::default()` is zero for every model.
#[derive(Debug, Clone, Default)]
pub struct Work {
    inline: [f64; INLINE_ACCOUNTS],
    /// Accounts `INLINE_ACCOUNTS..`, as far as any was booked.
    spill: Vec<f64>,
}

impl PartialEq for Work {
    /// Equal values per account.
    fn eq(&self, o: &Self) -> bool {
        let n = self.spill.len().max(o.spill.len());
        self.inline == o.inline
            && (0..n).all(|k| self.spill.get(k).unwrap_or(&0.0) == o.spill.get(k).unwrap_or(&0.0))
    }
}

impl std::ops::AddAssign<&Work> for Work {
    #[inline]
    fn add_assign(&mut self, o: &Work) {
        for (a, b) in self.inline.iter_mut().zip(&o.inline) {
            *a += b;
        }
        if !o.spill.is_empty() {
            self.add_spill(&o.spill);
        }
    }
}

impl std::ops::AddAssign for Work {
    #[inline]
    fn add_assign(&mut self, o: Self) {
        *self += &o;
    }
}

impl Work {
    /// `f(k)` for each of `n` accounts.
    #[inline]
    pub fn from_fn(n: usize, mut f: impl FnMut(usize) -> f64) -> Self {
        let mut w = Self::default();
        for k in 0..n {
            w.set(k, f(k));
        }
        w
    }
    /// The value of account `k`.
    #[inline]
    pub fn get(&self, k: usize) -> f64 {
        match self.inline.get(k) {
            Some(v) => *v,
            None => self.spill.get(k - INLINE_ACCOUNTS).copied().unwrap_or(0.0),
        }
    }
    /// Add `v` to account `k`.
    #[inline]
    pub fn add(&mut self, k: usize, v: f64) {
        *self.slot(k) += v;
    }
    /// Set account `k` to `v`.
    #[inline]
    pub fn set(&mut self, k: usize, v: f64) {
        *self.slot(k) = v;
    }
    #[inline]
    fn slot(&mut self, k: usize) -> &mut f64 {
        if k < INLINE_ACCOUNTS {
            &mut self.inline[k]
        } else {
            self.spilled(k - INLINE_ACCOUNTS)
        }
    }
    #[cold]
    fn spilled(&mut self, j: usize) -> &mut f64 {
        if j >= self.spill.len() {
            self.spill.resize(j + 1, 0.0);
        }
        &mut self.spill[j]
    }
    #[cold]
    fn add_spill(&mut self, o: &[f64]) {
        if self.spill.len() < o.len() {
            self.spill.resize(o.len(), 0.0);
        }
        for (a, b) in self.spill.iter_mut().zip(o) {
            *a += b;
        }
    }
    /// The values of the accounts kept (the inline ones and any booked beyond them).
    pub fn iter(&self) -> impl Iterator<Item = f64> + '_ {
        self.inline.iter().chain(&self.spill).copied()
    }
    /// The values of the first `n` accounts.
    pub fn values(&self, n: usize) -> Vec<f64> {
        (0..n).map(|k| self.get(k)).collect()
    }
    /// `h · self`: a power held over `h`.
    #[inline]
    pub fn scaled(mut self, h: f64) -> Self {
        self.inline.iter_mut().for_each(|v| *v *= h);
        self.spill.iter_mut().for_each(|v| *v *= h);
        self
    }
    /// The total of the accounts of `kind`.
    pub fn total(&self, accounts: &[Account], kind: AccountKind) -> f64 {
        accounts
            .iter()
            .enumerate()
            .filter(|(_, a)| a.kind == kind)
            .map(|(k, _)| self.get(k))
            .sum()
    }
}

/// What every kernel needs of a model.
pub trait Model {
    type State: Clone;
    /// Stored energy (the Hamiltonian).
    fn energy(&self, s: &Self::State) -> f64;
    /// Whether the state is usable (finite).
    fn is_finite(&self, s: &Self::State) -> bool;
    /// Why the last step made the state non-finite, when a sub-flow knows (it gave up rather
    /// than return an unconverged result): said with the run's failure.
    fn failure_reason(&self) -> Option<String> {
        None
    }
    /// Whether the model's field is the same on steps starting at `t_a` and `t_b` (no switch
    /// between them): sub-steps of the same flow may then be merged across the boundary.
    fn same_field(&self, t_a: f64, t_b: f64) -> bool;
    /// The ledger's accounts, as many as the model has; [`Work`] values follow this order.
    fn accounts(&self) -> &[Account];
    /// Whether the kernels call [`Model::project`] after every step. Sub-steps are then not
    /// merged across step boundaries (the state must exist there to be projected).
    fn projects(&self) -> bool {
        false
    }
    /// Project `s`, after a step, onto an invariant manifold of the model's exact flow that the
    /// method does not keep (standard projection, Hairer–Lubich–Wanner, *Geometric Numerical
    /// Integration*, §IV.4: it keeps the method's order). Returns the energy the projection
    /// adds, per account; a projection that leaves the energy unchanged returns zero.
    fn project(&self, _s: &mut Self::State) -> Work {
        Work::default()
    }
    /// Whether Runge–Kutta methods need the projection too. A Runge–Kutta method keeps every
    /// linear invariant of the field to round-off, so a model whose projected invariants are
    /// linear in the state says `false` here and its Runge–Kutta runs skip the projection.
    fn projects_runge_kutta(&self) -> bool {
        true
    }
    /// Names of quantities whose running maxima over every step the kernels keep (none by
    /// default): peaks that saving every k-th state would miss.
    fn probe_names(&self) -> &[&'static str] {
        &[]
    }
    /// The probed quantities at `s`, with the field of a step that starts at `t`.
    fn probe(&self, _t: f64, _s: &Self::State, _out: &mut [f64]) {}
    /// Prepare the state of a run that starts at `t0`: a memory the model keeps in its state
    /// beside what the flows integrate (rate-limited actuators), started if it is not set.
    /// Nothing by default.
    fn begin(&self, _t0: f64, _s: &mut Self::State) {}
    /// After every step (which started at `t_step`), on the step boundary `t1` (after the
    /// projection): update that memory. A model that keeps one must not let sub-steps merge
    /// across step boundaries ([`SplitModel::merges_exactly`]). Nothing by default.
    fn end_step(&self, _t_step: f64, _t1: f64, _s: &mut Self::State) {}
    /// For adaptive steps: the root mean square of the components of the difference `a − b`,
    /// each divided by `atol + rtol·max(|c_i|, |a_i|)`, with the components and their units the
    /// model chooses (`c` the state the step started from). `None`: the model has no such norm.
    fn error_norm(
        &self,
        _a: &Self::State,
        _b: &Self::State,
        _c: &Self::State,
        _rtol: f64,
        _atol: f64,
    ) -> Option<f64> {
        None
    }
    /// The first time after `t` at which the field switches (see [`Model::same_field`]), if
    /// the model knows it: adaptive steps land on it.
    fn next_switch(&self, _t: f64) -> Option<f64> {
        None
    }
    /// Why Runge–Kutta methods cannot integrate this model, if they cannot (a memory their
    /// kernel does not carry).
    fn runge_kutta_refused(&self) -> Option<String> {
        None
    }
}

/// Which of the two flows of a split model a sub-step belongs to.
pub use crate::methods::Flow;

/// A model split into a conservative flow S1 and a dissipative flow S2, each with a flow map.
pub trait SplitModel: Model {
    /// Whether two consecutive sub-steps of `flow` equal one sub-step of their summed length
    /// (an exact flow; a collocation is not): only then may the kernel merge the last sub-step
    /// of a step with the first of the next, so that what a run computes does not depend on
    /// which states it saves.
    fn merges_exactly(&self, _flow: Flow) -> bool {
        true
    }

    /// Check that the model can provide sub-flows of order `order` (paper Remark 2.3); the
    /// kernel asks this once, before the first step.
    fn supports_order(&self, order: usize) -> crate::Result<()>;

    /// Told once, before the first step, whether the run will ask for sub-steps from states it
    /// has asked for before (adaptive steps: the whole step after its halves, an output's
    /// branch from a step's start). A model that keeps what it computed at a state may keep
    /// more for such a run; what it computes must not change. Nothing by default.
    fn revisits_states(&self, _revisits: bool) {}
    /// Advance `s` by flow `which` over `h` (of either sign) on a step that starts at `t_step`
    /// (which decides switches, like the controller's start); the sub-step itself starts at
    /// time `t` (the flow's own clock: a time-dependent flow is evaluated from `t` to `t + h`).
    /// `order` is the order of the composition, for flows that are approximated to match.
    /// Returns the energy booked per account over the sub-step when `ledger` is set.
    #[allow(clippy::too_many_arguments)]
    fn flow(
        &self,
        which: Flow,
        h: f64,
        t_step: f64,
        t: f64,
        order: usize,
        ledger: bool,
        s: &mut Self::State,
    ) -> Work;
}

/// A model given by one vector field on `R^N`.
pub trait FieldModel<const N: usize>: Model {
    fn to_vector(&self, s: &Self::State) -> SVector<f64, N>;
    fn from_vector(&self, y: &SVector<f64, N>) -> Self::State;
    /// `y'` at time `t` on a step that starts at `t_step` (which decides switches).
    fn rhs(&self, t_step: f64, t: f64, y: &SVector<f64, N>) -> SVector<f64, N>;
    /// The power per account at `y` and time `t` on a step that starts at `t_step`.
    fn power(&self, t_step: f64, t: f64, y: &SVector<f64, N>) -> Work;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Accounts beyond the inline ones: booked, summed and compared like the first ones, and
    /// an account never booked reads zero.
    #[test]
    fn work_has_no_ceiling_on_its_accounts() {
        let n = 3 * INLINE_ACCOUNTS + 1;
        let accounts: Vec<Account> = (0..n)
            .map(|k| {
                if k % 3 == 0 {
                    Account::dissipated("d")
                } else {
                    Account::supplied("s")
                }
            })
            .collect();
        let mut w = Work::default();
        for k in 0..n {
            w.add(k, k as f64);
        }
        let mut v = Work::default();
        v += &w;
        v += w.clone().scaled(2.0);
        for k in 0..n {
            assert_eq!(v.get(k), 3.0 * k as f64);
        }
        assert_eq!(v.get(n + 5), 0.0);
        let dissipated: f64 = (0..n).filter(|k| k % 3 == 0).map(|k| 3.0 * k as f64).sum();
        let supplied: f64 = (0..n).filter(|k| k % 3 != 0).map(|k| 3.0 * k as f64).sum();
        assert_eq!(v.total(&accounts, AccountKind::Dissipated), dissipated);
        assert_eq!(v.total(&accounts, AccountKind::Supplied), supplied);
        // Zero accounts past the stored ones do not make two values differ.
        let mut padded = v.clone();
        padded.set(n + 9, 0.0);
        assert_eq!(padded, v);
        padded.set(n + 9, 1.0);
        assert_ne!(padded, v);
        assert_eq!(v.values(n + 1)[n], 0.0);
    }
}
