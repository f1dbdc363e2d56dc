//! Thrusters and thrust allocation: the actuators of the DP controller (docs/model.md §5.8).
//!
//! Table `[thrusters]` (optional; read with the controller, whose force they deliver):
//! - `hull_length`, `hull_beam` (m, in (0, 500] and (0, 150], `physical::HULL_LENGTH`, `HULL_BEAM`): the hull's box, `|x| ≤ L/2`, `|y| ≤ B/2`, `|z| ≤ B/2`
//!   about the body origin, inside which every thruster must sit;
//! - `unit`: a list of thrusters (`[[thrusters.unit]]` tables), each with
//!   - `kind`: `"tunnel"` (a fixed transverse axis, thrust of either sign), `"azimuth"` (turns
//!     freely, thrust ≥ 0) or `"fixed"` (a fixed axis, a main propeller);
//!   - `position` (m, body frame, from the body origin);
//!   - `max_thrust` (N, > 0); for `tunnel` and `fixed`, `min_thrust` (N, < 0; default
//!     `−max_thrust` for a tunnel) and `angle` (degrees, the axis in the body's x–y plane from
//!     x towards y; default 90 for a tunnel, 0 for a fixed propeller);
//!   - `weight` (> 0, default 1): the cost of its thrust in the allocation;
//!   - `thrust_rate` (N/s, > 0, optional): the fastest change of its thrust; for an azimuth,
//!     `turn_rate` (degrees/s, > 0, optional): its fastest turn;
//!   - `lost_at` (s, optional): a failure: from that time the thruster delivers nothing, at
//!     once, and the allocation distributes the demand over the thrusters left (from the first
//!     stage of flow S2 at or after that time; reported as `thruster<i>_available`). The
//!     thrusters left must still produce surge, sway and yaw independently.
//!   - `stuck_at` (s, optional; not with `lost_at`): a thruster that fails as set (its pitch,
//!     speed or azimuth control frozen: the failure such a control is designed to, since IMO
//!     MSC/Circ.645 §3.3.4 requires that it not send the thruster to uncontrolled full
//!     thrust): from that time the thruster keeps the thrust and angle it delivered at the end
//!     of the last step before, and the allocation distributes the rest of the demand,
//!     `τ − τ_stuck`, over the thrusters left. The vessel
//!     then carries what the thrusters deliver in its state ([`Actuators`], as for rate
//!     limits); a thruster stuck at or before the run's start keeps what the start's memory
//!     gives it, which is no thrust.
//!
//! **Allocation** (T. A. Johansen and T. I. Fossen, "Control allocation — a survey",
//! *Automatica* 49 (2013) 1087–1103, §2.2; Fossen, *Handbook of Marine Craft Hydrodynamics and
//! Motion Control*, 2nd ed., 2021, §11.2): the controller's demand in surge, sway and yaw,
//! `τ = (X, Y, N)` (body frame, moment about the body origin), is distributed by the weighted
//! least-norm solution `f = W⁻¹Bᵀ(BW⁻¹Bᵀ)⁻¹ τ` of `B f = τ`, in the extended thrust
//! formulation: a tunnel or fixed thruster is one force along its axis, an azimuth two (its
//! x and y components), so `B` does not depend on the azimuth angles and the map is linear.
//! Inside the thrusters' capacity the delivered `B f` equals the demand. Outside it, the whole
//! solution is scaled by the largest `c ∈ (0, 1]` that keeps every thruster within its
//! limits: the delivered force keeps the demand's direction in `(X, Y, N)` and loses only its
//! size.
//!
//! The delivered wrench is what acts on the vessel: each thruster's force `(f_x, f_y, 0)` at
//! its position, so a thruster below the body origin also heels and trims the vessel. The
//! controller's demand in heave, roll and pitch is not delivered (horizontal thrusters).
//!
//! **Rate limits** (docs/model.md §5.8): with any, what the thrusters delivered at the end of
//! the last step is a memory the state carries ([`Actuators`]); at a time `t` within the step
//! each thruster moves from it towards its command by at most its rate times `|t − t_m|`
//! ([`Thrusters::delivered`]), so the limits hold exactly at every step.
//!
//! Not modelled: thruster–hull and thruster–thruster interaction, forbidden sectors, thrust
//! lost while an azimuth turns.

