//! `phsplit._core`: the thin PyO3 layer over `phsplit-core`.
//!
//! It converts values (Python mappings to TOML tables, numpy arrays out), maps the core's
//! errors to Python exceptions, and releases the GIL around every integration. Every option
//! and parameter is parsed and validated by the core. Nothing here panics across the
//! boundary: every fallible call returns `PyResult`, and a panic in the core is caught.

mod numerics;

use nalgebra::Vector3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use phsplit_core::lie::so3;
use phsplit_core::methods::{self, Method};
use phsplit_core::model::vessel::{
    LinearFlow, Vessel, VesselState, VesselSystem, PAPER_VESSEL_TOML, STATE_DIM,
};
use phsplit_core::settings::{Settings, KEYS};
use phsplit_core::solve::{run_watched, AccountKind, Monitor, Status};
use phsplit_core::Error;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use toml::{Table, Value};

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

fn to_py(e: Error) -> PyErr {
    match e {
        Error::InvalidInput(m) => InvalidInputError::new_err(m),
        Error::Parse(m) => ScenarioParseError::new_err(m),
        Error::Domain(m) => IntegrationError::new_err(m),
    }
}

/// A Python value as TOML (mappings, sequences, bool, int, float, str); `path` names it in
/// the error.
fn to_toml(obj: &Bound<'_, PyAny>, path: &str) -> PyResult<Value> {
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Boolean(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(Value::Integer(i)),
            Err(_) => Ok(Value::Float(obj.extract()?)),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        return Ok(Value::Float(obj.extract()?));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        return Ok(Value::Table(to_table(d, path)?));
    }
    if obj.is_instance_of::<PyList>()
        || obj.is_instance_of::<PyTuple>()
        || obj.hasattr("__array__")?
    {
        // numpy scalars have __array__ too: a 0-d array is a number.
        if let Ok(x) = obj.extract::<f64>() {
            if !obj.is_instance_of::<PyList>() && !obj.is_instance_of::<PyTuple>() {
                return Ok(Value::Float(x));
            }
        }
        let items: Vec<Bound<'_, PyAny>> = obj.try_iter()?.collect::<PyResult<_>>()?;
        return Ok(Value::Array(
            items
                .iter()
                .enumerate()
                .map(|(i, v)| to_toml(v, &format!("{path}[{i}]")))
                .collect::<PyResult<_>>()?,
        ));
    }
    Err(InvalidInputError::new_err(format!(
        "{path} must be a number, a string, a boolean, a sequence or a mapping, got {}",
        obj.get_type().name()?
    )))
}

fn to_table(d: &Bound<'_, PyDict>, path: &str) -> PyResult<Table> {
    let mut t = Table::new();
    for (k, v) in d.iter() {
        let key: String = k.extract().map_err(|_| {
            InvalidInputError::new_err(format!("the keys of {path} must be strings"))
        })?;
        let sub = if path.is_empty() {
            key.clone()
        } else {
            format!("{path}.{key}")
        };
        t.insert(key, to_toml(&v, &sub)?);
    }
    Ok(t)
}

/// A TOML value as Python (tables → dict, arrays → list).
fn from_toml<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::String(s) => s.into_pyobject(py)?.into_any(),
        Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        Value::Float(f) => f.into_pyobject(py)?.into_any(),
        Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(from_toml(py, x)?)?;
            }
            l.into_any()
        }
        Value::Table(t) => {
            let d = PyDict::new(py);
            for (k, x) in t {
                d.set_item(k, from_toml(py, x)?)?;
            }
            d.into_any()
        }
        Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
    })
}

/// A vessel: rigid body, forces and ports, and default initial state (SI units).
#[pyclass(name = "Vessel", module = "phsplit._core", frozen)]
#[derive(Clone)]
struct PyVessel {
    inner: Vessel,
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
    /// Every parameter as read (defaults filled in), as a nested dict (SI units).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        from_toml(py, &Value::Table(self.inner.params.clone()))
    }
    /// The names of the vessel's components, in the order they are assembled.
    fn components(&self) -> Vec<&'static str> {
        self.inner.forces.iter().map(|f| f.name()).collect()
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
    /// the attitude of a flat 27-vector `state`, with the controller on or off
    /// (`VesselSystem::natural_periods`).
    #[pyo3(signature = (state, control))]
    fn natural_periods(
        &self,
        state: PyReadonlyArray1<'_, f64>,
        control: bool,
    ) -> PyResult<Vec<f64>> {
        let s = VesselState::from_slice_checked(&entries(&state), true).map_err(to_py)?;
        Ok(VesselSystem::new(&self.inner, None).natural_periods(&s.q, control))
    }
    /// The stored energy H of eq. (35) at a flat 27-vector state (J).
    fn energy(&self, state: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
        let s = VesselState::from_slice_checked(&entries(&state), true).map_err(to_py)?;
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

fn kind_name(k: AccountKind) -> &'static str {
    match k {
        AccountKind::Supplied => "supplied",
        AccountKind::Dissipated => "dissipated",
    }
}

