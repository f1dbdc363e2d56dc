//! The vessel under dynamic-positioning control (paper §3.4, eqs. 29–41; docs/model.md §2).
//!
//! Body-frame velocities `v` (linear) and `w` (angular), attitude `Q` (body → spatial), spatial
//! position `x` (z up). The vessel is a rigid body in a fluid ([`Body`]: its 6×6 mass matrix
//! `M = M_RB + M_A`, the paper's `diag(mv, mv, mv, T)` or general) with forces and ports as
//! components ([`forces`]), a default initial state ([`Initial`]), and the dynamical system
//! built from them for a run ([`system::VesselSystem`]).
//!
//! Energy (eq. 35): `H = ½ uᵀM⁻¹u` (`u = (p, m)`; the paper's `½ mᵀT⁻¹m + ½|p|²/mv`) `+ Σ` the
//! components' stores (the restoring
//! forces': `½ muᵀG⁺mu + ½ c x_z²`). The forces' power is booked per component in the ledger,
//! so that `dH/dt = Σ port power − Σ dissipation`.

pub mod body;
pub mod forces;
pub mod params;
pub mod state;
pub mod system;

use crate::error::Result;
use crate::lie::so3;
pub use body::Body;
use forces::Force;
use nalgebra::Vector3;
use params::{Params, Range};
pub use state::{Actuators, VesselState, LAYOUT, MAX_ACTUATORS, STATE_DIM};
use std::sync::Arc;
pub use system::{LinearFlow, VesselSystem};

/// The paper's vessel (Appendix D, as restated in docs/model.md §4), as TOML.
pub const PAPER_VESSEL_TOML: &str = include_str!("../../../data/paper_vessel.toml");

/// The shipped vessels: name, one line on what it is and where its numbers come from, and its
/// vessel file (each number's source in the file's comments).
pub const PRESETS: &[(&str, &str, &str)] = &[
    (
        "paper",
        "the paper's vessel (Celledoni, Høiseth, Ramzina 2018, App. D): diagonal M, CG at the origin",
        PAPER_VESSEL_TOML,
    ),
    (
        "osv",
        "83 m offshore supply vessel of Fossen's MSS (osv.m): full added mass, CG 4.5 m aft, cross-flow drag",
        include_str!("../../../data/vessels/osv.toml"),
    ),
    (
        "shipx-supply",
        "82.8 m supply vessel of MSS's ShipX data (not MSS's supply.m, a 76.2 m vessel), the paper's vessel with its added mass, CG 5.4 m aft, full damping and restoring",
        include_str!("../../../data/vessels/supply.toml"),
    ),
];

/// Earlier names of shipped vessels: (old name, preset it stands for). `supply` was renamed
/// `shipx-supply`: MSS's own `supply.m` is a different, 76.2 m vessel.
pub const PRESET_ALIASES: &[(&str, &str)] = &[("supply", "shipx-supply")];

/// The default initial state, in engineering variables (table `[initial]`).
#[derive(Debug, Clone, PartialEq)]
pub struct Initial {
    /// ZYX Euler angles (roll, pitch, yaw), rad.
    pub euler: [f64; 3],
    /// Spatial position, m.
    pub position: [f64; 3],
    /// Body linear velocity, m/s (default 0).
    pub velocity: [f64; 3],
    /// Body angular velocity, rad/s (default 0).
    pub angular_velocity: [f64; 3],
}

impl Initial {
    fn read(p: &mut Params) -> Result<Self> {
        const T: &str = "initial";
        Ok(Self {
            euler: p.vec3(T, "euler", None, "rad", Range::Finite)?,
            position: p.vec3(
                T,
                "position",
                None,
                "m",
                Range::Physical(&params::physical::POSITION),
            )?,
            velocity: p.vec3(T, "velocity", Some([0.0; 3]), "m/s", Range::Finite)?,
            angular_velocity: p.vec3(
                T,
                "angular_velocity",
                Some([0.0; 3]),
                "rad/s",
                Range::Finite,
            )?,
        })
    }
}

/// A vessel: rigid body, forces and ports, and default initial state, validated.
#[derive(Debug, Clone)]
pub struct Vessel {
    pub body: Body,
    pub initial: Initial,
    /// The components, in the order of [`forces::COMPONENTS`].
    pub forces: Vec<Arc<dyn Force>>,
    /// Every parameter as read (defaults filled in): the normalised vessel file.
    pub params: toml::Table,
}

impl Vessel {
    /// Build a vessel from a parameter file's text: `[vessel]`, `[control]`, `[initial]` and
    /// the tables of optional components. Every key is read by one part of the model and
    /// validated there; a key nobody reads is refused.
    pub fn from_toml_str(text: &str) -> Result<Self> {
        Self::from_params(Params::parse(text)?)
    }

    /// Build a vessel from a parsed parameter table.
    pub fn from_table(table: toml::Table) -> Result<Self> {
        Self::from_params(Params::from_table(table))
    }

