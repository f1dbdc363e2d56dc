//! The integration kernels: one for every composition method, one for every Butcher tableau.
//!
//! A kernel never knows it is a ship: it sees a model only through the traits of
//! [`super::system`].
//!
//! **Time dependence.** The only explicit time dependence the models have is a switch (the
//! controller turned on at a time). Kernels pass each flow and each stage the *start time of its
//! step*, so a switch acts at the first step boundary at or after its time and every step
//! integrates one autonomous field.

use super::options::Options;
use super::system::{FieldModel, Flow, SplitModel, Work};
use super::trajectory::{saves_after, Monitor, Recorder, Trajectory, Unwatched};
use crate::error::Result;
use crate::methods::{ButcherTableau, Composition, Method};
use nalgebra::SVector;

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
    run_splitting_watched(model, method, y0, opts, &mut Unwatched)
}

/// [`run_splitting`] under a [`Monitor`], asked after every step whether to go on.
pub fn run_splitting_watched<M: SplitModel>(
    model: &M,
    method: &Composition,
    y0: M::State,
    opts: &Options,
    monitor: &mut dyn Monitor,
) -> Result<Trajectory<M::State>> {
    opts.validate()?;
    model.supports_order(method.order)?;
    model.revisits_states(false);
    let subs = flows_of(method, opts);
    let fsal = subs.len() > 1 && subs[0].0 == subs[subs.len() - 1].0;
    let last = subs.len() - 1;
    let mut y0 = y0;
    model.begin(opts.t0, &mut y0);
    let mut rec = Recorder::new(model, opts.t0, y0.clone(), opts);
    let mut y = y0;
    // A last sub-step deferred into the next step: (flow, length, its step's start time, the
    // time it starts at).
    let mut pending: Option<(Flow, f64, f64, f64)> = None;
    for n in 0..opts.n_steps {
        let t = opts.t0 + n as f64 * opts.h;
        let (hn, t1) = (opts.step_length(n), opts.time_after(n));
        // Each flow's own clock: a sub-step of a flow starts at the step's start plus the
        // lengths of the earlier sub-steps of the same flow (time is carried by each flow as
        // an extra state with `t' = 1`, so a time-dependent flow keeps the method's order).
        let mut clock = [t, t];
        for (i, &(flow, c)) in subs.iter().enumerate() {
            let mut len = c * hn;
            let k = flow_index(flow);
            let mut start = clock[k];
            clock[k] += len;
            if i == 0 {
                if let Some((pf, plen, pt, pc)) = pending.take() {
                    if pf == flow && model.same_field(pt, t) {
                        len += plen;
                        start = pc;
                    } else {
                        rec.acc += model.flow(pf, plen, pt, pc, method.order, opts.ledger, &mut y);
                    }
                }
            }
            if i == last
                && fsal
                && !saves_after(n, opts)
                && model.same_field(t, t1)
                && !model.projects()
                && model.probe_names().is_empty()
                && model.merges_exactly(flow)
            {
                pending = Some((flow, len, t, start));
                continue;
            }
            rec.acc += model.flow(flow, len, t, start, method.order, opts.ledger, &mut y);
        }
        if !model.is_finite(&y) {
            return Ok(rec.fail(n, t));
        }
        if model.projects() {
            rec.acc += model.project(&mut y);
        }
        if pending.is_none() {
            model.end_step(t, t1, &mut y);
        }
        rec.traj.steps = n + 1;
        if pending.is_none() {
            // y sits on the step boundary (no sub-step deferred into the next step).
            rec.traj.last_good.clone_from(&y);
            rec.traj.t_last_good = t1;
            rec.observe(t1, &y);
        }
        let saved = saves_after(n, opts);
        if saved {
            rec.save(t1, y.clone());
        }
        if n + 1 < opts.n_steps && !monitor.keep_going(n + 1) {
            // Complete the step (a deferred sub-step), then stop on its boundary.
            if let Some((pf, plen, pt, pc)) = pending.take() {
                rec.acc += model.flow(pf, plen, pt, pc, method.order, opts.ledger, &mut y);
                if !model.is_finite(&y) {
                    return Ok(rec.fail(n, t));
                }
                model.end_step(t, t1, &mut y);
            }
            return Ok(rec.interrupt(n + 1, t1, y, saved));
        }
    }
    Ok(rec.traj)
}

