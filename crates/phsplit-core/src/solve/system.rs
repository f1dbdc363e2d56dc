//! What the solver needs of a model: the traits a model implements, and the ledger's units.
//!
//! The solver defines these and never imports a model; a model (the vessel, or a test's toy
//! system) implements them. A kernel sees a model only through [`SplitModel`] (two flows) or
//! [`FieldModel`] (one vector field), plus the energy and the ledger accounts of [`Model`].

use nalgebra::SVector;

/// Most ledger accounts a model may declare.
pub const MAX_ACCOUNTS: usize = 8;

/// Whether an account books energy that flowed in through a port or energy dissipated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AccountKind {
    /// Work done on the system through a port, `∫ ν·τ dt` (either sign).
    Supplied,
    /// Energy dissipated, `∫ νᵀDν dt` (≥ 0 for a dissipative component).
    Dissipated,
}

/// One account of the energy ledger: the work of one port, or the dissipation of one component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Account {
    /// Name, unique within the model (`"control"`, `"damping"`, `"external"`, …).
    pub name: &'static str,
    pub kind: AccountKind,
}

/// Energy (J) or power (W) booked per account, in the order of [`Model::accounts`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work(pub [f64; MAX_ACCOUNTS]);

impl std::ops::AddAssign for Work {
    fn add_assign(&mut self, o: Self) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
}

impl Work {
    /// `h · self`: a power held over `h`.
    pub fn scaled(mut self, h: f64) -> Self {
        self.0.iter_mut().for_each(|v| *v *= h);
        self
    }
    /// The total of the accounts of `kind`.
    pub fn total(&self, accounts: &[Account], kind: AccountKind) -> f64 {
        accounts
            .iter()
            .zip(self.0)
            .filter(|(a, _)| a.kind == kind)
            .map(|(_, v)| v)
            .sum()
    }
}

/// What every kernel needs of a model.
pub trait Model {
    type State: Copy;
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
    /// The ledger's accounts (at most [`MAX_ACCOUNTS`]); [`Work`] values follow this order.
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
    /// Names of quantities whose running maxima over every step the kernels keep (at most
    /// [`MAX_ACCOUNTS`]; none by default): peaks that saving every k-th state would miss.
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
