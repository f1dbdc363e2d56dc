//! Dump final states (full precision) of the paper's scenarios, for the old/new comparison.
use phsplit_core::methods::Method;
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};
use phsplit_core::methods::Outer;

fn main() {
    let vessel = Vessel::paper();
    for (name, h, t_end, cs) in [
        ("lie", 0.5, 200.0, Some(50.0)), ("sp2", 0.5, 200.0, Some(50.0)), ("sp4", 0.5, 200.0, Some(50.0)),
        ("sp6", 0.5, 200.0, Some(50.0)), ("euler", 0.01, 200.0, Some(50.0)), ("heun", 0.1, 200.0, Some(50.0)),
        ("rk4", 0.5, 200.0, Some(50.0)), ("sp2", 2.0 / 3.0, 50.0, Some(0.0)), ("sp4", 1.9375, 100.0, Some(0.0)),
    ] {
        for (lfn, lf) in [("exact", LinearFlow::Exact), ("gauss", LinearFlow::Gauss)] {
            let m: Method = name.parse().unwrap();
            let sys = VesselSystem::new(&vessel, cs).with_linear_flow(lf);
            let n = (t_end / h as f64 * (1.0 + 1e-12)).floor() as usize;
            let opts = Options { t0: 0.0, h, n_steps: n, save_every: n, outer: Outer::Dissipative, ledger: true };
            let tr = run(&sys, &m, vessel.initial_state(), &opts).unwrap();
            let y = tr.states.last().unwrap().to_vector();
            let v: Vec<String> = y.iter().map(|x| format!("{x:.17e}")).collect();
            println!("{name} {lfn} {h} {t_end} {} {:.17e} {:.17e} {:.17e}", v.join(" "), tr.energy.last().unwrap(), tr.supplied.iter().sum::<f64>(), tr.dissipated.iter().sum::<f64>());
        }
    }
}
