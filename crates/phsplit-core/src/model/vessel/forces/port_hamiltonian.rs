//! A linear port-Hamiltonian subsystem coupled to the hull (docs/explanation/components/
//! port-hamiltonian.md): the paper's §2 class of input–state–output port-Hamiltonian systems in
//! its linear form, with states of its own.
//!
//! Table `[port_hamiltonian]` (optional): `states` (n names), `units` (n CF units, default
//! `"1"`), the matrices `J` (n×n, skew), `R` (n×n, symmetric positive semidefinite), `Q` (n×n,
//! symmetric positive definite), `G` (n×k), and optionally `P` (n×k), `S` (k×k, symmetric),
//! `N` (k×k, skew), all zero by default; `input` (k degrees of freedom of the body velocity,
//! from surge, sway, heave, roll, pitch, yaw), `point` (m, body frame, default the origin: the
//! translational inputs are the velocity of that point and the force acts there), `initial`
//! (n numbers, default zero) and `name` (its account and outputs, default `port_hamiltonian`).
//!
//! With `e = Qx` and the input `u = Bν` (`ν = M⁻¹(p, m)`; a translational row of `B` is
//! `e_iᵀ[I, −r̂]`, a rotational one `e_iᵀ[0, I]`), the subsystem is (van der Schaft, Jeltsema,
//! *Port-Hamiltonian Systems Theory*, 2014, §4.1, with feedthrough)
//!
//! ```text
//!   x' = (J − R) e + (G − P) u,     y = (G + P)ᵀ e + (N + S) u,
//! ```
//!
//! and its generalised force on the hull is `τ = −Bᵀy` (body force and moment about the body
//! origin). It is passive when `[[R, P], [Pᵀ, S]] ⪰ 0`, which is checked.
//!
//! **Energy statement.** Its storage `½ xᵀQx` is part of H. The hull and the subsystem exchange
//! `uᵀy` through a power-conserving interconnection, booked to no account; the account `name`
//! (dissipated) books `[e; u]ᵀ[[R, P], [Pᵀ, S]][e; u] ≥ 0`. Its states are integrated in flow S2
//! together with the momenta (the coupling is linear in them and in `ν`), by the exact flow or
//! by Gauss collocation, with the account booked exactly along either (the Gramian, or Gauss
//! quadrature of the quadratic power); flow S1 leaves them unchanged. The splitting then keeps
//! the paper's Prop. 2.2 for the whole interconnection: every positive-step method has
//! `H_n ≤ H_0 + Σ supplied`.

use super::{Force, Frozen, Output, OwnLinear, OwnState};
use crate::error::Error;
use crate::flows::collocation::Z3;
use crate::lie::so3;
use crate::model::vessel::params::{Params, Range};
use crate::solve::Account;
use nalgebra::{DMatrix, DVector, Vector3};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// The largest storage a subsystem may start with (J).
const MAX_INITIAL_STORAGE: f64 = 1e12;

const T: &str = "port_hamiltonian";

/// The degrees of freedom an input may take, in the order of `ν = (v, ω)`.
pub const DOFS: [&str; 6] = ["surge", "sway", "heave", "roll", "pitch", "yaw"];

/// Largest number of states (a subsystem larger than this is not a component of a hull).
pub const MAX_STATES: usize = 64;

/// Largest magnitude of a matrix entry: the storage and the rows multiply entries by each other
/// and by the states, which must stay finite (no physical subsystem comes near it).
pub const MAX_ENTRY: f64 = 1e100;

/// Largest distance of the input point from the body origin (m).
pub const MAX_ARM: f64 = 1000.0;

#[derive(Debug)]
pub struct PortHamiltonian {
    name: &'static str,
    accounts: &'static [Account],
    states: Vec<OwnState>,
    /// `Q` (for the storage and the outputs), the output map `(G + P)ᵀQ` and `N + S`, `B`.
    q: DMatrix<f64>,
    y_x: DMatrix<f64>,
    y_u: DMatrix<f64>,
    b: DMatrix<f64>,
    dofs: Vec<usize>,
    lin: OwnLinear,
}

