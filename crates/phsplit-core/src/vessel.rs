//! The vessel under PID dynamic-positioning control (paper §3.4, eqs. 29–41; MODEL.md §2).
//!
//! Body-frame velocities `v` (linear) and `w` (angular), attitude `Q` (body → spatial), spatial
//! position `x` (z up, `z_eq = 0`). State: `p = mv v`, `m = T w`, `Q`, `mu` (= `G q3` on exact
//! solutions), `x`, and the controller's integral states `phi_th = ∫(theta − theta_ref)`,
//! `phi_x = ∫(x − x_ref)`. Fossen-style diagonal mass, damping and restoring data.
//!
//! Energy (35): `H = ½ mᵀT⁻¹m + ½|p|²/mv + ½ muᵀG⁺mu + ½ xᵀΛx`. The derivative terms of the PID
//! control are dissipation added to `D`; the P and I terms form the port `tau`, so that
//! `dH/dt = νᵀτ − νᵀDν` with `ν = (v, w)`.

use crate::error::{Error, Result};
use crate::linear::{self, gauss};
use crate::methods::Flow;
use crate::rigid_body::{FreeRigidBody, MagnusOrder};
use crate::so3;
use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use serde::Deserialize;

/// The paper's vessel (Appendix D as reconstructed in MODEL.md §3), as TOML.
pub const PAPER_VESSEL_TOML: &str = include_str!("../data/paper_vessel.toml");

/// Hull data (SI units; vectors are diagonals).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hull {
    /// `mv`, kg.
    pub mass: f64,
    /// `T = diag(T1, T2, T3)` roll, pitch, yaw, kg m².
    pub inertia: [f64; 3],
    /// `Dt` surge, sway, heave, kg/s.
    pub damping_translational: [f64; 3],
    /// `Dr` roll, pitch, yaw, kg m²/s.
    pub damping_rotational: [f64; 3],
    /// `GM_T`, m.
    pub gm_transverse: f64,
    /// `GM_L`, m.
    pub gm_longitudinal: f64,
    /// `g`, m/s².
    pub gravity: f64,
    /// `rho`, kg/m³.
    pub water_density: f64,
    /// `A_wp`, m².
    pub waterplane_area: f64,
}

/// PID gains (diagonals) and set point (paper eqs. 29–33).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Control {
    pub kp_translational: [f64; 3],
    pub kd_translational: [f64; 3],
    pub ki_translational: [f64; 3],
    pub kp_rotational: [f64; 3],
    pub kd_rotational: [f64; 3],
    pub ki_rotational: [f64; 3],
    /// `theta_ref`: roll, pitch, yaw set point, rad.
    pub euler_reference: [f64; 3],
    /// `x_ref`, m.
    pub position_reference: [f64; 3],
}

/// The initial state, in engineering variables.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    /// ZYX Euler angles (roll, pitch, yaw), rad.
    pub euler: [f64; 3],
    /// Spatial position, m.
    pub position: [f64; 3],
    /// Body linear velocity, m/s.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Body angular velocity, rad/s.
    #[serde(default)]
    pub angular_velocity: [f64; 3],
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
struct VesselFile {
    vessel: Hull,
    control: Control,
    initial: Initial,
}

/// A vessel: hull, controller and default initial state, with derived matrices.
#[derive(Debug, Clone, PartialEq)]
pub struct Vessel {
    pub hull: Hull,
    pub control: Control,
    pub initial: Initial,
    body: FreeRigidBody,
}

/// The state of the vessel (27 numbers with `Q` stored as a matrix).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VesselState {
    /// Linear momentum `p = mv v`, body frame, kg m/s.
    pub p: Vector3<f64>,
    /// Angular momentum `m = T w`, body frame, kg m²/s.
    pub m: Vector3<f64>,
    /// Attitude, body → spatial.
    pub q: Matrix3<f64>,
    /// Restoring-moment variable `mu` (= `G Qᵀe3` on exact solutions), N m.
    pub mu: Vector3<f64>,
    /// Spatial position, m.
    pub x: Vector3<f64>,
    /// `∫(theta − theta_ref) dt`, rad s.
    pub phi_th: Vector3<f64>,
    /// `∫(x − x_ref) dt`, m s.
    pub phi_x: Vector3<f64>,
}

/// Dimension of the state as a flat vector.
pub const STATE_DIM: usize = 27;