use crate::error::{Error, Result};
use crate::model::vessel::params::{physical, Params, Range};
use crate::model::vessel::state::MAX_ACTUATORS;
use nalgebra::{Matrix3, Vector2, Vector3};

mod rates;
use toml::{Table, Value};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Tunnel,
    Azimuth,
    Fixed,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Tunnel => "tunnel",
            Kind::Azimuth => "azimuth",
            Kind::Fixed => "fixed",
        }
    }
}

#[derive(Debug, Clone, PartialEq)]
pub struct Thruster {
    pub kind: Kind,
    pub position: Vector3<f64>,
    /// The axis (tunnel, fixed), rad in the body's x–y plane.
    pub angle: f64,
    pub min_thrust: f64,
    pub max_thrust: f64,
    pub weight: f64,
    /// The fastest change of the thrust (N/s), if limited.
    pub thrust_rate: Option<f64>,
    /// The fastest turn of an azimuth (rad/s), if limited.
    pub turn_rate: Option<f64>,
}

impl Thruster {
    /// `|thrust|` over the limit on its side (`max_thrust`, or `−min_thrust` in reverse).
    fn utilisation(&self, thrust: f64) -> f64 {
        thrust.abs()
            / if thrust >= 0.0 {
                self.max_thrust
            } else {
                -self.min_thrust
            }
    }
}

/// The thrusters with their allocation, precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct Thrusters {
    pub units: Vec<Thruster>,
    /// Per allocation variable: its unit, its direction in the body's x–y plane, and its row
    /// of the weighted pseudo-inverse (`f_j = p_j · τ`).
    vars: Vec<(usize, Vector2<f64>, Vector3<f64>)>,
    /// Each unit's variables, `vars[start..end]` (contiguous).
    ranges: Vec<(usize, usize)>,
    /// Whether each unit is stuck (its `stuck_at` passed): it has no variables and delivers
    /// what the memory holds ([`Self::delivered`]).
    stuck: Vec<bool>,
    /// From each time a thruster fails (its `lost_at` or `stuck_at`), the allocation without it
    /// and those failed before: each unit keeps its index; a lost one has no variables and
    /// delivers nothing, a stuck one keeps its memory.
    after: Vec<(f64, Thrusters)>,
}

/// One allocation: what each thruster gives and what the vessel receives.
#[derive(Debug, Clone, PartialEq)]
pub struct Allocation {
    /// The demand `(X, Y, N)` (N, N, N m).
    pub commanded: Vector3<f64>,
    /// What the thrusters deliver in surge, sway and yaw: `c · commanded`.
    pub delivered: Vector3<f64>,
    /// The scaling `c ∈ (0, 1]` (1 inside the capacity).
    pub scale: f64,
    /// Each thruster's thrust (N; signed for tunnel and fixed thrusters, ≥ 0 for azimuths) and
    /// angle (rad, the direction of its force in the body's x–y plane).
    pub thrust: Vec<f64>,
    pub angle: Vec<f64>,
    /// The largest `|thrust| / limit` over the thrusters.
    pub utilisation: f64,
    /// The delivered force and moment about the body origin (body frame, 6 DOF).
    pub force: Vector3<f64>,
    pub moment: Vector3<f64>,
}

