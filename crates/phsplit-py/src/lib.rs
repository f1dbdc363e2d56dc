//! `phsplit._core`: the thin PyO3 layer over `phsplit-core`.
//!
//! It converts values (Python mappings to TOML tables, numpy arrays out), maps the core's
//! errors to Python exceptions, and releases the GIL around every integration. Every option
//! and parameter is parsed and validated by the core. Nothing here panics across the
//! boundary: every fallible call returns `PyResult`, and a panic in the core is caught.

mod capability;
mod convert;
mod fmu;
mod numerics;
mod pipe;
mod run;

use convert::{entries, from_toml, to_table};

use nalgebra::Vector3;
use numpy::{PyArray1, PyReadonlyArray1};
use phsplit_core::lie::so3;
use phsplit_core::methods::{self, Method};
use phsplit_core::model::vessel::{
    LinearFlow, Vessel, VesselState, VesselSystem, PAPER_VESSEL_TOML, STATE_DIM,
};
use phsplit_core::settings::{Settings, KEYS};
use phsplit_core::solve::AccountKind;
use phsplit_core::Error;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use toml::Value;

create_exception!(
    _core,
    PhsplitError,
    PyException,
    "Base class of phsplit's errors."
);
create_exception!(
    _core,
    InvalidInputError,
    PyValueError,
    "A parameter, option or state outside its allowed range (also a ValueError)."
);
create_exception!(
    _core,
    ScenarioParseError,
    InvalidInputError,
    "A parameter or scenario file that cannot be parsed (an InvalidInputError, so also a ValueError)."
);
create_exception!(
    _core,
    IntegrationError,
    PhsplitError,
    "A flow that cannot be evaluated."
);

pub(crate) fn to_py(e: Error) -> PyErr {
    match e {
        Error::InvalidInput(m) => InvalidInputError::new_err(m),
        Error::Parse(m) => ScenarioParseError::new_err(m),
        Error::Domain(m) => IntegrationError::new_err(m),
    }
}

/// A vessel: rigid body, forces and ports, and default initial state (SI units).
#[pyclass(name = "Vessel", module = "phsplit._core", frozen)]
#[derive(Clone)]
pub(crate) struct PyVessel {
    pub(crate) inner: Vessel,
}

