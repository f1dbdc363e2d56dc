//! Waves as a port: first-order wave excitation from force transfer functions (force RAOs) and
//! second-order drift forces by Newman's approximation, on a sea state realised as a sum of
//! regular components (docs/model.md §5.9).
//!
//! Table `[waves]` (optional). The sea state, one entry per component (the Python package
//! realises them from a spectrum: `phsplit.sea`):
//! - `frequencies` ω_k (rad/s, > 0), `amplitudes` a_k (m, ≥ 0), `phases` φ_k (rad) and
//!   `directions` β_k (degrees, the direction the component travels towards, spatial, from
//!   x towards y).
//!
//! The vessel's transfer functions, on a grid of frequencies and directions relative to the
//! hull (`β − ψ`, ψ the heading; 0 = travelling along the body's x axis, following seas;
//! 180 = head seas; the grid must go round the circle, it is interpolated periodically):
//! - `rao_frequencies` (rad/s, increasing, covering every component's frequency) and
//!   `rao_directions` (degrees, increasing, spanning less than 360);
//! - `force_rao_real`, `force_rao_imag`: `[direction][frequency][6]`, the complex excitation
//!   force and moment per metre of wave amplitude (N/m, N m/m; surge, sway, heave, roll, pitch,
//!   yaw about the body origin, in the seakeeping frame: x along the heading ψ, z up; it follows
//!   the heading but not the wave-frequency roll and pitch, as linear seakeeping theory assumes,
//!   so the first-order forces do not rectify into a spurious mean force);
//! - `drift_coefficients` (optional): `[direction][frequency][3]`, the mean drift force in
//!   surge and sway and moment in yaw per square metre of amplitude (N/m², N m/m²).
//!
//! - `phase_at` (optional): where the components' phases are taken: `"reference"` (the default:
//!   at a fixed point, the origin of the translational block, i.e. the controller's set point,
//!   or the spatial origin without a controller: linear seakeeping about a mean position, as in
//!   the seakeeping frame of Fossen's handbook, §6.6) or `"vessel"` (at the body origin's
//!   instantaneous position, so that a moving vessel meets the waves at its encounter
//!   frequency; this also adds a spurious rectified mean force from the first-order phase
//!   modulation, which the drift coefficients already account for).
//!
//! The elevation at the phase point's horizontal position `(x, y)` is
//! `η = Σ a_k cos θ_k`, `θ_k = ω_k t − κ_k (x cos β_k + y sin β_k) + φ_k`, `κ_k = ω_k²/g`
//! (deep water). The first-order force is `τ₁ = Σ a_k Re(F(ω_k, β_k − ψ) e^{iθ_k})` (time
//! convention `e^{+iωt}`; the Capytaine loader conjugates Capytaine's `e^{−iωt}`). The
//! slowly-varying drift (J. N. Newman, "Second-order, slowly-varying forces on vessels in
//! irregular waves", 1974) is `τ₂ᵢ = 2 sᵢ (Σ_k a_k √|Dᵢ(ω_k, β_k − ψ)| cos θ_k)²`, with `sᵢ` the
//! sign of the mean `Σ a_k² Dᵢ`; its mean is `Σ a_k² Dᵢ` when the coefficients keep one sign.
//!
//! The forces depend on time and on the position (the phase), so they are a forcing of flow
//! S2 (Gauss collocation at the stage times, docs/model.md §3.7). Ledger: `waves`
//! (first order) and `wave_drift` (second order), both supplied: the waves are a source.

