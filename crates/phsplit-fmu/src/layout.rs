//! The FMU's variables: one table, read by the exporter (through the Python binding) to write
//! `modelDescription.xml` and by the FMU to serve `fmi2Get*`/`fmi2Set*` (docs/fmu.md).
//!
//! Two kinds of FMU come from this binary, chosen by the resource file `fmu.toml`:
//! - `vessel`: a phsplit vessel (any vessel file) integrated by one of phsplit's methods at an
//!   internal step, with the external load, the set point and the current as inputs;
//! - `load`: a periodic load source, `f(t) = f̄ + f̂ sin(2π t / T)` per component (a slowly
//!   varying pipe tension or wind load), the second FMU of the co-simulation examples.

use phsplit_core::model::vessel::{Vessel, VesselSystem};
use phsplit_core::settings::Settings;
use phsplit_core::solve::{Account, Model};
use toml::{Table, Value};

/// An error with the message the FMU logs.
pub type Result<T> = std::result::Result<T, String>;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Type {
    Real,
    Boolean,
    String,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Parameter,
    Input,
    Output,
}

/// A value of a variable.
#[derive(Debug, Clone, PartialEq)]
pub enum Val {
    Real(f64),
    Boolean(bool),
    String(String),
}

/// What a variable is in the model.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Role {
    /// A number of the vessel file: `[table] key` or its element `index`.
    VesselNumber {
        table: String,
        key: String,
        index: Option<usize>,
    },
    /// A run setting (`method`, `h`, …) or an FMU option (`external_frame`, `control`).
    Setting(&'static str),
    /// A component of a named group of inputs (`external_force`, …) or of a load's parameters.
    Group(&'static str, usize),
    /// An output: its group and component (or the account index of `ledger.*`).
    Output(&'static str, usize),
    /// The force (`moment = false`, N) or moment (N m) booked to ledger account `account`, its
    /// body-frame component `axis`: `force_<account>.*`, `moment_<account>.*`, as the results'
    /// variables of the same names.
    AccountWrench {
        account: usize,
        moment: bool,
        axis: usize,
    },
    /// The `index`-th quantity the vessel's components report
    /// (`phsplit_core::model::vessel::forces::Force::outputs`), under its own name.
    ComponentOutput(usize),
}

/// One scalar variable of the FMU.
#[derive(Debug, Clone, PartialEq)]
pub struct Variable {
    pub name: String,
    /// Its value reference (its index in the table).
    pub vr: u32,
    pub ty: Type,
    pub causality: Causality,
    /// The start value (parameters and inputs; outputs have none).
    pub start: Option<Val>,
    pub unit: &'static str,
    pub description: String,
    pub(crate) role: Role,
}

/// The FMU kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Vessel,
    Load,
}

/// The variables of an FMU and what it was built from.
#[derive(Debug, Clone)]
pub struct Layout {
    pub kind: Kind,
    pub vars: Vec<Variable>,
    /// The vessel file as the FMU runs it (normalised, with the `[external]` and `[current]`
    /// tables that carry the inputs).
    pub(crate) base: Table,
    /// The ledger accounts of the vessel.
    pub(crate) accounts: Vec<Account>,
}

/// Axis names of the spatial / body components.
pub(crate) const XYZ: [&str; 3] = ["x", "y", "z"];

/// The largest 1-D array of the vessel file whose elements become parameters (longer arrays,
/// tables of coefficients, stay as the resource file gives them).
const MAX_PARAMETER_ARRAY: usize = 6;

/// Keys of the vessel file that inputs set, so they are not parameters too.
fn driven_by_input(table: &str, key: &str, index: Option<usize>, setpoint_inputs: bool) -> bool {
    match (table, key) {
        ("external", "force" | "moment") => true,
        ("current", "velocity") => index.is_some_and(|i| i < 2),
        ("control", "position_reference") => setpoint_inputs && index.is_some_and(|i| i < 2),
        ("control", "euler_reference") => setpoint_inputs && index == Some(2),
        _ => false,
    }
}

struct Builder {
    vars: Vec<Variable>,
}

impl Builder {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        name: String,
        ty: Type,
        causality: Causality,
        start: Option<Val>,
        unit: &'static str,
        description: String,
        role: Role,
    ) {
        let vr = self.vars.len() as u32;
        self.vars.push(Variable {
            name,
            vr,
            ty,
            causality,
            start,
            unit,
            description,
            role,
        });
    }
    fn output(&mut self, group: &'static str, names: &[&str], unit: &'static str, what: &str) {
        for (i, n) in names.iter().enumerate() {
            self.push(
                format!("{group}.{n}"),
                Type::Real,
                Causality::Output,
                None,
                unit,
                format!("{what} ({n})"),
                Role::Output(group, i),
            );
        }
    }
    fn input(&mut self, group: &'static str, starts: &[(&str, f64, &'static str)], what: &str) {
        for (i, (n, v, unit)) in starts.iter().enumerate() {
            self.push(
                format!("{group}.{n}"),
                Type::Real,
                Causality::Input,
                Some(Val::Real(*v)),
                unit,
                format!("{what} ({n})"),
                Role::Group(group, i),
            );
        }
    }
    fn setting(&mut self, name: &'static str, start: Val, unit: &'static str, what: &str) {
        let ty = match start {
            Val::Real(_) => Type::Real,
            Val::Boolean(_) => Type::Boolean,
            Val::String(_) => Type::String,
        };
        self.push(
            name.to_string(),
            ty,
            Causality::Parameter,
            Some(start),
            unit,
            what.to_string(),
            Role::Setting(name),
        );
    }
}