#[pymethods]
impl PyVessel {
    /// The paper's vessel and scenario (Appendix D; docs/model.md §4).
    #[staticmethod]
    fn paper() -> Self {
        Self {
            inner: Vessel::paper(),
        }
    }
    /// Parse a vessel from TOML text: [vessel], [control], [initial] and optional components.
    #[staticmethod]
    fn from_toml_str(text: &str) -> PyResult<Self> {
        Ok(Self {
            inner: Vessel::from_toml_str(text).map_err(to_py)?,
        })
    }
    /// Build a vessel from a mapping with the tables of a vessel file.
    #[staticmethod]
    fn from_dict(d: &Bound<'_, PyDict>) -> PyResult<Self> {
        Ok(Self {
            inner: Vessel::from_table(to_table(d, "")?).map_err(to_py)?,
        })
    }
    /// Every parameter as read, as TOML text (the `toml` crate's writer; floats in their
    /// shortest round-trip form, so `from_toml_str(to_toml())` rebuilds the vessel exactly).
    fn to_toml(&self) -> PyResult<String> {
        toml::to_string(&self.inner.params)
            .map_err(|e| PhsplitError::new_err(format!("cannot write TOML: {e}")))
    }
    /// The TOML text of the paper's vessel, with its provenance.
    #[staticmethod]
    fn paper_toml() -> &'static str {
        PAPER_VESSEL_TOML
    }
    /// The shipped vessels: (name, description, vessel file text).
    #[staticmethod]
    fn presets() -> Vec<(&'static str, &'static str, &'static str)> {
        phsplit_core::model::vessel::PRESETS.to_vec()
    }
    /// Every parameter as read (defaults filled in), as a nested dict (SI units).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        from_toml(py, &Value::Table(self.inner.params.clone()))
    }
    /// The 6×6 mass matrix `M = M_RB + M_A` (kg, kg m, kg m^2 blocks; body frame, z up) as
    /// rows: the momenta are `(p, m) = M ν`.
    fn mass_matrix(&self) -> Vec<Vec<f64>> {
        let m = &self.inner.body.mass_matrix;
        (0..6)
            .map(|i| (0..6).map(|j| m[(i, j)]).collect())
            .collect()
    }
    /// The names of the vessel's components, in the order they are assembled.
    fn components(&self) -> Vec<&'static str> {
        self.inner.forces.iter().map(|f| f.name()).collect()
    }
    /// The states the components keep of their own, in the state's layout after the body's 27
    /// numbers: (name, unit, long name, initial value) each.
    fn own_states(&self) -> Vec<(String, String, String, f64)> {
        self.inner
            .own_states()
            .into_iter()
            .map(|o| (o.name, o.unit, o.long_name, o.initial))
            .collect()
    }
    /// The ledger's accounts: (name, "supplied" or "dissipated") per account.
    fn accounts(&self) -> Vec<(&'static str, &'static str)> {
        use phsplit_core::solve::Model;
        VesselSystem::new(&self.inner, None)
            .accounts()
            .iter()
            .map(|a| (a.name, kind_name(a.kind)))
            .collect()
    }
    /// The natural periods (s, ascending) of the oscillating modes of flow S2 linearised at
    /// the attitude of a flat 27-vector `state` (a memory of rate-limited thrusters after it is
    /// allowed), with the controller on or off
    /// (`VesselSystem::natural_periods`).
    #[pyo3(signature = (state, control))]
    fn natural_periods(
        &self,
        state: PyReadonlyArray1<'_, f64>,
        control: bool,
    ) -> PyResult<Vec<f64>> {
        let s = self
            .inner
            .user_state(&entries(&state), true)
            .map_err(to_py)?;
        Ok(VesselSystem::new(&self.inner, None).natural_periods(&s.q, control))
    }
    /// What the components report at a flat 27-vector state and time `t` (the pipe's tension,
    /// the moving set point, ...), with the controller on from `control_start` (None: off):
    /// `{name: value}`.
    #[pyo3(signature = (state, t, control_start=None))]
    fn outputs(
        &self,
        state: PyReadonlyArray1<'_, f64>,
        t: f64,
        control_start: Option<f64>,
    ) -> PyResult<std::collections::BTreeMap<String, f64>> {
        let s = self
            .inner
            .continuing_state(&entries(&state))
            .map_err(to_py)?;
        let sys = VesselSystem::new(&self.inner, control_start);
        Ok(sys
            .outputs(&s, t)
            .into_iter()
            .map(|o| (o.name, o.value))
            .collect())
    }
    /// The stored energy H of eq. (35) at a flat 27-vector state (J; a memory of rate-limited
    /// thrusters after it is allowed: it stores no energy).
    fn energy(&self, state: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
        let s = self
            .inner
            .user_state(&entries(&state), true)
            .map_err(to_py)?;
        Ok(self.inner.energy(&s))
    }
    /// The initial state as a flat 27-vector (p, m, Q column-major, mu, x, phi_th, phi_x),
    /// from engineering variables (defaults: the file's [initial] table).
    #[pyo3(signature = (euler=None, position=None, velocity=None, angular_velocity=None))]
    fn initial_state<'py>(
        &self,
        py: Python<'py>,
        euler: Option<[f64; 3]>,
        position: Option<[f64; 3]>,
        velocity: Option<[f64; 3]>,
        angular_velocity: Option<[f64; 3]>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let i = &self.inner.initial;
        let all = [
            ("euler", euler.unwrap_or(i.euler), "rad"),
            ("position", position.unwrap_or(i.position), "m"),
            ("velocity", velocity.unwrap_or(i.velocity), "m/s"),
            (
                "angular_velocity",
                angular_velocity.unwrap_or(i.angular_velocity),
                "rad/s",
            ),
        ];
        for (name, v, unit) in &all {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(InvalidInputError::new_err(format!(
                    "initial {name} must be finite ({unit}), got {v:?}"
                )));
            }
        }
        let s = self.inner.state_from(
            all[0].1.into(),
            all[1].1.into(),
            all[2].1.into(),
            all[3].1.into(),
        );
        Ok(PyArray1::from_slice(py, s.to_vector().as_slice()))
    }
    fn __repr__(&self) -> String {
        format!(
            "Vessel(mass={:.6e} kg, inertia={:?} kg m^2, components={:?})",
            self.inner.body.mass,
            self.inner.body.inertia.as_slice(),
            self.components()
        )
    }
}

