//! Wind as a port: mean wind and gusts acting through load coefficient tables
//! (docs/model.md §5.10).
//!
//! Table `[wind]` (optional):
//! - `speed` (m/s, ≥ 0): the mean wind speed at the reference height of the coefficients;
//!   `direction` (degrees, spatial, from x towards y): the direction the wind blows towards;
//! - gusts (optional; realised from a gust spectrum by `phsplit.sea.Wind`): `gust_frequencies`
//!   (rad/s, > 0), `gust_amplitudes` (m/s, ≥ 0), `gust_phases` (rad), one entry per component,
//!   so that the wind speed is `U(t) = speed + Σ a_k cos(ω_k t + φ_k)` along `direction`
//!   (longitudinal turbulence, uniform over the hull);
//! - the hull's windage: `frontal_area` A_F and `lateral_area` A_L (m², > 0), `length` L (m,
//!   > 0), `air_density` ρ_a (kg/m³, > 0);
//! - the load coefficients on a grid of relative wind angles: `angles` (degrees, increasing,
//!   spanning less than 360; interpolated linearly and periodically) and `cx`, `cy`, `cn`, one
//!   value per angle (user-given, or from Isherwood's or Blendermann's regressions).
//!
//! With `w = Qᵀ W(t) − v` the air's velocity relative to the hull in the body frame (`W` the
//! wind velocity, `v` the vessel's), its horizontal speed `V_r = |(w_x, w_y)|` and its angle
//! `γ = atan2(w_y, w_x)` (0: the air flows from stern to bow, 180: a head wind), the loads are
//! (T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2nd ed., 2021,
//! §10.1, with its angle convention replaced by this one):
//!
//! `X = q A_F C_X(γ)`, `Y = q A_L C_Y(γ)`, `N = q A_L L C_N(γ)`, `q = ½ ρ_a V_r²`,
//!
//! a body-frame force `(X, Y, 0)` and yaw moment `N` about the body origin. They depend on time
//! and on the vessel's velocity, so they are a forcing of flow S2 (Gauss collocation at the
//! stages, docs/model.md §3.7). Ledger: the port `wind` (supplied; the velocity-dependent part
//! is the aerodynamic damping, which it books too).

use super::{Force, Forcing, Frozen, Output, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::grid::{check_periodic, periodic_weights};
use crate::model::kept::{self, Recent};
use crate::model::phasors::Phasors;
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::VesselState;
use crate::solve::Account;
use nalgebra::Vector3;
use std::sync::Arc;

#[derive(Debug, Clone, PartialEq)]
pub struct Wind {
    pub speed: f64,
    /// Radians, spatial.
    pub direction: f64,
    /// `(ω_k, a_k, φ_k)`.
    pub gusts: Vec<(f64, f64, f64)>,
    pub frontal_area: f64,
    pub lateral_area: f64,
    pub length: f64,
    pub air_density: f64,
    /// Radians, increasing, spanning less than 2π.
    pub angles: Vec<f64>,
    /// `(C_X, C_Y, C_N)` per angle.
    pub coefficients: Vec<[f64; 3]>,
    /// The gusts' time factors `e^{i(ω_k t + φ_k)}`, fast (`crate::model::phasors`).
    time: Phasors,
    /// `(cos, sin)` of `direction`, once (the loads take them at every pass of the fixed point).
    towards: (f64, f64),
}

fn list(
    p: &mut Params,
    key: &str,
    unit: &str,
    range: Range,
    required: bool,
) -> crate::Result<Vec<f64>> {
    match p.rows("wind", key, 1, unit, range)? {
        Some(r) => Ok(r.into_iter().map(|x| x[0]).collect()),
        None if required => Err(Error::Parse(format!(
            "missing field `{key}` in [wind] ({unit})"
        ))),
        None => Ok(Vec::new()),
    }
}

pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "wind";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let speed = p.f64(T, "speed", "m/s", Range::NonNegative)?;
    if speed > 80.0 {
        return Err(Error::InvalidInput(format!(
            "wind.speed must be at most 80 m/s (beyond any recorded 10-minute mean at sea), got {speed}"
        )));
    }
    let direction = p
        .f64(T, "direction", "degrees", Range::Finite)?
        .to_radians();
    let frontal_area = p.f64(T, "frontal_area", "m^2", Range::Positive)?;
    let lateral_area = p.f64(T, "lateral_area", "m^2", Range::Positive)?;
    let length = p.f64(T, "length", "m", Range::Positive)?;
    let air_density = p.f64(T, "air_density", "kg/m^3", Range::Positive)?;
    let gf = list(p, "gust_frequencies", "rad/s", Range::Positive, false)?;
    let ga = list(p, "gust_amplitudes", "m/s", Range::NonNegative, false)?;
    let gp = list(p, "gust_phases", "rad", Range::Finite, false)?;
    if ga.len() != gf.len() || gp.len() != gf.len() {
        return Err(Error::InvalidInput(format!(
            "wind.gust_frequencies, gust_amplitudes and gust_phases must have one entry per component: got {}, {}, {}",
            gf.len(),
            ga.len(),
            gp.len()
        )));
    }
    let angles = list(p, "angles", "degrees", Range::Finite, true)?;
    let cx = list(p, "cx", "dimensionless", Range::Finite, true)?;
    let cy = list(p, "cy", "dimensionless", Range::Finite, true)?;
    let cn = list(p, "cn", "dimensionless", Range::Finite, true)?;
    if angles.is_empty()
        || cx.len() != angles.len()
        || cy.len() != angles.len()
        || cn.len() != angles.len()
    {
        return Err(Error::InvalidInput(format!(
            "wind.angles, cx, cy and cn must have one value per angle, and at least one: got {}, {}, {}, {}",
            angles.len(),
            cx.len(),
            cy.len(),
            cn.len()
        )));
    }
    check_periodic("wind.angles", &angles)?;
    Ok(Some(Arc::new(Wind {
        speed,
        direction,
        towards: (direction.cos(), direction.sin()),
        time: Phasors::new(gf.clone(), gp.clone()),
        gusts: (0..gf.len()).map(|k| (gf[k], ga[k], gp[k])).collect(),
        frontal_area,
        lateral_area,
        length,
        air_density,
        angles: angles.iter().map(|a| a.to_radians()).collect(),
        coefficients: (0..cx.len()).map(|k| [cx[k], cy[k], cn[k]]).collect(),
    })))
}