/// The accounts of a subsystem named `name`: interned, one static slice per distinct name
/// (a sweep over many vessels with the same name makes one).
fn accounts_of(name: &str) -> (&'static str, &'static [Account]) {
    static NAMES: OnceLock<Mutex<HashMap<String, (&'static str, &'static [Account])>>> =
        OnceLock::new();
    let mut map = NAMES
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    *map.entry(name.to_string()).or_insert_with(|| {
        let n: &'static str = Box::leak(name.to_string().into_boxed_str());
        let acc: &'static [Account] = Box::leak(Box::new([Account::dissipated(n)]));
        (n, acc)
    })
}

fn strings(p: &mut Params, key: &str, what: &str) -> crate::Result<Option<Vec<String>>> {
    let Some(v) = p.take_raw(T, key)? else {
        return Ok(None);
    };
    let bad = || {
        Error::Parse(format!(
            "{T}.{key} must be a list of strings ({what}), got {} {v}",
            v.type_str()
        ))
    };
    let toml::Value::Array(a) = &v else {
        return Err(bad());
    };
    let out: Vec<String> = a
        .iter()
        .map(|x| x.as_str().map(str::to_string).ok_or_else(bad))
        .collect::<crate::Result<_>>()?;
    p.record_value(T, key, v.clone());
    Ok(Some(out))
}

/// Letters, digits and underscores, starting with a letter, at most 64 characters (the names
/// of the outputs built from it, `<name>_<state>`, stay within NetCDF's 256).
fn is_name(s: &str) -> bool {
    let mut c = s.chars();
    s.len() <= 64
        && c.next().is_some_and(|f| f.is_ascii_alphabetic())
        && s.chars().all(|x| x.is_ascii_alphanumeric() || x == '_')
}

/// A matrix of `rows × cols` (`None`: absent and optional, zero).
fn matrix(
    p: &mut Params,
    key: &str,
    rows: usize,
    cols: usize,
    required: bool,
) -> crate::Result<DMatrix<f64>> {
    let what = format!("{rows}×{cols}");
    let raw = p.take_raw(T, key)?;
    let Some(v) = raw else {
        if required {
            return Err(p.missing(T, key, &format!("a {what} matrix, as a list of rows")));
        }
        return Ok(DMatrix::zeros(rows, cols));
    };
    let toml::Value::Array(a) = &v else {
        return Err(Error::Parse(format!(
            "{T}.{key} must be a {what} matrix (a list of {rows} rows of {cols} numbers), got {} {v}",
            v.type_str()
        )));
    };
    let mut m = DMatrix::zeros(rows, cols);
    if a.len() != rows {
        return Err(Error::InvalidInput(format!(
            "{T}.{key} must be {what} (a list of {rows} rows of {cols} numbers), got {} rows",
            a.len()
        )));
    }
    for (i, row) in a.iter().enumerate() {
        let r = row.as_array().filter(|r| r.len() == cols).ok_or_else(|| {
            Error::InvalidInput(format!(
                "{T}.{key} must be {what}; its row {i} is {row}, not {cols} numbers"
            ))
        })?;
        for (j, x) in r.iter().enumerate() {
            m[(i, j)] = x
                .as_float()
                .or(x.as_integer().map(|v| v as f64))
                .filter(|v| v.abs() <= MAX_ENTRY)
                .ok_or_else(|| {
                    Error::InvalidInput(format!(
                        "{T}.{key}[{i}][{j}] must be a finite number within ±{MAX_ENTRY:e} (the products of two entries and a state must stay finite), got {x}"
                    ))
                })?;
        }
    }
    p.record_value(T, key, v.clone());
    Ok(m)
}

/// The largest `|a_ij − s a_ji|` against the matrix's size, for the symmetry (`s = 1`) and
/// skew-symmetry (`s = −1`) checks: to round-off of the entries as written.
fn asymmetry(m: &DMatrix<f64>, s: f64) -> f64 {
    let size = m.amax().max(f64::MIN_POSITIVE);
    let mut worst: f64 = 0.0;
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            worst = worst.max((m[(i, j)] - s * m[(j, i)]).abs());
        }
    }
    worst / size
}

