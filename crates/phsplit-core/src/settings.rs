//! A run's settings: one set, one set of defaults, parsed and validated here for every front
//! end (the Python API, scenario files, batches and sweeps, the CLI).

use crate::error::{Error, Result};
use crate::methods::{Method, Outer};
use crate::model::vessel::params::unknown;
use crate::model::vessel::{LinearFlow, Vessel};
use crate::solve::{Options, Tolerance, MAX_STEPS};
use toml::{Table, Value};

/// The settings of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Settings {
    /// `[t0, t1]`, s.
    pub t_span: (f64, f64),
    /// Step size, s.
    pub h: f64,
    pub method: Method,
    /// The controller acts on the steps that start at or after this time (s); `None`: never.
    pub control_start: Option<f64>,
    pub outer: Outer,
    /// Save every k-th step (and the last).
    pub save_every: usize,
    pub linear_flow: FlowChoice,
    /// Keep the energy ledger.
    pub ledger: bool,
    /// Project after every step onto the invariants of the exact flow that the split does not
    /// keep (the restoring invariant; docs/model.md §3.6). Energy-neutral.
    pub project_invariants: bool,
    /// Adaptive steps (`solve/adaptive.rs`): relative and absolute tolerance and the longest
    /// step (s). With neither tolerance the steps are fixed; with one, the other takes
    /// `solve_ivp`'s default (1e-3, 1e-6).
    pub rtol: Option<f64>,
    pub atol: Option<f64>,
    pub h_max: Option<f64>,
}

impl Default for Settings {
    /// The paper's Fig. 2 run: SP4, h = 0.5 s on [0, 200] s, the controller from t = 50 s
    /// (paper §4), S2 outermost, every step saved, the ledger on; flow S2 `"auto"`: exact where
    /// it acts and is the cheaper (see [`FlowChoice::Auto`]), Gauss collocation elsewhere. The
    /// paper's own scheme, the exact S2 (§3.4.2), is `linear_flow = "exact"`: the Fig. 2
    /// scenario and the reproduction pin it.
    fn default() -> Self {
        Self {
            t_span: (0.0, 200.0),
            h: 0.5,
            method: "sp4".parse().expect("registered"),
            control_start: Some(50.0),
            outer: Outer::Dissipative,
            save_every: 1,
            linear_flow: FlowChoice::Auto,
            ledger: true,
            project_invariants: true,
            rtol: None,
            atol: None,
            h_max: None,
        }
    }
}

/// How flow S2 is chosen: as the user names it, or by the vessel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlowChoice {
    /// The exact S2 where it acts (no forcing part: docs/model.md §3.7) on a vessel whose mass
    /// matrix has the paper's diagonal form and whose components keep no states of their own
    /// (their exact flow is the dense system's, several times a collocated step); with a
    /// forcing part and a second-order method at fixed steps, Gauss collocation of order 4
    /// ([`LinearFlow::Gauss4`]); Gauss collocation of the method's order otherwise. Measured
    /// (`benchmarks/energy_accuracy.py`, `benchmarks/workloads.py`): on the paper's vessel the
    /// exact S2 reached the energy accuracies of Fig. 4 sooner (SP2 reached 1e-3 only with it)
    /// and the workloads' 1 cm sooner at fixed steps; with a general mass matrix the exact
    /// coupled S2 costs several times a collocated step (docs/performance.md); with a forcing,
    /// SP2's error at fixed steps came mostly from its one-stage S2, and two stages reached
    /// 1 cm over `dp-weather`'s hour at four times the step, in 0.58 of the time, and the OSV's
    /// in a current at twice the step (docs/how-to/choose-method-step-flow.md).
    Auto,
    /// The flow named.
    Named(LinearFlow),
}

impl std::str::FromStr for FlowChoice {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        if s == "auto" {
            return Ok(FlowChoice::Auto);
        }
        s.parse().map(FlowChoice::Named).map_err(|_| {
            Error::InvalidInput(format!(
                "linear_flow must be 'auto' (exact where it acts on a diagonal mass matrix, else Gauss), {}, got {s:?}",
                LinearFlow::CHOICES
            ))
        })
    }
}

