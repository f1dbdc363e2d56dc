//! An FMU instance: the values of its parameters and inputs, the standard's mode, and the vessel
//! stepped between communication points by phsplit's kernels (docs/fmu.md, "Stepping").

use crate::layout::{Causality, Kind, Layout, Result, Role, Type, Val, Variable};
use nalgebra::Vector3;
use phsplit_core::lie::so3;
use phsplit_core::model::vessel::{Vessel, VesselState, VesselSystem};
use phsplit_core::settings::Settings;
use phsplit_core::solve::{run, Model, Options, Role as AccountRole, Status};
use std::sync::Arc;
use toml::{Table, Value};

#[derive(Debug, Clone)]
struct Running {
    vessel: Arc<Vessel>,
    /// The inputs the vessel was built with.
    inputs: Vec<f64>,
    settings: Settings,
    state: VesselState,
    /// Energy booked per account, supplied and dissipated since the start (J).
    booked: Vec<f64>,
    supplied: f64,
    dissipated: f64,
}

/// The FMI 2.0 co-simulation state of an instance (the standard's state machine).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// After `fmi2Instantiate`: parameters and the experiment can be set.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization,
    /// After `fmi2ExitInitializationMode`: `fmi2DoStep`.
    Stepping,
    /// After `fmi2Terminate`.
    Terminated,
}

/// An FMU instance: its mode, the current values of the parameters and inputs, the experiment,
/// the time, and (after initialisation) the vessel's state. `Clone` is the FMU state of
/// `fmi2GetFMUstate`: all of it, the mode included.
#[derive(Debug, Clone)]
pub struct Instance {
    pub layout: Arc<Layout>,
    values: Vec<Option<Val>>,
    pub mode: Mode,
    /// `startTime` and `stopTime` of `fmi2SetupExperiment`.
    pub start_time: f64,
    pub stop_time: Option<f64>,
    pub time: f64,
    running: Option<Running>,
    /// The accounts' wrenches and the components' outputs at the current state, computed for
    /// the first output read and reused by the others until time, state or vessel change.
    reports: Reports,
}

/// What the outputs are read from at one state: the key (time, vessel, state, bit for bit),
/// each account's force and moment, and each component output's value.
type Report = (Vec<u64>, Vec<(Vector3<f64>, Vector3<f64>)>, Vec<f64>);

/// The kept [`Report`]; a copy of an instance (its saved state) starts without one.
#[derive(Debug, Default)]
struct Reports(std::sync::Mutex<Option<Report>>);

impl Clone for Reports {
    fn clone(&self) -> Self {
        Self::default()
    }
}

/// The components the inputs act through, and the tables they read.
const INPUT_COMPONENTS: [&str; 3] = ["pid", "external", "current"];
const INPUT_TABLES: [&str; 6] = [
    "vessel",
    "control",
    "setpoint",
    "thrusters",
    "external",
    "current",
];

/// How far a communication point may be from the instance's time (relative).
const TIME_TOLERANCE: f64 = 1e-9;

impl Instance {
    pub fn new(layout: Arc<Layout>) -> Self {
        let values = layout.vars.iter().map(|v| v.start.clone()).collect();
        Self {
            layout,
            values,
            mode: Mode::Instantiated,
            start_time: 0.0,
            stop_time: None,
            time: 0.0,
            running: None,
            reports: Reports::default(),
        }
    }

    /// Whether parameters are fixed (after initialisation).
    pub fn initialized(&self) -> bool {
        matches!(self.mode, Mode::Stepping | Mode::Terminated)
    }

    /// Set several values at once: all or none (the first bad one is named).
    pub fn set_many(&mut self, items: Vec<(u32, Val)>) -> Result<()> {
        let before = self.values.clone();
        let init = self.initialized();
        for (vr, val) in items {
            if let Err(e) = self.set(vr, val, init) {
                self.values = before;
                return Err(e);
            }
        }
        Ok(())
    }

    fn var(&self, vr: u32, ty: Type) -> Result<&Variable> {
        let v = self.layout.vars.get(vr as usize).ok_or_else(|| {
            format!(
                "no variable has value reference {vr} (this FMU has {})",
                self.layout.vars.len()
            )
        })?;
        if v.ty != ty {
            return Err(format!(
                "variable {} (value reference {vr}) is of type {:?}, not {ty:?}",
                v.name, v.ty
            ));
        }
        Ok(v)
    }