/// A composition's sub-steps as flows, with the outer flow the options choose.
pub(super) fn flows_of(method: &Composition, opts: &Options) -> Vec<(Flow, f64)> {
    let (fa, fb) = opts.outer.flows();
    method
        .substeps
        .iter()
        .map(|&(is_a, c)| (if is_a { fa } else { fb }, c))
        .collect()
}

/// The index of a flow's clock.
pub(super) fn flow_index(f: Flow) -> usize {
    match f {
        Flow::S1 => 0,
        Flow::S2 => 1,
    }
}

/// Run an explicit Runge–Kutta method on the full vector field.
pub fn run_runge_kutta<const N: usize, M: FieldModel<N>>(
    model: &M,
    tableau: &ButcherTableau,
    y0: M::State,
    opts: &Options,
) -> Result<Trajectory<M::State>> {
    run_runge_kutta_watched(model, tableau, y0, opts, &mut Unwatched)
}

/// [`run_runge_kutta`] under a [`Monitor`], asked after every step whether to go on.
pub fn run_runge_kutta_watched<const N: usize, M: FieldModel<N>>(
    model: &M,
    tableau: &ButcherTableau,
    y0: M::State,
    opts: &Options,
    monitor: &mut dyn Monitor,
) -> Result<Trajectory<M::State>> {
    opts.validate()?;
    if let Some(why) = model.runge_kutta_refused() {
        return Err(crate::Error::InvalidInput(why));
    }
    let s = tableau.stages();
    let mut y = model.to_vector(&y0);
    let mut rec = Recorder::new(model, opts.t0, y0, opts);
    let mut k: Vec<SVector<f64, N>> = vec![SVector::zeros(); s];
    for n in 0..opts.n_steps {
        let t = opts.t0 + n as f64 * opts.h;
        let (h, t1) = (opts.step_length(n), opts.time_after(n));
        let mut work = Work::default();
        for i in 0..s {
            let mut yi = y;
            for (j, aij) in tableau.a[i].iter().enumerate() {
                if *aij != 0.0 {
                    yi.axpy(h * aij, &k[j], 1.0);
                }
            }
            let ti = t + tableau.c[i] * h;
            k[i] = model.rhs(t, ti, &yi);
            if opts.ledger {
                work += model.power(t, ti, &yi).scaled(h * tableau.b[i]);
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
        if model.projects() && model.projects_runge_kutta() {
            let mut st = model.from_vector(&y1);
            work += model.project(&mut st);
            y1 = model.to_vector(&st);
        }
        y = y1;
        rec.acc += work;
        if !rec.traj.probe_names.is_empty() {
            rec.observe(t1, &model.from_vector(&y));
        }
        rec.traj.steps = n + 1;
        let saved = saves_after(n, opts);
        if saved {
            rec.save(t1, model.from_vector(&y));
        }
        if n + 1 < opts.n_steps && !monitor.keep_going(n + 1) {
            return Ok(rec.interrupt(n + 1, t1, model.from_vector(&y), saved));
        }
    }
    rec.traj.last_good = model.from_vector(&y);
    rec.traj.t_last_good = opts.time_after(opts.n_steps - 1);
    Ok(rec.traj)
}

/// Run any method on a model that offers both views.
pub fn run<const N: usize, M: SplitModel + FieldModel<N>>(
    model: &M,
    method: &Method,
    y0: M::State,
    opts: &Options,
) -> Result<Trajectory<M::State>> {
    run_watched(model, method, y0, opts, &mut Unwatched)
}

/// [`run`] under a [`Monitor`].
pub fn run_watched<const N: usize, M: SplitModel + FieldModel<N>>(
    model: &M,
    method: &Method,
    y0: M::State,
    opts: &Options,
    monitor: &mut dyn Monitor,
) -> Result<Trajectory<M::State>> {
    match (method, &opts.tolerance) {
        (Method::Splitting(c), None) => run_splitting_watched(model, c, y0, opts, monitor),
        (Method::Splitting(c), Some(tol)) => {
            super::adaptive::run_splitting_adaptive(model, c, y0, opts, tol, monitor)
        }
        (Method::RungeKutta(t), None) => run_runge_kutta_watched(model, t, y0, opts, monitor),
        (Method::RungeKutta(t), Some(_)) => Err(crate::Error::InvalidInput(format!(
            "adaptive steps (rtol, atol) are for the splitting methods (lie, sp2, mcl2, sp4, sp6); {} runs with a fixed step here: drop rtol and atol, or choose a splitting method",
            t.name
        ))),
    }
}

#[cfg(test)]
pub(crate) mod tests {
    //! The kernels on a model with closed forms, written for the test: a damped oscillator
    //! with a constant input, `q' = p`, `p' = −q − d p + u`, `H = ½(q² + p²)`, split into the
    //! rotation `q' = p, p' = −q` (S1, conservative) and `p' = −d p + u` (S2, dissipative with
    //! the port `u`: supplied `∫ p u dt`, dissipated `∫ d p² dt`).
    use super::*;
    use crate::methods::{Method, Outer, REGISTRY};
    use crate::solve::system::{Account, Model};
    use crate::solve::Status;

    pub(crate) const D: f64 = 0.3;
    pub(crate) const U: f64 = 0.7;

    pub(crate) struct Osc {
        /// Blow up the S2 flow (for the failure path): `p' = +growth p`.
        pub(crate) growth: Option<f64>,
    }
    const ACC: [Account; 2] = [Account::supplied("input"), Account::dissipated("damping")];

    impl Model for Osc {
        type State = [f64; 2];
        fn energy(&self, s: &[f64; 2]) -> f64 {
            0.5 * (s[0] * s[0] + s[1] * s[1])
        }
        fn is_finite(&self, s: &[f64; 2]) -> bool {
            s.iter().all(|v| v.is_finite())
        }
        fn same_field(&self, _: f64, _: f64) -> bool {
            true
        }
        fn accounts(&self) -> &[Account] {
            &ACC
        }
        fn error_norm(
            &self,
            a: &[f64; 2],
            b: &[f64; 2],
            c: &[f64; 2],
            r: f64,
            at: f64,
        ) -> Option<f64> {
            let e = (0..2).map(|i| ((a[i] - b[i]) / (at + r * a[i].abs().max(c[i].abs()))).powi(2));
            Some((e.sum::<f64>() / 2.0).sqrt())
        }
    }

    impl SplitModel for Osc {
        fn supports_order(&self, order: usize) -> Result<()> {
            assert!(order <= 6);
            Ok(())
        }
        fn flow(
            &self,
            which: Flow,
            h: f64,
            _t: f64,
            _at: f64,
            _o: usize,
            ledger: bool,
            s: &mut [f64; 2],
        ) -> Work {
            let mut w = Work::default();
            match which {
                Flow::S1 => {
                    let (c, sn) = (h.cos(), h.sin());
                    *s = [c * s[0] + sn * s[1], -sn * s[0] + c * s[1]];
                }
                Flow::S2 => {
                    if let Some(g) = self.growth {
                        s[1] *= (g * h).exp();
                        return w;
                    }
                    // p(t) = u/d + (p0 − u/d) e^{−dt}; the ledger's integrals in closed form.
                    let (pe, a) = (U / D, s[1] - U / D);
                    let e = (-D * h).exp();
                    if ledger {
                        let int_p = pe * h + a * (1.0 - e) / D;
                        let int_p2 = pe * pe * h
                            + 2.0 * pe * a * (1.0 - e) / D
                            + a * a * (1.0 - e * e) / (2.0 * D);
                        w.set(0, U * int_p);
                        w.set(1, D * int_p2);
                    }
                    s[1] = pe + a * e;
                }
            }
            w
        }
    }

    impl FieldModel<2> for Osc {
        fn to_vector(&self, s: &[f64; 2]) -> SVector<f64, 2> {
            SVector::<f64, 2>::new(s[0], s[1])
        }
        fn from_vector(&self, y: &SVector<f64, 2>) -> [f64; 2] {
            [y[0], y[1]]
        }
        fn rhs(&self, _t: f64, _at: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
            let g = self.growth.map_or(-D, |g| g);
            SVector::<f64, 2>::new(
                y[1],
                -y[0] + g * y[1] + if self.growth.is_some() { 0.0 } else { U },
            )
        }
        fn power(&self, _t: f64, _at: f64, y: &SVector<f64, 2>) -> Work {
            let mut w = Work::default();
            w.set(0, y[1] * U);
            w.set(1, D * y[1] * y[1]);
            w
        }
    }

    /// The exact solution: `e = q − u` solves `e'' + d e' + e = 0` (under-damped).
    pub(crate) fn exact(t: f64, y0: [f64; 2]) -> [f64; 2] {
        let om = (1.0 - D * D / 4.0).sqrt();
        let (e0, v0) = (y0[0] - U, y0[1]);
        let b = (v0 + 0.5 * D * e0) / om;
        let k = (-0.5 * D * t).exp();
        let (c, s) = ((om * t).cos(), (om * t).sin());
        let e = k * (e0 * c + b * s);
        let v = k * (-0.5 * D * (e0 * c + b * s) + (-e0 * om * s + b * om * c));
        [U + e, v]
    }

    fn opts(h: f64, n: usize, save_every: usize, outer: Outer) -> Options {
        Options {
            outer,
            ..Options::steps(0.0, h, n, save_every)
        }
    }

    #[test]
    fn every_registered_method_converges_at_its_order() {
        let y0 = [1.0, -0.5];
        let t_end = 2.0;
        let ex = exact(t_end, y0);
        for entry in REGISTRY {
            let m: Method = entry.name.parse().unwrap();
            for outer in [Outer::Dissipative, Outer::Conservative] {
                let hs: Vec<f64> = (2..7).map(|k| t_end / (1 << k) as f64).collect();
                let errs: Vec<f64> = hs
                    .iter()
                    .map(|&h| {
                        let n = (t_end / h).round() as usize;
                        let tr = run(&Osc { growth: None }, &m, y0, &opts(h, n, n, outer)).unwrap();
                        let y = tr.states.last().unwrap();
                        ((y[0] - ex[0]).powi(2) + (y[1] - ex[1]).powi(2)).sqrt()
                    })
                    .collect();
                // Least-squares slope of log(err) against log(h), over the points above round-off.
                let pts: Vec<(f64, f64)> = hs
                    .iter()
                    .zip(&errs)
                    .filter(|(_, e)| **e > 1e-13)
                    .map(|(h, e)| (h.ln(), e.ln()))
                    .collect();
                assert!(
                    pts.len() >= 3,
                    "{}: too few points above round-off: {errs:?}",
                    entry.name
                );
                let n = pts.len() as f64;
                let (mx, my) = (
                    pts.iter().map(|p| p.0).sum::<f64>() / n,
                    pts.iter().map(|p| p.1).sum::<f64>() / n,
                );
                let slope = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>()
                    / pts.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
                assert!(
                    (slope - m.order() as f64).abs() < 0.3,
                    "{} ({outer:?}): fitted order {slope:.3}, expected {}; errors {errs:?}",
                    entry.name,
                    m.order()
                );
            }
        }
    }

    #[test]
    fn merged_sub_steps_equal_the_unmerged_composition() {
        // Saving every step forbids merging across boundaries; saving at the end allows it.
        for name in ["lie", "sp2", "sp4", "sp6"] {
            let m: Method = name.parse().unwrap();
            for outer in [Outer::Dissipative, Outer::Conservative] {
                let a = run(
                    &Osc { growth: None },
                    &m,
                    [1.0, 0.2],
                    &opts(0.1, 50, 1, outer),
                )
                .unwrap();
                let b = run(
                    &Osc { growth: None },
                    &m,
                    [1.0, 0.2],
                    &opts(0.1, 50, 50, outer),
                )
                .unwrap();
                let (ya, yb) = (a.states.last().unwrap(), b.states.last().unwrap());
                assert!(
                    (ya[0] - yb[0]).abs() < 1e-13 && (ya[1] - yb[1]).abs() < 1e-13,
                    "{name}"
                );
                // The ledger adds up the same.
                let sa: f64 = a.supplied.iter().sum();
                assert!(
                    (sa - b.supplied[1]).abs() < 1e-13,
                    "{name}: {sa} vs {}",
                    b.supplied[1]
                );
            }
        }
    }

    #[test]
    fn saving_and_the_ledger() {
        let m: Method = "sp2".parse().unwrap();
        let tr = run(
            &Osc { growth: None },
            &m,
            [1.0, 0.0],
            &opts(0.1, 10, 3, Outer::Dissipative),
        )
        .unwrap();
        // Steps 3, 6, 9 and the last (10) are saved, after the initial state.
        let t: Vec<f64> = tr.t.iter().map(|t| (t * 10.0).round()).collect();
        assert_eq!(t, [0.0, 3.0, 6.0, 9.0, 10.0]);
        assert_eq!(tr.steps, 10);
        assert_eq!(tr.status, Status::Completed);
        assert_eq!(tr.account("damping").unwrap().len(), 5);
        // Positive steps (Prop. 2.2): ΔH = supplied − dissipated to round-off, by account.
        for i in 1..tr.t.len() {
            let dh = tr.energy[i] - tr.energy[i - 1];
            assert!((dh - (tr.booked[i].get(0) - tr.booked[i].get(1))).abs() < 1e-14);
            assert!(tr.dissipated[i] > 0.0);
        }
        assert_eq!(tr.last_good, *tr.states.last().unwrap());
    }

    #[test]
    fn a_run_that_blows_up_fails_with_what_it_had() {
        let osc = Osc { growth: Some(30.0) };
        for name in ["sp2", "rk4"] {
            let m: Method = name.parse().unwrap();
            let tr = run(&osc, &m, [1.0, 1.0], &opts(1.0, 400, 1, Outer::Dissipative)).unwrap();
            let Status::Failed { step, .. } = tr.status else {
                panic!("{name} did not fail")
            };
            assert!(step > 0 && step < 400, "{name}: {step}");
            assert_eq!(tr.steps, step);
            assert!(tr.states.iter().all(|s| s.iter().all(|v| v.is_finite())));
            assert!(tr.last_good.iter().all(|v| v.is_finite()));
            assert_eq!(tr.t.len(), step + 1);
        }
        // Bad options are refused before the first step.
        let e = run(
            &Osc { growth: None },
            &"sp2".parse().unwrap(),
            [0.0; 2],
            &opts(0.0, 1, 1, Outer::Dissipative),
        );
        assert!(e.unwrap_err().to_string().contains("h must be"));
    }

    /// Stops the run after a given number of steps.
    struct StopAfter(usize);
    impl crate::solve::Monitor for StopAfter {
        fn keep_going(&mut self, done: usize) -> bool {
            done < self.0
        }
    }

    #[test]
    fn an_interrupted_run_ends_on_a_completed_step() {
        for name in ["sp2", "sp4", "rk4"] {
            let m: Method = name.parse().unwrap();
            // save_every 5: the composition defers (merges) its last sub-step across unsaved
            // boundaries; the interrupt must complete the step first.
            let o = opts(0.1, 50, 5, Outer::Dissipative);
            let tr =
                run_watched(&Osc { growth: None }, &m, [1.0, 0.2], &o, &mut StopAfter(7)).unwrap();
            assert_eq!(
                tr.status,
                Status::Interrupted {
                    step: 7,
                    t: 0.7000000000000001
                },
                "{name}"
            );
            assert_eq!(tr.steps, 7);
            let t: Vec<f64> = tr.t.iter().map(|t| (t * 10.0).round()).collect();
            assert_eq!(t, [0.0, 5.0, 7.0], "{name}");
            let full = run(
                &Osc { growth: None },
                &m,
                [1.0, 0.2],
                &opts(0.1, 7, 1, Outer::Dissipative),
            )
            .unwrap();
            let (a, b) = (tr.states.last().unwrap(), full.states.last().unwrap());
            assert!(
                (a[0] - b[0]).abs() < 1e-14 && (a[1] - b[1]).abs() < 1e-14,
                "{name}: {a:?} vs {b:?}"
            );
            assert_eq!(tr.last_good, *a);
            // the ledger of the interrupted run closes as the completed one's
            let sa: f64 = tr.supplied.iter().sum();
            let sb: f64 = full.supplied.iter().sum();
            assert!((sa - sb).abs() < 1e-14, "{name}: {sa} vs {sb}");
        }
    }

    /// The oscillator with a projection after every step that halves `p` and books the energy
    /// it removes, counting its calls.
    struct Projected {
        inner: Osc,
        calls: std::cell::Cell<usize>,
    }
    impl Model for Projected {
        type State = [f64; 2];
        fn energy(&self, s: &[f64; 2]) -> f64 {
            self.inner.energy(s)
        }
        fn is_finite(&self, s: &[f64; 2]) -> bool {
            self.inner.is_finite(s)
        }
        fn same_field(&self, a: f64, b: f64) -> bool {
            self.inner.same_field(a, b)
        }
        fn accounts(&self) -> &[Account] {
            &ACC
        }
        fn projects(&self) -> bool {
            true
        }
        fn project(&self, s: &mut [f64; 2]) -> Work {
            self.calls.set(self.calls.get() + 1);
            let h0 = self.energy(s);
            s[1] *= 0.5;
            let mut w = Work::default();
            w.set(1, h0 - self.energy(s)); // removed: booked as dissipated
            w
        }
    }
    impl SplitModel for Projected {
        fn supports_order(&self, order: usize) -> Result<()> {
            self.inner.supports_order(order)
        }
        fn flow(
            &self,
            which: Flow,
            h: f64,
            t: f64,
            at: f64,
            o: usize,
            ledger: bool,
            s: &mut [f64; 2],
        ) -> Work {
            self.inner.flow(which, h, t, at, o, ledger, s)
        }
    }
    impl FieldModel<2> for Projected {
        fn to_vector(&self, s: &[f64; 2]) -> SVector<f64, 2> {
            self.inner.to_vector(s)
        }
        fn from_vector(&self, y: &SVector<f64, 2>) -> [f64; 2] {
            self.inner.from_vector(y)
        }
        fn rhs(&self, t: f64, at: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
            self.inner.rhs(t, at, y)
        }
        fn power(&self, t: f64, at: f64, y: &SVector<f64, 2>) -> Work {
            self.inner.power(t, at, y)
        }
    }

    #[test]
    fn a_projection_runs_after_every_step_unmerged_and_booked() {
        for name in ["sp2", "sp4", "lie", "rk4"] {
            let m: Method = name.parse().unwrap();
            let run_with = |save_every: usize| {
                let pm = Projected {
                    inner: Osc { growth: None },
                    calls: std::cell::Cell::new(0),
                };
                let tr = run(
                    &pm,
                    &m,
                    [1.0, 0.2],
                    &opts(0.1, 20, save_every, Outer::Dissipative),
                )
                .unwrap();
                (tr, pm.calls.get())
            };
            let (a, calls_a) = run_with(1);
            let (b, calls_b) = run_with(5);
            assert_eq!((calls_a, calls_b), (20, 20), "{name}");
            // No sub-step is merged across a boundary where the state is projected: saving
            // every 5th step gives the very same states.
            assert_eq!(a.states[5], b.states[1], "{name}");
            assert_eq!(a.states[20], b.states[4], "{name}");
            // The energy the projection removes is booked: the ledger closes per saved interval.
            for i in 1..b.t.len() {
                let dh = b.energy[i] - b.energy[i - 1];
                let bal = b.booked[i].get(0) - b.booked[i].get(1);
                let tol = if name == "rk4" { 1e-6 } else { 1e-14 }; // RK: a quadrature
                assert!((dh - bal).abs() < tol, "{name} {i}: {dh} vs {bal}");
            }
        }
    }

    #[test]
    fn a_span_that_is_not_whole_steps_is_reached_exactly() {
        // [0, 1] with h = 0.3: three steps of 0.3 and one of 0.1.
        let ex = exact(1.0, [1.0, -0.5]);
        for name in ["sp2", "sp4", "rk4", "lie"] {
            let m: Method = name.parse().unwrap();
            let o = Options {
                last_h: 0.1,
                ..opts(0.3, 4, 1, Outer::Dissipative)
            };
            let tr = run(&Osc { growth: None }, &m, [1.0, -0.5], &o).unwrap();
            assert!(
                (tr.t.last().unwrap() - 1.0).abs() < 1e-15,
                "{name}: {:?}",
                tr.t
            );
            let y = tr.states.last().unwrap();
            let err = ((y[0] - ex[0]).powi(2) + (y[1] - ex[1]).powi(2)).sqrt();
            // the local errors of a method of order p at h = 0.3: far below 0.3^p... but not 0
            assert!(
                err < 0.3f64.powi(m.order() as i32) && err > 0.0,
                "{name}: {err}"
            );
        }
    }
}
