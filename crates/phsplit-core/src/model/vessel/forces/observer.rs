//! The nonlinear passive observer with wave filtering (Fossen & Strand, Automatica 35 (1999)
//! 3–16; Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed. 2021,
//! §13.5) and the PID on its estimates: the controller of `[control]` with
//! `feedback = "observer"` (docs/model.md §5.20, docs/explanation/components/observer.md).
//!
//! The observer sees the measured horizontal position `(x, y)` and heading `ψ` (the vessel's,
//! continuously), and estimates, in surge, sway and yaw (index `i`):
//! - the wave-frequency motion, a second-order model per degree of freedom,
//!   `ξ̂₁' = ξ̂₂ + K₁ₐ ỹ`, `ξ̂₂' = −ω₀² ξ̂₁ − 2λω₀ ξ̂₂ + K₁ᵦ ỹ`;
//! - the low-frequency position and heading, `η̂' = R(ψ) ν̂ + K₂ ỹ`;
//! - a slowly varying bias force (the mean environment, spatial frame),
//!   `b̂' = −T⁻¹ b̂ + K₃ ỹ`;
//! - the low-frequency velocities, `M ν̂' = −D ν̂ + R(ψ)ᵀ b̂ + τ + R(ψ)ᵀ K₄ ỹ`;
//!
//! with `ỹ = y − η̂ − ξ̂₂`, `R(ψ)` the rotation by the measured heading, `M` the vessel's mass
//! matrix in surge, sway and yaw (rigid body and added mass) and `D` the observer's model
//! damping. Gains (Fossen 2021 §13.5; Fossen & Strand 1999 §4): `K₁ₐ = −2(ζₙ − λ) ω_c/ω₀`,
//! `K₁ᵦ = 2ω₀(ζₙ − λ)`, `K₂ = ω_c` (the notch at ω₀ and the cut-off ω_c of the wave filter),
//! and `K₃`, `K₄` with `1/T ≪ K₃/K₄ < ω₀ < ω_c`. Defaults: λ = 0.1, ζₙ = 1, ω_c/ω₀ = 1.2255
//! and T = 1000 s, those of the MSS toolbox's example (`exPassiveObs.m`: ω_c = 1.1 rad/s at
//! ω₀ = 0.8976 rad/s). The rule leaves the size of `K₃`, `K₄` open; by default phsplit places
//! the low-frequency error dynamics of each degree of freedom (below the wave filter,
//! `η̃ ≈ R ν̃/K₂`: `M s² + (D + K₄/K₂) s + K₃/K₂ = 0`) critically damped at the bias bandwidth
//! ω_b (default ω₀/5): `K₃ = K₂ M ω_b²`, `K₄ = K₂ (2 M ω_b − D)`, so `K₃/K₄ ≈ ω_b/2`, inside
//! the rule; in x and y the mean of the surge and sway placements, so that `R(ψ)ᵀ K₄ ỹ` turns
//! no surge residual into sway at any heading.
//!
//! The controller acts on the estimates: `τ = −Rᵀ(Kp e + Ki q) − Rᵀ Kd R ν̂` in surge, sway
//! and yaw (body frame), `e = η̂ − η_ref` (heading the short way round the set point),
//! `q' = e` while the controller acts. It is the paper's PID (eqs. 29–33) on the estimates in
//! the horizontal plane; it does not act in heave, roll or pitch (their gains must be zero).
//!
//! All of it is linear in the observer's states, the vessel's position and velocities at the
//! frozen attitude of flow S2 (the measured heading's `R`), so it is integrated with the
//! momenta in flow S2 as one linear system ([`OwnLinear`], exact or collocated: the
//! composition's order holds for the coupled vessel–observer system).
//!
//! With thrusters the hull gets what they deliver and ν̂ is driven by it, with back-calculation
//! on `q` if asked for: a forcing of flow S2 on the rows' demand (`observer/thrust.rs`).
//!
//! Ledger: the observer's states are information, not energy: they store nothing of H. The
//! controller's force on the hull is the port `control` (supplied; with thrusters, `thrusters`:
//! what they deliver): its power `ν·τ` booked exactly along the flow. The guarantee is the paper's for a port: the vessel's energy
//! changes by what the ports supply less what it dissipates, to round-off.