thread_local! {
    /// The last gust speeds this thread computed, the newest first: `(wind, t, U(t))`, the wind
    /// by its time factors' identity and `t` by its bits. The collocation asks for the same
    /// stage times at every pass of its fixed point, in turn: one entry per stage of the
    /// three-stage Gauss rule at most, and one for the ledger's.
    static LAST_SPEED: Recent<f64, SPEEDS> = const { Recent::new([(0, 0, 0.0); SPEEDS]) };
}

const ACCOUNTS: [Account; 1] = [Account::supplied("wind")];
/// Gust speeds a thread keeps ([`Wind::speed_fast`]).
const SPEEDS: usize = 4;

impl Wind {
    /// The wind speed at time `t` (m/s).
    pub fn speed_at(&self, t: f64) -> f64 {
        self.speed
            + self
                .gusts
                .iter()
                .map(|(w, a, ph)| a * (w * t + ph).cos())
                .sum::<f64>()
    }

    /// [`Wind::speed_at`] with the gusts' time factors by the lattice of [`Phasors`]: equal to
    /// the direct sum to round-off (docs/explanation/fast-sea.md).
    pub fn speed_fast(&self, t: f64) -> f64 {
        if self.gusts.is_empty() {
            return self.speed;
        }
        kept::at_time(&LAST_SPEED, self.time.identity(), t, || {
            self.speed
                + self.time.with_at(t, |re, _| {
                    self.gusts
                        .iter()
                        .zip(re)
                        .map(|((_, a, _), c)| a * c)
                        .sum::<f64>()
                })
        })
    }

    /// The coefficients at the relative angle `gamma` (rad), periodic linear interpolation.
    pub fn coefficients_at(&self, gamma: f64) -> [f64; 3] {
        let (i0, i1, w) = periodic_weights(&self.angles, gamma);
        let (c0, c1) = (self.coefficients[i0], self.coefficients[i1]);
        std::array::from_fn(|k| c0[k] * (1.0 - w) + c1[k] * w)
    }

    /// The body-frame force and moment at attitude `Qᵀ = qt`, body velocity `v` and time `t`.
    pub fn loads(
        &self,
        qt: &nalgebra::Matrix3<f64>,
        v: &Vector3<f64>,
        t: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
        self.loads_at_speed(qt, v, self.speed_at(t))
    }

    /// [`Wind::loads`] at the wind speed `u` (m/s).
    pub fn loads_at_speed(
        &self,
        qt: &nalgebra::Matrix3<f64>,
        v: &Vector3<f64>,
        u: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
        let (c, s) = self.towards;
        let wind = Vector3::new(u * c, u * s, 0.0);
        let rel = qt * wind - v;
        let vr2 = rel.x * rel.x + rel.y * rel.y;
        if vr2 == 0.0 {
            return (Vector3::zeros(), Vector3::zeros());
        }
        let c = self.coefficients_at(rel.y.atan2(rel.x));
        let q = 0.5 * self.air_density * vr2;
        (
            Vector3::new(
                q * self.frontal_area * c[0],
                q * self.lateral_area * c[1],
                0.0,
            ),
            Vector3::new(0.0, 0.0, q * self.lateral_area * self.length * c[2]),
        )
    }
}