    /// Set a parameter or input. Parameters are fixed once initialised (`initialized`).
    pub fn set(&mut self, vr: u32, val: Val, initialized: bool) -> Result<()> {
        let ty = match val {
            Val::Real(_) => Type::Real,
            Val::Boolean(_) => Type::Boolean,
            Val::String(_) => Type::String,
        };
        let v = self.var(vr, ty)?;
        match v.causality {
            Causality::Output => Err(format!("{} is an output and cannot be set", v.name)),
            Causality::Parameter if initialized => Err(format!(
                "{} is a fixed parameter and cannot be set after initialisation",
                v.name
            )),
            _ => {
                self.values[vr as usize] = Some(val);
                Ok(())
            }
        }
    }

    fn real(&self, role: Role) -> f64 {
        match self
            .layout
            .index_of(&role)
            .and_then(|i| self.values[i].clone())
        {
            Some(Val::Real(x)) => x,
            _ => 0.0,
        }
    }

    fn setting(&self, name: &'static str) -> Option<Val> {
        self.layout
            .index_of(&Role::Setting(name))
            .and_then(|i| self.values[i].clone())
    }

    /// The current values of the inputs, in table order.
    fn inputs(&self) -> Vec<f64> {
        self.layout
            .vars
            .iter()
            .zip(&self.values)
            .filter(|(v, _)| v.causality == Causality::Input)
            .map(|(_, x)| match x {
                Some(Val::Real(r)) => *r,
                _ => 0.0,
            })
            .collect()
    }

    /// The vessel file with the parameters and inputs applied.
    fn vessel_table(&self) -> Result<Table> {
        self.vessel_tables(None)
    }

    /// [`Self::vessel_table`], only the tables `only` (all with `None`): the components the
    /// inputs act through read these, and the others (wave and wind tables) are large.
    fn vessel_tables(&self, only: Option<&[&str]>) -> Result<Table> {
        let mut t: Table = match only {
            None => self.layout.base.clone(),
            Some(names) => self
                .layout
                .base
                .iter()
                .filter(|(k, _)| names.contains(&k.as_str()))
                .map(|(k, v)| (k.clone(), v.clone()))
                .collect(),
        };
        for (v, val) in self.layout.vars.iter().zip(&self.values) {
            if let (Role::VesselNumber { table, key, index }, Some(Val::Real(x))) = (&v.role, val) {
                if !t.contains_key(table) {
                    continue;
                }
                let slot = t
                    .get_mut(table)
                    .and_then(|s| s.as_table_mut())
                    .and_then(|s| s.get_mut(key))
                    .ok_or_else(|| format!("internal: {table}.{key} missing"))?;
                match (index, slot) {
                    (None, slot) => *slot = Value::Float(*x),
                    (Some(i), Value::Array(a)) => a[*i] = Value::Float(*x),
                    _ => return Err(format!("internal: {table}.{key} is not an array")),
                }
            }
        }
        let get = |g: &'static str, i: usize| self.real(Role::Group(g, i));
        let frame = match self.setting("external_frame") {
            Some(Val::String(s)) => s,
            _ => "body".into(),
        };
        let (mut f, mut m) = (
            Vector3::from_fn(|i, _| get("external_force", i)),
            Vector3::from_fn(|i, _| get("external_moment", i)),
        );
        let frame = match frame.as_str() {
            "body" | "spatial" => frame,
            "ned" => {
                // NED (north, east, down) from the spatial frame read as north-west-up: a
                // half-turn about north, a rotation, so force and moment transform alike.
                f = Vector3::new(f.x, -f.y, -f.z);
                m = Vector3::new(m.x, -m.y, -m.z);
                "spatial".into()
            }
            other => {
                return Err(format!(
                    "external_frame must be 'body', 'spatial' or 'ned', got {other:?}"
                ))
            }
        };
        let arr = |v: Vector3<f64>| Value::Array(v.iter().map(|x| Value::Float(*x)).collect());
        if let Some(Value::Table(e)) = t.get_mut("external") {
            e.insert("force".into(), arr(f));
            e.insert("moment".into(), arr(m));
            e.insert("frame".into(), Value::String(frame));
        }
        if self.layout.index_of(&Role::Group("setpoint", 0)).is_some() {
            if let Some(Value::Table(c)) = t.get_mut("control") {
                for (key, i, g) in [
                    ("position_reference", 0, 0),
                    ("position_reference", 1, 1),
                    ("euler_reference", 2, 2),
                ] {
                    if let Some(Value::Array(a)) = c.get_mut(key) {
                        a[i] = Value::Float(get("setpoint", g));
                    }
                }
            }
        }
        if self.layout.index_of(&Role::Group("current", 0)).is_some() {
            if let Some(Value::Table(c)) = t.get_mut("current") {
                if let Some(Value::Array(a)) = c.get_mut("velocity") {
                    a[0] = Value::Float(get("current", 0));
                    a[1] = Value::Float(get("current", 1));
                }
            }
        }
        Ok(t)
    }

