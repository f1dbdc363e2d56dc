//! Models: the vessel (paper §3.4) with its forces and ports as components. Models implement
//! the solver's traits ([`crate::solve::system`]); the solver never imports a model.
pub mod catenary;
pub mod grid;
pub mod kept;
pub mod phasors;
pub mod reference;
pub mod vessel;