use super::{Force, Forcing, Frozen, Output, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::lie::so3;
use crate::model::grid::{check_increasing, check_periodic, periodic_weights};
use crate::model::phasors::Phasors;
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::VesselState;
use crate::solve::Account;
use nalgebra::{Vector3, Vector6};
use std::cell::RefCell;
use std::sync::Arc;

mod table;
use table::{components_pre, cube};
pub use table::{AtFrequency, Table};

/// One regular component of the sea state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    pub omega: f64,
    pub amplitude: f64,
    pub phase: f64,
    /// Direction of travel, rad (spatial).
    pub direction: f64,
    /// Deep-water wavenumber `ω²/g`, rad/m.
    pub wavenumber: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Waves {
    pub components: Vec<Component>,
    /// Each component's transfer functions (and drift coefficients) at its own frequency.
    pre_rao: Vec<AtFrequency<6>>,
    pre_drift: Vec<AtFrequency<3>>,
    /// Phases at the vessel's instantaneous position (else at the fixed reference point).
    pub at_vessel: bool,
    pub force_rao: Table<6>,
    pub drift: Option<Table<3>>,
    /// The components' time factors `e^{i(ω_k t + φ_k)}`, fast (`crate::model::phasors`).
    time: Phasors,
    /// `(cos β_k, sin β_k)`.
    heading_cs: Vec<(f64, f64)>,
    /// The runs `lo..hi` of consecutive components that travel the same way (one run for a
    /// long-crested sea): they share the interpolation weights in direction.
    groups: Vec<(usize, usize)>,
    /// At direction node `i`, `a_k Re F_i(ω_k)` and `a_k Im F_i(ω_k)` (6 rows each) by pairs
    /// of consecutive components of a run (the last of a run of odd length alone, beside
    /// zeros): the pair `p` of node `i` at `[i P + p]` (`P` pairs in all), the six real parts of
    /// the first at `0..6` and its imaginary parts at `6..12`, the second's at `12..24`.
    by_pair: Vec<[f64; 24]>,
    /// Each run's first pair.
    pair_start: Vec<usize>,
    /// At direction node `i`, `D_i(ω_k)` (its three entries, and a zero) of component `k`:
    /// `[i K + k]`.
    drift_by_node: Vec<[f64; 4]>,
}

fn list(p: &mut Params, key: &str, unit: &str, range: Range) -> crate::Result<Vec<f64>> {
    Ok(p.rows("waves", key, 1, unit, range)?
        .ok_or_else(|| Error::Parse(format!("missing field `{key}` in [waves] ({unit})")))?
        .into_iter()
        .map(|r| r[0])
        .collect())
}

pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "waves";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let g = p.f64("vessel", "gravity", "m/s^2", Range::Positive)?;
    let om = list(p, "frequencies", "rad/s", Range::Positive)?;
    let am = list(p, "amplitudes", "m", Range::NonNegative)?;
    let ph = list(p, "phases", "rad", Range::Finite)?;
    let di = list(p, "directions", "degrees", Range::Finite)?;
    if om.is_empty() || am.len() != om.len() || ph.len() != om.len() || di.len() != om.len() {
        return Err(Error::InvalidInput(format!(
            "waves.frequencies, amplitudes, phases and directions must have one entry per component, and at least one: got {}, {}, {}, {}",
            om.len(),
            am.len(),
            ph.len(),
            di.len()
        )));
    }
    let rf = list(p, "rao_frequencies", "rad/s", Range::Positive)?;
    let rd = list(p, "rao_directions", "degrees", Range::Finite)?;
    if rf.is_empty() || rd.is_empty() {
        return Err(Error::InvalidInput(
            "waves.rao_frequencies and waves.rao_directions need at least one value each".into(),
        ));
    }
    check_increasing("waves.rao_frequencies", &rf, "rad/s")?;
    check_periodic("waves.rao_directions", &rd)?;
    let (lo, hi) = (rf[0], rf[rf.len() - 1]);
    if let Some(k) = om
        .iter()
        .position(|w| *w < lo * (1.0 - 1e-12) || *w > hi * (1.0 + 1e-12))
    {
        return Err(Error::InvalidInput(format!(
            "waves.frequencies[{k}] = {} rad/s lies outside the transfer functions' range waves.rao_frequencies = [{lo}, {hi}] rad/s; extend the data or narrow the spectrum's frequency range",
            om[k]
        )));
    }
    let at_vessel = p.choice(T, "phase_at", &["reference", "vessel"])? == "vessel";
    let (nd, nf) = (rd.len(), rf.len());
    let re = cube(p, "force_rao_real", nd, nf, 6, "N/m, N m/m", true)?.expect("required");
    let im = cube(p, "force_rao_imag", nd, nf, 6, "N/m, N m/m", true)?.expect("required");
    let drift = cube(p, "drift_coefficients", nd, nf, 3, "N/m^2, N m/m^2", false)?;
    let dirs: Vec<f64> = rd.iter().map(|d| d.to_radians()).collect();
    let to6 = |c: &Vec<Vec<Vec<f64>>>| -> Vec<Vec<[f64; 6]>> {
        c.iter()
            .map(|r| r.iter().map(|x| std::array::from_fn(|n| x[n])).collect())
            .collect()
    };
    let force_rao = Table::<6> {
        frequencies: rf.clone(),
        directions: dirs.clone(),
        re: to6(&re),
        im: to6(&im),
    };
    let drift = drift.map(|d| {
        let re: Vec<Vec<[f64; 3]>> = d
            .iter()
            .map(|r| r.iter().map(|x| [x[0], x[1], x[2]]).collect())
            .collect();
        Table::<3> {
            frequencies: rf.clone(),
            directions: dirs.clone(),
            im: re.iter().map(|r| vec![[0.0; 3]; r.len()]).collect(),
            re,
        }
    });
    let components: Vec<Component> = (0..om.len())
        .map(|k| Component {
            omega: om[k],
            amplitude: am[k],
            phase: ph[k],
            direction: di[k].to_radians(),
            wavenumber: om[k] * om[k] / g,
        })
        .collect();
    let pre_rao = components_pre(&components, &force_rao);
    let pre_drift = drift
        .as_ref()
        .map(|d| components_pre(&components, d))
        .unwrap_or_default();
    Ok(Some(Arc::new(Waves::new(
        components, pre_rao, pre_drift, at_vessel, force_rao, drift,
    ))))
}

