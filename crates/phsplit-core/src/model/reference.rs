//! Moving set points: a time table of set points shaped by the third-order reference model of
//! T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed. (Wiley,
//! 2021), §12.1 (the cascade of a first-order low-pass filter and a mass–spring–damper):
//!
//! `x_d / r = ω³ / ((s + ω)(s² + 2ζωs + ω²))`, i.e.
//! `x_d''' + (2ζ+1)ω x_d'' + (2ζ+1)ω² x_d' + ω³ x_d = ω³ r`,
//!
//! per channel, giving a smooth desired position, velocity and acceleration from a set point
//! `r(t)` that steps or moves at constant speed between the rows of a table
//! (docs/model.md §5.7).
//!
//! The filter is linear and `r` is piecewise linear in time, so its solution is exact: on a
//! segment the augmented state `(x_d, x_d', x_d'', r, r')` obeys `z' = Ā z` with `r'' = 0`,
//! and `z(t) = exp(Ā (t − t_k)) z_k`. The states at the rows are computed once; a value at
//! any time is one 5×5 exponential away (no step size, no error beyond round-off). The
//! filter starts at rest on the first row's set point.
//!
//! A collocation asks for the same stage times at every pass of its fixed point: each thread
//! keeps the last few values it computed (by the model's identity and the time's bits), so a
//! time asked again costs no exponential, and every value is the same bits however often, in
//! whatever order and on whichever thread it is asked.

use super::kept::{self, Identity, Recent};
use crate::error::{Error, Result};
use nalgebra::{SMatrix, SVector};

/// How many values a thread keeps: the stages of a three-stage collocation taken in turn, and
/// one more.
const KEPT: usize = 4;

thread_local! {
    /// The last values computed on this thread ([`kept::at_time`]).
    static LAST: Recent<Desired, KEPT> = const { Recent::new([(0, 0, Desired::ZERO); KEPT]) };
}

/// How the set point moves between two rows of the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// It stays at the earlier row's value until the next row's time (a step command).
    Step,
    /// It moves at constant speed from one row to the next (a route at a given speed).
    Linear,
}

/// The number of filtered channels: position `x, y, z` and the Euler angles.
pub const CHANNELS: usize = 6;

/// The reference model with its set-point table. Built by [`Reference::new`] and read, never
/// changed: the states at the rows and the identity of the per-thread memo are the table's.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// Natural frequency `ω` (rad/s) and relative damping `ζ`.
    pub omega: f64,
    pub zeta: f64,
    /// Row times (s), increasing.
    pub times: Vec<f64>,
    /// Set points per row, per channel.
    pub values: Vec<[f64; CHANNELS]>,
    pub interpolation: Interpolation,
    /// The filter's augmented state at each row, per channel.
    knots: Vec<[SVector<f64, 5>; CHANNELS]>,
    key: Identity,
}

/// The desired value, rate and acceleration of every channel at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Desired {
    pub value: [f64; CHANNELS],
    pub rate: [f64; CHANNELS],
    pub acceleration: [f64; CHANNELS],
}

impl Desired {
    const ZERO: Desired = Desired {
        value: [0.0; CHANNELS],
        rate: [0.0; CHANNELS],
        acceleration: [0.0; CHANNELS],
    };
}

impl Reference {
    /// Build the model; `times` strictly increasing and finite, `omega > 0`, `zeta > 0`.
    pub fn new(
        omega: f64,
        zeta: f64,
        times: Vec<f64>,
        values: Vec<[f64; CHANNELS]>,
        interpolation: Interpolation,
    ) -> Result<Self> {
        if !(omega.is_finite() && omega > 0.0) {
            return Err(Error::InvalidInput(format!(
                "setpoint.natural_frequency must be > 0 (rad/s), got {omega}"
            )));
        }
        if !(zeta.is_finite() && zeta > 0.0) {
            return Err(Error::InvalidInput(format!(
                "setpoint.relative_damping must be > 0, got {zeta}"
            )));
        }
        if times.is_empty() || times.len() != values.len() {
            return Err(Error::InvalidInput(format!(
                "the set-point table needs one or more rows with a time each: {} times for {} set points",
                times.len(),
                values.len()
            )));
        }
        for (i, t) in times.iter().enumerate() {
            if !t.is_finite() {
                return Err(Error::InvalidInput(format!(
                    "setpoint.times[{i}] must be finite (s), got {t}"
                )));
            }
            if i > 0 && *t <= times[i - 1] {
                return Err(Error::InvalidInput(format!(
                    "setpoint.times must increase strictly (s): times[{i}] = {t} after {}",
                    times[i - 1]
                )));
            }
        }
        for (i, row) in values.iter().enumerate() {
            if let Some(j) = row.iter().position(|v| !v.is_finite()) {
                return Err(Error::InvalidInput(format!(
                    "set point {i}, channel {j} must be finite, got {}",
                    row[j]
                )));
            }
        }
        let mut r = Self {
            omega,
            zeta,
            times,
            values,
            interpolation,
            knots: Vec::new(),
            key: Identity::new(),
        };
        let mut z: [SVector<f64, 5>; CHANNELS] = std::array::from_fn(|c| {
            SVector::<f64, 5>::from([r.values[0][c], 0.0, 0.0, r.values[0][c], r.slope(0, c)])
        });
        r.knots.push(z);
        for k in 1..r.times.len() {
            let e = r.transition(r.times[k] - r.times[k - 1]);
            for (c, zc) in z.iter_mut().enumerate() {
                let mut next = e * *zc;
                // The set point and its slope restart from the row (the exact piecewise input).
                next[3] = r.values[k][c];
                next[4] = r.slope(k, c);
                *zc = next;
            }
            r.knots.push(z);
        }
        Ok(r)
    }

