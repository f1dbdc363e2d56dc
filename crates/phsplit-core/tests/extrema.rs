//! Summaries from every step. The running maxima of the controller's force and moment
//! must equal the maxima over every step's state, also when only every 50th state is saved.
use phsplit_core::model::vessel::{Vessel, VesselState, VesselSystem};
use phsplit_core::settings::Settings;
use phsplit_core::solve::{run, Model, Trajectory};

/// The paper's vessel by `sys` with `method` at step `h` on `[0, t1]`, the controller from
/// `control`, saving every `save_every`-th state.
fn run_paper(
    sys: &VesselSystem,
    method: &str,
    (t1, h, control): (f64, f64, f64),
    save_every: usize,
) -> Trajectory<VesselState> {
    let s = Settings {
        t_span: (0.0, t1),
        h,
        method: method.parse().unwrap(),
        control_start: Some(control),
        save_every,
        ..Settings::default()
    };
    run(
        sys,
        &s.method,
        Vessel::paper().initial_state(),
        &s.options().unwrap(),
    )
    .unwrap()
}

#[test]
fn running_maxima_cover_every_step_whatever_is_saved() {
    let v = Vessel::paper();
    for (method, project) in [("sp2", true), ("sp2", false), ("rk4", true)] {
        let every = |save_every: usize| {
            let sys = VesselSystem::new(&v, Some(10.0))
                .with_extrema(true)
                .with_projection(project);
            let tr = run_paper(&sys, method, (100.0, 0.25, 10.0), save_every);
            (sys, tr)
        };
        let (sys, all) = every(1);
        let (_, some) = every(50);
        // The maxima over every saved state of the run that saves every step, computed here
        // from the states through the public wrench function.
        let idx = |name: &str| sys.accounts().iter().position(|a| a.name == name).unwrap();
        let (c, cd) = (idx("control"), idx("control_damping"));
        let mut fmax = 0.0f64;
        let mut mmax = 0.0f64;
        for (t, s) in all.t.iter().zip(&all.states) {
            let w = sys.account_wrenches(s, *t, sys.control_on(*t));
            let f = w[c].0 + w[cd].0;
            let m = w[c].1 + w[cd].1;
            fmax = fmax.max(f.norm());
            mmax = mmax.max(m.norm());
        }
        assert_eq!(all.probe_names, ["control_force", "control_moment"]);
        assert!(
            (all.probe_max[0] - fmax).abs() <= 1e-12 * fmax
                && (all.probe_max[1] - mmax).abs() <= 1e-12 * mmax
        );
        assert_eq!(
            some.probe_max, all.probe_max,
            "{method}: saving fewer states loses no peak"
        );
        // and the peak is larger than what the 50th-step samples show
        let mut sampled = 0.0f64;
        for (t, s) in some.t.iter().zip(&some.states) {
            let w = sys.account_wrenches(s, *t, sys.control_on(*t));
            sampled = sampled.max((w[c].0 + w[cd].0).norm());
        }
        assert!(
            sampled < all.probe_max[0],
            "{method}: {sampled} vs {}",
            all.probe_max[0]
        );
        assert!(all.probe_max_t[0] >= 10.0);
    }
}

/// Without the projection (which needs the state at every step boundary), a composition merges
/// its last and first sub-steps across unsaved boundaries, and the state at those boundaries
/// never exists; a run that keeps running maxima must not merge: saving every 50th step then
/// gives bitwise the states and maxima of saving every step.
#[test]
fn running_maxima_do_not_merge_sub_steps_away() {
    let v = Vessel::paper();
    for method in ["sp2", "sp4"] {
        let every = |save_every: usize| {
            let sys = VesselSystem::new(&v, Some(0.0))
                .with_extrema(true)
                .with_projection(false);
            run_paper(&sys, method, (100.0, 0.25, 0.0), save_every)
        };
        let (all, some) = (every(1), every(50));
        assert_eq!(some.states.last(), all.states.last(), "{method}");
        assert_eq!(some.states[1], all.states[50], "{method}");
        assert_eq!(some.probe_max, all.probe_max, "{method}");
    }
}

/// What a run computes does not depend on which states it saves: a collocated flow S2 (the
/// default) is never merged across step boundaries, so saving every 7th state gives bitwise the
/// states of saving every one; the exact S2 is merged, and agrees to round-off.
#[test]
fn a_run_does_not_depend_on_what_it_saves() {
    use phsplit_core::model::vessel::LinearFlow;
    let v = Vessel::paper();
    for lf in [LinearFlow::Gauss, LinearFlow::Exact] {
        let every = |save_every: usize| {
            let sys = VesselSystem::new(&v, Some(0.0))
                .with_projection(false)
                .with_linear_flow(lf);
            run_paper(&sys, "sp2", (70.0, 0.5, 0.0), save_every)
        };
        let (all, some) = (every(1), every(7));
        let (a, b) = (all.states.last().unwrap(), some.states.last().unwrap());
        if lf == LinearFlow::Gauss {
            assert_eq!(a, b);
        } else {
            let d = (a.to_vector() - b.to_vector()).amax() / a.to_vector().amax();
            assert!(d < 1e-12, "{d}");
        }
    }
}
