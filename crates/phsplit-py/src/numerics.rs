//! The core's numerics for Python: Jacobi elliptic functions and elliptic integrals
//! (`phsplit.special`), the exact free rigid body (`phsplit.rigid_body`) and SO(3)
//! (`phsplit.so3`).
//!
//! Thin by design: every function takes flat, contiguous float64 arrays of equal length (the
//! Python wrappers broadcast and reshape), loops over the core with the GIL released, and
//! returns flat arrays. Input outside a function's domain raises `phsplit.InvalidInputError`
//! naming the argument, the allowed range and the first offending value; NaN inputs give NaN
//! outputs (numpy's convention).

use nalgebra::{Matrix3, Vector3};
use numpy::{PyArray1, PyReadonlyArray1};
use phsplit_core::flows::rigid_body::{FreeRigidBody, MagnusOrder};
use phsplit_core::lie::{elliptic, so3};
use pyo3::prelude::*;
use pyo3::types::PyType;

/// `phsplit._core.InvalidInputError(msg)`, looked up when raised (the exception is defined by
/// the module that registers these functions).
fn invalid(py: Python<'_>, msg: String) -> PyErr {
    match py
        .import("phsplit._core")
        .and_then(|m| m.getattr("InvalidInputError"))
        .and_then(|e| e.cast_into::<PyType>().map_err(PyErr::from))
    {
        Ok(ty) => PyErr::from_type(ty, msg),
        Err(_) => pyo3::exceptions::PyValueError::new_err(msg),
    }
}

fn vec_of(a: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    a.as_array().iter().copied().collect()
}

/// Equal lengths, or an error naming both.
fn same_len(py: Python<'_>, what: &str, a: usize, b: usize) -> PyResult<()> {
    if a == b {
        Ok(())
    } else {
        Err(invalid(
            py,
            format!("{what}: the arrays must have equal lengths, got {a} and {b}"),
        ))
    }
}

// ------------------------------------------------------------------------------------------
// special

type Arrays4<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// `(sn, cn, dn, ph)(u | m)` elementwise over equal-length float64 arrays; `ph = am u`.
/// Every finite `m` (m < 0 and m > 1 by the modulus transformations); `u` finite.
#[pyfunction]
fn special_ellipj<'py>(
    py: Python<'py>,
    u: PyReadonlyArray1<'py, f64>,
    m: PyReadonlyArray1<'py, f64>,
) -> PyResult<Arrays4<'py>> {
    let (u, m) = (vec_of(&u), vec_of(&m));
    same_len(py, "ellipj(u, m)", u.len(), m.len())?;
    let out = py.detach(move || {
        let mut out = [
            Vec::with_capacity(u.len()),
            Vec::with_capacity(u.len()),
            Vec::with_capacity(u.len()),
            Vec::with_capacity(u.len()),
        ];
        for (&x, &p) in u.iter().zip(&m) {
            let v = if x.is_nan() || p.is_nan() {
                (f64::NAN, f64::NAN, f64::NAN, f64::NAN)
            } else if !x.is_finite() {
                return Err(format!("ellipj(u, m): u must be finite, got u = {x}"));
            } else if !p.is_finite() {
                return Err(format!("ellipj(u, m): m must be finite, got m = {p}"));
            } else {
                elliptic::try_jacobi_am(x, p).map_err(|e| format!("ellipj(u, m): {e}"))?
            };
            out[0].push(v.0);
            out[1].push(v.1);
            out[2].push(v.2);
            out[3].push(v.3);
        }
        Ok(out)
    });
    let [s, c, d, a] = out.map_err(|e| invalid(py, e))?;
    Ok((
        PyArray1::from_vec(py, s),
        PyArray1::from_vec(py, c),
        PyArray1::from_vec(py, d),
        PyArray1::from_vec(py, a),
    ))
}

/// `K(m)` elementwise; `m ≤ 1` (`K(1) = inf`, `K(−inf) = 0`).
#[pyfunction]
fn special_ellipk<'py>(
    py: Python<'py>,
    m: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let m = vec_of(&m);
    let out = py.detach(move || {
        m.iter()
            .map(|&p| {
                if p.is_nan() {
                    Ok(f64::NAN)
                } else if p > 1.0 {
                    Err(format!(
                        "ellipk(m): m must be ≤ 1 (K is complex above 1), got m = {p}"
                    ))
                } else {
                    elliptic::ellipk(p).map_err(|e| format!("ellipk(m): {e}"))
                }
            })
            .collect::<Result<Vec<f64>, String>>()
    });
    Ok(PyArray1::from_vec(py, out.map_err(|e| invalid(py, e))?))
}