    /// The run settings from the parameters, validated by the core.
    fn settings(&self) -> Result<Settings> {
        let mut t = Table::new();
        for name in ["method", "linear_flow", "outer"] {
            if let Some(Val::String(s)) = self.setting(name) {
                t.insert(name.into(), Value::String(s));
            }
        }
        if let Some(Val::Real(h)) = self.setting("h") {
            t.insert("h".into(), Value::Float(h));
            // Any span the step can resolve: only the step and the method matter here.
            t.insert(
                "t_span".into(),
                Value::Array(vec![Value::Float(0.0), Value::Float(h.abs().max(1.0))]),
            );
        }
        let on = !matches!(self.setting("control"), Some(Val::Boolean(false)));
        match (on, self.setting("control_start")) {
            (true, Some(Val::Real(tc))) => t.insert("control_start".into(), Value::Float(tc)),
            _ => t.insert("control_start".into(), Value::String("never".into())),
        };
        for key in ["project_invariants", "ledger"] {
            if let Some(Val::Boolean(p)) = self.setting(key) {
                t.insert(key.into(), Value::Boolean(p));
            }
        }
        let (s, _) =
            Settings::from_table(&t).map_err(|e| e.to_string().replacen("simulation.", "", 1))?;
        s.validate()
            .map_err(|e| e.to_string().replacen("simulation.", "", 1))?;
        Ok(s)
    }

    fn build_vessel(&self) -> Result<Vessel> {
        Vessel::from_table(self.vessel_table()?).map_err(|e| e.to_string())
    }

    /// Leave initialisation: build and check the vessel and the settings from the parameters,
    /// and start from the vessel file's `[initial]` state at `t0`.
    pub fn initialize(&mut self, t0: f64) -> Result<()> {
        self.time = t0;
        let r = self.build_state();
        self.mode = if r.is_ok() {
            Mode::Stepping
        } else {
            Mode::Initialization
        };
        r
    }

    fn build_state(&mut self) -> Result<()> {
        if self.layout.kind == Kind::Load {
            let period = self.real(Role::Setting("period"));
            if !(period.is_finite() && period > 0.0) {
                return Err(format!("period must be finite and > 0 (s), got {period}"));
            }
            return Ok(());
        }
        let settings = self.settings()?;
        let vessel = self.build_vessel()?;
        let state = vessel.initial_state();
        let n = VesselSystem::new(&vessel, None).accounts().len();
        self.running = Some(Running {
            vessel: Arc::new(vessel),
            inputs: self.inputs(),
            settings,
            state,
            booked: vec![0.0; n],
            supplied: 0.0,
            dissipated: 0.0,
        });
        Ok(())
    }

