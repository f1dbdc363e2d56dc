//! A constant, uniform ocean current (docs/model.md §5.5).
//!
//! Table `[current]` (optional): `velocity` (m/s, spatial frame, z up; the direction the water
//! flows towards), each component within ±10 m/s; or instead `speed` (m/s, within 0–10) with one
//! of `direction` or `direction_towards` (degrees, spatial, from x towards y: where the water
//! flows towards) or `direction_from` (where it comes from), written to the normalised file as
//! the `velocity` they give. The hydrodynamic damping then acts on the
//! velocity relative to the water, `−D_t (v − v_c)` with `v_c = Qᵀ V_c` in the body frame
//! (T. I. Fossen, "How to incorporate wind, waves and ocean currents in the marine craft
//! equations of motion", IFAC MCMC 2012: relative velocity in the damping; for a vessel without
//! added mass, as the paper's, that is the whole load of a constant irrotational current). The
//! rotational damping is unchanged (an irrotational current).
//!
//! The damping component keeps its force `−D ν` and its account (dissipated, `νᵀDν`); with a
//! full damping matrix (`vessel.damping_matrix`) the current's part is `D_tt Qᵀ V_c` on the force
//! and `D_rt Qᵀ V_c` on the moment.
//! this component adds the rest, `+D_t Qᵀ V_c`. At frozen attitude that is constant, so it
//! enters flow S2 as an affine term, exactly solvable, and its power `v·D_t Qᵀ V_c` is booked
//! as the work of the port `current` (supplied; it is negative when the vessel moves against
//! the current faster than the current would carry it). The ledger closes as before.
//!
//! **With quadratic damping** (`[damping_quadratic]`) this component also adds the rest of the
//! quadratic drag on the relative velocity, `C ∘ (|v| ∘ v − |v_r| ∘ v_r)` (docs/model.md §5.11),
//! booked to `current` as well; it is a forcing of flow S2, its linearisation at the sub-step's
//! start in the implicit rows.
//!
//! **A slowly varying current** (a time table): instead of `velocity`, `times` (s, increasing)
//! and `velocities` (one row of 3 numbers per time, m/s, spatial): the current moves linearly
//! between the rows and stays at the first and last row outside them. It is then a forcing of
//! flow S2 in time (Gauss collocation at the stage times, docs/model.md §3.7), booked as
//! before. (A time-varying current also accelerates the water around a vessel with added mass;
//! the paper's vessel has none, so the relative-velocity damping is again the whole load.)

