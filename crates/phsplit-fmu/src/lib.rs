//! phsplit-fmu: a phsplit vessel as an FMI 2.0 co-simulation FMU (docs/fmu.md).
//!
//! The `cdylib` is the FMU's binary (`binaries/linux64/phsplit_fmu.so`), with no Python inside:
//! the FMI 2.0 C API ([`ffi`]) over an instance stepping the vessel ([`instance`]) and the
//! variable table ([`layout`]). The `rlib` gives the exporter (`phsplit fmu export`, through the
//! Python binding) the same variable table the binary serves, so `modelDescription.xml` and the
//! binary cannot disagree.
pub mod ffi;
pub mod instance;
pub mod layout;

pub use instance::{internal_steps, Instance, Mode};
pub use layout::{Causality, Kind, Layout, Type, Val, Variable};