pub(crate) fn kind_name(k: AccountKind) -> &'static str {
    match k {
        AccountKind::Supplied => "supplied",
        AccountKind::Dissipated => "dissipated",
    }
}

/// Settings from a mapping over the defaults. With `api`, a value of the wrong type is an
/// InvalidInputError (a function argument) and names the argument; otherwise a
/// ScenarioParseError naming `simulation.<key>` (a file).
pub(crate) fn settings_of(
    d: &Bound<'_, PyDict>,
    api: bool,
) -> PyResult<(Settings, Option<String>)> {
    let t = to_table(d, if api { "" } else { "simulation" })?;
    Settings::from_table(&t).map_err(|e| match (api, e) {
        (true, Error::Parse(m)) | (true, Error::InvalidInput(m)) => {
            InvalidInputError::new_err(m.replacen("simulation.", "", 1))
        }
        (_, e) => to_py(e),
    })
}

pub(crate) fn settings_dict<'py>(
    py: Python<'py>,
    s: &Settings,
    name: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("t_span", (s.t_span.0, s.t_span.1))?;
    d.set_item("h", s.h)?;
    d.set_item("method", s.method.name())?;
    d.set_item("control_start", s.control_start)?;
    d.set_item("outer", s.outer.name())?;
    d.set_item("save_every", s.save_every)?;
    d.set_item("linear_flow", s.linear_flow.name())?;
    d.set_item("ledger", s.ledger)?;
    d.set_item("project_invariants", s.project_invariants)?;
    d.set_item("rtol", s.rtol)?;
    d.set_item("atol", s.atol)?;
    d.set_item("h_max", s.h_max)?;
    // The tolerance an adaptive run takes (the defaults of a missing one filled in), or None.
    let tol = s.tolerance().ok().flatten();
    d.set_item("tolerance", tol.map(|t| (t.rtol, t.atol, t.h_max)))?;
    let steps = s.steps().ok();
    d.set_item("n_steps", steps.map(|x| x.0))?;
    d.set_item("last_h", steps.map(|x| x.1))?;
    if let Some(n) = name {
        d.set_item("name", n)?;
    }
    Ok(d)
}

/// The default settings of a run (the paper's Fig. 2), as a dict.
#[pyfunction]
fn default_settings(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    settings_dict(py, &Settings::default(), None)
}

/// Parse and validate settings given as a mapping over the defaults; returns them complete,
/// with the step count. `api=False` reads a scenario file's [simulation] table.
#[pyfunction]
#[pyo3(signature = (d, api=true))]
fn check_settings<'py>(
    py: Python<'py>,
    d: &Bound<'py, PyDict>,
    api: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (s, name) = settings_of(d, api)?;
    settings_dict(py, &s, name)
}

/// A user's flat initial state, checked as `integrate` checks it (and projected to a rotation
/// when `orthonormalize`); returns the state the core would start from.
#[pyfunction]
fn check_state<'py>(
    py: Python<'py>,
    state: PyReadonlyArray1<'py, f64>,
    orthonormalize: bool,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    // The 27 numbers are checked here; a tail (the memory of rate-limited thrusters, as
    // `Solution.state(i)` gives it) is kept as it is, for the run to check against its vessel.
    let y = entries(&state);
    let (head, tail) = y.split_at(y.len().min(STATE_DIM));
    let s = VesselState::from_slice_checked(head, orthonormalize).map_err(to_py)?;
    let mut out = s.to_vector().as_slice().to_vec();
    out.extend_from_slice(tail);
    Ok(PyArray1::from_vec(py, out))
}