    /// Advance from the communication point `t` by `dt`: whole internal steps of `h` and, when
    /// `dt` is not a multiple of `h`, a last shorter one.
    pub fn step(&mut self, t: f64, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(format!(
                "the communication step must be finite and > 0, got {dt}"
            ));
        }
        if (t - self.time).abs() > TIME_TOLERANCE * self.time.abs().max(1.0) {
            return Err(format!(
                "the communication point {t} is not where the FMU is ({}); set an FMU state to go back",
                self.time
            ));
        }
        if let Some(stop) = self.stop_time {
            if t + dt > stop + TIME_TOLERANCE * stop.abs().max(1.0) {
                return Err(format!(
                    "the step to t = {} s goes past the experiment's stopTime {stop} s",
                    t + dt
                ));
            }
        }
        if self.layout.kind == Kind::Load {
            self.time = t + dt;
            return Ok(());
        }
        let inputs = self.inputs();
        let rebuilt = match &self.running {
            // Only the components the inputs act through are read again.
            Some(r) if r.inputs != inputs => Some(Arc::new(
                r.vessel
                    .with_rebuilt(self.vessel_tables(Some(&INPUT_TABLES))?, &INPUT_COMPONENTS)
                    .map_err(|e| e.to_string())?,
            )),
            Some(_) => None,
            None => return Err("the FMU is not initialised".into()),
        };
        let r = self.running.as_mut().expect("checked");
        if let Some(v) = rebuilt {
            r.vessel = v;
            r.inputs = inputs;
        }
        let (h_run, n_steps, last_h) = internal_steps(dt, r.settings.h);
        let opts = Options {
            t0: t,
            h: h_run,
            n_steps,
            last_h,
            save_every: n_steps,
            outer: r.settings.outer,
            ledger: r.settings.ledger,
            tolerance: None,
        };
        if let Err(e) = opts.validate() {
            return Err(format!(
                "the communication step {dt:e} s at t = {t} s asks for internal steps of {h_run:e} s and {last_h:e} s, which the time cannot resolve there ({e}); take communication steps that are multiples of h = {:e} s",
                r.settings.h
            ));
        }
        let sys = VesselSystem::new(&r.vessel, r.settings.control_start)
            .with_linear_flow(r.settings.linear_flow.for_vessel(
                &r.vessel,
                false,
                &r.settings.method,
            ))
            .with_projection(r.settings.project_invariants);
        let traj =
            run(&sys, &r.settings.method, r.state.clone(), &opts).map_err(|e| e.to_string())?;
        if let Status::Failed { t, reason, .. } = &traj.status {
            return Err(format!("the internal step from t = {t} s failed: {reason}; the step h is too long for this method, or the inputs are extreme"));
        }
        let last = traj.states.len() - 1;
        r.state = traj.states[last].clone();
        // Booked per saved interval (the first is zero): here the whole communication step.
        for w in &traj.booked {
            for (k, acc) in r.booked.iter_mut().enumerate() {
                *acc += w.get(k);
            }
        }
        r.supplied += traj.supplied.iter().sum::<f64>();
        r.dissipated += traj.dissipated.iter().sum::<f64>();
        self.time = t + dt;
        Ok(())
    }

    /// The value of a Real variable (parameters and inputs as set; outputs at the current
    /// state and time).
    pub fn get_real(&self, vr: u32) -> Result<f64> {
        let v = self.var(vr, Type::Real)?;
        match &v.role {
            Role::Output(group, i) => self.output(group, *i),
            Role::AccountWrench {
                account,
                moment,
                axis,
            } => self.report(|(_, w, _)| {
                let (f, m) = w[*account];
                if *moment {
                    m[*axis]
                } else {
                    f[*axis]
                }
            }),
            Role::ComponentOutput(i) => self.report(|(_, _, o)| o[*i]),
            _ => match &self.values[vr as usize] {
                Some(Val::Real(x)) => Ok(*x),
                _ => Err(format!("{} has no value", v.name)),
            },
        }
    }

    pub fn get_boolean(&self, vr: u32) -> Result<bool> {
        let v = self.var(vr, Type::Boolean)?;
        match &self.values[vr as usize] {
            Some(Val::Boolean(x)) => Ok(*x),
            _ => Err(format!("{} has no value", v.name)),
        }
    }

    pub fn get_string(&self, vr: u32) -> Result<String> {
        let v = self.var(vr, Type::String)?;
        match &self.values[vr as usize] {
            Some(Val::String(x)) => Ok(x.clone()),
            _ => Err(format!("{} has no value", v.name)),
        }
    }

    /// `read` of the accounts' wrenches and the components' outputs at the current state, the
    /// time and the controller's switch there, computed once per state.
    fn report(&self, read: impl FnOnce(&Report) -> f64) -> Result<f64> {
        let r = self
            .running
            .as_ref()
            .ok_or("outputs are defined once the FMU is initialised")?;
        let mut key = vec![self.time.to_bits(), Arc::as_ptr(&r.vessel) as usize as u64];
        key.extend(r.state.to_vector().iter().map(|v| v.to_bits()));
        let act = &r.state.act;
        key.extend([act.n as u64, act.t.to_bits()]);
        key.extend(act.thrust.iter().chain(&act.angle).map(|v| v.to_bits()));
        let mut kept = self.reports.0.lock().unwrap_or_else(|e| e.into_inner());
        if kept.as_ref().is_none_or(|k| k.0 != key) {
            let sys = VesselSystem::new(&r.vessel, r.settings.control_start);
            let wrenches = sys.account_wrenches(&r.state, self.time, sys.control_on(self.time));
            let outputs = sys
                .outputs(&r.state, self.time)
                .into_iter()
                .map(|o| o.value)
                .collect();
            *kept = Some((key, wrenches, outputs));
        }
        Ok(read(kept.as_ref().expect("kept above")))
    }

    fn output(&self, group: &str, i: usize) -> Result<f64> {
        if self.layout.kind == Kind::Load {
            let t = self.time;
            let period = self.real(Role::Setting("period"));
            let s = (2.0 * std::f64::consts::PI * t / period).sin();
            let (mean, amp) = match group {
                "force" => ("force_mean", "force_amplitude"),
                _ => ("moment_mean", "moment_amplitude"),
            };
            return Ok(self.real(Role::Group(mean, i)) + self.real(Role::Group(amp, i)) * s);
        }
        let r = self
            .running
            .as_ref()
            .ok_or("outputs are defined once the FMU is initialised")?;
        let s = &r.state;
        let body = &r.vessel.body;
        Ok(match group {
            "position" => s.x[i],
            "euler" => s.euler()[i],
            "quaternion" => so3::quaternion(&s.q)[i],
            "velocity" => body.velocity(&s.p, &s.m)[0][i],
            "angular_velocity" => body.velocity(&s.p, &s.m)[1][i],
            "control_force" | "control_moment" => {
                let sys = VesselSystem::new(&r.vessel, r.settings.control_start);
                let on = sys.control_on(self.time);
                let w = sys.account_wrenches(s, self.time, on);
                let mut total = Vector3::zeros();
                for (a, (f, m)) in self.layout.accounts.iter().zip(&w) {
                    if a.role == AccountRole::Control {
                        total += if group == "control_force" { f } else { m };
                    }
                }
                total[i]
            }
            "energy" if i == 0 => r.vessel.energy(s),
            "energy" | "ledger" if !r.settings.ledger => f64::NAN,
            "energy" if i == 1 => r.supplied,
            "energy" => r.dissipated,
            "ledger" => r.booked[i],
            other => return Err(format!("internal: unknown output group {other}")),
        })
    }
}

