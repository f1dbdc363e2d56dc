//! Adaptive steps for the composition methods: step doubling with a PI step-size controller.
//!
//! **Estimate.** Each step of length `h` from `y` is taken twice: once whole, `y₁ = Φ_h(y)`,
//! and as two halves, `ŷ₁ = Φ_{h/2}(Φ_{h/2}(y))`. For a method of order `p` the local error of
//! the halves is `(ŷ₁ − y₁)/(2ᵖ − 1)` to leading order (Richardson; Hairer, Nørsett & Wanner,
//! *Solving Ordinary Differential Equations I*, 2nd ed., §II.4, "Richardson extrapolation").
//! The step is accepted when the model's scaled norm of that estimate is at most 1
//! ([`super::system::Model::error_norm`], `atol + rtol·|y|` per component, as `solve_ivp`).
//!
//! **What is kept.** An accepted step keeps the two halves, not the extrapolated value: every
//! accepted step is two ordinary steps of the method with positive lengths, so each keeps the
//! method's energy statement (paper Prop. 2.2 for positive-step methods; Prop. 2.5's bound for
//! SP4 and SP6), and the ledger books exactly what the two halves book. A rejected trial books
//! nothing.
//!
//! **Controller.** Gustafsson's PI controller, `h_new = h · 0.9 · e_n^{−0.7/k} · e_{n−1}^{0.4/k}`
//! with `k = p + 1`, the factor kept within [0.2, 5]; after a rejection `h · max(0.2,
//! 0.9 e^{−1/k})` and no growth on the next step (Hairer & Wanner, *Solving Ordinary
//! Differential Equations II*, 2nd ed., §IV.2, eq. (2.43c) and the remarks after it;
//! K. Gustafsson, ACM TOMS 17, 1991).
//!
//! **Times.** Steps land exactly on the end of the run and on the model's switches and events
//! ([`super::system::Model::next_switch`]: the controller turned on, a sensor's sample, a
//! thruster lost), so each acts where it is due, not at the next step boundary after it.
//!
//! **Output times** ([`Tolerance::save_at`]) do not cut the steps: the state at an output time
//! `s` inside an accepted step is one step of the method from the last state of the run before
//! `s`, the step's start `t` or the end of its first half `t + h/2` (computed, not
//! interpolated), as fixed steps give their `save_at` states (`phsplit.events`). That step is at
//! most `h/2` long, so its local error is at most the accepted halves', which the controller
//! bounds. The run's own steps are the same with outputs as without, so dense outputs cost one
//! short step each, not a cap on the step size. Ledger: the row of an output is the run's
//! booking up to the branch's start plus the short step's own booking, less what the previous
//! output booked past the start of the accepted step, so `ΔH = supplied − dissipated` holds
//! between any two saved states as between steps.

use super::options::{Options, Tolerance};
use super::system::{Flow, SplitModel, Work};
use super::trajectory::{Monitor, Recorder, Status, Trajectory};
use crate::error::{Error, Result};
use crate::methods::Composition;

