//! A run's settings: one set, one set of defaults, parsed and validated here for every front
//! end (the Python API, scenario files, batches and sweeps, the CLI).

use crate::error::{Error, Result};
use crate::methods::{Method, Outer};
use crate::model::vessel::params::unknown;
use crate::model::vessel::LinearFlow;
use crate::solve::{Options, MAX_STEPS};
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
    pub linear_flow: LinearFlow,
    /// Keep the energy ledger.
    pub ledger: bool,
}

impl Default for Settings {
    /// The paper's Fig. 2 run: SP4, h = 0.5 s on [0, 200] s, the controller from t = 50 s
    /// (paper §4), S2 outermost and exact, every step saved, the ledger on.
    fn default() -> Self {
        Self {
            t_span: (0.0, 200.0),
            h: 0.5,
            method: "sp4".parse().expect("registered"),
            control_start: Some(50.0),
            outer: Outer::Dissipative,
            save_every: 1,
            linear_flow: LinearFlow::Exact,
            ledger: true,
        }
    }
}

/// The keys of a `[simulation]` table, with what each takes.
pub const KEYS: [(&str, &str); 9] = [
    ("t_span", "two numbers [t0, t1], s"),
    ("h", "step size, s"),
    ("method", "a method name"),
    ("control_start", "time the controller starts, s, or \"never\""),
    ("outer", "'dissipative' or 'conservative'"),
    ("save_every", "an integer >= 1"),
    ("linear_flow", "'exact' or 'gauss'"),
    ("ledger", "true or false"),
    ("name", "a label for the output files"),
];

fn what(key: &str) -> &'static str {
    KEYS.iter().find(|(k, _)| *k == key).map(|(_, w)| *w).unwrap_or("")
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
                "name" => name = Some(string(key, v)?.to_string()),
                other => {
                    return Err(Error::Parse(unknown(other, &valid, "field", "[simulation]")))
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
        self.n_steps().map(|_| ())
    }

    /// The number of steps: `floor((t1 − t0)/h)` to round-off.
    pub fn n_steps(&self) -> Result<usize> {
        let (t0, t1) = self.t_span;
        let n = ((t1 - t0) / self.h * (1.0 + 1e-12)).floor();
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
        Ok(n as usize)
    }

    /// The kernels' options for this run.
    pub fn options(&self) -> Result<Options> {
        self.validate()?;
        Ok(Options {
            t0: self.t_span.0,
            h: self.h,
            n_steps: self.n_steps()?,
            save_every: self.save_every,
            outer: self.outer,
            ledger: self.ledger,
        })
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

    #[test]
    fn tables_parse_and_refuse() {
        let (s, n) = Settings::from_table(&table(
            "t_span = [0, 20]\nh = 0.25\nmethod = \"strang\"\ncontrol_start = \"never\"\nname = \"x\"",
        ))
        .unwrap();
        assert_eq!((s.t_span, s.h, s.method.name(), s.control_start), ((0.0, 20.0), 0.25, "sp2", None));
        assert_eq!(n.as_deref(), Some("x"));
        for (text, needle) in [
            ("methdo = \"sp2\"", "did you mean 'method'"),
            ("h = \"fast\"", "simulation.h must be a number (step size, s)"),
            ("t_span = [1.0]", "two numbers"),
            ("method = \"SP4\"", "valid methods"),
            ("save_every = 0", ">= 1"),
            ("save_every = 1.5", "integer"),
            ("h = 0", "> 0"),
            ("h = 300", "longer than t_span"),
            ("t_span = [0, 1e300]\nh = 1e-300", "at most"),
            ("outer = \"S1\"", "dissipative"),
            ("linear_flow = \"pade\"", "gauss"),
            ("ledger = 1", "true or false"),
        ] {
            let e = Settings::from_table(&table(text)).unwrap_err().to_string();
            assert!(e.contains(needle), "{text}: {e}");
        }
    }
}