/// Read `[thrusters]`, if present.
pub fn read(p: &mut Params) -> Result<Option<Thrusters>> {
    const T: &str = "thrusters";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let length = p.f64(
        T,
        "hull_length",
        "m",
        Range::Physical(&physical::HULL_LENGTH),
    )?;
    let beam = p.f64(T, "hull_beam", "m", Range::Physical(&physical::HULL_BEAM))?;
    let raw = p.take_raw(T, "unit")?.ok_or_else(|| {
        Error::Parse("missing field `unit` in [thrusters]: a list of [[thrusters.unit]] tables (kind, position, max_thrust, ...)".into())
    })?;
    let Value::Array(list) = raw else {
        return Err(Error::Parse(format!(
            "thrusters.unit must be a list of tables ([[thrusters.unit]]), got {} {raw}",
            raw.type_str()
        )));
    };
    if list.is_empty() {
        return Err(Error::InvalidInput(
            "thrusters.unit is empty: give at least the thrusters that can produce surge, sway and yaw".into(),
        ));
    }
    let mut units = Vec::with_capacity(list.len());
    let mut lost_at = Vec::with_capacity(list.len());
    let mut stuck_at = Vec::with_capacity(list.len());
    let mut recorded = Vec::with_capacity(list.len());
    for (i, item) in list.iter().enumerate() {
        let name = format!("thrusters.unit[{i}]");
        let Value::Table(t) = item else {
            return Err(Error::Parse(format!(
                "{name} must be a table (kind, position, max_thrust, ...), got {} {item}",
                item.type_str()
            )));
        };
        let mut wrapped = Table::new();
        wrapped.insert(name.clone(), Value::Table(t.clone()));
        let mut sub = Params::from_table(wrapped);
        let unit = read_unit(&mut sub, &name, length, beam)?;
        let when = |sub: &mut Params, key: &str| {
            sub.opt_f64(
                &name,
                key,
                "s",
                Range::Physical(&crate::model::vessel::params::physical::TIME),
            )
        };
        let (lost, stuck) = (when(&mut sub, "lost_at")?, when(&mut sub, "stuck_at")?);
        if lost.is_some() && stuck.is_some() {
            return Err(Error::InvalidInput(format!(
                "{name}: give lost_at (the thruster delivers nothing) or stuck_at (it keeps its last thrust and angle), not both: a thruster fails one way"
            )));
        }
        lost_at.push(lost);
        stuck_at.push(stuck);
        // A key this kind does not read is refused, with the keys it does read.
        let out = sub.finish()?;
        if let Some(v) = out.get(&name) {
            recorded.push(v.clone());
        }
        units.push(unit);
    }
    p.record_value(T, "unit", Value::Array(recorded));
    let limited = units
        .iter()
        .any(|u| u.thrust_rate.is_some() || u.turn_rate.is_some())
        || stuck_at.iter().any(Option::is_some);
    if limited && units.len() > MAX_ACTUATORS {
        return Err(Error::InvalidInput(format!(
            "thrusters.unit has {} thrusters; with rate limits (thrust_rate, turn_rate) or a stuck_at at most {MAX_ACTUATORS} are kept (their memory is part of the state): remove them or merge thrusters",
            units.len()
        )));
    }
    Thrusters::new(units)?
        .with_failures(&lost_at, &stuck_at)
        .map(Some)
}

fn read_unit(p: &mut Params, s: &str, length: f64, beam: f64) -> Result<Thruster> {
    let kind = match p.required_choice(s, "kind", &["tunnel", "azimuth", "fixed"])? {
        "tunnel" => Kind::Tunnel,
        "azimuth" => Kind::Azimuth,
        _ => Kind::Fixed,
    };
    let position: Vector3<f64> = p
        .vec3(s, "position", None, "m, body frame", Range::Finite)?
        .into();
    let half = [length / 2.0, beam / 2.0, beam / 2.0];
    let what = ["hull_length/2", "hull_beam/2", "hull_beam/2"];
    for i in 0..3 {
        if position[i].abs() > half[i] {
            return Err(Error::InvalidInput(format!(
                "{s}.position[{i}] = {} m lies outside the hull's box (|{}| ≤ {} = {} m, from thrusters.hull_length and thrusters.hull_beam)",
                position[i],
                ["x", "y", "z"][i],
                what[i],
                half[i]
            )));
        }
    }
    let max_thrust = p.f64(s, "max_thrust", "N", Range::Positive)?;
    let thrust_rate = p.opt_f64(s, "thrust_rate", "N/s", Range::Positive)?;
    let turn_rate = match kind {
        Kind::Azimuth => p
            .opt_f64(s, "turn_rate", "degrees/s", Range::Positive)?
            .map(f64::to_radians),
        _ => None,
    };
    let weight = p
        .opt_f64(s, "weight", "dimensionless", Range::Positive)?
        .unwrap_or(1.0);
    let (angle, min_thrust) = match kind {
        Kind::Azimuth => (0.0, 0.0),
        Kind::Tunnel | Kind::Fixed => {
            let deg = p
                .opt_f64(s, "angle", "degrees", Range::Physical(&physical::ANGLE_DEG))?
                .unwrap_or(if kind == Kind::Tunnel { 90.0 } else { 0.0 });
            let min = p.opt_f64(s, "min_thrust", "N", Range::Finite)?;
            let min = match (kind, min) {
                (Kind::Tunnel, None) => -max_thrust,
                (_, Some(m)) if m < 0.0 => m,
                (_, got) => {
                    return Err(Error::InvalidInput(format!(
                        "{s}.min_thrust must be < 0 (N, the reverse thrust of a {} thruster; the allocation scales the demand and needs both signs), got {}",
                        kind.name(),
                        got.map_or("nothing".to_string(), |m| m.to_string())
                    )))
                }
            };
            (deg.to_radians(), min)
        }
    };
    Ok(Thruster {
        kind,
        position,
        angle,
        min_thrust,
        max_thrust,
        weight,
        thrust_rate,
        turn_rate,
    })
}