/// Run a composition method with adaptive steps from `opts.t0` to `tol.t1`; `opts.h` is the
/// first step tried, and every `opts.save_every`-th accepted step (and the last) is saved.
pub fn run_splitting_adaptive<M: SplitModel>(
    model: &M,
    method: &Composition,
    y0: M::State,
    opts: &Options,
    tol: &Tolerance,
    monitor: &mut dyn Monitor,
) -> Result<Trajectory<M::State>> {
    opts.validate()?;
    tol.validate(opts.t0)?;
    model.supports_order(method.order)?;
    model.revisits_states(true);
    let subs = super::kernel::flows_of(method, opts);
    let p = method.order as i32;
    let k = f64::from(p + 1);
    let richardson = f64::from(2i32.pow(p as u32) - 1);
    let mut y = y0;
    model.begin(opts.t0, &mut y);
    if model.error_norm(&y, &y, &y, tol.rtol, tol.atol).is_none() {
        return Err(Error::InvalidInput(
            "this model has no error norm for adaptive steps: give a fixed step (no rtol, atol)"
                .into(),
        ));
    }
    let mut rec = Recorder::new(model, opts.t0, y.clone(), opts);
    let (t0, t1) = (opts.t0, tol.t1);
    let span = t1 - t0;
    let mut t = t0;
    let mut h = opts.h.min(tol.h_max).min(span);
    let mut err_prev = 1e-4_f64;
    let mut rejected_last = false;
    let (mut accepted, mut rejected) = (0usize, 0usize);
    // Round-off guards: a step lands on the end (or a switch) when it would leave a sliver.
    let resolution = 64.0 * f64::EPSILON * t0.abs().max(t1.abs()).max(1.0);
    // Below this step the tolerance is taken as unreachable (a blow-up, or a discontinuity the
    // steps cannot resolve): the run stops as failed instead of creeping on.
    let h_min = resolution.max(1e-10 * span);
    // The trials' states, reused from trial to trial (a model's state may own a heap part).
    let (mut whole, mut halves) = (y.clone(), y.clone());
    let (mut mid, mut branch) = (y.clone(), y.clone());
    let saves = &tol.save_at;
    let mut next_save = saves.partition_point(|&ts| ts <= t0 + resolution);
    loop {
        let mut hn = h;
        let mut to = t1;
        if let Some(ts) = model.next_switch(t).filter(|&ts| ts > t + resolution) {
            to = to.min(ts);
        }
        let clipped = hn >= (to - t) - resolution.max(1e-9 * hn);
        if clipped {
            hn = to - t;
        }
        let last = clipped && to == t1;
        halves.clone_from(&y);
        let mut w = one_step(
            model,
            &subs,
            method.order,
            opts.ledger,
            0.5 * hn,
            t,
            &mut halves,
        );
        let finite_half = model.is_finite(&halves);
        // The first half's end and booking, kept when an output falls inside this step.
        let mid_needed = saves
            .get(next_save)
            .is_some_and(|&ts| ts < t + hn - resolution);
        let w_first = if mid_needed {
            w.clone()
        } else {
            Work::default()
        };
        if finite_half && mid_needed {
            mid.clone_from(&halves);
        }
        if finite_half {
            w += one_step(
                model,
                &subs,
                method.order,
                opts.ledger,
                0.5 * hn,
                t + 0.5 * hn,
                &mut halves,
            );
        }
        // The whole step after the halves: it is only compared (its ledger is not needed), and
        // its first sub-step can take the first half's assembly at the same start, made with
        // the ledger's rows (`model/vessel/system/memo.rs`).
        whole.clone_from(&y);
        one_step(model, &subs, method.order, false, hn, t, &mut whole);
        let err = if finite_half && model.is_finite(&halves) && model.is_finite(&whole) {
            model
                .error_norm(&halves, &whole, &y, tol.rtol, tol.atol)
                .unwrap_or(f64::INFINITY)
                / richardson
        } else {
            f64::INFINITY
        };
        if err.is_nan() || err > 1.0 {
            rejected += 1;
            rejected_last = true;
            let fac = if err.is_finite() {
                (0.9 * err.powf(-1.0 / k)).max(0.2)
            } else {
                0.2
            };
            h = hn * fac;
            if h <= h_min || accepted + rejected >= super::MAX_STEPS {
                rec.traj.steps = accepted;
                rec.traj.rejected = rejected;
                let why = if h <= h_min {
                    format!(
                        "the step size fell to {h:.3e} s without meeting rtol = {:e}, atol = {:e} (a blow-up or a discontinuity the steps cannot resolve)",
                        tol.rtol, tol.atol
                    )
                } else {
                    format!(
                        "{} trial steps were taken without reaching the end",
                        super::MAX_STEPS
                    )
                };
                rec.traj.status = Status::Failed {
                    step: accepted,
                    t,
                    reason: why,
                };
                return Ok(rec.traj);
            }
            continue;
        }
        // Accepted: the two halves; `halves` keeps the step's start for the outputs inside it.
        std::mem::swap(&mut y, &mut halves);
        let t_start = t;
        t = if clipped { to } else { t + hn };
        let mut past_start = Work::default(); // booked past `t_start` by the outputs saved so far
        let t_mid = t_start + 0.5 * hn;
        while let Some(&ts) = saves.get(next_save).filter(|&&ts| ts < t - resolution) {
            // From the step's start or from its midpoint, whichever is the last before `ts`:
            // one step of at most half the accepted length.
            let (from, t_from, mut wb) = if ts <= t_mid {
                (&halves, t_start, Work::default())
            } else {
                (&mid, t_mid, w_first.clone())
            };
            branch.clone_from(from);
            if ts - t_from > resolution {
                wb += one_step(
                    model,
                    &subs,
                    method.order,
                    opts.ledger,
                    ts - t_from,
                    t_from,
                    &mut branch,
                );
            }
            if !model.is_finite(&branch) {
                rec.traj.steps = accepted;
                rec.traj.rejected = rejected;
                return Ok(rec.fail(accepted, t_from));
            }
            rec.acc += &wb;
            rec.acc += past_start.scaled(-1.0);
            rec.save(ts, branch.clone());
            past_start = wb;
            next_save += 1;
        }
        rec.acc += w;
        rec.acc += past_start.scaled(-1.0);
        accepted += 1;
        let at_save = saves.get(next_save).is_some_and(|&ts| ts <= t + resolution);
        rec.traj.steps = accepted;
        rec.traj.rejected = rejected;
        rec.traj.last_good.clone_from(&y);
        rec.traj.t_last_good = t;
        rec.observe(t, &y);
        if at_save {
            next_save += 1;
        }
        let saved = last || at_save || (saves.is_empty() && accepted % opts.save_every == 0);
        if saved {
            rec.save(if at_save { saves[next_save - 1] } else { t }, y.clone());
        }
        if last {
            return Ok(rec.traj);
        }
        let e = err.max(1e-10);
        let mut fac = 0.9 * e.powf(-0.7 / k) * err_prev.powf(0.4 / k);
        fac = fac.clamp(0.2, 5.0);
        if rejected_last {
            fac = fac.min(1.0);
        }
        rejected_last = false;
        err_prev = e.max(1e-4);
        // A step cut short to land on a switch keeps the controller's length for the next.
        let base = if clipped { h.max(hn) } else { hn };
        h = (base * fac).min(tol.h_max);
        let done = (((t - t0) / span) * opts.n_steps as f64) as usize;
        if !monitor.keep_going(done.clamp(1, opts.n_steps)) {
            let st = rec.traj.steps;
            let mut tr = rec.interrupt(st, t, y, saved);
            tr.rejected = rejected;
            return Ok(tr);
        }
    }
}

