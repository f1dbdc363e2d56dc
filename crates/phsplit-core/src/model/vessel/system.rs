//! The vessel as a dynamical system for a run: the split (paper eqs. 39–41; docs/model.md §2–3),
//! assembled from the components, with the exact and collocated flow S2 and the ledger.
//!
//! Everything here is generic in the components: flow S2 at a frozen attitude is the sum of
//! their block contributions ([`forces::S2Builder`]); the full vector field is flow S1's
//! field plus S2's; the ledger's power, its exact integrals (Van Loan Gramian) and its Gauss
//! quadrature all follow from each account's force rows: with `ν = M⁻¹u` the power of a force
//! `f = F z̄` is the quadratic form `uᵀ M⁻¹ F z̄` of the augmented block state `z̄ = (u, v, w, 1)`.
//!
//! Flows S1 and S2 are `system/s1.rs` and `system/s2.rs` (how S2 is integrated, the user's
//! choice: `system/linear_flow.rs`); what the vessel reports at a state (the
//! components' outputs, each account's wrench, the controller's wrench for the probe) is
//! `system/report.rs`.

use super::forces::{Force, Forcing, Frozen, S2Builder, Sys};
use super::state::{Actuators, VesselState};
use super::Vessel;
use crate::flows::collocation::Z3;
use crate::flows::rigid_body::MagnusOrder;
use crate::lie::so3;
use crate::methods::Flow;
use crate::solve::{Account, FieldModel, Model, Work};
use nalgebra::{Matrix3, SVector, Vector3};

mod linear_flow;
mod memo;
mod modes;
mod own;
mod power;
mod report;
mod s1;
mod s2;
mod split;
mod step_control;

pub use linear_flow::LinearFlow;

/// Highest order of the sub-flows the vessel provides (Magnus 6, Gauss with 3 stages).
pub const MAX_SUBFLOW_ORDER: usize = 6;

/// The vessel as a dynamical system: the vessel plus the controller schedule and the choice
/// of flow S2.
#[derive(Debug, Clone)]
pub struct VesselSystem<'a> {
    pub vessel: &'a Vessel,
    /// The controller (and the growth of the integral states) acts on steps that start at or
    /// after this time; `None` keeps it off throughout.
    pub control_start: Option<f64>,
    /// How flow S2 is integrated.
    pub linear: LinearFlow,
    accounts: Vec<Account>,
    /// First account of each component.
    bases: Vec<usize>,
    /// Origin of the translational block (the controller's set point, if any).
    origin: Vector3<f64>,
    /// Project after every step onto the invariants the split does not keep (the restoring
    /// invariant `mu = G Qᵀe3`; [`Force::project`]).
    pub project: bool,
    /// Keep the running maxima of the controller's force and moment over every step.
    pub extrema: bool,
    /// Whether a component has a forcing part (non-affine or time-dependent): flow S2 is then
    /// integrated by Gauss collocation whatever [`LinearFlow`] says.
    forced: bool,
    /// Whether a component's forcing depends on the state (else one pass solves the stages).
    forced_stateful: bool,
    /// Whether a component's forcing depends on time only (evaluated once per stage).
    forced_timed: bool,
    /// Whether a component's part in flow S2 reads the frozen view's velocities or the
    /// actuators' memory ([`Force::assembly_reads_motion`]): the kept assembly then keys on
    /// them too (`system/memo.rs`).
    assembly_reads_motion: bool,
    /// Why a sub-flow gave up (a [`GaveUp`] code; 0: none), for the run's failure message.
    gave_up: std::sync::Arc<std::sync::atomic::AtomicU8>,
    /// How many rate-limited thrusters the state remembers ([`VesselState::act`]).
    pub actuators: usize,
    /// How many states the components keep of their own ([`VesselState::own`]).
    pub own_dim: usize,
    /// Each component with own states linear in flow S2: its index in the vessel's components,
    /// its range in [`VesselState::own`] and its first column in the dense flow S2 (`own.rs`).
    own_parts: Vec<(usize, std::ops::Range<usize>, usize)>,
    /// How many own states are linear in flow S2 (the dense system's beyond the body's).
    own_linear_dim: usize,
    /// Each component with a flow of its own: its index and its range in [`VesselState::own`].
    own_flowing: Vec<(usize, std::ops::Range<usize>)>,
    /// The component holding sensors' measurements ([`Frozen::held`], sampled at the step ends)
    /// and its range in [`VesselState::own`].
    held_part: Option<(usize, std::ops::Range<usize>)>,
    /// The exact flow S2's balance beyond the structural one, per controller state and block
    /// system: computed once, at the upright attitude (`s2.rs`, `exact_balance`).
    exact_balance: std::sync::OnceLock<[[nalgebra::SVector<f64, 10>; 2]; 2]>,
    /// The last frozen view and flow S2 assembled (`system/memo.rs`).
    s2_memo: memo::S2Memo<'a>,
}

/// Why a sub-flow gave up rather than return an unconverged result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum GaveUp {
    /// Kirchhoff's flow S1 did not converge, even in 1024 sub-steps.
    Kirchhoff = 1,
    /// The fixed point of flow S2's forcing did not converge in its passes.
    Forcing = 2,
    /// Flow S2's stage system was singular.
    Singular = 3,
    /// A component's own flow (the lumped-mass pipe's Newton iterations) did not converge.
    OwnFlow = 4,
}

impl<'a> VesselSystem<'a> {
    pub fn new(vessel: &'a Vessel, control_start: Option<f64>) -> Self {
        let mut accounts = Vec::new();
        let mut bases = Vec::new();
        for f in &vessel.forces {
            bases.push(accounts.len());
            accounts.extend_from_slice(f.accounts());
        }
        let origin = vessel
            .forces
            .iter()
            .find_map(|f| f.position_origin())
            .unwrap_or_else(Vector3::zeros);
        let linear = own::parts_of(vessel);
        // The component whose own states hold the sensors' measurements, and its range.
        let mut off = 0;
        let held_part = vessel.forces.iter().enumerate().find_map(|(i, f)| {
            off += f.own_states().len();
            f.held_states()
                .map(|_| (i, off - f.own_states().len()..off))
        });
        Self {
            vessel,
            control_start,
            linear: LinearFlow::Exact,
            bases,
            origin,
            project: true,
            extrema: false,
            forced: vessel.forces.iter().any(|f| f.forced()),
            forced_stateful: vessel
                .forces
                .iter()
                .any(|f| f.forced() && f.forcing_uses_state()),
            forced_timed: vessel
                .forces
                .iter()
                .any(|f| f.forced() && !f.forcing_uses_state()),
            assembly_reads_motion: vessel.forces.iter().any(|f| f.assembly_reads_motion()),
            gave_up: Default::default(),
            actuators: vessel.actuators(),
            own_dim: vessel.own_dim(),
            own_linear_dim: linear.iter().map(|p| p.1.len()).sum(),
            own_parts: linear,
            own_flowing: own::flowing_of(vessel),
            held_part,
            exact_balance: Default::default(),
            s2_memo: Default::default(),
            accounts,
        }
    }

    /// Record why a sub-flow gave up (the first reason of a run is kept).
    pub(crate) fn give_up(&self, why: GaveUp) {
        let _ = self.gave_up.compare_exchange(
            0,
            why as u8,
            std::sync::atomic::Ordering::Relaxed,
            std::sync::atomic::Ordering::Relaxed,
        );
    }

    /// Whether flow S2 has a forcing part (a non-affine or time-dependent component), so that
    /// it is integrated by Gauss collocation whatever the chosen [`LinearFlow`].
    pub fn is_forced(&self) -> bool {
        self.forced
    }

    /// How flow S2 is integrated in this system: the chosen [`LinearFlow`], or Gauss
    /// collocation of the method's order when S2 has a forcing part and the exact flow was
    /// chosen.
    pub fn s2_solver(&self) -> LinearFlow {
        if self.forced && self.linear == LinearFlow::Exact {
            LinearFlow::Gauss
        } else {
            self.linear
        }
    }