    fn from_params(mut p: Params) -> Result<Self> {
        let body = Body::read(&mut p)?;
        let mut forces = Vec::new();
        for (_, _, build) in forces::COMPONENTS {
            if let Some(f) = build(&mut p, &body)? {
                forces.push(f);
            }
        }
        let initial = Initial::read(&mut p)?;
        let params = p.finish()?;
        let v = Self {
            body,
            initial,
            forces,
            params,
        };
        let i = &v.initial;
        v.try_state_from(
            i.euler.into(),
            i.position.into(),
            i.velocity.into(),
            i.angular_velocity.into(),
        )?;
        v.check_names()?;
        Ok(v)
    }

    /// Every account and every reported quantity has its own name (a subsystem named after
    /// another component's account or output would hide it in the results).
    fn check_names(&self) -> Result<()> {
        use crate::solve::Model;
        let sys = VesselSystem::new(self, None);
        let mut seen = std::collections::BTreeMap::new();
        for f in &self.forces {
            for a in f.accounts() {
                if let Some(first) = seen.insert(a.name, f.name()) {
                    return Err(crate::error::Error::InvalidInput(format!(
                        "two ledger accounts are named {:?} (of {first} and {}): rename the latter ({}.name); the accounts are {}",
                        a.name,
                        f.name(),
                        f.name(),
                        sys.accounts()
                            .iter()
                            .map(|a| a.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    )));
                }
            }
        }
        let named: Vec<&str> = self.own_layout().map(|(f, _)| f.name()).collect();
        let mut outs = std::collections::BTreeSet::new();
        for o in sys.outputs(&self.initial_state(), 0.0) {
            if !outs.insert(o.name.clone()) {
                let keys: Vec<String> = named
                    .iter()
                    .map(|n| format!("{n}.name or {n}.states"))
                    .collect();
                return Err(crate::error::Error::InvalidInput(format!(
                    "two components report a quantity named {:?}: rename a subsystem or its state ({})",
                    o.name,
                    keys.join("; ")
                )));
            }
        }
        Ok(())
    }

    /// The same vessel with the components named in `names` built again from `table` (this
    /// vessel's file with some of their values changed); the other components are kept as they
    /// are, and their tables are not read again. For values that change often, like the FMU's
    /// inputs (the external load, the set point, the current): a rebuild of the whole vessel
    /// reads every table (waves and wind coefficient tables included) each time.
    pub fn with_rebuilt(&self, table: toml::Table, names: &[&str]) -> Result<Self> {
        let mut p = Params::from_table(table);
        let mut forces = Vec::with_capacity(self.forces.len());
        for (name, _, build) in forces::COMPONENTS {
            if names.contains(name) {
                if let Some(f) = build(&mut p, &self.body)? {
                    forces.push(f);
                }
            } else if let Some(f) = self.force(name) {
                forces.push(f.clone());
            }
        }
        let mut params = self.params.clone();
        for (section, v) in p.read_so_far() {
            if let (Some(toml::Value::Table(dst)), toml::Value::Table(src)) =
                (params.get_mut(&section), &v)
            {
                for (k, x) in src {
                    dst.insert(k.clone(), x.clone());
                }
            } else {
                params.insert(section, v);
            }
        }
        Ok(Self {
            body: self.body.clone(),
            initial: self.initial.clone(),
            forces,
            params,
        })
    }

    /// The tables a vessel file may have: the body's and initial state's, and the components'.
    pub fn tables() -> Vec<&'static str> {
        let mut t = vec!["vessel", "initial"];
        for (_, tables, _) in forces::COMPONENTS {
            for table in *tables {
                if !t.contains(table) {
                    t.push(table);
                }
            }
        }
        t
    }

    /// A shipped vessel by name ([`PRESETS`]).
    pub fn preset(name: &str) -> Result<Self> {
        let name = PRESET_ALIASES
            .iter()
            .find(|a| a.0 == name)
            .map_or(name, |a| a.1);
        match PRESETS.iter().find(|p| p.0 == name) {
            Some((_, _, text)) => Self::from_toml_str(text),
            None => Err(crate::error::Error::InvalidInput(format!(
                "unknown vessel preset {name:?}; the presets are {}",
                PRESETS
                    .iter()
                    .map(|p| format!("'{}'", p.0))
                    .collect::<Vec<_>>()
                    .join(", ")
            ))),
        }
    }

    /// The paper's vessel and scenario (docs/model.md §4).
    pub fn paper() -> Self {
        Self::from_toml_str(PAPER_VESSEL_TOML).expect("the shipped parameter file is valid")
    }

    /// The component registered as `name`, if the vessel has it.
    pub fn force(&self, name: &str) -> Option<&Arc<dyn Force>> {
        self.forces.iter().find(|f| f.name() == name)
    }