const ACCOUNTS: [Account; 2] = [Account::supplied("waves"), Account::supplied("wave_drift")];

thread_local! {
    /// The spatial factors `e^{−iκ_k (x cos β_k + y sin β_k)}` at the point of the last sea
    /// evaluated on this thread: `(sea, x, y)` (the sea by its time factors' identity, the point
    /// by its bits), the factors, and buffers for the phase factors.
    #[allow(clippy::type_complexity)]
    static AT_POINT: RefCell<(u64, u64, u64, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)> =
        const { RefCell::new((0, 0, 0, Vec::new(), Vec::new(), Vec::new(), Vec::new())) };
}

impl Waves {
    fn new(
        components: Vec<Component>,
        pre_rao: Vec<AtFrequency<6>>,
        pre_drift: Vec<AtFrequency<3>>,
        at_vessel: bool,
        force_rao: Table<6>,
        drift: Option<Table<3>>,
    ) -> Self {
        let time = Phasors::new(
            components.iter().map(|c| c.omega).collect(),
            components.iter().map(|c| c.phase).collect(),
        );
        let heading_cs = components
            .iter()
            .map(|c| (c.direction.cos(), c.direction.sin()))
            .collect();
        let k = components.len();
        let mut groups = Vec::new();
        let mut lo = 0;
        for i in 1..=k {
            if i == k || components[i].direction.to_bits() != components[lo].direction.to_bits() {
                groups.push((lo, i));
                lo = i;
            }
        }
        let nd = force_rao.directions.len();
        let mut pair_start = Vec::with_capacity(groups.len());
        let mut pairs = 0;
        for &(lo, hi) in &groups {
            pair_start.push(pairs);
            pairs += (hi - lo).div_ceil(2);
        }
        let mut by_pair = vec![[0.0; 24]; nd * pairs];
        for (&(lo, hi), &start) in groups.iter().zip(&pair_start) {
            for c in lo..hi {
                let (p, lane) = (start + (c - lo) / 2, (c - lo) % 2);
                for i in 0..nd {
                    let blk = &mut by_pair[i * pairs + p];
                    for n in 0..6 {
                        blk[12 * lane + n] = components[c].amplitude * pre_rao[c].re[i][n];
                        blk[12 * lane + 6 + n] = components[c].amplitude * pre_rao[c].im[i][n];
                    }
                }
            }
        }
        let mut drift_by_node = vec![[0.0; 4]; if drift.is_some() { nd * k } else { 0 }];
        if drift.is_some() {
            for c in 0..k {
                for i in 0..nd {
                    let d = pre_drift[c].re[i];
                    drift_by_node[i * k + c] = [d[0], d[1], d[2], 0.0];
                }
            }
        }
        Waves {
            groups,
            by_pair,
            pair_start,
            drift_by_node,
            components,
            pre_rao,
            pre_drift,
            at_vessel,
            force_rao,
            drift,
            time,
            heading_cs,
        }
    }