impl VesselState {
    /// Flatten: `p, m, Q` (column-major), `mu, x, phi_th, phi_x`.
    pub fn to_vector(&self) -> SVector<f64, STATE_DIM> {
        let mut y = SVector::<f64, STATE_DIM>::zeros();
        y.fixed_rows_mut::<3>(0).copy_from(&self.p);
        y.fixed_rows_mut::<3>(3).copy_from(&self.m);
        y.fixed_rows_mut::<9>(6).copy_from_slice(self.q.as_slice());
        y.fixed_rows_mut::<3>(15).copy_from(&self.mu);
        y.fixed_rows_mut::<3>(18).copy_from(&self.x);
        y.fixed_rows_mut::<3>(21).copy_from(&self.phi_th);
        y.fixed_rows_mut::<3>(24).copy_from(&self.phi_x);
        y
    }
    /// Inverse of [`Self::to_vector`].
    pub fn from_vector(y: &SVector<f64, STATE_DIM>) -> Self {
        Self {
            p: y.fixed_rows::<3>(0).into(),
            m: y.fixed_rows::<3>(3).into(),
            q: Matrix3::from_column_slice(y.fixed_rows::<9>(6).as_slice()),
            mu: y.fixed_rows::<3>(15).into(),
            x: y.fixed_rows::<3>(18).into(),
            phi_th: y.fixed_rows::<3>(21).into(),
            phi_x: y.fixed_rows::<3>(24).into(),
        }
    }
    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.to_vector().as_slice().iter().all(|v| v.is_finite())
    }
    /// ZYX Euler angles of the attitude (paper eq. 21).
    pub fn euler(&self) -> Vector3<f64> {
        so3::euler_zyx(&self.q)
    }
}

fn check_finite(name: &str, v: f64, unit: &str) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "{name} must be finite ({unit}), got {v}"
        )))
    }
}
fn check_positive(name: &str, v: f64, unit: &str) -> Result<()> {
    check_finite(name, v, unit)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "{name} must be > 0 ({unit}), got {v}"
        )))
    }
}
fn check_nonneg(name: &str, v: f64, unit: &str) -> Result<()> {
    check_finite(name, v, unit)?;
    if v >= 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "{name} must be ≥ 0 ({unit}), got {v}"
        )))
    }
}

impl Vessel {
    /// Build and validate a vessel.
    pub fn new(hull: Hull, control: Control, initial: Initial) -> Result<Self> {
        check_positive("vessel.mass", hull.mass, "kg")?;
        for i in 0..3 {
            check_positive(&format!("vessel.inertia[{i}]"), hull.inertia[i], "kg m^2")?;
            check_nonneg(
                &format!("vessel.damping_translational[{i}]"),
                hull.damping_translational[i],
                "kg/s",
            )?;
            check_nonneg(
                &format!("vessel.damping_rotational[{i}]"),
                hull.damping_rotational[i],
                "kg m^2/s",
            )?;
        }
        check_positive("vessel.gm_transverse", hull.gm_transverse, "m")?;
        check_positive("vessel.gm_longitudinal", hull.gm_longitudinal, "m")?;
        check_positive("vessel.gravity", hull.gravity, "m/s^2")?;
        check_positive("vessel.water_density", hull.water_density, "kg/m^3")?;
        check_positive("vessel.waterplane_area", hull.waterplane_area, "m^2")?;
        let gains = [
            ("kp_translational", control.kp_translational),
            ("kd_translational", control.kd_translational),
            ("ki_translational", control.ki_translational),
            ("kp_rotational", control.kp_rotational),
            ("kd_rotational", control.kd_rotational),
            ("ki_rotational", control.ki_rotational),
        ];
        for (name, g) in gains {
            for (i, v) in g.iter().enumerate() {
                check_nonneg(&format!("control.{name}[{i}]"), *v, "SI")?;
            }
        }
        for i in 0..3 {
            check_finite(
                &format!("control.euler_reference[{i}]"),
                control.euler_reference[i],
                "rad",
            )?;
            check_finite(
                &format!("control.position_reference[{i}]"),
                control.position_reference[i],
                "m",
            )?;
            check_finite(&format!("initial.euler[{i}]"), initial.euler[i], "rad")?;
            check_finite(&format!("initial.position[{i}]"), initial.position[i], "m")?;
            check_finite(
                &format!("initial.velocity[{i}]"),
                initial.velocity[i],
                "m/s",
            )?;
            check_finite(
                &format!("initial.angular_velocity[{i}]"),
                initial.angular_velocity[i],
                "rad/s",
            )?;
        }
        let body = FreeRigidBody::new(Vector3::from(hull.inertia))?;
        Ok(Self {
            hull,
            control,
            initial,
            body,
        })
    }

    /// Parse a vessel TOML file's text (sections `[vessel]`, `[control]`, `[initial]`).
    pub fn from_toml_str(text: &str) -> Result<Self> {
        let f: VesselFile = toml::from_str(text).map_err(|e| Error::Parse(e.to_string()))?;
        Self::new(f.vessel, f.control, f.initial)
    }

    /// The paper's vessel and scenario (MODEL.md §3).
    pub fn paper() -> Self {
        Self::from_toml_str(PAPER_VESSEL_TOML).expect("the shipped parameter file is valid")
    }

    /// The free rigid body of flow S1.
    pub fn body(&self) -> &FreeRigidBody {
        &self.body
    }

