//! The last few frozen views and flows S2 assembled, kept for the next sub-steps that need the
//! same.
//!
//! Flow S2's assembly (the frozen view's Euler angles, every component's rows, each account's
//! booked rows) depends on the state only through the attitude `Q` and whether the controller
//! acts, and, for a component with a forcing part that it linearises in the assembly, the
//! velocities `ν₀` it linearises at and the actuators' memory ([`Frozen::velocity`],
//! [`Frozen::actuators`]: only such components read them, as each says by
//! [`assembly_reads_motion`](super::super::forces::Force::assembly_reads_motion)).
//! The assembly is kept with the bits of what it was built from and reused when they match bit
//! for bit (`Q`, the controller; and the momenta and the actuators' memory when a component's
//! part reads them), with the view's velocities and memory set to the new state's;
//! one made with the ledger's rows serves a sub-step without the ledger too. A run's numbers are
//! the same as without it.
//!
//! Where it is reused:
//! - The probe after a step (the running maxima of a sweep's summary) and the next step's first
//!   sub-step, when that is S2 (S2 outermost, the default): both at the step's end state. The
//!   probe then assembles S2 whole instead of the controller's rows alone; where no sub-step
//!   takes that assembly (S1 outermost), the probe goes back to the controller's rows after the
//!   first step ([`S2Memo`] keeps which).
//! - Consecutive S2 sub-steps with nothing between them that turns `Q`: the S2 that ends a step,
//!   the probe and the S2 that begins the next, wherever the projection onto the restoring
//!   invariant (docs/model.md §3.6) leaves `Q` alone: without the projection, and with it
//!   wherever its turn is below its floor (4ε: most steps of a long run once the transient has
//!   passed). Sub-steps separated by S1 never share one.
//! - Adaptive steps (`solve/adaptive.rs`): the whole step and its first half both begin with S2
//!   at the step's start, and an output inside the step is one step from the step's start or
//!   from the end of its first half, where an assembly was made moments before. Each such
//!   assembly is still kept when it is asked again ([`KEPT`] of them, the least recently served
//!   replaced).
use super::super::forces::{Frozen, S2Builder};
use super::super::state::{Actuators, VesselState};
use super::VesselSystem;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering::Relaxed};
use std::sync::Mutex;

/// What an assembly depends on, bit for bit: `Q`, the controller's state, and the momenta `p`,
/// `m` and the actuators' memory where a component's part reads them
/// ([`Force::assembly_reads_motion`](super::super::forces::Force::assembly_reads_motion)). An
/// assembly with the ledger (each account's rows) serves a sub-step without it too.
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
    /// Whether an assembly at `s` would be this one's; `whole`: a component's part reads the
    /// momenta or the actuators' memory.
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
    /// Made by the probe, and since then reused by a sub-step.
    by_probe: bool,
    reused: bool,
    /// When it was last served ([`Kept::clock`]): the least recently served is replaced.
    served: u64,
}

/// How many assemblies are kept for a run that comes back to states (adaptive steps,
/// [`crate::solve::SplitModel::revisits_states`]; other runs keep one). An adaptive step
/// assembles S2 at its start twice (the whole step and its first half, `solve/adaptive.rs`),
/// and an output inside the step starts from the step's start or the end of its first half:
/// four keep each of those until it is asked again.
pub(super) const KEPT: usize = 4;

struct Kept<'a> {
    entries: Vec<Entry<'a>>,
    clock: u64,
    /// How many sub-steps were served a kept assembly.
    hits: u64,
}

/// The kept assemblies of one vessel system. A system shared by threads that step at once keeps
/// them for one of them; the others assemble as if there were none. Beside them, whether the
/// probe's whole assembly is taken by the next sub-step (until one was not): a flag of its own,
/// so that asking costs the probe no second lock a step (the locks were 5 % of a sweep's step).
/// Beside them too, how many it keeps ([`KEPT`] or one).
pub(super) struct S2Memo<'a>(Mutex<Kept<'a>>, AtomicBool, AtomicUsize);

