//! The vessel's forces and ports, one component a file, and their one registration
//! ([`COMPONENTS`]).
//!
//! A component owns, in its own file:
//! - its parameters and their validation (read from the vessel file through
//!   [`Params`](super::params::Params), which refuses any key no component takes);
//! - its part in flow S2, the linear flow at frozen attitude (paper eq. 41; docs/model.md §2):
//!   the generalised force it adds to the momentum rows, as an affine function of the
//!   block states, and the rows of any state it drives (`mu`, the integral states);
//! - its ledger accounts: each booked force is the work of a port (supplied) or a
//!   dissipation, and the ledger's power, exact integrals and quadratures follow from the
//!   force rows alone (see `system.rs`);
//! - any energy it stores (a part of H) and any state it initialises.
//!
//! The full vector field (eq. 39), flow S2 with its exact or collocated solution, and the
//! ledger are assembled from these contributions; nothing about a component is written
//! twice. Flow S1 (the free rigid body, eq. 40) carries no force.
//!
//! **Adding a force**: write `forces/<name>.rs` with a `build` function and a type that
//! implements [`Force`], and add one line to [`COMPONENTS`].
//!
//! **States of its own**: a component may keep states of its own (a subsystem's: a tank's
//! fluid, a filter, a line's nodes), declared by [`Force::own_states`] and evolving linearly
//! with the body velocities in flow S2 ([`Force::own_linear`], [`OwnLinear`]); their storage
//! is a part of H ([`Force::own_storage`]). The vessel lays them out after the body's 27
//! numbers, integrates them with the momenta and reports them (`port_hamiltonian.rs`).
//! States that evolve nonlinearly (a lumped-mass line's nodes) have a flow of their own
//! ([`Force::own_flow`]), passive by itself and nested in flow S2 (`pipe/lumped.rs`).
//!
//! **Forcing**: a part of a force that is not affine in the block states at frozen attitude
//! (the pipe's catenary tension as a function of the hang-off point's position), or that
//! depends on time (a moving set point), is given by [`Force::add_forcing`] instead, as a
//! value at a time and a block state. A vessel with such a part has flow S2 integrated by
//! Gauss collocation of the composition's order, with the forcing evaluated at the stages
//! and their times (docs/model.md §3.7): the ledger then books each account's power at the
//! stages with the Gauss weights, which for the quadratic storage H closes exactly.

use super::params::Params;
use super::state::{Actuators, VesselState};
use super::Body;
use crate::error::Result;
use crate::flows::collocation::{Blocks, Z3};
use crate::solve::Account;
use nalgebra::{Matrix3, Vector3};
use std::fmt::Debug;
use std::sync::Arc;

pub use forcing::Forcing;
pub use own::{Output, OwnLinear, OwnState};

pub mod anti_windup;
pub mod crossflow;
pub mod current;
pub mod damping;
pub mod damping_quadratic;
pub mod external;
mod forcing;
pub mod observer;
mod own;
pub mod pid;
pub mod pipe;
pub mod port_hamiltonian;
pub mod restoring;
pub mod roll_damping;
mod sensors;
mod setpoint;
pub mod spring;
pub mod thrusters;
pub mod waves;
pub mod wind;

/// A component's builder: reads its keys, validates them, and returns the component, or `None`
/// when the file does not ask for it (an optional component whose table is absent).
pub type Build = fn(&mut Params, &Body) -> Result<Option<Arc<dyn Force>>>;

/// The registration of every component, in the order they are assembled and booked:
/// its name, the tables of the vessel file its keys are in, and its builder.
pub const COMPONENTS: &[(&str, &[&str], Build)] = &[
    ("damping", &["vessel"], damping::build),
    (
        "damping_quadratic",
        &["damping_quadratic"],
        damping_quadratic::build,
    ),
    ("crossflow_drag", &["crossflow_drag"], crossflow::build),
    ("roll_damping", &["roll_damping"], roll_damping::build),
    ("restoring", &["vessel"], restoring::build),
    (
        "pid",
        &["control", "setpoint", "thrusters", "observer", "sensors"],
        pid::build,
    ),
    ("external", &["external"], external::build),
    ("current", &["current"], current::build),
    ("pipe", &["pipe"], pipe::build),
    ("spring", &["spring"], spring::build),
    (
        "port_hamiltonian",
        &["port_hamiltonian"],
        port_hamiltonian::build,
    ),
    ("waves", &["waves"], waves::build),
    ("wind", &["wind"], wind::build),
];