    /// The forcing of flow S2 at time `t`, block states `z` and own states `x`
    /// ([`VesselState::own`]'s layout; empty where there are none) (zero without forced
    /// components).
    fn forcing(&self, fr: &Frozen, t: f64, z: &[Z3; 2], x: &[f64]) -> Forcing {
        let mut g = Forcing::new();
        self.add_forcing_of(fr, t, z, x, None, &mut g);
        g
    }

    /// The forcing of the components whose forcing uses the state (`Some(true)`), does not
    /// (`Some(false)`), or of all (`None`), at the own states `x` (empty where there are none;
    /// a component then gets an empty slice of its own), added to `g`.
    fn add_forcing_of(
        &self,
        fr: &Frozen,
        t: f64,
        z: &[Z3; 2],
        x: &[f64],
        uses_state: Option<bool>,
        g: &mut Forcing,
    ) {
        if self.forced {
            let mut off = 0;
            for (f, base) in self.vessel.forces.iter().zip(&self.bases) {
                let n = f.own_states().len();
                if f.forced() && uses_state.is_none_or(|u| u == f.forcing_uses_state()) {
                    g.base = *base;
                    g.own_base = off;
                    let own = x.get(off..off + n).unwrap_or(&[]);
                    f.add_forcing_own(fr, t, z, own, g);
                }
                off += n;
            }
        }
    }

    /// The same system keeping (or not) the running maxima of the controller's force and
    /// moment (norms, body frame) over every step ([`Model::probe_names`]).
    pub fn with_extrema(mut self, extrema: bool) -> Self {
        self.extrema = extrema;
        self
    }

    /// The same system with (`true`, the default) or without (the paper's scheme as printed)
    /// the projection after every step ([`Force::project`], docs/model.md §3.6).
    pub fn with_projection(mut self, project: bool) -> Self {
        self.project = project;
        self
    }

    /// The same system with flow S2 integrated by `linear`.
    pub fn with_linear_flow(mut self, linear: LinearFlow) -> Self {
        self.linear = linear;
        self
    }

    /// Whether the controller acts on a step that starts at `t`.
    pub fn control_on(&self, t: f64) -> bool {
        match self.control_start {
            None => false,
            Some(tc) => t >= tc - 1e-9 * tc.abs().max(1.0),
        }
    }

    /// The frozen view of a sub-step that starts at `s`.
    fn frozen(&self, s: &VesselState, on: bool) -> Frozen<'a> {
        let mut fr = self.frozen_at(&s.q, on);
        fr.velocity = self.vessel.body.velocity(&s.p, &s.m);
        fr.actuators = s.act;
        fr.held = self.held_of(s);
        fr
    }

    /// The sensors' measurements held at `s` ([`Frozen::held`]).
    pub(super) fn held_of(&self, s: &VesselState) -> Option<[f64; super::forces::HELD]> {
        let (i, r) = self.held_part.as_ref()?;
        let h = self.vessel.forces[*i].held_states()?;
        let mut a = [0.0; super::forces::HELD];
        a.copy_from_slice(&s.own[r.start + h.start..r.start + h.end]);
        Some(a)
    }

    /// Component `i`'s update of its own states (range `r`) at time `t` ([`Force::own_end_step`]).
    fn own_end_step(&self, i: usize, r: &std::ops::Range<usize>, t: f64, s: &mut VesselState) {
        let mut x = s.own[r.clone()].to_vec();
        self.vessel.forces[i].own_end_step(t, s, &mut x);
        s.own[r.clone()].copy_from_slice(&x);
    }

    /// The frozen view at the attitude `q`, the vessel at rest.
    fn frozen_at(&self, q: &Matrix3<f64>, on: bool) -> Frozen<'a> {
        let qt = q.transpose();
        let (euler, w) = so3::euler_and_w(q);
        Frozen {
            q: *q,
            qt,
            q3: qt.column(2).into_owned(),
            euler,
            w,
            origin: self.origin,
            control_on: on,
            body: &self.vessel.body,
            velocity: [Vector3::zeros(); 2],
            actuators: Default::default(),
            held: None,
        }
    }

    /// Flow S2 at the attitude `q` (paper eq. 41), assembled from the components; with
    /// `ledger`, each account's force rows too.
    pub fn s2_at(&self, q: &Matrix3<f64>, on: bool, ledger: bool) -> S2Builder {
        self.s2_of(&self.frozen_at(q, on), ledger)
    }

    /// Flow S2 at the frozen view `fr` ([`Self::s2_at`]).
    fn s2_of(&self, fr: &Frozen, ledger: bool) -> S2Builder {
        let mut b = S2Builder::new(None);
        self.s2_into(fr, ledger, &mut b);
        b
    }

    /// [`Self::s2_of`] into the builder `b`, which keeps its allocation.
    fn s2_into(&self, fr: &Frozen, ledger: bool, b: &mut S2Builder) {
        b.reset(ledger.then_some(self.accounts.len()));
        // The kinematics of the position, x' = Q v: the body's, not a force's.
        b.rate_v(Sys::Trans, Sys::Trans, &fr.q);
        for (f, base) in self.vessel.forces.iter().zip(&self.bases) {
            b.base = *base;
            f.add_s2(fr, b);
        }
        let body = &self.vessel.body;
        b.finish(&body.minv_blocks, body.is_diagonal());
    }

    /// The block states of `s`: translation `(p, x − x_o, phi_x)`, rotation `(m, mu, phi_th)`.
    fn blocks_of(&self, s: &VesselState) -> [Z3; 2] {
        [[s.p, s.x - self.origin, s.phi_x], [s.m, s.mu, s.phi_th]]
    }

    fn set_blocks(&self, s: &mut VesselState, z: &[Z3; 2]) {
        s.p = z[0][0];
        s.x = self.origin + z[0][1];
        s.phi_x = z[0][2];
        s.m = z[1][0];
        s.mu = z[1][1];
        s.phi_th = z[1][2];
    }

    /// The diagonal of `M⁻¹` on the momentum of each block system (`M` of the paper's form).
    fn minv(&self) -> [Vector3<f64>; 2] {
        let b = &self.vessel.body.minv_blocks;
        [b[0][0].diagonal(), b[1][1].diagonal()]
    }

    /// The vector field of flow S1 (eq. 40) or S2 (eq. 41) at `s` and time `t`. Their sum is
    /// eq. (39).
    pub fn split_field(&self, s: &VesselState, t: f64, on: bool, which: Flow) -> VesselState {
        let z = Vector3::zeros();
        match which {
            Flow::S1 => {
                let (dp, dm, w) = self.s1_rates(s);
                VesselState {
                    p: dp,
                    m: dm,
                    q: s.q * so3::hat(&w),
                    mu: z,
                    x: z,
                    phi_th: z,
                    phi_x: z,
                    act: s.act,
                    own: vec![0.0; s.own.len()],
                }
            }
            Flow::S2 => {
                let view = self.frozen(s, on);
                let b = self.s2_of(&view, false);
                let zs = self.blocks_of(s);
                let [mut ft, mut fr] = [b.sys[0].field(&zs[0]), b.sys[1].field(&zs[1])];
                if let Some(c) = &b.cross {
                    // What each system takes from the other's momentum.
                    ft[0] += c[0][0] * zs[1][0] + c[0][2] * zs[1][1];
                    ft[1] += c[0][1] * zs[1][0];
                    fr[0] += c[1][0] * zs[0][0] + c[1][2] * zs[0][1];
                    fr[1] += c[1][1] * zs[0][0];
                }
                let g = self.forced.then(|| self.forcing(&view, t, &zs, &s.own));
                if let Some(g) = &g {
                    for i in 0..3 {
                        ft[i] += g.g[0][i];
                        fr[i] += g.g[1][i];
                    }
                }
                let mut own = Vec::new();
                if self.own_dim > 0 {
                    let (mut rates, tau) = self.own_field(&view, &zs, &s.own);
                    if let Some(g) = &g {
                        for (k, r) in rates.iter_mut().enumerate() {
                            *r += g.own_part(k);
                        }
                    }
                    ft[0] += tau[0];
                    fr[0] += tau[1];
                    for (_, tau) in self.own_flow_field(&view, s, &mut rates) {
                        ft[0] += tau[0];
                        fr[0] += tau[1];
                    }
                    own = rates;
                }
                VesselState {
                    p: ft[0],
                    m: fr[0],
                    q: Matrix3::zeros(),
                    mu: fr[1],
                    x: ft[1],
                    phi_th: fr[2],
                    phi_x: ft[2],
                    act: s.act,
                    own,
                }
            }
        }
    }

    /// The full vector field, eq. (39), at time `t`: S1's field plus S2's at the current
    /// attitude.
    pub fn vector_field(&self, s: &VesselState, t: f64, on: bool) -> VesselState {
        let mut d = self.split_field(s, t, on, Flow::S2);
        let (dp, dm, w) = self.s1_rates(s);
        d.p += dp;
        d.m += dm;
        d.q = s.q * so3::hat(&w);
        d
    }
}

