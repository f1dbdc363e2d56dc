//! The vessel's state and its one flat layout (paper §3.4; docs/model.md §2).

use crate::error::{Error, Result};
use crate::lie::so3;
use nalgebra::{Matrix3, SVector, Vector3};

/// The state of the vessel (27 numbers with `Q` stored as a matrix).
#[derive(Debug, Clone, PartialEq)]
pub struct VesselState {
    /// Linear momentum `p = mv v`, body frame, kg m/s.
    pub p: Vector3<f64>,
    /// Angular momentum `m = T w`, body frame, kg m²/s.
    pub m: Vector3<f64>,
    /// Attitude, body → spatial.
    pub q: Matrix3<f64>,
    /// Restoring-moment variable `mu` (= `G Qᵀe3` on exact solutions), N m.
    pub mu: Vector3<f64>,
    /// Spatial position, m.
    pub x: Vector3<f64>,
    /// `∫(theta − theta_ref) dt`, rad s.
    pub phi_th: Vector3<f64>,
    /// `∫(x − x_ref) dt`, m s.
    pub phi_x: Vector3<f64>,
    /// What rate-limited thrusters deliver (none for other vessels): not part of the 27-vector
    /// the flows integrate, but a memory the run keeps from step to step.
    pub act: Actuators,
    /// The components' own states (a linear port-Hamiltonian subsystem's, …), in the order of
    /// the vessel's layout of them (`Vessel::own_layout`); empty for a vessel whose components
    /// keep none. Integrated with the rest in flow S2; flow S1 leaves them unchanged.
    pub own: Vec<f64>,
}

/// Most thrusters a vessel with rate-limited thrusters may have (their memory is part of the
/// state, of fixed size).
pub const MAX_ACTUATORS: usize = 8;

/// The memory of rate-limited thrusters (docs/model.md §5.8): each thruster's thrust (N) and
/// the direction of its force (rad, in the body's x–y plane, in (−π, π]) as delivered at time
/// `t`. The vessel's flows read it and the end of every step writes it; `n = 0` means none
/// (a vessel without rate limits, or a run not yet started).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Actuators {
    pub n: usize,
    pub t: f64,
    pub thrust: [f64; MAX_ACTUATORS],
    pub angle: [f64; MAX_ACTUATORS],
}

impl Default for Actuators {
    fn default() -> Self {
        Self {
            n: 0,
            t: 0.0,
            thrust: [0.0; MAX_ACTUATORS],
            angle: [0.0; MAX_ACTUATORS],
        }
    }
}

impl Actuators {
    /// The flat form that follows the 27 numbers of a state that continues a run:
    /// `t, thrust[0..n], angle[0..n]` (`1 + 2n` numbers; none when `n = 0`).
    pub fn to_flat(&self) -> Vec<f64> {
        if self.n == 0 {
            return Vec::new();
        }
        let mut v = vec![self.t];
        v.extend_from_slice(&self.thrust[..self.n]);
        v.extend_from_slice(&self.angle[..self.n]);
        v
    }

    /// Inverse of [`Self::to_flat`] for `n` thrusters.
    pub fn from_flat(v: &[f64], n: usize) -> Result<Self> {
        if n == 0 || n > MAX_ACTUATORS || v.len() != 1 + 2 * n {
            return Err(Error::InvalidInput(format!(
                "the thrusters' memory of a state that continues a run has 1 + 2n numbers (time, each thruster's thrust, each thruster's angle) for n = {n} thrusters that keep a memory (rate limits, stuck_at), got {}",
                v.len()
            )));
        }
        let mut a = Self {
            n,
            t: v[0],
            ..Self::default()
        };
        a.thrust[..n].copy_from_slice(&v[1..1 + n]);
        a.angle[..n].copy_from_slice(&v[1 + n..]);
        Ok(a)
    }
}

/// Dimension of the state as a flat vector.
pub const STATE_DIM: usize = 27;

/// The flat layout: name, offset and length of each part, in order. Every conversion between
/// the state and a flat vector (here, in the binding, in Python) follows this table.
pub const LAYOUT: [(&str, usize, usize); 7] = [
    ("p", 0, 3),
    ("m", 3, 3),
    ("Q", 6, 9),
    ("mu", 15, 3),
    ("x", 18, 3),
    ("phi_th", 21, 3),
    ("phi_x", 24, 3),
];

impl VesselState {
    fn parts(&self) -> [&[f64]; 7] {
        [
            self.p.as_slice(),
            self.m.as_slice(),
            self.q.as_slice(),
            self.mu.as_slice(),
            self.x.as_slice(),
            self.phi_th.as_slice(),
            self.phi_x.as_slice(),
        ]
    }

    /// Flatten: `p, m, Q` (column-major), `mu, x, phi_th, phi_x` ([`LAYOUT`]).
    pub fn to_vector(&self) -> SVector<f64, STATE_DIM> {
        let mut y = SVector::<f64, STATE_DIM>::zeros();
        for ((_, off, len), part) in LAYOUT.iter().zip(self.parts()) {
            y.as_mut_slice()[*off..off + len].copy_from_slice(part);
        }
        y
    }