use super::{Force, Forcing, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::model::grid::check_increasing;
use crate::model::vessel::params::{physical, Params, Range};
use crate::solve::Account;
use nalgebra::Vector3;
use std::sync::Arc;

/// The largest current component accepted (m/s): ocean currents stay below about 3 m/s.
pub const MAX_SPEED: f64 = 10.0;

#[derive(Debug, Clone, PartialEq)]
pub struct Current {
    /// `V_c`, spatial frame, m/s (the constant current, or the table's first row).
    pub velocity: Vector3<f64>,
    /// The time table `(t, V_c)`, if the current varies.
    pub table: Option<(Vec<f64>, Vec<Vector3<f64>>)>,
    /// The vessel's linear damping on a translational velocity: its force block `D_tt` (kg/s)
    /// and its moment block `D_rt` (kg m/s; zero for the paper's diagonal damping).
    pub damping: nalgebra::Matrix3<f64>,
    pub damping_moment: nalgebra::Matrix3<f64>,
    /// The translational coefficients of the vessel's quadratic damping (kg/m), if it has one
    /// (`[damping_quadratic]`).
    pub quadratic: Option<Vector3<f64>>,
}

pub fn build(p: &mut Params, body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    Ok(read(p, body)?.map(|c| Arc::new(c) as Arc<dyn Force>))
}

/// The keys that give a constant current's direction by its speed (degrees, spatial, from x
/// towards y): where it flows towards (`direction`, `direction_towards`; the oceanographic
/// convention) or where it comes from (`direction_from`).
const DIRECTION_KEYS: [&str; 3] = ["direction", "direction_towards", "direction_from"];

/// A constant current given by `speed` (m/s, `0..=MAX_SPEED`) and one of [`DIRECTION_KEYS`]
/// instead of `velocity`: its velocity, recorded as `velocity` in the normalised file (so the
/// file reads back the same), or `None` without `speed`.
fn speed_and_direction(p: &mut Params) -> crate::Result<Option<[f64; 3]>> {
    const T: &str = "current";
    let number = |key: &str, v: &toml::Value, unit: &str| match v {
        toml::Value::Float(f) => Ok(*f),
        toml::Value::Integer(i) => Ok(*i as f64),
        other => Err(Error::Parse(format!(
            "current.{key} must be a number ({unit}), got {} {other}",
            other.type_str()
        ))),
    };
    let Some(raw) = p.take_raw(T, "speed")? else {
        for key in DIRECTION_KEYS {
            if p.take_raw(T, key)?.is_some() {
                return Err(Error::InvalidInput(format!(
                    "current.{key} gives the direction of current.speed (m/s), which is missing; or give current.velocity (m/s, spatial frame) alone"
                )));
            }
        }
        return Ok(None);
    };
    let speed = number("speed", &raw, "m/s")?;
    if !(0.0..=MAX_SPEED).contains(&speed) {
        return Err(Error::InvalidInput(format!(
            "current.speed must be within 0 to {MAX_SPEED} m/s, got {speed}"
        )));
    }
    if p.take_raw(T, "velocity")?.is_some() {
        return Err(Error::InvalidInput(
            "[current] takes either velocity (m/s, spatial frame) or speed with a direction, not both".into(),
        ));
    }
    let mut given = Vec::new();
    for key in DIRECTION_KEYS {
        if let Some(v) = p.take_raw(T, key)? {
            given.push((key, number(key, &v, "degrees")?));
        }
    }
    let [(key, deg)] = given[..] else {
        return Err(Error::InvalidInput(format!(
            "current.speed needs exactly one of current.direction or current.direction_towards (degrees, where it flows towards, spatial, from x towards y) or current.direction_from (where it comes from), got {}",
            if given.is_empty() { "none".to_string() } else { given.iter().map(|(k, _)| *k).collect::<Vec<_>>().join(" and ") }
        )));
    };
    if !(deg.is_finite() && deg.abs() <= 360.0) {
        return Err(Error::InvalidInput(format!(
            "current.{key} must be within ±360 degrees, got {deg}"
        )));
    }
    let towards = if key == "direction_from" {
        deg + 180.0
    } else {
        deg
    }
    .to_radians();
    let v = [speed * towards.cos(), speed * towards.sin(), 0.0];
    p.record_value(
        T,
        "velocity",
        toml::Value::Array(v.iter().map(|x| toml::Value::Float(*x)).collect()),
    );
    Ok(Some(v))
}

/// The current of the file's `[current]` table, if any (also read by `crossflow.rs`, whose drag
/// acts on the velocity relative to the water).
pub fn read(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Current>> {
    const T: &str = "current";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let times = p.rows(T, "times", 1, "s", Range::Physical(&physical::TIME))?;
    let rows = p.rows(T, "velocities", 3, "m/s, spatial frame", Range::Finite)?;
    let table = match (times, rows) {
        (None, None) => None,
        (Some(t), Some(v)) => {
            if t.is_empty() || t.len() != v.len() {
                return Err(Error::InvalidInput(format!(
                    "current.times and current.velocities must have one entry per row, and at least one: got {} times and {} velocities",
                    t.len(),
                    v.len()
                )));
            }
            let t: Vec<f64> = t.into_iter().map(|r| r[0]).collect();
            check_increasing("current.times", &t, "s")?;
            for (k, r) in v.iter().enumerate() {
                for (i, x) in r.iter().enumerate() {
                    if x.abs() > MAX_SPEED {
                        return Err(Error::InvalidInput(format!(
                            "current.velocities[{k}][{i}] must be within ±{MAX_SPEED} m/s (m/s, spatial frame), got {x}"
                        )));
                    }
                }
            }
            Some((t, v.into_iter().map(|r| Vector3::new(r[0], r[1], r[2])).collect::<Vec<_>>()))
        }
        _ => {
            return Err(Error::InvalidInput(
                "a current time table needs both current.times (s) and current.velocities (rows of 3 numbers, m/s)".into(),
            ))
        }
    };
    let velocity = if let Some((_, v)) = &table {
        if p.take_raw(T, "velocity")?.is_some() {
            return Err(Error::InvalidInput(
                "[current] takes either velocity (a constant current) or times and velocities (a time table), not both".into(),
            ));
        }
        [v[0].x, v[0].y, v[0].z]
    } else if let Some(v) = speed_and_direction(p)? {
        v
    } else {
        p.vec3(
            T,
            "velocity",
            Some([0.0; 3]),
            "m/s, spatial frame",
            Range::Finite,
        )?
    };
    for (i, v) in velocity.iter().enumerate() {
        if v.abs() > MAX_SPEED {
            return Err(Error::InvalidInput(format!(
                "current.velocity[{i}] must be within ±{MAX_SPEED} m/s (m/s, spatial frame), got {v}"
            )));
        }
    }
    let d = super::damping::read_matrix(p)?;
    let damping = d.fixed_view::<3, 3>(0, 0).into_owned();
    let damping_moment = d.fixed_view::<3, 3>(3, 0).into_owned();
    let quadratic = super::damping_quadratic::coefficients(p)?.map(|c| c.0);
    Ok(Some(Current {
        velocity: velocity.into(),
        table,
        damping,
        damping_moment,
        quadratic,
    }))
}

const ACCOUNTS: [Account; 1] = [Account::supplied("current")];

/// The current's part of the quadratic damping at the body velocity `v` and the current `vc`
/// (body frame): `C ∘ (|v| ∘ v − |v − vc| ∘ (v − vc))`, so that with the damping's own
/// `−C ∘ |v| ∘ v` the force is the relative velocity's, `−C ∘ |v_r| ∘ v_r`.
fn quadratic_part(c: &Vector3<f64>, v: &Vector3<f64>, vc: &Vector3<f64>) -> Vector3<f64> {
    let vr = v - vc;
    c.component_mul(&(v.abs().component_mul(v) - vr.abs().component_mul(&vr)))
}

impl Current {
    /// The linearisation of [`quadratic_part`] at the sub-step's start (velocity `ν₀`, the
    /// current of the constant case or of the table's first row): `J v + c0` with
    /// `J = diag(2 C ∘ (|v₀| − |v₀ − v_c|))`. In the implicit rows, it keeps the fixed point of
    /// the forcing contractive at long steps; the forcing carries the rest.
    fn quadratic_linearisation(
        &self,
        fr: &Frozen,
        c: &Vector3<f64>,
    ) -> (nalgebra::Matrix3<f64>, Vector3<f64>) {
        let v0 = fr.velocity[0];
        let vc0 = fr.qt * self.velocity;
        let j = (c * 2.0).component_mul(&(v0.abs() - (v0 - vc0).abs()));
        let c0 = quadratic_part(c, &v0, &vc0) - j.component_mul(&v0);
        (nalgebra::Matrix3::from_diagonal(&j), c0)
    }

    /// The body-frame force of the constant current at attitude `Qᵀ = qt`: `D_tt Qᵀ V_c`.
    pub fn body_force(&self, qt: &nalgebra::Matrix3<f64>) -> Vector3<f64> {
        self.damping * (qt * self.velocity)
    }

    /// The current at time `t` (m/s, spatial).
    pub fn velocity_at(&self, t: f64) -> Vector3<f64> {
        let Some((ts, vs)) = &self.table else {
            return self.velocity;
        };
        let k = ts.partition_point(|x| *x <= t);
        if k == 0 {
            return vs[0];
        }
        if k == ts.len() {
            return vs[k - 1];
        }
        let w = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
        vs[k - 1] * (1.0 - w) + vs[k] * w
    }
}

impl Force for Current {
    fn name(&self) -> &'static str {
        "current"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        if self.table.is_none() {
            let vc = fr.qt * self.velocity;
            b.force(Sys::Trans, Some(0), &Rows::constant(self.damping * vc));
            if self.damping_moment.amax() > 0.0 {
                b.force(Sys::Rot, Some(0), &Rows::constant(self.damping_moment * vc));
            }
        }
        if let Some(c) = &self.quadratic {
            let (lin, c0) = self.quadratic_linearisation(fr, c);
            b.force(
                Sys::Trans,
                Some(0),
                &Rows {
                    c: c0,
                    ..Rows::on_velocity(Sys::Trans, lin)
                },
            );
        }
    }
    fn forced(&self) -> bool {
        self.table.is_some() || self.quadratic.is_some()
    }
    fn forcing_uses_state(&self) -> bool {
        self.quadratic.is_some()
    }
    /// Only the quadratic part's linearisation reads the velocities.
    fn assembly_reads_motion(&self) -> bool {
        self.quadratic.is_some()
    }
    fn add_forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], g: &mut Forcing) {
        let vc = fr.qt * self.velocity_at(t);
        if self.table.is_some() {
            g.force(Sys::Trans, Some(0), self.damping * vc);
            g.force(Sys::Rot, Some(0), self.damping_moment * vc);
        }
        if let Some(c) = &self.quadratic {
            // The quadratic damping on the relative velocity: C ∘ (|v| v − |v − v_c| (v − v_c)),
            // less its linearisation at the sub-step's start, which add_s2 puts in the
            // implicit rows.
            let v = fr.nu(z)[0];
            let (lin, c0) = self.quadratic_linearisation(fr, c);
            let f = quadratic_part(c, &v, &vc);
            g.force(Sys::Trans, Some(0), f - lin * v - c0);
        }
    }
}
