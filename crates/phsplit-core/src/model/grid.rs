//! Tables on grids, as the components read them: checks that a grid increases (and, for
//! directions, spans less than a turn), and the interval and weight of linear interpolation on a
//! periodic grid of angles.

use crate::error::{Error, Result};
use std::f64::consts::TAU;

/// `values` (named `name`, in `unit`) must increase strictly.
pub fn check_increasing(name: &str, values: &[f64], unit: &str) -> Result<()> {
    match (1..values.len()).find(|&i| values[i] <= values[i - 1]) {
        Some(i) => Err(Error::InvalidInput(format!(
            "{name} must increase strictly ({unit}): [{i}] = {} after {}",
            values[i],
            values[i - 1]
        ))),
        None => Ok(()),
    }
}

/// A periodic grid of angles (degrees): increasing strictly and spanning less than 360.
pub fn check_periodic(name: &str, degrees: &[f64]) -> Result<()> {
    check_increasing(name, degrees, "degrees")?;
    match (degrees.first(), degrees.last()) {
        (Some(a), Some(b)) if b - a >= 360.0 => Err(Error::InvalidInput(format!(
            "{name} must span less than 360 degrees (the grid is periodic), got {a} to {b}"
        ))),
        _ => Ok(()),
    }
}

/// Linear interpolation at the angle `x` (rad, any value) on the periodic grid `grid` (rad,
/// increasing, spanning less than 2π): the two nodes around `x` and the weight of the second,
/// the last interval closing the circle.
pub fn periodic_weights(grid: &[f64], x: f64) -> (usize, usize, f64) {
    let n = grid.len();
    if n <= 1 {
        return (0, 0, 0.0);
    }
    let b = grid[0] + (x - grid[0]).rem_euclid(TAU);
    let i = grid.partition_point(|g| *g <= b);
    if i == 0 || i == n {
        let bb = if b < grid[n - 1] { b + TAU } else { b };
        let w = (bb - grid[n - 1]) / (grid[0] + TAU - grid[n - 1]);
        (n - 1, 0, w.clamp(0.0, 1.0))
    } else {
        let w = (b - grid[i - 1]) / (grid[i] - grid[i - 1]);
        (i - 1, i, w.clamp(0.0, 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn periodic_weights_close_the_circle() {
        let g = [0.0, PI / 2.0, PI];
        assert_eq!(periodic_weights(&g, PI / 4.0), (0, 1, 0.5));
        let (i0, i1, w) = periodic_weights(&g, 1.5 * PI);
        assert_eq!((i0, i1), (2, 0));
        assert!((w - 0.5).abs() < 1e-15);
        let (i0, i1, w) = periodic_weights(&g, -PI / 2.0);
        assert_eq!((i0, i1), (2, 0));
        assert!((w - 0.5).abs() < 1e-15);
        assert!(check_periodic("g", &[0.0, 90.0, 360.0]).is_err());
        assert!(check_increasing("t", &[0.0, 0.0], "s").is_err());
    }
}
