//! A constant external force and moment at a point of the hull: the `X` of the paper's
//! eq. (1), `M ν' + C(ν)ν + D(ν)ν + g(η) = τ + X + w` (docs/model.md §5).
//!
//! Table `[external]` (optional): `force` (N) and `moment` (N m), given in the body frame
//! (`frame = "body"`, the default) or in the spatial frame (`frame = "spatial"`: z up, the
//! frame of the position `x`; they then keep their spatial direction as the vessel turns),
//! applied at `point` (m, body frame, from the body origin). The body-frame force and moment
//! are `f_b = F`, `m_b = M + r × F` (body) or `f_b = QᵀF`, `m_b = QᵀM + r × QᵀF` (spatial).
//!
//! Constant at frozen attitude, it enters flow S2 as an affine term. Its power
//! `ν·τ_ext = v·f_b + w·m_b` is booked as the work of the port `external` (supplied).
//! The split stays passive with respect to its ports, so the ledger closes as before.

use super::{Force, Frozen, Rows, S2Builder, Sys};
use crate::error::Error;
use crate::model::vessel::params::{Params, Range};
use crate::solve::Account;
use nalgebra::Vector3;
use std::sync::Arc;

/// The frame a constant load is given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    Body,
    Spatial,
}

#[derive(Debug, Clone, PartialEq)]
pub struct External {
    pub force: Vector3<f64>,
    pub moment: Vector3<f64>,
    pub point: Vector3<f64>,
    pub frame: Frame,
}

/// Largest distance of the point of application from the body origin (m): a load further
/// out than this is not on a hull.
pub const MAX_ARM: f64 = 1000.0;

pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    const T: &str = "external";
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let force = p.vec3(T, "force", Some([0.0; 3]), "N", Range::Finite)?;
    let moment = p.vec3(T, "moment", Some([0.0; 3]), "N m", Range::Finite)?;
    let point = p.vec3(T, "point", Some([0.0; 3]), "m, body frame", Range::Finite)?;
    let frame = match p.choice(T, "frame", &["body", "spatial"])? {
        "spatial" => Frame::Spatial,
        _ => Frame::Body,
    };
    for (i, r) in point.iter().enumerate() {
        if r.abs() > MAX_ARM {
            return Err(Error::InvalidInput(format!(
                "external.point[{i}] must lie within {MAX_ARM} m of the body origin (m, body frame), got {r}"
            )));
        }
    }
    Ok(Some(Arc::new(External {
        force: force.into(),
        moment: moment.into(),
        point: point.into(),
        frame,
    })))
}

const ACCOUNTS: [Account; 1] = [Account::supplied("external")];

impl External {
    /// The body-frame force and moment (about the body origin) at attitude `Qᵀ = qt`.
    pub fn body_wrench(&self, qt: &nalgebra::Matrix3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let (f, m) = match self.frame {
            Frame::Body => (self.force, self.moment),
            Frame::Spatial => (qt * self.force, qt * self.moment),
        };
        (f, m + self.point.cross(&f))
    }
}

impl Force for External {
    fn name(&self) -> &'static str {
        "external"
    }
    fn accounts(&self) -> &'static [Account] {
        &ACCOUNTS
    }
    fn add_s2(&self, fr: &Frozen, b: &mut S2Builder) {
        let (f, m) = self.body_wrench(&fr.qt);
        b.force(Sys::Trans, Some(0), &Rows::constant(f));
        b.force(Sys::Rot, Some(0), &Rows::constant(m));
    }
}
