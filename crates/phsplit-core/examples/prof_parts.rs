use phsplit_core::flows::rigid_body::MagnusOrder;
use phsplit_core::methods::{Method, Outer};
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Model, Options};
use std::hint::black_box;
use std::time::Instant;
fn main() {
    let vessel = Vessel::preset("osv").unwrap();
    let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(LinearFlow::Gauss);
    let method: Method = "sp2".parse().unwrap();
    let opts = Options {
        t0: 0.0,
        h: 0.5,
        n_steps: 200,
        last_h: 0.5,
        save_every: 200,
        outer: Outer::Dissipative,
        ledger: true,
    };
    let tr = run(&sys, &method, vessel.initial_state(), &opts).unwrap();
    let y = *tr.states.last().unwrap();
    let n = 200000;
    for ledger in [true, false] {
        let t = Instant::now();
        for _ in 0..n {
            let mut s = y;
            black_box(sys.flow_s2(&mut s, black_box(0.25), 100.0, true, ledger, 1));
        }
        println!(
            "S2(h/2) ledger={ledger}: {:.3} us",
            t.elapsed().as_secs_f64() / n as f64 * 1e6
        );
    }
    let t = Instant::now();
    for _ in 0..n {
        let mut s = y;
        sys.flow_s1(&mut s, black_box(0.5), MagnusOrder::Two);
        black_box(s);
    }
    println!(
        "S1(h): {:.3} us",
        t.elapsed().as_secs_f64() / n as f64 * 1e6
    );
    let t = Instant::now();
    for _ in 0..n {
        let mut s = y;
        black_box(Model::project(&sys, &mut s));
        black_box(s);
    }
    println!(
        "project: {:.3} us",
        t.elapsed().as_secs_f64() / n as f64 * 1e6
    );
    let t = Instant::now();
    for _ in 0..n {
        black_box(sys.s2_at(black_box(&y.q), true, true));
    }
    println!(
        "s2_at ledger: {:.3} us",
        t.elapsed().as_secs_f64() / n as f64 * 1e6
    );
    let t = Instant::now();
    for _ in 0..n {
        black_box(Model::energy(&sys, black_box(&y)));
    }
    println!(
        "energy: {:.3} us",
        t.elapsed().as_secs_f64() / n as f64 * 1e6
    );
}
