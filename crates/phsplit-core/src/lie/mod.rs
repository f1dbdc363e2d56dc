//! Rotations and the special functions of the exact flows.
mod double_double;
pub mod elliptic;
pub mod so3;