/// `K(1 − p)` elementwise from the complementary parameter `p = 1 − m ≥ 0`.
#[pyfunction]
fn special_ellipkm1<'py>(
    py: Python<'py>,
    p: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let p = vec_of(&p);
    let out = py.detach(move || {
        p.iter()
            .map(|&x| {
                if x.is_nan() {
                    Ok(f64::NAN)
                } else {
                    elliptic::ellipk_m1(x)
                        .map_err(|_| format!("ellipkm1(p): p = 1 − m must be ≥ 0, got p = {x}"))
                }
            })
            .collect::<Result<Vec<f64>, String>>()
    });
    Ok(PyArray1::from_vec(py, out.map_err(|e| invalid(py, e))?))
}

/// `F(φ | m)` elementwise over equal-length arrays, where it is real.
#[pyfunction]
fn special_ellipkinc<'py>(
    py: Python<'py>,
    phi: PyReadonlyArray1<'py, f64>,
    m: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (phi, m) = (vec_of(&phi), vec_of(&m));
    same_len(py, "ellipkinc(phi, m)", phi.len(), m.len())?;
    let out = py.detach(move || {
        phi.iter()
            .zip(&m)
            .map(|(&f, &p)| {
                if f.is_nan() || p.is_nan() {
                    Ok(f64::NAN)
                } else if !f.is_finite() {
                    Err(format!(
                        "ellipkinc(phi, m): phi must be finite, got phi = {f}"
                    ))
                } else if !p.is_finite() {
                    Err(format!("ellipkinc(phi, m): m must be finite, got m = {p}"))
                } else {
                    elliptic::ellipf(f, p).map_err(|e| format!("ellipkinc(phi, m): {e}"))
                }
            })
            .collect::<Result<Vec<f64>, String>>()
    });
    Ok(PyArray1::from_vec(py, out.map_err(|e| invalid(py, e))?))
}

// ------------------------------------------------------------------------------------------
// rigid_body

fn magnus(py: Python<'_>, order: usize) -> PyResult<MagnusOrder> {
    match order {
        2 => Ok(MagnusOrder::Two),
        4 => Ok(MagnusOrder::Four),
        6 => Ok(MagnusOrder::Six),
        _ => Err(invalid(
            py,
            format!("magnus_order must be 2, 4 or 6, got {order}"),
        )),
    }
}

fn vector3(py: Python<'_>, what: &str, v: &[f64]) -> PyResult<Vector3<f64>> {
    if v.len() != 3 {
        return Err(invalid(
            py,
            format!("{what} must have 3 components, got {}", v.len()),
        ));
    }
    if !v.iter().all(|x| x.is_finite()) {
        return Err(invalid(py, format!("{what} must be finite, got {v:?}")));
    }
    Ok(Vector3::new(v[0], v[1], v[2]))
}

/// The free rigid body `m' = m × T⁻¹m`, `Q' = Q hat(T⁻¹m)` with principal inertias `T`
/// (paper eq. 40, flow S1): the exact momentum and a Magnus attitude.
#[pyclass(name = "FreeRigidBody", module = "phsplit._core", frozen)]
struct PyFreeRigidBody {
    inner: FreeRigidBody,
}

#[pymethods]
impl PyFreeRigidBody {
    #[new]
    fn new(py: Python<'_>, inertia: PyReadonlyArray1<'_, f64>) -> PyResult<Self> {
        let v = vec_of(&inertia);
        if v.len() != 3 {
            return Err(invalid(
                py,
                format!(
                    "inertia must have 3 components (T1, T2, T3), got {}",
                    v.len()
                ),
            ));
        }
        FreeRigidBody::new(Vector3::new(v[0], v[1], v[2]))
            .map(|inner| Self { inner })
            .map_err(|e| invalid(py, e.to_string()))
    }

    /// The principal inertias.
    #[getter]
    fn inertia(&self) -> [f64; 3] {
        let v = self.inner.inertia();
        [v.x, v.y, v.z]
    }