    /// The slope of the set point on the segment that starts at row `k`.
    fn slope(&self, k: usize, c: usize) -> f64 {
        match self.interpolation {
            Interpolation::Linear if k + 1 < self.times.len() => {
                (self.values[k + 1][c] - self.values[k][c]) / (self.times[k + 1] - self.times[k])
            }
            _ => 0.0,
        }
    }

    /// `exp(Ā τ)` of the augmented filter.
    fn transition(&self, tau: f64) -> SMatrix<f64, 5, 5> {
        let (w, z) = (self.omega, self.zeta);
        let k = 2.0 * z + 1.0;
        #[rustfmt::skip]
        let a = SMatrix::<f64, 5, 5>::from_row_slice(&[
            0.0, 1.0, 0.0, 0.0, 0.0,
            0.0, 0.0, 1.0, 0.0, 0.0,
            -w * w * w, -k * w * w, -k * w, w * w * w, 0.0,
            0.0, 0.0, 0.0, 0.0, 1.0,
            0.0, 0.0, 0.0, 0.0, 0.0,
        ]);
        (a * tau).exp()
    }

    /// The set point itself (the filter's input) at `t`.
    pub fn set_point(&self, t: f64) -> [f64; CHANNELS] {
        let k = self.segment(t);
        let tau = (t - self.times[k]).max(0.0);
        std::array::from_fn(|c| self.values[k][c] + self.slope(k, c) * tau)
    }

    /// The route's horizontal direction at `t`: the unit vector from the row before `t` to the
    /// next one that differs horizontally (the last such leg after the table's end), or `None`
    /// for a set point that never moves horizontally.
    pub fn route_direction(&self, t: f64) -> Option<[f64; 2]> {
        let n = self.times.len();
        let legs = |k: usize| {
            let (a, b) = (&self.values[k], &self.values[k + 1]);
            let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
            let l = dx.hypot(dy);
            (l > 0.0).then(|| [dx / l, dy / l])
        };
        let k = self.segment(t).min(n.saturating_sub(2));
        (k..n.saturating_sub(1))
            .find_map(legs)
            .or_else(|| (0..k).rev().find_map(legs))
    }

    fn segment(&self, t: f64) -> usize {
        self.times.partition_point(|tk| *tk <= t).saturating_sub(1)
    }

    /// The desired value, rate and acceleration at `t` (before the first row: at rest on it).
    pub fn at(&self, t: f64) -> Desired {
        kept::at_time(&LAST, self.key, t, || self.compute(t))
    }

    /// [`Self::at`], computed.
    fn compute(&self, t: f64) -> Desired {
        let k = self.segment(t);
        let tau = t - self.times[k];
        let mut d = Desired {
            value: [0.0; CHANNELS],
            rate: [0.0; CHANNELS],
            acceleration: [0.0; CHANNELS],
        };
        if tau <= 0.0 {
            for c in 0..CHANNELS {
                let z = self.knots[k][c];
                (d.value[c], d.rate[c], d.acceleration[c]) = (z[0], z[1], z[2]);
            }
            return d;
        }
        let e = self.transition(tau);
        for c in 0..CHANNELS {
            let z = e * self.knots[k][c];
            (d.value[c], d.rate[c], d.acceleration[c]) = (z[0], z[1], z[2]);
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn one(c: f64) -> [f64; CHANNELS] {
        [c; CHANNELS]
    }

    /// ζ = 1: a triple pole at −ω; the unit step response is
    /// `1 − e^{−ωt}(1 + ωt + (ωt)²/2)` (the Erlang-3 distribution function).
    #[test]
    fn step_response_matches_the_closed_form_for_zeta_one() {
        let w = 0.3;
        let r = Reference::new(
            w,
            1.0,
            vec![0.0, 10.0],
            vec![one(0.0), one(1.0)],
            Interpolation::Step,
        )
        .unwrap();
        for t in [10.0, 10.5, 13.0, 20.0, 40.0, 100.0] {
            let x = w * (t - 10.0);
            let want = 1.0 - (-x).exp() * (1.0 + x + 0.5 * x * x);
            let rate = w * (-x).exp() * 0.5 * x * x;
            let d = r.at(t);
            assert!(
                (d.value[0] - want).abs() < 1e-12,
                "{t}: {} vs {want}",
                d.value[0]
            );
            assert!((d.rate[2] - rate).abs() < 1e-12);
        }
        assert_eq!(r.at(5.0).value[0], 0.0);
    }

    /// A value asked again, after others (more than a thread keeps) and on another thread, is
    /// the same bits as computed.
    #[test]
    fn values_asked_again_are_the_computed_ones() {
        let route = |middle: f64| {
            Reference::new(
                0.05,
                0.8,
                vec![0.0, 600.0, 4000.0],
                vec![one(0.0), one(middle), one(30.0)],
                Interpolation::Linear,
            )
            .unwrap()
        };
        let r = route(1.0);
        let times: Vec<f64> = (0..9).map(|i| 100.0 + 517.3 * i as f64).collect();
        let first: Vec<Desired> = times.iter().map(|&t| r.at(t)).collect();
        for (i, &t) in times.iter().enumerate().rev() {
            assert_eq!(r.at(t), r.compute(t));
            assert_eq!(r.at(t), first[i]);
            let (r2, t2) = (r.clone(), t);
            let there = std::thread::spawn(move || r2.at(t2)).join().unwrap();
            assert_eq!(there, first[i]);
        }
        // Another model at the same times is not served this one's values.
        let other = route(2.0);
        assert_ne!(other.at(times[1]).value, r.at(times[1]).value);
        assert_eq!(other.at(times[1]), other.compute(times[1]));
    }
}