/// The smallest eigenvalue of a symmetric matrix scaled by its diagonal,
/// `D^{-1/2} M D^{-1/2}` (`D` its diagonal's magnitudes, 1 where zero), and the largest
/// magnitude: the states have units of their own, and the scaled matrix's eigenvalues do not
/// depend on them (a diagonal `Q = diag(C, 1/A)` is definite whatever C and A are).
fn min_eigenvalue(m: &DMatrix<f64>) -> (f64, f64) {
    let d: Vec<f64> = (0..m.nrows())
        .map(|i| {
            let a = m[(i, i)].abs().sqrt();
            if a > 0.0 {
                a
            } else {
                1.0
            }
        })
        .collect();
    let sym = DMatrix::from_fn(m.nrows(), m.ncols(), |i, j| {
        0.5 * (m[(i, j)] + m[(j, i)]) / (d[i] * d[j])
    });
    let ev = sym.symmetric_eigenvalues();
    let lo = ev.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = ev.iter().map(|v| v.abs()).fold(0.0, f64::max);
    (lo, hi)
}

pub fn build(p: &mut Params, _body: &super::Body) -> crate::Result<Option<Arc<dyn Force>>> {
    p.declare(T);
    if !p.has(T) {
        return Ok(None);
    }
    let name = match p.take_raw(T, "name")? {
        None => T.to_string(),
        Some(toml::Value::String(s)) if is_name(&s) => s,
        Some(v) => {
            return Err(Error::InvalidInput(format!(
                "{T}.name must be a name of at most 64 letters, digits and underscores that starts with a letter (it names the subsystem's account and outputs), got {v}"
            )))
        }
    };
    p.record_value(T, "name", toml::Value::String(name.clone()));
    let states = strings(p, "states", "the names of the subsystem's states")?
        .ok_or_else(|| p.missing(T, "states", "a list of state names"))?;
    let n = states.len();
    if n == 0 || n > MAX_STATES {
        return Err(Error::InvalidInput(format!(
            "{T}.states must name between 1 and {MAX_STATES} states, got {n}"
        )));
    }
    for (i, s) in states.iter().enumerate() {
        if !is_name(s) {
            return Err(Error::InvalidInput(format!(
                "{T}.states[{i}] must be a name of at most 64 letters, digits and underscores that starts with a letter, got {s:?}"
            )));
        }
        if states[..i].contains(s) {
            return Err(Error::InvalidInput(format!(
                "{T}.states names {s:?} twice; each state needs its own name"
            )));
        }
    }
    let units = strings(p, "units", "a CF unit per state")?.unwrap_or_else(|| vec!["1".into(); n]);
    if units.len() != n {
        return Err(Error::InvalidInput(format!(
            "{T}.units must give one unit per state ({n}), got {}",
            units.len()
        )));
    }
    for (i, u) in units.iter().enumerate() {
        if !is_cf_unit(u) {
            return Err(Error::InvalidInput(format!(
                "{T}.units[{i}] = {u:?} is not a CF unit: a product of SI symbols with integer powers, as UDUNITS writes them (\"kg m2 s-1\", \"rad\", \"N m\", \"1\")"
            )));
        }
    }
    let input = strings(p, "input", "degrees of freedom of the body velocity")?
        .ok_or_else(|| p.missing(T, "input", "a list of degrees of freedom"))?;
    let mut dofs = Vec::new();
    for (i, d) in input.iter().enumerate() {
        let Some(k) = DOFS.iter().position(|x| x == d) else {
            return Err(Error::InvalidInput(format!(
                "{T}.input[{i}] must be one of {}, got {d:?}",
                DOFS.map(|x| format!("'{x}'")).join(", ")
            )));
        };
        if dofs.contains(&k) {
            return Err(Error::InvalidInput(format!(
                "{T}.input names {d:?} twice; each degree of freedom is one input"
            )));
        }
        dofs.push(k);
    }
    let k = dofs.len();
    if k == 0 {
        return Err(Error::InvalidInput(format!(
            "{T}.input must name at least one degree of freedom ({})",
            DOFS.join(", ")
        )));
    }
    let point = p.vec3(T, "point", Some([0.0; 3]), "m, body frame", Range::Finite)?;
    if let Some(i) = point.iter().position(|r| r.abs() > MAX_ARM) {
        return Err(Error::InvalidInput(format!(
            "{T}.point[{i}] must lie within {MAX_ARM} m of the body origin (m, body frame), got {}",
            point[i]
        )));
    }
    let j = matrix(p, "J", n, n, true)?;
    let r = matrix(p, "R", n, n, true)?;
    let q = matrix(p, "Q", n, n, true)?;
    let g = matrix(p, "G", n, k, true)?;
    let pm = matrix(p, "P", n, k, false)?;
    let s = matrix(p, "S", k, k, false)?;
    let nm = matrix(p, "N", k, k, false)?;
    // Round-off of the entries as written: a matrix given to 12 digits passes.
    const SYM: f64 = 1e-12;
    for (key, m, sign, what) in [
        ("J", &j, -1.0, "skew-symmetric (J = −Jᵀ)"),
        ("R", &r, 1.0, "symmetric (R = Rᵀ)"),
        ("Q", &q, 1.0, "symmetric (Q = Qᵀ)"),
        ("S", &s, 1.0, "symmetric (S = Sᵀ)"),
        ("N", &nm, -1.0, "skew-symmetric (N = −Nᵀ)"),
    ] {
        let a = asymmetry(m, sign);
        if a > SYM {
            return Err(Error::InvalidInput(format!(
                "{T}.{key} must be {what}: its largest |a_ij {} a_ji| is {a:.3e} of its largest entry (allowed: ≤ {SYM:e})",
                if sign > 0.0 { "−" } else { "+" }
            )));
        }
    }
    let (lo, hi) = min_eigenvalue(&q);
    if !(lo > 1e-12 * hi) {
        return Err(Error::InvalidInput(format!(
            "{T}.Q must be symmetric positive definite (the storage ½ xᵀQx): its smallest eigenvalue is {lo:.6e}, its largest {hi:.6e} (of Q scaled by its diagonal, D^(-1/2) Q D^(-1/2); allowed: smallest > 1e-12 × largest)"
        )));
    }
    let (lo, hi) = min_eigenvalue(&r);
    if lo < -1e-12 * hi.max(f64::MIN_POSITIVE) {
        return Err(Error::InvalidInput(format!(
            "{T}.R must be symmetric positive semidefinite (a dissipation): its smallest eigenvalue scaled by its diagonal is {lo:.6e} (allowed: ≥ 0)"
        )));
    }
    let mut d = DMatrix::zeros(n + k, n + k);
    d.view_mut((0, 0), (n, n)).copy_from(&r);
    d.view_mut((0, n), (n, k)).copy_from(&pm);
    d.view_mut((n, 0), (k, n)).copy_from(&pm.transpose());
    d.view_mut((n, n), (k, k)).copy_from(&s);
    let (lo, hi) = min_eigenvalue(&d);
    if lo < -1e-12 * hi.max(f64::MIN_POSITIVE) {
        return Err(Error::InvalidInput(format!(
            "{T}: [[R, P], [Pᵀ, S]] must be positive semidefinite for the subsystem to be passive: its smallest eigenvalue scaled by its diagonal is {lo:.6e} (allowed: ≥ 0; with P = 0 this needs S ⪰ 0)"
        )));
    }
    let initial = match p.rows(T, "initial", 1, "the states' units", Range::Finite)? {
        None => vec![0.0; n],
        Some(v) if v.len() == n => v.into_iter().map(|r| r[0]).collect(),
        Some(v) => {
            return Err(Error::InvalidInput(format!(
                "{T}.initial must give one value per state ({n}), got {}",
                v.len()
            )))
        }
    };
    // The storage it starts with: the largest ship at full speed carries about 3e10 J of
    // kinetic energy; a subsystem that starts with more than 1e12 J is a slip of units.
    let x0 = DVector::from_column_slice(&initial);
    let h0 = 0.5 * x0.dot(&(&q * &x0));
    if !(h0.is_finite() && h0 <= MAX_INITIAL_STORAGE) {
        return Err(Error::InvalidInput(format!(
            "{T}.initial stores {h0:.4e} J (½ xᵀQx): at most {MAX_INITIAL_STORAGE:e} J, a hundred times the kinetic energy of the largest ship at full speed; check the initial values and the units of Q"
        )));
    }
    let (name, accounts) = accounts_of(&name);
    // u = Bν.
    let rh = so3::hat(&Vector3::from(point));
    let mut b = DMatrix::zeros(k, 6);
    for (i, &dof) in dofs.iter().enumerate() {
        if dof < 3 {
            b[(i, dof)] = 1.0;
            for c in 0..3 {
                b[(i, 3 + c)] = -rh[(dof, c)];
            }
        } else {
            b[(i, dof)] = 1.0;
        }
    }
    let y_x = (&g + &pm).transpose() * &q;
    let y_u = &nm + &s;
    let mut t = DMatrix::zeros(n + k, n + 6);
    t.view_mut((0, 0), (n, n)).copy_from(&q);
    t.view_mut((n, n), (k, 6)).copy_from(&b);
    let lin = OwnLinear::exchange(
        (&j - &r) * &q,
        (&g - &pm) * &b,
        -b.transpose() * &y_x,
        -b.transpose() * &y_u * &b,
        0,
        t.transpose() * &d * &t,
    );
    let states = states
        .iter()
        .zip(units)
        .zip(initial)
        .map(|((s, unit), initial)| OwnState {
            name: format!("{name}_{s}"),
            long_name: format!("state {s} of the port-Hamiltonian subsystem {name}"),
            unit,
            initial,
        })
        .collect();
    Ok(Some(Arc::new(PortHamiltonian {
        name,
        accounts,
        states,
        q,
        y_x,
        y_u,
        b,
        dofs,
        lin,
    })))
}

