//! Thrusters and thrust allocation: the actuators of the DP controller (docs/model.md §5.8).
//!
//! Table `[thrusters]` (optional; read with the controller, whose force they deliver):
//! - `hull_length`, `hull_beam` (m, > 0): the hull's box, `|x| ≤ L/2`, `|y| ≤ B/2`, `|z| ≤ B/2`
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
//!     `turn_rate` (degrees/s, > 0, optional): its fastest turn.
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

use super::pid::wrap_pi;
use crate::error::{Error, Result};
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::{Actuators, MAX_ACTUATORS};
use nalgebra::{Matrix3, Vector2, Vector3};
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

/// The thrusters with their allocation, precomputed.
#[derive(Debug, Clone, PartialEq)]
pub struct Thrusters {
    pub units: Vec<Thruster>,
    /// Per allocation variable: its unit, its direction in the body's x–y plane, and its row
    /// of the weighted pseudo-inverse (`f_j = p_j · τ`).
    vars: Vec<(usize, Vector2<f64>, Vector3<f64>)>,
    /// Each unit's variables, `vars[start..end]` (contiguous).
    ranges: Vec<(usize, usize)>,
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
    let length = p.f64(T, "hull_length", "m", Range::Positive)?;
    let beam = p.f64(T, "hull_beam", "m", Range::Positive)?;
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
        .any(|u| u.thrust_rate.is_some() || u.turn_rate.is_some());
    if limited && units.len() > MAX_ACTUATORS {
        return Err(Error::InvalidInput(format!(
            "thrusters.unit has {} thrusters; with rate limits (thrust_rate, turn_rate) at most {MAX_ACTUATORS} are kept (their memory is part of the state): remove the rate limits or merge thrusters",
            units.len()
        )));
    }
    Thrusters::new(units).map(Some)
}