/// One step of the method of length `h` from `t`, each sub-step of a flow starting at the
/// step's start plus the earlier sub-steps of the same flow (as in the fixed-step kernel),
/// then the projection and the model's step end. Returns what the step booked.
fn one_step<M: SplitModel>(
    model: &M,
    subs: &[(Flow, f64)],
    order: usize,
    ledger: bool,
    h: f64,
    t: f64,
    y: &mut M::State,
) -> Work {
    let mut acc = Work::default();
    let mut clock = [t, t];
    for &(flow, c) in subs {
        let len = c * h;
        let k = super::kernel::flow_index(flow);
        let start = clock[k];
        clock[k] += len;
        acc += model.flow(flow, len, t, start, order, ledger, y);
    }
    if !model.is_finite(y) {
        return acc;
    }
    if model.projects() {
        acc += model.project(y);
    }
    model.end_step(t, t + h, y);
    acc
}

#[cfg(test)]
mod tests {
    //! On the kernels' damped oscillator with a constant input (closed form, `kernel::tests`).
    use super::*;
    use crate::methods::{Method, Outer};
    use crate::solve::kernel::tests::{exact, Osc};
    use crate::solve::{run, Options};

    fn adaptive(method: &str, tol: f64, h0: f64, t1: f64, h_max: f64) -> Trajectory<[f64; 2]> {
        adaptive_on(&Osc { growth: None }, method, tol, h0, t1, h_max)
    }

    fn adaptive_on(
        model: &Osc,
        method: &str,
        tol: f64,
        h0: f64,
        t1: f64,
        h_max: f64,
    ) -> Trajectory<[f64; 2]> {
        let m: Method = method.parse().unwrap();
        let opts = Options {
            outer: Outer::Dissipative,
            tolerance: Some(Tolerance {
                rtol: tol,
                atol: tol,
                h_max,
                t1,
                save_at: Vec::new(),
            }),
            ..Options::steps(0.0, h0, (t1 / h0) as usize, 1)
        };
        run(model, &m, [1.0, -0.5], &opts).unwrap()
    }

    fn error(tr: &Trajectory<[f64; 2]>) -> f64 {
        let t = *tr.t.last().unwrap();
        let (y, ex) = (tr.states.last().unwrap(), exact(t, [1.0, -0.5]));
        (y[0] - ex[0]).abs().max((y[1] - ex[1]).abs())
    }

