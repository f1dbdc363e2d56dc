//! The registry of methods: one table, one row a method, with its names, kind, metadata and
//! constructor. Adding a method is adding a row (and its coefficients in `composition.rs` or
//! `butcher.rs`); its name then parses ([`Method`]'s `FromStr`), lists ([`names`]) and enters
//! the convergence battery of the kernels' tests.

use super::butcher::ButcherTableau;
use super::composition::Composition;
use crate::error::{Error, Result};

/// Any method phsplit can run.
#[derive(Debug, Clone, PartialEq)]
pub enum Method {
    Splitting(Composition),
    RungeKutta(ButcherTableau),
}

/// One row of the registry.
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    /// The name a user gives (lower case; parsing is exact).
    pub name: &'static str,
    /// Other accepted names.
    pub aliases: &'static [&'static str],
    /// What the method is, in a few words (for `phsplit methods`).
    pub summary: &'static str,
    build: fn() -> Method,
}

/// Every method, in the order they are listed to users.
pub const REGISTRY: &[Entry] = &[
    Entry {
        name: "lie",
        aliases: &["lie-trotter"],
        summary: "Lie–Trotter splitting, positive steps",
        build: || Method::Splitting(Composition::lie()),
    },
    Entry {
        name: "sp2",
        aliases: &["strang"],
        summary: "Strang splitting, positive steps",
        build: || Method::Splitting(Composition::strang()),
    },
    Entry {
        name: "mcl2",
        aliases: &["mclachlan2"],
        summary: "McLachlan's 2-stage order-2 splitting, minimal error norm, positive steps",
        build: || Method::Splitting(Composition::mclachlan_2()),
    },
    Entry {
        name: "sp4",
        aliases: &[],
        summary: "Blanes–Moan splitting, 6 stages",
        build: || Method::Splitting(Composition::blanes_moan_4()),
    },
    Entry {
        name: "sp6",
        aliases: &[],
        summary: "Blanes–Moan splitting, 10 stages",
        build: || Method::Splitting(Composition::blanes_moan_6()),
    },
    Entry {
        name: "euler",
        aliases: &[],
        summary: "explicit Euler (baseline)",
        build: || Method::RungeKutta(ButcherTableau::euler()),
    },
    Entry {
        name: "heun",
        aliases: &["improved-euler"],
        summary: "Heun, the paper's Improved Euler (baseline)",
        build: || Method::RungeKutta(ButcherTableau::heun()),
    },
    Entry {
        name: "rk4",
        aliases: &[],
        summary: "classical Runge–Kutta (baseline)",
        build: || Method::RungeKutta(ButcherTableau::rk4()),
    },
];

/// The names of the registered methods, in order.
pub fn names() -> Vec<&'static str> {
    REGISTRY.iter().map(|e| e.name).collect()
}

impl std::str::FromStr for Method {
    type Err = Error;
    /// A registered name or alias, exactly (lower case): `"sp4"`, `"strang"`, … Anything else
    /// is refused with the list of valid names.
    fn from_str(name: &str) -> Result<Self> {
        REGISTRY
            .iter()
            .find(|e| e.name == name || e.aliases.contains(&name))
            .map(|e| (e.build)())
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "unknown method {name:?}; valid methods: {}",
                    names().join(", ")
                ))
            })
    }
}