    /// The elevation (m) at the horizontal position `(x, y)` and time `t`.
    pub fn elevation(&self, x: f64, y: f64, t: f64) -> f64 {
        self.components
            .iter()
            .map(|c| c.amplitude * self.theta(c, x, y, t).cos())
            .sum()
    }

    /// [`Waves::elevation`] with the components' phase factors as products of the time factors
    /// of the lattice of [`Phasors`] and the spatial ones, as [`Waves::loads_fast`] takes them:
    /// equal to the direct sum to round-off (docs/explanation/fast-sea.md).
    pub fn elevation_fast(&self, x: f64, y: f64, t: f64) -> f64 {
        self.at_point(x, y, |sre, sim, _, _| {
            self.time.with_at(t, |tre, tim| {
                self.components
                    .iter()
                    .enumerate()
                    .map(|(i, c)| c.amplitude * (tre[i] * sre[i] - tim[i] * sim[i]))
                    .sum()
            })
        })
    }

    fn theta(&self, c: &Component, x: f64, y: f64, t: f64) -> f64 {
        c.omega * t - c.wavenumber * (x * c.direction.cos() + y * c.direction.sin()) + c.phase
    }

    /// The first-order force and moment and the drift `(X, Y, N)` on the body (body frame) at
    /// horizontal position `(x, y)`, heading `psi` and time `t`.
    pub fn loads(&self, x: f64, y: f64, psi: f64, t: f64) -> (Vector6<f64>, Vector3<f64>) {
        let mut first = Vector6::zeros();
        let mut s = Vector3::<f64>::zeros();
        let mut mean = Vector3::<f64>::zeros();
        for (k, c) in self.components.iter().enumerate() {
            let th = self.theta(c, x, y, t);
            let (sn, cs) = th.sin_cos();
            let beta = c.direction - psi;
            let (re, im) = self.force_rao.in_direction(&self.pre_rao[k], beta);
            for n in 0..6 {
                first[n] += c.amplitude * (re[n] * cs - im[n] * sn);
            }
            if let Some(d) = &self.drift {
                let (dv, _) = d.in_direction(&self.pre_drift[k], beta);
                for n in 0..3 {
                    s[n] += c.amplitude * dv[n].abs().sqrt() * cs;
                    mean[n] += c.amplitude * c.amplitude * dv[n];
                }
            }
        }
        let drift = Vector3::from_fn(|n, _| 2.0 * mean[n].signum() * s[n] * s[n]);
        (first, drift)
    }

    /// The spatial factors `e^{−iκ_k (x cos β_k + y sin β_k)}` into `re`, `im`.
    fn spatial(&self, x: f64, y: f64, re: &mut Vec<f64>, im: &mut Vec<f64>) {
        re.clear();
        im.clear();
        for (c, (cb, sb)) in self.components.iter().zip(&self.heading_cs) {
            let (s, co) = (-c.wavenumber * (x * cb + y * sb)).sin_cos();
            re.push(co);
            im.push(s);
        }
    }

