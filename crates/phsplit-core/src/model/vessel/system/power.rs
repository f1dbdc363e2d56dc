//! The ledger's power at a state: each account's `±ν·f` from the booked rows of flow S2, the
//! rows on the other system's position, and the forcing (docs/model.md §3.5).

use super::super::forces::{Forcing, S2Builder};
use super::super::state::VesselState;
use super::VesselSystem;
use crate::flows::collocation::Z3;
use crate::solve::{AccountKind, Work};

impl VesselSystem<'_> {
    pub(super) fn sign(&self, k: usize) -> f64 {
        match self.accounts[k].kind {
            AccountKind::Supplied => 1.0,
            AccountKind::Dissipated => -1.0,
        }
    }

    /// Power per account at block states `z`, from the booked rows: `±(M⁻¹u)·f`.
    pub(super) fn power_at(&self, b: &S2Builder, z: &[Z3; 2]) -> Work {
        let booked = b.booked.as_deref().expect("assembled with the ledger");
        let nu = self.vessel.body.velocity(&z[0][0], &z[1][0]);
        let mut w = Work::from_fn(self.accounts.len(), |k| {
            let mut p = 0.0;
            for sys in 0..2 {
                p += nu[sys].dot(&booked[k][sys].at(&nu, &z[sys]));
            }
            self.sign(k) * p
        });
        for (a, sys, r) in &b.cross_booked {
            let k = *sys as usize;
            w.add(*a, self.sign(*a) * nu[k].dot(&(r * z[1 - k][1])));
        }
        w
    }

    /// The power per account at `s` and time `t` (W).
    pub fn power(&self, s: &VesselState, t: f64, on: bool) -> Work {
        let fr = self.frozen(s, on);
        let b = self.s2_of(&fr, true);
        let z = self.blocks_of(s);
        let mut w = self.power_at(&b, &z);
        if self.forced {
            let g = self.forcing(&fr, t, &z, &s.own);
            w += self.forcing_power(&[&g], &z);
        }
        w
    }

    /// The power per account of the sum of the forcings `gs` at block states `z`: `±(M⁻¹u)·f`.
    pub(super) fn forcing_power(&self, gs: &[&Forcing], z: &[Z3; 2]) -> Work {
        let nu = self.vessel.body.velocity(&z[0][0], &z[1][0]);
        Work::from_fn(self.accounts.len(), |k| {
            let mut p = 0.0;
            for g in gs {
                let f = g.booked(k);
                p += nu[0].dot(&f[0]) + nu[1].dot(&f[1]);
            }
            self.sign(k) * p
        })
    }
}
