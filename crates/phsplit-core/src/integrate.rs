//! The integration kernels: one for every composition method, one for every Butcher tableau.
//!
//! A model never integrates itself and a kernel never knows it is a ship: kernels see a model
//! only through [`SplitModel`] (two flows) or [`FieldModel`] (one vector field), plus the
//! energy and the power of [`Model`] for the ledger.
//!
//! **Time dependence.** The only explicit time dependence the models have is a switch (the
//! controller turned on at a time). Kernels pass each flow and each stage the *start time of its
//! step*, so a switch acts at the first step boundary at or after its time and every step
//! integrates one autonomous field.
//!
//! **Ledger.** For every saved interval: the change of stored energy `ΔH`, the energy supplied
//! through the port and the energy dissipated. Splitting methods compute the last two exactly
//! along their sub-flows (the conservative flow supplies and dissipates nothing), so
//! `ΔH = supplied − dissipated` holds to round-off for positive-step methods (paper Prop. 2.2).
//! Runge–Kutta methods get the method's own quadrature of the power, `h Σ bᵢ P(Yᵢ)`, and the
//! residual shows the energy they create or destroy.

use crate::error::{Error, Result};
use crate::methods::{ButcherTableau, Composition, Flow, Method, Outer};
use nalgebra::SVector;

/// Energy supplied through the port and dissipated, over some interval (J), or as rates (W).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Work {
    pub supplied: f64,
    pub dissipated: f64,
}

impl std::ops::AddAssign for Work {
    fn add_assign(&mut self, o: Self) {
        self.supplied += o.supplied;
        self.dissipated += o.dissipated;
    }
}

/// What every kernel needs of a model.
pub trait Model {
    type State: Copy;
    /// Stored energy (the Hamiltonian).
    fn energy(&self, s: &Self::State) -> f64;
    /// Whether the state is usable (finite).
    fn is_finite(&self, s: &Self::State) -> bool;
    /// Whether the model's field is the same on steps starting at `t_a` and `t_b` (no switch
    /// between them): sub-steps of the same flow may then be merged across the boundary.
    fn same_field(&self, t_a: f64, t_b: f64) -> bool;
}

/// A model split into a conservative flow S1 and a dissipative flow S2, each with a flow map.
pub trait SplitModel: Model {
    /// Advance `s` by flow `which` over `h` (of either sign) on a step that starts at `t_step`.
    /// `order` is the order of the composition, for flows that are approximated to match.
    /// Returns the supplied and dissipated energy over the sub-step when `ledger` is set.
    fn flow(
        &self,
        which: Flow,
        h: f64,
        t_step: f64,
        order: usize,
        ledger: bool,
        s: &mut Self::State,
    ) -> Work;
}

/// A model given by one vector field on `R^N`.
pub trait FieldModel<const N: usize>: Model {
    fn to_vector(&self, s: &Self::State) -> SVector<f64, N>;
    fn from_vector(&self, y: &SVector<f64, N>) -> Self::State;
    /// `y'` on a step that starts at `t_step`.
    fn rhs(&self, t_step: f64, y: &SVector<f64, N>) -> SVector<f64, N>;
    /// Supplied and dissipated power at `y` on a step that starts at `t_step`.
    fn power(&self, t_step: f64, y: &SVector<f64, N>) -> Work;
}

/// Options common to the kernels.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Start time.
    pub t0: f64,
    /// Step size (> 0).
    pub h: f64,
    /// Number of steps.
    pub n_steps: usize,
    /// Save every k-th step (the last step is always saved).
    pub save_every: usize,
    /// Which flow is outermost in a composition.
    pub outer: Outer,
    /// Compute the energy ledger.
    pub ledger: bool,
}

/// Upper bound on the number of steps of one run.
pub const MAX_STEPS: usize = 2_000_000_000;

impl Options {
    /// Check the options; the message names the field and the allowed range.
    pub fn validate(&self) -> Result<()> {
        if !self.t0.is_finite() {
            return Err(Error::InvalidInput(format!(
                "t0 must be finite (s), got {}",
                self.t0
            )));
        }
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(Error::InvalidInput(format!(
                "h must be finite and > 0 (s), got {}",
                self.h
            )));
        }
        if self.n_steps == 0 || self.n_steps > MAX_STEPS {
            return Err(Error::InvalidInput(format!(
                "the number of steps must be between 1 and {MAX_STEPS}, got {}",
                self.n_steps
            )));
        }
        if self.save_every == 0 {
            return Err(Error::InvalidInput("save_every must be ≥ 1, got 0".into()));
        }
        Ok(())
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Completed,
    /// The state became non-finite during step `step` (starting at `t`); the trajectory holds
    /// everything saved before, and the last good state.
    Failed {
        step: usize,
        t: f64,
        reason: String,
    },
}