/// The two block systems of flow S2 (paper eq. 41):
/// translation in `(p, x − x_o, phi_x)`, rotation in `(m, mu, phi_th)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sys {
    Trans = 0,
    Rot = 1,
}

/// A generalised force on the momentum `u` of one block system, affine in the body velocities
/// `ν = (v_t, ω) = M⁻¹u` and in the system's other states `(v, w)`:
/// `f = F_t v_t + F_r ω + fv v + fw w + c` (body frame; N or N m), with `fnu = [F_t, F_r]`.
/// (A force on the other system's second state is added by [`S2Builder::force_from_other_v`].)
/// A force written on the velocities holds for any mass matrix: the system turns it into rows
/// on the momenta (and, where `M` or the force couples translation and rotation, into one
/// coupled system).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rows {
    pub fnu: [Matrix3<f64>; 2],
    pub fv: Matrix3<f64>,
    pub fw: Matrix3<f64>,
    pub c: Vector3<f64>,
}

impl Rows {
    pub const ZERO: Rows = Rows {
        fnu: [
            Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        ],
        fv: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        fw: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        c: Vector3::new(0.0, 0.0, 0.0),
    };
    /// A constant force.
    pub fn constant(c: Vector3<f64>) -> Self {
        Rows { c, ..Self::ZERO }
    }
    /// A force linear in the velocity of the system `of` (a damping): `f = F ν_of`.
    pub fn on_velocity(of: Sys, f: Matrix3<f64>) -> Self {
        let mut r = Self::ZERO;
        r.fnu[of as usize] = f;
        r
    }
    /// The force at the velocities `nu` and the block state `z` of its system.
    pub fn at(&self, nu: &[Vector3<f64>; 2], z: &[Vector3<f64>; 3]) -> Vector3<f64> {
        self.fnu[0] * nu[0] + self.fnu[1] * nu[1] + self.fv * z[1] + self.fw * z[2] + self.c
    }
    fn add(&mut self, o: &Rows) {
        self.fnu[0] += o.fnu[0];
        self.fnu[1] += o.fnu[1];
        self.fv += o.fv;
        self.fw += o.fw;
        self.c += o.c;
    }
}

/// What a component sees of the frozen attitude and the step.
#[derive(Debug, Clone, Copy)]
pub struct Frozen<'a> {
    /// Attitude `Q0` (body → spatial) and `Qᵀ`.
    pub q: Matrix3<f64>,
    pub qt: Matrix3<f64>,
    /// `q3 = Q0ᵀ e3`, the vertical in the body frame.
    pub q3: Vector3<f64>,
    /// The ZYX Euler angles of `Q0` (eq. 21) and `W = Pi_e(θ)⁻¹ Q0` (`θ' = W w`), computed once
    /// per sub-step for every component that needs them.
    pub euler: Vector3<f64>,
    pub w: Matrix3<f64>,
    /// The origin `x_o` of the translational block's position, `v = x − x_o` (m).
    pub origin: Vector3<f64>,
    /// Whether the controller acts on this step.
    pub control_on: bool,
    pub body: &'a Body,
    /// The body velocities `ν₀ = M⁻¹u` (linear, angular) where the sub-step starts (zero for a
    /// view at rest): a component whose force is not affine may put its linearisation there
    /// into the implicit rows and only the rest into its forcing (`damping_quadratic.rs`).
    pub velocity: [Vector3<f64>; 2],
    /// What rate-limited thrusters delivered at the end of the last step (none for other
    /// vessels, and in a view at rest).
    pub actuators: Actuators,
    /// The measurements sensors hold over the step ([`Force::held_states`]; `None` in a view
    /// at rest and for a vessel without sensors).
    pub held: Option<[f64; HELD]>,
}

/// How many numbers the sensors hold over a step (`sensors.rs`).
pub const HELD: usize = 5;

impl Frozen<'_> {
    /// The body velocities `ν = M⁻¹u` (linear, angular) at the block states `z`.
    pub fn nu(&self, z: &[Z3; 2]) -> [Vector3<f64>; 2] {
        self.body.velocity(&z[0][0], &z[1][0])
    }
}

