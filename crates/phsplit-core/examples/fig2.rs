//! The paper's Fig. 2 scenario with SP4: prints the end state and the ledger closure.
//! `cargo run --release -p phsplit-core --example fig2 [method] [h]`
use phsplit_core::methods::{Method, Outer};
use phsplit_core::model::vessel::{Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let method = args
        .get(1)
        .map(String::as_str)
        .unwrap_or("sp4")
        .parse::<Method>()
        .unwrap();
    let h: f64 = args.get(2).map(|s| s.parse().unwrap()).unwrap_or(0.5);
    let vessel = Vessel::paper();
    let sys = VesselSystem::new(&vessel, Some(50.0));
    let opts = Options {
        t0: 0.0,
        h,
        n_steps: (200.0 / h).round() as usize,
        last_h: h,
        save_every: 1,
        outer: Outer::Dissipative,
        ledger: true,
    };
    let t0 = std::time::Instant::now();
    let tr = run(&sys, &method, vessel.initial_state(), &opts).unwrap();
    let dt = t0.elapsed();
    let s = tr.states.last().unwrap();
    let e = s.euler();
    println!(
        "{}: {:?} steps={} in {:?}",
        method.name(),
        tr.status,
        tr.steps,
        dt
    );
    println!("x = {:.4} {:.4} {:.4}", s.x[0], s.x[1], s.x[2]);
    println!("euler = {:.5} {:.5} {:.5}", e[0], e[1], e[2]);
    let mut worst: f64 = 0.0;
    for i in 1..tr.t.len() {
        let dh = tr.energy[i] - tr.energy[i - 1];
        let r = dh - (tr.supplied[i] - tr.dissipated[i]);
        let scale = tr.energy[i - 1].abs() + tr.supplied[i].abs() + tr.dissipated[i].abs();
        worst = worst.max(r.abs() / scale);
        if std::env::var("DBG").is_ok() && (i % 20 == 0 || r.abs() / scale > 1e-9) {
            println!(
                "t={:.2} H={:.6e} dH={:.4e} sup={:.4e} dis={:.4e} r={:.3e}",
                tr.t[i], tr.energy[i], dh, tr.supplied[i], tr.dissipated[i], r
            );
        }
    }
    println!(
        "H0 = {:.6e}, H_end = {:.6e}, worst relative ledger residual {:.3e}",
        tr.energy[0],
        tr.energy.last().unwrap(),
        worst
    );
}
