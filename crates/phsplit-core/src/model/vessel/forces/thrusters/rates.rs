//! Rate-limited thrusters (docs/model.md §5.8): what they deliver within a step from the memory
//! of what they delivered at the end of the last one ([`Actuators`]), the memory's start and
//! check, and the projection onto what an azimuth can reach.

use super::{Allocation, Kind, Thrusters};
use crate::error::{Error, Result};
use crate::model::vessel::forces::pid::wrap_pi;
use crate::model::vessel::state::Actuators;
use nalgebra::{Vector2, Vector3};
use std::f64::consts::{FRAC_PI_2, PI};

impl Thrusters {
    /// Whether a thruster's thrust or turn is rate-limited: the vessel then keeps what the
    /// thrusters deliver in its state ([`Actuators`]).
    pub fn rate_limited(&self) -> bool {
        self.units
            .iter()
            .any(|u| u.thrust_rate.is_some() || u.turn_rate.is_some())
    }

    /// Whether the vessel keeps what the thrusters deliver in its state: with rate limits, or
    /// with a thruster that sticks (`stuck_at`).
    pub fn has_memory(&self) -> bool {
        self.rate_limited() || self.may_stick()
    }

    /// What the stuck thrusters of memory `mem` deliver in surge, sway and yaw (body frame).
    fn stuck_part(&self, mem: &Actuators) -> Vector3<f64> {
        let mut tau = Vector3::zeros();
        for (i, u) in self.units.iter().enumerate() {
            if self.stuck[i] {
                let (s, c) = mem.angle[i].sin_cos();
                let (fx, fy) = (mem.thrust[i] * c, mem.thrust[i] * s);
                tau += Vector3::new(fx, fy, u.position.x * fy - u.position.y * fx);
            }
        }
        tau
    }

    /// Thruster `i`'s command for the demand `tau` whose allocation is scaled by `c`
    /// ([`Thrusters::scale`]): its thrust, its angle (an azimuth commanded no thrust keeps the
    /// angle `keep`) and its force in the body's x–y plane.
    fn unit_command(
        &self,
        i: usize,
        tau: &Vector3<f64>,
        c: f64,
        keep: f64,
    ) -> (f64, f64, Vector2<f64>) {
        let u = &self.units[i];
        let (fx, fy, along) = self.unit_force(i, tau);
        let f = Vector2::new(c * fx, c * fy);
        match u.kind {
            Kind::Azimuth => {
                let t = c * fx.hypot(fy);
                (
                    t,
                    if t > 1e-12 * u.max_thrust {
                        f.y.atan2(f.x)
                    } else {
                        keep
                    },
                    f,
                )
            }
            _ => (c * along, u.angle, f),
        }
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
    ///
    /// A stuck thruster keeps its memory; the others are commanded the rest of the demand,
    /// `tau` less what the stuck ones deliver.
    pub fn delivered(&self, tau: &Vector3<f64>, mem: &Actuators, dt: f64) -> Actuators {
        let dt = dt.abs();
        let rest = tau - self.stuck_part(mem);
        let tau = &rest;
        let c = self.scale(tau);
        let mut out = Actuators {
            n: self.units.len(),
            t: mem.t + dt,
            ..Actuators::default()
        };
        for (i, u) in self.units.iter().enumerate() {
            if self.stuck[i] {
                (out.thrust[i], out.angle[i]) = (mem.thrust[i], mem.angle[i]);
                continue;
            }
            let (thrust, angle, cmd) = self.unit_command(i, tau, c, mem.angle[i]);
            (out.thrust[i], out.angle[i]) = match u.kind {
                Kind::Azimuth => {
                    let (s, co) = mem.angle[i].sin_cos();
                    let m = Vector2::new(co, s) * mem.thrust[i];
                    let disc = u.thrust_rate.map(|r| r * dt);
                    // A pod that can turn half a circle reaches every direction; one that can
                    // turn less is kept within a quarter circle at most (a convex cone).
                    let cone = u
                        .turn_rate
                        .filter(|r| r * dt < PI)
                        .map(|r| (mem.angle[i], (r * dt).min(FRAC_PI_2)));
                    let f = nearest_reachable(&cmd, &m, disc, cone);
                    let t = f.norm();
                    if t > 1e-12 * u.max_thrust {
                        (t, f.y.atan2(f.x))
                    } else {
                        // No force: the pod turns towards its command, within its rate.
                        let turn = wrap_pi(angle - mem.angle[i]);
                        let most = u.turn_rate.map_or(f64::INFINITY, |r| r * dt);
                        let a = mem.angle[i] + turn.clamp(-most, most);
                        (t, if a.abs() < PI { a } else { wrap_pi(a) })
                    }
                }
                _ => {
                    let step = thrust - mem.thrust[i];
                    match u.thrust_rate {
                        Some(r) if step.abs() > r * dt => {
                            (mem.thrust[i] + (r * dt).copysign(step), angle)
                        }
                        _ => (thrust, angle),
                    }
                }
            };
        }
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
        let c = self.scale(tau);
        let mut a = Actuators {
            n: self.units.len(),
            t,
            ..Actuators::default()
        };
        for i in 0..self.units.len() {
            (a.thrust[i], a.angle[i], _) = self.unit_command(i, tau, c, 0.0);
        }
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
        let util = (self.units.iter().zip(&d.thrust[..n]))
            .fold(0.0, |m: f64, (u, t)| m.max(u.utilisation(*t)));
        Allocation {
            commanded: *tau,
            delivered: Vector3::new(force.x, force.y, moment.z),
            scale: self.scale(&(tau - self.stuck_part(mem))),
            thrust: d.thrust[..n].to_vec(),
            angle: d.angle[..n].to_vec(),
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
    use super::super::tests::osv;
    use super::*;

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
}