/// The entries of a 1-D array, contiguous or strided.
fn entries(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// Settings from a mapping over the defaults. With `api`, a value of the wrong type is an
/// InvalidInputError (a function argument) and names the argument; otherwise a
/// ScenarioParseError naming `simulation.<key>` (a file).
fn settings_of(d: &Bound<'_, PyDict>, api: bool) -> PyResult<(Settings, Option<String>)> {
    let t = to_table(d, if api { "" } else { "simulation" })?;
    Settings::from_table(&t).map_err(|e| match (api, e) {
        (true, Error::Parse(m)) | (true, Error::InvalidInput(m)) => {
            InvalidInputError::new_err(m.replacen("simulation.", "", 1))
        }
        (_, e) => to_py(e),
    })
}

fn settings_dict<'py>(
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
    let s = VesselState::from_slice_checked(&entries(&state), orthonormalize).map_err(to_py)?;
    Ok(PyArray1::from_slice(py, s.to_vector().as_slice()))
}

/// A mapping of TOML values (tables of numbers, strings, booleans, lists) as TOML text, by
/// the `toml` crate's writer: phsplit's one TOML writer.
#[pyfunction]
fn dumps_toml(d: &Bound<'_, PyDict>) -> PyResult<String> {
    let t = to_table(d, "")?;
    toml::to_string(&t).map_err(|e| InvalidInputError::new_err(format!("cannot write TOML: {e}")))
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

/// Watches a run from Python: about every 0.1 s it takes the GIL, runs Python's signal
/// handlers (Ctrl-C, or SIGTERM where the program turned it into KeyboardInterrupt) and calls
/// the progress callback `f(steps_done, n_steps)`. An exception stops the run; it is kept to be
/// raised (or, for KeyboardInterrupt, reported as an interrupted run) once the GIL is back.
struct PyMonitor {
    progress: Option<Py<PyAny>>,
    n_steps: usize,
    last: std::time::Instant,
    error: Option<PyErr>,
}

impl Monitor for PyMonitor {
    fn keep_going(&mut self, done: usize) -> bool {
        if done % 256 != 0 || self.last.elapsed().as_secs_f64() < 0.1 {
            return true;
        }
        self.last = std::time::Instant::now();
        let r = Python::attach(|py| -> PyResult<()> {
            py.check_signals()?;
            if let Some(cb) = &self.progress {
                cb.call1(py, (done, self.n_steps))?;
            }
            Ok(())
        });
        match r {
            Ok(()) => true,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }
}

/// Integrate with the given settings (a mapping over the defaults) from `state0` (a flat
/// 27-vector; None: the vessel's initial state); returns a dict of numpy arrays. The GIL is
/// released while integrating; signals are checked about every 0.1 s, and Ctrl-C returns what
/// was computed with status "interrupted". `progress(steps_done, n_steps)` is called as often.
#[pyfunction]
#[pyo3(signature = (vessel, settings, state0=None, orthonormalize=false, progress=None, extrema=false, continuing=false))]
fn integrate<'py>(
    py: Python<'py>,
    vessel: &PyVessel,
    settings: &Bound<'py, PyDict>,
    state0: Option<PyReadonlyArray1<'_, f64>>,
    orthonormalize: bool,
    progress: Option<Py<PyAny>>,
    extrema: bool,
    continuing: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (settings, _) = settings_of(settings, true)?;
    let opts = settings.options().map_err(to_py)?;
    let y0 = match &state0 {
        None => vessel.inner.initial_state(),
        Some(a) if continuing => VesselState::from_slice_continuing(&entries(a)).map_err(to_py)?,
        Some(a) => VesselState::from_slice_checked(&entries(a), orthonormalize).map_err(to_py)?,
    };
    let v = vessel.inner.clone();
    let s2 = settings.clone();
    let mut monitor = PyMonitor {
        progress,
        n_steps: opts.n_steps,
        last: std::time::Instant::now(),
        error: None,
    };
    let mon = &mut monitor;
    // A panic in the core (a bug) reaches Python as a PhsplitError, never an abort.
    let out = py
        .detach(move || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let sys = VesselSystem::new(&v, s2.control_start)
                    .with_linear_flow(s2.linear_flow)
                    .with_projection(s2.project_invariants)
                    .with_extrema(extrema);
                let traj = run_watched(&sys, &s2.method, y0, &opts, mon)?;
                // The force and moment of each account at the saved states.
                let wrenches: Vec<_> = traj
                    .t
                    .iter()
                    .zip(&traj.states)
                    .map(|(t, s)| sys.account_wrenches(s, sys.control_on(*t)))
                    .collect();
                Ok::<_, Error>((traj, wrenches))
            }))
        })
        .map_err(|p| {
            let msg = p
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "unknown panic".into());
            PhsplitError::new_err(format!("internal error in the phsplit core: {msg}"))
        })?
        .map_err(to_py)?;
    let (traj, wrenches) = out;
    if let Some(e) = monitor.error.take() {
        if !e.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) {
            return Err(e); // an exception of the progress callback, or of a signal handler
        }
    }
    let n = traj.t.len();
    let k = traj.accounts.len();
    let mut cols: [Vec<f64>; 8] = Default::default();
    let mut qmat = Vec::with_capacity(9 * n);
    let mut quat = Vec::with_capacity(4 * n);
    for s in &traj.states {
        for (c, v) in cols
            .iter_mut()
            .zip([s.p, s.m, s.mu, s.x, s.phi_th, s.phi_x, s.euler()])
        {
            c.extend_from_slice(v.as_slice());
        }
        // Q row-major, as numpy expects for a (3, 3) block.
        for i in 0..3 {
            for j in 0..3 {
                qmat.push(s.q[(i, j)]);
            }
        }
        quat.extend_from_slice(so3::quaternion(&s.q).as_slice());
        cols[7].push(so3::orthogonality_defect(&s.q));
    }
    let d = PyDict::new(py);
    let arr3 = |v: &Vec<f64>| PyArray1::from_slice(py, v).reshape([n, 3]);
    d.set_item("t", PyArray1::from_vec(py, traj.t.clone()))?;
    for (i, name) in ["p", "m", "mu", "x", "phi_th", "phi_x", "euler"]
        .iter()
        .enumerate()
    {
        d.set_item(*name, arr3(&cols[i])?)?;
    }
    d.set_item(
        "orthogonality_defect",
        PyArray1::from_vec(py, cols[7].clone()),
    )?;
    d.set_item("Q", PyArray1::from_vec(py, qmat).reshape([n, 3, 3])?)?;
    d.set_item("quaternion", PyArray1::from_vec(py, quat).reshape([n, 4])?)?;
    d.set_item("energy", PyArray1::from_vec(py, traj.energy.clone()))?;
    d.set_item("supplied", PyArray1::from_vec(py, traj.supplied.clone()))?;
    d.set_item(
        "dissipated",
        PyArray1::from_vec(py, traj.dissipated.clone()),
    )?;
    let names: Vec<&str> = traj.accounts.iter().map(|a| a.name).collect();
    let kinds: Vec<&str> = traj.accounts.iter().map(|a| kind_name(a.kind)).collect();
    d.set_item("accounts", names)?;
    d.set_item("account_kinds", kinds)?;
    let booked: Vec<f64> = traj.booked.iter().flat_map(|w| w.0[..k].to_vec()).collect();
    d.set_item("booked", PyArray1::from_vec(py, booked).reshape([n, k])?)?;
    let mut force = Vec::with_capacity(n * k * 3);
    let mut moment = Vec::with_capacity(n * k * 3);
    for w in &wrenches {
        for (f, m) in w {
            force.extend_from_slice(f.as_slice());
            moment.extend_from_slice(m.as_slice());
        }
    }
    d.set_item(
        "account_force",
        PyArray1::from_vec(py, force).reshape([n, k, 3])?,
    )?;
    d.set_item(
        "account_moment",
        PyArray1::from_vec(py, moment).reshape([n, k, 3])?,
    )?;
    d.set_item("steps", traj.steps)?;
    d.set_item(
        "last_good",
        PyArray1::from_slice(py, traj.last_good.to_vector().as_slice()),
    )?;
    d.set_item("t_last_good", traj.t_last_good)?;
    let ext = PyDict::new(py);
    for (k, name) in traj.probe_names.iter().enumerate() {
        ext.set_item(*name, (traj.probe_max[k], traj.probe_max_t[k]))?;
    }
    d.set_item("running_max", ext)?;
    d.set_item("settings", settings_dict(py, &settings, None)?)?;
    match traj.status {
        Status::Completed => d.set_item("status", "completed")?,
        Status::Failed { step, t, reason } => {
            d.set_item("status", "failed")?;
            d.set_item("failure", format!("step {step} (t = {t}): {reason}"))?;
        }
        Status::Interrupted { step, t } => {
            d.set_item("status", "interrupted")?;
            d.set_item(
                "failure",
                format!("interrupted after step {step} (t = {t})"),
            )?;
        }
    }
    Ok(d)
}

