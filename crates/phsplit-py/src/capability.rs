//! What a static DP capability analysis asks of the core (`phsplit.capability`): each ledger
//! account's wrench at a state, the mean of Newman's wave drift for a set of regular
//! components, and the thrust allocation of a demand with chosen thrusters lost. Every number
//! is the core's: the account wrenches of `VesselSystem::account_wrenches`, the drift tables
//! interpolated by `waves::Table::at`, the allocation of `Thrusters::allocate` on the
//! thrusters the vessel file's `[thrusters]` table gives (read by `thrusters::read`).

use crate::convert::entries;
use crate::{to_py, InvalidInputError, PyVessel};
use nalgebra::Vector3;
use numpy::PyReadonlyArray1;
use phsplit_core::model::vessel::forces::thrusters::{self, Thrusters};
use phsplit_core::model::vessel::forces::waves::Table;
use phsplit_core::model::vessel::params::Params;
use phsplit_core::model::vessel::VesselSystem;
use phsplit_core::solve::Model;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use toml::{Table as TomlTable, Value};

/// An account's name, force and moment.
type Wrench = (&'static str, [f64; 3], [f64; 3]);
/// A thruster's kind, position (x, y, z) and thrust limits (max, min).
type Unit = (&'static str, f64, f64, f64, f64, f64);

/// Each ledger account's force and moment (body frame, N and N m) at a flat state and time
/// `t`, with the controller off: `[(name, force, moment)]`.
#[pyfunction]
#[pyo3(signature = (vessel, state, t=0.0))]
fn account_wrenches(
    vessel: &PyVessel,
    state: PyReadonlyArray1<'_, f64>,
    t: f64,
) -> PyResult<Vec<Wrench>> {
    let s = vessel
        .inner
        .continuing_state(&entries(&state))
        .map_err(to_py)?;
    let sys = VesselSystem::new(&vessel.inner, None);
    let names: Vec<&'static str> = sys.accounts().iter().map(|a| a.name).collect();
    Ok(sys
        .account_wrenches(&s, t, false)
        .into_iter()
        .zip(names)
        .map(|((f, m), n)| (n, [f.x, f.y, f.z], [m.x, m.y, m.z]))
        .collect())
}

fn number(v: &Value, what: &str) -> PyResult<f64> {
    match v {
        Value::Float(x) => Ok(*x),
        Value::Integer(i) => Ok(*i as f64),
        _ => Err(InvalidInputError::new_err(format!(
            "{what} must be a number, got {v}"
        ))),
    }
}

fn numbers(t: &TomlTable, key: &str) -> PyResult<Vec<f64>> {
    match t.get(key) {
        Some(Value::Array(a)) => a
            .iter()
            .map(|v| number(v, &format!("waves.{key}")))
            .collect(),
        _ => Err(InvalidInputError::new_err(format!(
            "the vessel's [waves] table has no list `{key}`"
        ))),
    }
}

/// The vessel's drift-coefficient table (`[waves]` `drift_coefficients`), as the core
/// interpolates it; `None` without `[waves]` or without drift coefficients.
fn drift_table(vessel: &PyVessel) -> PyResult<Option<Table<3>>> {
    let Some(Value::Table(w)) = vessel.inner.params.get("waves") else {
        return Ok(None);
    };
    let Some(Value::Array(cube)) = w.get("drift_coefficients") else {
        return Ok(None);
    };
    let frequencies = numbers(w, "rao_frequencies")?;
    let directions: Vec<f64> = numbers(w, "rao_directions")?
        .into_iter()
        .map(f64::to_radians)
        .collect();
    let mut re = Vec::with_capacity(cube.len());
    for row in cube {
        let Value::Array(row) = row else {
            return Err(InvalidInputError::new_err(
                "waves.drift_coefficients must be [direction][frequency][3]",
            ));
        };
        let mut r = Vec::with_capacity(row.len());
        for x in row {
            let Value::Array(x) = x else {
                return Err(InvalidInputError::new_err(
                    "waves.drift_coefficients must be [direction][frequency][3]",
                ));
            };
            if x.len() != 3 {
                return Err(InvalidInputError::new_err(
                    "waves.drift_coefficients must hold 3 values (surge, sway, yaw) per entry",
                ));
            }
            r.push([
                number(&x[0], "waves.drift_coefficients")?,
                number(&x[1], "waves.drift_coefficients")?,
                number(&x[2], "waves.drift_coefficients")?,
            ]);
        }
        re.push(r);
    }
    let im = re.iter().map(|r| vec![[0.0; 3]; r.len()]).collect();
    Ok(Some(Table {
        frequencies,
        directions,
        re,
        im,
    }))
}

/// The mean of the core's wave drift (Newman's approximation, `forces/waves.rs`) on a vessel
/// at heading `heading` (rad) for regular components (`omegas` rad/s, `amplitudes` m,
/// `directions` degrees, spatial, the direction of travel): `(X, Y, N)` in the seakeeping frame,
/// `s_i Σ a_k² |D_i(ω_k, β_k − ψ)|` with `s_i` the sign of `Σ a_k² D_i`. `None` if the vessel
/// has no drift coefficients.
#[pyfunction]
fn mean_wave_drift(
    vessel: &PyVessel,
    heading: f64,
    omegas: Vec<f64>,
    amplitudes: Vec<f64>,
    directions: Vec<f64>,
) -> PyResult<Option<[f64; 3]>> {
    if amplitudes.len() != omegas.len() || directions.len() != omegas.len() {
        return Err(InvalidInputError::new_err(format!(
            "omegas, amplitudes and directions must have one entry per component: got {}, {}, {}",
            omegas.len(),
            amplitudes.len(),
            directions.len()
        )));
    }
    let Some(table) = drift_table(vessel)? else {
        return Ok(None);
    };
    let (lo, hi) = (
        table.frequencies[0],
        table.frequencies[table.frequencies.len() - 1],
    );
    let mut signed = [0.0; 3];
    let mut size = [0.0; 3];
    for k in 0..omegas.len() {
        let w = omegas[k];
        if !(w >= lo * (1.0 - 1e-12) && w <= hi * (1.0 + 1e-12)) {
            return Err(InvalidInputError::new_err(format!(
                "omegas[{k}] = {w} rad/s lies outside the drift table's frequencies [{lo}, {hi}] rad/s"
            )));
        }
        let (d, _) = table.at(w, directions[k].to_radians() - heading);
        let a2 = amplitudes[k] * amplitudes[k];
        for n in 0..3 {
            signed[n] += a2 * d[n];
            size[n] += a2 * d[n].abs();
        }
    }
    Ok(Some(std::array::from_fn(|n| signed[n].signum() * size[n])))
}

/// The vessel's thrusters (its `[thrusters]` table, read by the core), without those in `lost`.
fn thrusters_of(vessel: &PyVessel, lost: &[usize]) -> PyResult<Thrusters> {
    let Some(t) = vessel.inner.params.get("thrusters") else {
        return Err(InvalidInputError::new_err(
            "the vessel has no [thrusters] table: a capability needs the thrusters and their limits",
        ));
    };
    let mut table = TomlTable::new();
    table.insert("thrusters".into(), t.clone());
    let all = thrusters::read(&mut Params::from_table(table))
        .map_err(to_py)?
        .expect("the table is present");
    let n = all.units.len();
    if let Some(bad) = lost.iter().find(|i| **i >= n) {
        return Err(InvalidInputError::new_err(format!(
            "failures: thruster index {bad} does not exist (the vessel has {n} thrusters, 0..{})",
            n - 1
        )));
    }
    if lost.is_empty() {
        return Ok(all);
    }
    let units = all
        .units
        .into_iter()
        .enumerate()
        .filter(|(i, _)| !lost.contains(i))
        .map(|(_, u)| u)
        .collect();
    Thrusters::new(units).map_err(to_py)
}

/// The thrusters of the vessel's `[thrusters]` table, as the core reads them:
/// `[(kind, x, y, z, max_thrust, min_thrust)]`.
#[pyfunction]
fn thruster_units(vessel: &PyVessel) -> PyResult<Vec<Unit>> {
    Ok(thrusters_of(vessel, &[])?
        .units
        .iter()
        .map(|u| {
            (
                u.kind.name(),
                u.position.x,
                u.position.y,
                u.position.z,
                u.max_thrust,
                u.min_thrust,
            )
        })
        .collect())
}

/// The core's allocation of the demand `(X, Y, N)` (body frame, N and N m) on the vessel's
/// thrusters with those in `lost` removed: `{scale, utilisation, delivered, thrust, angle}`
/// (`scale` = 1 inside the capacity). Refused (InvalidInputError) when the remaining thrusters
/// cannot produce surge, sway and yaw independently.
#[pyfunction]
#[pyo3(signature = (vessel, demand, lost=Vec::new()))]
fn allocate<'py>(
    py: Python<'py>,
    vessel: &PyVessel,
    demand: [f64; 3],
    lost: Vec<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let th = thrusters_of(vessel, &lost)?;
    let a = th.allocate(&Vector3::from(demand));
    let d = PyDict::new(py);
    d.set_item("scale", a.scale)?;
    d.set_item("utilisation", a.utilisation)?;
    d.set_item("delivered", [a.delivered.x, a.delivered.y, a.delivered.z])?;
    d.set_item("thrust", a.thrust)?;
    d.set_item("angle", a.angle)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(account_wrenches, m)?)?;
    m.add_function(wrap_pyfunction!(mean_wave_drift, m)?)?;
    m.add_function(wrap_pyfunction!(thruster_units, m)?)?;
    m.add_function(wrap_pyfunction!(allocate, m)?)?;
    Ok(())
}
