//! The dynamic pipe driven at its top alone (`phsplit.pipe.drive`): the lumped-mass line of a
//! vessel file's `[pipe]` table (`model = "lumped_mass"`, `pipe/lumped.rs`) with its top moved
//! along given positions, as a line code is driven with a prescribed fairlead motion (the
//! comparison with MoorDyn, benchmarks/pipe_moordyn.py). Every number is the core's step
//! (`Chain::step` with `Top::Given`).

use crate::{to_py, InvalidInputError, PyVessel};
use nalgebra::Vector3;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use phsplit_core::model::vessel::forces::pipe::{chain::Top, lumped};
use phsplit_core::model::vessel::params::Params;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Drive the vessel's lumped-mass pipe with its top at `tops[i]` (m, spatial) at `times[i]` (s,
/// increasing), from its static shape under `tops[0]`: per time, the top segment's tension
/// and the tension at the top (N, with half a segment's weight), the line's storage (J) and
/// the energy booked since the previous time (J: the work done at the top, the drag's, axial
/// damping's and seabed's dissipation, the current's work), and the node positions at the end.
#[pyfunction]
fn drive_pipe<'py>(
    py: Python<'py>,
    vessel: &PyVessel,
    times: PyReadonlyArray1<'_, f64>,
    tops: PyReadonlyArray2<'_, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let v = &vessel.inner;
    let pipe = match v.params.get("pipe").and_then(|p| p.get("model")) {
        Some(toml::Value::String(m)) if m == "lumped_mass" => {
            lumped::read(&mut Params::from_table(v.params.clone()), &v.body).map_err(to_py)?
        }
        _ => {
            return Err(InvalidInputError::new_err(
                "the vessel has no dynamic pipe to drive: its [pipe] table needs model = \"lumped_mass\"",
            ))
        }
    };
    let t = times.as_slice()?.to_vec();
    let r = tops.as_array();
    if r.ncols() != 3 || r.nrows() != t.len() || t.len() < 2 {
        return Err(InvalidInputError::new_err(format!(
            "tops must have one row of 3 numbers (m, spatial) per time, at least 2 times; got {} times and tops of shape ({}, {})",
            t.len(),
            r.nrows(),
            r.ncols()
        )));
    }
    if t.windows(2).any(|w| !(w[1] > w[0])) || t.iter().any(|x| !x.is_finite()) {
        return Err(InvalidInputError::new_err(
            "times must be finite and increasing (s)",
        ));
    }
    if r.iter().any(|x| !x.is_finite()) {
        return Err(InvalidInputError::new_err("tops must be finite (m)"));
    }
    let c = &pipe.chain;
    let top = |i: usize| Vector3::new(r[(i, 0)], r[(i, 1)], r[(i, 2)]);
    let nodes = c
        .static_shape(&top(0))
        .map_err(InvalidInputError::new_err)?;
    let mut x = vec![0.0; c.dim()];
    x[..3].copy_from_slice(top(0).as_slice());
    for (i, q) in nodes.iter().enumerate() {
        x[3 + 3 * i..6 + 3 * i].copy_from_slice(q.as_slice());
    }
    let n = t.len();
    let mut seg = vec![0.0; n];
    let mut at_top = vec![0.0; n];
    let mut storage = vec![0.0; n];
    let mut books: [Vec<f64>; 5] = std::array::from_fn(|_| vec![0.0; n]);
    let record = |i: usize, x: &[f64], seg: &mut [f64], at_top: &mut [f64], st: &mut [f64]| {
        seg[i] = c.tension((c.node(x, 1) - c.node(x, 0)).norm());
        at_top[i] = c.top_force(x).norm();
        st[i] = c.storage(x);
    };
    record(0, &x, &mut seg, &mut at_top, &mut storage);
    for i in 1..n {
        let w = c
            .step(&mut x, t[i] - t[i - 1], &Top::Given(top(i)))
            .ok_or_else(|| {
                InvalidInputError::new_err(format!(
                    "the pipe's implicit step from t = {} s to {} s did not converge: its nodes move too far within the step; take shorter steps",
                    t[i - 1], t[i]
                ))
            })?;
        for (b, e) in books
            .iter_mut()
            .zip([w.top, w.drag, w.axial, w.seabed, w.current])
        {
            b[i] = e;
        }
        record(i, &x, &mut seg, &mut at_top, &mut storage);
    }
    let out = PyDict::new(py);
    out.set_item("segment_tension", seg)?;
    out.set_item("top_tension", at_top)?;
    out.set_item("storage", storage)?;
    for (k, b) in ["top_work", "drag", "axial_damping", "seabed", "current"]
        .iter()
        .zip(books)
    {
        out.set_item(*k, b)?;
    }
    let nodes: Vec<[f64; 3]> = (0..=c.segments)
        .map(|i| {
            let q = c.node(&x, i);
            [q.x, q.y, q.z]
        })
        .collect();
    out.set_item("nodes", nodes)?;
    Ok(out)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(drive_pipe, m)?)?;
    Ok(())
}
