//! One SP2 step of a preset vessel with the ledger and the default projection, run `reps` times
//! over 1,000 steps (h = 0.05 s): for counting a step's instructions (`perf stat -e
//! instructions:u`) where timings are too noisy. Run:
//! `cargo run --release -p phsplit-core --example vessel_steps -- osv exact 200` (a preset's
//! name or a vessel file).
use nalgebra::Vector3;
use phsplit_core::methods::{Method, Outer};
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};
use std::hint::black_box;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("paper", |s| s.as_str());
    let lf = match args.get(2).map_or("exact", |s| s.as_str()) {
        "gauss" => LinearFlow::Gauss,
        _ => LinearFlow::Exact,
    };
    let reps: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(100);
    // A preset's name, or a vessel file.
    let vessel = if name.ends_with(".toml") {
        Vessel::from_toml_str(&std::fs::read_to_string(name).unwrap()).unwrap()
    } else {
        Vessel::preset(name).unwrap()
    };
    let mut y0 = vessel.initial_state();
    y0.p += Vector3::new(1e5, 2e4, 0.0);
    y0.m += Vector3::new(1e5, -1e5, 3e5);
    let method: Method = "sp2".parse().unwrap();
    let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(lf);
    let opts = Options {
        t0: 0.0,
        h: 0.05,
        n_steps: 1000,
        last_h: 0.05,
        save_every: 1000,
        outer: Outer::Dissipative,
        ledger: true,
        tolerance: None,
    };
    let t = std::time::Instant::now();
    let mut e = 0.0;
    for _ in 0..reps {
        let tr = run(&sys, &method, black_box(y0.clone()), &opts).unwrap();
        e += tr.energy[tr.energy.len() - 1];
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{name} {lf:?}: {:.3} us per step ({reps} x 1000 steps), H_end sum {e:.17e}",
        dt / reps as f64 * 1e3
    );
}