use super::sensors::{self, Sensors};
use parts::{gains, states};

mod parts;
mod thrust;
use super::{Frozen, Output, OwnLinear, OwnState, HELD};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::Body;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

const T: &str = "observer";

/// ω_c/ω₀ of the MSS example (1.1 rad/s at 0.8976 rad/s).
const CUTOFF_RATIO: f64 = 1.1 / 0.8976;

/// The wave model's and the filter's frequencies (rad/s).
const FREQUENCY: crate::model::vessel::params::Physical = crate::model::vessel::params::Physical {
    lo: 0.0,
    hi: 10.0,
    lo_closed: false,
    hi_closed: true,
    why: "rad/s; a sea's waves are below 10 rad/s (periods above 0.6 s); a larger value is a frequency in other units",
};

/// The wave model's and the notch's relative damping.
const RELATIVE_DAMPING: crate::model::vessel::params::Physical =
    crate::model::vessel::params::Physical {
        lo: 0.0,
        hi: 10.0,
        lo_closed: false,
        hi_closed: true,
        why: "a relative damping (1: critical); beyond 10 the filter is no notch",
    };

/// The model's damping: a large ship's linear yaw damping is about 1e10 kg m²/s.
const MODEL_DAMPING: crate::model::vessel::params::Physical =
    crate::model::vessel::params::Physical {
        lo: 0.0,
        hi: 1e13,
        lo_closed: true,
        hi_closed: true,
        why: "a thousand times a large ship's yaw damping",
    };

/// K₃ and K₄ given: far above any placement's (a large ship's K₄ in yaw is about 1e11).
const GAIN: crate::model::vessel::params::Physical = crate::model::vessel::params::Physical {
    lo: 0.0,
    hi: 1e16,
    lo_closed: false,
    hi_closed: true,
    why: "far above what any placement gives",
};

/// How far an initial estimate may lie from the set point (m).
const MAX_ESTIMATE_OFFSET: f64 = 1e4;

/// An initial bias estimate: within what any environment can put on a vessel.
const BIAS_RANGE: crate::model::vessel::params::Physical = crate::model::vessel::params::Physical {
    lo: -1e10,
    hi: 1e10,
    lo_closed: true,
    hi_closed: true,
    why: "no environment puts 10 GN or 10 GN m on a vessel",
};

/// Offsets of the state groups in the observer's 18 states.
const XI1: usize = 0;
const XI2: usize = 3;
const ETA: usize = 6;
const BIAS: usize = 9;
const NU: usize = 12;
const INT: usize = 15;
pub const N: usize = 18;

#[derive(Debug, Clone, PartialEq)]
pub struct Observer {
    omega0: f64,
    lambda: f64,
    k1a: f64,
    k1b: f64,
    k2: f64,
    k3: Vector3<f64>,
    k4: Vector3<f64>,
    bias_time: f64,
    /// `M⁻¹` and `D` in surge, sway, yaw.
    minv: Matrix3<f64>,
    damping: Vector3<f64>,
    /// The controller's gains in (x, y, ψ) and its set point.
    kp: Vector3<f64>,
    kd: Vector3<f64>,
    ki: Vector3<f64>,
    reference: Vector3<f64>,
    /// Initial estimates: position and heading (`None`: the measured ones) and bias.
    initial_eta: Option<Vector3<f64>>,
    initial_bias: Vector3<f64>,
    states: Vec<OwnState>,
    /// The rows at heading 0 (their shape; the vessel's layout reads it).
    template: OwnLinear,
    /// The sensors it reads (`sensors.rs`); `None`: the vessel's position and heading,
    /// continuously.
    sensors: Option<Sensors>,
}

/// The controller's gains in the horizontal plane, with its set point.
pub struct Gains {
    pub kp: [Vector3<f64>; 2],
    pub kd: [Vector3<f64>; 2],
    pub ki: [Vector3<f64>; 2],
    pub position_reference: Vector3<f64>,
    pub euler_reference: Vector3<f64>,
}

