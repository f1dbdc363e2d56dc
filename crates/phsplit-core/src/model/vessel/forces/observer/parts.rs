//! The observer's gains placed at the bias bandwidth, and the names of its states (with the
//! sensors' after them): `observer.rs`.

use super::super::sensors::{self, Sensors};
use super::super::OwnState;
use super::N;
use crate::error::Error;
use nalgebra::{Matrix3, Vector3};

/// K₄ and K₃ as given, or placed (the same in x and y, below): the low-frequency error
/// dynamics of each degree of freedom (below the wave filter, `η̃ ≈ R ν̃ / K₂`) are
/// `M s² + (D + K₄/K₂) s + K₃/K₂ = 0`; critically damped at ω_b they need `K₃ = K₂ M ω_b²`,
/// `K₄ = K₂ (2 M ω_b − D)`. `given_b`: ω_b was given (else it is the default ω₀/5).
pub(super) fn gains(
    k4: Option<Vector3<f64>>,
    k3: Option<Vector3<f64>>,
    omega_b: f64,
    given_b: bool,
    k2: f64,
    m: &Matrix3<f64>,
    damping: &Vector3<f64>,
) -> crate::Result<(Vector3<f64>, Vector3<f64>)> {
    if let (Some(k4), Some(k3)) = (k4, k3) {
        if given_b {
            return Err(Error::InvalidInput(
                "observer.bias_bandwidth places velocity_gain and bias_gain, and both are given, so it would not act: remove bias_bandwidth, or one of the gains".into(),
            ));
        }
        return Ok((k4, k3));
    }
    let mut p4 = Vector3::zeros();
    let mut p3 = Vector3::zeros();
    for (i, dof) in ["surge", "sway", "yaw"].iter().enumerate() {
        let mi = m[(i, i)];
        let excess = 2.0 * mi * omega_b - damping[i];
        if excess <= 0.0 {
            return Err(Error::InvalidInput(format!(
                "observer: in {dof} the model damping ({:.4e}) alone exceeds the critical damping of the bias estimate at bias_bandwidth {}= {omega_b} rad/s ({:.4e}): raise bias_bandwidth, or give velocity_gain and bias_gain",
                damping[i],
                if given_b { "" } else { "(not given: wave_frequency / 5) " },
                2.0 * mi * omega_b
            )));
        }
        p4[i] = k2 * excess;
        p3[i] = k2 * mi * omega_b * omega_b;
    }
    // The same in x and y, placed with the mean of surge and sway: `K₃`, `K₄` act on the
    // spatial residual and reach the hull's axes through `R(ψ)ᵀ`; unequal, they would turn a
    // surge residual into a sway estimate at every heading off the axes (with the paper's
    // surge and sway damping, 2 % of the surge wave motion into sway at 31°).
    for p in [&mut p4, &mut p3] {
        let mean = 0.5 * (p[0] + p[1]);
        p[0] = mean;
        p[1] = mean;
    }
    Ok((k4.unwrap_or(p4), k3.unwrap_or(p3)))
}

pub(super) fn states(sensed: bool) -> Vec<OwnState> {
    let mut out = Vec::with_capacity(N + sensors::N);
    let mut push = |name: &str, unit: &str, long: &str| {
        out.push(OwnState {
            name: name.into(),
            unit: unit.into(),
            long_name: long.into(),
            initial: 0.0,
        })
    };
    for (d, u) in [("x", "m s"), ("y", "m s"), ("yaw", "rad s")] {
        push(
            &format!("observer_wave_state_{d}"),
            u,
            &format!("observer's first wave-model state in {d} (the integral of the wave motion)"),
        );
    }
    for (d, u) in [("x", "m"), ("y", "m"), ("yaw", "rad")] {
        push(
            &format!("observer_wave_{d}"),
            u,
            &format!("observer's estimate of the wave-frequency motion in {d} (spatial)"),
        );
    }
    push(
        "observer_x",
        "m",
        "observer's estimate of the low-frequency position x (spatial)",
    );
    push(
        "observer_y",
        "m",
        "observer's estimate of the low-frequency position y (spatial)",
    );
    push(
        "observer_heading",
        "rad",
        "observer's estimate of the low-frequency heading",
    );
    for (d, u) in [("x", "N"), ("y", "N"), ("yaw", "N m")] {
        push(
            &format!("observer_bias_{d}"),
            u,
            &format!("observer's estimate of the slowly varying force in {d} (spatial frame)"),
        );
    }
    push(
        "observer_surge_velocity",
        "m s-1",
        "observer's estimate of the surge velocity",
    );
    push(
        "observer_sway_velocity",
        "m s-1",
        "observer's estimate of the sway velocity",
    );
    push(
        "observer_yaw_rate",
        "rad s-1",
        "observer's estimate of the yaw rate",
    );
    for (d, u) in [("x", "m s"), ("y", "m s"), ("heading", "rad s")] {
        push(
            &format!("control_integral_{d}"),
            u,
            &format!("integral of the estimated error in {d} (the controller's I term)"),
        );
    }
    if sensed {
        for (name, unit, long) in Sensors::states() {
            push(name, unit, long);
        }
    }
    out
}
