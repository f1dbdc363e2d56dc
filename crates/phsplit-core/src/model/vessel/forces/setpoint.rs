//! The controller's moving set point, table `[setpoint]` (docs/model.md §5.7): its keys and
//! their validation (the set point's use is the controller's, `pid.rs`).

use super::pid::wrap_pi;
use crate::error::Error;
use crate::model::reference::{Interpolation, Reference, CHANNELS};
use crate::model::vessel::params::{physical, Params, Range};

/// The `[setpoint]` table, if present (see the module documentation).
pub(super) fn read(p: &mut Params, euler_reference: &[f64; 3]) -> crate::Result<Option<Reference>> {
    const T: &str = "setpoint";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let omega = p.f64(T, "natural_frequency", "rad/s", Range::Positive)?;
    let zeta = p
        .opt_f64(T, "relative_damping", "dimensionless", Range::Positive)?
        .unwrap_or(1.0);
    let interpolation = match p.choice(T, "interpolation", &["linear", "step"])? {
        "step" => Interpolation::Step,
        _ => Interpolation::Linear,
    };
    let positions = p
        .rows(T, "positions", 3, "m, spatial", Range::Finite)?
        .ok_or_else(|| {
            Error::Parse("missing field `positions` in [setpoint] (rows of 3 numbers, m, spatial: the set points)".into())
        })?;
    if positions.is_empty() {
        return Err(Error::InvalidInput(
            "setpoint.positions must have at least one row (m, spatial)".into(),
        ));
    }
    let headings = p.rows(
        T,
        "headings",
        1,
        "rad",
        Range::Physical(&physical::ANGLE_RAD),
    )?;
    if let Some(hd) = &headings {
        if hd.len() != positions.len() {
            return Err(Error::InvalidInput(format!(
                "setpoint.headings must have one value per row of setpoint.positions ({} rows), got {}",
                positions.len(),
                hd.len()
            )));
        }
    }
    let times = p.rows(T, "times", 1, "s", Range::Physical(&physical::TIME))?;
    let speed = p.opt_f64(T, "speed", "m/s", Range::Positive)?;
    let start = p.opt_f64(T, "start_time", "s", Range::Physical(&physical::TIME))?;
    let times: Vec<f64> = match (times, speed) {
        (Some(t), None) => {
            if start.is_some() {
                return Err(Error::InvalidInput(
                    "setpoint.start_time goes with setpoint.speed (waypoints); with setpoint.times each row has its own time".into(),
                ));
            }
            if t.len() != positions.len() {
                return Err(Error::InvalidInput(format!(
                    "setpoint.times must have one value per row of setpoint.positions ({} rows), got {}",
                    positions.len(),
                    t.len()
                )));
            }
            t.into_iter().map(|r| r[0]).collect()
        }
        (None, Some(v)) => {
            let mut t = vec![start.unwrap_or(0.0)];
            for k in 1..positions.len() {
                let d: f64 = (0..3)
                    .map(|i| (positions[k][i] - positions[k - 1][i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                if d == 0.0 {
                    return Err(Error::InvalidInput(format!(
                        "setpoint.positions[{k}] repeats the waypoint before it: waypoints passed at a speed must differ"
                    )));
                }
                t.push(t[k - 1] + d / v);
            }
            t
        }
        (Some(_), Some(_)) => {
            return Err(Error::InvalidInput(
                "[setpoint] takes either times (s, one per row) or speed (m/s, waypoints), not both".into(),
            ))
        }
        (None, None) => {
            return Err(Error::InvalidInput(
                "[setpoint] needs times (s, one per row of positions) or speed (m/s, the rows are waypoints)".into(),
            ))
        }
    };
    // Headings are unwrapped: each row turns the short way from the one before (3.1 then
    // −3.1 rad is a turn of 0.08 rad, not of 6.2).
    let mut yaw_prev: Option<f64> = None;
    let values: Vec<[f64; CHANNELS]> = positions
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let mut yaw = headings.as_ref().map_or(euler_reference[2], |h| h[k][0]);
            if let Some(prev) = yaw_prev {
                yaw = prev + wrap_pi(yaw - prev);
            }
            yaw_prev = Some(yaw);
            [
                r[0],
                r[1],
                r[2],
                euler_reference[0],
                euler_reference[1],
                yaw,
            ]
        })
        .collect();
    Reference::new(omega, zeta, times, values, interpolation).map(Some)
}
