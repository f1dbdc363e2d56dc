//! The pipe of a pipe-lay operation as a port: the top force of a natural catenary at the
//! hang-off point on the hull (the paper's Fig. 1; docs/model.md §5.6).
//!
//! Table `[pipe]` (optional):
//! - `submerged_weight` `w` (N/m, > 0) and `water_depth` (m, in (0, 11000], `physical::WATER_DEPTH`; the seabed below the still
//!   water line, `z = 0` of the position);
//! - `hang_off` (m, body frame, from the body origin): where the pipe leaves the vessel (the
//!   stinger tip in S-lay, the tower's lower end in J-lay);
//! - exactly one way to fix the catenary:
//!   - `horizontal_tension` `H` (N) or `top_tension` `T` (N), held by the tensioner;
//!   - `departure_angle` (degrees from the horizontal, in [5, 90), `physical::DEPARTURE_ANGLE`): the pipe's angle at the
//!     hang-off point (S-lay: the stinger's departure angle, typically 30–60°; J-lay: the
//!     tower's angle, typically 80–90°);
//!   - `touchdown = [x, y]` (m, spatial): a touchdown point on the seabed; the catenary then
//!     follows from the horizontal span between it and the hang-off point;
//! - `lay_direction` (degrees, spatial, from the x axis towards y, within ±360): the direction in which the
//!   vessel lays the pipe; the pipe lies behind it. Required with a tension or an angle;
//! - `lay_speed` (m/s, ≥ 0, default 0): with `touchdown`, the touchdown point moves along
//!   `lay_direction` at this speed from t = 0 (the lay progressing).
//!
//! The height of the hang-off point above the seabed, `d = water_depth + z_h` with
//! `z_h = (x + Q r_h)·e3`, and, with `touchdown`, the span follow the vessel's motion, so the
//! force is not affine in the state: it is a forcing of flow S2 (evaluated at the collocation
//! stages). In the spatial frame the pipe pulls the hang-off point with `−H ê − V e3`, `ê` the
//! horizontal unit vector from the touchdown point to the hang-off point and `V = w s` the
//! weight of the suspended length; on the body, `f_b = Qᵀ F` at `r_h`, moment `r_h × f_b`.
//!
//! Ledger: the pipe's power `ν·τ_pipe` is booked as the work of the port `pipe` (supplied;
//! negative while the pipe pulls the vessel back). The pipe exchanges energy with the vessel
//! through the tensioner, so it is a port, not a store of H: the split stays passive with
//! respect to its ports, and the ledger closes with the pipe's work in it.

use super::{Force, Forcing, Frozen, Output, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::catenary::Catenary;
use crate::model::vessel::params::{physical, Params, Range};
use crate::model::vessel::state::VesselState;
use crate::solve::Account;
use nalgebra::{Matrix3, Vector2, Vector3};
use std::sync::Arc;

/// How the catenary is fixed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    HorizontalTension(f64),
    TopTension(f64),
    /// Radians from the horizontal.
    DepartureAngle(f64),
    /// The touchdown point at t = 0 (m, spatial).
    Touchdown(Vector2<f64>),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Pipe {
    pub weight: f64,
    pub water_depth: f64,
    pub hang_off: Vector3<f64>,
    pub mode: Mode,
    /// Unit vector of the lay direction (spatial, horizontal).
    pub lay_direction: Vector2<f64>,
    pub lay_speed: f64,
}

/// The pipe's state at one vessel position: its catenary, where it touches down, and the
/// force at the hang-off point (N, spatial).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PipeState {
    pub catenary: Catenary,
    pub touchdown: Vector2<f64>,
    pub force: Vector3<f64>,
}

/// Largest distance of the hang-off point from the body origin (m).
pub const MAX_ARM: f64 = 1000.0;

mod bending;
pub mod chain;
pub mod lumped;
mod statics;

/// The pipe's models (`pipe.model`): the quasi-static natural catenary (the default) or the
/// dynamic lumped-mass line (`pipe/lumped.rs`).
pub const MODELS: [&str; 2] = ["catenary", "lumped_mass"];

