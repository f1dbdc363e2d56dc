//! phsplit-fmu: a phsplit vessel as an FMI 2.0 co-simulation FMU (issue 15; docs/fmu.md).
//!
//! The `cdylib` is the FMU's binary (`binaries/linux64/phsplit_fmu.so`): the FMI 2.0 C API
//! ([`ffi`]) over the model ([`model`]), with no Python inside. The `rlib` gives the exporter
//! (`phsplit fmu export`, through the Python binding) the same variable table the binary serves,
//! so `modelDescription.xml` and the binary cannot disagree.
pub mod ffi;
pub mod model;

pub use model::{Causality, Instance, Kind, Layout, Mode, Type, Val, Variable};