    /// Inverse of [`Self::to_vector`].
    pub fn from_vector(y: &SVector<f64, STATE_DIM>) -> Self {
        let s = y.as_slice();
        let v3 = |k: usize| Vector3::from_column_slice(&s[LAYOUT[k].1..LAYOUT[k].1 + 3]);
        Self {
            p: v3(0),
            m: v3(1),
            q: Matrix3::from_column_slice(&s[6..15]),
            mu: v3(3),
            x: v3(4),
            phi_th: v3(5),
            phi_x: v3(6),
            act: Actuators::default(),
            own: Vec::new(),
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.parts().iter().all(|p| p.iter().all(|v| v.is_finite()))
            && self.own.iter().all(|v| v.is_finite())
    }

    /// A state from a flat vector given by a user: the right length, finite, and with an
    /// attitude that is a rotation (or, with `orthonormalize`, projected to the nearest one).
    /// A state that continues a run (the last state of an earlier call of the same run): only
    /// its length and finiteness are checked. An explicit Runge–Kutta method lets `Q` drift off
    /// SO(3) by its own error, and the continuation must take the state as it is, so that a run
    /// cut into several calls gives the same numbers as one call.
    /// After the 27 numbers come the components' `own` states (all of them), then, for a vessel
    /// with `actuators` rate-limited thrusters, optionally their memory
    /// ([`Actuators::to_flat`]); without it the run starts them afresh.
    pub fn from_slice_continuing(y: &[f64], own: usize, actuators: usize) -> Result<Self> {
        let base = STATE_DIM + own;
        let with_memory = base + 1 + 2 * actuators;
        if y.len() != base && (actuators == 0 || y.len() != with_memory) {
            let what = match (own, actuators) {
                (0, 0) => format!("a state is a flat vector of {STATE_DIM} numbers"),
                (0, a) => format!("a state to continue from is a flat vector of {STATE_DIM} numbers, or {with_memory} with the memory of the {a} thrusters (rate limits, stuck_at)"),
                (o, 0) => format!("a state to continue from is a flat vector of {base} numbers ({STATE_DIM}, then the components' {o} own states)"),
                (o, a) => format!("a state to continue from is a flat vector of {base} numbers ({STATE_DIM}, then the components' {o} own states), or {with_memory} with the memory of the {a} thrusters (rate limits, stuck_at)"),
            };
            return Err(Error::InvalidInput(format!("{what}, got {}", y.len())));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "the state to continue from must be finite; entry {i} is {}",
                y[i]
            )));
        }
        let mut s = Self::from_vector(&SVector::<f64, STATE_DIM>::from_column_slice(
            &y[..STATE_DIM],
        ));
        s.own = y[STATE_DIM..base].to_vec();
        if y.len() > base {
            s.act = Actuators::from_flat(&y[base..], actuators)?;
        }
        Ok(s)
    }

    /// [`Self::from_slice_checked`] for a vessel whose components keep `own` states of their
    /// own (`own_initial`, their values where a run starts) and with `actuators` rate-limited
    /// thrusters: the 27 numbers alone (the own states then start at `own_initial`), or
    /// followed by the own states and optionally the thrusters' memory
    /// ([`Actuators::to_flat`], as `Solution.state(i)` gives it), which must then be finite.
    pub fn from_slice_user(
        y: &[f64],
        orthonormalize: bool,
        own_initial: &[f64],
        actuators: usize,
    ) -> Result<Self> {
        let own = own_initial.len();
        if y.len() == STATE_DIM || (own == 0 && actuators == 0) {
            let mut s = Self::from_slice_checked(y, orthonormalize)?;
            s.own = own_initial.to_vec();
            return Ok(s);
        }
        let base = STATE_DIM + own;
        let with_memory = base + 1 + 2 * actuators;
        if y.len() != base && (actuators == 0 || y.len() != with_memory) {
            let mut what = format!(
                "the initial state (initial) is a flat vector of {STATE_DIM} numbers (p, m, Q column-major, mu, x, phi_th, phi_x)"
            );
            if own > 0 {
                what += &format!(", or {base} with the components' {own} own states");
            }
            if actuators > 0 {
                what += &format!(
                    ", or {with_memory} with the memory of the vessel's {actuators} thrusters that keep one (rate limits, stuck_at: time, thrusts, angles)"
                );
            }
            return Err(Error::InvalidInput(format!("{what}, got {}", y.len())));
        }
        let mut s = Self::from_slice_checked(&y[..STATE_DIM], orthonormalize)?;
        if let Some(i) = y[STATE_DIM..].iter().position(|v| !v.is_finite()) {
            let part = if i < own {
                "the components' own states after the state"
            } else {
                "the thrusters' memory after the state"
            };
            return Err(Error::InvalidInput(format!(
                "{part} must be finite; entry {} is {}",
                STATE_DIM + i,
                y[STATE_DIM + i]
            )));
        }
        s.own = y[STATE_DIM..base].to_vec();
        if y.len() > base {
            s.act = Actuators::from_flat(&y[base..], actuators)?;
        }
        Ok(s)
    }

    /// The flat form of a state that continues a run: the 27 numbers, the components' own
    /// states, then the thrusters' memory ([`Self::from_slice_continuing`]'s input).
    pub fn to_continuing(&self) -> Vec<f64> {
        let mut v = self.to_vector().as_slice().to_vec();
        v.extend_from_slice(&self.own);
        v.extend(self.act.to_flat());
        v
    }

    pub fn from_slice_checked(y: &[f64], orthonormalize: bool) -> Result<Self> {
        if y.len() != STATE_DIM {
            return Err(Error::InvalidInput(format!(
                "the initial state (initial) is a flat vector of {STATE_DIM} numbers (p, m, Q column-major, mu, x, phi_th, phi_x), got {}",
                y.len()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "the initial state (initial) must be finite; entry {i} ({}) is {}",
                LAYOUT
                    .iter()
                    .find(|(_, o, l)| i >= *o && i < o + l)
                    .map_or("?", |p| p.0),
                y[i]
            )));
        }
        if y[17] != 0.0 {
            // G = diag(·, ·, 0): mu_3 has no store in H and no account in the ledger, so a
            // nonzero value would exert a moment the energy balance cannot see (docs/model.md
            // §2.3, §6 N6). Every run keeps it exactly 0 (its rate is G_33 (...) = 0).
            return Err(Error::InvalidInput(format!(
                "the initial state's entry 17 (mu[2], the yaw component of the restoring state) must be 0 (the restoring matrix G has no yaw entry), got {}",
                y[17]
            )));
        }
        let mut s = Self::from_vector(&SVector::<f64, STATE_DIM>::from_column_slice(y));
        let (defect, det) = (so3::orthogonality_defect(&s.q), s.q.determinant());
        if orthonormalize {
            if det <= 0.0 {
                return Err(Error::InvalidInput(format!(
                    "the initial attitude Q cannot be projected to a rotation: det Q = {det:.6} (a reflection or singular; allowed: det Q > 0)"
                )));
            }
            s.q = so3::orthonormalize(&s.q);
            if !s.q.iter().all(|v| v.is_finite()) {
                return Err(Error::InvalidInput(
                    "the initial attitude Q cannot be projected to a rotation (it is zero or not finite)".into(),
                ));
            }
        } else if defect > 1e-9 || det < 0.0 {
            return Err(Error::InvalidInput(format!(
                "the initial attitude Q is not a rotation: ‖QᵀQ − I‖ = {defect:.3e}, det Q = {det:.6} (allowed: ‖QᵀQ − I‖ ≤ 1e-9, det Q = 1); pass orthonormalize=True to project it to the nearest rotation"
            )));
        }
        Ok(s)
    }

    /// ZYX Euler angles of the attitude (paper eq. 21).
    pub fn euler(&self) -> Vector3<f64> {
        so3::euler_zyx(&self.q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_layout_is_contiguous_and_round_trips() {
        let mut off = 0;
        for (_, o, len) in LAYOUT {
            assert_eq!(o, off);
            off += len;
        }
        assert_eq!(off, STATE_DIM);
        let y = SVector::<f64, STATE_DIM>::from_fn(|i, _| i as f64 * 1.5 - 3.0);
        assert_eq!(VesselState::from_vector(&y).to_vector(), y);
    }

    #[test]
    fn user_states_are_checked() {
        let mut y = VesselState::from_vector(&SVector::zeros());
        y.q = Matrix3::identity();
        let ok = y.to_vector();
        assert!(VesselState::from_slice_checked(ok.as_slice(), false).is_ok());
        let e = VesselState::from_slice_checked(&ok.as_slice()[..26], false).unwrap_err();
        assert!(e.to_string().contains("got 26"));
        let mut bad = ok;
        bad[18] = f64::NAN;
        let e = VesselState::from_slice_checked(bad.as_slice(), false).unwrap_err();
        assert!(e.to_string().contains("entry 18 (x)"), "{e}");
        let mut refl = ok;
        refl[14] = -1.0; // Q = diag(1, 1, −1): a reflection
        for ortho in [false, true] {
            let e = VesselState::from_slice_checked(refl.as_slice(), ortho).unwrap_err();
            assert!(e.to_string().contains("det Q"), "{e}");
        }
        let mut scaled = ok;
        scaled[6] = 1.1;
        assert!(VesselState::from_slice_checked(scaled.as_slice(), false).is_err());
        let s = VesselState::from_slice_checked(scaled.as_slice(), true).unwrap();
        assert!(so3::orthogonality_defect(&s.q) < 1e-15);
    }
}