    fn inertia(&self) -> Vector3<f64> {
        Vector3::from(self.hull.inertia)
    }
    /// `c = g rho A_wp`, heave stiffness, N/m.
    pub fn heave_stiffness(&self) -> f64 {
        self.hull.gravity * self.hull.water_density * self.hull.waterplane_area
    }
    /// Diagonal of `G = mv g diag(GM_L, GM_T, 0)`.
    pub fn g_diag(&self) -> Vector3<f64> {
        let w = self.hull.mass * self.hull.gravity;
        Vector3::new(
            w * self.hull.gm_longitudinal,
            w * self.hull.gm_transverse,
            0.0,
        )
    }
    /// Diagonal of `G⁺` (pseudo-inverse of `G`).
    fn g_plus(&self) -> Vector3<f64> {
        self.g_diag().map(|v| if v == 0.0 { 0.0 } else { 1.0 / v })
    }

    /// The state from engineering variables: attitude from ZYX Euler angles, `p = mv v`,
    /// `m = T w`, `mu = G Qᵀe3`, integral states zero.
    pub fn state_from(
        &self,
        euler: Vector3<f64>,
        position: Vector3<f64>,
        velocity: Vector3<f64>,
        angular_velocity: Vector3<f64>,
    ) -> VesselState {
        let q = so3::from_euler_zyx(&euler);
        let q3 = q.transpose() * Vector3::z();
        VesselState {
            p: velocity * self.hull.mass,
            m: angular_velocity.component_mul(&self.inertia()),
            q,
            mu: self.g_diag().component_mul(&q3),
            x: position,
            phi_th: Vector3::zeros(),
            phi_x: Vector3::zeros(),
        }
    }

    /// The default initial state of the file.
    pub fn initial_state(&self) -> VesselState {
        let i = &self.initial;
        self.state_from(
            i.euler.into(),
            i.position.into(),
            i.velocity.into(),
            i.angular_velocity.into(),
        )
    }

    /// The energy `H` of eq. (35), J (without the constant terms).
    pub fn energy(&self, s: &VesselState) -> f64 {
        let c = self.heave_stiffness();
        self.body.kinetic_energy(&s.m)
            + 0.5 * s.p.norm_squared() / self.hull.mass
            + 0.5 * s.mu.component_mul(&s.mu).dot(&self.g_plus())
            + 0.5 * c * s.x.z * s.x.z
    }
}

/// How flow S2 (linear) is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearFlow {
    /// The exact flow: a matrix exponential per sub-step (paper §3.4.2).
    #[default]
    Exact,
    /// Gauss–Legendre collocation (the diagonal Padé approximant of the exponential) with as
    /// many stages as the composition needs (`⌈order/2⌉`): cheaper, of the composition's order,
    /// and still energy-dissipative on S2, so the passivity of the composition is kept (paper
    /// Remark 2.3). The ledger stays exact (Gauss quadrature of a quadratic storage).
    Gauss,
}

/// The vessel as a dynamical system: the vessel plus the controller schedule.
#[derive(Debug, Clone)]
pub struct VesselSystem<'a> {
    pub vessel: &'a Vessel,
    /// The controller (and the growth of the integral states) acts on steps that start at or
    /// after this time; `None` keeps it off throughout.
    pub control_start: Option<f64>,
    /// How flow S2 is integrated.
    pub linear: LinearFlow,
    /// Stages of Gauss collocation when `linear` is `Gauss` (1, 2 or 3).
    pub gauss_stages: usize,
    /// Kp, Kd, Ki translational then rotational, as diagonal matrices.
    gain_mats: [Matrix3<f64>; 6],
}

/// The controller quantities at a given attitude: `W = Pi_e(theta)⁻¹ Q` and the
/// attitude-dependent damping and port terms.
struct Frozen {
    q: Matrix3<f64>,
    q3: Vector3<f64>,
    theta_err: Vector3<f64>,
    w_mat: Matrix3<f64>,
}

/// Power flows at a state: `(supplied, dissipated)`, W.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Power {
    pub supplied: f64,
    pub dissipated: f64,
}

impl<'a> VesselSystem<'a> {
    pub fn new(vessel: &'a Vessel, control_start: Option<f64>) -> Self {
        let c = &vessel.control;
        let d = |v: [f64; 3]| Matrix3::from_diagonal(&Vector3::from(v));
        Self {
            vessel,
            control_start,
            linear: LinearFlow::Exact,
            gauss_stages: 1,
            gain_mats: [
                d(c.kp_translational),
                d(c.kd_translational),
                d(c.ki_translational),
                d(c.kp_rotational),
                d(c.kd_rotational),
                d(c.ki_rotational),
            ],
        }
    }

    /// The same system with flow S2 integrated by `linear`, to order at least `order`.
    pub fn with_linear_flow(mut self, linear: LinearFlow, order: usize) -> Self {
        self.linear = linear;
        self.gauss_stages = order.div_ceil(2).clamp(1, 3);
        self
    }

    /// Whether the controller acts on a step that starts at `t`.
    pub fn control_on(&self, t: f64) -> bool {
        match self.control_start {
            None => false,
            Some(tc) => t >= tc - 1e-9 * tc.abs().max(1.0),
        }
    }

    fn frozen(&self, q: &Matrix3<f64>) -> Frozen {
        let (theta, w_mat) = so3::euler_and_w(q);
        let theta_ref = Vector3::from(self.vessel.control.euler_reference);
        Frozen {
            q: *q,
            q3: q.row(2).transpose(),
            theta_err: theta - theta_ref,
            w_mat,
        }
    }

