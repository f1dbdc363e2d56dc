//! The natural catenary of a pipe (or any cable) hanging from a point to a flat seabed that it
//! meets tangentially: bending stiffness and elongation neglected, uniform submerged weight
//! `w` per metre (docs/model.md §5.6).
//!
//! With the horizontal tension `H` (constant along the pipe) and `a = H / w` the catenary
//! parameter, the pipe with its lowest point (the touchdown point, TDP) at the seabed and the
//! hang-off point a height `d` above it satisfies (the classical catenary; e.g. M. Irvine,
//! *Cable Structures*, 1981, §1.2; O. M. Faltinsen, *Sea Loads on Ships and Offshore
//! Structures*, 1990, §8.2):
//! - horizontal span from the TDP to the hang-off point: `X = a acosh(1 + d/a)`;
//! - suspended length: `s = √(d² + 2ad) = a sinh(X/a)`;
//! - vertical tension at the top: `V = w s`; top tension `T = √(H² + V²) = H + w d`;
//! - angle of the pipe at the top from the horizontal: `tan α = V/H = s/a`.
//!
//! Given any one of `H`, `T`, `α` or `X` (with `w`, `d`), the others follow: `H = T − w d`;
//! `a = d (1 + sec α) / tan² α` (from `s² = a² tan² α = d² + 2ad`); and from `X` by solving the
//! monotone `X = a acosh(1 + d/a)` for `a`.

use crate::error::{Error, Result};

/// The catenary from its hang-off point to the touchdown point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Catenary {
    /// Submerged weight per metre `w` (N/m).
    pub weight: f64,
    /// Height of the hang-off point above the seabed `d` (m).
    pub height: f64,
    /// Horizontal tension `H` (N).
    pub horizontal_tension: f64,
}

impl Catenary {
    fn checked(weight: f64, height: f64) -> Result<()> {
        if !(weight.is_finite() && weight > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the catenary's submerged weight must be > 0 (N/m), got {weight}"
            )));
        }
        if !(height.is_finite() && height > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the catenary's hang-off height above the seabed must be > 0 (m), got {height}"
            )));
        }
        Ok(())
    }

    /// From the horizontal tension `H` (N, > 0).
    pub fn from_horizontal_tension(weight: f64, height: f64, h: f64) -> Result<Self> {
        Self::checked(weight, height)?;
        if !(h.is_finite() && h > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the horizontal tension must be > 0 (N), got {h}"
            )));
        }
        Ok(Self {
            weight,
            height,
            horizontal_tension: h,
        })
    }

    /// From the top tension `T` (N): `H = T − w d`, which must be > 0 (the top tension must
    /// exceed the weight of a vertical pipe of the same height).
    pub fn from_top_tension(weight: f64, height: f64, t: f64) -> Result<Self> {
        Self::checked(weight, height)?;
        let h = t - weight * height;
        if !(h.is_finite() && h > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the top tension must exceed w·d = {} N (the weight of a vertical pipe from the seabed to the hang-off point), got {t}",
                weight * height
            )));
        }
        Self::from_horizontal_tension(weight, height, h)
    }

    /// From the pipe's angle at the top, measured from the horizontal (rad, in (0, π/2)):
    /// `a = d (1 + sec α) / tan² α`.
    pub fn from_top_angle(weight: f64, height: f64, alpha: f64) -> Result<Self> {
        Self::checked(weight, height)?;
        if !(alpha.is_finite() && alpha > 0.0 && alpha < std::f64::consts::FRAC_PI_2) {
            return Err(Error::InvalidInput(format!(
                "the pipe's angle at the top must lie strictly between 0 and 90 degrees from the horizontal, got {} degrees",
                alpha.to_degrees()
            )));
        }
        let (c, t) = (alpha.cos(), alpha.tan());
        let a = height * (1.0 + 1.0 / c) / (t * t);
        Self::from_horizontal_tension(weight, height, weight * a)
    }

    /// From the horizontal span `X` (m, > 0) between the touchdown point and the hang-off point:
    /// the root `a` of `a acosh(1 + d/a) = X`, increasing in `a` from 0 (a vertical pipe) to ∞
    /// (`≈ √(2ad)`), by Newton's method on `ln a` from a bracketing start, to round-off.
    pub fn from_span(weight: f64, height: f64, span: f64) -> Result<Self> {
        Self::checked(weight, height)?;
        if !(span.is_finite() && span > 0.0) {
            return Err(Error::InvalidInput(format!(
                "the horizontal span from the touchdown point must be > 0 (m), got {span}"
            )));
        }
        let a = parameter_from_span(height, span);
        Self::from_horizontal_tension(weight, height, weight * a)
    }

    /// The catenary parameter `a = H / w` (m).
    pub fn parameter(&self) -> f64 {
        self.horizontal_tension / self.weight
    }
    /// The suspended length `s = √(d² + 2ad)` (m).
    pub fn suspended_length(&self) -> f64 {
        let (a, d) = (self.parameter(), self.height);
        (d * (d + 2.0 * a)).sqrt()
    }
    /// The horizontal span from the touchdown point to the hang-off point,
    /// `X = a acosh(1 + d/a) = a ln(1 + d/a + √((d/a)(2 + d/a)))` (m), written with `ln_1p` so
    /// that it stays accurate for `d ≪ a`.
    pub fn span(&self) -> f64 {
        span_of(self.parameter(), self.height)
    }
    /// The vertical tension at the top, `V = w s` (N).
    pub fn vertical_tension(&self) -> f64 {
        self.weight * self.suspended_length()
    }
    /// The top tension `T = H + w d` (N).
    pub fn top_tension(&self) -> f64 {
        self.horizontal_tension + self.weight * self.height
    }
    /// The pipe's angle at the top from the horizontal, `atan(V/H)` (rad).
    pub fn top_angle(&self) -> f64 {
        self.suspended_length().atan2(self.parameter())
    }
}