fn read_unit(p: &mut Params, s: &str, length: f64, beam: f64) -> Result<Thruster> {
    let kind = match p.choice(s, "kind", &["tunnel", "azimuth", "fixed"])? {
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
                .opt_f64(s, "angle", "degrees", Range::Finite)?
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
        let mut cols: Vec<(usize, Vector2<f64>, Vector3<f64>, f64)> = Vec::new();
        for (i, u) in units.iter().enumerate() {
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
        })
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

    /// Whether a thruster's thrust or turn is rate-limited: the vessel then keeps what the
    /// thrusters deliver in its state ([`Actuators`]).
    pub fn rate_limited(&self) -> bool {
        self.units
            .iter()
            .any(|u| u.thrust_rate.is_some() || u.turn_rate.is_some())
    }

    /// Each thruster's commanded thrust and angle for the demand `tau` (the allocation, scaled
    /// into the limits), at time `t`: the memory of thrusters that have just delivered their
    /// command. An azimuth commanded no thrust keeps the angle `keep[i]`.
    fn commanded(&self, tau: &Vector3<f64>, keep: &[f64]) -> Actuators {
        let c = self.scale(tau);
        let mut a = Actuators {
            n: self.units.len(),
            ..Actuators::default()
        };
        for (i, u) in self.units.iter().enumerate() {
            let (fx, fy, along) = self.unit_force(i, tau);
            (a.thrust[i], a.angle[i]) = match u.kind {
                Kind::Azimuth => {
                    let t = c * fx.hypot(fy);
                    let angle = if t > 1e-12 * u.max_thrust {
                        (c * fy).atan2(c * fx)
                    } else {
                        keep[i]
                    };
                    (t, angle)
                }
                _ => (c * along, u.angle),
            };
        }
        a
    }

    /// What rate-limited thrusters deliver for the demand `tau`, `dt` seconds (of either sign:
    /// a sub-step of a composition may run backwards) after they delivered `mem`
    /// (docs/model.md §5.8). The delivered force is the point nearest the command of what the
    /// thruster can reach:
    /// - a tunnel or fixed thruster: thrusts within `thrust_rate · |dt|` of the memory's;
    /// - an azimuth: forces `f` with `|f − f_m| ≤ thrust_rate · |dt|` (the force vector changes
    ///   at most at that rate) whose direction lies within `turn_rate · |dt|` of the pod's
    ///   angle `α_m` (at most 90°, so that the set is convex; no limit once the pod could turn
    ///   half a circle), a convex set that holds `f_m`.
    ///
    /// The nearest point of a convex set moves continuously with the command, so flow S2's
    /// fixed point sees a continuous forcing, even where a command reverses. A command within
    /// reach is delivered exactly. An azimuth's new angle is its force's direction; one that
    /// delivers no force turns towards its command by at most `turn_rate · |dt|`.
    pub fn delivered(&self, tau: &Vector3<f64>, mem: &Actuators, dt: f64) -> Actuators {
        let n = self.units.len();
        let mut out = self.commanded(tau, &mem.angle[..n]);
        let dt = dt.abs();
        let c = self.scale(tau);
        for (i, u) in self.units.iter().enumerate() {
            match u.kind {
                Kind::Azimuth => {
                    let (fx, fy, _) = self.unit_force(i, tau);
                    let cmd = Vector2::new(c * fx, c * fy);
                    let (s, co) = mem.angle[i].sin_cos();
                    let m = Vector2::new(co, s) * mem.thrust[i];
                    let disc = u.thrust_rate.map(|r| r * dt);
                    // A pod that can turn half a circle reaches every direction; one that can
                    // turn less is kept within a quarter circle at most (a convex cone).
                    let cone = u
                        .turn_rate
                        .filter(|r| r * dt < std::f64::consts::PI)
                        .map(|r| (mem.angle[i], (r * dt).min(std::f64::consts::FRAC_PI_2)));
                    let f = nearest_reachable(&cmd, &m, disc, cone);
                    out.thrust[i] = f.norm();
                    out.angle[i] = if out.thrust[i] > 1e-12 * u.max_thrust {
                        f.y.atan2(f.x)
                    } else {
                        // No force: the pod turns towards its command, within its rate.
                        let turn = wrap_pi(out.angle[i] - mem.angle[i]);
                        let most = u.turn_rate.map_or(f64::INFINITY, |r| r * dt);
                        let a = mem.angle[i] + turn.clamp(-most, most);
                        if a.abs() < std::f64::consts::PI {
                            a
                        } else {
                            wrap_pi(a)
                        }
                    };
                }
                _ => {
                    if let Some(r) = u.thrust_rate {
                        let step = out.thrust[i] - mem.thrust[i];
                        if step.abs() > r * dt {
                            out.thrust[i] = mem.thrust[i] + (r * dt).copysign(step);
                        }
                    }
                }
            }
        }
        out.t = mem.t + dt;
        out
    }

    /// Check a memory given with a state to start a run from at `t0` (as `Solution.state(i)`
    /// writes it): its time is `t0`, each thrust within its thruster's limits, a tunnel or fixed
    /// thruster's angle its axis, an azimuth's angle in [−π, π].
    pub fn check_memory(&self, act: &Actuators, t0: f64) -> Result<()> {
        let tol = 1e-9 * t0.abs().max(1.0);
        if (act.t - t0).abs() > tol {
            return Err(Error::InvalidInput(format!(
                "the thrusters' memory after the state is at t = {} s, but the run starts at t0 = {t0} s: a memory belongs to the state of its own time (Solution.state(i) at t[i])",
                act.t
            )));
        }
        for (i, u) in self.units.iter().enumerate() {
            let (t, a) = (act.thrust[i], act.angle[i]);
            let lo = if u.kind == Kind::Azimuth {
                0.0
            } else {
                u.min_thrust
            };
            if !(t >= lo * (1.0 + 1e-9) - 1e-9 && t <= u.max_thrust * (1.0 + 1e-9)) {
                return Err(Error::InvalidInput(format!(
                    "the thrusters' memory gives thruster {i} ({}) a thrust of {t} N; allowed: {lo} to {} N (thrusters.unit[{i}])",
                    u.kind.name(),
                    u.max_thrust
                )));
            }
            let ok = match u.kind {
                Kind::Azimuth => a.abs() <= std::f64::consts::PI * (1.0 + 1e-12),
                _ => (a - u.angle).abs() <= 1e-12 * (1.0 + u.angle.abs()),
            };
            if !ok {
                return Err(Error::InvalidInput(format!(
                    "the thrusters' memory gives thruster {i} ({}) an angle of {a} rad; allowed: {} (thrusters.unit[{i}])",
                    u.kind.name(),
                    if u.kind == Kind::Azimuth {
                        "−π to π".to_string()
                    } else {
                        format!("its axis, {} rad", u.angle)
                    }
                )));
            }
        }
        Ok(())
    }

    /// The memory of thrusters that deliver their command for the demand `tau` at time `t`
    /// (how a run starts them; an idle azimuth points along the body's x axis).
    pub fn memory_at(&self, tau: &Vector3<f64>, t: f64) -> Actuators {
        let mut a = self.commanded(tau, &[0.0; MAX_ACTUATORS][..self.units.len()]);
        a.t = t;
        a
    }

    /// The force and moment (body frame, about the body origin) of thrusts and angles `a`.
    pub fn wrench_of(&self, a: &Actuators) -> (Vector3<f64>, Vector3<f64>) {
        let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
        for (i, u) in self.units.iter().enumerate() {
            let (s, c) = a.angle[i].sin_cos();
            let f = Vector3::new(a.thrust[i] * c, a.thrust[i] * s, 0.0);
            force += f;
            moment += u.position.cross(&f);
        }
        (force, moment)
    }

    /// [`Self::allocate`] for rate-limited thrusters: the demand `tau`, and what they deliver
    /// `dt` after `mem` ([`Self::delivered`]).
    pub fn allocate_limited(&self, tau: &Vector3<f64>, mem: &Actuators, dt: f64) -> Allocation {
        let d = self.delivered(tau, mem, dt);
        let (force, moment) = self.wrench_of(&d);
        let n = self.units.len();
        let mut util: f64 = 0.0;
        for (u, t) in self.units.iter().zip(&d.thrust[..n]) {
            let lim = if *t >= 0.0 {
                u.max_thrust
            } else {
                -u.min_thrust
            };
            util = util.max(t.abs() / lim);
        }
        Allocation {
            commanded: *tau,
            delivered: Vector3::new(force.x, force.y, moment.z),
            scale: self.scale(tau),
            thrust: d.thrust[..n].to_vec(),
            angle: d.angle[..n].to_vec(),
            utilisation: util,
            force,
            moment,
        }
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
            let (t, a, lim) = match u.kind {
                Kind::Azimuth => (f.x.hypot(f.y), f.y.atan2(f.x), u.max_thrust),
                _ => {
                    let t = along * c;
                    let lim = if t >= 0.0 {
                        u.max_thrust
                    } else {
                        -u.min_thrust
                    };
                    (t, u.angle, lim)
                }
            };
            util = util.max(t.abs() / lim);
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

/// The point nearest `c` of the convex set `{f : |f − m| ≤ disc} ∩ {f : f = 0 or the direction
/// of f within `half` of `axis`}` (`disc` or `cone = (axis, half)` absent: that constraint
/// absent; `half ≤ π/2`, so the cone is convex), which holds `m` (on the cone's axis). The
/// nearest point of a convex set is 1-Lipschitz in `c`. It lies on the boundary when `c` is
/// outside: on the disc's circle, or on one of the cone's two edges within the disc.
fn nearest_reachable(
    c: &Vector2<f64>,
    m: &Vector2<f64>,
    disc: Option<f64>,
    cone: Option<(f64, f64)>,
) -> Vector2<f64> {
    let slack = 1e-12 * (c.norm() + m.norm());
    let in_disc = |p: &Vector2<f64>| disc.is_none_or(|r| (p - m).norm() <= r + slack);
    let in_cone = |p: &Vector2<f64>| {
        cone.is_none_or(|(axis, half)| {
            p.norm() <= slack || wrap_pi(p.y.atan2(p.x) - axis).abs() <= half + 1e-12
        })
    };
    if in_disc(c) && in_cone(c) {
        return *c;
    }
    let mut best = *m;
    let mut best_d = (c - m).norm();
    let mut consider = |p: Vector2<f64>| {
        let d = (c - p).norm();
        if d < best_d {
            best = p;
            best_d = d;
        }
    };
    if let Some(r) = disc {
        let d = c - m;
        let p = if d.norm() > r {
            m + d * (r / d.norm())
        } else {
            *c
        };
        if in_cone(&p) {
            consider(p);
        }
    }
    if let Some((axis, half)) = cone {
        for edge in [axis - half, axis + half] {
            let e = Vector2::new(edge.cos(), edge.sin());
            // The edge's points s e (s ≥ 0) within the disc: s in [lo, hi].
            let (lo, hi) = match disc {
                None => (0.0, f64::INFINITY),
                Some(r) => {
                    // |s e − m| = r: s = e·m ± √(r² − (e × m)²), without the cancellation of
                    // (e·m)² − |m|².
                    let em = e.dot(m);
                    let cross = e.x * m.y - e.y * m.x;
                    let q = r * r - cross * cross;
                    if q < 0.0 {
                        continue;
                    }
                    ((em - q.sqrt()).max(0.0), em + q.sqrt())
                }
            };
            if hi >= lo {
                consider(e * c.dot(&e).clamp(lo, hi));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The offshore supply vessel of Fossen's MSS (`osv.m`, 2024): two bow tunnel thrusters
    /// (300 kN at x = 37 and 35 m) and two stern azimuths (420 and 655 kN at x = −41.5 m,
    /// y = ±7 m), positions about midships.
    fn osv() -> Thrusters {
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

    /// The OSV's thrusters with thrust rates of 10 kN/s and azimuths turning at 0.1 rad/s.
    fn limited() -> Thrusters {
        let mut units = osv().units;
        for u in &mut units {
            u.thrust_rate = Some(1e4);
            if u.kind == Kind::Azimuth {
                u.turn_rate = Some(0.1);
            }
        }
        Thrusters::new(units).unwrap()
    }

    #[test]
    fn rate_limits_move_from_the_memory_towards_the_command() {
        let th = limited();
        assert!(th.rate_limited() && !osv().rate_limited());
        let tau = Vector3::new(-2e5, 1.5e5, 4e6);
        let cmd = th.memory_at(&tau, 0.0);
        // idle thrusters, the azimuths pointing along x: after 2 s each tunnel's thrust is
        // 20 kN towards its command (or the command, if nearer); each azimuth's force is within
        // 20 kN of zero and 0.2 rad of the x axis, and as near its command as that allows
        let idle = th.memory_at(&Vector3::zeros(), 0.0);
        assert!(idle.thrust[..4].iter().all(|t| *t == 0.0) && idle.angle[2] == 0.0);
        let d = th.delivered(&tau, &idle, 2.0);
        for i in 0..2 {
            let want = cmd.thrust[i].clamp(-2e4, 2e4);
            assert!((d.thrust[i] - want).abs() <= 1e-9 * 2e4, "{i}");
        }
        for i in [2, 3] {
            assert!(d.thrust[i] <= 2e4 * (1.0 + 1e-12), "{i}");
            assert!(wrap_pi(d.angle[i]).abs() <= 0.2 + 1e-12, "{i}");
            if d.thrust[i] <= 1e-9 {
                // commanded backwards, beyond the turn: no force yet, the pod turned 0.2 rad
                // towards the command
                assert!(wrap_pi(cmd.angle[i]).abs() > std::f64::consts::FRAC_PI_2 + 0.2);
                assert!((d.angle[i] - 0.2f64.copysign(wrap_pi(cmd.angle[i]))).abs() < 1e-15);
            }
        }
        // a command within reach is delivered exactly, and the wrench is the allocation's
        let near = th.delivered(&tau, &cmd, 0.5);
        for i in 0..4 {
            assert!((near.thrust[i] - cmd.thrust[i]).abs() <= 1e-15 * cmd.thrust[i].abs());
        }
        let (f, m) = th.wrench_of(&near);
        let a = th.allocate(&tau);
        assert!(
            (f - a.force).norm() <= 1e-9 * a.force.norm()
                && (m - a.moment).norm() <= 1e-9 * a.moment.norm()
        );
        // near ±π: the force stays within the turn of the pod's angle, on the command's side,
        // and either sign of the time works
        let mut back = cmd;
        back.angle[2] = 3.1;
        let d = th.delivered(&tau, &back, -1.0);
        let moved = wrap_pi(d.angle[2] - 3.1);
        assert!(moved.abs() <= 0.1 + 1e-12);
        assert!(
            wrap_pi(cmd.angle[2] - 3.1) * moved >= 0.0,
            "the command's side"
        );
        // an azimuth commanded no thrust, with time to get there, delivers none and keeps its
        // angle
        let d = th.delivered(&Vector3::zeros(), &back, 100.0);
        assert_eq!(d.angle[2], 3.1);
        assert!(d.thrust[2] <= 1e-9);
    }

    /// The nearest reachable point against its definition: it is reachable, and no reachable
    /// point is nearer (the variational inequality `(c − p)·(q − p) ≤ 0` for every reachable
    /// `q`, checked on a polar grid of the set); it moves no more than the command does.
    #[test]
    fn the_nearest_reachable_point_is_the_projection() {
        let mut cases = Vec::new();
        for (k, (thrust, axis)) in [(0.0f64, 0.0f64), (3e5, 0.3), (3e5, 3.1), (1e3, -2.0)]
            .into_iter()
            .enumerate()
        {
            let m = Vector2::new(axis.cos(), axis.sin()) * thrust;
            for disc in [None, Some(2e4), Some(5e5)] {
                for half in [
                    None,
                    Some(0.05),
                    Some(0.6),
                    Some(std::f64::consts::FRAC_PI_2),
                ] {
                    for j in 0..24 {
                        let a = j as f64 * 0.2618 + 0.1 * k as f64;
                        let r = [1e3, 2e5, 4e5][j % 3];
                        cases.push((
                            Vector2::new(a.cos(), a.sin()) * r,
                            m,
                            disc,
                            half.map(|h| (axis, h)),
                        ));
                    }
                }
            }
        }
        let inside =
            |q: &Vector2<f64>, m: &Vector2<f64>, disc: Option<f64>, cone: Option<(f64, f64)>| {
                disc.is_none_or(|r| (q - m).norm() <= r)
                    && cone.is_none_or(|(ax, h)| {
                        q.norm() == 0.0 || wrap_pi(q.y.atan2(q.x) - ax).abs() <= h
                    })
            };
        for (c, m, disc, cone) in &cases {
            let p = nearest_reachable(c, m, *disc, *cone);
            let scale = c.norm() + m.norm();
            // reachable (to round-off)
            if let Some(r) = disc {
                assert!((p - m).norm() <= r + 1e-9 * scale);
            }
            if let Some((ax, h)) = cone {
                assert!(p.norm() <= 1e-9 * scale || wrap_pi(p.y.atan2(p.x) - ax).abs() <= h + 1e-9);
            }
            // no reachable point nearer: a polar grid around the origin and around m
            for i in 0..60 {
                for j in 1..40 {
                    let ang = i as f64 * std::f64::consts::TAU / 60.0;
                    let rad = j as f64 * 2e4;
                    for centre in [Vector2::zeros(), *m] {
                        let q = centre + Vector2::new(ang.cos(), ang.sin()) * rad;
                        if inside(&q, m, *disc, *cone) {
                            assert!(
                                (c - p).dot(&(q - p)) <= 1e-9 * scale * scale,
                                "{c:?} {m:?} {disc:?} {cone:?}"
                            );
                        }
                    }
                }
            }
            // 1-Lipschitz in the command
            let c2 = c + Vector2::new(1.0, -2.0);
            let p2 = nearest_reachable(&c2, m, *disc, *cone);
            assert!((p2 - p).norm() <= (c2 - c).norm() * (1.0 + 1e-9) + 1e-9 * scale);
        }
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
