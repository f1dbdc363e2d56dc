//! The FMU exporter's view of the FMU: its variable table, from the same code the FMU's binary
//! serves (`phsplit-fmu`), so `modelDescription.xml` and the binary agree by construction.

use crate::InvalidInputError;
use phsplit_fmu::{Causality, Layout, Type, Val};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The variables of an FMU built from the resource files' texts (`fmu.toml`, and
/// `vessel.toml` for a vessel): a list of dicts with `name`, `vr`, `type` (Real, Boolean,
/// String), `causality` (parameter, input, output), `start` (None for outputs), `unit` and
/// `description`. A vessel or settings the core refuses raise InvalidInputError.
#[pyfunction]
#[pyo3(signature = (fmu_toml, vessel_toml=None))]
pub fn fmu_variables<'py>(
    py: Python<'py>,
    fmu_toml: &str,
    vessel_toml: Option<&str>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let layout = Layout::new(fmu_toml, vessel_toml).map_err(InvalidInputError::new_err)?;
    let mut out = Vec::with_capacity(layout.vars.len());
    for v in &layout.vars {
        let d = PyDict::new(py);
        d.set_item("name", &v.name)?;
        d.set_item("vr", v.vr)?;
        d.set_item(
            "type",
            match v.ty {
                Type::Real => "Real",
                Type::Boolean => "Boolean",
                Type::String => "String",
            },
        )?;
        d.set_item(
            "causality",
            match v.causality {
                Causality::Parameter => "parameter",
                Causality::Input => "input",
                Causality::Output => "output",
            },
        )?;
        match &v.start {
            None => d.set_item("start", py.None())?,
            Some(Val::Real(x)) => d.set_item("start", *x)?,
            Some(Val::Boolean(b)) => d.set_item("start", *b)?,
            Some(Val::String(s)) => d.set_item("start", s)?,
        }
        d.set_item("unit", v.unit)?;
        d.set_item("description", &v.description)?;
        out.push(d);
    }
    Ok(out)
}
