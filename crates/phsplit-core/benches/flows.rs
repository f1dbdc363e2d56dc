//! Micro-benchmarks of the core: each flow, the vector field, and one step of every method on
//! the paper's vessel (controller on). Run: `cargo bench -p phsplit-core --bench flows`
//! (or `make bench`); criterion prints the time per call.
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Matrix3, Vector3};
use phsplit_core::flows::rigid_body::MagnusOrder;
use phsplit_core::lie::elliptic::jacobi;
use phsplit_core::methods::{names, Method, Outer};
use phsplit_core::model::vessel::{LinearFlow, Vessel, VesselSystem};
use phsplit_core::solve::{run, Options};
use std::hint::black_box;

/// 1,000 steps of h = 0.05 s (where every method is stable), saving only the last state.
fn thousand_steps(ledger: bool) -> Options {
    Options {
        t0: 0.0,
        h: 0.05,
        n_steps: 1000,
        last_h: 0.05,
        save_every: 1000,
        outer: Outer::Dissipative,
        ledger,
        tolerance: None,
    }
}

fn flows(c: &mut Criterion) {
    let vessel = Vessel::paper();
    let mut y0 = vessel.initial_state();
    y0.m = Vector3::new(2e6, -1e6, 3e6); // a moving body: the elliptic path, not a fixed point
    y0.p = Vector3::new(1e6, 2e5, 0.0);
    let body = vessel.body.free;
    let q0 = Matrix3::identity();
    c.bench_function("jacobi sn cn dn (m = 0.7)", |b| {
        b.iter(|| jacobi(black_box(1.3), black_box(0.7)))
    });
    c.bench_function("free rigid body orbit setup", |b| {
        b.iter(|| body.orbit(black_box(&y0.m)))
    });
    for (name, order) in [
        ("2", MagnusOrder::Two),
        ("4", MagnusOrder::Four),
        ("6", MagnusOrder::Six),
    ] {
        c.bench_function(&format!("flow S1: free rigid body + Magnus {name}"), |b| {
            b.iter(|| body.flow(black_box(&y0.m), black_box(&q0), black_box(0.5), order))
        });
    }
    let sys = VesselSystem::new(&vessel, Some(0.0));
    c.bench_function("vector field (eq. 39)", |b| {
        b.iter(|| sys.vector_field(black_box(&y0), 0.0, true))
    });
    for (name, lf, order) in [
        ("exact", LinearFlow::Exact, 2usize),
        ("gauss s=1", LinearFlow::Gauss, 2),
        ("gauss s=2", LinearFlow::Gauss, 4),
        ("gauss s=3", LinearFlow::Gauss, 6),
    ] {
        let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(lf);
        // Two attitudes in turn: each call assembles flow S2 (a repeated state would be served
        // by the kept assembly, `system/memo.rs`, and measure the solve alone).
        let mut y1 = y0.clone();
        y1.q = nalgebra::Rotation3::from_euler_angles(0.02, -0.01, 0.3).into_inner();
        let states = [y0.clone(), y1];
        for ledger in [false, true] {
            let mut n = 0usize;
            c.bench_function(
                &format!("flow S2: {name}{}", if ledger { " + ledger" } else { "" }),
                |b| {
                    b.iter(|| {
                        n += 1;
                        let mut s = states[n & 1].clone();
                        sys.flow_s2(&mut s, black_box(0.5), 0.0, true, ledger, order.div_ceil(2))
                    })
                },
            );
        }
    }
    // One step of every method, measured as 1,000 steps (h = 0.05 s, where every method is
    // stable, forward Euler included) with decimated saving and the default projection onto
    // the restoring invariant (so no sub-steps merge across steps); the splitting methods also
    // with the ledger.
    for name in names() {
        let method: Method = name.parse().unwrap();
        let variants: &[LinearFlow] = match method {
            Method::Splitting(_) => &[LinearFlow::Exact, LinearFlow::Gauss],
            Method::RungeKutta(_) => &[LinearFlow::Exact],
        };
        for &lf in variants {
            let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(lf);
            let opts = thousand_steps(false);
            let label = match (&method, lf) {
                (Method::RungeKutta(_), _) => format!("1000 steps: {name}"),
                (_, lf) => format!("1000 steps: {name} ({} S2)", lf.name()),
            };
            c.bench_function(&label, |b| {
                b.iter(|| run(&sys, &method, black_box(y0.clone()), &opts).unwrap())
            });
            // With the ledger (a step's cost with every account booked).
            if let Method::Splitting(_) = method {
                let opts = Options {
                    ledger: true,
                    ..opts
                };
                c.bench_function(&format!("{label} + ledger"), |b| {
                    b.iter(|| run(&sys, &method, black_box(y0.clone()), &opts).unwrap())
                });
            }
        }
    }
}

/// One SP2 step of the paper's vessel and of the OSV preset (full added mass, cross-flow drag:
/// the coupled flow S2 with its forcing), with the ledger and the default projection, measured
/// as 1,000 steps of h = 0.05 s: the step costs that the ledger's number of accounts must not
/// raise (docs/model.md §3).
fn vessel_steps(c: &mut Criterion) {
    let method: Method = "sp2".parse().unwrap();
    for name in ["paper", "osv"] {
        let vessel = Vessel::preset(name).unwrap();
        let mut y0 = vessel.initial_state();
        y0.p += Vector3::new(1e5, 2e4, 0.0);
        y0.m += Vector3::new(1e5, -1e5, 3e5);
        for lf in [LinearFlow::Exact, LinearFlow::Gauss] {
            let sys = VesselSystem::new(&vessel, Some(0.0)).with_linear_flow(lf);
            let opts = thousand_steps(true);
            let label = format!("{name}: 1000 steps: sp2 ({lf:?} S2) + ledger");
            c.bench_function(&label, |b| {
                b.iter(|| run(&sys, &method, black_box(y0.clone()), &opts).unwrap())
            });
        }
    }
}

criterion_group! {
    name = vessels;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3)).warm_up_time(std::time::Duration::from_millis(500));
    targets = vessel_steps
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2)).warm_up_time(std::time::Duration::from_millis(500));
    targets = flows
}
criterion_main!(benches, vessels);
