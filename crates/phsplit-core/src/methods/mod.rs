//! Methods as data: compositions (paper §2, format (10)), Butcher tableaus, and the one
//! registry that names them.
pub mod butcher;
pub mod composition;
pub mod registry;

pub use butcher::ButcherTableau;
pub use composition::{Composition, Flow, Outer};
pub use registry::{names, Method, REGISTRY};