/// A compiled right-hand side `f(t, y)` of eq. (39) for external solvers (scipy, CVODE):
/// `y` a flat 27-vector; the controller acts from `control_start` (None: never).
#[pyclass(name = "VectorField", module = "phsplit._core", frozen)]
struct PyVectorField {
    vessel: Vessel,
    control_start: Option<f64>,
}

#[pymethods]
impl PyVectorField {
    #[new]
    #[pyo3(signature = (vessel, control_start=None))]
    fn new(vessel: &PyVessel, control_start: Option<f64>) -> Self {
        Self {
            vessel: vessel.inner.clone(),
            control_start,
        }
    }
    /// `y' = f(t, y)` as a new array.
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        t: f64,
        y: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let d = self.field(t, &y)?;
        Ok(PyArray1::from_slice(py, d.as_slice()))
    }
    /// `f(t, y)` written into `out` (the CVODE calling convention `f(t, y, yp)`).
    fn into(
        &self,
        t: f64,
        y: PyReadonlyArray1<'_, f64>,
        mut out: numpy::PyReadwriteArray1<'_, f64>,
    ) -> PyResult<()> {
        let d = self.field(t, &y)?;
        let o = out
            .as_slice_mut()
            .map_err(|e| InvalidInputError::new_err(e.to_string()))?;
        if o.len() != STATE_DIM {
            return Err(InvalidInputError::new_err(format!(
                "out must have {STATE_DIM} entries, got {}",
                o.len()
            )));
        }
        o.copy_from_slice(d.as_slice());
        Ok(())
    }
}

