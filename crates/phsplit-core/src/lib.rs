pub mod elliptic;
pub mod error;
pub mod linear;
pub mod so3;
pub use error::{Error, Result};
pub mod rigid_body;