impl PortHamiltonian {
    /// The input `u = Bν` and the output `y` at the states `x` and the velocities `nu`.
    fn io(&self, x: &[f64], nu: &[Vector3<f64>; 2]) -> (DVector<f64>, DVector<f64>) {
        let v = DVector::from_iterator(6, nu[0].iter().chain(nu[1].iter()).cloned());
        let u = &self.b * v;
        let y = &self.y_x * DVector::from_column_slice(x) + &self.y_u * &u;
        (u, y)
    }
}

impl Force for PortHamiltonian {
    fn name(&self) -> &'static str {
        T
    }
    fn accounts(&self) -> &'static [Account] {
        self.accounts
    }
    fn add_s2(&self, _fr: &Frozen, _b: &mut super::S2Builder) {}
    fn own_states(&self) -> &[OwnState] {
        &self.states
    }
    fn own_linear(&self) -> Option<&OwnLinear> {
        Some(&self.lin)
    }
    fn own_storage(&self, x: &[f64]) -> f64 {
        let x = DVector::from_column_slice(x);
        0.5 * x.dot(&(&self.q * &x))
    }
    fn own_outputs(&self, fr: &Frozen, z: &[Z3; 2], x: &[f64], _t: f64, out: &mut Vec<Output>) {
        let nu = fr.nu(z);
        let (u, y) = self.io(x, &nu);
        let name = self.name;
        out.push(Output::new(
            format!("{name}_storage"),
            "J",
            format!("energy stored in the port-Hamiltonian subsystem {name}, ½ xᵀQx"),
            self.own_storage(x),
        ));
        out.push(Output::new(
            format!("{name}_power"),
            "W",
            format!("power from the hull into the port-Hamiltonian subsystem {name}, yᵀu"),
            u.dot(&y),
        ));
        for (i, &dof) in self.dofs.iter().enumerate() {
            let unit = if dof < 3 { "N" } else { "N m" };
            out.push(Output::new(
                format!("{name}_force_{}", DOFS[dof]),
                unit,
                format!(
                    "generalised force of the port-Hamiltonian subsystem {name} on the hull in {}, −y",
                    DOFS[dof]
                ),
                -y[i],
            ));
        }
    }
}

