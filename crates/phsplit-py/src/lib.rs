//! `phsplit._core`: the thin PyO3 layer over `phsplit-core`.
//!
//! One error conversion (core `Error` → a Python exception class per variant), newtype
//! `#[pyclass]` wrappers, numpy arrays out, and the GIL released around every integration.
//! Nothing here panics across the boundary: every fallible call returns `PyResult`.

use nalgebra::Vector3;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use phsplit_core::integrate::{run, Options, Status};
use phsplit_core::methods::{Method, Outer, METHOD_NAMES};
use phsplit_core::so3;
use phsplit_core::vessel::{
    LinearFlow, Vessel, VesselState, VesselSystem, PAPER_VESSEL_TOML, STATE_DIM,
};
use phsplit_core::Error;
use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

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
    PyValueError,
    "A parameter or scenario file that cannot be parsed (also a ValueError)."
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
        e @ Error::Integration { .. } => IntegrationError::new_err(e.to_string()),
    }
}

/// A vessel: hull data, PID controller and default initial state (SI units).
#[pyclass(name = "Vessel", module = "phsplit._core", frozen)]
#[derive(Clone)]
struct PyVessel {
    inner: Vessel,
}

fn v3(a: [f64; 3]) -> [f64; 3] {
    a
}

#[pymethods]
impl PyVessel {
    /// The paper's vessel and scenario (Appendix D as reconstructed in MODEL.md §3).
    #[staticmethod]
    fn paper() -> Self {
        Self {
            inner: Vessel::paper(),
        }
    }
    /// Parse a vessel from TOML text with sections [vessel], [control], [initial].
    #[staticmethod]
    fn from_toml_str(text: &str) -> PyResult<Self> {
        Ok(Self {
            inner: Vessel::from_toml_str(text).map_err(to_py)?,
        })
    }
    /// The TOML text of the paper's vessel, with its provenance.
    #[staticmethod]
    fn paper_toml() -> &'static str {
        PAPER_VESSEL_TOML
    }
    /// All parameters as a nested dict (SI units).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let v = &self.inner;
        let hull = PyDict::new(py);
        hull.set_item("mass", v.hull.mass)?;
        hull.set_item("inertia", v3(v.hull.inertia))?;
        hull.set_item("damping_translational", v.hull.damping_translational)?;
        hull.set_item("damping_rotational", v.hull.damping_rotational)?;
        hull.set_item("gm_transverse", v.hull.gm_transverse)?;
        hull.set_item("gm_longitudinal", v.hull.gm_longitudinal)?;
        hull.set_item("gravity", v.hull.gravity)?;
        hull.set_item("water_density", v.hull.water_density)?;
        hull.set_item("waterplane_area", v.hull.waterplane_area)?;
        let c = &v.control;
        let control = PyDict::new(py);
        control.set_item("kp_translational", c.kp_translational)?;
        control.set_item("kd_translational", c.kd_translational)?;
        control.set_item("ki_translational", c.ki_translational)?;
        control.set_item("kp_rotational", c.kp_rotational)?;
        control.set_item("kd_rotational", c.kd_rotational)?;
        control.set_item("ki_rotational", c.ki_rotational)?;
        control.set_item("euler_reference", c.euler_reference)?;
        control.set_item("position_reference", c.position_reference)?;
        let i = &v.initial;
        let initial = PyDict::new(py);
        initial.set_item("euler", i.euler)?;
        initial.set_item("position", i.position)?;
        initial.set_item("velocity", i.velocity)?;
        initial.set_item("angular_velocity", i.angular_velocity)?;
        let d = PyDict::new(py);
        d.set_item("vessel", hull)?;
        d.set_item("control", control)?;
        d.set_item("initial", initial)?;
        Ok(d)
    }
    /// The stored energy H of eq. (35) at a flat 27-vector state (J).
    fn energy(&self, state: PyReadonlyArray1<'_, f64>) -> PyResult<f64> {
        Ok(self.inner.energy(&flat_state(&state)?))
    }
    /// The initial state as a flat 27-vector (p, m, Q column-major, mu, x, phi_th, phi_x),
    /// from engineering variables (defaults: the file's [initial] section).
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
            "Vessel(mass={:.6e} kg, inertia={:?} kg m^2)",
            self.inner.hull.mass, self.inner.hull.inertia
        )
    }
}

