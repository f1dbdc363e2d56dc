//! What a component declares of its own states: each state ([`OwnState`]) and, for states
//! linear in flow S2, their rows ([`OwnLinear`]).

/// One state a component keeps of its own ([`super::Force::own_states`]): its name in the results
/// (unique among the vessel's outputs), CF unit, long name, and value where a run starts.
#[derive(Debug, Clone, PartialEq)]
pub struct OwnState {
    pub name: String,
    pub unit: String,
    pub long_name: String,
    pub initial: f64,
}

/// A component's own states in flow S2 ([`super::Force::own_linear`]), linear in them (`x`, the
/// component's slice of [`super::VesselState::own`]) and in the body velocities `ν = (v, ω)`, with
/// constant matrices: `x' = axx x + axnu ν`; its generalised force on the hull (body frame,
/// force and moment about the body origin) `τ = fx x + fnu ν`; and the dissipation its account
/// `account` (an index in [`super::Force::accounts`], a dissipated account) books,
/// `[x; ν]ᵀ diss [x; ν]`. The exchange `ντ` with the hull is internal: what `τ` does to the
/// kinetic energy the component's storage pays, less the dissipation (its contract, checked by
/// the vessel's ledger tests: `d/dt(storage) = −ντ − [x; ν]ᵀ diss [x; ν]`). The vessel
/// integrates these rows with the momenta as one linear system in flow S2 (`system/own.rs`).
#[derive(Debug, Clone, PartialEq)]
pub struct OwnLinear {
    pub axx: nalgebra::DMatrix<f64>,
    pub axnu: nalgebra::DMatrix<f64>,
    pub fx: nalgebra::DMatrix<f64>,
    pub fnu: nalgebra::DMatrix<f64>,
    pub account: usize,
    pub diss: nalgebra::DMatrix<f64>,
}
