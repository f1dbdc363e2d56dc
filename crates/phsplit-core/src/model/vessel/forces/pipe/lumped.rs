//! The dynamic pipe: a lumped-mass line with states of its own, hanging from the hang-off point
//! of the hull (docs/model.md §5.18; the paper's Fig. 1 and its reference 13, Jensen et al.,
//! Ocean Eng. 2010, of a pipe coupled to a DP vessel as a passive system).
//!
//! Table `[pipe]` with `model = "lumped_mass"` (the natural catenary, `pipe.rs`, is the other
//! model): `length` (m, unstretched), `segments` (an integer, 2 to [`MAX_SEGMENTS`]),
//! `axial_stiffness` `EA` (N), `mass` (kg/m, in air), `diameter` (m, hydrodynamic outer),
//! `water_depth` (m), `hang_off` (m, body frame), `anchor` (`[x, y]`, m, spatial, on the
//! seabed), and optionally `drag_normal` (1.2), `drag_tangential` (0.008), `added_mass` (1.0),
//! `seabed_stiffness` (Pa/m, 3e6), `seabed_damping` (Pa s/m, 3e5), `axial`
//! (`"tension_only"`, default, or `"tension_and_compression"`). The defaults are MoorDyn's
//! (its line and seabed defaults). Gravity and water density are the vessel's; a constant
//! current (`[current]`) moves the water the drag acts against.
//!
//! **Its own states**: the top node `r` (where the line leaves the hull, spatial), the free
//! nodes' positions and momenta ([`Chain`]). Its storage, a part of H: the nodes' kinetic
//! energy, the segments' strain, the weight and the seabed's springs.
//!
//! **Its flow**: the line and the hull's momenta `u` at the frozen attitude `Q₀` form a
//! port-Hamiltonian system of constant structure, `r' = B ν`, `u' = Bᵀ F` with
//! `B = Q₀ [I, −[r_h]×]` (the hang-off point's velocity and the line's pull as a force and
//! moment on the hull), `ν = M⁻¹u`, the nodes canonical. Its discrete-gradient step
//! ([`Chain::step`]) keeps its energy `½uᵀM⁻¹u + storage` to the Newton tolerance, less the drag
//! and seabed dissipation, plus the current's work. It is nested in flow S2 by Strang's rule,
//! `S2(h/2) S3(h) S2(h/2)` (order 2; the vessel refuses compositions of higher order with it).
//! Flows S1 and S2 leave the line's states alone.
//!
//! **Ledger**: `pipe_drag`, `pipe_axial_damping` and `seabed` (dissipated), `pipe_current`
//! (supplied), and the power port at the hang-off point booked on both sides, `pipe_on_vessel`
//! (the line's work on the hull) and `vessel_on_pipe` (the hull's on the line): they cancel in
//! every step, as the port is internal to H.
//!
//! **The hang-off point**: the top `r` follows the hull by `r' = B ν` in the nested flow while
//! the hull moves in S1 and S2; the two integrate the same velocity at different sub-steps, so
//! they part by the composition's error, `O(h²)` per unit time and, under a steady pull (a DP
//! vessel holding against the pipe), steadily. The top is therefore steered back to the
//! hang-off point over [`DRIFT_RELAXATION`], a velocity `(x + Q r_h − r)/τ` added to its
//! motion, set at each step's end (where hull and top are synchronised: inside a step they
//! differ by a first-order amount the sub-flows have not yet made up) and held over the next
//! (an own state, `pipe_top_return`); what the line's pull does on it is booked as the supplied account
//! `pipe_hang_off`, `O(h²)` with the drift (docs/model.md §5.18 gives the measured values).
//! Their distance is reported (`pipe_hang_off_drift`).

use super::super::{Force, Frozen, Output, OwnState, S2Builder};
use super::chain::{Chain, Top};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::lie::so3;
use crate::model::vessel::params::{Params, Range};
use crate::model::vessel::state::VesselState;
use crate::solve::Account;
use nalgebra::{Matrix3, SMatrix, Vector3};
use std::sync::Arc;

/// The time over which the line's top returns to the hang-off point when the splitting has
/// left it elsewhere (s): long against the waves' periods, short against an operation.
pub const DRIFT_RELAXATION: f64 = 100.0;

/// Most segments of a line.
pub const MAX_SEGMENTS: usize = 1000;

#[derive(Debug, Clone)]
pub struct LumpedPipe {
    pub chain: Chain,
    /// The hang-off point (m, body frame).
    pub hang_off: Vector3<f64>,
    states: Vec<OwnState>,
}

