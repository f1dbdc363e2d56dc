//! What a run returns: saved states, the energy ledger per saved interval, and how it ended.

use super::options::Options;
use super::system::{Account, AccountKind, Model, Work};

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
    /// Stopped at the request of the caller (an interrupt) after `step` steps, at `t`; the
    /// trajectory ends with the state there.
    Interrupted {
        step: usize,
        t: f64,
    },
}

/// Watches a run: called after every step with the number of steps done; returning `false`
/// stops the run there (status [`Status::Interrupted`]). Also the place for progress reports.
pub trait Monitor {
    fn keep_going(&mut self, steps_done: usize) -> bool;
}

/// A monitor that never stops a run.
pub struct Unwatched;

impl Monitor for Unwatched {
    #[inline]
    fn keep_going(&mut self, _: usize) -> bool {
        true
    }
}

/// Saved states and the ledger of a run.
///
/// **Ledger.** For every saved interval: the change of stored energy `ΔH` (from `energy`), and
/// the energy booked by each account of the model (`booked`, in the order of `accounts`):
/// supplied through a port, or dissipated. `supplied` and `dissipated` are their totals.
/// Splitting methods book exactly along their sub-flows (the conservative flow books nothing),
/// so `ΔH = supplied − dissipated` holds to round-off for positive-step methods (paper
/// Prop. 2.2). Runge–Kutta methods book the method's own quadrature of the power,
/// `h Σ bᵢ P(Yᵢ)`, and the residual shows the energy they create or destroy.
#[derive(Debug, Clone)]
pub struct Trajectory<S> {
    /// Saved times.
    pub t: Vec<f64>,
    /// Saved states.
    pub states: Vec<S>,
    /// `H` at the saved states.
    pub energy: Vec<f64>,
    /// The model's ledger accounts.
    pub accounts: Vec<Account>,
    /// Energy booked per account since the previous saved state (zero for the first).
    pub booked: Vec<Work>,
    /// Energy supplied through the ports since the previous saved state (0 for the first).
    pub supplied: Vec<f64>,
    /// Energy dissipated since the previous saved state (0 for the first).
    pub dissipated: Vec<f64>,
    /// Steps taken (accepted steps of an adaptive run).
    pub steps: usize,
    /// Trial steps rejected by an adaptive run's error control (0 for fixed steps).
    pub rejected: usize,
    pub status: Status,
    /// The last finite state reached (the final state of a completed run).
    pub last_good: S,
    /// Time of `last_good`.
    pub t_last_good: f64,
    /// The model's probed quantities ([`crate::solve::Model::probe_names`]), their largest value
    /// over every step boundary of the run (the initial state included) and when it occurred.
    pub probe_names: Vec<&'static str>,
    pub probe_max: Vec<f64>,
    pub probe_max_t: Vec<f64>,
}

impl<S> Trajectory<S> {
    /// The series of one account (J per saved interval), by name.
    pub fn account(&self, name: &str) -> Option<Vec<f64>> {
        let k = self.accounts.iter().position(|a| a.name == name)?;
        Some(self.booked.iter().map(|w| w.get(k)).collect())
    }
}

/// Builds a trajectory as a kernel runs: saving, accumulating the ledger, failing.
pub(crate) struct Recorder<'m, M: Model> {
    model: &'m M,
    pub(crate) traj: Trajectory<M::State>,
    pub(crate) acc: Work,
    /// The probe's values at the last state observed.
    probed: Vec<f64>,
}

impl<'m, M: Model> Recorder<'m, M> {
    pub(crate) fn new(model: &'m M, t0: f64, y0: M::State, opts: &Options) -> Self {
        let capacity = (opts.n_steps / opts.save_every + 2).min(1 << 24);
        let mut traj = Trajectory {
            t: Vec::with_capacity(capacity),
            states: Vec::with_capacity(capacity),
            energy: Vec::with_capacity(capacity),
            accounts: model.accounts().to_vec(),
            booked: Vec::with_capacity(capacity),
            supplied: Vec::with_capacity(capacity),
            dissipated: Vec::with_capacity(capacity),
            steps: 0,
            rejected: 0,
            status: Status::Completed,
            last_good: y0.clone(),
            t_last_good: t0,
            probe_names: model.probe_names().to_vec(),
            probe_max: vec![f64::NEG_INFINITY; model.probe_names().len()],
            probe_max_t: vec![t0; model.probe_names().len()],
        };
        traj.t.push(t0);
        traj.energy.push(model.energy(&y0));
        traj.states.push(y0);
        traj.booked.push(Work::default());
        traj.supplied.push(0.0);
        traj.dissipated.push(0.0);
        let mut rec = Self {
            model,
            traj,
            acc: Work::default(),
            probed: Vec::new(),
        };
        let y0 = rec.traj.last_good.clone();
        rec.observe(t0, &y0);
        rec
    }
    /// Update the running maxima of the probed quantities with the state `y` at `t`.
    pub(crate) fn observe(&mut self, t: f64, y: &M::State) {
        let n = self.traj.probe_names.len();
        if n == 0 {
            return;
        }
        self.probed.clear();
        self.probed.resize(n, 0.0);
        self.model.probe(t, y, &mut self.probed);
        let v = &self.probed;
        for k in 0..n {
            if v[k] > self.traj.probe_max[k] {
                self.traj.probe_max[k] = v[k];
                self.traj.probe_max_t[k] = t;
            }
        }
    }
    /// End the run: the state became non-finite during step `step`, which started at `t`.
    pub(crate) fn fail(mut self, step: usize, t: f64) -> Trajectory<M::State> {
        let reason = match self.model.failure_reason() {
            Some(why) => format!("the state became non-finite: {why}"),
            None => "the state became non-finite".into(),
        };
        self.traj.status = Status::Failed { step, t, reason };
        self.traj
    }
    /// End the run at the caller's request after `steps` steps, at `t` with the state `y` (saved
    /// if it was not).
    pub(crate) fn interrupt(
        mut self,
        steps: usize,
        t: f64,
        y: M::State,
        saved: bool,
    ) -> Trajectory<M::State> {
        if !saved {
            self.save(t, y.clone());
        }
        self.traj.steps = steps;
        self.traj.last_good = y;
        self.traj.t_last_good = t;
        self.traj.status = Status::Interrupted { step: steps, t };
        self.traj
    }
    pub(crate) fn save(&mut self, t: f64, y: M::State) {
        let acc = &self.traj.accounts;
        self.traj.t.push(t);
        self.traj.energy.push(self.model.energy(&y));
        self.traj.states.push(y);
        self.traj
            .supplied
            .push(self.acc.total(acc, AccountKind::Supplied));
        self.traj
            .dissipated
            .push(self.acc.total(acc, AccountKind::Dissipated));
        self.traj.booked.push(std::mem::take(&mut self.acc));
    }
}

/// Whether the state after step `step` (0-based) is saved.
pub(crate) fn saves_after(step: usize, opts: &Options) -> bool {
    (step + 1) % opts.save_every == 0 || step + 1 == opts.n_steps
}