impl FlowChoice {
    pub fn name(self) -> &'static str {
        match self {
            FlowChoice::Auto => "auto",
            FlowChoice::Named(f) => f.name(),
        }
    }
    /// The flow S2 a run of `vessel` takes, with fixed or `adaptive` steps, by `method`.
    /// Adaptive steps take Gauss of the method's order: each step has its own length, so the
    /// exact flow's exponentials are not reused from step to step
    /// (`benchmarks/workloads.py`: the paper's hour to 1 cm by SP2 adaptive took about three
    /// times as long with the exact S2), and the OSV's hour to 1 cm by SP2 adaptive took 1.6
    /// times as long with two Gauss stages.
    pub fn for_vessel(self, vessel: &Vessel, adaptive: bool, method: &Method) -> LinearFlow {
        match self {
            FlowChoice::Named(f) => f,
            FlowChoice::Auto if adaptive => LinearFlow::Gauss,
            FlowChoice::Auto => {
                // As `VesselSystem::s2_solver`: the exact flow acts where no component forces S2.
                let forced = vessel.forces.iter().any(|f| f.forced());
                let own = vessel.own_layout().next().is_some();
                if !forced && vessel.body.is_diagonal() && !own {
                    LinearFlow::Exact
                } else if forced && !own && matches!(method, Method::Splitting(c) if c.order == 2) {
                    LinearFlow::Gauss4
                } else {
                    LinearFlow::Gauss
                }
            }
        }
    }
}

/// The keys of a `[simulation]` table, with what each takes.
pub const KEYS: [(&str, &str); 13] = [
    ("t_span", "two numbers [t0, t1], s"),
    ("h", "step size, s"),
    ("method", "a method name"),
    (
        "control_start",
        "time the controller starts, s, or \"never\"",
    ),
    ("outer", "'dissipative' or 'conservative'"),
    ("save_every", "an integer >= 1"),
    (
        "linear_flow",
        "'auto', 'exact', 'gauss', 'gauss4' or 'gauss6'",
    ),
    ("ledger", "true or false"),
    ("project_invariants", "true or false"),
    ("rtol", "relative tolerance of adaptive steps, in (0, 1]"),
    (
        "atol",
        "absolute tolerance of adaptive steps (m, rad, m/s, rad/s), in (0, 1e3]",
    ),
    ("h_max", "longest adaptive step, s"),
    ("name", "a label for the output files"),
];

fn what(key: &str) -> &'static str {
    KEYS.iter()
        .find(|(k, _)| *k == key)
        .map(|(_, w)| *w)
        .unwrap_or("")
}

fn number(key: &str, v: &Value) -> Result<f64> {
    match v {
        Value::Float(f) => Ok(*f),
        Value::Integer(i) => Ok(*i as f64),
        other => Err(Error::Parse(format!(
            "simulation.{key} must be a number ({}), got {} {other}",
            what(key),
            other.type_str()
        ))),
    }
}

fn string<'a>(key: &str, v: &'a Value) -> Result<&'a str> {
    v.as_str().ok_or_else(|| {
        Error::Parse(format!(
            "simulation.{key} must be {}, got {} {v}",
            what(key),
            v.type_str()
        ))
    })
}

/// An output name: letters, digits, `.`, `_`, `-`, starting with a letter or digit, at most
/// 100 characters, so that it names a file inside the output folder and nowhere else.
pub fn check_name(name: &str) -> Result<String> {
    let ok = !name.is_empty()
        && name.len() <= 100
        && name
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_alphanumeric())
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-'));
    if ok {
        Ok(name.to_string())
    } else {
        Err(Error::InvalidInput(format!(
            "simulation.name must be 1 to 100 letters, digits, '.', '_' or '-', starting with a letter or digit (it names the output files inside the output folder), got {name:?}"
        )))
    }
}

