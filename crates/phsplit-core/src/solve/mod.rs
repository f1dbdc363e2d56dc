//! The solver: kernels, options, trajectories and saving. It never imports a model; models
//! implement the traits of [`system`].
pub mod adaptive;
pub mod kernel;
pub mod options;
pub mod system;
pub mod trajectory;

pub use kernel::{run, run_runge_kutta, run_splitting, run_watched};
pub use options::{Options, Tolerance, MAX_STEPS};
pub use system::{
    Account, AccountKind, FieldModel, Model, Role, SplitModel, Work, INLINE_ACCOUNTS,
};
pub use trajectory::{Monitor, Status, Trajectory, Unwatched};