/// Whether `u` is a unit the CF conventions take (CF 1.8 §3.1, UDUNITS-2 syntax), in the form
/// phsplit writes: `1`, or SI symbols with an optional decimal prefix and an integer power,
/// separated by spaces or dots (`kg m2 s-1`, `N.m`, `rad s-1`, `degree`).
fn is_cf_unit(u: &str) -> bool {
    const SYMBOLS: [&str; 22] = [
        "m", "s", "g", "kg", "rad", "sr", "N", "J", "W", "Pa", "K", "A", "V", "Hz", "mol", "cd",
        "C", "ohm", "T", "degree", "bar", "L",
    ];
    const PREFIXES: [&str; 8] = ["k", "M", "G", "c", "m", "u", "n", "h"];
    let known = |sym: &str| {
        SYMBOLS.contains(&sym)
            || PREFIXES.iter().any(|p| {
                sym.len() > p.len() && sym.starts_with(p) && SYMBOLS.contains(&&sym[p.len()..])
            })
    };
    let u = u.trim();
    if u == "1" {
        return true;
    }
    let tokens: Vec<&str> = u.split([' ', '.']).filter(|t| !t.is_empty()).collect();
    !tokens.is_empty()
        && tokens.iter().all(|t| {
            let cut = t
                .find(|c: char| c == '-' || c.is_ascii_digit())
                .unwrap_or(t.len());
            let (sym, power) = t.split_at(cut);
            known(sym)
                && (power.is_empty()
                    || power
                        .trim_start_matches('-')
                        .chars()
                        .all(|c| c.is_ascii_digit())
                        && !power.trim_start_matches('-').is_empty())
        })
}