const ACCOUNTS: [Account; 7] = [
    Account::dissipated("pipe_drag"),
    Account::dissipated("pipe_axial_damping"),
    Account::dissipated("seabed"),
    Account::supplied("pipe_current"),
    Account::supplied("pipe_on_vessel"),
    Account::supplied("vessel_on_pipe"),
    Account::supplied("pipe_hang_off"),
];

/// Read `[pipe]` with `model = "lumped_mass"`.
pub fn build(p: &mut Params, body: &super::super::Body) -> crate::Result<Arc<dyn Force>> {
    Ok(Arc::new(read(p, body)?))
}

/// A pipe's or line's outer diameter (m): the largest pipelines and risers are under 2 m.
const DIAMETER: crate::model::vessel::params::Physical = crate::model::vessel::params::Physical {
    lo: 0.0,
    hi: 5.0,
    lo_closed: false,
    hi_closed: true,
    why: "no pipe or line laid from a vessel is 5 m across",
};

/// [`build`]'s pipe itself (for a line driven at its top alone: `phsplit.pipe`).
pub fn read(p: &mut Params, body: &super::super::Body) -> crate::Result<LumpedPipe> {
    const T: &str = "pipe";
    let length = p.f64(T, "length", "m", Range::Positive)?;
    let n = p.f64(T, "segments", "an integer", Range::Positive)?;
    if n.fract() != 0.0 || !(2.0..=MAX_SEGMENTS as f64).contains(&n) {
        return Err(Error::InvalidInput(format!(
            "pipe.segments must be an integer from 2 to {MAX_SEGMENTS}, got {n}"
        )));
    }
    let segments = n as usize;
    let ea = p.f64(T, "axial_stiffness", "N", Range::Positive)?;
    let mass = p.f64(T, "mass", "kg/m", Range::Positive)?;
    let d = p.f64(T, "diameter", "m", Range::Physical(&DIAMETER))?;
    let (depth, hang_off) = super::depth_and_hang_off(p)?;
    let anchor = p
        .rows(T, "anchor", 1, "m, spatial x and y", Range::Finite)?
        .ok_or_else(|| p.missing(T, "anchor", "[x, y], m, spatial"))?;
    if anchor.len() != 2 {
        return Err(Error::InvalidInput(format!(
            "pipe.anchor must be 2 numbers [x, y] (m, spatial; the anchor lies on the seabed), got {}",
            anchor.len()
        )));
    }
    let anchor = [anchor[0][0], anchor[1][0]];
    let opt = |p: &mut Params, key: &str, unit: &str, default: f64| {
        Ok::<f64, Error>(
            p.opt_f64(T, key, unit, Range::NonNegative)?
                .unwrap_or(default),
        )
    };
    let cdn = opt(p, "drag_normal", "dimensionless", 1.2)?;
    let cdt = opt(p, "drag_tangential", "dimensionless", 0.008)?;
    let ca = opt(p, "added_mass", "dimensionless", 1.0)?;
    let kb = opt(p, "seabed_stiffness", "Pa/m", 3.0e6)?;
    let cb = opt(p, "seabed_damping", "Pa s/m", 3.0e5)?;
    let axial = p.choice(T, "axial", &["tension_only", "tension_and_compression"])?;
    let ba = opt(p, "axial_damping", "N s", 0.0)?;
    let ei = opt(p, "bending_stiffness", "N m^2", 0.0)?;
    let g = p.f64("vessel", "gravity", "m/s^2", Range::Positive)?;
    let rho = p.f64("vessel", "water_density", "kg/m^3", Range::Positive)?;
    let area = std::f64::consts::PI * d * d / 4.0;
    if mass <= rho * area {
        return Err(Error::InvalidInput(format!(
            "pipe.mass = {mass} kg/m floats: it must exceed the displaced water, ρ π d²/4 = {:.2} kg/m for pipe.diameter = {d} m",
            rho * area
        )));
    }
    let current = match super::super::current::read(&mut p.clone(), body)? {
        None => Vector3::zeros(),
        Some(c) if c.table.is_some() => {
            return Err(Error::InvalidInput(
                "the lumped-mass pipe takes a constant current ([current] velocity or speed), not a time table; use pipe.model = \"catenary\" or a constant current".into(),
            ))
        }
        Some(c) => c.velocity,
    };
    let l = length / segments as f64;
    let chain = Chain {
        segments,
        rest: l,
        ea,
        compression: axial == "tension_and_compression",
        axial_damping: ba / l,
        bending: ei,
        mass: (mass + ca * rho * area) * l,
        weight: (mass - rho * area) * g * l,
        drag_normal: 0.5 * rho * cdn * d * l,
        drag_tangential: 0.5 * rho * cdt * std::f64::consts::PI * d * l,
        seabed: -depth,
        seabed_stiffness: kb * d * l,
        seabed_damping: cb * d * l,
        anchor: Vector3::new(anchor[0], anchor[1], -depth),
        current,
    };
    if length <= depth + hang_off.z {
        return Err(Error::InvalidInput(format!(
            "pipe.length = {length} m is not longer than the height of the hang-off point above the seabed ({} m, pipe.water_depth + pipe.hang_off[2]): the pipe cannot reach the seabed",
            depth + hang_off.z
        )));
    }
    Ok(LumpedPipe {
        states: own_states(&chain),
        chain,
        hang_off,
    })
}

