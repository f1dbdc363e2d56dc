//! phsplit-core: passivity-preserving splitting methods for rigid-body port-Hamiltonian systems.
//!
//! Implements E. Celledoni, E. H. Høiseth, N. Ramzina, *Passivity-preserving splitting methods
//! for rigid body systems*, Multibody System Dynamics 44 (2018) 251–275 (arXiv:1408.2544):
//! the vessel model of its §3.4, the exact flows of its split (40)/(41), the compositions of its
//! §2 and explicit Runge–Kutta baselines, with an energy ledger by port. The model is restated
//! in the repository's `docs/model.md`. No Python here; the `phsplit-py` crate binds it.
//!
//! Layout:
//! - [`lie`]: rotations, quaternions, Euler angles ([`lie::so3`]); Jacobi sn/cn/dn, K, F
//!   ([`lie::elliptic`]).
//! - [`flows`]: the free rigid body ([`flows::rigid_body`]), affine flows and Van Loan
//!   integrals ([`flows::affine`]), Gauss collocation ([`flows::collocation`]).
//! - [`methods`]: compositions and Butcher tableaus as data, one registry.
//! - [`solve`]: kernels, options, trajectories and the ledger; the traits a model implements.
//! - [`model`]: the vessel: parameters, state, system, and its forces as components.
//! - [`settings`]: a run's settings, parsed and validated once.
pub mod error;
pub mod flows;
pub mod lie;
pub mod methods;
pub mod model;
pub mod settings;
pub mod solve;
pub use error::{Error, Result};
