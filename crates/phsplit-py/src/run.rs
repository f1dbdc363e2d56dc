//! Integration from Python: the run with its monitor (signals, progress) and the GIL
//! released, and the compiled vector field for external solvers.

use crate::convert::entries;
use crate::{
    kind_name, settings_dict, settings_of, to_py, InvalidInputError, PhsplitError, PyVessel,
};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use phsplit_core::lie::so3;
use phsplit_core::model::vessel::{Vessel, VesselState, VesselSystem, STATE_DIM};
use phsplit_core::solve::{run_watched, Monitor, Status};
use phsplit_core::Error;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Watches a run from Python: about every 0.1 s it takes the GIL, runs Python's signal
/// handlers (Ctrl-C, or SIGTERM where the program turned it into KeyboardInterrupt) and calls
/// the progress callback `f(steps_done, n_steps)`. An exception stops the run; it is kept to be
/// raised (or, for KeyboardInterrupt, reported as an interrupted run) once the GIL is back.
struct PyMonitor {
    progress: Option<Py<PyAny>>,
    n_steps: usize,
    last: std::time::Instant,
    next_check: usize,
    error: Option<PyErr>,
}

impl Monitor for PyMonitor {
    fn keep_going(&mut self, done: usize) -> bool {
        // `done` grows by one a step, or (adaptive steps) by the nominal steps of h covered.
        if done < self.next_check {
            return true;
        }
        self.next_check = done + 256;
        if self.last.elapsed().as_secs_f64() < 0.1 {
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
#[pyo3(signature = (vessel, settings, state0=None, orthonormalize=false, progress=None, extrema=false, continuing=false, save_at=None))]
fn integrate<'py>(
    py: Python<'py>,
    vessel: &PyVessel,
    settings: &Bound<'py, PyDict>,
    state0: Option<PyReadonlyArray1<'_, f64>>,
    orthonormalize: bool,
    progress: Option<Py<PyAny>>,
    extrema: bool,
    continuing: bool,
    save_at: Option<PyReadonlyArray1<'_, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (settings, _) = settings_of(settings, true)?;
    let mut opts = settings.options().map_err(to_py)?;
    // Output times of an adaptive run: its steps land on them (fixed steps: phsplit.events).
    if let Some(ts) = &save_at {
        let Some(tol) = opts.tolerance.as_mut() else {
            return Err(InvalidInputError::new_err(
                "save_at is taken by the core only with adaptive steps (rtol, atol)",
            ));
        };
        tol.save_at = entries(ts);
        tol.validate(opts.t0).map_err(to_py)?;
    }
    let y0 = match &state0 {
        None => vessel.inner.initial_state(),
        Some(a) if continuing => vessel.inner.continuing_state(&entries(a)).map_err(to_py)?,
        Some(a) => vessel
            .inner
            .user_state(&entries(a), orthonormalize)
            .map_err(to_py)?,
    };
    vessel
        .inner
        .check_memory(&y0, settings.t_span.0)
        .map_err(to_py)?;
    let v = vessel.inner.clone();
    let s2 = settings.clone();
    let mut monitor = PyMonitor {
        progress,
        n_steps: opts.n_steps,
        last: std::time::Instant::now(),
        next_check: 256,
        error: None,
    };
    let mon = &mut monitor;
    // A panic in the core (a bug) reaches Python as a PhsplitError, never an abort.
    let out = py
        .detach(move || {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let sys = VesselSystem::new(&v, s2.control_start)
                    .with_linear_flow(s2.linear_flow.for_vessel(&v, s2.adaptive(), &s2.method))
                    .with_projection(s2.project_invariants)
                    .with_extrema(extrema);
                let traj = run_watched(&sys, &s2.method, y0, &opts, mon)?;
                let s2_solver = sys.s2_solver();
                // The force and moment of each account, and the components' outputs, at the
                // saved states: both of one state in turn, so that what a thread keeps of the
                // sea at that time (docs/explanation/fast-sea.md) serves both.
                let (wrenches, outputs): (Vec<_>, Vec<_>) = traj
                    .t
                    .iter()
                    .zip(&traj.states)
                    .map(|(t, s)| {
                        (
                            sys.account_wrenches(s, *t, sys.control_on(*t)),
                            sys.outputs(s, *t),
                        )
                    })
                    .unzip();
                Ok::<_, Error>((traj, wrenches, outputs, s2_solver))
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
    let (traj, wrenches, outputs, s2_solver) = out;
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
    let controls: Vec<&str> = traj
        .accounts
        .iter()
        .filter(|a| a.role == phsplit_core::solve::Role::Control)
        .map(|a| a.name)
        .collect();
    d.set_item("control_accounts", controls)?;
    let booked: Vec<f64> = traj.booked.iter().flat_map(|w| w.values(k)).collect();
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
    // The components' reported quantities: name -> (unit, long name, values at the saved states).
    let reported = PyDict::new(py);
    if let Some(first) = outputs.first() {
        for (k, o) in first.iter().enumerate() {
            let vals: Vec<f64> = outputs.iter().map(|row| row[k].value).collect();
            reported.set_item(
                &o.name,
                (o.unit, &o.long_name, PyArray1::from_vec(py, vals)),
            )?;
        }
    }
    d.set_item("outputs", reported)?;
    d.set_item("steps", traj.steps)?;
    d.set_item("rejected", traj.rejected)?;
    // A state that continues the run: the 27 numbers, the components' own states, then the
    // memory of rate-limited thrusters (none for other vessels).
    d.set_item(
        "last_good",
        PyArray1::from_vec(py, traj.last_good.to_continuing()),
    )?;
    let own = traj.states.first().map_or(0, |s| s.own.len());
    if own > 0 {
        let vals: Vec<f64> = traj.states.iter().flat_map(|s| s.own.clone()).collect();
        d.set_item("own", PyArray1::from_vec(py, vals).reshape([n, own])?)?;
    }
    let width = traj.states.first().map_or(0, |s| s.act.to_flat().len());
    let memory: Vec<f64> = traj.states.iter().flat_map(|s| s.act.to_flat()).collect();
    if width > 0 && memory.len() == n * width {
        d.set_item(
            "actuators",
            PyArray1::from_vec(py, memory).reshape([n, width])?,
        )?;
    }
    d.set_item("t_last_good", traj.t_last_good)?;
    let ext = PyDict::new(py);
    for (k, name) in traj.probe_names.iter().enumerate() {
        ext.set_item(*name, (traj.probe_max[k], traj.probe_max_t[k]))?;
    }
    d.set_item("running_max", ext)?;
    d.set_item("settings", settings_dict(py, &settings, None)?)?;
    // How flow S2 was integrated: the chosen linear flow, or Gauss collocation where S2 has a
    // forcing part (the exact flow cannot act on it).
    d.set_item("s2_solver", s2_solver.name())?;
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
/// Most DOP853 steps per segment: about half a minute on this machine, after which a run that
/// cannot finish (a stiff or blown-up field) is refused instead of running on unwatched.
const MAX_DOP853_STEPS: usize = 10_000_000;

#[pyclass(name = "VectorField", module = "phsplit._core", frozen)]
struct PyVectorField {
    vessel: Vessel,
    control_start: Option<f64>,
}

#[pymethods]
impl PyVectorField {
    #[new]
    #[pyo3(signature = (vessel, control_start=None))]
    fn new(vessel: &PyVessel, control_start: Option<f64>) -> PyResult<Self> {
        // The field is the 27 states' (eq. 39): a vessel whose components keep states of their
        // own, or a memory from step to step, has none that a solver of it could integrate.
        use phsplit_core::solve::Model;
        if let Some(why) = VesselSystem::new(&vessel.inner, control_start).runge_kutta_refused() {
            return Err(InvalidInputError::new_err(format!(
                "no vector field f(t, y) of {STATE_DIM} states for external solvers for this vessel: {why}"
            )));
        }
        Ok(Self {
            vessel: vessel.inner.clone(),
            control_start,
        })
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

    /// Integrate `y' = f(t, y)` over `t_span` from `y0` with DOP853 (E. Hairer, S. P. Nørsett,
    /// G. Wanner, *Solving Ordinary Differential Equations I*, 2nd ed., Springer 1993, §II.10;
    /// the `differential-equations` crate's implementation) at the tolerances `rtol` and `atol`
    /// (a number or one per component), entirely in Rust with the GIL released: the compiled
    /// classical peer of the work-precision study. The controller switch at `control_start` is
    /// a segment boundary. Returns `(y_end, function_evaluations, accepted_steps)`; a solver
    /// error, or more than 10^7 steps in a segment, raises IntegrationError. Only the end point
    /// is stored, or the states at `t_eval` (increasing times within `t_span`, by the method's
    /// dense output) as a flat array of rows; the run is not interruptible (keep it short).
    #[pyo3(signature = (t_span, y0, rtol, atol, t_eval=None))]
    fn solve_dop853<'py>(
        &self,
        py: Python<'py>,
        t_span: (f64, f64),
        y0: PyReadonlyArray1<'_, f64>,
        rtol: f64,
        atol: PyReadonlyArray1<'_, f64>,
        t_eval: Option<PyReadonlyArray1<'_, f64>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, usize, usize)> {
        let t_eval: Vec<f64> = t_eval.map(|a| entries(&a)).unwrap_or_default();
        use differential_equations::prelude::*;
        let y = entries(&y0);
        let a = entries(&atol);
        if y.len() != STATE_DIM || (a.len() != STATE_DIM && a.len() != 1) {
            return Err(InvalidInputError::new_err(format!(
                "y0 must have {STATE_DIM} entries and atol 1 or {STATE_DIM}, got {} and {}",
                y.len(),
                a.len()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(InvalidInputError::new_err(format!(
                "y0 must be finite; entry {i} is {}",
                y[i]
            )));
        }
        if !(rtol > 0.0 && rtol.is_finite() && a.iter().all(|x| *x > 0.0 && x.is_finite())) {
            return Err(InvalidInputError::new_err(
                "rtol and atol must be finite and > 0",
            ));
        }
        let (t0, t1) = t_span;
        if !(t0.is_finite() && t1.is_finite() && t1 > t0) {
            return Err(InvalidInputError::new_err(format!(
                "t_span must be finite with t1 > t0, got ({t0}, {t1})"
            )));
        }
        if t_eval.iter().any(|t| !(*t > t0 && *t <= t1)) || t_eval.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(InvalidInputError::new_err(
                "t_eval must be increasing times in (t0, t1]",
            ));
        }
        struct Segment<'a> {
            sys: VesselSystem<'a>,
            on: bool,
        }
        impl ODE<f64, nalgebra::SVector<f64, STATE_DIM>> for Segment<'_> {
            fn diff(
                &self,
                t: f64,
                y: &nalgebra::SVector<f64, STATE_DIM>,
                dydt: &mut nalgebra::SVector<f64, STATE_DIM>,
            ) {
                *dydt = self
                    .sys
                    .vector_field(&VesselState::from_vector(y), t, self.on)
                    .to_vector();
            }
        }
        let atol_v: Vec<f64> = if a.len() == 1 {
            vec![a[0]; STATE_DIM]
        } else {
            a
        };
        let mut state = nalgebra::SVector::<f64, STATE_DIM>::from_column_slice(&y);
        let vessel = self.vessel.clone();
        let control_start = self.control_start;
        let out = py.detach(move || {
            let sys = VesselSystem::new(&vessel, control_start);
            let mut cuts = vec![t0];
            if let Some(tc) = control_start {
                if tc > t0 && tc < t1 {
                    cuts.push(tc);
                }
            }
            cuts.push(t1);
            let (mut nfev, mut steps) = (0usize, 0usize);
            let mut rows: Vec<f64> = Vec::with_capacity(t_eval.len() * STATE_DIM);
            for w in cuts.windows(2) {
                let seg = Segment {
                    sys: sys.clone(),
                    on: sys.control_on(w[0]),
                };
                let method = ExplicitRungeKutta::dop853()
                    .rtol(rtol)
                    .atol(atol_v.clone())
                    .max_steps(MAX_DOP853_STEPS);
                // Only the end point is kept (the default output stores every step), or the
                // segment's asked times and its end.
                let mut times: Vec<f64> = t_eval
                    .iter()
                    .copied()
                    .filter(|t| *t > w[0] && *t < w[1])
                    .collect();
                times.push(w[1]);
                let sol = IVP::ode(&seg, w[0], w[1], state)
                    .method(method)
                    .t_eval(times.clone())
                    .solve()
                    .map_err(|e| format!("{e:?}"))?;
                state = *sol.y.last().ok_or("no output")?;
                for (t, y) in sol.t.iter().zip(&sol.y) {
                    if t_eval.binary_search_by(|x| x.total_cmp(t)).is_ok() {
                        rows.extend_from_slice(y.as_slice());
                    }
                }
                nfev += sol.evals.function;
                steps += sol.steps.accepted;
            }
            if !t_eval.is_empty() {
                return Ok::<_, String>((rows, nfev, steps));
            }
            Ok::<_, String>((state.as_slice().to_vec(), nfev, steps))
        });
        let (y1, nfev, steps) = out.map_err(crate::IntegrationError::new_err)?;
        Ok((PyArray1::from_vec(py, y1), nfev, steps))
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
        Ok(sys.vector_field(&s, t, sys.control_on(t)).to_vector())
    }
}

pub(crate) fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyVectorField>()?;
    m.add_function(wrap_pyfunction!(integrate, m)?)?;
    Ok(())
}