/// `pipe.water_depth` (m) and `pipe.hang_off` (m, body frame), checked: the hang-off point
/// within [`MAX_ARM`] of the body origin and above the seabed. Both models read them so.
fn depth_and_hang_off(p: &mut Params) -> crate::Result<(f64, Vector3<f64>)> {
    const T: &str = "pipe";
    let water_depth = p.f64(
        T,
        "water_depth",
        "m",
        Range::Physical(&physical::WATER_DEPTH),
    )?;
    let hang_off: Vector3<f64> = p
        .vec3(T, "hang_off", None, "m, body frame", Range::Finite)?
        .into();
    for (i, r) in hang_off.iter().enumerate() {
        if r.abs() > MAX_ARM {
            return Err(Error::InvalidInput(format!(
                "pipe.hang_off[{i}] must lie within {MAX_ARM} m of the body origin (m, body frame), got {r}"
            )));
        }
    }
    if water_depth + hang_off.z <= 0.0 {
        return Err(Error::InvalidInput(format!(
            "pipe.hang_off[2] = {} m puts the hang-off point at or below the seabed (pipe.water_depth = {water_depth} m); it must lie above it",
            hang_off.z
        )));
    }
    Ok((water_depth, hang_off))
}

pub fn build(p: &mut Params, body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "pipe";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    if p.choice(T, "model", &MODELS)? == "lumped_mass" {
        return lumped::build(p, body).map(Some);
    }
    let weight = p.f64(T, "submerged_weight", "N/m", Range::Positive)?;
    let (water_depth, hang_off) = depth_and_hang_off(p)?;
    let h = p.opt_f64(T, "horizontal_tension", "N", Range::Positive)?;
    let top = p.opt_f64(T, "top_tension", "N", Range::Positive)?;
    let angle = p.opt_f64(
        T,
        "departure_angle",
        "degrees from the horizontal",
        Range::Positive,
    )?;
    let td = p.rows(T, "touchdown", 1, "m, spatial x and y", Range::Finite)?;
    let given: Vec<&str> = [
        ("horizontal_tension", h.is_some()),
        ("top_tension", top.is_some()),
        ("departure_angle", angle.is_some()),
        ("touchdown", td.is_some()),
    ]
    .iter()
    .filter(|(_, g)| *g)
    .map(|(n, _)| *n)
    .collect();
    if given.len() != 1 {
        return Err(Error::InvalidInput(format!(
            "[pipe] needs exactly one of horizontal_tension (N), top_tension (N), departure_angle (degrees) or touchdown ([x, y], m) to fix the catenary, got {}",
            if given.is_empty() { "none".to_string() } else { given.join(", ") }
        )));
    }
    let d0 = water_depth + hang_off.z;
    let mode = if let Some(h) = h {
        Mode::HorizontalTension(h)
    } else if let Some(t) = top {
        Catenary::from_top_tension(weight, d0, t).map_err(|_| {
            Error::InvalidInput(format!(
                "pipe.top_tension must exceed the weight of a vertical pipe from the seabed to the hang-off point, w·d = {} N, got {t}",
                weight * d0
            ))
        })?;
        Mode::TopTension(t)
    } else if let Some(a) = angle {
        if a >= 90.0 {
            return Err(Error::InvalidInput(format!(
                "pipe.departure_angle must lie strictly between 0 and 90 (degrees from the horizontal), got {a}"
            )));
        }
        let r = physical::DEPARTURE_ANGLE;
        if !r.contains(a) {
            return Err(Error::InvalidInput(format!(
                "pipe.departure_angle must lie within {} (degrees from the horizontal; {}), got {a}",
                r.interval(),
                r.why
            )));
        }
        Mode::DepartureAngle(a.to_radians())
    } else {
        let td = td.expect("one was given");
        if td.len() != 2 {
            return Err(Error::InvalidInput(format!(
                "pipe.touchdown must be 2 numbers (m, spatial x and y), got {} entries",
                td.len()
            )));
        }
        Mode::Touchdown(Vector2::new(td[0][0], td[1][0]))
    };
    let needs_direction = !matches!(mode, Mode::Touchdown(_));
    let dir = p.opt_f64(
        T,
        "lay_direction",
        "degrees",
        Range::Physical(&physical::ANGLE_DEG),
    )?;
    let lay_speed = p
        .opt_f64(T, "lay_speed", "m/s", Range::NonNegative)?
        .unwrap_or(0.0);
    if lay_speed > 0.0 && needs_direction {
        return Err(Error::InvalidInput(
            "pipe.lay_speed moves the touchdown point: it goes with pipe.touchdown; with a tension or an angle the touchdown point follows the vessel by itself".into(),
        ));
    }
    let lay_direction = match dir {
        Some(deg) => Vector2::new(deg.to_radians().cos(), deg.to_radians().sin()),
        None if needs_direction || lay_speed > 0.0 => {
            return Err(Error::InvalidInput(
                "missing field `lay_direction` in [pipe] (degrees, spatial, from the x axis towards y): the direction in which the pipe is laid".into(),
            ))
        }
        None => Vector2::new(1.0, 0.0),
    };
    Ok(Some(Arc::new(Pipe {
        weight,
        water_depth,
        hang_off,
        mode,
        lay_direction,
        lay_speed,
    })))
}