    /// The state from engineering variables: attitude from ZYX Euler angles, momenta
    /// `(p, m) = M ν`, the components' own states consistent with them (`mu = G Qᵀe3`),
    /// integral states zero.
    pub fn state_from(
        &self,
        euler: Vector3<f64>,
        position: Vector3<f64>,
        velocity: Vector3<f64>,
        angular_velocity: Vector3<f64>,
    ) -> VesselState {
        let z = Vector3::zeros();
        let [p, m] = self.body.momentum(&velocity, &angular_velocity);
        let mut s = VesselState {
            p,
            m,
            q: so3::from_euler_zyx(&euler),
            mu: z,
            x: position,
            phi_th: z,
            phi_x: z,
            act: Default::default(),
            own: self
                .forces
                .iter()
                .flat_map(|f| f.own_states().iter().map(|o| o.initial))
                .collect(),
        };
        for f in &self.forces {
            f.init_state(&mut s);
        }
        if self.init_own(&mut s).is_err() {
            s.own.fill(f64::NAN);
        }
        s
    }

    /// [`Self::state_from`], with the error of a component that cannot set its own states from
    /// the body's (the pipe's static shape that does not converge).
    pub fn try_state_from(
        &self,
        euler: Vector3<f64>,
        position: Vector3<f64>,
        velocity: Vector3<f64>,
        angular_velocity: Vector3<f64>,
    ) -> Result<VesselState> {
        let mut s = self.state_from(euler, position, velocity, angular_velocity);
        self.init_own(&mut s)?;
        Ok(s)
    }

    /// Let each component set its own states from the body's state in `s`
    /// ([`Force::init_own`]).
    fn init_own(&self, s: &mut VesselState) -> Result<()> {
        let ranges: Vec<_> = self.own_layout().map(|(f, r)| (f.clone(), r)).collect();
        for (f, r) in ranges {
            let mut x = s.own[r.clone()].to_vec();
            f.init_own(s, &mut x)?;
            s.own[r].copy_from_slice(&x);
        }
        Ok(())
    }

    /// The default initial state of the file.
    pub fn initial_state(&self) -> VesselState {
        let i = &self.initial;
        self.state_from(
            i.euler.into(),
            i.position.into(),
            i.velocity.into(),
            i.angular_velocity.into(),
        )
    }

    /// How many rate-limited thrusters the state remembers ([`VesselState::act`]; 0 without
    /// rate limits).
    pub fn actuators(&self) -> usize {
        self.forces.iter().map(|f| f.actuators()).sum()
    }

    /// Check the memory of rate-limited thrusters a state brings, for a run from `t0`
    /// ([`Force::check_memory`]); a state without one passes.
    pub fn check_memory(&self, s: &VesselState, t0: f64) -> Result<()> {
        if s.act.n == 0 {
            return Ok(());
        }
        self.forces
            .iter()
            .try_for_each(|f| f.check_memory(&s.act, t0))
    }

    /// The energy `H` of eq. (35), J (without constant terms), with the storage of the
    /// components' own states.
    pub fn energy(&self, s: &VesselState) -> f64 {
        let own: f64 = self
            .own_layout()
            .map(|(f, r)| f.own_storage(&s.own[r]))
            .sum();
        self.body.kinetic_energy(s) + self.forces.iter().map(|f| f.storage(s)).sum::<f64>() + own
    }

    /// The components that keep states of their own, each with its range in
    /// [`VesselState::own`] (in the order of the components).
    pub fn own_layout(&self) -> impl Iterator<Item = (&Arc<dyn Force>, std::ops::Range<usize>)> {
        let mut off = 0;
        self.forces.iter().filter_map(move |f| {
            let n = f.own_states().len();
            (n > 0).then(|| {
                off += n;
                (f, off - n..off)
            })
        })
    }

    /// How many states the components keep of their own ([`VesselState::own`]).
    pub fn own_dim(&self) -> usize {
        self.forces.iter().map(|f| f.own_states().len()).sum()
    }

    /// Where the components' own states start, in the layout's order.
    pub fn own_initial(&self) -> Vec<f64> {
        self.own_states().iter().map(|o| o.initial).collect()
    }

    /// A state that continues a run ([`VesselState::from_slice_continuing`]); a state of the
    /// body's 27 numbers alone takes the own states' initial values.
    pub fn continuing_state(&self, y: &[f64]) -> Result<VesselState> {
        let own = self.own_initial();
        if y.len() == state::STATE_DIM && !own.is_empty() {
            let mut v = y.to_vec();
            v.extend_from_slice(&own);
            let mut s = VesselState::from_slice_continuing(&v, own.len(), self.actuators())?;
            self.init_own(&mut s)?;
            return Ok(s);
        }
        VesselState::from_slice_continuing(y, own.len(), self.actuators())
    }

    /// A state a user gives ([`VesselState::from_slice_user`]).
    pub fn user_state(&self, y: &[f64], orthonormalize: bool) -> Result<VesselState> {
        let mut s =
            VesselState::from_slice_user(y, orthonormalize, &self.own_initial(), self.actuators())?;
        if y.len() == state::STATE_DIM {
            // The body's numbers alone: the components set their own states from them.
            self.init_own(&mut s)?;
        }
        Ok(s)
    }

    /// The components' own states, in the layout's order ([`Self::own_layout`]).
    pub fn own_states(&self) -> Vec<forces::OwnState> {
        self.forces
            .iter()
            .flat_map(|f| f.own_states().iter().cloned())
            .collect()
    }
}