/// Flow S2 at a frozen attitude under assembly: the two block systems, and, when the ledger
/// is kept, each account's force rows.
///
/// The components give their forces on the velocities ([`Rows`]) and the rates of their own
/// states on the velocities ([`S2Builder::rate_v`]); [`S2Builder::finish`] turns them into rows
/// on the momenta with `ν = M⁻¹u`. Where nothing couples translation and rotation (`M` of the
/// paper's form and no coupling force) the two block systems stay separate (`sys`, with
/// `cross = None`); otherwise `cross[k]` holds what system `k`'s rows take from the other
/// system's momentum, and flow S2 is one coupled system.
#[derive(Debug, Clone)]
pub struct S2Builder {
    pub sys: [Blocks; 2],
    /// Force on `u_k` per velocity `ν_j` (`[k][j]`), before [`Self::finish`].
    nu_u: [[Matrix3<f64>; 2]; 2],
    /// Rate of `v_k` per velocity `ν_j`, before [`Self::finish`].
    nu_v: [[Matrix3<f64>; 2]; 2],
    /// Force on `u_k` per the other system's second state `v_l` (the restoring's heave–pitch
    /// coupling through `mu`).
    other_v: [Matrix3<f64>; 2],
    /// After [`Self::finish`], when the systems are coupled: for each system `k`, the rows of
    /// `u_k'` and of `v_k'` on the other system's momentum, and of `u_k'` on its `v`.
    pub cross: Option<[[Matrix3<f64>; 3]; 2]>,
    /// Force rows per account and system (only with the ledger: one per account of the run).
    pub booked: Option<Vec<[Rows; 2]>>,
    /// Booked forces on one system's momentum per the other system's second state, `F v_l`
    /// (with the ledger): the account, the system acted on, `F`. Few or none (a spring at a
    /// point of the hull), so kept apart from [`Rows`] and its every account's products.
    pub cross_booked: Vec<(usize, Sys, Matrix3<f64>)>,
    /// First account of the component being assembled.
    pub(crate) base: usize,
    /// The ledger rows' allocation while the builder has no ledger ([`Self::reset`]).
    spare: Option<Vec<[Rows; 2]>>,
}