impl VesselSystem<'_> {
    /// Let each component with actuators update their memory in `s` (the view of `s` with the
    /// controller `on`).
    fn update_memory(
        &self,
        s: &mut VesselState,
        on: bool,
        update: impl Fn(&dyn Force, &Frozen, &[Z3; 2], &mut Actuators),
    ) {
        let fr = self.frozen(s, on);
        let z = self.blocks_of(s);
        for f in &self.vessel.forces {
            if f.actuators() > 0 {
                update(f.as_ref(), &fr, &z, &mut s.act);
            }
        }
    }
}

// ------------------------------------------------------------------------------------------
// The vessel for the solver.

impl Model for VesselSystem<'_> {
    type State = VesselState;
    fn energy(&self, s: &VesselState) -> f64 {
        self.vessel.energy(s)
    }
    fn is_finite(&self, s: &VesselState) -> bool {
        s.is_finite()
    }
    fn failure_reason(&self) -> Option<String> {
        let code = self.gave_up.load(std::sync::atomic::Ordering::Relaxed);
        Some(match code {
            1 => "flow S1 (Kirchhoff's equations for the general mass matrix) did not converge even in 1024 sub-steps: the rotation is far too fast for the step; take a shorter step".into(),
            2 => "the fixed point of flow S2's non-affine or time-dependent forces (quadratic or cross-flow drag, wind, waves, pipe, thrusters) did not converge: they change too much within the step; take a shorter step".into(),
            3 => "flow S2's collocation stage system was singular; take a shorter step".into(),
            4 => "the lumped-mass pipe's implicit step (Newton's method on its discrete gradient) did not converge: its nodes move too far within the step; take a shorter step".into(),
            _ => return None,
        })
    }
    fn same_field(&self, t_a: f64, t_b: f64) -> bool {
        self.control_on(t_a) == self.control_on(t_b)
    }
    fn accounts(&self) -> &[Account] {
        &self.accounts
    }
    fn projects(&self) -> bool {
        self.project
    }
    /// The restoring invariant `mu − G Qᵀe3` is linear in the state: Runge–Kutta keeps it.
    fn projects_runge_kutta(&self) -> bool {
        false
    }
    fn probe_names(&self) -> &[&'static str] {
        if self.extrema {
            &["control_force", "control_moment"]
        } else {
            &[]
        }
    }
    /// The norms of the controller's force and moment (its P, I and D accounts together, or what
    /// its thrusters deliver).
    fn probe(&self, t: f64, s: &VesselState, out: &mut [f64]) {
        let (f, m) = self.control_wrench(s, t);
        out[0] = f.norm();
        out[1] = m.norm();
    }
    /// Rate-limited thrusters: start their memory with what they deliver at `t0`, unless the
    /// state brings it (a run continued from an earlier call's last state).
    fn begin(&self, t0: f64, s: &mut VesselState) {
        // Sensors take their first samples where the run starts (a continued run keeps its own).
        if let Some((i, r)) = &self.held_part {
            self.own_end_step(*i, r, t0, s);
        }
        if self.actuators > 0 && s.act.n != self.actuators {
            self.update_memory(s, self.control_on(t0), |f, fr, z, act| {
                f.begin_memory(fr, t0, z, act)
            });
        }
    }
    /// The components' own states' updates at the end of the step (a pipe's drift correction,
    /// the sensors' samples); rate-limited thrusters: record what they deliver.
    fn end_step(&self, t_step: f64, t1: f64, s: &mut VesselState) {
        for (i, r) in self.own_flowing.iter().chain(&self.held_part) {
            self.own_end_step(*i, r, t1, s);
        }
        if self.actuators > 0 {
            self.update_memory(s, self.control_on(t_step), |f, fr, z, act| {
                f.end_step(fr, t1, z, act)
            });
        }
    }
    fn runge_kutta_refused(&self) -> Option<String> {
        self.runge_kutta_refusal()
    }
    fn error_norm(
        &self,
        a: &VesselState,
        b: &VesselState,
        c: &VesselState,
        r: f64,
        at: f64,
    ) -> Option<f64> {
        Some(self.motion_error(a, b, c, r, at))
    }
    fn next_switch(&self, t: f64) -> Option<f64> {
        let start = self
            .control_start
            .filter(|&tc| !self.control_on(t) && tc > t);
        let events = self.vessel.forces.iter().filter_map(|f| f.next_event(t));
        start.into_iter().chain(events).reduce(f64::min)
    }
    fn project(&self, s: &mut VesselState) -> Work {
        for f in &self.vessel.forces {
            f.project(s);
        }
        Work::default()
    }
}