    /// Diagonal gains as matrices (built once, in [`Self::new`]), zero when the controller is off.
    fn gains(&self, on: bool) -> [Matrix3<f64>; 6] {
        if on {
            self.gain_mats
        } else {
            [Matrix3::zeros(); 6]
        }
    }

    /// The full vector field, eq. (39), with the controller on or off.
    pub fn vector_field(&self, s: &VesselState, on: bool) -> VesselState {
        // One pass over eq. (39); `split_field` gives the two halves (tested to add up to this).
        let vsl = self.vessel;
        let v = s.p / vsl.hull.mass;
        let w = vsl.body.omega(&s.m);
        let f = self.frozen(&s.q);
        let c = &vsl.control;
        let k = if on { 1.0 } else { 0.0 };
        let d = |a: [f64; 3]| Vector3::from(a) * k;
        let xr = Vector3::from(c.position_reference);
        let ex = s.x - xr;
        let qv = f.q * v;
        let tau_t = -f.q.transpose()
            * (d(c.kp_translational).component_mul(&ex)
                + d(c.kd_translational).component_mul(&qv)
                + d(c.ki_translational).component_mul(&s.phi_x));
        let ww = f.w_mat * w;
        let tau_r = -f.w_mat.transpose()
            * (d(c.kp_rotational).component_mul(&f.theta_err)
                + d(c.kd_rotational).component_mul(&ww)
                + d(c.ki_rotational).component_mul(&s.phi_th));
        let dt = Vector3::from(vsl.hull.damping_translational);
        let dr = Vector3::from(vsl.hull.damping_rotational);
        let lam_x = Vector3::new(0.0, 0.0, vsl.heave_stiffness() * s.x.z);
        VesselState {
            p: -w.cross(&s.p) - (dt.component_mul(&v) + f.q.transpose() * lam_x - tau_t),
            m: -w.cross(&s.m) - (dr.component_mul(&w) + s.mu.cross(&f.q3) - tau_r),
            q: s.q * so3::hat(&w),
            mu: -vsl.g_diag().component_mul(&w.cross(&f.q3)),
            x: qv,
            phi_th: f.theta_err * k,
            phi_x: ex * k,
        }
    }

    /// The vector field of flow S1 (eq. 40) or S2 (eq. 41) at `s`. Their sum is eq. (39).
    pub fn split_field(&self, s: &VesselState, on: bool, which: Flow) -> VesselState {
        let v = s.p / self.vessel.hull.mass;
        let w = self.vessel.body.omega(&s.m);
        let z = Vector3::zeros();
        match which {
            Flow::S1 => VesselState {
                p: -w.cross(&s.p),
                m: -w.cross(&s.m),
                q: s.q * so3::hat(&w),
                mu: z,
                x: z,
                phi_th: z,
                phi_x: z,
            },
            Flow::S2 => {
                let f = self.frozen(&s.q);
                let [kp_t, kd_t, ki_t, kp_r, kd_r, ki_r] = self.gains(on);
                let xr = Vector3::from(self.vessel.control.position_reference);
                let lam = Vector3::new(0.0, 0.0, self.vessel.heave_stiffness());
                let dt = Vector3::from(self.vessel.hull.damping_translational);
                let dr = Vector3::from(self.vessel.hull.damping_rotational);
                let tau_t =
                    -f.q.transpose() * (kp_t * (s.x - xr) + kd_t * f.q * v + ki_t * s.phi_x);
                let wm = f.w_mat;
                let tau_r =
                    -wm.transpose() * (kp_r * f.theta_err + kd_r * wm * w + ki_r * s.phi_th);
                VesselState {
                    p: -(dt.component_mul(&v) + f.q.transpose() * lam.component_mul(&s.x) - tau_t),
                    m: -(dr.component_mul(&w) + s.mu.cross(&f.q3) - tau_r),
                    q: Matrix3::zeros(),
                    mu: -self.vessel.g_diag().component_mul(&w.cross(&f.q3)),
                    x: f.q * v,
                    phi_th: if on { f.theta_err } else { z },
                    phi_x: if on { s.x - xr } else { z },
                }
            }
        }
    }

    /// Supplied (P and I terms: the port) and dissipated (hydrodynamic damping plus the D terms)
    /// power at `s`.
    pub fn power(&self, s: &VesselState, on: bool) -> Power {
        let v = s.p / self.vessel.hull.mass;
        let w = self.vessel.body.omega(&s.m);
        let f = self.frozen(&s.q);
        let [kp_t, kd_t, ki_t, kp_r, kd_r, ki_r] = self.gains(on);
        let xr = Vector3::from(self.vessel.control.position_reference);
        let dt = Matrix3::from_diagonal(&Vector3::from(self.vessel.hull.damping_translational));
        let dr = Matrix3::from_diagonal(&Vector3::from(self.vessel.hull.damping_rotational));
        let wm = f.w_mat;
        let tau_t = -f.q.transpose() * (kp_t * (s.x - xr) + ki_t * s.phi_x);
        let tau_r = -wm.transpose() * (kp_r * f.theta_err + ki_r * s.phi_th);
        let d_t = dt + f.q.transpose() * kd_t * f.q;
        let d_r = dr + wm.transpose() * kd_r * wm;
        Power {
            supplied: v.dot(&tau_t) + w.dot(&tau_r),
            dissipated: v.dot(&(d_t * v)) + w.dot(&(d_r * w)),
        }
    }

