//! Rotations and the special functions of the exact flows.
pub mod elliptic;
pub mod so3;