/// The internal steps of a communication step `dt` at the step `h`: `(h_run, n, last)`, `n`
/// steps of `h_run` with the last one `last`. A multiple of `h` (to 1e-9 relative) is that many
/// steps of `h`, as `phsplit.simulate` takes them; within 1e-6 of a multiple, that many equal
/// steps (no sliver of a last step that the time could not resolve); a step shorter than `h` is
/// one step; otherwise whole steps of `h` and a last shorter one.
pub fn internal_steps(dt: f64, h: f64) -> (f64, usize, f64) {
    let ratio = dt / h;
    let whole = ratio.round();
    if whole >= 1.0 && (ratio - whole).abs() <= 1e-9 * ratio {
        (h, whole as usize, h)
    } else if whole >= 1.0 && (ratio - whole).abs() <= 1e-6 * ratio {
        let even = dt / whole;
        (even, whole as usize, even)
    } else if ratio < 1.0 {
        (dt, 1, dt)
    } else {
        let n = ratio.floor();
        (h, n as usize + 1, dt - n * h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::XYZ;
    use phsplit_core::model::vessel::PAPER_VESSEL_TOML;

    const FIG2: &str =
        "[fmu]\nkind = \"vessel\"\n[simulation]\nmethod = \"sp4\"\nh = 0.5\ncontrol_start = 50.0\n";

    fn fig2() -> Arc<Layout> {
        Arc::new(Layout::new(FIG2, Some(PAPER_VESSEL_TOML)).unwrap())
    }

    fn vr(l: &Layout, name: &str) -> u32 {
        l.vars.iter().find(|v| v.name == name).unwrap().vr
    }

    #[test]
    fn setting_and_getting_follow_the_causalities() {
        let l = fig2();
        let mut inst = Instance::new(l.clone());
        let e = inst
            .set(vr(&l, "position.x"), Val::Real(1.0), false)
            .unwrap_err();
        assert!(e.contains("is an output"), "{e}");
        let e = inst
            .set(vr(&l, "method"), Val::Real(1.0), false)
            .unwrap_err();
        assert!(e.contains("method") && e.contains("String"), "{e}");
        let e = inst.get_real(9999).unwrap_err();
        assert!(e.contains("no variable has value reference 9999"), "{e}");
        assert!(inst.get_real(vr(&l, "position.x")).is_err()); // before initialisation
        assert!(inst.step(0.0, 1.0).unwrap_err().contains("not initialised"));
        inst.set(vr(&l, "vessel.mass"), Val::Real(-3.0), false)
            .unwrap();
        let e = inst.initialize(0.0).unwrap_err();
        assert!(e.contains("vessel.mass"), "{e}");
        inst.set(vr(&l, "vessel.mass"), Val::Real(6.3622085e6), false)
            .unwrap();
        inst.initialize(0.0).unwrap();
        let e = inst.set(vr(&l, "h"), Val::Real(0.1), true).unwrap_err();
        assert!(e.contains("fixed parameter"), "{e}");
        inst.set(vr(&l, "external_force.x"), Val::Real(1e5), true)
            .unwrap();
        assert_eq!(inst.get_real(vr(&l, "position.x")).unwrap(), 723.0);
        let e = inst.step(0.5, 1.0).unwrap_err();
        assert!(e.contains("communication point 0.5"), "{e}");
        assert!(inst.step(0.0, f64::NAN).is_err());
    }

    /// Communication steps that are not multiples of h end with a shorter internal step: the
    /// same state as the core's run of the same grid.
    #[test]
    fn a_partial_step_is_the_cores_run_of_the_same_grid() {
        let l = fig2();
        let mut inst = Instance::new(l.clone());
        inst.initialize(0.0).unwrap();
        inst.step(0.0, 1.3).unwrap(); // 0.5 + 0.5 + 0.3
        let v = Vessel::from_table(inst.vessel_table().unwrap()).unwrap();
        let sys = VesselSystem::new(&v, Some(50.0));
        let opts = Options {
            last_h: 0.3,
            ..Options::steps(0.0, 0.5, 3, 3)
        };
        let m: phsplit_core::methods::Method = "sp4".parse().unwrap();
        let traj = run(&sys, &m, v.initial_state(), &opts).unwrap();
        let want = traj.states.last().unwrap().x;
        for i in 0..3 {
            let got = inst
                .get_real(vr(&l, &format!("position.{}", XYZ[i])))
                .unwrap();
            assert_eq!(got, want[i]);
        }
        assert!((inst.time - 1.3).abs() < 1e-15);
    }

    #[test]
    fn internal_steps_cover_the_communication_step() {
        assert_eq!(internal_steps(1.0, 0.5), (0.5, 2, 0.5));
        assert_eq!(internal_steps(0.2, 0.5), (0.2, 1, 0.2));
        let (h, n, last) = internal_steps(1.3, 0.5);
        assert_eq!((h, n), (0.5, 3));
        assert!((last - 0.3).abs() < 1e-15);
        // A sliver over a multiple: equal steps instead of a last step of 1e-9 s.
        let (h, n, last) = internal_steps(0.5 + 1e-9, 0.5);
        assert_eq!((n, h, last), (1, 0.5 + 1e-9, 0.5 + 1e-9));
        let (h, n, _) = internal_steps(3.0 + 1e-8, 0.5);
        assert_eq!(n, 6);
        assert!((h * 6.0 - (3.0 + 1e-8)).abs() < 1e-15);
    }

    #[test]
    fn the_load_is_its_formula() {
        let l = Arc::new(Layout::new(
            "[fmu]\nkind = \"load\"\n[load]\nforce_mean = [1.0, 2.0, 3.0]\nforce_amplitude = [0.5, 0.0, -1.0]\nperiod = 8.0\n",
            None,
        )
        .unwrap());
        let mut inst = Instance::new(l.clone());
        inst.initialize(0.0).unwrap();
        inst.step(0.0, 2.0).unwrap(); // a quarter period: sin = 1
        let f: Vec<f64> = ["force.x", "force.y", "force.z", "moment.x"]
            .iter()
            .map(|n| inst.get_real(vr(&l, n)).unwrap())
            .collect();
        assert!((f[0] - 1.5).abs() < 1e-15 && f[1] == 2.0 && (f[2] - 2.0).abs() < 1e-15);
        assert_eq!(f[3], 0.0);
        inst.set(vr(&l, "period"), Val::Real(0.0), false).unwrap();
        assert!(inst.initialize(0.0).unwrap_err().contains("period"));
    }
}