    /// Exact flow S1 over `h`: the free rigid body with a Magnus attitude of the given order
    /// (paper §3.4.1). `p(h) = Q(h)ᵀ Q0 p0`; `mu, x, phi` unchanged.
    pub fn flow_s1(&self, s: &mut VesselState, h: f64, order: MagnusOrder) {
        let (m1, q1) = self.vessel.body.flow(&s.m, &s.q, h, order);
        s.p = q1.transpose() * (s.q * s.p);
        s.m = m1;
        s.q = q1;
    }

    /// Flow S2 at the frozen attitude `Q0` (paper eq. 41) as two block systems
    /// ([`gauss::Blocks`]): translation in `(p, x − x_ref, phi_x)`, rotation in
    /// `(m, mu, phi_th)`. Assembled directly in 3×3 blocks; the diagonal gains and inertias are
    /// applied as row and column scalings, not as matrix products.
    fn s2_at(&self, q0: &Matrix3<f64>, on: bool) -> S2At {
        let vsl = self.vessel;
        let c = &vsl.control;
        let f = self.frozen(q0);
        let mv = vsl.hull.mass;
        let k = if on { 1.0 } else { 0.0 };
        let kv = |a: [f64; 3]| Vector3::from(a) * k;
        let qt = q0.transpose();
        let qt_diag = |g: &Vector3<f64>| times_diag(&qt, g);
        let c_heave = vsl.heave_stiffness();
        let xr = Vector3::from(c.position_reference);
        // Translation. In the set-point error e = x − x_ref rather than x: the port's quadratic
        // form then has no large terms that cancel (with x ≈ x_ref ≈ 780 m they cost six digits).
        let kd_t = kv(c.kd_translational);
        let mut d_t = qt_diag(&kd_t) * q0;
        for i in 0..3 {
            d_t[(i, i)] += vsl.hull.damping_translational[i];
        }
        let qt_kp = qt_diag(&kv(c.kp_translational));
        let mut qt_lam_kp = qt_kp;
        qt_lam_kp.column_mut(2).axpy(c_heave, &qt.column(2), 1.0);
        let trans = gauss::Blocks {
            auu: d_t * (-1.0 / mv),
            auv: -qt_lam_kp,
            auw: -qt_diag(&kv(c.ki_translational)),
            cu: qt.column(2) * (-c_heave * xr.z),
            avu: q0 * (1.0 / mv),
            awv: Matrix3::identity() * k,
            cw: Vector3::zeros(),
        };
        // Rotation.
        let tinv = vsl.inertia().map(|v| 1.0 / v);
        let wm = f.w_mat;
        let wt = wm.transpose();
        let wt_diag = |g: &Vector3<f64>| times_diag(&wt, g);
        let mut d_r = wt_diag(&kv(c.kd_rotational)) * wm;
        for i in 0..3 {
            d_r[(i, i)] += vsl.hull.damping_rotational[i];
        }
        let auu_r = -times_diag(&d_r, &tinv);
        let hq3 = so3::hat(&f.q3);
        let g = vsl.g_diag();
        let mut avu_r = hq3;
        for i in 0..3 {
            for j in 0..3 {
                avu_r[(i, j)] *= g[i] * tinv[j];
            }
        }
        let rot = gauss::Blocks {
            auu: auu_r,
            auv: hq3,
            auw: -wt_diag(&kv(c.ki_rotational)),
            cu: -(wt * kv(c.kp_rotational).component_mul(&f.theta_err)),
            avu: avu_r,
            awv: Matrix3::zeros(),
            cw: f.theta_err * k,
        };
        S2At {
            trans,
            rot,
            qt_kp: -qt_kp,
            tinv,
            mv,
        }
    }

    /// Flow S2 over `h` (paper §3.4.2): two affine systems solved by matrix exponentials
    /// (or Gauss collocation, see [`LinearFlow`]). With `ledger`, also the supplied and
    /// dissipated energy over the sub-step, exactly (Van Loan Gramian, or Gauss quadrature).
    pub fn flow_s2(&self, s: &mut VesselState, h: f64, on: bool, ledger: bool) -> Power {
        let at = self.s2_at(&s.q, on);
        let xr = Vector3::from(self.vessel.control.position_reference);
        let zt = [s.p, s.x - xr, s.phi_x];
        let zr = [s.m, s.mu, s.phi_th];
        let (zt1, zr1, work) = match self.linear {
            LinearFlow::Gauss => self.gauss_s2(&at, &zt, &zr, h, ledger),
            LinearFlow::Exact => {
                let (bt, br) = at.augmented(ledger, self.vessel);
                let (zt1, wt) = bt.advance(&zt, h, ledger);
                let (zr1, wr) = br.advance(&zr, h, ledger);
                let work = Power {
                    supplied: wt.supplied + wr.supplied,
                    dissipated: wt.dissipated + wr.dissipated,
                };
                (zt1, zr1, work)
            }
        };
        s.p = zt1[0];
        s.x = xr + zt1[1];
        s.phi_x = zt1[2];
        s.m = zr1[0];
        s.mu = zr1[1];
        s.phi_th = zr1[2];
        work
    }

