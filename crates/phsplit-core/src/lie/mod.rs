//! Rotations and the special functions of the exact flows.
pub(crate) mod double_double;
pub mod elliptic;
pub mod so3;