impl Thrusters {
    /// Precompute the weighted pseudo-inverse; the thrusters must be able to produce surge,
    /// sway and yaw independently (`B` of rank 3).
    pub fn new(units: Vec<Thruster>) -> Result<Self> {
        let intact = vec![false; units.len()];
        Self::without(units, &intact, &intact)
    }

    /// The allocation of `units` without those marked `lost` (which keep their index and
    /// deliver nothing, at once: no rate limit holds them) or `stuck` (which keep their memory).
    fn without(mut units: Vec<Thruster>, lost: &[bool], stuck: &[bool]) -> Result<Self> {
        let mut cols: Vec<(usize, Vector2<f64>, Vector3<f64>, f64)> = Vec::new();
        for (i, u) in units.iter_mut().enumerate() {
            if lost[i] {
                (u.thrust_rate, u.turn_rate) = (None, None);
                continue;
            }
            if stuck[i] {
                continue;
            }
            let dirs: Vec<Vector2<f64>> = match u.kind {
                Kind::Azimuth => vec![Vector2::new(1.0, 0.0), Vector2::new(0.0, 1.0)],
                _ => vec![Vector2::new(u.angle.cos(), u.angle.sin())],
            };
            for d in dirs {
                let (lx, ly) = (u.position.x, u.position.y);
                cols.push((i, d, Vector3::new(d.x, d.y, lx * d.y - ly * d.x), u.weight));
            }
        }
        // B W⁻¹ Bᵀ, 3×3 symmetric.
        let mut bwb = Matrix3::zeros();
        for (_, _, b, w) in &cols {
            bwb += b * b.transpose() / *w;
        }
        let eig = bwb.symmetric_eigenvalues();
        let (lo, hi) = (eig.min(), eig.max());
        if !(lo > 1e-12 * hi) {
            return Err(Error::InvalidInput(format!(
                "the thrusters cannot produce surge, sway and yaw independently (the allocation matrix has rank < 3: smallest singular value ratio {:.1e}); add a thruster or move one off the line of the others, and keep the thrusters' weights within a few decades of each other",
                (lo.max(0.0) / hi).sqrt()
            )));
        }
        let inv = bwb.try_inverse().expect("checked positive definite");
        let vars: Vec<_> = cols
            .into_iter()
            .map(|(i, d, b, w)| (i, d, inv * b / w))
            .collect();
        let ranges = (0..units.len())
            .map(|u| {
                let start = vars.iter().position(|v| v.0 == u).unwrap_or(vars.len());
                let len = vars.iter().filter(|v| v.0 == u).count();
                (start, start + len)
            })
            .collect();
        Ok(Self {
            units,
            vars,
            ranges,
            stuck: stuck.to_vec(),
            after: Vec::new(),
        })
    }

    /// With the losses of `lost_at` (one per unit, s; `None`: never lost).
    pub fn with_losses(self, lost_at: &[Option<f64>]) -> Result<Self> {
        self.with_failures(lost_at, &vec![None; lost_at.len()])
    }