    /// Flow S2 by Gauss collocation on the block systems; with `ledger`, the supplied and
    /// dissipated energy by the Gauss quadrature of the power at the stages (exact for the
    /// collocation polynomial's quadratic storage: `H(z1) − H(z0) = h Σ b_i Ḣ(Z_i)`).
    /// A singular stage system (impossible for a dissipative system, but checked) yields a
    /// non-finite state.
    fn gauss_s2(
        &self,
        at: &S2At,
        zt: &gauss::Z3,
        zr: &gauss::Z3,
        h: f64,
        ledger: bool,
    ) -> (gauss::Z3, gauss::Z3, Power) {
        let s = self.gauss_stages;
        let nan = [Vector3::from_element(f64::NAN); 3];
        let mut work = Power::default();
        let (Some((zt1, st)), Some((zr1, sr))) = (
            gauss::blocks_step(&at.trans, zt, h, s),
            gauss::blocks_step(&at.rot, zr, h, s),
        ) else {
            return (nan, nan, work);
        };
        if ledger {
            let b = gauss::weights(s);
            for i in 0..s {
                let p = at.stage_power(&st[i], &sr[i]);
                work.supplied += h * b[i] * p.supplied;
                work.dissipated += h * b[i] * p.dissipated;
            }
        }
        (zt1, zr1, work)
    }
}

/// Flow S2 at a frozen attitude, in blocks, with what the ledger needs besides.
struct S2At {
    trans: gauss::Blocks,
    rot: gauss::Blocks,
    /// `−Qᵀ Kp_t`: the proportional part of the translational port.
    qt_kp: Matrix3<f64>,
    tinv: Vector3<f64>,
    mv: f64,
}

impl S2At {
    /// Supplied (P and I) and dissipated (damping plus D) power at a state of the two block
    /// systems: `v·τ_PI + w·τ_PI` and `vᵀD_t v + wᵀD_r w`, with `D_t = −m_v A_uu`,
    /// `D_r T⁻¹ = −A_uu` (rotation).
    fn stage_power(&self, zt: &gauss::Z3, zr: &gauss::Z3) -> Power {
        let v = zt[0] / self.mv;
        let w = zr[0].component_mul(&self.tinv);
        let tau_t = self.qt_kp * zt[1] + self.trans.auw * zt[2];
        let tau_r = self.rot.cu + self.rot.auw * zr[2];
        Power {
            supplied: v.dot(&tau_t) + w.dot(&tau_r),
            dissipated: -v.dot(&(self.trans.auu * zt[0])) - w.dot(&(self.rot.auu * zr[0])),
        }
    }

    /// The two systems as balanced 10×10 augmented matrices for the exact exponential, with
    /// the quadratic forms of supplied and dissipated power (built only with `ledger`).
    fn augmented(&self, ledger: bool, vsl: &Vessel) -> (S2Block, S2Block) {
        let mv = self.mv;
        let tinv = Matrix3::from_diagonal(&self.tinv);
        let mut dis_t = SMatrix::<f64, 10, 10>::zeros();
        let mut sup_t = SMatrix::<f64, 10, 10>::zeros();
        let mut dis_r = SMatrix::<f64, 10, 10>::zeros();
        let mut sup_r = SMatrix::<f64, 10, 10>::zeros();
        if ledger {
            // vᵀ D_t v with v = p/mv, D_t = −mv A_uu.
            dis_t
                .fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&(-self.trans.auu / mv));
            // v·τ_PI = (p/mv)ᵀ(−Qᵀ Kp e − Qᵀ Ki phi_x), symmetrised.
            put_sym(&mut sup_t, 0, 3, &(self.qt_kp / mv));
            put_sym(&mut sup_t, 0, 6, &(self.trans.auw / mv));
            // wᵀ D_r w with w = T⁻¹ m: T⁻¹ D_r T⁻¹ = −T⁻¹ A_uu, symmetrised against round-off.
            let dr = -tinv * self.rot.auu;
            dis_r
                .fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&((dr + dr.transpose()) * 0.5));
            put_sym(&mut sup_r, 0, 6, &(tinv * self.rot.auw));
            put_sym_col(&mut sup_r, 0, 9, &(tinv * self.rot.cu));
        }
        let gmax = vsl.g_diag().max();
        let scale_t = SVector::<f64, 10>::from_fn(|i, _| if i < 3 { mv } else { 1.0 });
        let scale_r = SVector::<f64, 10>::from_fn(|i, _| match i {
            0..=2 => vsl.hull.inertia[i],
            3..=5 => gmax,
            _ => 1.0,
        });
        (
            S2Block {
                abar: self.trans.augmented(),
                supplied: sup_t,
                dissipated: dis_t,
                scale: scale_t,
            },
            S2Block {
                abar: self.rot.augmented(),
                supplied: sup_r,
                dissipated: dis_r,
                scale: scale_r,
            },
        )
    }
}