/// `a acosh(1 + d/a)`, accurate for every ratio `d/a`.
fn span_of(a: f64, d: f64) -> f64 {
    let r = d / a;
    a * (r + (r * (2.0 + r)).sqrt()).ln_1p()
}

/// The catenary parameter with the span `x` at the height `d` (see [`Catenary::from_span`]).
fn parameter_from_span(d: f64, x: f64) -> f64 {
    // Start: the parabolic limit a ≈ x²/(2d) for x ≫ d, and a small a for x ≪ d; then
    // bracket [lo, hi] and Newton on ln a with bisection as a safeguard.
    let (mut lo, mut hi) = (f64::MIN_POSITIVE.sqrt() * d, 1.0f64);
    while span_of(hi, d) < x {
        hi *= 4.0;
    }
    let mut a = (x * x / (2.0 * d)).clamp(lo.max(hi / 1e30), hi);
    for _ in 0..200 {
        let f = span_of(a, d) - x;
        if f > 0.0 {
            hi = a;
        } else {
            lo = a;
        }
        // dX/da = acosh(1 + d/a) − d / √(d² + 2ad)  (> 0).
        let r = d / a;
        let deriv = (r + (r * (2.0 + r)).sqrt()).ln_1p() - d / (d * (d + 2.0 * a)).sqrt();
        let mut next = a - f / deriv;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        if (next - a).abs() <= 2.0 * f64::EPSILON * a {
            return next;
        }
        a = next;
    }
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_four_ways_in_give_the_same_catenary() {
        let (w, d) = (1000.0, 300.0);
        let c = Catenary::from_horizontal_tension(w, d, 5e5).unwrap();
        for other in [
            Catenary::from_top_tension(w, d, c.top_tension()).unwrap(),
            Catenary::from_top_angle(w, d, c.top_angle()).unwrap(),
            Catenary::from_span(w, d, c.span()).unwrap(),
        ] {
            let r = (other.horizontal_tension - c.horizontal_tension).abs() / 5e5;
            assert!(r < 1e-13, "{other:?} vs {c:?}: {r}");
        }
        // T² = H² + V² (the top tension is the norm of the top force).
        let (h, v) = (c.horizontal_tension, c.vertical_tension());
        assert!((h.hypot(v) - c.top_tension()).abs() < 1e-12 * c.top_tension());
    }

    #[test]
    fn the_span_inverse_holds_over_twenty_decades_of_slack() {
        for d in [1.0, 50.0, 3000.0] {
            for x in [1e-6, 1e-2, 1.0, 10.0, 1e3, 1e5, 1e8] {
                let c = Catenary::from_span(7.0, d, x).unwrap();
                let back = c.span();
                assert!((back - x).abs() <= 1e-13 * x, "d {d} x {x}: {back}");
            }
        }
    }

    #[test]
    fn bad_inputs_are_named() {
        for (e, needle) in [
            (
                Catenary::from_horizontal_tension(-1.0, 10.0, 1.0),
                "submerged weight must be > 0",
            ),
            (
                Catenary::from_horizontal_tension(1.0, 0.0, 1.0),
                "height above the seabed must be > 0",
            ),
            (
                Catenary::from_top_tension(10.0, 100.0, 500.0),
                "top tension must exceed w·d = 1000 N",
            ),
            (
                Catenary::from_top_angle(10.0, 100.0, 2.0),
                "strictly between 0 and 90 degrees",
            ),
            (
                Catenary::from_span(10.0, 100.0, 0.0),
                "span from the touchdown",
            ),
        ] {
            let msg = e.unwrap_err().to_string();
            assert!(msg.contains(needle), "{msg}");
        }
    }
}