impl Settings {
    /// Settings from a `[simulation]` table over the defaults; unknown keys are refused with
    /// the nearest valid one. Returns the settings and the `name`, if given.
    pub fn from_table(t: &Table) -> Result<(Self, Option<String>)> {
        let mut s = Settings::default();
        let mut name = None;
        let valid: Vec<String> = KEYS.iter().map(|(k, _)| k.to_string()).collect();
        for (key, v) in t {
            match key.as_str() {
                "t_span" => {
                    let a = v.as_array().filter(|a| a.len() == 2).ok_or_else(|| {
                        Error::Parse(format!(
                            "simulation.t_span must be two numbers [t0, t1] in s, got {v}"
                        ))
                    })?;
                    s.t_span = (number("t_span", &a[0])?, number("t_span", &a[1])?);
                }
                "h" => s.h = number(key, v)?,
                "method" => s.method = string(key, v)?.parse()?,
                "control_start" => {
                    s.control_start = match v {
                        Value::String(x) if x == "never" => None,
                        other => Some(number(key, other)?),
                    }
                }
                "outer" => s.outer = string(key, v)?.parse()?,
                "linear_flow" => s.linear_flow = string(key, v)?.parse()?,
                "save_every" => {
                    s.save_every = match v {
                        Value::Integer(i) if *i >= 1 => *i as usize,
                        other => {
                            return Err(Error::Parse(format!(
                                "simulation.save_every must be an integer >= 1, got {other}"
                            )))
                        }
                    }
                }
                "ledger" => {
                    s.ledger = v.as_bool().ok_or_else(|| {
                        Error::Parse(format!("simulation.ledger must be true or false, got {v}"))
                    })?
                }
                "project_invariants" => {
                    s.project_invariants = v.as_bool().ok_or_else(|| {
                        Error::Parse(format!(
                            "simulation.project_invariants must be true or false, got {v}"
                        ))
                    })?
                }
                "rtol" => s.rtol = Some(number(key, v)?),
                "atol" => s.atol = Some(number(key, v)?),
                "h_max" => s.h_max = Some(number(key, v)?),
                "name" => name = Some(check_name(string(key, v)?)?),
                other => {
                    return Err(Error::Parse(unknown(
                        other,
                        &valid,
                        "field",
                        "[simulation]",
                    )))
                }
            }
        }
        s.validate()?;
        Ok((s, name))
    }