/// One of the S2 systems as an augmented 10×10 matrix, for the exact exponential.
struct S2Block {
    abar: SMatrix<f64, 10, 10>,
    supplied: SMatrix<f64, 10, 10>,
    dissipated: SMatrix<f64, 10, 10>,
    /// Diagonal balancing `z = S z̃`: the exponentials are taken of `S⁻¹ Ā S`, whose entries
    /// are of comparable size (momenta become velocities, `mu` becomes dimensionless), instead
    /// of `Ā`, whose entries span fifteen orders of magnitude.
    scale: SVector<f64, 10>,
}

impl S2Block {
    fn balanced(&self) -> SMatrix<f64, 10, 10> {
        let s = &self.scale;
        let inv = s.map(|v| 1.0 / v);
        SMatrix::from_fn(|i, j| self.abar[(i, j)] * s[j] * inv[i])
    }
    /// A form `M` in balanced variables: `z̃ᵀ (S M S) z̃ = zᵀ M z`.
    fn balanced_form(&self, m: &SMatrix<f64, 10, 10>) -> SMatrix<f64, 10, 10> {
        let s = &self.scale;
        SMatrix::from_fn(|i, j| m[(i, j)] * s[i] * s[j])
    }

    /// Advance `z` over `h` by the exact flow; with `ledger`, also the supplied and dissipated
    /// energy (exact integrals of the quadratic forms along the flow).
    fn advance(&self, z: &gauss::Z3, h: f64, ledger: bool) -> (gauss::Z3, Power) {
        let sc = &self.scale;
        let mut zz = SVector::<f64, 10>::zeros();
        for (k, v) in z.iter().enumerate() {
            zz.fixed_rows_mut::<3>(3 * k).copy_from(v);
        }
        zz[9] = 1.0;
        let zb = zz.component_div(sc);
        let a = self.balanced();
        let mut work = Power::default();
        let zb1 = if ledger {
            let (f, gram) = linear::flow_and_gramian(&a, &zb, h);
            work.supplied = linear::trace_product(&self.balanced_form(&self.supplied), &gram);
            work.dissipated = linear::trace_product(&self.balanced_form(&self.dissipated), &gram);
            f * zb
        } else {
            linear::flow(&a, h) * zb
        };
        let z1 = zb1.component_mul(sc);
        (
            [
                z1.fixed_rows::<3>(0).into_owned(),
                z1.fixed_rows::<3>(3).into_owned(),
                z1.fixed_rows::<3>(6).into_owned(),
            ],
            work,
        )
    }
}

/// `M diag(g)`: column j of `M` times `g_j` (diagonal gains and inertias as scalings).
fn times_diag(m: &Matrix3<f64>, g: &Vector3<f64>) -> Matrix3<f64> {
    let mut out = *m;
    for j in 0..3 {
        out.column_mut(j).scale_mut(g[j]);
    }
    out
}