impl S2Builder {
    /// A builder booking to `accounts` accounts (`None`: without the ledger).
    pub(crate) fn new(accounts: Option<usize>) -> Self {
        let zero = Blocks {
            auu: Matrix3::zeros(),
            auv: Matrix3::zeros(),
            auw: Matrix3::zeros(),
            cu: Vector3::zeros(),
            avu: Matrix3::zeros(),
            awv: Matrix3::zeros(),
            cw: Vector3::zeros(),
        };
        Self {
            sys: [zero; 2],
            nu_u: [[Matrix3::zeros(); 2]; 2],
            nu_v: [[Matrix3::zeros(); 2]; 2],
            other_v: [Matrix3::zeros(); 2],
            cross: None,
            booked: accounts.map(|n| vec![[Rows::ZERO; 2]; n]),
            cross_booked: Vec::new(),
            base: 0,
            spare: None,
        }
    }
    /// Empty the builder for a new assembly booking to `accounts` accounts, as [`Self::new`]
    /// does, keeping the ledger's allocation.
    pub(crate) fn reset(&mut self, accounts: Option<usize>) {
        for b in &mut self.sys {
            for m in [&mut b.auu, &mut b.auv, &mut b.auw, &mut b.avu, &mut b.awv] {
                m.fill(0.0);
            }
            b.cu.fill(0.0);
            b.cw.fill(0.0);
        }
        for m in self.nu_u.iter_mut().chain(self.nu_v.iter_mut()).flatten() {
            m.fill(0.0);
        }
        for m in &mut self.other_v {
            m.fill(0.0);
        }
        self.cross = None;
        self.cross_booked.clear();
        self.base = 0;
        // The rows' allocation is kept aside while the builder has no ledger.
        let mut v = self.booked.take().or(self.spare.take()).unwrap_or_default();
        match accounts {
            Some(n) => {
                v.clear();
                v.resize(n, [Rows::ZERO; 2]);
                self.booked = Some(v);
            }
            None => self.spare = Some(v),
        }
    }
    /// Add a force on the momentum of `sys`, booked to the component's account `account`
    /// (its index in [`Force::accounts`]), or to none (`None`: a conservative exchange between
    /// stores of H, like the restoring forces).
    pub fn force(&mut self, sys: Sys, account: Option<usize>, f: &Rows) {
        let k = sys as usize;
        self.nu_u[k][0] += f.fnu[0];
        self.nu_u[k][1] += f.fnu[1];
        let b = &mut self.sys[k];
        b.auv += f.fv;
        b.auw += f.fw;
        b.cu += f.c;
        if let (Some(a), Some(book)) = (account, self.booked.as_mut()) {
            book[self.base + a][k].add(f);
        }
    }
    /// Add `r ν_of` to the rate of the second state `v` of `sys` (the position's kinematics,
    /// the restoring variable `mu`).
    pub fn rate_v(&mut self, sys: Sys, of: Sys, r: &Matrix3<f64>) {
        self.nu_v[sys as usize][of as usize] += r;
    }
    /// Add a force `r v_l` on the momentum of `sys` from the second state `v_l` of the other
    /// system (translation: `x − x_o`; rotation: `mu`), booked to the component's account
    /// `account`, or to none (`None`: a conservative exchange between stores of H, like the
    /// restoring's heave–pitch coupling). It couples the systems: flow S2 is then one coupled
    /// affine system, exact or collocated, and a booked force's power is exact along it like any
    /// row's (the spring's moment from the position, `spring.rs`).
    pub fn force_from_other_v(&mut self, sys: Sys, account: Option<usize>, r: &Matrix3<f64>) {
        self.other_v[sys as usize] += r;
        if let (Some(a), Some(_)) = (account, self.booked.as_ref()) {
            self.cross_booked.push((self.base + a, sys, *r));
        }
    }
    /// The booked forces on the other system's second state at the block states `z`, added to
    /// each account's force `f[account][system]`.
    pub fn add_cross_booked(&self, z: &[Z3; 2], f: &mut [[Vector3<f64>; 2]]) {
        for (a, sys, r) in &self.cross_booked {
            let k = *sys as usize;
            f[*a][k] += r * z[1 - k][1];
        }
    }
    /// The block system `sys`, to add the rows of the integral states a component drives
    /// (`w' = A_wv v + c_w`).
    pub fn rows(&mut self, sys: Sys) -> &mut Blocks {
        &mut self.sys[sys as usize]
    }
    /// Turn the rows on the velocities into rows on the momenta, `ν = M⁻¹u` with the blocks
    /// `minv[j][l]` of `M⁻¹`; decide whether the systems are coupled.
    pub(crate) fn finish(&mut self, minv: &[[Matrix3<f64>; 2]; 2], diagonal: bool) {
        let nonzero = |m: &Matrix3<f64>| m.iter().any(|x| *x != 0.0);
        let crossing = (0..2).any(|k| {
            nonzero(&self.nu_u[k][1 - k])
                || nonzero(&self.nu_v[k][1 - k])
                || nonzero(&self.other_v[k])
        });
        if diagonal && !crossing {
            // `M⁻¹` diagonal and nothing coupling: each system's rows scale by its own diagonal
            // (the numbers of the general products below, without the products by zero blocks).
            for k in 0..2 {
                let d = minv[k][k].diagonal();
                let cols = |m: &Matrix3<f64>| Matrix3::from_fn(|i, j| m[(i, j)] * d[j]);
                self.sys[k].auu = cols(&self.nu_u[k][k]);
                self.sys[k].avu = cols(&self.nu_v[k][k]);
            }
            self.cross = None;
            return;
        }
        let on_u = |r: &[Matrix3<f64>; 2], l: usize| r[0] * minv[0][l] + r[1] * minv[1][l];
        let mut cross = [[Matrix3::zeros(); 3]; 2];
        let mut coupled = !diagonal;
        for k in 0..2 {
            let l = 1 - k;
            self.sys[k].auu = on_u(&self.nu_u[k], k);
            self.sys[k].avu = on_u(&self.nu_v[k], k);
            cross[k] = [
                on_u(&self.nu_u[k], l),
                on_u(&self.nu_v[k], l),
                self.other_v[k],
            ];
            coupled |= self.nu_u[k][l].iter().any(|x| *x != 0.0)
                || self.nu_v[k][l].iter().any(|x| *x != 0.0)
                || self.other_v[k].iter().any(|x| *x != 0.0);
        }
        self.cross = coupled.then_some(cross);
    }
}

