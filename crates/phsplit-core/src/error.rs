//! One error type for the core; the Python binding maps each variant to a Python exception.

/// Everything the core can refuse or fail at.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
pub enum Error {
    /// A parameter or input outside its allowed range; the message names the field and the range.
    #[error("{0}")]
    InvalidInput(String),
    /// A special function evaluated outside its domain.
    #[error("{0}")]
    Domain(String),
    /// A scenario or parameter file that cannot be read or parsed.
    #[error("{0}")]
    Parse(String),
}

pub type Result<T> = std::result::Result<T, Error>;