    /// [`Waves::loads`] with the time factors of the components by the lattice of
    /// [`Phasors`] and the spatial ones once per point: equal to the direct sum to round-off
    /// (docs/explanation/fast-sea.md).
    pub fn loads_fast(&self, x: f64, y: f64, psi: f64, t: f64) -> (Vector6<f64>, Vector3<f64>) {
        self.at_point(x, y, |sre, sim, cs, sn| {
            self.time.with_at(t, |tre, tim| {
                self.sum(psi, [tre, tim], [sre, sim], [cs, sn])
            })
        })
    }

    /// `f` with the spatial factors at `(x, y)` and the thread's buffers for the phase factors.
    /// The thread keeps the factors of the last point and sea it was asked for: the stages of
    /// one sub-step take the sea at the same point (the sub-step's start, or the fixed
    /// reference point), and a saved state's loads and elevation are at the same point.
    fn at_point<R>(
        &self,
        x: f64,
        y: f64,
        f: impl FnOnce(&[f64], &[f64], &mut Vec<f64>, &mut Vec<f64>) -> R,
    ) -> R {
        AT_POINT.with(|cell| {
            let mut at = cell.borrow_mut();
            let (sea, px, py, sre, sim, cs, sn) = &mut *at;
            let key = self.time.identity().get();
            if *sea != key || *px != x.to_bits() || *py != y.to_bits() {
                self.spatial(x, y, sre, sim);
                (*sea, *px, *py) = (key, x.to_bits(), y.to_bits());
            }
            f(sre, sim, cs, sn)
        })
    }

    /// The loads from the components' phase factors `e^{iθ_k}` as products of time and space
    /// factors, at heading `psi`: the sum of [`Waves::loads`] by runs of components that share
    /// a direction, the linear interpolation in direction taken out of each run's sums
    /// (`Σ_k a_k Re(((1 − w) F_0k + w F_1k) e^{iθ_k}) = (1 − w) Σ_k a_k Re(F_0k e^{iθ_k}) +
    /// w Σ_k a_k Re(F_1k e^{iθ_k})`), each sum over contiguous rows.
    /// `[tre, tim]`: the time factors; `[sre, sim]`: the space factors; `[cs, sn]`: buffers for
    /// their products.
    fn sum(
        &self,
        psi: f64,
        [tre, tim]: [&[f64]; 2],
        [sre, sim]: [&[f64]; 2],
        [cs, sn]: [&mut Vec<f64>; 2],
    ) -> (Vector6<f64>, Vector3<f64>) {
        let k = self.components.len();
        cs.clear();
        sn.clear();
        cs.extend((0..k).map(|i| tre[i] * sre[i] - tim[i] * sim[i]));
        sn.extend((0..k).map(|i| tre[i] * sim[i] + tim[i] * sre[i]));
        let (cs, sn) = (&cs[..], &sn[..]);
        let mut first = [0.0; 6];
        let mut s = [0.0; 3];
        let mut mean = [0.0; 3];
        let pairs = self.by_pair.len() / self.force_rao.directions.len().max(1);
        for (&(lo, hi), &start) in self.groups.iter().zip(&self.pair_start) {
            let (i0, i1, wd) = periodic_weights(
                &self.force_rao.directions,
                self.components[lo].direction - psi,
            );
            let (c, sg) = (&cs[lo..hi], &sn[lo..hi]);
            // The six rows of each node in one pass over the run's pairs of components.
            let acc = [i0, i1].map(|i| {
                let at = i * pairs + start;
                first_order(&self.by_pair[at..at + (hi - lo).div_ceil(2)], c, sg)
            });
            for n in 0..6 {
                first[n] += (1.0 - wd) * acc[0][n] + wd * acc[1][n];
            }
            if self.drift.is_some() {
                let a = &self.components[lo..hi];
                let d0 = &self.drift_by_node[i0 * k + lo..i0 * k + hi];
                let d1 = &self.drift_by_node[i1 * k + lo..i1 * k + hi];
                // Each entry's sums over the run in order, the three entries side by side.
                let (mut sm, mut mm) = ([0.0; 4], [0.0; 4]);
                for (((a, c), d0), d1) in a.iter().zip(c).zip(d0).zip(d1) {
                    let a = a.amplitude;
                    for n in 0..4 {
                        let dv = (1.0 - wd) * d0[n] + wd * d1[n];
                        sm[n] += a * dv.abs().sqrt() * c;
                        mm[n] += a * a * dv;
                    }
                }
                for n in 0..3 {
                    s[n] += sm[n];
                    mean[n] += mm[n];
                }
            }
        }
        let drift = Vector3::from_fn(|n, _| 2.0 * mean[n].signum() * s[n] * s[n]);
        (Vector6::from_column_slice(&first), drift)
    }
}