impl PyVectorField {
    /// The field at a 27-vector, without the finiteness check (solvers probe freely).
    fn field(
        &self,
        t: f64,
        y: &PyReadonlyArray1<'_, f64>,
    ) -> PyResult<nalgebra::SVector<f64, STATE_DIM>> {
        let s = entries(y);
        if s.len() != STATE_DIM {
            return Err(InvalidInputError::new_err(format!(
                "a state is a flat vector of {STATE_DIM} numbers, got {}",
                s.len()
            )));
        }
        let s =
            VesselState::from_vector(&nalgebra::SVector::<f64, STATE_DIM>::from_column_slice(&s));
        let sys = VesselSystem::new(&self.vessel, self.control_start);
        Ok(sys.vector_field(&s, sys.control_on(t)).to_vector())
    }
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
    m.add_class::<PyVectorField>()?;
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    m.add_function(wrap_pyfunction!(method_info, m)?)?;
    m.add_function(wrap_pyfunction!(euler_zyx, m)?)?;
    m.add_function(wrap_pyfunction!(default_settings, m)?)?;
    m.add_function(wrap_pyfunction!(check_settings, m)?)?;
    m.add_function(wrap_pyfunction!(settings_keys, m)?)?;
    m.add_function(wrap_pyfunction!(dumps_toml, m)?)?;
    m.add_function(wrap_pyfunction!(check_state, m)?)?;
    m.add_function(wrap_pyfunction!(vessel_tables, m)?)?;
    m.add("METHODS", methods::names())?;
    m.add("OUTER", methods::composition::OUTER_NAMES.to_vec())?;
    m.add(
        "LINEAR_FLOWS",
        vec![LinearFlow::Exact.name(), LinearFlow::Gauss.name()],
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