    /// With the failures of `lost_at` and `stuck_at` (one each per unit, s; `None`: no such
    /// failure): from each such time the allocation redistributes the demand (less what the
    /// stuck thrusters deliver) over the thrusters left.
    pub fn with_failures(
        mut self,
        lost_at: &[Option<f64>],
        stuck_at: &[Option<f64>],
    ) -> Result<Self> {
        let mut times: Vec<f64> = lost_at.iter().chain(stuck_at).flatten().copied().collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        let by = |at: &[Option<f64>], tk: f64| -> Vec<bool> {
            at.iter().map(|l| l.is_some_and(|t| t <= tk)).collect()
        };
        for tk in times {
            let (lost, stuck) = (by(lost_at, tk), by(stuck_at, tk));
            let left = Self::without(self.units.clone(), &lost, &stuck).map_err(|e| {
                let gone: Vec<String> = (0..lost.len())
                    .filter(|i| lost[*i] || stuck[*i])
                    .map(|i| if lost[i] { i.to_string() } else { format!("{i} (stuck)") })
                    .collect();
                Error::InvalidInput(format!(
                    "thrusters.unit[*].lost_at/stuck_at: with thruster(s) {} failed from t = {tk} s, {e}",
                    gone.join(", ")
                ))
            })?;
            self.after.push((tk, left));
        }
        Ok(self)
    }

    /// Whether a thruster ever sticks: the vessel then keeps what the thrusters deliver in its
    /// state.
    pub fn may_stick(&self) -> bool {
        self.after.iter().any(|(_, th)| th.stuck.iter().any(|s| *s))
    }

    /// The first time after `t` at which a thruster is lost or sticks.
    pub fn next_loss(&self, t: f64) -> Option<f64> {
        self.after.iter().map(|(tk, _)| *tk).find(|&tk| tk > t)
    }

    /// The allocation at time `t` (s): without the thrusters lost by then.
    pub fn at(&self, t: f64) -> &Thrusters {
        self.after
            .iter()
            .rev()
            .find(|(tk, _)| t >= *tk)
            .map_or(self, |(_, th)| th)
    }

    /// Whether thruster `i` still answers the allocation at time `t` (not lost, not stuck).
    pub fn available(&self, i: usize, t: f64) -> bool {
        let th = self.at(t);
        th.ranges[i].0 < th.ranges[i].1
    }

    /// Thruster `i`'s unscaled force `(f_x, f_y)` for the demand `tau`, and its thrust along
    /// its axis (tunnel, fixed; 0 for an azimuth).
    fn unit_force(&self, i: usize, tau: &Vector3<f64>) -> (f64, f64, f64) {
        let (mut fx, mut fy, mut along) = (0.0, 0.0, 0.0);
        for (_, d, p) in &self.vars[self.ranges[i].0..self.ranges[i].1] {
            let f = p.dot(tau);
            fx += f * d.x;
            fy += f * d.y;
            along = f;
        }
        if self.units[i].kind == Kind::Azimuth {
            along = 0.0;
        }
        (fx, fy, along)
    }

    /// The largest scaling `c ∈ (0, 1]` of the least-norm solution that keeps every thruster
    /// within its limits.
    fn scale(&self, tau: &Vector3<f64>) -> f64 {
        let mut c: f64 = 1.0;
        for (i, u) in self.units.iter().enumerate() {
            let (fx, fy, along) = self.unit_force(i, tau);
            match u.kind {
                Kind::Azimuth => {
                    let m = fx.hypot(fy);
                    if m > u.max_thrust {
                        c = c.min(u.max_thrust / m);
                    }
                }
                _ => {
                    if along > u.max_thrust {
                        c = c.min(u.max_thrust / along);
                    } else if along < u.min_thrust {
                        c = c.min(u.min_thrust / along);
                    }
                }
            }
        }
        c
    }

    /// The delivered force and moment (body frame, about the body origin) for the demand
    /// `(X, Y, N)`: [`Self::allocate`]'s wrench without its per-thruster record (no allocation:
    /// flow S2 evaluates it at every stage).
    pub fn wrench(&self, tau: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let c = self.scale(tau);
        let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
        for (i, u) in self.units.iter().enumerate() {
            let (fx, fy, _) = self.unit_force(i, tau);
            let f = Vector3::new(fx * c, fy * c, 0.0);
            force += f;
            moment += u.position.cross(&f);
        }
        (force, moment)
    }