/// Saved states and the ledger of a run.
#[derive(Debug, Clone)]
pub struct Trajectory<S> {
    /// Saved times.
    pub t: Vec<f64>,
    /// Saved states.
    pub states: Vec<S>,
    /// `H` at the saved states.
    pub energy: Vec<f64>,
    /// Energy supplied through the port since the previous saved state (0 for the first).
    pub supplied: Vec<f64>,
    /// Energy dissipated since the previous saved state (0 for the first).
    pub dissipated: Vec<f64>,
    /// Steps taken.
    pub steps: usize,
    pub status: Status,
    /// The last finite state reached (the final state of a completed run).
    pub last_good: S,
    /// Time of `last_good`.
    pub t_last_good: f64,
}

struct Recorder<'m, M: Model> {
    model: &'m M,
    traj: Trajectory<M::State>,
    acc: Work,
}

impl<'m, M: Model> Recorder<'m, M> {
    fn new(model: &'m M, t0: f64, y0: M::State, capacity: usize) -> Self {
        let mut traj = Trajectory {
            t: Vec::with_capacity(capacity),
            states: Vec::with_capacity(capacity),
            energy: Vec::with_capacity(capacity),
            supplied: Vec::with_capacity(capacity),
            dissipated: Vec::with_capacity(capacity),
            steps: 0,
            status: Status::Completed,
            last_good: y0,
            t_last_good: t0,
        };
        traj.t.push(t0);
        traj.states.push(y0);
        traj.energy.push(model.energy(&y0));
        traj.supplied.push(0.0);
        traj.dissipated.push(0.0);
        Self {
            model,
            traj,
            acc: Work::default(),
        }
    }
    /// End the run: the state became non-finite during step `step`, which started at `t`.
    fn fail(mut self, step: usize, t: f64) -> Trajectory<M::State> {
        self.traj.status = Status::Failed {
            step,
            t,
            reason: "the state became non-finite".into(),
        };
        self.traj
    }
    fn save(&mut self, t: f64, y: M::State) {
        self.traj.t.push(t);
        self.traj.states.push(y);
        self.traj.energy.push(self.model.energy(&y));
        self.traj.supplied.push(self.acc.supplied);
        self.traj.dissipated.push(self.acc.dissipated);
        self.acc = Work::default();
    }
}

fn saves_after(step: usize, opts: &Options) -> bool {
    (step + 1) % opts.save_every == 0 || step + 1 == opts.n_steps
}

fn capacity(opts: &Options) -> usize {
    (opts.n_steps / opts.save_every + 2).min(1 << 24)
}

/// Run a composition method (paper format (10); Lie–Trotter) on a split model.
///
/// Adjacent sub-steps of the same flow are merged within a step (done once, in the method
/// table) and across step boundaries that are not saved and where the field does not switch
/// (first same as last).
pub fn run_splitting<M: SplitModel>(
    model: &M,
    method: &Composition,
    y0: M::State,
    opts: &Options,
) -> Result<Trajectory<M::State>> {
    opts.validate()?;
    let (fa, fb) = opts.outer.flows();
    let subs: Vec<(Flow, f64)> = method
        .substeps
        .iter()
        .map(|&(is_a, c)| (if is_a { fa } else { fb }, c))
        .collect();
    let fsal = subs.len() > 1 && subs[0].0 == subs[subs.len() - 1].0;
    let last = subs.len() - 1;
    let mut rec = Recorder::new(model, opts.t0, y0, capacity(opts));
    let mut y = y0;
    // A last sub-step deferred into the next step: (flow, length, its step's start time).
    let mut pending: Option<(Flow, f64, f64)> = None;
    for n in 0..opts.n_steps {
        let t = opts.t0 + n as f64 * opts.h;
        for (i, &(flow, c)) in subs.iter().enumerate() {
            let mut len = c * opts.h;
            if i == 0 {
                if let Some((pf, plen, pt)) = pending.take() {
                    if pf == flow && model.same_field(pt, t) {
                        len += plen;
                    } else {
                        rec.acc += model.flow(pf, plen, pt, method.order, opts.ledger, &mut y);
                    }
                }
            }
            if i == last && fsal && !saves_after(n, opts) && model.same_field(t, t + opts.h) {
                pending = Some((flow, len, t));
                continue;
            }
            rec.acc += model.flow(flow, len, t, method.order, opts.ledger, &mut y);
        }
        if !model.is_finite(&y) {
            return Ok(rec.fail(n, t));
        }
        rec.traj.steps = n + 1;
        if pending.is_none() {
            // y sits on the step boundary (no sub-step deferred into the next step).
            rec.traj.last_good = y;
            rec.traj.t_last_good = t + opts.h;
        }
        if saves_after(n, opts) {
            rec.save(t + opts.h, y);
        }
    }
    Ok(rec.traj)
}

