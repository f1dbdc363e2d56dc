//! A fixed workload for profilers (callgrind, perf): `n` steps of one method on the paper's
//! vessel with the controller on. `cargo build --release --example profile_step` then e.g.
//! `valgrind --tool=callgrind target/release/examples/profile_step sp2 gauss 20000`.
use phsplit_core::methods::{Method, Outer};
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let method = a
        .get(1)
        .map(String::as_str)
        .unwrap_or("sp2")
        .parse::<Method>()
        .expect("method");
    let lf = match a.get(2).map(String::as_str).unwrap_or("gauss") {
        "exact" => LinearFlow::Exact,
        _ => LinearFlow::Gauss,
    };
    let n: usize = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let vessel = Vessel::paper();
    let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(lf);
    let opts = Options {
        t0: 0.0,
        h: 0.1,
        n_steps: n,
        last_h: 0.1,
        save_every: n,
        outer: Outer::Dissipative,
        ledger: false,
    };
    let tr = run(&sys, &method, vessel.initial_state(), &opts).expect("run");
    println!("{:?} {:?}", tr.status, tr.states.last().map(|s| s.x));
}
