//! SP2 steps of a vessel read from a vessel file (the TOML `phsplit.Vessel.to_toml` writes), with
//! the ledger and the controller on: for comparing a step's cost in a sea with the same step in
//! calm water (`benchmarks/sea_cost.py` writes both files and counts their instructions). Run:
//! `cargo run --release -p phsplit-core --example sea_steps -- vessel.toml 0.5 200 [linear_flow
//! [outer]]` (`linear_flow`: the core's default, `"exact"` where it acts and Gauss of the
//! method's order where S2 has a forcing part, unless named; `outer`: `"dissipative"`, S2
//! outermost, unless `"conservative"`).
use phsplit_core::methods::{Method, Outer};
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args
        .get(1)
        .expect("usage: sea_steps VESSEL.toml [h] [steps]");
    let h: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0.5);
    let n: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let text = std::fs::read_to_string(path).expect("read the vessel file");
    let vessel = Vessel::from_toml_str(&text).expect("a valid vessel file");
    let y0 = vessel.initial_state();
    let method: Method = "sp2".parse().unwrap();
    let mut sys = VesselSystem::new(&vessel, Some(0.0));
    if let Some(lf) = args.get(4) {
        sys = sys.with_linear_flow(lf.parse::<LinearFlow>().expect("a linear flow"));
    }
    let opts = Options {
        t0: 0.0,
        h,
        n_steps: n,
        last_h: h,
        save_every: n,
        outer: args
            .get(5)
            .map(|o| o.parse::<Outer>().expect("an outer flow"))
            .unwrap_or(Outer::Dissipative),
        ledger: true,
        tolerance: None,
    };
    let t = std::time::Instant::now();
    let tr = run(&sys, &method, black_box(y0), &opts).unwrap();
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{path}: {:.3} us per step ({n} steps of {h} s), H_end {:.17e}",
        dt / n as f64 * 1e6,
        tr.energy[tr.energy.len() - 1]
    );
}
