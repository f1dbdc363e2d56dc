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
//! implements [`Force`], and add one line to [`COMPONENTS`]. A force that is not affine in
//! the block states at frozen attitude (nonlinear damping, say) needs a sub-flow of its own:
//! that extension point is the next step of the model, not part of this contract yet.

use super::params::Params;
use super::state::VesselState;
use super::Body;
use crate::error::Result;
use crate::flows::collocation::Blocks;
use crate::solve::{Account, MAX_ACCOUNTS};
use nalgebra::{Matrix3, Vector3};
use std::fmt::Debug;
use std::sync::Arc;

pub mod current;
pub mod damping;
pub mod external;
pub mod pid;
pub mod restoring;

/// A component's builder: reads its keys, validates them, and returns the component, or `None`
/// when the file does not ask for it (an optional component whose table is absent).
pub type Build = fn(&mut Params, &Body) -> Result<Option<Arc<dyn Force>>>;

/// The registration of every component, in the order they are assembled and booked:
/// its name, the table of the vessel file its keys are in, and its builder.
pub const COMPONENTS: &[(&str, &str, Build)] = &[
    ("damping", "vessel", damping::build),
    ("restoring", "vessel", restoring::build),
    ("pid", "control", pid::build),
    ("external", "external", external::build),
    ("current", "current", current::build),
];

/// The two block systems of flow S2 (paper eq. 41):
/// translation in `(p, x − x_o, phi_x)`, rotation in `(m, mu, phi_th)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Sys {
    Trans = 0,
    Rot = 1,
}

/// A generalised force on the momentum `u` of one block system, affine in its state
/// `(u, v, w)`: `f = fu u + fv v + fw w + c` (body frame; N or N m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rows {
    pub fu: Matrix3<f64>,
    pub fv: Matrix3<f64>,
    pub fw: Matrix3<f64>,
    pub c: Vector3<f64>,
}

impl Rows {
    pub const ZERO: Rows = Rows {
        fu: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        fv: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        fw: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        c: Vector3::new(0.0, 0.0, 0.0),
    };
    /// A constant force.
    pub fn constant(c: Vector3<f64>) -> Self {
        Rows { c, ..Self::ZERO }
    }
    /// The force at a block state.
    pub fn at(&self, z: &[Vector3<f64>; 3]) -> Vector3<f64> {
        self.fu * z[0] + self.fv * z[1] + self.fw * z[2] + self.c
    }
    fn add(&mut self, o: &Rows) {
        self.fu += o.fu;
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
    /// The origin `x_o` of the translational block's position, `v = x − x_o` (m).
    pub origin: Vector3<f64>,
    /// Whether the controller acts on this step.
    pub control_on: bool,
    pub body: &'a Body,
}

/// Flow S2 at a frozen attitude under assembly: the two block systems, and, when the ledger
/// is kept, each account's force rows.
#[derive(Debug, Clone)]
pub struct S2Builder {
    pub sys: [Blocks; 2],
    /// Force rows per account and system (only with `ledger`).
    pub booked: Option<Box<[[Rows; 2]; MAX_ACCOUNTS]>>,
    /// First account of the component being assembled.
    pub(crate) base: usize,
}

impl S2Builder {
    pub(crate) fn new(ledger: bool) -> Self {
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
            booked: ledger.then(|| Box::new([[Rows::ZERO; 2]; MAX_ACCOUNTS])),
            base: 0,
        }
    }
    /// Add a force on the momentum of `sys`, booked to the component's account `account`
    /// (its index in [`Force::accounts`]), or to none (`None`: a conservative exchange between
    /// stores of H, like the restoring forces).
    pub fn force(&mut self, sys: Sys, account: Option<usize>, f: &Rows) {
        let b = &mut self.sys[sys as usize];
        b.auu += f.fu;
        b.auv += f.fv;
        b.auw += f.fw;
        b.cu += f.c;
        if let (Some(k), Some(book)) = (account, self.booked.as_mut()) {
            book[self.base + k][sys as usize].add(f);
        }
    }
    /// The block system `sys`, to add the rows of the states a component drives
    /// (`v' = A_vu u`, `w' = A_wv v + c_w`).
    pub fn rows(&mut self, sys: Sys) -> &mut Blocks {
        &mut self.sys[sys as usize]
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
    /// Energy it stores, a part of H (J).
    fn storage(&self, _s: &VesselState) -> f64 {
        0.0
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
}