impl Method {
    pub fn name(&self) -> &'static str {
        match self {
            Method::Splitting(c) => c.name,
            Method::RungeKutta(t) => t.name,
        }
    }
    /// `"splitting"` or `"runge-kutta"`.
    pub fn kind(&self) -> &'static str {
        match self {
            Method::Splitting(_) => "splitting",
            Method::RungeKutta(_) => "runge-kutta",
        }
    }
    pub fn order(&self) -> usize {
        match self {
            Method::Splitting(c) => c.order,
            Method::RungeKutta(t) => t.order,
        }
    }
    pub fn stages(&self) -> usize {
        match self {
            Method::Splitting(c) => c.stages,
            Method::RungeKutta(t) => t.stages(),
        }
    }
    pub fn citation(&self) -> &'static str {
        match self {
            Method::Splitting(c) => c.citation,
            Method::RungeKutta(t) => t.citation,
        }
    }
    /// The order the sub-flows must have for the composition to keep its order (paper
    /// Remark 2.3): the method's order for a splitting, none (0) for a Runge–Kutta method,
    /// which uses no sub-flows. A model that cannot provide it refuses the method.
    pub fn subflow_order(&self) -> usize {
        match self {
            Method::Splitting(c) => c.order,
            Method::RungeKutta(_) => 0,
        }
    }
    /// Whether the method carries the passivity guarantee of Prop. 2.2 (all sub-steps positive).
    /// Runge–Kutta methods never do.
    pub fn all_positive(&self) -> bool {
        match self {
            Method::Splitting(c) => c.all_positive(),
            Method::RungeKutta(_) => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::methods::{Composition, Method, REGISTRY};

    fn sums(c: &Composition) -> (f64, f64) {
        let a: f64 = c.coefficients(true).iter().sum();
        let b: f64 = c.coefficients(false).iter().sum();
        (a, b)
    }

    #[test]
    fn consistency_and_shape() {
        for c in [
            Composition::lie(),
            Composition::strang(),
            Composition::mclachlan_2(),
            Composition::blanes_moan_4(),
            Composition::blanes_moan_6(),
        ] {
            let (a, b) = sums(&c);
            assert!(
                (a - 1.0).abs() < 1e-15 && (b - 1.0).abs() < 1e-15,
                "{}: {a} {b}",
                c.name
            );
            // Alternating flows after merging.
            for w in c.substeps.windows(2) {
                assert_ne!(w[0].0, w[1].0);
            }
        }
        let s = Composition::strang();
        assert_eq!(s.substeps, vec![(true, 0.5), (false, 1.0), (true, 0.5)]);
        assert_eq!(Composition::blanes_moan_4().substeps.len(), 13);
        assert_eq!(Composition::blanes_moan_6().substeps.len(), 21);
        assert!(s.all_positive() && Composition::lie().all_positive());
        assert!(!Composition::blanes_moan_4().all_positive());
        assert!(!Composition::blanes_moan_6().all_positive());
    }

    #[test]
    fn symmetric_methods_are_palindromes() {
        for c in [
            Composition::strang(),
            Composition::mclachlan_2(),
            Composition::blanes_moan_4(),
            Composition::blanes_moan_6(),
        ] {
            let rev: Vec<_> = c.substeps.iter().rev().cloned().collect();
            assert_eq!(rev, c.substeps, "{}", c.name);
        }
    }

    #[test]
    fn mclachlans_coefficient_is_the_published_one() {
        // λ = 0.1931833275037836 as printed by Omelyan, Mryglod & Folk (2002) and
        // used for McLachlan's method; the closed form in the code must give it to round-off.
        let c = Composition::mclachlan_2();
        assert!((c.substeps[0].1 - 0.193_183_327_503_783_6).abs() < 4.0 * f64::EPSILON);
        assert_eq!(c.substeps.len(), 5);
        assert!(c.all_positive() && c.dissipation_ratio_bound(true) == f64::INFINITY);
    }

    #[test]
    fn prop_2_5_bounds_of_sp4() {
        // docs/model.md §1: 12.9 when the dissipative flow takes the a's, 4.48 for the b's.
        let c = Composition::blanes_moan_4();
        assert!((c.dissipation_ratio_bound(true) - 12.9).abs() < 0.05);
        assert!((c.dissipation_ratio_bound(false) - 4.48).abs() < 0.01);
        assert_eq!(
            Composition::strang().dissipation_ratio_bound(true),
            f64::INFINITY
        );
    }

    #[test]
    fn names_resolve_and_unknown_ones_list_the_valid() {
        for e in REGISTRY {
            assert_eq!(e.name.parse::<Method>().unwrap().name(), e.name);
            for a in e.aliases {
                assert_eq!(a.parse::<Method>().unwrap().name(), e.name);
            }
        }
        // Parsing is exact: one rule, here and in every front end.
        for bad in ["SP4", "Sp2", " sp2", "sp2 ", "S1", ""] {
            assert!(bad.parse::<Method>().is_err(), "{bad:?}");
        }
        let e = "rk45".parse::<Method>().unwrap_err().to_string();
        assert!(
            e.contains("rk45") && e.contains("sp4") && e.contains("heun"),
            "{e}"
        );
    }
}