/// Put `B/2` at block (r, c) and `Bᵀ/2` at (c, r), so that `zᵀMz` contains `z_rᵀ B z_c`.
fn put_sym(m: &mut SMatrix<f64, 10, 10>, r: usize, c: usize, b: &Matrix3<f64>) {
    m.fixed_view_mut::<3, 3>(r, c).copy_from(&(b * 0.5));
    m.fixed_view_mut::<3, 3>(c, r)
        .copy_from(&(b.transpose() * 0.5));
}
fn put_sym_col(m: &mut SMatrix<f64, 10, 10>, r: usize, c: usize, b: &Vector3<f64>) {
    m.fixed_view_mut::<3, 1>(r, c).copy_from(&(b * 0.5));
    m.fixed_view_mut::<1, 3>(c, r)
        .copy_from(&(b.transpose() * 0.5));
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn random_state(v: &Vessel, seed: [f64; 8]) -> VesselState {
        let mut s = v.state_from(
            Vector3::new(seed[0] * 0.3, seed[1] * 0.2, seed[2] * 3.0),
            Vector3::new(700.0 + seed[3] * 100.0, seed[4] * 50.0, seed[5] * 2.0),
            Vector3::new(seed[6], -seed[7], 0.3 * seed[0]),
            Vector3::new(0.02 * seed[1], -0.01 * seed[2], 0.03 * seed[3]),
        );
        s.phi_th = Vector3::new(seed[4], seed[5], seed[6]) * 10.0;
        s.phi_x = Vector3::new(seed[7], seed[0], seed[1]) * 100.0;
        s.mu += Vector3::new(seed[2], -seed[3], 0.0) * 1e6; // off the exact-solution manifold
        s
    }

    #[test]
    fn paper_vessel_loads_and_matches_model_md() {
        let v = Vessel::paper();
        assert_eq!(v.hull.mass, 6.3622085e6);
        assert_eq!(v.control.position_reference, [780.0, 20.0, 0.0]);
        let s = v.initial_state();
        assert!((s.euler() - Vector3::new(0.05, -0.02, 0.10)).norm() < 1e-15);
        assert!(v.energy(&s) > 0.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn split_fields_add_up_and_s2_is_exact(seed in proptest::array::uniform8(-1.0f64..1.0), on in any::<bool>()) {
            let v = Vessel::paper();
            let sys = VesselSystem::new(&v, Some(0.0));
            let s = random_state(&v, seed);
            // S1 + S2 = full field (eq. 39), written out independently here.
            let full = sys.vector_field(&s, on).to_vector();
            let mv = v.hull.mass;
            let vel = s.p / mv;
            let w = s.m.component_div(&Vector3::from(v.hull.inertia));
            let q3 = s.q.transpose() * Vector3::z();
            let th = s.euler();
            let wm = so3::pi_e_inv(&th) * s.q;
            let c = &v.control;
            let k = |a: [f64; 3]| if on { Matrix3::from_diagonal(&Vector3::from(a)) } else { Matrix3::zeros() };
            let xr = Vector3::from(c.position_reference);
            let te = th - Vector3::from(c.euler_reference);
            let tau_t = -s.q.transpose() * (k(c.kp_translational) * (s.x - xr) + k(c.kd_translational) * s.q * vel + k(c.ki_translational) * s.phi_x);
            let tau_r = -wm.transpose() * (k(c.kp_rotational) * te + k(c.kd_rotational) * wm * w + k(c.ki_rotational) * s.phi_th);
            let lx = Vector3::new(0.0, 0.0, v.heave_stiffness() * s.x.z);
            let expect = VesselState {
                p: -w.cross(&s.p) - (Vector3::from(v.hull.damping_translational).component_mul(&vel) + s.q.transpose() * lx - tau_t),
                m: -w.cross(&s.m) - (Vector3::from(v.hull.damping_rotational).component_mul(&w) + s.mu.cross(&q3) - tau_r),
                q: s.q * so3::hat(&w),
                mu: -v.g_diag().component_mul(&w.cross(&q3)),
                x: s.q * vel,
                phi_th: if on { te } else { Vector3::zeros() },
                phi_x: if on { s.x - xr } else { Vector3::zeros() },
            }.to_vector();
            let scale = expect.norm();
            prop_assert!((full - expect).norm() <= 1e-13 * scale, "field mismatch {}", (full - expect).norm() / scale);
            // The halves of the split add up to the full field.
            let sum = sys.split_field(&s, on, Flow::S1).to_vector() + sys.split_field(&s, on, Flow::S2).to_vector();
            prop_assert!((sum - full).norm() <= 1e-14 * scale, "S1 + S2 != full: {}", (sum - full).norm() / scale);
            // The exact S2 flow has the S2 field as its derivative at h = 0 (centred difference).
            let e = 1e-3;
            let (mut a, mut b) = (s, s);
            sys.flow_s2(&mut a, e, on, false);
            sys.flow_s2(&mut b, -e, on, false);
            let fd = (a.to_vector() - b.to_vector()) / (2.0 * e);
            let f2 = sys.split_field(&s, on, Flow::S2).to_vector();
            prop_assert!((fd - f2).norm() <= 1e-6 * f2.norm().max(1.0), "S2 flow vs field {}", (fd - f2).norm() / f2.norm());
        }

        #[test]
        fn s2_ledger_balances_exactly(seed in proptest::array::uniform8(-1.0f64..1.0), h in 0.01f64..50.0,
                                      variant in 0usize..4) {
            let v = Vessel::paper();
            // exact, and Gauss with 1, 2, 3 stages
            let sys = match variant {
                0 => VesselSystem::new(&v, Some(0.0)),
                k => VesselSystem::new(&v, Some(0.0)).with_linear_flow(LinearFlow::Gauss, 2 * k),
            };
            let mut s = random_state(&v, seed);
            s.mu.z = 0.0;
            let h0 = v.energy(&s);
            let w = sys.flow_s2(&mut s, h, true, true);
            let dh = v.energy(&s) - h0;
            let scale = h0.abs() + w.supplied.abs() + w.dissipated.abs();
            prop_assert!(w.dissipated >= 0.0);
            prop_assert!((dh - (w.supplied - w.dissipated)).abs() <= 1e-11 * scale,
                "dH {dh} supplied {} dissipated {}", w.supplied, w.dissipated);
        }
    }

    #[test]
    fn s1_conserves_energy() {
        let v = Vessel::paper();
        let sys = VesselSystem::new(&v, None);
        let mut s = random_state(&v, [0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.4, -0.1]);
        let h0 = v.energy(&s);
        for _ in 0..100 {
            sys.flow_s1(&mut s, 0.7, MagnusOrder::Four);
        }
        assert!((v.energy(&s) - h0).abs() < 1e-13 * h0);
        assert!(so3::orthogonality_defect(&s.q) < 1e-13);
    }
}
