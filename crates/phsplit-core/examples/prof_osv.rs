use phsplit_core::methods::{Method, Outer};
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(|s| s.as_str()).unwrap_or("osv");
    let meth = args.get(2).map(|s| s.as_str()).unwrap_or("sp2");
    let project = args.get(3).map(|s| s == "1").unwrap_or(true);
    let n: usize = args.get(4).map(|s| s.parse().unwrap()).unwrap_or(20000);
    let vessel = if name == "paper" {
        Vessel::paper()
    } else if name.ends_with(".toml") {
        Vessel::from_toml_str(&std::fs::read_to_string(name).unwrap()).unwrap()
    } else {
        Vessel::preset(name).unwrap()
    };
    let y0 = vessel.initial_state();
    let sys = VesselSystem::new(&vessel, Some(0.0))
        .with_linear_flow(LinearFlow::Gauss)
        .with_projection(project);
    let method: Method = meth.parse().unwrap();
    let opts = Options {
        t0: 0.0,
        h: 0.5,
        n_steps: n,
        last_h: 0.5,
        save_every: 1000,
        outer: Outer::Dissipative,
        ledger: true,
    };
    let t = Instant::now();
    let tr = run(&sys, &method, y0, &opts).unwrap();
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{name} {meth} project={project}: {:.3} us/step  saved {}",
        dt / n as f64 * 1e6,
        tr.t.len()
    );
}