impl FieldModel<{ super::STATE_DIM }> for VesselSystem<'_> {
    fn to_vector(&self, s: &VesselState) -> SVector<f64, { super::STATE_DIM }> {
        s.to_vector()
    }
    fn from_vector(&self, y: &SVector<f64, { super::STATE_DIM }>) -> VesselState {
        VesselState::from_vector(y)
    }
    fn rhs(
        &self,
        t_step: f64,
        t: f64,
        y: &SVector<f64, { super::STATE_DIM }>,
    ) -> SVector<f64, { super::STATE_DIM }> {
        self.vector_field(&VesselState::from_vector(y), t, self.control_on(t_step))
            .to_vector()
    }
    fn power(&self, t_step: f64, t: f64, y: &SVector<f64, { super::STATE_DIM }>) -> Work {
        VesselSystem::power(
            self,
            &VesselState::from_vector(y),
            t,
            self.control_on(t_step),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::forces::external::{External, Frame};
    use super::*;
    use crate::solve::AccountKind;
    use proptest::prelude::*;

    /// A 3-vector of the vessel's normalised parameters.
    fn param(v: &Vessel, section: &str, key: &str) -> Vector3<f64> {
        let a = v.params[section][key].as_array().unwrap();
        Vector3::from_fn(|i, _| a[i].as_float().unwrap())
    }
    fn scalar(v: &Vessel, key: &str) -> f64 {
        v.params["vessel"][key].as_float().unwrap()
    }

    /// The natural periods against the closed forms of the decoupled upright oscillators
    /// (heave `2π √(mv/(g ρ A_wp))`, roll `2π √(T1/(mv g GM_T))`, pitch `2π √(T2/(mv g GM_L))`),
    /// written from the vessel file's numbers, not from the components.
    #[test]
    fn natural_periods_match_the_closed_forms() {
        let v = Vessel::paper();
        let sys = VesselSystem::new(&v, Some(0.0));
        let (m, g) = (scalar(&v, "mass"), scalar(&v, "gravity"));
        let t = param(&v, "vessel", "inertia");
        let tau = 2.0 * std::f64::consts::PI;
        let heave =
            tau * (m / (g * scalar(&v, "water_density") * scalar(&v, "waterplane_area"))).sqrt();
        let roll = tau * (t.x / (m * g * scalar(&v, "gm_transverse"))).sqrt();
        let pitch = tau * (t.y / (m * g * scalar(&v, "gm_longitudinal"))).sqrt();
        let mut want = vec![heave, roll, pitch];
        want.sort_by(|a, b| a.total_cmp(b));
        let got = sys.natural_periods(&Matrix3::identity(), false);
        assert_eq!(got.len(), 3, "{got:?}");
        for (a, b) in got.iter().zip(&want) {
            assert!((a - b).abs() <= 1e-9 * b, "{got:?} vs {want:?}");
        }
        assert!(
            (pitch - 4.079).abs() < 1e-3
                && (heave - 4.249).abs() < 1e-3
                && (roll - 9.21).abs() < 1e-2
        );
        // The controller adds the surge, sway and yaw loops (strongly damped: no faster mode).
        let on = sys.natural_periods(&Matrix3::identity(), true);
        assert!(
            on.len() >= 3 && (on[0] - pitch).abs() <= 1e-9 * pitch,
            "{on:?}"
        );
    }

    fn random_state(v: &Vessel, seed: [f64; 8]) -> VesselState {
        let mut s = v.state_from(
            Vector3::new(seed[0] * 0.3, seed[1] * 0.2, seed[2] * 3.0),
            Vector3::new(700.0 + seed[3] * 100.0, seed[4] * 50.0, seed[5] * 2.0),
            Vector3::new(seed[6], -seed[7], 0.3 * seed[0]),
            Vector3::new(0.02 * seed[1], -0.01 * seed[2], 0.03 * seed[3]),
        );
        s.phi_th = Vector3::new(seed[4], seed[5], seed[6]) * 10.0;
        s.phi_x = Vector3::new(seed[7], seed[0], seed[1]) * 100.0;
        s.mu += Vector3::new(seed[2], -seed[3], 0.0) * 1e6; // off the exact-solution manifold
        s
    }

    /// The paper's vessel with a constant external load.
    fn with_external(frame: &str) -> Vessel {
        let text = format!(
            "{}\n[external]\nforce = [2e5, -1e5, 3e4]\nmoment = [1e6, 0, -2e6]\npoint = [-40, 5, 3]\nframe = \"{frame}\"\n",
            super::super::PAPER_VESSEL_TOML
        );
        Vessel::from_toml_str(&text).unwrap()
    }

    /// The probe's controller wrench is the sum of the controller's accounts in
    /// `account_wrenches` (every component assembled), for the paper's controller and for the
    /// pipe-lay vessel, whose controller delivers through thrusters beside a pipe.
    #[test]
    fn the_probe_is_the_wrench_of_the_controllers_accounts() {
        let scenario: toml::Table =
            include_str!("../../../../../python/src/phsplit/scenarios/pipelay.toml")
                .parse()
                .unwrap();
        let mut table: toml::Table = include_str!("../../../data/paper_vessel.toml")
            .parse()
            .unwrap();
        for k in ["setpoint", "pipe", "thrusters"] {
            table.insert(k.into(), scenario[k].clone());
        }
        let pipelay = Vessel::from_table(table).unwrap();
        for v in [Vessel::paper(), pipelay] {
            let sys = VesselSystem::new(&v, Some(5.0));
            let mut s = v.initial_state();
            for (i, t) in [0.0, 7.0, 700.0, 1800.0].into_iter().enumerate() {
                let k = i as f64 + 1.0;
                s.p += Vector3::new(1e5, -2e5, 3e4) * k;
                s.m += Vector3::new(-1e6, 2e6, 5e6) * k;
                s.x += Vector3::new(3.0, -2.0, 0.1) * k;
                s.phi_x += Vector3::new(10.0, 5.0, -1.0);
                s.phi_th += Vector3::new(0.1, -0.1, 0.2);
                let (f, m) = sys.control_wrench(&s, t);
                let w = sys.account_wrenches(&s, t, sys.control_on(t));
                let (mut fw, mut mw) = (Vector3::zeros(), Vector3::zeros());
                let mut n = 0;
                for (a, (fa, ma)) in sys.accounts().iter().zip(&w) {
                    // The controller's accounts by name, as the PID and thrusters declare them.
                    if ["control", "control_damping", "thrusters"].contains(&a.name) {
                        fw += fa;
                        mw += ma;
                        n += 1;
                    }
                }
                assert!(n >= 1);
                assert!(t < 5.0 || fw.norm() > 0.0, "the controller acts at {t}");
                assert!((f - fw).norm() <= 1e-12 * fw.norm().max(1.0), "{f} vs {fw}");
                assert!((m - mw).norm() <= 1e-12 * mw.norm().max(1.0), "{m} vs {mw}");
            }
        }
    }

    #[test]
    fn paper_vessel_loads_with_its_components() {
        let v = Vessel::paper();
        assert_eq!(v.body.mass, 6.3622085e6);
        assert_eq!(
            param(&v, "control", "position_reference"),
            Vector3::new(780.0, 20.0, 0.0)
        );
        let s = v.initial_state();
        assert!((s.euler() - Vector3::new(0.05, -0.02, 0.10)).norm() < 1e-15);
        assert!(v.energy(&s) > 0.0);
        let names: Vec<_> = v.forces.iter().map(|f| f.name()).collect();
        assert_eq!(names, ["damping", "restoring", "pid"]);
        let sys = VesselSystem::new(&v, Some(0.0));
        let acc: Vec<_> = sys.accounts().iter().map(|a| a.name).collect();
        assert_eq!(acc, ["damping", "control", "control_damping"]);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn split_fields_add_up_and_s2_is_exact(seed in proptest::array::uniform8(-1.0f64..1.0), on in any::<bool>()) {
            let v = Vessel::paper();
            let sys = VesselSystem::new(&v, Some(0.0));
            let s = random_state(&v, seed);
            // The full field (eq. 39), written out independently here.
            let full = sys.vector_field(&s, 0.0, on).to_vector();
            let mv = v.body.mass;
            let vel = s.p / mv;
            let inertia = param(&v, "vessel", "inertia");
            let w = s.m.component_div(&inertia);
            let q3 = s.q.transpose() * Vector3::z();
            let th = s.euler();
            let wm = so3::pi_e_inv(&th) * s.q;
            let k = |key: &str| if on { Matrix3::from_diagonal(&param(&v, "control", key)) } else { Matrix3::zeros() };
            let xr = param(&v, "control", "position_reference");
            let mut te = th - param(&v, "control", "euler_reference");
            // the heading error the short way round (pid.rs)
            te.z = (te.z + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI;
            let tau_t = -s.q.transpose() * (k("kp_translational") * (s.x - xr) + k("kd_translational") * s.q * vel + k("ki_translational") * s.phi_x);
            let tau_r = -wm.transpose() * (k("kp_rotational") * te + k("kd_rotational") * wm * w + k("ki_rotational") * s.phi_th);
            let grav = scalar(&v, "gravity");
            let heave = grav * scalar(&v, "water_density") * scalar(&v, "waterplane_area");
            let g = Vector3::new(mv * grav * scalar(&v, "gm_longitudinal"), mv * grav * scalar(&v, "gm_transverse"), 0.0);
            let lx = Vector3::new(0.0, 0.0, heave * s.x.z);
            let expect = VesselState {
                p: -w.cross(&s.p) - (param(&v, "vessel", "damping_translational").component_mul(&vel) + s.q.transpose() * lx - tau_t),
                m: -w.cross(&s.m) - (param(&v, "vessel", "damping_rotational").component_mul(&w) + s.mu.cross(&q3) - tau_r),
                q: s.q * so3::hat(&w),
                mu: -g.component_mul(&w.cross(&q3)),
                x: s.q * vel,
                phi_th: if on { te } else { Vector3::zeros() },
                phi_x: if on { s.x - xr } else { Vector3::zeros() },
                act: Default::default(),
                own: Vec::new(),
            }.to_vector();
            let scale = expect.norm();
            prop_assert!((full - expect).norm() <= 1e-13 * scale, "field mismatch {}", (full - expect).norm() / scale);
            // The halves of the split add up to the full field.
            let sum = sys.split_field(&s, 0.0, on, Flow::S1).to_vector() + sys.split_field(&s, 0.0, on, Flow::S2).to_vector();
            prop_assert!((sum - full).norm() <= 1e-14 * scale, "S1 + S2 != full: {}", (sum - full).norm() / scale);
            // The exact S2 flow has the S2 field as its derivative at h = 0 (centred difference).
            let e = 1e-3;
            let (mut a, mut b) = (s.clone(), s.clone());
            sys.flow_s2(&mut a, e, 0.0, on, false, 1);
            sys.flow_s2(&mut b, -e, 0.0, on, false, 1);
            let fd = (a.to_vector() - b.to_vector()) / (2.0 * e);
            let f2 = sys.split_field(&s, 0.0, on, Flow::S2).to_vector();
            prop_assert!((fd - f2).norm() <= 1e-6 * f2.norm().max(1.0), "S2 flow vs field {}", (fd - f2).norm() / f2.norm());
            // The power per account, written out: damping and D terms dissipate, P and I supply.
            let p = sys.power(&s, 0.0, on);
            let dt = Matrix3::from_diagonal(&param(&v, "vessel", "damping_translational"));
            let dr = Matrix3::from_diagonal(&param(&v, "vessel", "damping_rotational"));
            let expect_p = [
                vel.dot(&(dt * vel)) + w.dot(&(dr * w)),
                vel.dot(&(-s.q.transpose() * (k("kp_translational") * (s.x - xr) + k("ki_translational") * s.phi_x)))
                    + w.dot(&(-wm.transpose() * (k("kp_rotational") * te + k("ki_rotational") * s.phi_th))),
                vel.dot(&(s.q.transpose() * k("kd_translational") * s.q * vel)) + w.dot(&(wm.transpose() * k("kd_rotational") * wm * w)),
            ];
            // The P and I power is a sum of terms that can cancel to a small total: its
            // round-off is relative to the terms, not to the total.
            let gross = [
                expect_p[0].abs(),
                vel.abs().dot(&(s.q.transpose() * (k("kp_translational") * (s.x - xr) + k("ki_translational") * s.phi_x)).abs())
                    + w.abs().dot(&(wm.transpose() * (k("kp_rotational") * te + k("ki_rotational") * s.phi_th)).abs()),
                expect_p[2].abs(),
            ];
            for (i, e) in expect_p.iter().enumerate() {
                prop_assert!((p.get(i) - e).abs() <= 1e-12 * gross[i].max(1.0), "account {i}: {} vs {e}", p.get(i));
            }
        }

        #[test]
        fn s2_ledger_balances_exactly(seed in proptest::array::uniform8(-1.0f64..1.0), h in 0.01f64..50.0,
                                      variant in 0usize..4, external in any::<bool>()) {
            let v = if external { with_external("spatial") } else { Vessel::paper() };
            // exact, and Gauss with 1, 2, 3 stages
            let sys = match variant {
                0 => VesselSystem::new(&v, Some(0.0)),
                _ => VesselSystem::new(&v, Some(0.0)).with_linear_flow(LinearFlow::Gauss),
            };
            let mut s = random_state(&v, seed);
            s.mu.z = 0.0;
            let h0 = v.energy(&s);
            let w = sys.flow_s2(&mut s, h, 0.0, true, true, variant.max(1));
            let dh = v.energy(&s) - h0;
            let acc = sys.accounts();
            let sup = w.total(acc, AccountKind::Supplied);
            let dis = w.total(acc, AccountKind::Dissipated);
            let scale = h0.abs() + w.iter().map(|x| x.abs()).sum::<f64>();
            for (a, x) in acc.iter().zip(w.iter()) {
                if a.kind == AccountKind::Dissipated {
                    prop_assert!(x >= 0.0, "{} dissipated {x}", a.name);
                }
            }
            prop_assert!((dh - (sup - dis)).abs() <= 1e-11 * scale,
                "dH {dh} supplied {sup} dissipated {dis}");
        }
    }

    /// The exact flow S2 (Taylor sums on the balanced blocks, each account's energy from the
    /// momentum rows of the Hilbert Gramian) against the unbalanced system's matrix exponential
    /// and Van Loan Gramian (nalgebra's Padé approximant on the 10×10 and 20×20 matrices), at
    /// attitudes far from the upright one where the balance was computed, with the controller
    /// on and off, for steps from one Taylor piece to the Padé fallback and backwards.
    #[test]
    fn the_exact_flow_s2_is_the_matrix_exponential_with_the_van_loan_ledger() {
        use crate::flows::affine;
        use nalgebra::{SMatrix, SVector};
        let v = with_external("body");
        let sys = VesselSystem::new(&v, Some(0.0));
        let minv = sys.minv();
        let seeds = [
            [0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.4, -0.1],
            [-0.9, 0.8, -1.0, 0.8, 0.3, -0.5, 0.9, 0.2],
            [1.0, 1.0, 0.9, -1.0, 1.0, 1.0, -1.0, 1.0],
        ];
        // Three random states, and one at rest 1e-12 m from the set point, where a constant
        // load dwarfs the state (a review found the fallback's exponential losing the dynamics
        // there when the constant coordinate was scaled to the state: 2e-2 relative, h = 50 s).
        let xr = param(&v, "control", "position_reference");
        let near_rest = v.state_from(
            Vector3::new(0.05, -0.02, 0.1),
            xr + Vector3::new(1e-12, 0.0, 0.0),
            Vector3::zeros(),
            Vector3::zeros(),
        );
        let states: Vec<VesselState> = seeds
            .iter()
            .map(|seed| random_state(&v, *seed))
            .chain([near_rest])
            .collect();
        for s0 in states {
            let seed = s0.x;
            for on in [true, false] {
                for h in [0.01, 0.5, 3.0, -0.25, 20.0, 40.0] {
                    let fr = sys.frozen(&s0, on);
                    let b = sys.s2_of(&fr, true);
                    let z0 = sys.blocks_of(&s0);
                    let (z1, work) = sys.exact_s2(&b, &z0, h, on);
                    let mut expected = vec![0.0; sys.accounts().len()];
                    for k in 0..2 {
                        // The structural balance only (diagonal, powers of two: exact), so
                        // that the references see entries of comparable size.
                        let d = s2::balance(&b.sys[k], &minv[k]);
                        let aa = b.sys[k].augmented();
                        let abar = SMatrix::<f64, 10, 10>::from_fn(|i, j| aa[(i, j)] * d[j] / d[i]);
                        let mut z = SVector::<f64, 10>::zeros();
                        for i in 0..3 {
                            z.fixed_rows_mut::<3>(3 * i).copy_from(&z0[k][i]);
                        }
                        z[9] = 1.0;
                        let z = z.component_div(&d);
                        let (_, gram) = affine::flow_and_gramian::<10, 20>(&abar, &z, h);
                        let gram =
                            SMatrix::<f64, 10, 10>::from_fn(|i, j| gram[(i, j)] * d[i] * d[j]);
                        // The flow against the double-double Taylor series (32 digits).
                        let r = affine::tests::reference_action(&abar, &z, h);
                        let r = SVector::<f64, 10>::from_fn(|i, _| r[i].hi * d[i]);
                        for i in 0..3 {
                            let got = z1[k][i];
                            let want = r.fixed_rows::<3>(3 * i).into_owned();
                            let err = (got - want).norm();
                            // h = 40 s is the Padé fallback: accurate in norm to 1e-12.
                            let tol = if h.abs() > 30.0 { 1e-12 } else { 1e-13 };
                            assert!(
                                err <= tol * want.norm().max(1e-300),
                                "seed {seed:?} on {on} h {h} system {k} part {i}: {got} vs {want}"
                            );
                        }
                        for (acc, rows) in b.booked.as_ref().unwrap().iter().enumerate() {
                            let f = &rows[k];
                            let mut rr = SMatrix::<f64, 3, 10>::zeros();
                            rr.fixed_view_mut::<3, 3>(0, 0)
                                .copy_from(&(f.fnu[k] * Matrix3::from_diagonal(&minv[k])));
                            rr.fixed_view_mut::<3, 3>(0, 3).copy_from(&f.fv);
                            rr.fixed_view_mut::<3, 3>(0, 6).copy_from(&f.fw);
                            rr.fixed_view_mut::<3, 1>(0, 9).copy_from(&f.c);
                            let mut p = SMatrix::<f64, 10, 10>::zeros();
                            for i in 0..3 {
                                for j in 0..10 {
                                    p[(i, j)] += 0.5 * minv[k][i] * rr[(i, j)];
                                    p[(j, i)] += 0.5 * minv[k][i] * rr[(i, j)];
                                }
                            }
                            expected[acc] += sys.sign(acc) * affine::trace_product(&p, &gram);
                        }
                    }
                    let size: f64 = expected.iter().map(|x| x.abs()).sum::<f64>() + v.energy(&s0);
                    for (acc, (got, want)) in work.iter().zip(&expected).enumerate() {
                        assert!(
                            (got - want).abs() <= 1e-10 * size,
                            "seed {seed:?} on {on} h {h} account {}: {got} vs {want}",
                            sys.accounts()[acc].name
                        );
                    }
                }
            }
        }
    }

    /// The forced collocation (dense stage solve, forcing iterated) against the structured
    /// affine one: a set-point table whose only row is the fixed set point adds a forcing that
    /// is identically zero, so both must give the same flow and ledger to round-off.
    #[test]
    fn forced_collocation_with_zero_forcing_is_the_affine_collocation() {
        let base = Vessel::paper();
        let xr = param(&base, "control", "position_reference");
        let er = param(&base, "control", "euler_reference");
        let text = format!(
            "{}\n[setpoint]\nnatural_frequency = 0.1\ntimes = [0.0]\npositions = [[{}, {}, {}]]\nheadings = [{}]\n",
            super::super::PAPER_VESSEL_TOML, xr.x, xr.y, xr.z, er.z
        );
        let v = Vessel::from_toml_str(&text).unwrap();
        let forced = VesselSystem::new(&v, Some(0.0));
        assert!(forced.is_forced() && forced.s2_solver() == LinearFlow::Gauss);
        let plain = VesselSystem::new(&base, Some(0.0)).with_linear_flow(LinearFlow::Gauss);
        for stages in 1..=3 {
            let s0 = random_state(&base, [0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.4, -0.1]);
            let (mut a, mut b) = (s0.clone(), s0);
            let wa = forced.flow_s2(&mut a, 0.7, 3.0, true, true, stages);
            let wb = plain.flow_s2(&mut b, 0.7, 3.0, true, true, stages);
            let (va, vb) = (a.to_vector(), b.to_vector());
            assert!(
                (va - vb).norm() <= 1e-12 * vb.norm(),
                "{stages}: {}",
                (va - vb).norm() / vb.norm()
            );
            for k in 0..3 {
                assert!(
                    (wa.get(k) - wb.get(k)).abs() <= 1e-9 * wb.get(k).abs().max(1.0),
                    "{k}: {wa:?} {wb:?}"
                );
            }
        }
    }

    #[test]
    fn s1_conserves_energy() {
        let v = Vessel::paper();
        let sys = VesselSystem::new(&v, None);
        let mut s = random_state(&v, [0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.4, -0.1]);
        let h0 = v.energy(&s);
        for _ in 0..100 {
            sys.flow_s1(&mut s, 0.7, MagnusOrder::Four);
        }
        assert!((v.energy(&s) - h0).abs() < 1e-13 * h0);
        assert!(so3::orthogonality_defect(&s.q) < 1e-13);
    }

    #[test]
    fn external_load_is_the_stated_force_moment_and_power() {
        for frame in ["body", "spatial"] {
            let v = with_external(frame);
            let sys = VesselSystem::new(&v, None);
            let s = random_state(&v, [0.2, -0.4, 0.6, 0.3, -0.5, 0.1, 0.7, -0.3]);
            let base = Vessel::paper();
            let d = sys.vector_field(&s, 0.0, false).to_vector()
                - VesselSystem::new(&base, None)
                    .vector_field(&s, 0.0, false)
                    .to_vector();
            let (f, m) = (Vector3::new(2e5, -1e5, 3e4), Vector3::new(1e6, 0.0, -2e6));
            let r = Vector3::new(-40.0, 5.0, 3.0);
            let (fb, mb) = if frame == "body" {
                (f, m)
            } else {
                (s.q.transpose() * f, s.q.transpose() * m)
            };
            // The load changes only the momentum rates, by the body force and its moment.
            assert!((d.fixed_rows::<3>(0) - fb).norm() < 1e-9 * fb.norm());
            assert!((d.fixed_rows::<3>(3) - (mb + r.cross(&fb))).norm() < 1e-9 * mb.norm());
            assert!(d.rows(6, 21).norm() < 1e-9);
            let k = sys
                .accounts()
                .iter()
                .position(|a| a.name == "external")
                .unwrap();
            let vel = s.p / v.body.mass;
            let w = s.m.component_div(&v.body.inertia);
            let expect = vel.dot(&fb) + w.dot(&(mb + r.cross(&fb)));
            assert!((sys.power(&s, 0.0, false).get(k) - expect).abs() < 1e-12 * expect.abs());
            let ext = v.force("external").unwrap();
            assert!(format!("{ext:?}").contains("External"));
            let _ = External {
                force: f,
                moment: m,
                point: r,
                frame: Frame::Body,
            };
        }
    }

    /// The paper's vessel with quadratic damping and, optionally, a current.
    fn with_quadratic(current: bool) -> Vessel {
        let mut text = format!(
            "{}\n[damping_quadratic]\ncoefficients = [4e3, 1.75e5, 2e5, 3e8, 4e9, 2e10]\n",
            super::super::PAPER_VESSEL_TOML
        );
        if current {
            text.push_str("[current]\nvelocity = [0.6, -0.8, 0.0]\n");
        }
        Vessel::from_toml_str(&text).unwrap()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]
        /// The quadratic damping's force, written out here: `−C|ν_r|ν_r` on the relative
        /// velocity (translation; the current's part booked to the current) and `−C|ω|ω`;
        /// flow S2's ledger closes exactly at any step, and the dissipation is ≥ 0.
        #[test]
        fn quadratic_damping_is_its_force_and_the_ledger_closes(
            seed in proptest::array::uniform8(-1.0f64..1.0), h in 0.01f64..10.0,
            current in any::<bool>(), stages in 1usize..4) {
            let v = with_quadratic(current);
            let base_text = if current {
                format!("{}\n[current]\nvelocity = [0.6, -0.8, 0.0]\n", super::super::PAPER_VESSEL_TOML)
            } else {
                super::super::PAPER_VESSEL_TOML.to_string()
            };
            let base = Vessel::from_toml_str(&base_text).unwrap();
            let mut s = random_state(&v, seed);
            s.mu.z = 0.0;
            let sys = VesselSystem::new(&v, Some(0.0));
            let d = sys.vector_field(&s, 0.0, true).to_vector()
                - VesselSystem::new(&base, Some(0.0)).vector_field(&s, 0.0, true).to_vector();
            let c_t = Vector3::new(4e3, 1.75e5, 2e5);
            let c_r = Vector3::new(3e8, 4e9, 2e10);
            let vel = s.p / v.body.mass;
            let w = s.m.component_div(&v.body.inertia);
            let vc = if current { s.q.transpose() * Vector3::new(0.6, -0.8, 0.0) } else { Vector3::zeros() };
            let vr = vel - vc;
            let ft = -c_t.component_mul(&vr.abs()).component_mul(&vr);
            let mr = -c_r.component_mul(&w.abs()).component_mul(&w);
            prop_assert!((d.fixed_rows::<3>(0) - ft).norm() <= 1e-9 * ft.norm().max(1.0), "{} vs {}", d.fixed_rows::<3>(0), ft);
            prop_assert!((d.fixed_rows::<3>(3) - mr).norm() <= 1e-9 * mr.norm().max(1.0));
            prop_assert!(d.rows(6, 21).norm() == 0.0);
            // The split's S2 at a long step: the ledger closes, the dissipation is >= 0.
            let lin = sys.clone().with_linear_flow(LinearFlow::Gauss);
            let h0 = v.energy(&s);
            let mut s1 = s;
            let work = lin.flow_s2(&mut s1, h, 0.0, true, true, stages);
            prop_assert!(s1.is_finite(), "h = {h}");
            let dh = v.energy(&s1) - h0;
            let acc = sys.accounts();
            let sup = work.total(acc, AccountKind::Supplied);
            let dis = work.total(acc, AccountKind::Dissipated);
            let k = acc.iter().position(|a| a.name == "damping_quadratic").unwrap();
            prop_assert!(work.get(k) >= 0.0, "{}", work.get(k));
            let scale = h0.abs() + work.iter().map(|x| x.abs()).sum::<f64>();
            prop_assert!((dh - (sup - dis)).abs() <= 1e-11 * scale, "dH {dh} vs {}", sup - dis);
        }
    }

    /// `gauss4` and `gauss6` collocate S2 with at least the composition's stages, and refuse a
    /// composition of a higher order than theirs (it would lose its order).
    #[test]
    fn a_fixed_order_s2_takes_at_least_the_methods_stages() {
        use crate::solve::SplitModel;
        for (lf, want) in [
            (LinearFlow::Gauss, [1, 1, 2, 3]),
            (LinearFlow::Gauss4, [2, 2, 2, 3]),
            (LinearFlow::Gauss6, [3, 3, 3, 3]),
        ] {
            let got = [1, 2, 4, 6].map(|order| lf.stages(order));
            assert_eq!(got, want, "{}", lf.name());
        }
        let v = Vessel::paper();
        let sys = VesselSystem::new(&v, Some(0.0)).with_linear_flow(LinearFlow::Gauss4);
        assert!(sys.supports_order(4).is_ok());
        let e = sys.supports_order(6).unwrap_err().to_string();
        assert!(e.contains("gauss4") && e.contains("order 6"), "{e}");
        let sys = VesselSystem::new(&v, Some(0.0)).with_linear_flow(LinearFlow::Gauss6);
        assert!(sys.supports_order(6).is_ok());
        for lf in LinearFlow::ALL {
            assert_eq!(lf.name().parse::<LinearFlow>().unwrap(), lf);
        }
    }

    /// The coupled flow S2 (one 18-dimensional system) where nothing couples is the block
    /// systems' flow: the paper's vessel through both paths, exact and Gauss with 1–3 stages,
    /// the flow and every account to round-off.
    #[test]
    fn the_coupled_flow_s2_is_the_block_flow_where_nothing_couples() {
        let v = Vessel::paper();
        for (lf, stages) in [
            (LinearFlow::Exact, 1),
            (LinearFlow::Gauss, 1),
            (LinearFlow::Gauss, 2),
            (LinearFlow::Gauss, 3),
        ] {
            let sys = VesselSystem::new(&v, Some(0.0)).with_linear_flow(lf);
            for (seed, h) in [
                ([0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.4, -0.1], 0.7),
                ([-0.6, 0.4, -0.1, 0.8, 0.3, -0.5, 0.9, 0.2], 25.0),
            ] {
                let s0 = random_state(&v, seed);
                let fr = sys.frozen(&s0, true);
                let mut b = sys.s2_of(&fr, true);
                assert!(b.cross.is_none());
                let z0 = sys.blocks_of(&s0);
                let (za, wa) = match lf {
                    LinearFlow::Exact => sys.exact_s2(&b, &z0, h, true),
                    _ => sys.gauss_s2(&b, &z0, h, stages),
                };
                b.cross = Some([[Matrix3::zeros(); 3]; 2]);
                let (zb, wb) = sys.coupled_s2(&fr, &b, &z0, h, 0.0, stages);
                for k in 0..2 {
                    for i in 0..3 {
                        let d = (za[k][i] - zb[k][i]).norm();
                        assert!(
                            d <= 1e-12 * za[k][i].norm().max(1e-300),
                            "{lf:?} {stages} {k} {i}: {d}"
                        );
                    }
                }
                let scale = wa.iter().map(|x| x.abs()).sum::<f64>();
                for acc in 0..sys.accounts().len() {
                    assert!(
                        (wa.get(acc) - wb.get(acc)).abs() <= 1e-11 * scale,
                        "{lf:?} {stages} account {acc}: {} vs {}",
                        wa.get(acc),
                        wb.get(acc)
                    );
                }
            }
        }
    }

    /// The offshore supply vessel (general `M`: added mass with couplings, CG off the origin):
    /// flow S2 is coupled, its ledger closes exactly for the exact flow and for Gauss collocation
    /// (with the cross-flow drag's forcing) at short and long steps, and flow S1 (Kirchhoff's
    /// equations by Gauss collocation) keeps `H` to round-off over 10^5 steps of 1 s.
    #[test]
    fn a_general_vessel_keeps_its_ledger_and_flow_s1_its_energy() {
        let v = Vessel::preset("osv").unwrap();
        assert!(!v.body.is_diagonal());
        let lin = {
            // without the cross-flow drag, S2 is affine: its exact flow applies
            let mut t = v.params.clone();
            t.remove("crossflow_drag");
            Vessel::from_table(t).unwrap()
        };
        for (vessel, lf) in [
            (&lin, LinearFlow::Exact),
            (&lin, LinearFlow::Gauss),
            (&v, LinearFlow::Gauss),
        ] {
            let sys = VesselSystem::new(vessel, Some(0.0)).with_linear_flow(lf);
            for (seed, h, stages) in [
                ([0.3, -0.2, 0.5, 0.1, -0.7, 0.2, 0.4, -0.1], 0.5, 1),
                ([-0.6, 0.4, -0.1, 0.8, 0.3, -0.5, 0.9, 0.2], 20.0, 2),
                ([0.1, 0.9, -0.4, -0.2, 0.6, 0.3, -0.8, 0.5], 5.0, 3),
            ] {
                let mut s = vessel.state_from(
                    Vector3::new(seed[0] * 0.1, seed[1] * 0.05, seed[2]),
                    Vector3::new(seed[3] * 30.0, seed[4] * 30.0, seed[5]),
                    Vector3::new(seed[6], seed[7], 0.2 * seed[0]),
                    Vector3::new(0.02 * seed[1], -0.01 * seed[2], 0.03 * seed[3]),
                );
                s.phi_x = Vector3::new(seed[7], seed[0], 0.0) * 50.0;
                let b = sys.s2_of(&sys.frozen(&s, true), false);
                assert!(b.cross.is_some());
                let h0 = vessel.energy(&s);
                let w = sys.flow_s2(&mut s, h, 0.0, true, true, stages);
                assert!(s.is_finite(), "{lf:?} h = {h}");
                let acc = sys.accounts();
                let sup = w.total(acc, AccountKind::Supplied);
                let dis = w.total(acc, AccountKind::Dissipated);
                for (a, x) in acc.iter().zip(w.iter()) {
                    if a.kind == AccountKind::Dissipated {
                        assert!(x >= 0.0, "{} dissipated {x}", a.name);
                    }
                }
                let dh = vessel.energy(&s) - h0;
                let scale = h0.abs() + w.iter().map(|x| x.abs()).sum::<f64>();
                assert!(
                    (dh - (sup - dis)).abs() <= 1e-11 * scale,
                    "{lf:?} h {h}: dH {dh} vs {}",
                    sup - dis
                );
            }
        }
        let sys = VesselSystem::new(&v, None);
        let mut s = v.state_from(
            Vector3::new(0.05, -0.02, 0.3),
            Vector3::zeros(),
            Vector3::new(2.0, -0.5, 0.1),
            Vector3::new(0.01, -0.004, 0.02),
        );
        let h0 = v.body.kinetic_energy(&s);
        let mut worst: f64 = 0.0;
        for _ in 0..100_000 {
            sys.flow_s1(&mut s, 1.0, MagnusOrder::Four);
            worst = worst.max((v.body.kinetic_energy(&s) - h0).abs() / h0);
        }
        assert!(worst <= 1e-13, "H drifts by {worst:e}");
        assert!(so3::orthogonality_defect(&s.q) < 1e-12);
    }

    /// The restoring with the heave spring at the centre of flotation (the OSV's `x_F = −0.5 m`):
    /// the initial state is on the invariant `mu = G q3 − k z e1`, the projection brings a state
    /// that left it back (the attitude turned, `mu` and `z` kept) and leaves `H` as it was.
    /// The OSV, and the OSV with its centre of flotation also 1.5 m off the centreline (a hull
    /// that is not port–starboard symmetric).
    fn flotation_vessels() -> Vec<Vessel> {
        let osv = Vessel::preset("osv").unwrap();
        let mut t = osv.params.clone();
        t["vessel"]
            .as_table_mut()
            .unwrap()
            .insert("flotation_center_y".into(), toml::Value::Float(1.5));
        vec![osv, Vessel::from_table(t).unwrap()]
    }

    #[test]
    fn the_flotation_centre_keeps_its_invariant_and_projection() {
        for v in flotation_vessels() {
            let r = v.force("restoring").unwrap();
            let sys = VesselSystem::new(&v, Some(0.0));
            let mut s = v.state_from(
                Vector3::new(0.04, -0.03, 0.2),
                Vector3::new(3.0, -2.0, 0.4),
                Vector3::zeros(),
                Vector3::zeros(),
            );
            // mu from its definition, written out: G' = mv g diag(GM_L, GM_T, 0) + c r_F r_Fᵀ,
            // mu = G' q3 + z c r_F, r_F = (x_F, y_F, 0).
            let (m, gr) = (scalar(&v, "mass"), scalar(&v, "gravity"));
            let c = gr * scalar(&v, "water_density") * scalar(&v, "waterplane_area");
            let xf = scalar(&v, "flotation_center_x");
            let yf = v.params["vessel"]
                .get("flotation_center_y")
                .map_or(0.0, |x| x.as_float().unwrap());
            let (gl, gt) = (
                m * gr * scalar(&v, "gm_longitudinal"),
                m * gr * scalar(&v, "gm_transverse"),
            );
            let want = |s: &VesselState| {
                let q3 = s.q.transpose() * Vector3::z();
                let zf = s.x.z + xf * q3.x + yf * q3.y;
                Vector3::new(gl * q3.x + c * xf * zf, gt * q3.y + c * yf * zf, 0.0)
            };
            assert!((s.mu - want(&s)).norm() <= 1e-12 * s.mu.norm());
            // Flow S1 turns Q without mu: off the invariant; the projection restores it.
            sys.flow_s1(&mut s, 2.0, MagnusOrder::Four);
            s.m += Vector3::new(1e7, -2e7, 3e7);
            sys.flow_s1(&mut s, 3.0, MagnusOrder::Four);
            let off = (s.mu - want(&s)).norm() / s.mu.norm();
            assert!(off > 1e-6, "{off}");
            let h0 = v.energy(&s);
            r.project(&mut s);
            assert!(
                (s.mu - want(&s)).norm() <= 1e-12 * s.mu.norm(),
                "{}",
                (s.mu - want(&s)).norm()
            );
            assert_eq!(v.energy(&s), h0);
            // The store at rest tilted: V = ½ c z_F² + ½ q3ᵀ G q3 on the invariant (with the
            // paper's G = mv g diag(GM_L, GM_T, 0) and z_F = z + x_F q3_x + y_F q3_y, the height
            // of the centre of flotation).
            let q3 = s.q.transpose() * Vector3::z();
            let zf = s.x.z + xf * q3.x + yf * q3.y;
            let v_pot = 0.5 * c * zf * zf + 0.5 * (gl * q3.x * q3.x + gt * q3.y * q3.y);
            assert!(
                (r.storage(&s) - v_pot).abs() <= 1e-12 * v_pot,
                "{} vs {v_pot}",
                r.storage(&s)
            );
        }
    }

    /// A partial rebuild (the FMU's inputs) gives the vessel a whole rebuild of the same file
    /// gives: the same components, field and normalised parameters.
    #[test]
    fn a_partial_rebuild_is_a_whole_rebuild() {
        let v = with_external("spatial");
        let mut table = v.params.clone();
        let ext = table["external"].as_table_mut().unwrap();
        ext.insert(
            "force".into(),
            toml::Value::Array(vec![1e5.into(), 2e5.into(), (-3e4).into()]),
        );
        let ctl = table["control"].as_table_mut().unwrap();
        ctl.insert(
            "position_reference".into(),
            toml::Value::Array(vec![790.0.into(), 25.0.into(), 0.0.into()]),
        );
        let part = v.with_rebuilt(table.clone(), &["external", "pid"]).unwrap();
        let whole = Vessel::from_table(table).unwrap();
        assert_eq!(part.params, whole.params);
        let names = |x: &Vessel| x.forces.iter().map(|f| f.name()).collect::<Vec<_>>();
        assert_eq!(names(&part), names(&whole));
        let s = random_state(&v, [0.2, -0.4, 0.6, 0.3, -0.5, 0.1, 0.7, -0.3]);
        let (a, b) = (
            VesselSystem::new(&part, Some(0.0)),
            VesselSystem::new(&whole, Some(0.0)),
        );
        assert_eq!(
            a.vector_field(&s, 0.0, true).to_vector(),
            b.vector_field(&s, 0.0, true).to_vector()
        );
        assert_ne!(
            a.vector_field(&s, 0.0, true).to_vector(),
            VesselSystem::new(&v, Some(0.0))
                .vector_field(&s, 0.0, true)
                .to_vector()
        );
        // A bad value in a rebuilt component is refused as in a whole build.
        let mut bad = v.params.clone();
        bad["external"].as_table_mut().unwrap().insert(
            "point".into(),
            toml::Value::Array(vec![0.0.into(), 0.0.into(), 5000.0.into()]),
        );
        let e = v.with_rebuilt(bad, &["external"]).unwrap_err().to_string();
        assert!(e.contains("external.point[2]"), "{e}");
    }

    #[test]
    fn external_table_is_validated() {
        let base = super::super::PAPER_VESSEL_TOML;
        for (extra, needle) in [
            (
                "[external]\nforce = [1, 2]\n",
                "external.force must be 3 numbers",
            ),
            (
                "[external]\nforce = [1, nan, 0]\n",
                "external.force[1] must be finite",
            ),
            (
                "[external]\nframe = \"ned\"\n",
                "external.frame must be one of 'body', 'spatial'",
            ),
            (
                "[external]\npoint = [0, 0, 5000]\n",
                "external.point[2] must lie within",
            ),
            ("[external]\nforse = [0, 0, 1]\n", "did you mean 'force'"),
            ("[externl]\nforce = [0, 0, 1]\n", "did you mean 'external'"),
        ] {
            let e = Vessel::from_toml_str(&format!("{base}\n{extra}"))
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{extra}: {e}");
        }
    }
}
