//! The last frozen view and flow S2 assembled, kept for the next sub-step that needs the same.
//!
//! Flow S2's assembly (the frozen view's Euler angles, every component's rows, each account's
//! booked rows) depends on the state only through the attitude `Q` and whether the controller
//! acts, and, for a component with a forcing part, the velocities `ν₀` it linearises at and the
//! actuators' memory ([`Frozen::velocity`], [`Frozen::actuators`]: only such components read
//! them). Only flow S1 changes `Q`. So in a composition that begins and ends with S2 (SP2 is
//! `S2(h/2) S1(h) S2(h/2)`), the S2 that ends a step and the S2 that begins the next are
//! assembled at the same attitude, and so is the probe after the step. The assembly is kept
//! with the bits of what it was built from and reused when they match bit for bit (`Q`, the
//! controller, the ledger; and the momenta and the actuators' memory when a component has a
//! forcing part), with the view's velocities and memory set to the new state's: a run's
//! numbers are the same as without it.

use super::super::forces::{Frozen, S2Builder};
use super::super::state::{Actuators, VesselState};
use super::VesselSystem;
use std::sync::Mutex;

/// What an assembly depends on, bit for bit: `Q`, the controller's state, and, where a component
/// has a forcing part, the momenta `p`, `m` and the actuators' memory. An assembly with the
/// ledger (each account's rows) serves a sub-step without it too.
#[derive(Clone, Copy)]
struct Key {
    q: nalgebra::Matrix3<f64>,
    on: bool,
    p: nalgebra::Vector3<f64>,
    m: nalgebra::Vector3<f64>,
    act: Actuators,
}

/// Whether `a` and `b` have the same bits (so `0.0` and `-0.0` differ, and a NaN is never kept).
fn same<'x>(a: impl IntoIterator<Item = &'x f64>, b: impl IntoIterator<Item = &'x f64>) -> bool {
    a.into_iter()
        .zip(b)
        .all(|(x, y)| x.to_bits() == y.to_bits() && !x.is_nan())
}

impl Key {
    fn of(s: &VesselState, on: bool) -> Self {
        Key {
            q: s.q,
            on,
            p: s.p,
            m: s.m,
            act: s.act,
        }
    }
    /// Whether an assembly at `s` would be this one's; `whole`: a component has a forcing part.
    fn matches(&self, s: &VesselState, on: bool, whole: bool) -> bool {
        let (a, b) = (&self.act, &s.act);
        self.on == on
            && same(&self.q, &s.q)
            && (!whole
                || (same(&self.p, &s.p)
                    && same(&self.m, &s.m)
                    && a.n == b.n
                    && same([&a.t], [&b.t])
                    && same(&a.thrust, &b.thrust)
                    && same(&a.angle, &b.angle)))
    }
}

struct Entry<'a> {
    key: Key,
    fr: Frozen<'a>,
    b: S2Builder,
}

/// The kept assembly of one vessel system. A system shared by threads that step at once keeps
/// it for one of them; the others assemble as if there were none.
#[derive(Default)]
pub(super) struct S2Memo<'a>(Mutex<Option<Entry<'a>>>);

impl Clone for S2Memo<'_> {
    /// A copy of the system starts with nothing kept.
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl std::fmt::Debug for S2Memo<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("S2Memo")
    }
}

impl<'a> VesselSystem<'a> {
    /// Call `f` with the frozen view of a sub-step that starts at `s` and flow S2 assembled
    /// there (with `ledger`, each account's rows too), reusing the last assembly when it was
    /// made from the same bits.
    pub(super) fn with_s2<R>(
        &self,
        s: &VesselState,
        on: bool,
        ledger: bool,
        f: impl FnOnce(&Frozen<'a>, &S2Builder) -> R,
    ) -> R {
        let Ok(mut guard) = self.s2_memo.0.try_lock() else {
            // In use by another thread (or poisoned by a panic): assemble here.
            let fr = self.frozen(s, on);
            return f(&fr, &self.s2_of(&fr, ledger));
        };
        let entry = match &mut *guard {
            Some(e) if e.key.matches(s, on, self.forced) && (e.b.booked.is_some() || !ledger) => {
                e.fr.velocity = self.vessel.body.velocity(&s.p, &s.m);
                e.fr.actuators = s.act;
                e
            }
            Some(e) => {
                e.key = Key::of(s, on);
                e.fr = self.frozen(s, on);
                self.s2_into(&e.fr, ledger, &mut e.b);
                e
            }
            None => {
                let fr = self.frozen(s, on);
                let b = self.s2_of(&fr, ledger);
                guard.insert(Entry {
                    key: Key::of(s, on),
                    fr,
                    b,
                })
            }
        };
        serve(entry, ledger, f)
    }
}

/// `f` on the kept assembly, without the accounts' rows if the sub-step has no ledger.
fn serve<'a, R>(
    e: &mut Entry<'a>,
    ledger: bool,
    f: impl FnOnce(&Frozen<'a>, &S2Builder) -> R,
) -> R {
    if ledger {
        return f(&e.fr, &e.b);
    }
    let rows = e.b.booked.take();
    let r = f(&e.fr, &e.b);
    e.b.booked = rows;
    r
}

#[cfg(test)]
mod tests {
    use super::super::super::forces::Force;
    use super::super::super::{Vessel, PRESETS};
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    fn moving(v: &Vessel) -> VesselState {
        let mut s = v.initial_state();
        s.p = Vector3::new(1e5, -2e4, 3e3);
        s.m = Vector3::new(2e4, 3e4, -1e5);
        s.q = Rotation3::from_euler_angles(0.02, -0.01, 0.4).into_inner();
        s
    }

