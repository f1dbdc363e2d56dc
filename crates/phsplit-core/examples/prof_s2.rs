use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use std::hint::black_box;
use std::time::Instant;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let vessel = if args.len() > 1 {
        Vessel::from_toml_str(&std::fs::read_to_string(&args[1]).unwrap()).unwrap()
    } else {
        Vessel::preset("osv").unwrap()
    };
    let mut y0 = vessel.initial_state();
    y0.p = vessel.body.mass_matrix.fixed_view::<3, 6>(0, 0)
        * nalgebra::Vector6::new(0.3, 0.2, 0.05, 0.01, 0.01, 0.003);
    y0.m = vessel.body.mass_matrix.fixed_view::<3, 6>(3, 0)
        * nalgebra::Vector6::new(0.3, 0.2, 0.05, 0.01, 0.01, 0.003);
    let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(LinearFlow::Gauss);
    let n = 200000;
    for ledger in [false, true] {
        let t = Instant::now();
        for _ in 0..n {
            let mut s = y0;
            black_box(sys.flow_s2(&mut s, black_box(0.25), 0.0, true, ledger, 1));
        }
        println!(
            "flow_s2 ledger={ledger}: {:.3} us",
            t.elapsed().as_secs_f64() / n as f64 * 1e6
        );
        let t = Instant::now();
        for _ in 0..n {
            black_box(sys.s2_at(black_box(&y0.q), true, ledger));
        }
        println!(
            "s2_at ledger={ledger}: {:.3} us",
            t.elapsed().as_secs_f64() / n as f64 * 1e6
        );
    }
}
