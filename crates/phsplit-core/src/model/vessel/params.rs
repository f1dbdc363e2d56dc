//! Parameter files (TOML): a reader through which each part of the model takes its own keys,
//! validated where they are taken, and which refuses every key nobody took.
//!
//! A vessel file has tables `[vessel]` (the hull: rigid body, damping, restoring), `[control]`
//! (the PID controller), `[initial]` (the default initial state) and the optional tables of
//! further components (`[external]`, …). Each component reads its keys with [`Params`]'s typed
//! getters, which check the type and the range and name the key, its unit and what is
//! allowed. [`Params::finish`] then rejects any key or table that no component read, with the
//! nearest valid name, so that every key either acts or is refused.
//!
//! The reader also records every value it handed out (defaults included) in a normalised
//! table: what the model was built from, for provenance and for editing a copy.

use crate::error::{Error, Result};
use std::collections::BTreeMap;
use toml::{Table, Value};

/// The range a number must lie in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Range {
    Finite,
    Positive,
    NonNegative,
    /// A physical range: what any vessel or sea can have (the named ranges below).
    Physical(&'static Physical),
}

/// A physical range of a length, angle or time key, with why it is where it is: a value beyond
/// it is no vessel's or sea's, but a slip (a unit, a digit), and is refused by name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Physical {
    pub lo: f64,
    pub hi: f64,
    /// Whether `lo` and `hi` themselves are allowed.
    pub lo_closed: bool,
    pub hi_closed: bool,
    /// Why the range is where it is (quoted in the error).
    pub why: &'static str,
}

impl Eq for Physical {}

impl Physical {
    pub fn contains(&self, v: f64) -> bool {
        (if self.lo_closed {
            v >= self.lo
        } else {
            v > self.lo
        }) && (if self.hi_closed {
            v <= self.hi
        } else {
            v < self.hi
        })
    }

    pub fn interval(&self) -> String {
        format!(
            "{}{}, {}{}",
            if self.lo_closed { "[" } else { "(" },
            compact(self.lo),
            compact(self.hi),
            if self.hi_closed { "]" } else { ")" }
        )
    }
}