impl Force for Wind {
    fn name(&self) -> &'static str {
        "wind"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    /// All of the wind's loads are forcing (time and velocity dependent).
    fn add_s2(&self, _fr: &Frozen, _b: &mut S2Builder) {}
    fn forced(&self) -> bool {
        true
    }
    /// Its part in flow S2 is empty.
    fn assembly_reads_motion(&self) -> bool {
        false
    }
    fn add_forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], g: &mut Forcing) {
        let (f, m) = self.loads_at_speed(&fr.qt, &fr.nu(z)[0], self.speed_fast(t));
        g.force(Sys::Trans, Some(0), f);
        g.force(Sys::Rot, Some(0), m);
    }
    fn outputs(&self, _fr: &Frozen, _z: &[Z3; 2], _s: &VesselState, t: f64, out: &mut Vec<Output>) {
        out.push(Output::new(
            "wind_speed",
            "m s-1",
            "wind speed (mean and gusts)",
            self.speed_fast(t),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fast_gust_sum_is_the_direct_sum_to_round_off_over_an_hour() {
        let mut st: u64 = 7;
        let mut u = || {
            st = st
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (st >> 11) as f64 / (1u64 << 53) as f64
        };
        let gusts: Vec<(f64, f64, f64)> = (0..100)
            .map(|_| (0.001 * 500f64.powf(u()), 0.8 * u(), 6.283 * u()))
            .collect();
        let w = Wind {
            speed: 15.0,
            direction: 0.3,
            towards: (0.3f64.cos(), 0.3f64.sin()),
            time: Phasors::new(
                gusts.iter().map(|g| g.0).collect(),
                gusts.iter().map(|g| g.2).collect(),
            ),
            gusts: gusts.clone(),
            frontal_area: 182.0,
            lateral_area: 533.0,
            length: 76.2,
            air_density: 1.225,
            angles: vec![0.0, std::f64::consts::PI],
            coefficients: vec![[0.6, 0.0, 0.0], [-0.7, 0.0, 0.0]],
        };
        let scale = 15.0 + gusts.iter().map(|g| g.1).sum::<f64>();
        let gauss = 0.5 - 3f64.sqrt() / 6.0;
        for n in (0..7200).chain(7150..7200) {
            for c in [gauss, 0.5, 1.0 - gauss] {
                let t = 0.5 * (n as f64 + c);
                // U(t) = speed + Σ a_k cos(ω_k t + φ_k), written out.
                let want = 15.0
                    + gusts
                        .iter()
                        .map(|(om, a, ph)| a * (om * t + ph).cos())
                        .sum::<f64>();
                let got = w.speed_fast(t);
                assert!(
                    (got - want).abs() <= 1e-12 * scale,
                    "t = {t}: {got} vs {want}"
                );
                // again at the same time (the collocation's passes): the same bits
                assert_eq!(w.speed_fast(t).to_bits(), got.to_bits());
            }
        }
        // Stage times asked in turn, as the collocation's passes ask for them, and more of them
        // than are kept: the speeds are those computed on a thread that asked for nothing else.
        let times = [
            10.3, 10.7, 11.1, 10.3, 10.7, 55.0, 60.2, 70.9, 81.4, 10.3, 10.7,
        ];
        let in_turn: Vec<u64> = times.iter().map(|&t| w.speed_fast(t).to_bits()).collect();
        let alone: Vec<u64> = times
            .iter()
            .map(|&t| {
                let w = w.clone();
                std::thread::spawn(move || w.speed_fast(t).to_bits())
                    .join()
                    .unwrap()
            })
            .collect();
        assert_eq!(in_turn, alone);
    }

    #[test]
    fn a_head_wind_on_a_table_gives_the_stated_loads() {
        let w = Wind {
            speed: 20.0,
            direction: std::f64::consts::PI, // blowing towards −x
            towards: (-1.0, std::f64::consts::PI.sin()),
            gusts: vec![],
            time: Phasors::new(vec![], vec![]),
            frontal_area: 300.0,
            lateral_area: 900.0,
            length: 80.0,
            air_density: 1.2,
            angles: vec![
                0.0,
                std::f64::consts::FRAC_PI_2,
                std::f64::consts::PI,
                1.5 * std::f64::consts::PI,
            ],
            coefficients: vec![
                [0.6, 0.0, 0.0],
                [0.0, 0.9, 0.05],
                [-0.7, 0.0, 0.0],
                [0.0, -0.9, -0.05],
            ],
        };
        // vessel at rest, heading x: the air flows from bow to stern, γ = 180°.
        let (f, m) = w.loads(&nalgebra::Matrix3::identity(), &Vector3::zeros(), 0.0);
        let q = 0.5 * 1.2 * 400.0;
        assert!((f.x - q * 300.0 * -0.7).abs() < 1e-9 && f.y.abs() < 1e-9 && m.z.abs() < 1e-9);
        // moving at 5 m/s into it: V_r = 25 m/s
        let (f, _) = w.loads(
            &nalgebra::Matrix3::identity(),
            &Vector3::new(5.0, 0.0, 0.0),
            0.0,
        );
        assert!((f.x - 0.5 * 1.2 * 625.0 * 300.0 * -0.7).abs() < 1e-9);
        // between the table's angles, periodic: γ = 225° is halfway between 180° and 270°
        let c = w.coefficients_at(1.25 * std::f64::consts::PI);
        assert!((c[0] + 0.35).abs() < 1e-12 && (c[1] + 0.45).abs() < 1e-12);
        let c = w.coefficients_at(-0.25 * std::f64::consts::PI);
        assert!((c[0] - 0.3).abs() < 1e-12 && (c[1] + 0.45).abs() < 1e-12);
    }
}