fn own_states(c: &Chain) -> Vec<OwnState> {
    // Each group of 3-vectors: (name of entry `i`, unit, long name of entry `i`), for `i` in its
    // range (`0..1` for a group of one).
    type Name = fn(usize, &str) -> (String, String);
    let groups: [(std::ops::Range<usize>, &str, Name); 4] = [
        (0..1, "m", |_, a| {
            (
                format!("pipe_top_{a}"),
                format!("the pipe's top node, {a} (spatial)"),
            )
        }),
        (1..c.segments, "m", |i, a| {
            (
                format!("pipe_node{i}_{a}"),
                format!("the pipe's node {i}, {a} (spatial)"),
            )
        }),
        (1..c.segments, "kg m s-1", |i, a| {
            (
                format!("pipe_node{i}_p{a}"),
                format!("the pipe's node {i}, momentum {a} (spatial)"),
            )
        }),
        (0..1, "m s-1", |_, a| {
            (
                format!("pipe_top_return_{a}"),
                format!("the velocity returning the pipe's top to the hang-off point over the step, {a} (spatial)"),
            )
        }),
    ];
    let mut v = Vec::with_capacity(c.dim() + 3);
    for (range, unit, name) in groups {
        for i in range {
            for a in ["x", "y", "z"] {
                let (name, long_name) = name(i, a);
                v.push(OwnState {
                    name,
                    unit: unit.into(),
                    long_name,
                    initial: 0.0,
                });
            }
        }
    }
    v
}

impl LumpedPipe {
    /// `B = Q₀ [I, −[r_h]×]`: the hang-off point's spatial velocity per body velocity.
    fn b(&self, q: &Matrix3<f64>) -> SMatrix<f64, 3, 6> {
        let mut b = SMatrix::<f64, 3, 6>::zeros();
        b.fixed_view_mut::<3, 3>(0, 0).copy_from(q);
        b.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(-q * so3::hat(&self.hang_off)));
        b
    }
    fn minv(fr: &Frozen) -> SMatrix<f64, 6, 6> {
        let m = &fr.body.minv_blocks;
        let mut out = SMatrix::<f64, 6, 6>::zeros();
        for j in 0..2 {
            for l in 0..2 {
                out.fixed_view_mut::<3, 3>(3 * j, 3 * l).copy_from(&m[j][l]);
            }
        }
        out
    }
    /// The line's pull on the top as a force and moment on the hull (body frame).
    fn wrench(&self, fr: &Frozen, pull: &Vector3<f64>) -> [Vector3<f64>; 2] {
        let f = fr.qt * pull;
        [f, self.hang_off.cross(&f)]
    }
    /// The tension of each segment (N), from the top.
    pub fn tensions(&self, x: &[f64]) -> Vec<f64> {
        (0..self.chain.segments)
            .map(|j| {
                let c = &self.chain;
                c.tension((c.node(x, j + 1) - c.node(x, j)).norm())
            })
            .collect()
    }
}