/// A number as a message says it: in full below 1e7, else in scientific notation (`1e13`, not
/// fourteen digits; `1e300`, not three hundred).
pub fn compact(v: f64) -> String {
    if v != 0.0 && v.is_finite() && (v.abs() >= 1e7 || v.abs() < 1e-4) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

pub mod physical;

impl Range {
    fn check(self, name: &str, v: f64, unit: &str) -> Result<()> {
        let ok = v.is_finite()
            && match self {
                Range::Finite => true,
                Range::Positive => v > 0.0,
                Range::NonNegative => v >= 0.0,
                Range::Physical(r) => r.contains(v),
            };
        if ok {
            return Ok(());
        }
        if let (Range::Physical(r), true) = (self, v.is_finite()) {
            if r.lo == 0.0 && !r.lo_closed && v <= 0.0 {
                // A positive quantity: said as every other positive key says it.
                return Err(Error::InvalidInput(format!(
                    "{name} must be > 0 ({unit}), got {v}"
                )));
            }
            return Err(Error::InvalidInput(format!(
                "{name} must lie within {} ({unit}; {}), got {}",
                r.interval(),
                r.why,
                compact(v)
            )));
        }
        let what = match self {
            _ if !v.is_finite() => "finite",
            Range::Positive => "> 0",
            Range::NonNegative => "≥ 0",
            Range::Finite | Range::Physical(_) => "finite",
        };
        Err(Error::InvalidInput(format!(
            "{name} must be {what} ({unit}), got {v}"
        )))
    }
}

/// A parsed parameter file being read by the components.
#[derive(Debug, Clone)]
pub struct Params {
    input: Table,
    /// Keys taken, per table.
    taken: BTreeMap<String, Vec<String>>,
    /// Tables that a component looked for (taken whole or optional and absent).
    known_tables: Vec<String>,
    out: Table,
}

impl Params {
    /// Parse TOML text. A syntax error names the line and column.
    pub fn parse(text: &str) -> Result<Self> {
        let input: Table = text.parse().map_err(|e: toml::de::Error| {
            // One line, as the scenario reader says it: the message and where (toml's own
            // text quotes the line with a caret, over several lines).
            let at = e.span().map_or(String::new(), |r| {
                let before = &text[..r.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before[before.rfind('\n').map_or(0, |i| i + 1)..]
                    .chars()
                    .count()
                    + 1;
                format!(" (at line {line}, column {col})")
            });
            Error::Parse(format!("TOML syntax error: {}{at}", e.message().trim_end()))
        })?;
        Ok(Self::from_table(input))
    }

    /// Read an already parsed table.
    pub fn from_table(input: Table) -> Self {
        Self {
            input,
            taken: BTreeMap::new(),
            known_tables: Vec::new(),
            out: Table::new(),
        }
    }

    /// Whether the table `[section]` is present.
    pub fn has(&self, section: &str) -> bool {
        self.input.contains_key(section)
    }

    /// Declare `[section]` as read by a component even if absent (for the unknown-table check).
    pub fn declare(&mut self, section: &str) {
        if !self.known_tables.iter().any(|s| s == section) {
            self.known_tables.push(section.to_string());
        }
    }

    fn raw(&mut self, section: &str, key: &str) -> Result<Option<&Value>> {
        self.declare(section);
        self.taken
            .entry(section.to_string())
            .or_default()
            .push(key.to_string());
        match self.input.get(section) {
            None => Ok(None),
            Some(Value::Table(t)) => Ok(t.get(key)),
            Some(_) => Err(Error::Parse(format!("[{section}] must be a table"))),
        }
    }

    fn record(&mut self, section: &str, key: &str, v: Value) {
        let t = self
            .out
            .entry(section.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        if let Value::Table(t) = t {
            t.insert(key.to_string(), v);
        }
    }

    fn number(section: &str, key: &str, v: &Value, unit: &str) -> Result<f64> {
        match v {
            Value::Float(f) => Ok(*f),
            Value::Integer(i) => Ok(*i as f64),
            other => Err(Error::Parse(format!(
                "{section}.{key} must be a number ({unit}), got {} {other}",
                other.type_str()
            ))),
        }
    }

    /// A number, required.
    pub fn f64(&mut self, section: &str, key: &str, unit: &str, range: Range) -> Result<f64> {
        let v = self
            .raw(section, key)?
            .cloned()
            .ok_or_else(|| self.missing(section, key, unit))?;
        let x = Self::number(section, key, &v, unit)?;
        range.check(&format!("{section}.{key}"), x, unit)?;
        self.record(section, key, Value::Float(x));
        Ok(x)
    }

    /// A 3-vector, or `default` if absent (`None`: required).
    pub fn vec3(
        &mut self,
        section: &str,
        key: &str,
        default: Option<[f64; 3]>,
        unit: &str,
        range: Range,
    ) -> Result<[f64; 3]> {
        let x = match self.raw(section, key)?.cloned() {
            None => default.ok_or_else(|| self.missing(section, key, unit))?,
            Some(Value::Array(a)) => {
                if a.len() != 3 {
                    return Err(Error::Parse(format!(
                        "{section}.{key} must be 3 numbers ({unit}), got {} entries",
                        a.len()
                    )));
                }
                let mut x = [0.0; 3];
                for (i, v) in a.iter().enumerate() {
                    x[i] = Self::number(section, &format!("{key}[{i}]"), v, unit)?;
                }
                x
            }
            Some(other) => {
                return Err(Error::Parse(format!(
                    "{section}.{key} must be 3 numbers ({unit}), got {} {other}",
                    other.type_str()
                )))
            }
        };
        for (i, v) in x.iter().enumerate() {
            range.check(&format!("{section}.{key}[{i}]"), *v, unit)?;
        }
        self.record(
            section,
            key,
            Value::Array(x.iter().map(|v| Value::Float(*v)).collect()),
        );
        Ok(x)
    }

    /// The raw value of a key, taken (for a component that reads a nested structure itself,
    /// validating it and then recording what it used with [`Params::record_value`]).
    pub fn take_raw(&mut self, section: &str, key: &str) -> Result<Option<Value>> {
        Ok(self.raw(section, key)?.cloned())
    }

    /// Record the normalised value of a key read with [`Params::take_raw`].
    pub fn record_value(&mut self, section: &str, key: &str, v: Value) {
        self.record(section, key, v);
    }

    /// A number, or `None` if absent.
    pub fn opt_f64(
        &mut self,
        section: &str,
        key: &str,
        unit: &str,
        range: Range,
    ) -> Result<Option<f64>> {
        let Some(v) = self.raw(section, key)?.cloned() else {
            return Ok(None);
        };
        let x = Self::number(section, key, &v, unit)?;
        range.check(&format!("{section}.{key}"), x, unit)?;
        self.record(section, key, Value::Float(x));
        Ok(Some(x))
    }

    /// A list of rows of `width` numbers each (`width` 1: a list of numbers), or `None` if
    /// absent.
    pub fn rows(
        &mut self,
        section: &str,
        key: &str,
        width: usize,
        unit: &str,
        range: Range,
    ) -> Result<Option<Vec<Vec<f64>>>> {
        let Some(v) = self.raw(section, key)?.cloned() else {
            return Ok(None);
        };
        let shape = if width == 1 {
            "a list of numbers".to_string()
        } else {
            format!("a list of rows of {width} numbers")
        };
        let Value::Array(a) = &v else {
            return Err(Error::Parse(format!(
                "{section}.{key} must be {shape} ({unit}), got {} {v}",
                v.type_str()
            )));
        };
        let mut out = Vec::with_capacity(a.len());
        for (i, row) in a.iter().enumerate() {
            let vals: Vec<f64> = match (width, row) {
                (1, x) if !x.is_array() => {
                    vec![Self::number(section, &format!("{key}[{i}]"), x, unit)?]
                }
                (w, Value::Array(r)) if w > 1 && r.len() == w => r
                    .iter()
                    .enumerate()
                    .map(|(j, x)| Self::number(section, &format!("{key}[{i}][{j}]"), x, unit))
                    .collect::<Result<_>>()?,
                _ => {
                    return Err(Error::Parse(format!(
                        "{section}.{key} must be {shape} ({unit}); entry {i} is {row}"
                    )))
                }
            };
            for (j, x) in vals.iter().enumerate() {
                let name = if width == 1 {
                    format!("{section}.{key}[{i}]")
                } else {
                    format!("{section}.{key}[{i}][{j}]")
                };
                range.check(&name, *x, unit)?;
            }
            out.push(vals);
        }
        let rec = Value::Array(
            out.iter()
                .map(|r| {
                    if width == 1 {
                        Value::Float(r[0])
                    } else {
                        Value::Array(r.iter().map(|x| Value::Float(*x)).collect())
                    }
                })
                .collect(),
        );
        self.record(section, key, rec);
        Ok(Some(out))
    }

    /// One of `allowed` (the first is the default when absent).
    pub fn choice(
        &mut self,
        section: &str,
        key: &str,
        allowed: &[&'static str],
    ) -> Result<&'static str> {
        let got = match self.raw(section, key)?.cloned() {
            None => allowed[0],
            Some(Value::String(s)) => *allowed.iter().find(|a| **a == s).ok_or_else(|| {
                Error::InvalidInput(format!(
                    "{section}.{key} must be one of {}, got {s:?}",
                    quoted(allowed)
                ))
            })?,
            Some(other) => {
                return Err(Error::Parse(format!(
                    "{section}.{key} must be one of {}, got {} {other}",
                    quoted(allowed),
                    other.type_str()
                )))
            }
        };
        self.record(section, key, Value::String(got.to_string()));
        Ok(got)
    }

    /// One of `allowed`, required (for a choice whose default would be a guess).
    pub fn required_choice(
        &mut self,
        section: &str,
        key: &str,
        allowed: &[&'static str],
    ) -> Result<&'static str> {
        if self.raw(section, key)?.is_none() {
            let what = format!("one of {}", quoted(allowed));
            return Err(self.missing(section, key, &what));
        }
        self.choice(section, key, allowed)
    }

    /// A required key is absent: a misspelling of it is named as such, else it is missing.
    pub fn missing(&self, section: &str, key: &str, unit: &str) -> Error {
        self.misspelling(section, key)
            .unwrap_or_else(|| missing(section, key, unit))
    }

    /// The error naming a key of `[section]` that is a misspelling of `key`, if there is one
    /// (a key another getter read is no misspelling of this one).
    pub fn misspelling(&self, section: &str, key: &str) -> Option<Error> {
        let Some(Value::Table(t)) = self.input.get(section) else {
            return None;
        };
        let want = [key.to_string()];
        let taken = self.taken.get(section);
        let read = |k: &String| taken.is_some_and(|t| t.iter().any(|x| x == k));
        let typo = t.keys().find(|k| !read(k) && nearest(k, &want).is_some())?;
        let mut valid = taken.cloned().unwrap_or_default();
        valid.retain(|k| k != typo);
        Some(Error::Parse(unknown(
            typo,
            &valid,
            "field",
            &format!("[{section}]"),
        )))
    }

    /// The normalised table of what was read, without the check for unread keys (for a
    /// partial rebuild of a vessel whose file was checked whole before).
    pub fn read_so_far(self) -> Table {
        self.out
    }

    /// Refuse every table and key that no component read; return the normalised table.
    pub fn finish(self) -> Result<Table> {
        for (section, v) in &self.input {
            if !self.known_tables.iter().any(|s| s == section) {
                return Err(Error::Parse(unknown(
                    section,
                    &self.known_tables,
                    "table",
                    "the file",
                )));
            }
            if let Value::Table(t) = v {
                let taken = self.taken.get(section).cloned().unwrap_or_default();
                for key in t.keys() {
                    if !taken.iter().any(|k| k == key) {
                        return Err(Error::Parse(unknown(
                            key,
                            &taken,
                            "field",
                            &format!("[{section}]"),
                        )));
                    }
                }
            }
        }
        Ok(self.out)
    }
}

fn missing(section: &str, key: &str, unit: &str) -> Error {
    Error::Parse(format!(
        "missing field `{key}` in [{section}] ({section}.{key}, {unit})"
    ))
}

fn quoted(allowed: &[&str]) -> String {
    allowed
        .iter()
        .map(|a| format!("'{a}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// "unknown field `x` in [t]; did you mean 'y'? (allowed: …)".
pub fn unknown(name: &str, valid: &[String], what: &str, place: &str) -> String {
    let hint = nearest(name, valid)
        .map(|n| format!("; did you mean '{n}'?"))
        .unwrap_or_default();
    let mut v: Vec<&str> = valid.iter().map(|s| s.as_str()).collect();
    v.sort();
    v.dedup();
    format!(
        "unknown {what} `{name}` in {place}{hint} (allowed: {})",
        v.join(", ")
    )
}

/// The valid name closest to `name`, if it is close (edit distance at most half the longer
/// length, and at most 3).
pub fn nearest<'a>(name: &str, valid: &'a [String]) -> Option<&'a str> {
    valid
        .iter()
        .map(|v| (levenshtein(name, v), v))
        .filter(|(d, v)| *d <= 3 && *d * 2 <= v.chars().count().max(name.chars().count()))
        .min_by_key(|(d, _)| *d)
        .map(|(_, v)| v.as_str())
}

fn levenshtein(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for i in 1..=a.len() {
        let mut cur = vec![i; b.len() + 1];
        for j in 1..=b.len() {
            let sub = prev[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            cur[j] = sub.min(prev[j] + 1).min(cur[j - 1] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_are_taken_checked_and_the_rest_refused() {
        let mut p = Params::parse("[a]\nx = 2\nv = [1.0, 2, 3.5]\nvv = 1\n[b]\n").unwrap();
        assert_eq!(p.f64("a", "x", "m", Range::Positive).unwrap(), 2.0);
        assert_eq!(
            p.vec3("a", "v", None, "m", Range::Finite).unwrap(),
            [1.0, 2.0, 3.5]
        );
        assert_eq!(
            p.vec3("a", "w", Some([0.0; 3]), "m", Range::Finite)
                .unwrap(),
            [0.0; 3]
        );
        p.declare("b");
        let e = p.clone().finish().unwrap_err().to_string();
        assert!(
            e.contains("unknown field `vv` in [a]; did you mean 'v'?"),
            "{e}"
        );
        assert!(matches!(
            p.f64("a", "missing", "kg", Range::Finite),
            Err(Error::Parse(m)) if m.contains("missing field `missing`")
        ));
    }

    #[test]
    fn ranges_and_types_are_named() {
        let mut p = Params::parse("[a]\nx = -1\ny = nan\ns = \"no\"\nv = [1, 2]\n").unwrap();
        let e = p.f64("a", "x", "kg", Range::Positive).unwrap_err();
        assert_eq!(e.to_string(), "a.x must be > 0 (kg), got -1");
        let e = p.f64("a", "y", "kg", Range::NonNegative).unwrap_err();
        assert!(e.to_string().contains("a.y must be finite"));
        assert!(matches!(
            p.f64("a", "s", "kg", Range::Finite),
            Err(Error::Parse(_))
        ));
        let e = p.vec3("a", "v", None, "m", Range::Finite).unwrap_err();
        assert!(e.to_string().contains("3 numbers"));
        let e = Params::parse("[a\n").unwrap_err().to_string();
        assert!(e.contains("line") && e.contains("column"), "{e}");
    }

    #[test]
    fn physical_ranges_name_the_interval_and_why() {
        let mut p = Params::parse("[a]\nd = 5000\nok = 4.5\nk = 1\n").unwrap();
        let e = p
            .f64("a", "d", "m", Range::Physical(&physical::DRAFT))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "a.d must lie within (0, 40] (m; no ship draws more than 40 m), got 5000"
        );
        assert_eq!(
            p.f64("a", "ok", "m", Range::Physical(&physical::DRAFT))
                .unwrap(),
            4.5
        );
        let e = p
            .required_choice("a", "kind", &["tunnel", "azimuth"])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("missing field `kind`") && e.contains("'tunnel'"),
            "{e}"
        );
        let e = p
            .f64("a", "d", "m", Range::Physical(&physical::DRAFT))
            .unwrap_err()
            .to_string();
        assert!(e.contains("must lie within (0, 40]"), "{e}");
        let mut q = Params::parse("[a]\nd = -1\n").unwrap();
        let e = q
            .f64("a", "d", "m", Range::Physical(&physical::WATER_DEPTH))
            .unwrap_err()
            .to_string();
        assert_eq!(e, "a.d must be > 0 (m), got -1");
        for (name, _, r) in physical::ALL {
            assert!(r.lo < r.hi && !r.why.is_empty(), "{name}");
        }
    }

    #[test]
    fn unknown_tables_get_the_nearest_name() {
        let mut p = Params::parse("[vesel]\nmass = 1\n").unwrap();
        p.declare("vessel");
        p.declare("control");
        let e = p.finish().unwrap_err().to_string();
        assert!(
            e.contains("unknown table `vesel`") && e.contains("did you mean 'vessel'"),
            "{e}"
        );
    }
}