#[cfg(test)]
mod tests {
    use crate::model::vessel::{LinearFlow, Vessel, VesselSystem, PAPER_VESSEL_TOML};
    use crate::solve::{AccountKind, Model};
    use nalgebra::{DVector, Vector3};

    /// A two-state subsystem on sway at a point off the centre and on roll, with every matrix
    /// nonzero (`[[R, P], [Pᵀ, S]] ⪰ 0` by construction: `LLᵀ`).
    const TABLE: &str = r#"
[port_hamiltonian]
name = "tank"
states = ["a", "b"]
units = ["rad", "kg m2 s-1"]
J = [[0.0, 1.0], [-1.0, 0.0]]
R = [[0.5, 0.1], [0.1, 0.4]]
Q = [[3.0e6, 1.0], [1.0, 2.0e-6]]
G = [[0.3, 1.0e-3], [2.0e5, -1.0e5]]
P = [[0.2, 0.1], [0.1, -0.3]]
S = [[0.35, -0.05], [-0.05, 0.4]]
N = [[0.0, 0.7], [-0.7, 0.0]]
input = ["sway", "roll"]
point = [10.0, -2.0, 4.0]
initial = [0.02, 1.0e4]
"#;

    fn vessel(extra: &str) -> crate::Result<Vessel> {
        Vessel::from_toml_str(&format!("{PAPER_VESSEL_TOML}\n{extra}"))
    }

    #[test]
    fn the_storage_pays_for_the_force_on_the_hull_and_the_dissipation() {
        let v = vessel(TABLE).unwrap();
        assert_eq!(v.own_dim(), 2);
        let f = v.force("port_hamiltonian").unwrap();
        let lin = f.own_linear().unwrap();
        let q = DVector::from_column_slice(&[0.0; 2]);
        let _ = q;
        for seed in 0..20 {
            let r = |k: u64| ((seed * 7919 + k * 104729) % 1000) as f64 / 500.0 - 1.0;
            let x = DVector::from_vec(vec![0.05 * r(1), 3e4 * r(2)]);
            let nu = DVector::from_vec(vec![
                r(3),
                r(4),
                r(5),
                0.01 * r(6),
                0.02 * r(7),
                0.01 * r(8),
            ]);
            let xdot = &lin.axx * &x + &lin.axnu * &nu;
            let tau = &lin.fx * &x + &lin.fnu * &nu;
            let mut xn = x.as_slice().to_vec();
            xn.extend_from_slice(nu.as_slice());
            let xn = DVector::from_vec(xn);
            let d = xn.dot(&(&lin.diss * &xn));
            // d/dt ½xᵀQx by a centred difference of the storage along x'.
            let e = 1e-6;
            let (xp, xm) = (&x + &xdot * e, &x - &xdot * e);
            let rate = (f.own_storage(xp.as_slice()) - f.own_storage(xm.as_slice())) / (2.0 * e);
            let want = -nu.dot(&tau) - d;
            let scale = rate.abs().max(d.abs()).max(nu.dot(&tau).abs());
            assert!((rate - want).abs() <= 1e-7 * scale, "{rate} vs {want}");
            assert!(d >= -1e-12 * scale, "dissipation {d}");
        }
    }