/// A mapping of TOML values (tables of numbers, strings, booleans, lists) as TOML text, by
/// the `toml` crate's writer: phsplit's one TOML writer.
#[pyfunction]
fn dumps_toml(d: &Bound<'_, PyDict>) -> PyResult<String> {
    let t = to_table(d, "")?;
    toml::to_string(&t).map_err(|e| InvalidInputError::new_err(format!("cannot write TOML: {e}")))
}

/// The physical ranges of length, angle and time keys (`params::physical`): name, unit,
/// low, high, whether each end is allowed, and why the range is where it is.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn physical_ranges() -> Vec<(
    &'static str,
    &'static str,
    f64,
    f64,
    bool,
    bool,
    &'static str,
)> {
    phsplit_core::model::vessel::params::physical::ALL
        .iter()
        .map(|(name, unit, r)| (*name, *unit, r.lo, r.hi, r.lo_closed, r.hi_closed, r.why))
        .collect()
}

/// The keys of a [simulation] table with what each takes.
#[pyfunction]
fn settings_keys() -> Vec<(&'static str, &'static str)> {
    KEYS.to_vec()
}

/// Metadata of a method: name, kind, order, stages, citation, all_positive, subflow_order and
/// the Prop. 2.5 bounds of a splitting.
#[pyfunction]
fn method_info<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
    let m: Method = name.parse().map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("name", m.name())?;
    d.set_item("order", m.order())?;
    d.set_item("stages", m.stages())?;
    d.set_item("citation", m.citation())?;
    d.set_item("all_positive", m.all_positive())?;
    d.set_item("kind", m.kind())?;
    d.set_item("subflow_order", m.subflow_order())?;
    if let Method::Splitting(c) = &m {
        d.set_item(
            "dissipation_ratio_bound_outer",
            c.dissipation_ratio_bound(true),
        )?;
        d.set_item(
            "dissipation_ratio_bound_inner",
            c.dissipation_ratio_bound(false),
        )?;
    }
    Ok(d)
}

/// Euler angles (ZYX: roll, pitch, yaw) of a 3×3 attitude matrix, eq. (21).
#[pyfunction]
fn euler_zyx(q: [[f64; 3]; 3]) -> [f64; 3] {
    let m = nalgebra::Matrix3::from_fn(|i, j| q[i][j]);
    let e: Vector3<f64> = so3::euler_zyx(&m);
    [e.x, e.y, e.z]
}

/// The tables a vessel file may have (the components' and the vessel's own).
#[pyfunction]
fn vessel_tables() -> Vec<&'static str> {
    Vessel::tables()
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    numerics::register(m)?;
    m.add_class::<PyVessel>()?;
    run::register(m)?;
    capability::register(m)?;
    pipe::register(m)?;
    m.add_function(wrap_pyfunction!(method_info, m)?)?;
    m.add_function(wrap_pyfunction!(fmu::fmu_variables, m)?)?;
    m.add_function(wrap_pyfunction!(euler_zyx, m)?)?;
    m.add_function(wrap_pyfunction!(default_settings, m)?)?;
    m.add_function(wrap_pyfunction!(check_settings, m)?)?;
    m.add_function(wrap_pyfunction!(settings_keys, m)?)?;
    m.add_function(wrap_pyfunction!(physical_ranges, m)?)?;
    m.add_function(wrap_pyfunction!(dumps_toml, m)?)?;
    m.add_function(wrap_pyfunction!(check_state, m)?)?;
    m.add_function(wrap_pyfunction!(vessel_tables, m)?)?;
    m.add("METHODS", methods::names())?;
    m.add("OUTER", methods::composition::OUTER_NAMES.to_vec())?;
    m.add(
        "LINEAR_FLOWS",
        LinearFlow::ALL.map(LinearFlow::name).to_vec(),
    )?;
    m.add("MAX_STEPS", phsplit_core::solve::MAX_STEPS)?;
    m.add("STATE_DIM", STATE_DIM)?;
    m.add("PhsplitError", m.py().get_type::<PhsplitError>())?;
    m.add("InvalidInputError", m.py().get_type::<InvalidInputError>())?;
    m.add(
        "ScenarioParseError",
        m.py().get_type::<ScenarioParseError>(),
    )?;
    m.add("IntegrationError", m.py().get_type::<IntegrationError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