    /// Check every value; the message names the setting and what is allowed.
    pub fn validate(&self) -> Result<()> {
        let (t0, t1) = self.t_span;
        if !(t0.is_finite() && t1.is_finite()) || t1 <= t0 {
            return Err(Error::InvalidInput(format!(
                "t_span must be finite with t1 > t0 (s), got ({t0}, {t1})"
            )));
        }
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(Error::InvalidInput(format!(
                "h must be finite and > 0 (s), got {}",
                self.h
            )));
        }
        if let Some(tc) = self.control_start {
            if !tc.is_finite() {
                return Err(Error::InvalidInput(format!(
                    "control_start must be finite (s) or None (never), got {tc}"
                )));
            }
        }
        if self.save_every == 0 {
            return Err(Error::InvalidInput(
                "save_every must be an integer >= 1, got 0".into(),
            ));
        }
        let (n, last_h) = self.steps()?;
        let tolerance = self.tolerance()?;
        if let Some(tol) = &tolerance {
            tol.validate(t0)?;
            if self.h > tol.h_max {
                return Err(Error::InvalidInput(format!(
                    "h = {} s, the first adaptive step tried, is longer than h_max = {} s: give h <= h_max",
                    self.h, tol.h_max
                )));
            }
            if matches!(self.method, Method::RungeKutta(_)) {
                return Err(Error::InvalidInput(format!(
                    "adaptive steps (rtol, atol) are for the splitting methods (lie, sp2, mcl2, sp4, sp6); {} runs with a fixed step here: drop rtol and atol, or choose a splitting method",
                    self.method.name()
                )));
            }
        }
        Options {
            t0: self.t_span.0,
            h: self.h,
            n_steps: n,
            last_h,
            save_every: self.save_every,
            outer: self.outer,
            ledger: self.ledger,
            tolerance,
        }
        .validate()
    }
    /// The adaptive run's tolerance, if `rtol` or `atol` is given.
    pub fn tolerance(&self) -> Result<Option<Tolerance>> {
        if self.rtol.is_none() && self.atol.is_none() {
            if let Some(hm) = self.h_max {
                return Err(Error::InvalidInput(format!(
                    "h_max = {hm} s bounds adaptive steps only: give rtol or atol as well, or drop h_max (fixed steps take h)"
                )));
            }
            return Ok(None);
        }
        let (t0, t1) = self.t_span;
        Ok(Some(Tolerance {
            rtol: self.rtol.unwrap_or(1e-3),
            atol: self.atol.unwrap_or(1e-6),
            h_max: self.h_max.unwrap_or(t1 - t0),
            t1,
            save_at: Vec::new(),
        }))
    }
    /// Whether the steps are adaptive.
    pub fn adaptive(&self) -> bool {
        self.rtol.is_some() || self.atol.is_some()
    }

    /// The number of steps: whole steps of `h`, and a last shorter one when the span is not a
    /// whole number of steps (beyond round-off), so that the run ends at `t1`.
    pub fn n_steps(&self) -> Result<usize> {
        Ok(self.steps()?.0)
    }

    /// The number of steps and the length of the last one.
    pub fn steps(&self) -> Result<(usize, f64)> {
        let (t0, t1) = self.t_span;
        let span = t1 - t0;
        if !span.is_finite() {
            return Err(Error::InvalidInput(format!(
                "t_span must be finite with t1 > t0 (s), got ({t0}, {t1}), a span of {span} s"
            )));
        }
        let n = (span / self.h * (1.0 + 1e-12)).floor();
        if n < 1.0 {
            return Err(Error::InvalidInput(format!(
                "h = {} s is longer than t_span ({} s): no step to take",
                self.h,
                t1 - t0
            )));
        }
        if n > MAX_STEPS as f64 {
            return Err(Error::InvalidInput(format!(
                "t_span / h asks for {n:.3e} steps; a run takes at most {MAX_STEPS:.0e} steps (split it into several runs, or take a longer h)"
            )));
        }
        let rest = span - n * self.h;
        if rest > 1e-9 * self.h {
            Ok((n as usize + 1, rest))
        } else {
            Ok((n as usize, self.h))
        }
    }

    /// The kernels' options for this run.
    pub fn options(&self) -> Result<Options> {
        self.validate()?;
        let (n_steps, last_h) = self.steps()?;
        let o = Options {
            t0: self.t_span.0,
            h: self.h,
            n_steps,
            last_h,
            save_every: self.save_every,
            outer: self.outer,
            ledger: self.ledger,
            tolerance: self.tolerance()?,
        };
        o.validate()?;
        Ok(o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(s: &str) -> Table {
        s.parse().unwrap()
    }

    #[test]
    fn defaults_are_the_papers_fig2() {
        let s = Settings::default();
        assert_eq!(s.method.name(), "sp4");
        assert_eq!(s.options().unwrap().n_steps, 400);
        let (t, name) = Settings::from_table(&table("")).unwrap();
        assert_eq!(t, s);
        assert_eq!(name, None);
    }

    /// The table of keys names every flow S2 the core parses (it is written out, a constant).
    #[test]
    fn the_keys_name_every_linear_flow() {
        let (_, allowed) = KEYS.iter().find(|(k, _)| *k == "linear_flow").unwrap();
        for f in LinearFlow::ALL {
            assert!(allowed.contains(&format!("'{}'", f.name())), "{allowed}");
        }
        assert!(allowed.contains("'auto'"));
    }

    #[test]
    fn a_span_that_is_not_whole_steps_ends_with_a_shorter_one() {
        let mut s = Settings {
            t_span: (0.0, 1.0),
            h: 0.3,
            ..Settings::default()
        };
        let o = s.options().unwrap();
        assert_eq!((o.n_steps, o.h), (4, 0.3));
        assert!((o.last_h - 0.1).abs() < 1e-15);
        assert!((o.time_after(3) - 1.0).abs() < 1e-15);
        s.t_span = (0.0, 0.9 + 1e-14); // round-off: three whole steps
        assert_eq!(s.options().unwrap().n_steps, 3);
        assert_eq!(s.options().unwrap().last_h, 0.3);
    }

    #[test]
    fn tables_parse_and_refuse() {
        let (s, n) = Settings::from_table(&table(
            "t_span = [0, 20]\nh = 0.25\nmethod = \"strang\"\ncontrol_start = \"never\"\nname = \"x\"",
        ))
        .unwrap();
        assert_eq!(
            (s.t_span, s.h, s.method.name(), s.control_start),
            ((0.0, 20.0), 0.25, "sp2", None)
        );
        assert_eq!(n.as_deref(), Some("x"));
        for (text, needle) in [
            ("methdo = \"sp2\"", "did you mean 'method'"),
            (
                "h = \"fast\"",
                "simulation.h must be a number (step size, s)",
            ),
            ("t_span = [1.0]", "two numbers"),
            ("method = \"SP4\"", "valid methods"),
            ("save_every = 0", ">= 1"),
            ("save_every = 1.5", "integer"),
            ("h = 0", "> 0"),
            ("h = 300", "longer than t_span"),
            ("t_span = [0, 1e300]\nh = 1e-300", "at most"),
            ("outer = \"S1\"", "dissipative"),
            ("linear_flow = \"pade\"", "'auto'"),
            ("ledger = 1", "true or false"),
            ("name = \"../../escape\"", "simulation.name must be"),
            ("name = \"\"", "simulation.name must be"),
            ("name = \"a/b\"", "simulation.name must be"),
            ("t_span = [1e17, 1.00000000000000010e17]\nh = 1", "resolve"),
            ("t_span = [0, 1e308]\nh = 1e-300", "at most"),
            ("t_span = [-1e308, 1e308]", "finite"),
        ] {
            let e = Settings::from_table(&table(text)).unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }
}