    /// The kept assembly is the one a fresh assembly gives, twice over; where no component has
    /// a forcing part, a new momentum is served from it with the new velocities in the view;
    /// where one has (the quadratic damping linearises at `ν₀`), a new momentum rebuilds it; a
    /// new attitude rebuilds it always.
    #[test]
    fn the_kept_assembly_is_a_fresh_one_and_rebuilt_when_what_it_reads_changes() {
        let text = format!(
            "{}\n[damping_quadratic]\ncoefficients = [4e3, 1.75e5, 2e5, 3e8, 4e9, 2e10]\n",
            super::super::super::PAPER_VESSEL_TOML
        );
        let quadratic = Vessel::from_toml_str(&text).unwrap();
        for v in [Vessel::paper(), quadratic] {
            let sys = VesselSystem::new(&v, Some(0.0));
            let mut s = moving(&v);
            for ledger in [true, false] {
                for on in [true, false] {
                    let fresh = sys.s2_of(&sys.frozen(&s, on), ledger);
                    for _ in 0..2 {
                        sys.with_s2(&s, on, ledger, |fr, b| {
                            assert_eq!(b.sys, fresh.sys);
                            assert_eq!(b.cross, fresh.cross);
                            assert_eq!(b.booked, fresh.booked);
                            assert_eq!(fr.euler, sys.frozen(&s, on).euler);
                        });
                    }
                }
            }
            let before = sys.with_s2(&s, true, true, |_, b| b.sys);
            // A new linear momentum, then a new angular one.
            for change in [
                |s: &mut VesselState| s.p *= 3.0,
                |s: &mut VesselState| s.m *= 2.0,
            ] {
                let last = sys.with_s2(&s, true, true, |_, b| b.sys);
                change(&mut s);
                let fresh = sys.s2_of(&sys.frozen(&s, true), true);
                sys.with_s2(&s, true, true, |fr, b| {
                    assert_eq!(fr.velocity, sys.frozen(&s, true).velocity);
                    assert_eq!(b.sys, fresh.sys);
                    assert_eq!(b.booked, fresh.booked);
                    // The paper's rows do not depend on the momenta; the linearised drag's do.
                    assert_eq!(b.sys == last, !sys.forced);
                });
            }
            s.q = Rotation3::from_euler_angles(0.1, -0.05, 0.3).into_inner();
            let fresh = sys.s2_of(&sys.frozen(&s, true), true);
            sys.with_s2(&s, true, true, |_, b| {
                assert_eq!(b.sys, fresh.sys);
                assert_ne!(b.sys, before);
            });
        }
    }

    /// What lets the kept assembly leave the momenta and the actuators' memory out of its key
    /// where no component has a forcing part: no component without one reads them. Each such
    /// component of every preset, of the paper's vessel with an external load and a current,
    /// and of the pipe-lay vessel gives the same rows at rest and with velocities and a memory.
    #[test]
    fn components_without_a_forcing_part_read_neither_velocities_nor_memory() {
        let mut vessels: Vec<Vessel> = PRESETS
            .iter()
            .map(|p| Vessel::preset(p.0).unwrap())
            .collect();
        vessels.push(
            Vessel::from_toml_str(&format!(
                "{}\n[external]\nforce = [2e5, -1e5, 3e4]\nmoment = [1e6, 0, -2e6]\npoint = [-40, 5, 3]\n[current]\nvelocity = [0.6, -0.8, 0.0]\n",
                super::super::super::PAPER_VESSEL_TOML
            ))
            .unwrap(),
        );
        let scenario: toml::Table =
            include_str!("../../../../../../python/src/phsplit/scenarios/pipelay.toml")
                .parse()
                .unwrap();
        let mut table: toml::Table = super::super::super::PAPER_VESSEL_TOML.parse().unwrap();
        for k in ["setpoint", "pipe", "thrusters"] {
            table.insert(k.into(), scenario[k].clone());
        }
        vessels.push(Vessel::from_table(table).unwrap());
        let mut checked = 0;
        for v in &vessels {
            let sys = VesselSystem::new(v, Some(0.0));
            let s = moving(v);
            let rest = sys.frozen_at(&s.q, true);
            let mut going = sys.frozen(&s, true);
            going.actuators.n = 2;
            going.actuators.t = 3.0;
            going.actuators.thrust[..2].copy_from_slice(&[0.4, -0.2]);
            going.actuators.angle[..2].copy_from_slice(&[1.0, -0.5]);
            assert!(going.velocity[0].norm() > 0.0 && going.velocity[1].norm() > 0.0);
            let assemble = |f: &dyn Force, base: usize, fr: &Frozen| {
                let mut b = S2Builder::new(Some(sys.accounts.len()));
                b.base = base;
                f.add_s2(fr, &mut b);
                b.finish(&v.body.minv_blocks, v.body.is_diagonal());
                (b.sys, b.cross, b.booked)
            };
            for (f, &base) in v.forces.iter().zip(&sys.bases) {
                if !f.forced() {
                    assert_eq!(
                        assemble(f.as_ref(), base, &rest),
                        assemble(f.as_ref(), base, &going),
                        "{} reads the velocities or the actuators' memory",
                        f.name()
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked >= 12, "{checked}");
    }
}
