//! The sea's transfer-function tables (docs/model.md §5.9): a table over relative direction and
//! frequency, interpolated linearly in frequency and periodically in direction, its values at
//! each component's frequency, and the reading of a `[direction][frequency][n]` array from the
//! vessel file.

use super::Component;
use crate::error::Error;
use crate::model::grid::periodic_weights;
use crate::model::vessel::params::Params;
use toml::Value;

/// A table over (relative direction, frequency) of `N` real or complex values, interpolated
/// linearly in frequency and periodically in direction.
#[derive(Debug, Clone, PartialEq)]
pub struct Table<const N: usize> {
    pub frequencies: Vec<f64>,
    /// Radians, increasing, spanning less than 2π.
    pub directions: Vec<f64>,
    /// `[direction][frequency]`.
    pub re: Vec<Vec<[f64; N]>>,
    pub im: Vec<Vec<[f64; N]>>,
}

/// A table's values at one frequency, per direction: the frequency interpolation done once.
#[derive(Debug, Clone, PartialEq)]
pub struct AtFrequency<const N: usize> {
    pub re: Vec<[f64; N]>,
    pub im: Vec<[f64; N]>,
}

impl<const N: usize> Table<N> {
    /// The values at `omega` for every direction of the grid (linear in frequency).
    pub fn at_frequency(&self, omega: f64) -> AtFrequency<N> {
        let mut re = Vec::with_capacity(self.directions.len());
        let mut im = Vec::with_capacity(self.directions.len());
        for i in 0..self.directions.len() {
            // The grid's own interpolation, at the direction's node.
            let (r, m) = self.at(omega, self.directions[i]);
            re.push(r);
            im.push(m);
        }
        AtFrequency { re, im }
    }

    /// Interpolate values precomputed at one frequency in the relative direction `beta`,
    /// periodically, as [`Table::at`] does.
    pub fn in_direction(&self, pre: &AtFrequency<N>, beta: f64) -> ([f64; N], [f64; N]) {
        let (i0, i1, wd) = self.direction_weights(beta);
        let mut re = [0.0; N];
        let mut im = [0.0; N];
        for n in 0..N {
            re[n] = (1.0 - wd) * pre.re[i0][n] + wd * pre.re[i1][n];
            im[n] = (1.0 - wd) * pre.im[i0][n] + wd * pre.im[i1][n];
        }
        (re, im)
    }

    /// The two directions around `beta` and the weight of the second.
    fn direction_weights(&self, beta: f64) -> (usize, usize, f64) {
        periodic_weights(&self.directions, beta)
    }

    /// The interpolated (re, im) at `omega` (inside the frequency range) and relative
    /// direction `beta` (rad, any value).
    pub fn at(&self, omega: f64, beta: f64) -> ([f64; N], [f64; N]) {
        let f = &self.frequencies;
        let j = f
            .partition_point(|x| *x <= omega)
            .clamp(1, f.len().max(2) - 1);
        let (j0, j1) = if f.len() == 1 { (0, 0) } else { (j - 1, j) };
        let wf = if j0 == j1 {
            0.0
        } else {
            ((omega - f[j0]) / (f[j1] - f[j0])).clamp(0.0, 1.0)
        };
        let (i0, i1, wd) = self.direction_weights(beta);
        let mut re = [0.0; N];
        let mut im = [0.0; N];
        for (di, wdi) in [(i0, 1.0 - wd), (i1, wd)] {
            for (fj, wfj) in [(j0, 1.0 - wf), (j1, wf)] {
                let w = wdi * wfj;
                if w == 0.0 {
                    continue;
                }
                for n in 0..N {
                    re[n] += w * self.re[di][fj][n];
                    im[n] += w * self.im[di][fj][n];
                }
            }
        }
        (re, im)
    }
}

/// A `[direction][frequency][n]` array of finite numbers.
pub(super) fn cube(
    p: &mut Params,
    key: &str,
    nd: usize,
    nf: usize,
    n: usize,
    unit: &str,
    required: bool,
) -> crate::Result<Option<Vec<Vec<Vec<f64>>>>> {
    let Some(v) = p.take_raw("waves", key)? else {
        if required {
            return Err(Error::Parse(format!(
                "missing field `{key}` in [waves] ([direction][frequency][{n}] numbers, {unit})"
            )));
        }
        return Ok(None);
    };
    let shape = || {
        Error::InvalidInput(format!(
            "waves.{key} must be {nd} × {nf} × {n} numbers ([direction][frequency][dof], {unit}), as rao_directions × rao_frequencies"
        ))
    };
    let Value::Array(ds) = &v else {
        return Err(shape());
    };
    if ds.len() != nd {
        return Err(shape());
    }
    let mut out = Vec::with_capacity(nd);
    for (i, d) in ds.iter().enumerate() {
        let Value::Array(fs) = d else {
            return Err(shape());
        };
        if fs.len() != nf {
            return Err(shape());
        }
        let mut row = Vec::with_capacity(nf);
        for (j, f) in fs.iter().enumerate() {
            let Value::Array(xs) = f else {
                return Err(shape());
            };
            if xs.len() != n {
                return Err(shape());
            }
            let mut vals = Vec::with_capacity(n);
            for (k, x) in xs.iter().enumerate() {
                let y = match x {
                    Value::Float(y) => *y,
                    Value::Integer(y) => *y as f64,
                    _ => return Err(shape()),
                };
                if !y.is_finite() {
                    return Err(Error::InvalidInput(format!(
                        "waves.{key}[{i}][{j}][{k}] must be finite ({unit}), got {y}"
                    )));
                }
                vals.push(y);
            }
            row.push(vals);
        }
        out.push(row);
    }
    p.record_value("waves", key, v);
    Ok(Some(out))
}

pub(super) fn components_pre<const N: usize>(c: &[Component], t: &Table<N>) -> Vec<AtFrequency<N>> {
    c.iter().map(|c| t.at_frequency(c.omega)).collect()
}