    /// Allocate the demand `(X, Y, N)`, with each thruster's thrust and angle.
    pub fn allocate(&self, tau: &Vector3<f64>) -> Allocation {
        let n = self.units.len();
        let c = self.scale(tau);
        let mut thrust = Vec::with_capacity(n);
        let mut angle = Vec::with_capacity(n);
        let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
        let mut util: f64 = 0.0;
        for (i, u) in self.units.iter().enumerate() {
            let (fx, fy, along) = self.unit_force(i, tau);
            let f = Vector3::new(fx * c, fy * c, 0.0);
            force += f;
            moment += u.position.cross(&f);
            let (t, a) = match u.kind {
                Kind::Azimuth => (f.x.hypot(f.y), f.y.atan2(f.x)),
                _ => (along * c, u.angle),
            };
            util = util.max(u.utilisation(t));
            thrust.push(t);
            angle.push(a);
        }
        Allocation {
            commanded: *tau,
            delivered: Vector3::new(force.x, force.y, moment.z),
            scale: c,
            thrust,
            angle,
            utilisation: util,
            force,
            moment,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The offshore supply vessel of Fossen's MSS (`osv.m`, 2024): two bow tunnel thrusters
    /// (300 kN at x = 37 and 35 m) and two stern azimuths (420 and 655 kN at x = −41.5 m,
    /// y = ±7 m), positions about midships.
    pub(super) fn osv() -> Thrusters {
        let t = |x: f64, max: f64| Thruster {
            kind: Kind::Tunnel,
            position: Vector3::new(x, 0.0, 0.0),
            angle: std::f64::consts::FRAC_PI_2,
            min_thrust: -max,
            max_thrust: max,
            weight: 1.0,
            thrust_rate: None,
            turn_rate: None,
        };
        let a = |y: f64, max: f64| Thruster {
            kind: Kind::Azimuth,
            position: Vector3::new(-41.5, y, 0.0),
            angle: 0.0,
            min_thrust: 0.0,
            max_thrust: max,
            weight: 1.0,
            thrust_rate: None,
            turn_rate: None,
        };
        Thrusters::new(vec![
            t(37.0, 300e3),
            t(35.0, 300e3),
            a(7.0, 420e3),
            a(-7.0, 655e3),
        ])
        .unwrap()
    }

    #[test]
    fn a_demand_inside_the_capacity_is_delivered() {
        let th = osv();
        for tau in [
            Vector3::new(2e5, 0.0, 0.0),
            Vector3::new(-1e5, 2e5, 3e6),
            Vector3::new(0.0, -1e5, -5e6),
        ] {
            let a = th.allocate(&tau);
            assert_eq!(th.wrench(&tau), (a.force, a.moment));
            assert_eq!(a.scale, 1.0);
            assert!((a.delivered - tau).norm() <= 1e-12 * tau.norm(), "{a:?}");
        }
    }

    #[test]
    fn a_demand_outside_keeps_its_direction_and_the_limits() {
        let th = osv();
        let tau = Vector3::new(3e6, 1e6, 4e7);
        let a = th.allocate(&tau);
        assert_eq!(th.wrench(&tau), (a.force, a.moment));
        assert!(a.scale < 1.0);
        let cos = a.delivered.dot(&tau) / (a.delivered.norm() * tau.norm());
        assert!(cos > (1e-9f64).cos() - 1e-15, "{cos}");
        for (u, t) in th.units.iter().zip(&a.thrust) {
            assert!(*t <= u.max_thrust * (1.0 + 1e-12) && *t >= u.min_thrust * (1.0 + 1e-12));
        }
        assert!((a.utilisation - 1.0).abs() < 1e-12);
    }

    #[test]
    fn thrusters_on_one_line_cannot_allocate_yaw() {
        let u = |x: f64| Thruster {
            kind: Kind::Fixed,
            position: Vector3::new(x, 0.0, 0.0),
            angle: 0.0,
            min_thrust: -1e5,
            max_thrust: 1e5,
            weight: 1.0,
            thrust_rate: None,
            turn_rate: None,
        };
        let e = Thrusters::new(vec![u(10.0), u(-10.0)])
            .unwrap_err()
            .to_string();
        assert!(e.contains("rank < 3"), "{e}");
    }
}