/// Table `[observer]` (see the module documentation): `wave_frequency` ω₀ (rad/s, required),
/// `wave_damping` λ (default 0.1), `notch_damping` ζₙ (> λ, default 1), `cutoff_frequency` ω_c
/// (> ω₀, default 1.2255 ω₀), `bias_time_constant` T (s, default 1000), `damping` (the model's
/// linear damping in surge, sway, yaw: kg/s, kg/s, kg m²/s, required), `velocity_gain` K₄
/// (N/m, N/m, N m/rad) and `bias_gain` K₃ (N/(m s), N/(m s), N m/(rad s)), both by default
/// placed at `bias_bandwidth` ω_b (rad/s, default ω₀/5); `initial_estimate` `(x, y, ψ)`
/// (m, m, rad; default the measured) and `initial_bias` (N, N, N m; default 0).
pub fn read(p: &mut Params, body: &Body, g: &Gains) -> crate::Result<Observer> {
    if !p.has(T) {
        return Err(Error::InvalidInput(
            "control.feedback = \"observer\" needs an [observer] table (at least wave_frequency, rad/s, and damping, the observer's model damping in surge, sway, yaw)".into(),
        ));
    }
    for (k, name) in [(0, "heave"), (1, "roll"), (2, "pitch")] {
        let (vec, i) = if k == 0 { (0, 2) } else { (1, k - 1) };
        if g.kp[vec][i] != 0.0 || g.kd[vec][i] != 0.0 || g.ki[vec][i] != 0.0 {
            let which = if vec == 0 {
                "translational"
            } else {
                "rotational"
            };
            return Err(Error::InvalidInput(format!(
                "control.feedback = \"observer\": the observer estimates surge, sway and yaw only, so the controller cannot act in {name}: set its entry [{i}] of kp_{which}, kd_{which} and ki_{which} to 0"
            )));
        }
    }
    let omega0 = p.f64(T, "wave_frequency", "rad/s", Range::Physical(&FREQUENCY))?;
    let lambda = p
        .opt_f64(
            T,
            "wave_damping",
            "dimensionless",
            Range::Physical(&RELATIVE_DAMPING),
        )?
        .unwrap_or(0.1);
    let zeta = p
        .opt_f64(
            T,
            "notch_damping",
            "dimensionless",
            Range::Physical(&RELATIVE_DAMPING),
        )?
        .unwrap_or(1.0);
    if zeta <= lambda {
        return Err(Error::InvalidInput(format!(
            "observer.notch_damping ({zeta}) must exceed observer.wave_damping ({lambda}): the notch at the wave frequency needs zeta_n > lambda (Fossen 2021, section 13.5)"
        )));
    }
    let omega_c = p
        .opt_f64(T, "cutoff_frequency", "rad/s", Range::Physical(&FREQUENCY))?
        .unwrap_or(CUTOFF_RATIO * omega0);
    if omega_c <= omega0 {
        return Err(Error::InvalidInput(format!(
            "observer.cutoff_frequency ({omega_c} rad/s) must exceed observer.wave_frequency ({omega0} rad/s) (Fossen 2021, section 13.5: 1/T << K3/K4 < omega_0 < omega_c)"
        )));
    }
    let bias_time = p
        .opt_f64(T, "bias_time_constant", "s", Range::Positive)?
        .unwrap_or(1000.0);
    let damping: Vector3<f64> = p
        .vec3(
            T,
            "damping",
            None,
            "kg/s, kg/s, kg m^2/s",
            Range::Physical(&MODEL_DAMPING),
        )?
        .into();
    let given_b = p.opt_f64(T, "bias_bandwidth", "rad/s", Range::Physical(&FREQUENCY))?;
    let omega_b = given_b.unwrap_or(omega0 / 5.0);
    let mut opt = |key: &str, unit: &str| -> crate::Result<Option<Vector3<f64>>> {
        match p.take_raw(T, key)? {
            None => Ok(None),
            Some(_) => Ok(Some(
                p.vec3(T, key, None, unit, Range::Physical(&GAIN))?.into(),
            )),
        }
    };
    let k4 = opt("velocity_gain", "N/m, N/m, N m/rad")?;
    let k3 = opt("bias_gain", "N/(m s), N/(m s), N m/(rad s)")?;
    let idx = [0, 1, 5];
    let m = Matrix3::from_fn(|i, j| body.mass_matrix[(idx[i], idx[j])]);
    let (k4, k3) = gains(k4, k3, omega_b, given_b.is_some(), omega_c, &m, &damping)?;
    for i in 0..3 {
        let r = k3[i] / k4[i];
        if !(r > 1.0 / bias_time && r < omega0) {
            return Err(Error::InvalidInput(format!(
                "observer: bias_gain[{i}] / velocity_gain[{i}] = {r:.4} 1/s must lie between 1/bias_time_constant ({:.4} 1/s) and wave_frequency ({omega0} rad/s) (Fossen 2021, section 13.5: 1/T << K3/K4 < omega_0 < omega_c)",
                1.0 / bias_time
            )));
        }
    }
    let initial_eta: Option<Vector3<f64>> = match p.take_raw(T, "initial_estimate")? {
        None => None,
        Some(_) => Some(
            p.vec3(T, "initial_estimate", None, "m, m, rad", Range::Finite)?
                .into(),
        ),
    };
    if let Some(e) = initial_eta {
        let off = (e.x - g.position_reference.x).hypot(e.y - g.position_reference.y);
        if off > MAX_ESTIMATE_OFFSET {
            return Err(Error::InvalidInput(format!(
                "observer.initial_estimate is {off:.4e} m from control.position_reference: an estimate must lie within {MAX_ESTIMATE_OFFSET} m of the set point"
            )));
        }
        let psi = &crate::model::vessel::params::physical::ANGLE_RAD;
        if !psi.contains(e.z) {
            return Err(Error::InvalidInput(format!(
                "observer.initial_estimate[2] must lie within {} (rad; {}), got {}",
                psi.interval(),
                psi.why,
                e.z
            )));
        }
    }
    let initial_bias: Vector3<f64> = p
        .vec3(
            T,
            "initial_bias",
            Some([0.0; 3]),
            "N, N, N m",
            Range::Physical(&BIAS_RANGE),
        )?
        .into();
    let minv = m.try_inverse().ok_or_else(|| {
        Error::InvalidInput(
            "observer: the vessel's mass matrix in surge, sway and yaw is singular".into(),
        )
    })?;
    let pick = |a: &[Vector3<f64>; 2]| Vector3::new(a[0].x, a[0].y, a[1].z);
    let sensors = sensors::read(p)?;
    let mut o = Observer {
        omega0,
        lambda,
        k1a: -2.0 * (zeta - lambda) * omega_c / omega0,
        k1b: 2.0 * omega0 * (zeta - lambda),
        k2: omega_c,
        k3,
        k4,
        bias_time,
        minv,
        damping,
        kp: pick(&g.kp),
        kd: pick(&g.kd),
        ki: pick(&g.ki),
        reference: Vector3::new(
            g.position_reference.x,
            g.position_reference.y,
            g.euler_reference.z,
        ),
        initial_eta,
        initial_bias,
        states: states(sensors.is_some()),
        sensors,
        template: OwnLinear::exchange(
            DMatrix::zeros(N, N),
            DMatrix::zeros(N, 6),
            DMatrix::zeros(6, N),
            DMatrix::zeros(6, 6),
            0,
            DMatrix::zeros(N + 6, N + 6),
        ),
    };
    o.template = o.rows(0.0, true, None);
    Ok(o)
}