/// A force or port of the vessel. See the module documentation for the contract.
pub trait Force: Debug + Send + Sync {
    /// The component's name (its registration name).
    fn name(&self) -> &'static str;
    /// The ledger accounts it books, in the order of the indices it gives
    /// [`S2Builder::force`].
    fn accounts(&self) -> &'static [Account] {
        &[]
    }
    /// Its part in flow S2 at the frozen attitude.
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder);
    /// Whether it has a forcing part ([`Force::add_forcing`]): flow S2 is then integrated by
    /// Gauss collocation.
    fn forced(&self) -> bool {
        false
    }
    /// Whether its part in flow S2 ([`Force::add_s2`]) reads the frozen view's velocities or
    /// the actuators' memory ([`Frozen::velocity`], [`Frozen::actuators`]), so that an assembly
    /// of S2 kept for reuse must match the momenta and that memory too (`system/memo.rs`). By
    /// default, whether it has a forcing part (a component that linearises its forcing at the
    /// sub-step's start does); a forcing that keeps nothing in the assembly says no.
    fn assembly_reads_motion(&self) -> bool {
        self.forced()
    }
    /// Whether its forcing depends on the block states (else only on time and the frozen
    /// attitude: the collocation then evaluates it once per stage, not once per iteration).
    fn forcing_uses_state(&self) -> bool {
        true
    }
    /// Its forcing part at time `t` and block states `z` (translation `(p, x − x_o, phi_x)`,
    /// rotation `(m, mu, phi_th)`) at the frozen attitude: the part of its force that is not
    /// affine in `z` or that depends on time.
    fn add_forcing(&self, _fr: &Frozen, _t: f64, _z: &[Z3; 2], _g: &mut Forcing) {}
    /// [`Force::add_forcing`] with the component's own states `x` (empty where the caller has
    /// none): a forcing that reads them, or adds to their rates ([`Forcing::rate_own`]; the
    /// observer's with thrusters, `observer/thrust.rs`). By default, [`Force::add_forcing`].
    fn add_forcing_own(&self, fr: &Frozen, t: f64, z: &[Z3; 2], _x: &[f64], g: &mut Forcing) {
        self.add_forcing(fr, t, z, g);
    }
    /// The quantities it reports at state `s` (block states `z`, frozen view `fr`) and time
    /// `t` (the pipe's top tension, the moving set point, the thrusters, …), appended to `out`;
    /// the same names at every state.
    fn outputs(
        &self,
        _fr: &Frozen,
        _z: &[Z3; 2],
        _s: &VesselState,
        _t: f64,
        _out: &mut Vec<Output>,
    ) {
    }
    /// Energy it stores, a part of H (J).
    fn storage(&self, _s: &VesselState) -> f64 {
        0.0
    }
    /// The states it keeps of its own (a subsystem's), laid out after the 27 numbers of the
    /// body in the order of the components ([`super::Vessel::own_layout`]); none by default.
    /// They reach the results, files, continued runs and the FMU from this declaration.
    fn own_states(&self) -> &[OwnState] {
        &[]
    }
    /// How its own states evolve in flow S2 and what they do to the hull ([`OwnLinear`]).
    /// A component with own states gives them (flow S1 leaves them unchanged).
    fn own_linear(&self) -> Option<&OwnLinear> {
        None
    }
    /// Its own states' rows at the frozen view `fr` when they depend on it (an observer's, on
    /// the measured heading); `None`: [`Force::own_linear`]'s, the same at every attitude.
    fn own_linear_at(&self, _fr: &Frozen) -> Option<OwnLinear> {
        None
    }
    /// Energy stored in its own states `x`, a part of H (J).
    fn own_storage(&self, _x: &[f64]) -> f64 {
        0.0
    }
    /// Whether its own states evolve by a flow of its own ([`Force::own_flow`]) instead of
    /// linearly in flow S2 (a lumped-mass line's nodes).
    fn has_own_flow(&self) -> bool {
        false
    }
    /// Its own flow over `h` (> 0) at the frozen attitude `fr` from the body's state `s`:
    /// advance its own states `x` and the body's momenta `u = (p, m)` (body frame) together, as
    /// a passive system of its own (a discrete gradient: `pipe/chain.rs`), adding to `booked[k]`
    /// the energy of its account `k` (J). The vessel nests it in flow S2 by Strang's rule
    /// (docs/model.md §5.18). Returns `false` when its solver did not converge.
    #[allow(clippy::too_many_arguments)]
    fn own_flow(
        &self,
        _fr: &Frozen,
        _s: &VesselState,
        _h: f64,
        _x: &mut [f64],
        _u: &mut [Vector3<f64>; 2],
        _booked: &mut [f64],
    ) -> bool {
        true
    }
    /// The rates of its own states `x` under its own flow at the body velocities `nu`, written
    /// to `rates`, and its generalised force on the hull (body frame): its part of the vector
    /// field (eq. 39), for the reference computations and tests.
    fn own_rates(
        &self,
        _fr: &Frozen,
        _x: &[f64],
        _nu: &[Vector3<f64>; 2],
        _rates: &mut [f64],
    ) -> [Vector3<f64>; 2] {
        [Vector3::zeros(); 2]
    }
    /// The account (an index in [`Force::accounts`]) under which its own flow's force on the
    /// hull is reported ([`super::VesselSystem::account_wrenches`]).
    fn own_hull_account(&self) -> Option<usize> {
        None
    }
    /// Update, at the end of every step (time `t`) and where a run starts, what its own states
    /// hold constant over the next step from the body's state `s` and its own states `x` there
    /// (where both are synchronised: inside a step the sub-flows have moved them by different
    /// parts of it): a pipe's drift correction, the sensors' samples.
    fn own_end_step(&self, _t: f64, _s: &VesselState, _x: &mut [f64]) {}
    /// Which of its own states (a range of [`HELD`] in its own states) are measurements held
    /// over a step, which the frozen view carries ([`Frozen::held`]).
    fn held_states(&self) -> Option<std::ops::Range<usize>> {
        None
    }
    /// Its next event after `t` (a sensor's sample, a thruster lost): adaptive steps land on it.
    fn next_event(&self, _t: f64) -> Option<f64> {
        None
    }
    /// Set its own states `x` from the body's state `s` where a run starts (the pipe's static
    /// shape under the hang-off point); by default they keep their declared initial values.
    fn init_own(&self, _s: &VesselState, _x: &mut [f64]) -> Result<()> {
        Ok(())
    }
    /// The quantities it reports from its own states `x` at time `t` (beyond the states
    /// themselves, which the vessel reports from [`Force::own_states`]).
    fn own_outputs(&self, _fr: &Frozen, _z: &[Z3; 2], _x: &[f64], _t: f64, _out: &mut Vec<Output>) {
    }
    /// Set the state variables it owns from the rest of the state (a consistent start).
    fn init_state(&self, _s: &mut VesselState) {}
    /// Restore, after a step, an invariant of the exact flow that involves the component's own
    /// state and that the splitting does not keep ([`crate::solve::Model::project`]). It must
    /// leave H unchanged (it books nothing), which its tests check.
    fn project(&self, _s: &mut VesselState) {}
    /// A position it prefers as the origin of the translational block (the controller's set
    /// point): quadratic forms in `x − x_o` then carry no large terms that cancel.
    fn position_origin(&self) -> Option<Vector3<f64>> {
        None
    }
    /// How many actuators it keeps a memory of in the state ([`Actuators`]; the rate-limited
    /// thrusters), 0 if none. At most one component may keep one.
    fn actuators(&self) -> usize {
        0
    }
    /// Start its actuators' memory at time `t` (block states `z`, frozen view `fr`), before a
    /// run's first step.
    fn begin_memory(&self, _fr: &Frozen, _t: f64, _z: &[Z3; 2], _act: &mut Actuators) {}
    /// Record in its actuators' memory what they deliver at the end of a step, at time `t`.
    fn end_step(&self, _fr: &Frozen, _t: f64, _z: &[Z3; 2], _act: &mut Actuators) {}
    /// Check a memory a run is given to start from (a user's state), for a run from `t0`.
    fn check_memory(&self, _act: &Actuators, _t0: f64) -> Result<()> {
        Ok(())
    }
}
