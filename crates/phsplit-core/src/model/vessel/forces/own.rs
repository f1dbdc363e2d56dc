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
/// component's slice of [`super::VesselState::own`]), in the body velocities `ν = (v, ω)` and in
/// the translational block's position `v_x = x − x_o` (spatial), with matrices constant over a
/// sub-step (constant for a run, or given at each frozen attitude by
/// [`super::Force::own_linear_at`]): `x' = axx x + axnu ν + axv v_x + axc`; its generalised force
/// on the hull (body frame, force and moment about the body origin) `τ = fx x + fnu ν + fc`; and
/// the dissipation its account `account` (an index in [`super::Force::accounts`]) books,
/// `[x; ν]ᵀ diss [x; ν]`.
///
/// Two contracts, by `port`:
/// - `port = false` (a subsystem of the plant: a tank, the fluid memory): the exchange `ντ` with
///   the hull is internal: what `τ` does to the kinetic energy the component's storage pays,
///   less the dissipation (checked by the vessel's ledger tests:
///   `d/dt(storage) = −ντ − [x; ν]ᵀ diss [x; ν]`).
/// - `port = true` (a controller with states: an observer and the control law on its
///   estimates): the states store no energy of H; the power `ν·τ` of the force on the hull is
///   the work of a port, booked to `account` (a supplied account).
///
/// The vessel integrates these rows with the momenta as one linear system in flow S2
/// (`system/own.rs`).
#[derive(Debug, Clone, PartialEq)]
pub struct OwnLinear {
    pub axx: nalgebra::DMatrix<f64>,
    pub axnu: nalgebra::DMatrix<f64>,
    pub axv: nalgebra::DMatrix<f64>,
    pub axc: nalgebra::DVector<f64>,
    pub fx: nalgebra::DMatrix<f64>,
    pub fnu: nalgebra::DMatrix<f64>,
    pub fc: nalgebra::DVector<f64>,
    pub account: usize,
    pub diss: nalgebra::DMatrix<f64>,
    pub port: bool,
}

impl OwnLinear {
    /// A subsystem of the plant exchanging energy with the hull (`port = false`), its rows on
    /// `x` and `ν` alone.
    pub fn exchange(
        axx: nalgebra::DMatrix<f64>,
        axnu: nalgebra::DMatrix<f64>,
        fx: nalgebra::DMatrix<f64>,
        fnu: nalgebra::DMatrix<f64>,
        account: usize,
        diss: nalgebra::DMatrix<f64>,
    ) -> Self {
        let m = axx.nrows();
        Self {
            axx,
            axnu,
            axv: nalgebra::DMatrix::zeros(m, 3),
            axc: nalgebra::DVector::zeros(m),
            fx,
            fnu,
            fc: nalgebra::DVector::zeros(6),
            account,
            diss,
            port: false,
        }
    }
}

/// A named scalar a component reports at a state, for the results (CF units).
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    pub name: String,
    pub unit: &'static str,
    pub long_name: String,
    pub value: f64,
}

impl Output {
    pub fn new(
        name: impl Into<String>,
        unit: &'static str,
        long_name: impl Into<String>,
        value: f64,
    ) -> Self {
        Self {
            name: name.into(),
            unit,
            long_name: long_name.into(),
            value,
        }
    }
}
