//! The kernels' options, checked once.

use crate::error::{Error, Result};
use crate::methods::Outer;

/// Options common to the kernels.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Start time.
    pub t0: f64,
    /// Step size (> 0).
    pub h: f64,
    /// Number of steps.
    pub n_steps: usize,
    /// Length of the last step (`0 < last_h ≤ h`; `h` when the span is a whole number of steps):
    /// a run reaches its end time exactly.
    pub last_h: f64,
    /// Save every k-th step (the last step is always saved).
    pub save_every: usize,
    /// Which flow is outermost in a composition.
    pub outer: Outer,
    /// Compute the energy ledger.
    pub ledger: bool,
    /// Adaptive steps to this tolerance (`h` is then the first step tried); `None`: fixed steps.
    pub tolerance: Option<Tolerance>,
}

/// The tolerance of an adaptive run (`solve/adaptive.rs`).
#[derive(Debug, Clone, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance (> 0).
    pub rtol: f64,
    /// Absolute tolerance (> 0), in the units of the model's error norm.
    pub atol: f64,
    /// Longest step (s).
    pub h_max: f64,
    /// End time (s).
    pub t1: f64,
    /// Output times (s, increasing, within the run): the steps land on them and only they are
    /// saved, with the start and the end. Empty: every `save_every`-th accepted step.
    pub save_at: Vec<f64>,
}

impl Tolerance {
    /// Check the tolerance of a run from `t0`; the message names the setting and its range.
    pub fn validate(&self, t0: f64) -> Result<()> {
        use crate::model::vessel::params::compact;
        for (name, v, top, text) in [
            ("rtol", self.rtol, 1.0, "1"),
            ("atol", self.atol, 1e3, "1e3"),
        ] {
            if !(v.is_finite() && v > 0.0 && v <= top) {
                return Err(Error::InvalidInput(format!(
                    "{name} must be a number in (0, {text}], got {}",
                    compact(v)
                )));
            }
        }
        if self.rtol < 1e-13 {
            return Err(Error::InvalidInput(format!(
                "rtol must be at least 1e-13 (below it round-off decides the steps), got {}",
                compact(self.rtol)
            )));
        }
        if self.atol < 1e-12 {
            return Err(Error::InvalidInput(format!(
                "atol must be at least 1e-12 (m, rad, m/s, rad/s: below it round-off of the position and attitude decides the steps), got {}",
                compact(self.atol)
            )));
        }
        if !(self.h_max.is_finite() && self.h_max > 0.0) {
            return Err(Error::InvalidInput(format!(
                "h_max must be finite and > 0 (s), got {}",
                self.h_max
            )));
        }
        if self
            .save_at
            .iter()
            .any(|v| !v.is_finite() || *v < t0 || *v > self.t1)
            || self.save_at.windows(2).any(|w| w[1] <= w[0])
        {
            return Err(Error::InvalidInput(format!(
                "save_at must be strictly increasing finite times within [{t0}, {}] s",
                self.t1
            )));
        }
        if !(self.t1.is_finite() && self.t1 > t0) {
            return Err(Error::InvalidInput(format!(
                "the end time must be finite and after t0 = {t0} s, got {}",
                self.t1
            )));
        }
        let n = (self.t1 - t0) / self.h_max;
        if n > super::MAX_STEPS as f64 {
            return Err(Error::InvalidInput(format!(
                "t_span / h_max asks for at least {n:.3e} steps; a run takes at most {:.0e} steps (take a longer h_max)",
                super::MAX_STEPS as f64
            )));
        }
        Ok(())
    }
}

/// Upper bound on the number of steps of one run.
pub const MAX_STEPS: usize = 2_000_000_000;

impl Options {
    /// Options for `n_steps` steps of `h` from `t0` (the last one whole), saving every
    /// `save_every`-th step, S2 outermost, with the ledger.
    pub fn steps(t0: f64, h: f64, n_steps: usize, save_every: usize) -> Self {
        Self {
            t0,
            h,
            n_steps,
            last_h: h,
            save_every,
            outer: Outer::Dissipative,
            ledger: true,
            tolerance: None,
        }
    }

    /// The length of step `n` (0-based).
    pub fn step_length(&self, n: usize) -> f64 {
        if n + 1 == self.n_steps {
            self.last_h
        } else {
            self.h
        }
    }

    /// The time at the end of step `n`.
    pub fn time_after(&self, n: usize) -> f64 {
        if n + 1 == self.n_steps && self.last_h != self.h {
            self.t0 + n as f64 * self.h + self.last_h
        } else {
            self.t0 + (n + 1) as f64 * self.h
        }
    }

    /// Check the options; the message names the field and the allowed range.
    pub fn validate(&self) -> Result<()> {
        if !self.t0.is_finite() {
            return Err(Error::InvalidInput(format!(
                "t0 must be finite (s), got {}",
                self.t0
            )));
        }
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(Error::InvalidInput(format!(
                "h must be finite and > 0 (s), got {}",
                self.h
            )));
        }
        if self.n_steps == 0 || self.n_steps > MAX_STEPS {
            return Err(Error::InvalidInput(format!(
                "the number of steps must be between 1 and {MAX_STEPS}, got {}",
                self.n_steps
            )));
        }
        if !(self.last_h > 0.0 && self.last_h <= self.h) {
            return Err(Error::InvalidInput(format!(
                "the last step must be in (0, h] (s), got {} with h = {}",
                self.last_h, self.h
            )));
        }
        // Every step must advance the time: h above the resolution of t over the run.
        let t_max = self
            .t0
            .abs()
            .max((self.t0 + self.n_steps as f64 * self.h).abs());
        let ulp = t_max * f64::EPSILON;
        if self.last_h <= 4.0 * ulp || self.h <= 64.0 * ulp {
            return Err(Error::InvalidInput(format!(
                "h = {} s is below what the times of this run can resolve (|t| up to {t_max:e} s, where doubles are {ulp:.3e} s apart): shift t_span towards 0 or take a longer h",
                if self.last_h < self.h { self.last_h } else { self.h }
            )));
        }
        if self.save_every == 0 {
            return Err(Error::InvalidInput(
                "save_every must be an integer >= 1, got 0".into(),
            ));
        }
        Ok(())
    }
}
