//! The dynamic (lumped-mass) pipe coupled to the paper's vessel (docs/model.md §5.18): the
//! coupled system's ledger, the hang-off point's splitting drift and its correction, and the
//! pipe table's checks.
use phsplit_core::model::vessel::{Vessel, VesselSystem};
use phsplit_core::settings::Settings;
use phsplit_core::solve::{run, Status};

/// The paper's vessel holding station with a 600 m pipe from its stern into 200 m of water
/// (the line of benchmarks/pipe_moordyn.py), its anchor 539 m behind the hang-off point.
fn vessel(pipe: &str) -> Vessel {
    let text = format!(
        "{}\n[pipe]\nmodel = \"lumped_mass\"\nlength = 600.0\nsegments = 30\naxial_stiffness = 3.0e9\nmass = 120.0\ndiameter = 0.3\nwater_depth = 200.0\nhang_off = [-40.0, 0.0, -10.0]\nanchor = [143.8, -4.0]\n{pipe}\n",
        phsplit_core::model::vessel::PAPER_VESSEL_TOML
            .replace("euler_reference = [0.0, 0.0, 0.54]", "euler_reference = [0.0, 0.0, 0.10]")
            .replace("position_reference = [780.0, 20.0, 0.0]", "position_reference = [723.0, 0.0, 0.0]")
    );
    Vessel::from_toml_str(&text).unwrap()
}

struct Hour {
    /// Worst `|ΔH − (supplied − dissipated)| / |H|` over the steps.
    ledger: f64,
    /// The energy the hang-off correction booked (J), and the largest drift (m).
    correction: f64,
    drift: f64,
    /// The account `pipe_on_vessel` plus `vessel_on_pipe` (J): the port's two sides.
    port_sum: f64,
    port: f64,
}

fn hour(v: &Vessel, h: f64) -> Hour {
    let sys = VesselSystem::new(v, Some(0.0));
    let st = Settings {
        t_span: (0.0, 3600.0),
        h,
        method: "sp2".parse().unwrap(),
        control_start: Some(0.0),
        save_every: 1,
        ledger: true,
        ..Settings::default()
    };
    let traj = run(&sys, &st.method, v.initial_state(), &st.options().unwrap()).unwrap();
    assert_eq!(traj.status, Status::Completed, "h = {h}");
    let ledger = (1..traj.t.len())
        .map(|i| {
            let dh = traj.energy[i] - traj.energy[i - 1];
            (dh - (traj.supplied[i] - traj.dissipated[i])).abs() / traj.energy[i].abs()
        })
        .fold(0.0, f64::max);
    let drift = traj
        .states
        .iter()
        .step_by(60)
        .map(|s| {
            sys.outputs(s, 0.0)
                .into_iter()
                .find(|o| o.name == "pipe_hang_off_drift")
                .unwrap()
                .value
        })
        .fold(0.0, f64::max);
    let sum = |name: &str| traj.account(name).unwrap().iter().sum::<f64>();
    Hour {
        ledger,
        correction: sum("pipe_hang_off"),
        drift,
        port_sum: sum("pipe_on_vessel") + sum("vessel_on_pipe"),
        port: sum("pipe_on_vessel").abs(),
    }
}

/// An hour at the vessel's steps (0.25, 0.5 and 1 s, the axial waves' periods being
/// milliseconds): the ledger closes per step to 1e-10 of H with the pipe's storage in H, the
/// hang-off port's two sides cancel, the top stays on the hang-off point within centimetres,
/// and what its correction books falls as h² (docs/model.md §5.18).
#[test]
fn an_hour_at_the_vessels_step_keeps_the_ledger() {
    let v = vessel("");
    let runs: Vec<(f64, Hour)> = [0.25, 0.5, 1.0].iter().map(|&h| (h, hour(&v, h))).collect();
    for (h, r) in &runs {
        println!(
            "h = {h} s: ledger {:.1e} of H per step, hang-off correction {:.3e} J, drift at most {:.2e} m, port {:.3e} J (sides sum to {:.1e})",
            r.ledger, r.correction, r.drift, r.port, r.port_sum
        );
        assert!(r.ledger < 1e-10, "h = {h}: ledger {:e}", r.ledger);
        assert!(
            r.port_sum.abs() <= 1e-9 * r.port.max(1.0),
            "h = {h}: the port's sides differ by {}",
            r.port_sum
        );
        assert!(r.drift < 0.1 * h * h, "h = {h}: drift {} m", r.drift);
    }
    // The slope of the correction's energy in h: 2 (it is the splitting's error).
    let slope = ((runs[2].1.correction / runs[0].1.correction).ln()) / 4f64.ln();
    println!("the correction's energy falls as h^{slope:.2}");
    assert!((slope - 2.0).abs() < 0.3, "slope {slope}");
}

/// Bad pipe tables get one line naming the key.
#[test]
fn bad_pipe_tables_name_the_key() {
    let cases = [
        ("segments = 1", "pipe.segments"),
        ("segments = 2.5", "pipe.segments"),
        ("axial_stiffness = 0.0", "pipe.axial_stiffness"),
        ("axial_stiffness = -3e9", "pipe.axial_stiffness"),
        ("length = 150.0", "pipe.length"),
        ("hang_off = [-40.0, 0.0, -250.0]", "pipe.hang_off"),
        ("mass = 50.0", "pipe.mass"),
        ("anchor = [1.0]", "pipe.anchor"),
        ("drag_normal = -1.0", "pipe.drag_normal"),
        ("axial = \"elastic\"", "pipe.axial"),
        ("bending_stiffness = -1e6", "pipe.bending_stiffness"),
    ];
    for (line, key) in cases {
        let base = format!(
            "{}\n[pipe]\nmodel = \"lumped_mass\"\n",
            phsplit_core::model::vessel::PAPER_VESSEL_TOML
        );
        let mut keys = vec![
            ("length", "600.0"),
            ("segments", "30"),
            ("axial_stiffness", "3.0e9"),
            ("mass", "120.0"),
            ("diameter", "0.3"),
            ("water_depth", "200.0"),
            ("hang_off", "[-40.0, 0.0, -10.0]"),
            ("anchor", "[143.8, -4.0]"),
        ];
        let k = line.split(' ').next().unwrap();
        keys.retain(|(name, _)| *name != k);
        let mut text = base;
        for (name, value) in keys {
            text += &format!("{name} = {value}\n");
        }
        text += line;
        let err = Vessel::from_toml_str(&text).unwrap_err().to_string();
        assert!(err.contains(key), "{line}: {err}");
        assert!(!err.contains('\n'), "{line}: one line: {err}");
    }
}

/// A composition of order 4 is refused with the pipe's flow nested by Strang's rule.
#[test]
fn higher_orders_are_refused_with_the_reason() {
    let v = vessel("");
    let sys = VesselSystem::new(&v, Some(0.0));
    let st = Settings {
        t_span: (0.0, 10.0),
        h: 0.5,
        method: "sp4".parse().unwrap(),
        ..Settings::default()
    };
    let err = run(&sys, &st.method, v.initial_state(), &st.options().unwrap())
        .unwrap_err()
        .to_string();
    assert!(err.contains("Strang") && err.contains("sp2"), "{err}");
}