impl Force for Waves {
    fn name(&self) -> &'static str {
        "waves"
    }
    /// `waves`, and `wave_drift` when there are drift coefficients.
    fn accounts(&self) -> &'static [Account] {
        if self.drift.is_some() {
            &ACCOUNTS
        } else {
            &ACCOUNTS[..1]
        }
    }
    /// All of the waves' loads are forcing (time and position dependent).
    fn add_s2(&self, _fr: &Frozen, _b: &mut S2Builder) {}
    fn forced(&self) -> bool {
        true
    }
    /// Its part in flow S2 is empty.
    fn assembly_reads_motion(&self) -> bool {
        false
    }
    /// With the phases at the reference point, the loads depend on time and heading only.
    fn forcing_uses_state(&self) -> bool {
        self.at_vessel
    }
    fn add_forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], g: &mut Forcing) {
        let x = if self.at_vessel {
            fr.origin + z[0][1]
        } else {
            fr.origin
        };
        let psi = fr.euler.z;
        let (first, drift) = self.loads_fast(x.x, x.y, psi, t);
        // The loads are given in the seakeeping frame (x along the heading, z up: it follows the
        // mean heading, not the oscillations); on the body: Qᵀ R_z(ψ).
        let to_body = fr.qt * so3::from_euler_zyx(&Vector3::new(0.0, 0.0, psi));
        g.force(
            Sys::Trans,
            Some(0),
            to_body * Vector3::new(first[0], first[1], first[2]),
        );
        g.force(
            Sys::Rot,
            Some(0),
            to_body * Vector3::new(first[3], first[4], first[5]),
        );
        if self.drift.is_some() {
            g.force(
                Sys::Trans,
                Some(1),
                to_body * Vector3::new(drift.x, drift.y, 0.0),
            );
            g.force(Sys::Rot, Some(1), to_body * Vector3::new(0.0, 0.0, drift.z));
        }
    }
    fn outputs(&self, fr: &Frozen, _z: &[Z3; 2], s: &VesselState, t: f64, out: &mut Vec<Output>) {
        let x = if self.at_vessel { s.x } else { fr.origin };
        out.push(Output::new(
            "wave_elevation",
            "m",
            "wave elevation at the point where the wave phases are taken",
            self.elevation_fast(x.x, x.y, t),
        ));
    }
}