/// `R(ψ)` in the horizontal plane, yaw unchanged.
fn rot(psi: f64) -> Matrix3<f64> {
    let (s, c) = psi.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

impl Observer {
    pub fn states(&self) -> &[OwnState] {
        &self.states
    }
    pub fn template(&self) -> &OwnLinear {
        &self.template
    }

    /// The measured heading taken the short way round the set point.
    fn heading(&self, psi: f64) -> f64 {
        self.reference.z + super::pid::wrap_pi(psi - self.reference.z)
    }

    /// How many own states: the observer's, and the sensors' after them.
    fn n(&self) -> usize {
        N + self.sensors.as_ref().map_or(0, |_| sensors::N)
    }

    /// The rows at the measured heading `psi`; `on`: the controller acts; `held`: the sensors'
    /// held measurement `(x, y, ψ)` and validities ([`Frozen::held`]), or `None` for the
    /// vessel's position and heading measured continuously.
    pub fn rows(&self, psi: f64, on: bool, held: Option<&[f64; HELD]>) -> OwnLinear {
        let n = self.n();
        let r = rot(psi);
        let rt = r.transpose();
        let mut axx = DMatrix::zeros(n, n);
        let mut axv = DMatrix::zeros(n, 3);
        let mut axc = DVector::zeros(n);
        // ỹ = S (Y_v v + y_c − η̂ − ξ̂₂) (rows of 3 on x, v and the constant), S the sensors'
        // validities: continuously measured, y = v + x_o (x_o enters the constant in `rows_at`)
        // and ψ; sampled, the held measurement, a constant over the step.
        let mut yx = DMatrix::<f64>::zeros(3, n);
        let mut yv = DMatrix::<f64>::zeros(3, 3);
        let (yc, mask) = match held {
            None => {
                yv[(0, 0)] = 1.0;
                yv[(1, 1)] = 1.0;
                (Vector3::new(0.0, 0.0, self.heading(psi)), [1.0, 1.0, 1.0])
            }
            Some(h) => (
                Vector3::new(h[0], h[1], self.heading(h[2])),
                [h[3], h[3], h[4]],
            ),
        };
        for i in 0..3 {
            yx[(i, ETA + i)] = -mask[i];
            yx[(i, XI2 + i)] = -mask[i];
        }
        let yc = Vector3::from_fn(|i, _| mask[i] * yc[i]);
        let yc_n = DVector::from_column_slice(yc.as_slice());
        let add_y = |axx: &mut DMatrix<f64>,
                     axv: &mut DMatrix<f64>,
                     axc: &mut DVector<f64>,
                     row: usize,
                     k: &Matrix3<f64>| {
            let k = DMatrix::from_fn(3, 3, |i, j| k[(i, j)]);
            let mut rows = axx.rows_mut(row, 3);
            rows += &k * &yx;
            let mut rows = axv.rows_mut(row, 3);
            rows += &k * &yv;
            let mut rows = axc.rows_mut(row, 3);
            rows += &k * &yc_n;
        };
        let w2 = self.omega0 * self.omega0;
        for i in 0..3 {
            axx[(XI1 + i, XI2 + i)] = 1.0;
            axx[(XI2 + i, XI1 + i)] = -w2;
            axx[(XI2 + i, XI2 + i)] = -2.0 * self.lambda * self.omega0;
            axx[(BIAS + i, BIAS + i)] = -1.0 / self.bias_time;
        }
        let eye = Matrix3::identity();
        add_y(&mut axx, &mut axv, &mut axc, XI1, &(eye * self.k1a));
        add_y(&mut axx, &mut axv, &mut axc, XI2, &(eye * self.k1b));
        add_y(&mut axx, &mut axv, &mut axc, ETA, &(eye * self.k2));
        add_y(
            &mut axx,
            &mut axv,
            &mut axc,
            BIAS,
            &Matrix3::from_diagonal(&self.k3),
        );
        // η̂' += R ν̂.
        for i in 0..3 {
            for j in 0..3 {
                axx[(ETA + i, NU + j)] += r[(i, j)];
            }
        }
        // The controller τ = Tx x + tc (surge, sway, yaw; body frame), zero while off.
        let mut tx = DMatrix::<f64>::zeros(3, n);
        let mut tc = Vector3::zeros();
        if on {
            let kp = Matrix3::from_diagonal(&self.kp);
            let ki = Matrix3::from_diagonal(&self.ki);
            let kd = rt * Matrix3::from_diagonal(&self.kd) * r;
            for i in 0..3 {
                for j in 0..3 {
                    tx[(i, ETA + j)] -= (rt * kp)[(i, j)];
                    tx[(i, INT + j)] -= (rt * ki)[(i, j)];
                    tx[(i, NU + j)] -= kd[(i, j)];
                }
            }
            tc = rt * kp * self.reference;
            // q' = η̂ − η_ref.
            for i in 0..3 {
                axx[(INT + i, ETA + i)] = 1.0;
                axc[INT + i] -= self.reference[i];
            }
        }
        // ν̂' = M⁻¹(−D ν̂ + Rᵀ b̂ + τ + Rᵀ K₄ ỹ).
        let k4 = rt * Matrix3::from_diagonal(&self.k4);
        let mut nx = tx.clone();
        let mut nv = DMatrix::<f64>::zeros(3, 3);
        let mut nc = tc + k4 * yc;
        for i in 0..3 {
            nx[(i, NU + i)] -= self.damping[i];
            for j in 0..3 {
                nx[(i, BIAS + j)] += rt[(i, j)];
                for l in 0..n {
                    nx[(i, l)] += k4[(i, j)] * yx[(j, l)];
                }
                for l in 0..3 {
                    nv[(i, l)] += k4[(i, j)] * yv[(j, l)];
                }
            }
        }
        let minv = DMatrix::from_fn(3, 3, |i, j| self.minv[(i, j)]);
        let nx = &minv * nx;
        let nv = &minv * nv;
        nc = self.minv * nc;
        for i in 0..3 {
            for j in 0..n {
                axx[(NU + i, j)] += nx[(i, j)];
            }
            for j in 0..3 {
                axv[(NU + i, j)] += nv[(i, j)];
            }
            axc[NU + i] += nc[i];
        }
        // The force on the hull: (X, Y, 0) and (0, 0, N), body frame.
        let mut fx = DMatrix::zeros(6, n);
        let mut fc = DVector::zeros(6);
        for (k, row) in [0usize, 1, 5].into_iter().enumerate() {
            for j in 0..n {
                fx[(row, j)] = tx[(k, j)];
            }
            fc[row] = tc[k];
        }
        OwnLinear {
            axx,
            axnu: DMatrix::zeros(n, 6),
            axv,
            axc,
            fx,
            fnu: DMatrix::zeros(6, 6),
            fc,
            account: 0,
            diss: DMatrix::zeros(n + 6, n + 6),
            port: true,
        }
    }

    /// The rows at the frozen view, with the measured position's offset `x_o` in the constant.
    pub fn rows_at(&self, fr: &Frozen) -> OwnLinear {
        if let (Some(_), Some(h)) = (&self.sensors, &fr.held) {
            return self.rows(h[2], fr.control_on, Some(h));
        }
        let mut l = self.rows(fr.euler.z, fr.control_on, None);
        // y = v + x_o: the constant gets the rows on v times x_o.
        let xo = DVector::from_column_slice(fr.origin.as_slice());
        l.axc += &l.axv * xo;
        l
    }

    /// The initial estimates at the body's state: position and heading measured (or given),
    /// bias as given, all else zero.
    pub fn init(&self, x_pos: &Vector3<f64>, psi: f64, x: &mut [f64]) {
        x.fill(0.0);
        let eta = self
            .initial_eta
            .unwrap_or(Vector3::new(x_pos.x, x_pos.y, self.heading(psi)));
        for i in 0..3 {
            x[ETA + i] = eta[i];
            x[BIAS + i] = self.initial_bias[i];
        }
        if let Some(sn) = &self.sensors {
            sn.init(x_pos, psi, &mut x[N..]);
        }
    }

    /// The sensors' samples at the end of a step at time `t` (and where a run starts).
    pub fn end_step(&self, t: f64, pos: &Vector3<f64>, q: &Matrix3<f64>, x: &mut [f64]) {
        if let Some(sn) = &self.sensors {
            sn.update(t, pos, q, crate::lie::so3::euler_and_w(q).0.z, &mut x[N..]);
        }
    }

    /// The sensors' next sample or dropout edge after `t`.
    pub fn next_sample(&self, t: f64) -> Option<f64> {
        self.sensors.as_ref().map(|sn| sn.next_event(t))
    }

    /// Where the sensors' held measurements are in the own states.
    pub fn held_states(&self) -> Option<std::ops::Range<usize>> {
        self.sensors.as_ref().map(|_| N..N + HELD)
    }

    /// How far the estimates are from the vessel: the horizontal position and the heading.
    pub fn outputs(&self, fr: &Frozen, z: &[Z3; 2], x: &[f64], out: &mut Vec<Output>) {
        let pos = fr.origin + z[0][1];
        let err = (x[ETA] - pos.x).hypot(x[ETA + 1] - pos.y);
        let psi = self.heading(fr.euler.z);
        out.push(Output::new(
            "observer_position_error",
            "m",
            "horizontal distance of the observer's position estimate from the vessel's position",
            err,
        ));
        out.push(Output::new(
            "observer_heading_error",
            "rad",
            "observer's heading estimate less the vessel's heading",
            super::pid::wrap_pi(x[ETA + 2] - psi),
        ));
    }
}