/// The entries of a 1-D array, contiguous or strided.
fn entries(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

fn flat_state(a: &PyReadonlyArray1<'_, f64>) -> PyResult<VesselState> {
    let s = &entries(a)[..];
    if s.len() != STATE_DIM {
        return Err(InvalidInputError::new_err(format!(
            "a state is a flat vector of {STATE_DIM} numbers (p, m, Q column-major, mu, x, phi_th, phi_x), got {}",
            s.len()
        )));
    }
    if s.iter().any(|v| !v.is_finite()) {
        return Err(InvalidInputError::new_err(
            "the initial state must be finite",
        ));
    }
    Ok(VesselState::from_vector(
        &nalgebra::SVector::<f64, STATE_DIM>::from_column_slice(s),
    ))
}

/// Metadata of a method: order, stages, citation, all_positive, kind.
#[pyfunction]
fn method_info<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyDict>> {
    let m = Method::by_name(name).map_err(to_py)?;
    let d = PyDict::new(py);
    d.set_item("name", m.name())?;
    d.set_item("order", m.order())?;
    d.set_item("stages", m.stages())?;
    d.set_item("citation", m.citation())?;
    d.set_item("all_positive", m.all_positive())?;
    d.set_item(
        "kind",
        match m {
            Method::Splitting(_) => "splitting",
            Method::RungeKutta(_) => "runge-kutta",
        },
    )?;
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

/// Integrate; returns a dict of numpy arrays. The GIL is released while integrating.
#[pyfunction]
#[pyo3(signature = (vessel, t0, h, n_steps, method, control_start, outer, save_every, ledger, state0, linear_flow="exact", orthonormalize=false))]
#[allow(clippy::too_many_arguments)]
fn integrate<'py>(
    py: Python<'py>,
    vessel: &PyVessel,
    t0: f64,
    h: f64,
    n_steps: usize,
    method: &str,
    control_start: Option<f64>,
    outer: &str,
    save_every: usize,
    ledger: bool,
    state0: PyReadonlyArray1<'_, f64>,
    linear_flow: &str,
    orthonormalize: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let method = Method::by_name(method).map_err(to_py)?;
    let linear = match linear_flow {
        "exact" => LinearFlow::Exact,
        "gauss" => LinearFlow::Gauss,
        other => {
            return Err(InvalidInputError::new_err(format!(
                "linear_flow must be 'exact' (matrix exponential) or 'gauss' (Gauss collocation / diagonal Padé), got {other:?}"
            )))
        }
    };
    let order = method.order();
    let outer = match outer {
        "dissipative" | "S2" | "s2" => Outer::Dissipative,
        "conservative" | "S1" | "s1" => Outer::Conservative,
        other => {
            return Err(InvalidInputError::new_err(format!(
                "outer must be 'dissipative' (S2 outermost) or 'conservative' (S1 outermost), got {other:?}"
            )))
        }
    };
    if let Some(tc) = control_start {
        if !tc.is_finite() {
            return Err(InvalidInputError::new_err(format!(
                "control_start must be finite (s) or None, got {tc}"
            )));
        }
    }
    let mut y0 = flat_state(&state0)?;
    if orthonormalize {
        y0.q = so3::orthonormalize(&y0.q);
        if !y0.q.iter().all(|v| v.is_finite()) {
            return Err(InvalidInputError::new_err(
                "the initial attitude Q cannot be projected to a rotation (it is zero or not finite)",
            ));
        }
    } else if so3::orthogonality_defect(&y0.q) > 1e-9 || y0.q.determinant() < 0.0 {
        return Err(InvalidInputError::new_err(format!(
            "the initial attitude Q is not a rotation: ‖QᵀQ − I‖ = {:.3e}, det Q = {:.6} (allowed: ‖QᵀQ − I‖ ≤ 1e-9, det Q = 1); pass orthonormalize=True to project it to the nearest rotation",
            so3::orthogonality_defect(&y0.q),
            y0.q.determinant()
        )));
    }
    let opts = Options {
        t0,
        h,
        n_steps,
        save_every,
        outer,
        ledger,
    };
    let v = vessel.inner.clone();
    // A panic in the core (a bug) reaches Python as a PhsplitError, never an abort.
    let traj = py
        .detach(move || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let sys = VesselSystem::new(&v, control_start).with_linear_flow(linear, order);
                run(&sys, &method, y0, &opts)
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
    let n = traj.t.len();
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
        let q = so3::quaternion(&s.q);
        quat.extend_from_slice(q.as_slice());
        cols[7].push(so3::orthogonality_defect(&s.q));
    }
    let d = PyDict::new(py);
    let arr3 = |v: &Vec<f64>| PyArray1::from_slice(py, v).reshape([n, 3]);
    d.set_item("t", PyArray1::from_vec(py, traj.t.clone()))?;
    for (k, name) in ["p", "m", "mu", "x", "phi_th", "phi_x", "euler"]
        .iter()
        .enumerate()
    {
        d.set_item(*name, arr3(&cols[k])?)?;
    }
    d.set_item(
        "orthogonality_defect",
        PyArray1::from_vec(py, cols[7].clone()),
    )?;
    d.set_item("Q", PyArray1::from_vec(py, qmat).reshape([n, 3, 3])?)?;
    d.set_item("quaternion", PyArray1::from_vec(py, quat).reshape([n, 4])?)?;
    d.set_item("energy", PyArray1::from_vec(py, traj.energy))?;
    d.set_item("supplied", PyArray1::from_vec(py, traj.supplied))?;
    d.set_item("dissipated", PyArray1::from_vec(py, traj.dissipated))?;
    d.set_item("steps", traj.steps)?;
    d.set_item(
        "last_good",
        PyArray1::from_slice(py, traj.last_good.to_vector().as_slice()),
    )?;
    d.set_item("t_last_good", traj.t_last_good)?;
    match traj.status {
        Status::Completed => d.set_item("status", "completed")?,
        Status::Failed { step, t, reason } => {
            d.set_item("status", "failed")?;
            d.set_item("failure", format!("step {step} (t = {t}): {reason}"))?;
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
        let s = state_any(&y)?;
        let sys = VesselSystem::new(&self.vessel, self.control_start);
        let d = sys.vector_field(&s, sys.control_on(t)).to_vector();
        Ok(PyArray1::from_slice(py, d.as_slice()))
    }
    /// `f(t, y)` written into `out` (the CVODE calling convention `f(t, y, yp)`).
    fn into(
        &self,
        t: f64,
        y: PyReadonlyArray1<'_, f64>,
        mut out: numpy::PyReadwriteArray1<'_, f64>,
    ) -> PyResult<()> {
        let s = state_any(&y)?;
        let sys = VesselSystem::new(&self.vessel, self.control_start);
        let d = sys.vector_field(&s, sys.control_on(t)).to_vector();
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

/// A 27-vector state without the finiteness check (solvers probe freely).
fn state_any(a: &PyReadonlyArray1<'_, f64>) -> PyResult<VesselState> {
    let s = &entries(a)[..];
    if s.len() != STATE_DIM {
        return Err(InvalidInputError::new_err(format!(
            "a state is a flat vector of {STATE_DIM} numbers, got {}",
            s.len()
        )));
    }
    Ok(VesselState::from_vector(
        &nalgebra::SVector::<f64, STATE_DIM>::from_column_slice(s),
    ))
}

/// Euler angles (ZYX: roll, pitch, yaw) of a 3×3 attitude matrix, eq. (21).
#[pyfunction]
fn euler_zyx(q: [[f64; 3]; 3]) -> [f64; 3] {
    let m = nalgebra::Matrix3::from_fn(|i, j| q[i][j]);
    let e: Vector3<f64> = so3::euler_zyx(&m);
    [e.x, e.y, e.z]
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyVessel>()?;
    m.add_class::<PyVectorField>()?;
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    m.add_function(wrap_pyfunction!(method_info, m)?)?;
    m.add_function(wrap_pyfunction!(euler_zyx, m)?)?;
    m.add("METHODS", METHOD_NAMES.to_vec())?;
    m.add("MAX_STEPS", phsplit_core::integrate::MAX_STEPS)?;
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
