//! The vessel's state and its one flat layout (paper §3.4; docs/model.md §2).

use crate::error::{Error, Result};
use crate::lie::so3;
use nalgebra::{Matrix3, SVector, Vector3};

/// The state of the vessel (27 numbers with `Q` stored as a matrix).
#[derive(Debug, Clone, Copy, PartialEq)]
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
        }
    }

    /// Whether every component is finite.
    pub fn is_finite(&self) -> bool {
        self.parts().iter().all(|p| p.iter().all(|v| v.is_finite()))
    }

    /// A state from a flat vector given by a user: the right length, finite, and with an
    /// attitude that is a rotation (or, with `orthonormalize`, projected to the nearest one).
    /// A state that continues a run (the last state of an earlier call of the same run): only
    /// its length and finiteness are checked. An explicit Runge–Kutta method lets `Q` drift off
    /// SO(3) by its own error, and the continuation must take the state as it is, so that a run
    /// cut into several calls gives the same numbers as one call.
    pub fn from_slice_continuing(y: &[f64]) -> Result<Self> {
        if y.len() != STATE_DIM {
            return Err(Error::InvalidInput(format!(
                "a state is a flat vector of {STATE_DIM} numbers, got {}",
                y.len()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "the state to continue from must be finite; entry {i} is {}",
                y[i]
            )));
        }
        Ok(Self::from_vector(
            &SVector::<f64, STATE_DIM>::from_column_slice(y),
        ))
    }

    pub fn from_slice_checked(y: &[f64], orthonormalize: bool) -> Result<Self> {
        if y.len() != STATE_DIM {
            return Err(Error::InvalidInput(format!(
                "a state is a flat vector of {STATE_DIM} numbers (p, m, Q column-major, mu, x, phi_th, phi_x), got {}",
                y.len()
            )));
        }
        if let Some(i) = y.iter().position(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "the initial state must be finite; entry {i} ({}) is {}",
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