    /// Exact momenta: `m0` is `n × 3` (flat, row-major) or one row for all times, `t` has `n`
    /// entries; returns `n × 3` flat.
    fn momentum<'py>(
        &self,
        py: Python<'py>,
        m0: PyReadonlyArray1<'py, f64>,
        t: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let (m0, t) = (vec_of(&m0), vec_of(&t));
        if m0.len() % 3 != 0 || !(m0.len() == 3 || m0.len() == 3 * t.len()) {
            return Err(invalid(
                py,
                format!(
                    "momentum(m0, t): m0 must be 3 values or 3 per time, got {} values for {} times",
                    m0.len(),
                    t.len()
                ),
            ));
        }
        if let Some(x) = m0.iter().find(|x| !x.is_finite()) {
            return Err(invalid(
                py,
                format!("momentum(m0, t): m0 must be finite, got {x}"),
            ));
        }
        if let Some(x) = t.iter().find(|x| x.is_infinite()) {
            return Err(invalid(
                py,
                format!("momentum(m0, t): t must be finite, got {x}"),
            ));
        }
        let body = self.inner;
        let out = py.detach(move || {
            let mut out = Vec::with_capacity(3 * t.len());
            let single = (m0.len() == 3).then(|| body.orbit(&Vector3::new(m0[0], m0[1], m0[2])));
            for (i, &ti) in t.iter().enumerate() {
                let m = match &single {
                    Some(o) => o.momentum(ti),
                    None => body
                        .orbit(&Vector3::new(m0[3 * i], m0[3 * i + 1], m0[3 * i + 2]))
                        .momentum(ti),
                };
                let m = if ti.is_nan() {
                    Vector3::from_element(f64::NAN)
                } else {
                    m
                };
                out.extend_from_slice(m.as_slice());
            }
            out
        });
        Ok(PyArray1::from_vec(py, out))
    }

    /// One exact flow over `h`: `(m(h), Q(h))` from `(m0, Q0)` with a Magnus attitude of order
    /// 2, 4 or 6. `q0` is the 9 entries of `Q0`, row-major; returns `(m, Q row-major)`.
    fn flow(
        &self,
        py: Python<'_>,
        m0: PyReadonlyArray1<'_, f64>,
        q0: PyReadonlyArray1<'_, f64>,
        h: f64,
        magnus_order: usize,
    ) -> PyResult<([f64; 3], [f64; 9])> {
        let m0 = vector3(py, "flow: m0", &vec_of(&m0))?;
        let q = vec_of(&q0);
        if q.len() != 9 || !q.iter().all(|x| x.is_finite()) {
            return Err(invalid(
                py,
                format!("flow: Q0 must be a finite 3 × 3 matrix, got {q:?}"),
            ));
        }
        if !h.is_finite() {
            return Err(invalid(py, format!("flow: h must be finite, got {h}")));
        }
        let q0 = Matrix3::from_row_slice(&q);
        let order = magnus(py, magnus_order)?;
        let (m, q) = self.inner.flow(&m0, &q0, h, order);
        let mut qr = [0.0; 9];
        for i in 0..3 {
            for j in 0..3 {
                qr[3 * i + j] = q[(i, j)];
            }
        }
        Ok(([m.x, m.y, m.z], qr))
    }

    /// Period of the momentum (`inf` on the separatrix, `None` at a fixed point).
    fn period(&self, py: Python<'_>, m0: PyReadonlyArray1<'_, f64>) -> PyResult<Option<f64>> {
        let m0 = vector3(py, "period: m0", &vec_of(&m0))?;
        Ok(self.inner.orbit(&m0).period())
    }

    /// `(k², k'² = 1 − k²)` of the orbit through `m0` (`None` at a fixed point).
    fn elliptic_parameter(
        &self,
        py: Python<'_>,
        m0: PyReadonlyArray1<'_, f64>,
    ) -> PyResult<Option<(f64, f64)>> {
        let m0 = vector3(py, "elliptic_parameter: m0", &vec_of(&m0))?;
        let o = self.inner.orbit(&m0);
        Ok(o.parameter().zip(o.complementary_parameter()))
    }

    fn __repr__(&self) -> String {
        let v = self.inner.inertia();
        format!("FreeRigidBody(inertia=[{}, {}, {}])", v.x, v.y, v.z)
    }
}

// ------------------------------------------------------------------------------------------
// so3