    /// The global error falls with the tolerance as error-per-step control predicts,
    /// `tol^{p/(p+1)}` (fitted slope), and every run ends exactly at `t1`.
    #[test]
    fn the_error_follows_the_tolerance() {
        for (name, p) in [("sp2", 2.0), ("sp4", 4.0)] {
            let tols = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8];
            let errs: Vec<f64> = tols
                .iter()
                .map(|&tol| {
                    let tr = adaptive(name, tol, 0.1, 20.0, 20.0);
                    assert_eq!(*tr.t.last().unwrap(), 20.0, "{name}");
                    assert_eq!(tr.status, Status::Completed);
                    error(&tr)
                })
                .collect();
            let (lx, ly): (Vec<f64>, Vec<f64>) = tols
                .iter()
                .zip(&errs)
                .map(|(t, e)| (t.ln(), e.ln()))
                .unzip();
            let n = lx.len() as f64;
            let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
            let slope = lx
                .iter()
                .zip(&ly)
                .map(|(x, y)| (x - mx) * (y - my))
                .sum::<f64>()
                / lx.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
            let expected = p / (p + 1.0);
            assert!(
                (slope - expected).abs() < 0.2,
                "{name}: slope {slope:.3} against {expected:.3}; errors {errs:?}"
            );
            assert!(errs[0] < 1e-2 && errs[4] < 1e-5, "{name}: {errs:?}");
        }
    }

    /// Each saved interval's ledger closes to round-off (every accepted step is two positive
    /// steps of the method), rejected trials book nothing, and the steps lengthen as an
    /// oscillator without input settles (with the input, the split's flows do not keep its
    /// equilibrium `q = u`, so the local error does not fall as it settles).
    #[test]
    fn the_ledger_closes_and_settled_phases_take_long_steps() {
        // A first step far too long: rejected, then shortened.
        let tr = adaptive("sp2", 1e-7, 10.0, 60.0, 60.0);
        assert!(tr.rejected >= 1, "the 10 s first step was accepted");
        for i in 1..tr.t.len() {
            let dh = tr.energy[i] - tr.energy[i - 1];
            let booked = tr.supplied[i] - tr.dissipated[i];
            assert!(
                (dh - booked).abs() < 1e-13,
                "interval {i}: {dh} vs {booked}"
            );
        }
        assert!(error(&tr) < 1e-5);
        let tr = adaptive_on(&Osc { growth: Some(-0.3) }, "sp2", 1e-7, 0.1, 60.0, 60.0);
        let dt: Vec<f64> = tr.t.windows(2).map(|w| w[1] - w[0]).collect();
        let (early, late) = (dt[1], dt[dt.len() - 2]);
        assert!(late > 5.0 * early, "steps {early} early, {late} late");
    }

    /// `h_max` bounds every step; a Runge–Kutta method is refused.
    #[test]
    fn h_max_bounds_the_steps_and_runge_kutta_is_refused() {
        let tr = adaptive("sp4", 1e-3, 0.5, 30.0, 0.75);
        assert!(tr.t.windows(2).all(|w| w[1] - w[0] <= 0.75 + 1e-12));
        let opts = Options {
            tolerance: Some(Tolerance {
                rtol: 1e-6,
                atol: 1e-6,
                h_max: 1.0,
                t1: 1.0,
                save_at: Vec::new(),
            }),
            ..Options::steps(0.0, 0.1, 10, 1)
        };
        let m: Method = "rk4".parse().unwrap();
        let e = run(&Osc { growth: None }, &m, [1.0, -0.5], &opts).unwrap_err();
        assert!(e.to_string().contains("splitting methods"), "{e}");
    }

    /// Output times: only they are saved (with the start and the end), at exactly those times;
    /// the run takes the same steps as without them; the states there are the method's within
    /// the tolerance; and the ledger closes between any two of them, also between two outputs
    /// inside one step.
    #[test]
    fn output_times_do_not_cut_the_steps() {
        let m: Method = "sp4".parse().unwrap();
        let tolerance = |save_at: Vec<f64>| Options {
            tolerance: Some(Tolerance {
                rtol: 1e-8,
                atol: 1e-8,
                h_max: 20.0,
                t1: 20.0,
                save_at,
            }),
            ..Options::steps(0.0, 0.1, 200, 1)
        };
        let plain = run(
            &Osc { growth: None },
            &m,
            [1.0, -0.5],
            &tolerance(Vec::new()),
        )
        .unwrap();
        // Outputs every 0.05 s: several inside each step.
        let save_at: Vec<f64> = (1..400).map(|k| 0.05 * k as f64).collect();
        let tr = run(
            &Osc { growth: None },
            &m,
            [1.0, -0.5],
            &tolerance(save_at.clone()),
        )
        .unwrap();
        let mut want = vec![0.0];
        want.extend(&save_at);
        want.push(20.0);
        assert_eq!(tr.t, want);
        assert_eq!(tr.steps, plain.steps);
        assert!(tr.steps < 100, "{} steps for 400 outputs", tr.steps);
        assert_eq!(tr.states.last(), plain.states.last());
        for i in 0..tr.t.len() {
            let (t, y) = (tr.t[i], tr.states[i]);
            let ex = exact(t, [1.0, -0.5]);
            assert!(
                (y[0] - ex[0]).abs() < 1e-6,
                "t = {t}: {} vs {}",
                y[0],
                ex[0]
            );
            if i > 0 {
                let dh = tr.energy[i] - tr.energy[i - 1];
                let booked = tr.supplied[i] - tr.dissipated[i];
                assert!((dh - booked).abs() < 1e-13, "t = {t}: {dh} vs {booked}");
            }
        }
    }
}