/// `Σ_k (a_nk c_k − b_nk s_k)` for the six rows `n` of a run's pairs of components `blocks`
/// ([`Waves`]' `by_pair`, with `a` the real and `b` the imaginary parts), in two interleaved
/// partial sums per row (even and odd `k`, the last of an odd run in the even sum): the pairs'
/// fixed layout lets the compiler use two-lane arithmetic.
#[inline]
fn first_order(blocks: &[[f64; 24]], c: &[f64], s: &[f64]) -> [f64; 6] {
    let n = c.len().min(s.len()).min(2 * blocks.len());
    let mut acc = [[0.0; 6]; 2];
    for (blk, (c, s)) in blocks
        .iter()
        .zip(c[..n].chunks_exact(2).zip(s[..n].chunks_exact(2)))
    {
        for l in 0..2 {
            for r in 0..6 {
                acc[l][r] += blk[12 * l + r] * c[l] - blk[12 * l + 6 + r] * s[l];
            }
        }
    }
    if n % 2 == 1 {
        let (blk, q) = (&blocks[n / 2], n - 1);
        for r in 0..6 {
            acc[0][r] += blk[r] * c[q] - blk[6 + r] * s[q];
        }
    }
    std::array::from_fn(|r| acc[0][r] + acc[1][r])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::phasors::tests::uniform;
    use std::f64::consts::PI;

    /// A sea of `n` components (`spread`: each its own direction; else all towards 211°) on
    /// tables of 16 directions and 12 frequencies with values of both signs.
    fn sea(n: usize, spread: bool, st: &mut u64) -> Waves {
        let freqs: Vec<f64> = (0..12).map(|j| 0.2 + 0.2 * j as f64).collect();
        let dirs: Vec<f64> = (0..16).map(|i| (i as f64 * 22.5f64).to_radians()).collect();
        let mut cube6 = |scale: f64| -> Vec<Vec<[f64; 6]>> {
            (0..16)
                .map(|_| {
                    (0..12)
                        .map(|_| std::array::from_fn(|_| scale * (2.0 * uniform(st) - 1.0)))
                        .collect()
                })
                .collect()
        };
        let (re, im) = (cube6(1e6), cube6(1e6));
        let d: Vec<Vec<[f64; 3]>> = cube6(1e4)
            .into_iter()
            .map(|r| r.into_iter().map(|x| [x[0], x[1], x[2]]).collect())
            .collect();
        let force_rao = Table::<6> {
            frequencies: freqs.clone(),
            directions: dirs.clone(),
            re,
            im,
        };
        let drift = Table::<3> {
            frequencies: freqs,
            directions: dirs,
            im: vec![vec![[0.0; 3]; 12]; 16],
            re: d,
        };
        let components: Vec<Component> = (0..n)
            .map(|_| {
                let omega = 0.35 + 1.65 * uniform(st);
                Component {
                    omega,
                    amplitude: 0.5 * uniform(st),
                    phase: 6.283 * uniform(st),
                    direction: if spread {
                        6.283 * uniform(st)
                    } else {
                        211f64.to_radians()
                    },
                    wavenumber: omega * omega / 9.81,
                }
            })
            .collect();
        let pre_rao = components_pre(&components, &force_rao);
        let pre_drift = components_pre(&components, &drift);
        Waves::new(
            components,
            pre_rao,
            pre_drift,
            false,
            force_rao,
            Some(drift),
        )
    }

    /// The loads by the formulas of the module documentation, written out: the phase of each
    /// component, the bilinear interpolation of the tables, the sums; and the scales the sums
    /// are measured against, `Σ_k a_k |F_k|` per row and `2 (Σ_k a_k √|D_k|)²`.
    fn written_out(w: &Waves, x: f64, y: f64, psi: f64, t: f64) -> ([f64; 9], [f64; 9]) {
        let (mut out, mut scale) = ([0.0; 9], [0.0; 9]);
        let (mut s, mut ss, mut mean) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        for c in &w.components {
            let th = c.omega * t - c.wavenumber * (x * c.direction.cos() + y * c.direction.sin())
                + c.phase;
            let (re, im) = w.force_rao.at(c.omega, c.direction - psi);
            for n in 0..6 {
                out[n] += c.amplitude * (re[n] * th.cos() - im[n] * th.sin());
                scale[n] += c.amplitude * re[n].hypot(im[n]);
            }
            let (d, _) = w.drift.as_ref().unwrap().at(c.omega, c.direction - psi);
            for n in 0..3 {
                s[n] += c.amplitude * d[n].abs().sqrt() * th.cos();
                ss[n] += c.amplitude * d[n].abs().sqrt();
                mean[n] += c.amplitude * c.amplitude * d[n];
            }
        }
        for n in 0..3 {
            out[6 + n] = 2.0 * mean[n].signum() * s[n] * s[n];
            scale[6 + n] = 2.0 * ss[n] * ss[n];
        }
        (out, scale)
    }

    #[test]
    fn the_fast_sums_are_the_direct_sums_to_round_off_over_an_hour() {
        let mut st = 2026;
        let gauss = 0.5 - 3f64.sqrt() / 6.0;
        for spread in [false, true] {
            let w = sea(150, spread, &mut st);
            let (x0, y0) = (780.0, 20.0);
            let mut worst: f64 = 0.0;
            for i in 0..1500 {
                // Stage times of an hour of h = 0.5 s steps (a Gauss node inside a step), the
                // last ones at t ≈ 3600 s, at headings round the circle and near 211° − 180°.
                let n = if i < 1000 { i } else { 7200 - (i - 1000) };
                let t = 0.5 * n as f64 + 0.5 * if i % 2 == 0 { gauss } else { 0.5 };
                let psi = if i % 3 == 0 {
                    6.283 * uniform(&mut st) - 3.1
                } else {
                    31f64.to_radians() + 0.05 * (uniform(&mut st) - 0.5)
                };
                let (want, scale) = written_out(&w, x0, y0, psi, t);
                // The elevation (the output), against the sum written out, on the scale of
                // the amplitudes' sum.
                let amplitudes: f64 = w.components.iter().map(|c| c.amplitude).sum();
                let eta: f64 = w
                    .components
                    .iter()
                    .map(|c| {
                        c.amplitude
                            * (c.omega * t
                                - c.wavenumber * (x0 * c.direction.cos() + y0 * c.direction.sin())
                                + c.phase)
                                .cos()
                    })
                    .sum();
                // Each twice: the spatial factors computed (after another point), then kept.
                for fresh in [true, false] {
                    if fresh {
                        w.elevation_fast(x0 + 1.0, y0, t);
                    }
                    let e = (w.elevation_fast(x0, y0, t) - eta).abs() / amplitudes;
                    worst = worst.max(e);
                    assert!(e <= 1e-12, "elevation at t = {t}: {e:e} of the scale");
                    if fresh {
                        w.loads_fast(x0, y0 - 1.0, psi, t);
                    }
                    let (first, drift) = w.loads_fast(x0, y0, psi, t);
                    for n in 0..9 {
                        let got = if n < 6 { first[n] } else { drift[n - 6] };
                        let e = (got - want[n]).abs() / scale[n];
                        worst = worst.max(e);
                        assert!(
                            e <= 1e-12,
                            "t = {t}, ψ = {psi}, row {n}: {got} vs {want:?}, {e:e} of the scale"
                        );
                    }
                }
            }
            eprintln!("spread {spread}: worst {worst:e} of the scale");
            // It is round-off, not zero: the two sums are computed differently.
            assert!(worst > 0.0);
        }
    }

    #[test]
    fn the_table_interpolates_bilinearly_and_round_the_circle() {
        let t = Table::<1> {
            frequencies: vec![1.0, 2.0],
            directions: vec![0.0, PI / 2.0, PI],
            re: vec![
                vec![[0.0], [1.0]],
                vec![[10.0], [11.0]],
                vec![[20.0], [21.0]],
            ],
            im: vec![vec![[0.0], [0.0]]; 3],
        };
        assert_eq!(t.at(1.5, 0.0).0[0], 0.5);
        assert_eq!(t.at(1.0, PI / 4.0).0[0], 5.0);
        // between π and 2π (= 0): periodic
        assert!((t.at(1.0, 1.5 * PI).0[0] - 10.0).abs() < 1e-12);
        assert!((t.at(1.0, -PI / 2.0).0[0] - 10.0).abs() < 1e-12);
        assert!((t.at(2.0, 2.0 * PI + PI / 2.0).0[0] - 11.0).abs() < 1e-12);
        // the frequency interpolation done once gives the same values
        for (w, b) in [(1.3, 0.4), (1.9, 4.0), (1.0, -2.0)] {
            let pre = t.at_frequency(w);
            let (a, c) = (t.in_direction(&pre, b).0[0], t.at(w, b).0[0]);
            assert!((a - c).abs() <= 1e-14 * c.abs().max(1.0), "{a} vs {c}");
        }
    }
}
