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
    /// Save every k-th step (the last step is always saved).
    pub save_every: usize,
    /// Which flow is outermost in a composition.
    pub outer: Outer,
    /// Compute the energy ledger.
    pub ledger: bool,
}

/// Upper bound on the number of steps of one run.
pub const MAX_STEPS: usize = 2_000_000_000;

impl Options {
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
        if self.save_every == 0 {
            return Err(Error::InvalidInput(
                "save_every must be an integer >= 1, got 0".into(),
            ));
        }
        Ok(())
    }
}
