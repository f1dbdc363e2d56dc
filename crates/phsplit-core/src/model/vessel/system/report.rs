//! What the vessel reports at a state, for the results and the probe: the components'
//! outputs, the force and moment of each ledger account, and the controller's wrench.

use super::super::forces::{Force, Forcing, Frozen, Output, S2Builder, Sys};
use super::super::state::VesselState;
use super::VesselSystem;
use crate::solve::Role;
use nalgebra::Vector3;

/// Whether a component books to one of the controller's accounts ([`Role::Control`]): its P,
/// I and D parts, or what its thrusters deliver.
fn controls(f: &dyn Force) -> bool {
    f.accounts().iter().any(|a| a.role == Role::Control)
}

impl VesselSystem<'_> {
    /// The quantities the components report at `s` and time `t` ([`super::forces::Force::outputs`]).
    pub fn outputs(&self, s: &VesselState, t: f64) -> Vec<Output> {
        let mut out = Vec::new();
        let fr = self.frozen(s, self.control_on(t));
        let z = self.blocks_of(s);
        for f in &self.vessel.forces {
            f.outputs(&fr, &z, s, t, &mut out);
        }
        // The components' own states, as they declare them, and what they report from them.
        for (f, r) in self.vessel.own_layout() {
            for (o, v) in f.own_states().iter().zip(&s.own[r.clone()]) {
                out.push(Output::new(
                    o.name.clone(),
                    intern_unit(&o.unit),
                    o.long_name.clone(),
                    *v,
                ));
            }
            f.own_outputs(&fr, &z, &s.own[r], t, &mut out);
        }
        out
    }

    /// The force (N) and moment (N m) on the body, body frame, of each account at `s` and
    /// time `t`.
    pub fn account_wrenches(
        &self,
        s: &VesselState,
        t: f64,
        on: bool,
    ) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        // The assembly with each account's rows, kept as a sub-step's is (`memo.rs`: the same
        // bits as a fresh one, without a new allocation for each state reported).
        self.with_s2(s, on, true, false, |fr, b| {
            let booked = b.booked.as_deref().expect("built with the ledger");
            let z = self.blocks_of(s);
            let nu = self.vessel.body.velocity(&s.p, &s.m);
            let g = self.forcing(fr, t, &z, &s.own);
            let mut f: Vec<[Vector3<f64>; 2]> = (0..self.accounts.len())
                .map(|k| {
                    [
                        booked[k][0].at(&nu, &z[0]) + g.booked(k)[0],
                        booked[k][1].at(&nu, &z[1]) + g.booked(k)[1],
                    ]
                })
                .collect();
            b.add_cross_booked(&z, &mut f);
            // A subsystem's force on the hull (its account books what it dissipates).
            if self.own_dim > 0 {
                let mut rates = vec![0.0; s.own.len()];
                let own = self.own_wrenches(fr, &z, &s.own);
                for (acc, w) in own
                    .into_iter()
                    .chain(self.own_flow_field(fr, s, &mut rates))
                {
                    f[acc][0] += w[0];
                    f[acc][1] += w[1];
                }
            }
            f.into_iter().map(|[f, m]| (f, m)).collect()
        })
    }

    /// The controller's force and moment (body frame, about the body origin) at `s` on a step
    /// that starts at `t`: the sum of [`Self::account_wrenches`] over the accounts of [`Role::Control`]. The
    /// probe runs after every step, at the state the next step starts from: the whole of flow
    /// S2 is assembled (with each account's rows) and kept, and the next step's first sub-step,
    /// when it is S2, uses it (`system/memo.rs`); where it is not S2, the probe assembles the
    /// components that book to the controller's accounts alone.
    pub(super) fn control_wrench(&self, s: &VesselState, t: f64) -> (Vector3<f64>, Vector3<f64>) {
        let on = self.control_on(t);
        let z = self.blocks_of(s);
        let wrench = |fr: &Frozen, b: &S2Builder| {
            let booked = b.booked.as_deref().expect("assembled with the ledger");
            let mut g = Forcing::new();
            let (mut force, mut moment) = (Vector3::zeros(), Vector3::zeros());
            let mut off = 0;
            for (f, &base) in self.vessel.forces.iter().zip(&self.bases) {
                let n = f.own_states().len();
                off += n;
                if !controls(f.as_ref()) {
                    continue;
                }
                if f.forced() {
                    g.base = base;
                    g.own_base = off - n;
                    let own = s.own.get(off - n..off).unwrap_or(&[]);
                    f.add_forcing_own(fr, t, &z, own, &mut g);
                }
                for (i, a) in f.accounts().iter().enumerate() {
                    if a.role == Role::Control {
                        let k = base + i;
                        force += booked[k][0].at(&fr.velocity, &z[0]) + g.booked(k)[0];
                        moment += booked[k][1].at(&fr.velocity, &z[1]) + g.booked(k)[1];
                    }
                }
            }
            for (k, sys, r) in &b.cross_booked {
                if self.accounts[*k].role == Role::Control {
                    let f = r * z[1 - *sys as usize][1];
                    match sys {
                        Sys::Trans => force += f,
                        Sys::Rot => moment += f,
                    }
                }
            }
            // A controller with states of its own (an observer): its force on the hull.
            if self.own_linear_dim > 0 {
                for (k, w) in self.own_wrenches(fr, &z, &s.own) {
                    if self.accounts[k].role == Role::Control {
                        force += w[0];
                        moment += w[1];
                    }
                }
            }
            (force, moment)
        };
        if self.probe_assembles_whole() {
            return self.with_s2(s, on, true, true, |fr, b| wrench(fr, b));
        }
        let fr = self.frozen(s, on);
        let mut b = S2Builder::new(Some(self.accounts.len()));
        for (f, &base) in self.vessel.forces.iter().zip(&self.bases) {
            if controls(f.as_ref()) {
                b.base = base;
                f.add_s2(&fr, &mut b);
            }
        }
        wrench(&fr, &b)
    }
}

/// A unit as the `&'static str` of an [`Output`]: the usual ones as written, any other
/// interned (one allocation per distinct unit).
fn intern_unit(u: &str) -> &'static str {
    use std::collections::HashSet;
    use std::sync::{Mutex, OnceLock};
    static UNITS: OnceLock<Mutex<HashSet<&'static str>>> = OnceLock::new();
    let mut set = UNITS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    if let Some(k) = set.get(u) {
        return k;
    }
    let k: &'static str = Box::leak(u.to_string().into_boxed_str());
    set.insert(k);
    k
}