/// Run an explicit Runge–Kutta method on the full vector field.
pub fn run_runge_kutta<const N: usize, M: FieldModel<N>>(
    model: &M,
    tableau: &ButcherTableau,
    y0: M::State,
    opts: &Options,
) -> Result<Trajectory<M::State>> {
    opts.validate()?;
    let s = tableau.stages();
    let mut rec = Recorder::new(model, opts.t0, y0, capacity(opts));
    let mut y = model.to_vector(&y0);
    let mut k: Vec<SVector<f64, N>> = vec![SVector::zeros(); s];
    let h = opts.h;
    for n in 0..opts.n_steps {
        let t = opts.t0 + n as f64 * h;
        let mut work = Work::default();
        for i in 0..s {
            let mut yi = y;
            for (j, aij) in tableau.a[i].iter().enumerate() {
                if *aij != 0.0 {
                    yi.axpy(h * aij, &k[j], 1.0);
                }
            }
            k[i] = model.rhs(t, &yi);
            if opts.ledger {
                let p = model.power(t, &yi);
                work.supplied += h * tableau.b[i] * p.supplied;
                work.dissipated += h * tableau.b[i] * p.dissipated;
            }
        }
        let mut y1 = y;
        for i in 0..s {
            y1.axpy(h * tableau.b[i], &k[i], 1.0);
        }
        // Finiteness is checked on the vector; the state is built only when it is saved, and
        // the last good state at the end (or at a failure: `y` is then the last good one).
        if !y1.as_slice().iter().all(|v| v.is_finite()) {
            rec.traj.last_good = model.from_vector(&y);
            rec.traj.t_last_good = t;
            return Ok(rec.fail(n, t));
        }
        y = y1;
        rec.acc += work;
        rec.traj.steps = n + 1;
        if saves_after(n, opts) {
            rec.save(t + h, model.from_vector(&y));
        }
    }
    if opts.n_steps > 0 {
        rec.traj.last_good = model.from_vector(&y);
        rec.traj.t_last_good = opts.t0 + opts.n_steps as f64 * h;
    }
    Ok(rec.traj)
}

/// Run any method on a model that offers both views.
pub fn run<const N: usize, M: SplitModel + FieldModel<N>>(
    model: &M,
    method: &Method,
    y0: M::State,
    opts: &Options,
) -> Result<Trajectory<M::State>> {
    match method {
        Method::Splitting(c) => run_splitting(model, c, y0, opts),
        Method::RungeKutta(t) => run_runge_kutta(model, t, y0, opts),
    }
}

// ------------------------------------------------------------------------------------------
// The vessel as a model.

use crate::rigid_body::MagnusOrder;
use crate::vessel::{VesselState, VesselSystem, STATE_DIM};

impl Model for VesselSystem<'_> {
    type State = VesselState;
    fn energy(&self, s: &VesselState) -> f64 {
        self.vessel.energy(s)
    }
    fn is_finite(&self, s: &VesselState) -> bool {
        s.is_finite()
    }
    fn same_field(&self, t_a: f64, t_b: f64) -> bool {
        self.control_on(t_a) == self.control_on(t_b)
    }
}

impl SplitModel for VesselSystem<'_> {
    fn flow(
        &self,
        which: Flow,
        h: f64,
        t_step: f64,
        order: usize,
        ledger: bool,
        s: &mut VesselState,
    ) -> Work {
        match which {
            Flow::S1 => {
                self.flow_s1(s, h, MagnusOrder::at_least(order));
                Work::default()
            }
            Flow::S2 => {
                let p = self.flow_s2(s, h, self.control_on(t_step), ledger);
                Work {
                    supplied: p.supplied,
                    dissipated: p.dissipated,
                }
            }
        }
    }
}

impl FieldModel<STATE_DIM> for VesselSystem<'_> {
    fn to_vector(&self, s: &VesselState) -> SVector<f64, STATE_DIM> {
        s.to_vector()
    }
    fn from_vector(&self, y: &SVector<f64, STATE_DIM>) -> VesselState {
        VesselState::from_vector(y)
    }
    fn rhs(&self, t_step: f64, y: &SVector<f64, STATE_DIM>) -> SVector<f64, STATE_DIM> {
        self.vector_field(&VesselState::from_vector(y), self.control_on(t_step))
            .to_vector()
    }
    fn power(&self, t_step: f64, y: &SVector<f64, STATE_DIM>) -> Work {
        let p = VesselSystem::power(self, &VesselState::from_vector(y), self.control_on(t_step));
        Work {
            supplied: p.supplied,
            dissipated: p.dissipated,
        }
    }
}