    #[test]
    fn the_ledger_closes_on_one_sub_step_of_either_flow_s2() {
        let v = vessel(TABLE).unwrap();
        let mut s0 = v.initial_state();
        s0.p += Vector3::new(1e6, -2e6, 3e5);
        s0.m += Vector3::new(4e6, 1e6, -2e6);
        for lf in [LinearFlow::Exact, LinearFlow::Gauss] {
            let sys = VesselSystem::new(&v, Some(0.0)).with_linear_flow(lf);
            for stages in 1..=3 {
                let mut s = s0.clone();
                let w = sys.flow_s2(&mut s, 0.9, 0.0, true, true, stages);
                let acc = sys.accounts();
                let booked =
                    w.total(acc, AccountKind::Supplied) - w.total(acc, AccountKind::Dissipated);
                let dh = v.energy(&s) - v.energy(&s0);
                let k = acc.iter().position(|a| a.name == "tank").unwrap();
                assert!(
                    w.get(k) > 0.0,
                    "{lf:?} s={stages}: the tank dissipates {}",
                    w.get(k)
                );
                let flows: f64 = (0..acc.len()).map(|i| w.get(i).abs()).sum();
                let size = v.energy(&s0).max(v.energy(&s)).max(flows);
                eprintln!("{lf:?} s={stages}: {:.3e}", (dh - booked).abs() / size);
                assert!(
                    (dh - booked).abs() <= 1e-10 * size,
                    "{lf:?} s={stages}: ΔH {dh} booked {booked}"
                );
                assert!(s.own.iter().zip(&s0.own).any(|(a, b)| a != b));
            }
        }
    }

    #[test]
    fn bad_matrices_are_named() {
        let cases = [
            (
                "J = [[0.0, 1.0], [-1.0, 0.0]]",
                "J = [[0.0, 1.0], [1.0, 0.0]]",
                "port_hamiltonian.J must be skew",
            ),
            (
                "R = [[0.5, 0.1], [0.1, 0.4]]",
                "R = [[0.5, 0.1], [0.2, 0.4]]",
                "port_hamiltonian.R must be symmetric",
            ),
            (
                "R = [[0.5, 0.1], [0.1, 0.4]]",
                "R = [[-0.5, 0.1], [0.1, 0.4]]",
                "port_hamiltonian.R must be symmetric positive semidefinite",
            ),
            (
                "Q = [[3.0e6, 1.0], [1.0, 2.0e-6]]",
                "Q = [[3.0e6, 1.0], [1.0, -2.0e-6]]",
                "port_hamiltonian.Q must be symmetric positive definite",
            ),
            (
                "G = [[0.3, 1.0e-3], [2.0e5, -1.0e5]]",
                "G = [[0.3], [2.0e5]]",
                "port_hamiltonian.G must be 2×2",
            ),
            (
                "S = [[0.35, -0.05], [-0.05, 0.4]]",
                "S = [[0.0, 0.0], [0.0, 0.0]]",
                "[[R, P], [Pᵀ, S]] must be positive semidefinite",
            ),
            (
                "input = [\"sway\", \"roll\"]",
                "input = [\"sway\", \"rol\"]",
                "port_hamiltonian.input[1] must be one of",
            ),
            (
                "input = [\"sway\", \"roll\"]",
                "input = [\"roll\", \"roll\"]",
                "names \"roll\" twice",
            ),
            (
                "states = [\"a\", \"b\"]",
                "states = [\"a\", \"a\"]",
                "names \"a\" twice",
            ),
            (
                "initial = [0.02, 1.0e4]",
                "initial = [0.02]",
                "port_hamiltonian.initial must give one value per state",
            ),
        ];
        for (from, to, want) in cases {
            assert!(TABLE.contains(from), "{from}");
            let e = vessel(&TABLE.replace(from, to)).unwrap_err().to_string();
            assert!(e.contains(want), "{to}: {e}");
        }
        let e = vessel(&TABLE.replace("J = [[0.0, 1.0], [-1.0, 0.0]]\n", "")).unwrap_err();
        assert!(e.to_string().contains("port_hamiltonian.J"), "{e}");
    }

    #[test]
    fn units_are_cf_units() {
        for ok in [
            "1",
            "rad",
            "kg m2 s-1",
            "N m",
            "N.m",
            "m s-2",
            "degree",
            "kN",
            "MJ",
            "m3",
        ] {
            assert!(super::is_cf_unit(ok), "{ok}");
        }
        for bad in ["furlongs", "", "m/s", "kg^2", "m-", "1 m x", "metres"] {
            assert!(!super::is_cf_unit(bad), "{bad}");
        }
    }
}
