//! phsplit-core: passivity-preserving splitting methods for rigid-body port-Hamiltonian systems.
//!
//! Implements E. Celledoni, E. H. Høiseth, N. Ramzina, *Passivity-preserving splitting methods
//! for rigid body systems*, Multibody System Dynamics 44 (2018) 251–275 (arXiv:1408.2544):
//! the vessel model of its §3.4, the exact flows of its split (40)/(41), the compositions of its
//! §2 and explicit Runge–Kutta baselines, with an energy ledger. No Python here; the `phsplit-py`
//! crate binds it.
//!
//! Modules: [`so3`] (rotations, quaternions, Euler angles), [`elliptic`] (Jacobi sn/cn/dn, K, F),
//! [`rigid_body`] (exact free rigid body, Magnus attitude), [`linear`] (affine flows, Van Loan
//! integrals), [`methods`] (methods as data), [`vessel`] (the model), [`integrate`] (the kernels).
pub mod elliptic;
pub mod error;
pub mod integrate;
pub mod linear;
pub mod methods;
pub mod rigid_body;
pub mod so3;
pub mod vessel;
pub use error::{Error, Result};