impl Force for LumpedPipe {
    fn name(&self) -> &'static str {
        "pipe"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, _fr: &Frozen, _b: &mut S2Builder) {}
    fn own_states(&self) -> &[OwnState] {
        &self.states
    }
    fn own_storage(&self, x: &[f64]) -> f64 {
        self.chain.storage(x)
    }
    fn has_own_flow(&self) -> bool {
        true
    }
    fn own_flow(
        &self,
        fr: &Frozen,
        _s: &VesselState,
        h: f64,
        x: &mut [f64],
        u: &mut [Vector3<f64>; 2],
        booked: &mut [f64],
    ) -> bool {
        let b = self.b(&fr.q);
        let minv = Self::minv(fr);
        let mut u6 = nalgebra::Vector6::zeros();
        u6.fixed_rows_mut::<3>(0).copy_from(&u[0]);
        u6.fixed_rows_mut::<3>(3).copy_from(&u[1]);
        // The top follows the hang-off point at `B ν`, and returns to it from where the
        // splitting left it over DRIFT_RELAXATION (`correct`, m/s, set at the last step's end).
        let k = self.chain.dim();
        let correct = Vector3::new(x[k], x[k + 1], x[k + 2]);
        let drift = b * minv * u6 + correct;
        let c = b * minv * b.transpose();
        let Some(w) = self.chain.step(x, h, &Top::Body { drift, c }) else {
            return false;
        };
        let [f, m] = self.wrench(fr, &w.pull);
        u[0] += f * h;
        u[1] += m * h;
        // The hull's kinetic energy changes by F̄·(Δr − h·correct), what the line does on it;
        // the line receives the opposite and, from the correction, −F̄·h·correct.
        let port = -w.top - w.pull.dot(&correct) * h;
        let fix = -w.pull.dot(&correct) * h;
        for (k, e) in [w.drag, w.axial, w.seabed, w.current, port, -port, fix]
            .into_iter()
            .enumerate()
        {
            booked[k] += e;
        }
        true
    }
    fn own_rates(
        &self,
        fr: &Frozen,
        x: &[f64],
        nu: &[Vector3<f64>; 2],
        rates: &mut [f64],
    ) -> [Vector3<f64>; 2] {
        let k = self.chain.dim();
        let top =
            fr.q * (nu[0] + nu[1].cross(&self.hang_off)) + Vector3::new(x[k], x[k + 1], x[k + 2]);
        let pull = self.chain.rates(x, &top, rates);
        self.wrench(fr, &pull)
    }
    fn own_end_step(&self, _t: f64, s: &VesselState, x: &mut [f64]) {
        let k = self.chain.dim();
        let c = (s.x + s.q * self.hang_off - self.chain.node(x, 0)) / DRIFT_RELAXATION;
        x[k..k + 3].copy_from_slice(c.as_slice());
    }
    fn own_hull_account(&self) -> Option<usize> {
        Some(4)
    }
    fn init_own(&self, s: &VesselState, x: &mut [f64]) -> crate::Result<()> {
        let top = s.x + s.q * self.hang_off;
        let nodes = self.chain.static_shape(&top).map_err(Error::InvalidInput)?;
        x.fill(0.0);
        x[..3].copy_from_slice(top.as_slice());
        for (i, q) in nodes.iter().enumerate() {
            x[3 + 3 * i..6 + 3 * i].copy_from_slice(q.as_slice());
        }
        Ok(())
    }
    fn own_outputs(&self, fr: &Frozen, z: &[Z3; 2], x: &[f64], _t: f64, out: &mut Vec<Output>) {
        let c = &self.chain;
        let n = c.segments;
        let t = self.tensions(x);
        out.push(Output::new(
            "pipe_top_tension",
            "N",
            "the pipe's tension at the hang-off point (its top segment's and half a segment's weight)",
            c.top_force(x).norm(),
        ));
        out.push(Output::new(
            "pipe_anchor_tension",
            "N",
            "the pipe's tension at the anchor",
            t[n - 1],
        ));
        let (td, suspended) = c.touchdown(x);
        out.push(Output::new(
            "pipe_touchdown_x",
            "m",
            "the pipe's touchdown point, x (spatial)",
            td.x,
        ));
        out.push(Output::new(
            "pipe_touchdown_y",
            "m",
            "the pipe's touchdown point, y (spatial)",
            td.y,
        ));
        out.push(Output::new(
            "pipe_suspended_length",
            "m",
            "the pipe's unstretched length from the hang-off point to the touchdown",
            suspended,
        ));
        out.push(Output::new(
            "pipe_contact_length",
            "m",
            "the pipe's unstretched length on the seabed",
            c.length() - suspended,
        ));
        let mut kappa: f64 = 0.0;
        for i in 1..n {
            let (a, b, d) = (c.node(x, i - 1), c.node(x, i), c.node(x, i + 1));
            let (s0, s1) = (b - a, d - b);
            let (l0, l1) = (s0.norm(), s1.norm());
            if l0 > 0.0 && l1 > 0.0 {
                kappa = kappa.max((s1 / l1 - s0 / l0).norm() / (0.5 * (l0 + l1)));
            }
        }
        out.push(Output::new(
            "pipe_max_curvature",
            "m-1",
            "the pipe's largest curvature (the sagbend's; turn per length between segments)",
            kappa,
        ));
        out.push(Output::new(
            "pipe_max_bending_moment",
            "N m",
            "the pipe's largest bending moment, EI times its largest curvature (0 without pipe.bending_stiffness)",
            c.bending * kappa,
        ));
        let hang = fr.origin + z[0][1] + fr.q * self.hang_off;
        out.push(Output::new(
            "pipe_hang_off_drift",
            "m",
            "distance of the pipe's top node from the hull's hang-off point (the splitting's error)",
            (c.node(x, 0) - hang).norm(),
        ));
    }
}
