//! Exact and structure-preserving flows: the free rigid body (flow S1), affine linear flows
//! by the matrix exponential, and Gauss collocation (flow S2).
pub mod affine;
pub mod collocation;
pub mod kirchhoff;
pub mod rigid_body;
pub mod stage_solve;