impl Default for S2Memo<'_> {
    fn default() -> Self {
        Self(
            Mutex::new(Kept {
                entries: Vec::new(),
                clock: 0,
                hits: 0,
            }),
            AtomicBool::new(true),
            AtomicUsize::new(1),
        )
    }
}

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
    /// there (with `ledger`, each account's rows too), reusing a kept assembly made from the
    /// same bits; `by_probe`: the call is the probe's.
    pub(super) fn with_s2<R>(
        &self,
        s: &VesselState,
        on: bool,
        ledger: bool,
        by_probe: bool,
        f: impl FnOnce(&Frozen<'a>, &S2Builder) -> R,
    ) -> R {
        let Ok(mut guard) = self.s2_memo.0.try_lock() else {
            // In use by another thread (or poisoned by a panic): assemble here.
            let fr = self.frozen(s, on);
            return f(&fr, &self.s2_of(&fr, ledger));
        };
        let kept = &mut *guard;
        kept.clock += 1;
        let clock = kept.clock;
        let hit = kept.entries.iter().position(|e| {
            e.key.matches(s, on, self.assembly_reads_motion) && (e.b.booked.is_some() || !ledger)
        });
        let entry = if let Some(i) = hit {
            let e = &mut kept.entries[i];
            if e.by_probe && !by_probe {
                e.reused = true;
                self.s2_memo.1.store(true, Relaxed);
            }
            e.fr.velocity = self.vessel.body.velocity(&s.p, &s.m);
            e.fr.actuators = s.act;
            e.fr.held = self.held_of(s);
            e.served = clock;
            kept.hits += 1;
            &mut kept.entries[i]
        } else if kept.entries.len() < self.s2_memo.2.load(Relaxed) {
            let fr = self.frozen(s, on);
            let b = self.s2_of(&fr, ledger);
            kept.entries.push(Entry {
                key: Key::of(s, on),
                fr,
                b,
                by_probe,
                reused: false,
                served: clock,
            });
            kept.entries.last_mut().expect("just pushed")
        } else {
            // The least recently served is rebuilt in place (its allocation kept).
            let e = kept
                .entries
                .iter_mut()
                .min_by_key(|e| e.served)
                .expect("at least one kept");
            if e.by_probe && !e.reused {
                self.s2_memo.1.store(false, Relaxed);
            }
            e.key = Key::of(s, on);
            e.fr = self.frozen(s, on);
            e.by_probe = by_probe;
            e.reused = false;
            e.served = clock;
            self.s2_into(&e.fr, ledger, &mut e.b);
            e
        };
        serve(entry, ledger, f)
    }

    /// Keep up to `n` assemblies (at least one) from now on; the least recently served go
    /// beyond that.
    pub(super) fn keep_assemblies(&self, n: usize) {
        let n = n.max(1);
        self.s2_memo.2.store(n, Relaxed);
        if let Ok(mut kept) = self.s2_memo.0.try_lock() {
            if kept.entries.len() > n {
                kept.entries.sort_by_key(|e| std::cmp::Reverse(e.served));
                kept.entries.truncate(n);
            }
        }
    }

    /// Whether the probe should assemble S2 whole (its assembly is taken by the next sub-step)
    /// rather than the controller's rows alone.
    pub(super) fn probe_assembles_whole(&self) -> bool {
        self.s2_memo.1.load(Relaxed)
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
                        sys.with_s2(&s, on, ledger, false, |fr, b| {
                            assert_eq!(b.sys, fresh.sys);
                            assert_eq!(b.cross, fresh.cross);
                            assert_eq!(b.booked, fresh.booked);
                            assert_eq!(fr.euler, sys.frozen(&s, on).euler);
                        });
                    }
                }
            }
            let before = sys.with_s2(&s, true, true, false, |_, b| b.sys);
            // A new linear momentum, then a new angular one.
            for change in [
                |s: &mut VesselState| s.p *= 3.0,
                |s: &mut VesselState| s.m *= 2.0,
            ] {
                let last = sys.with_s2(&s, true, true, false, |_, b| b.sys);
                change(&mut s);
                let fresh = sys.s2_of(&sys.frozen(&s, true), true);
                sys.with_s2(&s, true, true, false, |fr, b| {
                    assert_eq!(fr.velocity, sys.frozen(&s, true).velocity);
                    assert_eq!(b.sys, fresh.sys);
                    assert_eq!(b.booked, fresh.booked);
                    // The paper's rows do not depend on the momenta; the linearised drag's do.
                    assert_eq!(b.sys == last, !sys.forced);
                });
            }
            s.q = Rotation3::from_euler_angles(0.1, -0.05, 0.3).into_inner();
            let fresh = sys.s2_of(&sys.frozen(&s, true), true);
            sys.with_s2(&s, true, true, false, |_, b| {
                assert_eq!(b.sys, fresh.sys);
                assert_ne!(b.sys, before);
            });
        }
    }

    /// An adaptive run takes kept assemblies (the whole step's and its first half's common
    /// start, an output's start), at least one per step tried, and gives the same bits as a run
    /// that assembles every sub-step afresh (its memo held by someone else).
    #[test]
    fn adaptive_steps_take_kept_assemblies_and_the_same_bits() {
        use crate::methods::{Method, Outer};
        use crate::solve::{run, Options, Tolerance};
        let v = Vessel::paper();
        let method: Method = "sp2".parse().unwrap();
        let opts = Options {
            outer: Outer::Dissipative,
            tolerance: Some(Tolerance {
                rtol: 1e-3,
                atol: 1e-3,
                h_max: 300.0,
                t1: 300.0,
                save_at: (1..30).map(|k| 10.0 * k as f64).collect(),
            }),
            ledger: true,
            ..Options::steps(0.0, 1.0, 300, 1)
        };
        let sys = VesselSystem::new(&v, Some(0.0));
        let kept = run(&sys, &method, v.initial_state(), &opts).unwrap();
        let hits = sys.s2_memo.0.lock().unwrap().hits as usize;
        assert!(hits >= kept.steps + kept.rejected, "{hits} {}", kept.steps);
        assert_eq!(sys.s2_memo.0.lock().unwrap().entries.len(), KEPT);
        // Fixed steps on the same system keep the last assembly only.
        let fixed = Options {
            tolerance: None,
            ..Options::steps(0.0, 1.0, 20, 5)
        };
        run(&sys, &method, v.initial_state(), &fixed).unwrap();
        assert_eq!(sys.s2_memo.0.lock().unwrap().entries.len(), 1);
        let fresh = VesselSystem::new(&v, Some(0.0));
        let held = fresh.s2_memo.0.lock().unwrap();
        let again = run(&fresh, &method, v.initial_state(), &opts).unwrap();
        drop(held);
        assert_eq!(fresh.s2_memo.0.lock().unwrap().hits, 0);
        assert_eq!(kept.t, again.t);
        assert_eq!(kept.energy, again.energy);
        for (a, b) in kept.states.iter().zip(&again.states) {
            assert_eq!((a.p, a.m, a.q, a.x, a.mu), (b.p, b.m, b.q, b.x, b.mu));
        }
    }

    /// The probe assembles S2 whole where the next sub-step takes it (S2 outermost) and goes
    /// back to the controller's rows where none does (S1 outermost); the probe's maxima are the
    /// same either way, to the bit.
    #[test]
    fn the_probe_assembles_whole_only_where_the_next_sub_step_takes_it() {
        use crate::methods::{Method, Outer};
        use crate::solve::{run, Options};
        let v = Vessel::paper();
        let method: Method = "sp2".parse().unwrap();
        let mut maxima = vec![];
        for (outer, whole) in [(Outer::Dissipative, true), (Outer::Conservative, false)] {
            let sys = VesselSystem::new(&v, Some(0.0)).with_extrema(true);
            let opts = Options {
                t0: 0.0,
                h: 0.5,
                n_steps: 40,
                last_h: 0.5,
                save_every: 10,
                outer,
                ledger: true,
                tolerance: None,
            };
            let tr = run(&sys, &method, v.initial_state(), &opts).unwrap();
            assert_eq!(sys.probe_assembles_whole(), whole, "{outer:?}");
            // The same maxima as the probe's own assembly of the controller's rows gives.
            let fresh = VesselSystem::new(&v, Some(0.0)).with_extrema(true);
            fresh.s2_memo.1.store(false, Relaxed);
            let again = run(&fresh, &method, v.initial_state(), &opts).unwrap();
            assert_eq!(tr.probe_max, again.probe_max);
            assert_eq!(tr.t, again.t);
            maxima.push(tr.probe_max);
        }
        assert!(maxima[0][0] > 0.0);
    }

    /// What lets the kept assembly leave the momenta and the actuators' memory out of its key
    /// where no component's part reads them
    /// ([`Force::assembly_reads_motion`](super::super::forces::Force::assembly_reads_motion)):
    /// each component that says so (every one without a forcing part, and the wind), of every preset, of the
    /// paper's vessel with an external load, a current and a gusting wind, and of the pipe-lay
    /// vessel, gives the same rows at rest and with velocities and a memory.
    #[test]
    fn components_whose_assembly_reads_no_motion_read_neither_velocities_nor_memory() {
        let mut vessels: Vec<Vessel> = PRESETS
            .iter()
            .map(|p| Vessel::preset(p.0).unwrap())
            .collect();
        vessels.push(
            Vessel::from_toml_str(&format!(
                "{}\n[external]\nforce = [2e5, -1e5, 3e4]\nmoment = [1e6, 0, -2e6]\npoint = [-40, 5, 3]\n[current]\nvelocity = [0.6, -0.8, 0.0]\n{}",
                super::super::super::PAPER_VESSEL_TOML,
                "[wind]\nspeed = 15.0\ndirection = 30.0\nfrontal_area = 182.0\nlateral_area = 533.0\nlength = 76.2\nair_density = 1.225\nangles = [0.0, 90.0, 180.0, 270.0]\ncx = [0.6, 0.0, -0.7, 0.0]\ncy = [0.0, 0.9, 0.0, -0.9]\ncn = [0.0, 0.05, 0.0, -0.05]\ngust_frequencies = [0.05, 0.2]\ngust_amplitudes = [1.0, 0.5]\ngust_phases = [0.3, 2.0]\n"
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
                if !f.assembly_reads_motion() {
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
        assert!(checked >= 13, "{checked}");
    }
}