/// Rows of `k` values from a flat array, each mapped by `f` to `out_k` values.
fn rowwise<'py>(
    py: Python<'py>,
    what: &str,
    a: PyReadonlyArray1<'py, f64>,
    k: usize,
    f: impl Fn(&[f64]) -> Vec<f64> + Send,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let v = vec_of(&a);
    if v.len() % k != 0 {
        return Err(invalid(
            py,
            format!(
                "{what}: expected rows of {k} values, got {} values",
                v.len()
            ),
        ));
    }
    let out = py.detach(move || v.chunks(k).flat_map(&f).collect::<Vec<f64>>());
    Ok(PyArray1::from_vec(py, out))
}

fn rows_of(m: &Matrix3<f64>) -> Vec<f64> {
    (0..3)
        .flat_map(|i| (0..3).map(move |j| m[(i, j)]))
        .collect()
}

/// `exp(hat w)` for rows `w` (3 values each); returns 9 values (row-major) per row.
#[pyfunction]
fn so3_exp<'py>(
    py: Python<'py>,
    w: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    rowwise(py, "so3.exp", w, 3, |r| {
        rows_of(&so3::exp(&Vector3::new(r[0], r[1], r[2])))
    })
}

/// The principal logarithm of row-major 3 × 3 matrices; returns 3 values per matrix.
#[pyfunction]
fn so3_log<'py>(
    py: Python<'py>,
    r: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    rowwise(py, "so3.log", r, 9, |r| {
        so3::log(&Matrix3::from_row_slice(r)).as_slice().to_vec()
    })
}

/// ZYX Euler angles `(phi, theta, psi)` of row-major 3 × 3 matrices.
#[pyfunction]
fn so3_euler_zyx<'py>(
    py: Python<'py>,
    r: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    rowwise(py, "so3.euler_zyx", r, 9, |r| {
        so3::euler_zyx(&Matrix3::from_row_slice(r))
            .as_slice()
            .to_vec()
    })
}

/// `Rz(psi) Ry(theta) Rx(phi)` from rows `(phi, theta, psi)`; 9 values (row-major) per row.
#[pyfunction]
fn so3_from_euler_zyx<'py>(
    py: Python<'py>,
    e: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    rowwise(py, "so3.from_euler_zyx", e, 3, |r| {
        rows_of(&so3::from_euler_zyx(&Vector3::new(r[0], r[1], r[2])))
    })
}

/// Unit quaternions `(q0, q1, q2, q3)`, scalar first, `q0 ≥ 0`, of row-major 3 × 3 matrices.
#[pyfunction]
fn so3_quaternion<'py>(
    py: Python<'py>,
    r: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    rowwise(py, "so3.quaternion", r, 9, |r| {
        so3::quaternion(&Matrix3::from_row_slice(r))
            .as_slice()
            .to_vec()
    })
}

/// The rotation matrix (row-major) of rows `(q0, q1, q2, q3)`, normalised first.
#[pyfunction]
fn so3_from_quaternion<'py>(
    py: Python<'py>,
    q: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    rowwise(py, "so3.from_quaternion", q, 4, |r| {
        let q = nalgebra::Vector4::new(r[0], r[1], r[2], r[3]);
        rows_of(&so3::rodrigues(&(q / q.norm())))
    })
}

/// Adds the numerics to the `_core` module (called from its `#[pymodule]`).
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(special_ellipj, m)?)?;
    m.add_function(wrap_pyfunction!(special_ellipk, m)?)?;
    m.add_function(wrap_pyfunction!(special_ellipkm1, m)?)?;
    m.add_function(wrap_pyfunction!(special_ellipkinc, m)?)?;
    m.add_class::<PyFreeRigidBody>()?;
    m.add_function(wrap_pyfunction!(so3_exp, m)?)?;
    m.add_function(wrap_pyfunction!(so3_log, m)?)?;
    m.add_function(wrap_pyfunction!(so3_euler_zyx, m)?)?;
    m.add_function(wrap_pyfunction!(so3_from_euler_zyx, m)?)?;
    m.add_function(wrap_pyfunction!(so3_quaternion, m)?)?;
    m.add_function(wrap_pyfunction!(so3_from_quaternion, m)?)?;
    m.add("GIMBAL_LOCK", so3::GIMBAL_LOCK)?;
    Ok(())
}