/// A component output's unit (CF, UDUNITS spelling, as the results write it) in the FMU's
/// spelling (`resources` of the exporter: `m/s`, `N.m`, `deg`).
fn fmi_unit(cf: &'static str) -> &'static str {
    match cf {
        "m s-1" => "m/s",
        "rad s-1" => "rad/s",
        "N m" => "N.m",
        "degree" => "deg",
        other => other,
    }
}

/// The 3-vector `key` of the table `t` (zeros where absent).
fn vec3_in(t: &Table, key: &str) -> [f64; 3] {
    let mut out = [0.0; 3];
    if let Some(Value::Array(a)) = t.get(key) {
        for (o, v) in out.iter_mut().zip(a) {
            *o = float(v).unwrap_or(0.0);
        }
    }
    out
}

/// The 3-vector `[table] key` of a vessel file (zeros where absent).
fn vec3_of(t: &Table, table: &str, key: &str) -> [f64; 3] {
    t.get(table)
        .and_then(|v| v.as_table())
        .map_or([0.0; 3], |s| vec3_in(s, key))
}

fn float(v: &Value) -> Option<f64> {
    v.as_float().or_else(|| v.as_integer().map(|i| i as f64))
}

impl Layout {
    /// The layout of an FMU from its resource files: `fmu` (the `fmu.toml` text: `[fmu] kind`,
    /// `[simulation]` for a vessel, `[load]` for a load) and, for a vessel, the vessel file.
    pub fn new(fmu: &str, vessel: Option<&str>) -> Result<Self> {
        let fmu: Table = fmu
            .parse()
            .map_err(|e| format!("resources/fmu.toml cannot be read: {e}"))?;
        let kind = fmu
            .get("fmu")
            .and_then(|t| t.get("kind"))
            .and_then(|v| v.as_str())
            .unwrap_or("vessel");
        match kind {
            "vessel" => {
                let text = vessel.ok_or("a vessel FMU needs resources/vessel.toml")?;
                let sim = fmu
                    .get("simulation")
                    .and_then(|v| v.as_table())
                    .cloned()
                    .unwrap_or_default();
                Self::vessel(text, &sim)
            }
            "load" => Ok(Self::load(
                fmu.get("load")
                    .and_then(|v| v.as_table())
                    .cloned()
                    .unwrap_or_default(),
            )),
            other => Err(format!(
                "resources/fmu.toml: [fmu] kind must be 'vessel' or 'load', got {other:?}"
            )),
        }
    }

    /// A vessel FMU of the vessel file `text` with the run settings `sim` (a `[simulation]`
    /// table: method, h, control_start, linear_flow, outer, project_invariants).
    pub fn vessel(text: &str, sim: &Table) -> Result<Self> {
        let mut table: Table = text
            .parse()
            .map_err(|e| format!("the vessel file cannot be read: {e}"))?;
        // The tables the inputs act through; present (with zero loads) in every vessel FMU, so
        // that the ledger has the same accounts whatever the inputs.
        let ext = table
            .entry("external")
            .or_insert_with(|| Value::Table(Table::new()));
        if let Value::Table(e) = ext {
            for k in ["force", "moment", "point"] {
                e.entry(k)
                    .or_insert_with(|| Value::Array(vec![Value::Float(0.0); 3]));
            }
            e.entry("frame")
                .or_insert_with(|| Value::String("body".into()));
        }
        let has_current_table = table.get("current").and_then(|c| c.get("times")).is_some();
        if !has_current_table {
            let c = table
                .entry("current")
                .or_insert_with(|| Value::Table(Table::new()));
            if let Value::Table(c) = c {
                c.entry("velocity")
                    .or_insert_with(|| Value::Array(vec![Value::Float(0.0); 3]));
            }
        }
        let vessel = Vessel::from_table(table).map_err(|e| e.to_string())?;
        let base = vessel.params.clone();
        let (settings, _) = Settings::from_table(sim).map_err(|e| e.to_string())?;
        let sys = VesselSystem::new(&vessel, Some(0.0));
        let accounts: Vec<Account> = sys.accounts().to_vec();
        let setpoint_inputs = base.contains_key("control") && !base.contains_key("setpoint");

        let mut b = Builder { vars: Vec::new() };
        // Outputs.
        b.output(
            "position",
            &XYZ,
            "m",
            "position of the body origin, spatial frame (z up)",
        );
        b.output(
            "euler",
            &["roll", "pitch", "yaw"],
            "rad",
            "ZYX Euler angles of the attitude",
        );
        b.output(
            "quaternion",
            &["w", "x", "y", "z"],
            "1",
            "unit quaternion of the attitude, body to spatial, scalar first",
        );
        b.output(
            "velocity",
            &["u", "v", "w"],
            "m/s",
            "linear velocity, body frame",
        );
        b.output(
            "angular_velocity",
            &["p", "q", "r"],
            "rad/s",
            "angular velocity, body frame",
        );
        b.output(
            "control_force",
            &XYZ,
            "N",
            "force of the controller (or what its thrusters deliver), body frame",
        );
        b.output(
            "control_moment",
            &XYZ,
            "N.m",
            "moment of the controller (or its thrusters) about the body origin, body frame",
        );
        b.output(
            "energy",
            &["stored", "supplied", "dissipated"],
            "J",
            "stored energy H; energy supplied through the ports and dissipated since the start",
        );
        let names: Vec<&str> = accounts.iter().map(|a| a.name).collect();
        b.output(
            "ledger",
            &names,
            "J",
            "energy booked by the account since the start (supplied or dissipated, as its kind)",
        );
        // Every account's force and moment, and every quantity a component reports: from the
        // vessel's own declarations, so a new component's ports and outputs appear here with no
        // code of the FMU's.
        for (k, a) in accounts.iter().enumerate() {
            for (moment, what, unit) in [(false, "force", "N"), (true, "moment", "N.m")] {
                for (axis, n) in XYZ.iter().enumerate() {
                    b.push(
                        format!("{what}_{}.{n}", a.name),
                        Type::Real,
                        Causality::Output,
                        None,
                        unit,
                        format!(
                            "{what} booked to the ledger account {}, body frame{} ({n})",
                            a.name,
                            if moment {
                                ", about the body origin"
                            } else {
                                ""
                            }
                        ),
                        Role::AccountWrench {
                            account: k,
                            moment,
                            axis,
                        },
                    );
                }
            }
        }
        for (i, o) in sys
            .outputs(&vessel.initial_state(), 0.0)
            .into_iter()
            .enumerate()
        {
            b.push(
                o.name,
                Type::Real,
                Causality::Output,
                None,
                fmi_unit(o.unit),
                o.long_name,
                Role::ComponentOutput(i),
            );
        }
        // Inputs.
        let f = vec3_of(&base, "external", "force");
        let m = vec3_of(&base, "external", "moment");
        b.input(
            "external_force",
            &[("x", f[0], "N"), ("y", f[1], "N"), ("z", f[2], "N")],
            "external force at external.point, in the frame external_frame",
        );
        b.input(
            "external_moment",
            &[("x", m[0], "N.m"), ("y", m[1], "N.m"), ("z", m[2], "N.m")],
            "external moment, in the frame external_frame",
        );
        if setpoint_inputs {
            let xr = vec3_of(&base, "control", "position_reference");
            let er = vec3_of(&base, "control", "euler_reference");
            b.input(
                "setpoint",
                &[
                    ("x", xr[0], "m"),
                    ("y", xr[1], "m"),
                    ("heading", er[2], "rad"),
                ],
                "the controller's set point: position (spatial frame) and heading (yaw)",
            );
        }
        if !has_current_table {
            let c = vec3_of(&base, "current", "velocity");
            b.input(
                "current",
                &[("x", c[0], "m/s"), ("y", c[1], "m/s")],
                "uniform current velocity, spatial frame (the direction the water flows towards)",
            );
        }
        // Run settings.
        let s = &settings;
        b.setting(
            "method",
            Val::String(s.method.name().into()),
            "",
            "integration method (phsplit methods: sp2, sp4, sp6, rk4, ...)",
        );
        b.setting("h", Val::Real(s.h), "s", "internal step; a communication step that is not a multiple of it ends with a shorter step");
        b.setting(
            "linear_flow",
            Val::String(s.linear_flow.name().into()),
            "",
            "flow S2: 'auto' (exact where it acts on a diagonal mass matrix, else Gauss), 'exact' or 'gauss'",
        );
        b.setting(
            "outer",
            Val::String(s.outer.name().into()),
            "",
            "outermost flow of a composition: 'dissipative' or 'conservative'",
        );
        b.setting(
            "control",
            Val::Boolean(s.control_start.is_some()),
            "",
            "whether the controller acts",
        );
        b.setting(
            "control_start",
            Val::Real(s.control_start.unwrap_or(0.0)),
            "s",
            "the controller acts on internal steps that start at or after this time",
        );
        b.setting(
            "project_invariants",
            Val::Boolean(s.project_invariants),
            "",
            "project onto the restoring invariant after every internal step (energy-neutral)",
        );
        b.setting(
            "ledger",
            Val::Boolean(s.ledger),
            "",
            "keep the energy ledger (energy.supplied, energy.dissipated and ledger.* are NaN without it; steps are several times cheaper)",
        );
        let frame = base
            .get("external")
            .and_then(|e| e.get("frame"))
            .and_then(|v| v.as_str())
            .unwrap_or("body")
            .to_string();
        b.setting("external_frame", Val::String(frame), "", "frame of the external force and moment inputs: 'body', 'spatial' (z up) or 'ned' (north-east-down, with the spatial frame read as north-west-up)");
        // The vessel file's numbers as parameters.
        for (tname, t) in &base {
            let Some(t) = t.as_table() else { continue };
            for (key, v) in t {
                if tname == "external" && key == "frame" {
                    continue;
                }
                match v {
                    Value::Float(_) => {
                        b.push(
                            format!("{tname}.{key}"),
                            Type::Real,
                            Causality::Parameter,
                            Some(Val::Real(float(v).unwrap())),
                            "",
                            format!("vessel file [{tname}] {key}"),
                            Role::VesselNumber {
                                table: tname.clone(),
                                key: key.clone(),
                                index: None,
                            },
                        );
                    }
                    Value::Array(a)
                        if !a.is_empty()
                            && a.len() <= MAX_PARAMETER_ARRAY
                            && a.iter().all(|x| x.is_float()) =>
                    {
                        for (i, x) in a.iter().enumerate() {
                            if driven_by_input(tname, key, Some(i), setpoint_inputs) {
                                continue;
                            }
                            b.push(
                                format!("{tname}.{key}[{i}]"),
                                Type::Real,
                                Causality::Parameter,
                                Some(Val::Real(float(x).unwrap())),
                                "",
                                format!("vessel file [{tname}] {key}[{i}] (0-based)"),
                                Role::VesselNumber {
                                    table: tname.clone(),
                                    key: key.clone(),
                                    index: Some(i),
                                },
                            );
                        }
                    }
                    _ => {}
                }
            }
        }
        let mut seen = std::collections::HashSet::new();
        if let Some(v) = b.vars.iter().find(|v| !seen.insert(v.name.as_str())) {
            return Err(format!(
                "the vessel's variable {} is declared twice (a component's output named like a ledger account's force or one of the FMU's own variables)",
                v.name
            ));
        }
        Ok(Self {
            kind: Kind::Vessel,
            vars: b.vars,
            base,
            accounts,
        })
    }

    /// A periodic load source: parameters `force_mean.*`, `force_amplitude.*`,
    /// `moment_mean.*`, `moment_amplitude.*` (start values from the `[load]` table's 3-vectors of
    /// the same names) and `period` (s); outputs `force.*`, `moment.*`.
    pub fn load(t: Table) -> Self {
        let mut b = Builder { vars: Vec::new() };
        b.output("force", &XYZ, "N", "load force");
        b.output("moment", &XYZ, "N.m", "load moment");
        for (name, unit) in [
            ("force_mean", "N"),
            ("force_amplitude", "N"),
            ("moment_mean", "N.m"),
            ("moment_amplitude", "N.m"),
        ] {
            let v = vec3_in(&t, name);
            for (i, n) in XYZ.iter().enumerate() {
                b.push(
                    format!("{name}.{n}"),
                    Type::Real,
                    Causality::Parameter,
                    Some(Val::Real(v[i])),
                    unit,
                    format!("{name} ({n})"),
                    Role::Group(name, i),
                );
            }
        }
        let period = t.get("period").and_then(float).unwrap_or(60.0);
        b.setting(
            "period",
            Val::Real(period),
            "s",
            "period of the load's oscillation",
        );
        Self {
            kind: Kind::Load,
            vars: b.vars,
            base: Table::new(),
            accounts: Vec::new(),
        }
    }

    pub(crate) fn index_of(&self, role: &Role) -> Option<usize> {
        self.vars.iter().position(|v| &v.role == role)
    }
}

/// The vessel being stepped.

#[cfg(test)]
mod tests {
    use super::*;
    use phsplit_core::model::vessel::PAPER_VESSEL_TOML;

    const FIG2: &str =
        "[fmu]\nkind = \"vessel\"\n[simulation]\nmethod = \"sp4\"\nh = 0.5\ncontrol_start = 50.0\n";

    fn fig2() -> Layout {
        Layout::new(FIG2, Some(PAPER_VESSEL_TOML)).unwrap()
    }

    #[test]
    fn the_table_is_consistent() {
        let l = fig2();
        let mut names = std::collections::HashSet::new();
        for (i, v) in l.vars.iter().enumerate() {
            assert_eq!(v.vr as usize, i);
            assert!(names.insert(v.name.clone()), "duplicate {}", v.name);
            assert_eq!(
                v.start.is_none(),
                v.causality == Causality::Output,
                "{}",
                v.name
            );
        }
        // The inputs are not parameters too.
        for n in [
            "external.force[0]",
            "control.position_reference[0]",
            "current.velocity[1]",
        ] {
            assert!(!names.contains(n), "{n}");
        }
        assert!(names.contains("control.position_reference[2]"));
        assert!(names.contains("ledger.external") && names.contains("ledger.current"));
        // A moving set point (a [setpoint] table) takes the place of the set-point inputs.
        let text = format!("{PAPER_VESSEL_TOML}\n[setpoint]\nnatural_frequency = 0.1\ntimes = [0.0]\npositions = [[780.0, 20.0, 0.0]]\nheadings = [0.0]\n");
        let moving = Layout::new(FIG2, Some(&text)).unwrap();
        assert!(!moving
            .vars
            .iter()
            .any(|v| v.causality == Causality::Input && v.name.starts_with("setpoint.")));
        assert!(moving
            .vars
            .iter()
            .any(|v| v.name == "setpoint.natural_frequency"));
    }

    #[test]
    fn bad_resources_are_named() {
        let e = Layout::new("[fmu]\nkind = \"boat\"\n", None).unwrap_err();
        assert!(e.contains("kind must be 'vessel' or 'load'"), "{e}");
        let e = Layout::new(FIG2, None).unwrap_err();
        assert!(e.contains("resources/vessel.toml"), "{e}");
        let bad = PAPER_VESSEL_TOML.replace("mass = 6.3622085e6", "mass = -1.0");
        let e = Layout::new(FIG2, Some(&bad)).unwrap_err();
        assert!(e.contains("vessel.mass"), "{e}");
        let e = Layout::new(
            "[fmu]\n[simulation]\nmethod = \"rk5\"\n",
            Some(PAPER_VESSEL_TOML),
        )
        .unwrap_err();
        assert!(e.contains("method"), "{e}");
    }
}