const ACCOUNTS: [Account; 1] = [Account::supplied("pipe")];

impl Pipe {
    /// The pipe with the vessel at position `x` (m) and attitude `q`, at time `t` (s). A pose
    /// that puts the hang-off point at or below the seabed, or a non-finite one (a run that
    /// has blown up), has no catenary: the state is then NaN, and a run that meets it fails
    /// with what it had (never a panic).
    pub fn state_at(&self, x: &Vector3<f64>, q: &Matrix3<f64>, t: f64) -> PipeState {
        let top = x + q * self.hang_off;
        let d = self.water_depth + top.z;
        let w = self.weight;
        let horizontal = Vector2::new(top.x, top.y);
        let (cat, e) = match self.mode {
            Mode::HorizontalTension(h) => (
                Catenary::from_horizontal_tension(w, d, h),
                self.lay_direction,
            ),
            Mode::TopTension(tt) => (
                // Held above w·d: a vessel that rises far enough would lift the pipe off.
                Catenary::from_top_tension(w, d, tt.max(w * d * (1.0 + 1e-9))),
                self.lay_direction,
            ),
            Mode::DepartureAngle(a) => (Catenary::from_top_angle(w, d, a), self.lay_direction),
            Mode::Touchdown(p0) => {
                let tdp = p0 + self.lay_direction * (self.lay_speed * t.max(0.0));
                let r = horizontal - tdp;
                let span = r.norm().max(1e-9 * d);
                let e = if r.norm() > 0.0 {
                    r / r.norm()
                } else {
                    self.lay_direction
                };
                (Catenary::from_span(w, d, span), e)
            }
        };
        let nan = Vector3::from_element(f64::NAN);
        let Ok(cat) = cat else {
            return PipeState {
                catenary: Catenary {
                    weight: w,
                    height: d,
                    horizontal_tension: f64::NAN,
                },
                touchdown: Vector2::from_element(f64::NAN),
                force: nan,
            };
        };
        let touchdown = horizontal - e * cat.span();
        let h = cat.horizontal_tension;
        let force = Vector3::new(-h * e.x, -h * e.y, -cat.vertical_tension());
        PipeState {
            catenary: cat,
            touchdown,
            force,
        }
    }
}

impl Force for Pipe {
    fn name(&self) -> &'static str {
        "pipe"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    /// All of the pipe's force is forcing (it is not affine in the position).
    fn add_s2(&self, _fr: &Frozen, _b: &mut S2Builder) {}
    fn forced(&self) -> bool {
        true
    }
    fn outputs(&self, _fr: &Frozen, _z: &[Z3; 2], s: &VesselState, t: f64, out: &mut Vec<Output>) {
        let p = self.state_at(&s.x, &s.q, t);
        let c = &p.catenary;
        for (name, unit, long_name, value) in [
            (
                "pipe_top_tension",
                "N",
                "pipe tension at the hang-off point",
                c.top_tension(),
            ),
            (
                "pipe_horizontal_tension",
                "N",
                "horizontal tension of the pipe's catenary",
                c.horizontal_tension,
            ),
            (
                "pipe_vertical_tension",
                "N",
                "vertical tension at the hang-off point (weight of the suspended pipe)",
                c.vertical_tension(),
            ),
            (
                "pipe_departure_angle",
                "degree",
                "angle of the pipe at the hang-off point from the horizontal",
                c.top_angle().to_degrees(),
            ),
            (
                "pipe_suspended_length",
                "m",
                "suspended length of the pipe",
                c.suspended_length(),
            ),
            (
                "pipe_touchdown_x",
                "m",
                "touchdown point of the pipe, x (spatial)",
                p.touchdown.x,
            ),
            (
                "pipe_touchdown_y",
                "m",
                "touchdown point of the pipe, y (spatial)",
                p.touchdown.y,
            ),
        ] {
            out.push(Output::new(name, unit, long_name, value));
        }
    }
    fn add_forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], g: &mut Forcing) {
        let x = fr.origin + z[0][1];
        let f = fr.qt * self.state_at(&x, &fr.q, t).force;
        g.force(Sys::Trans, Some(0), f);
        g.force(Sys::Rot, Some(0), self.hang_off.cross(&f));
    }
}
