//! Composition (splitting) methods as data (paper §2, format (10); docs/model.md §1).
//!
//! A composition method is a table of sub-step coefficients for two flows `A` and `B` with its
//! metadata; one kernel ([`crate::solve::kernel::run_splitting`]) runs all of them. Which of
//! the system's flows plays `A` is chosen at run time ([`Outer`]).

use crate::error::{Error, Result};

/// Which of the two flows of a split system a sub-step belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Flow {
    /// The conservative flow S1 (the free rigid body for the vessel).
    S1,
    /// The dissipative flow S2, which carries the port (linear for the vessel).
    S2,
}

/// Which flow plays `A`, the outermost flow of the composition (format (10) of the paper).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Outer {
    /// The dissipative flow S2 is outermost. This is the default: for SP4 it is the
    /// arrangement with the weaker Prop. 2.5 condition (`σmax/σmin ≤ 12.9` instead of 4.48);
    /// for SP6 it is the other way round (1.91 instead of 4.36; docs/model.md §1.5).
    #[default]
    Dissipative,
    /// The conservative flow S1 is outermost.
    Conservative,
}

/// Names accepted for [`Outer`]: the flow that is outermost.
pub const OUTER_NAMES: [&str; 2] = ["dissipative", "conservative"];

impl std::str::FromStr for Outer {
    type Err = Error;
    /// `dissipative` (S2 outermost) or `conservative` (S1 outermost); nothing else.
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "dissipative" => Ok(Outer::Dissipative),
            "conservative" => Ok(Outer::Conservative),
            other => Err(Error::InvalidInput(format!(
                "outer must be 'dissipative' (S2 outermost) or 'conservative' (S1 outermost), got {other:?}"
            ))),
        }
    }
}

impl Outer {
    /// The name [`std::str::FromStr`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            Outer::Dissipative => "dissipative",
            Outer::Conservative => "conservative",
        }
    }
    /// The system flow that plays `A`, and the one that plays `B`.
    pub fn flows(self) -> (Flow, Flow) {
        match self {
            Outer::Dissipative => (Flow::S2, Flow::S1),
            Outer::Conservative => (Flow::S1, Flow::S2),
        }
    }
}

/// A composition (splitting) method: `A(c₁h) B(c₂h) A(c₃h) …` with metadata.
#[derive(Debug, Clone, PartialEq)]
pub struct Composition {
    /// Short name (`lie`, `sp2`, `sp4`, `sp6`).
    pub name: &'static str,
    /// Classical order.
    pub order: usize,
    /// Number of sub-steps `2m` of format (10) per step, before adjacent sub-steps of one
    /// flow are merged (the paper's count; Strang: 2, of which merging leaves one `B` flow).
    pub stages: usize,
    /// Where the coefficients come from.
    pub citation: &'static str,
    /// The sub-steps of one step, in order of application: `(is_a, coefficient)`, with adjacent
    /// sub-steps of the same flow already merged and zero-length ones dropped.
    pub substeps: Vec<(bool, f64)>,
}

impl Composition {
    /// The symmetric format (10) of the paper from `a₁..a_{m+1}` and `b₁..b_m`:
    /// `A(a₁h) B(b₁h) … A(a_m h) B(b_m h) A(a_{m+1}h) B(b_m h) A(a_m h) … B(b₁h) A(a₁h)`.
    pub fn symmetric(
        name: &'static str,
        order: usize,
        citation: &'static str,
        a: &[f64],
        b: &[f64],
    ) -> Self {
        assert_eq!(a.len(), b.len() + 1, "format (10) needs m+1 a's and m b's");
        let m = b.len();
        let mut raw: Vec<(bool, f64)> = Vec::with_capacity(4 * m + 1);
        for i in 0..m {
            raw.push((true, a[i]));
            raw.push((false, b[i]));
        }
        raw.push((true, a[m]));
        for i in (0..m).rev() {
            raw.push((false, b[i]));
            raw.push((true, a[i]));
        }
        Self {
            name,
            order,
            stages: 2 * m,
            citation,
            substeps: merge(raw),
        }
    }

    /// Lie–Trotter, `A(h) B(h)`: order 1, positive steps.
    pub fn lie() -> Self {
        Self {
            name: "lie",
            order: 1,
            stages: 1,
            citation: "Trotter (1959); paper §2, Remark 2.1",
            substeps: vec![(true, 1.0), (false, 1.0)],
        }
    }

    /// Strang, `A(h/2) B(h) A(h/2)`: order 2, positive steps.
    pub fn strang() -> Self {
        Self::symmetric(
            "sp2",
            2,
            "Strang (1968); paper format (10) with m = 1",
            &[0.5, 0.0],
            &[0.5],
        )
    }

    /// McLachlan's two-stage method of order 2,
    /// `A(λh) B(h/2) A((1 − 2λ)h) B(h/2) A(λh)`, with the `λ` that minimises the norm of its
    /// leading error terms among such methods, in closed form `λ = 1/2 − s/12 + 1/(6s)`,
    /// `s = (36 + 2√326)^{1/3}`, `λ = 0.19318332750378…`
    /// (McLachlan, SIAM J. Sci. Comput. 16 (1995) 151–168; the same coefficient as the
    /// "minimum-norm" 2MN integrator of Omelyan, Mryglod & Folk, Comput. Phys. Commun. 146
    /// (2002) 188–202). All sub-steps positive: passive for any step (Prop. 2.2).
    pub fn mclachlan_2() -> Self {
        let s = (36.0 + 2.0 * 326f64.sqrt()).cbrt();
        let lambda = 0.5 - s / 12.0 + 1.0 / (6.0 * s);
        Self::symmetric(
            "mcl2",
            2,
            "McLachlan, SIAM J. Sci. Comput. 16 (1995) 151–168 (two stages, minimal error norm)",
            &[lambda, 1.0 - 2.0 * lambda],
            &[0.5],
        )
    }

    /// Blanes & Moan (2002), order 4, 6 stages (paper §2; docs/model.md §1).
    pub fn blanes_moan_4() -> Self {
        let (a1, a2, a3) = (
            0.079_203_696_431_195_7,
            0.353_172_906_049_774,
            -0.042_065_080_357_719_5,
        );
        let a4 = 1.0 - 2.0 * (a1 + a2 + a3);
        let (b1, b2) = (0.209_515_106_613_362, -0.143_851_773_179_818);
        let b3 = 0.5 - (b1 + b2);
        Self::symmetric(
            "sp4",
            4,
            "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313–330, Table 2 (S6, order 4)",
            &[a1, a2, a3, a4],
            &[b1, b2, b3],
        )
    }

    /// Blanes & Moan (2002), order 6, 10 stages (paper §2; docs/model.md §1).
    pub fn blanes_moan_6() -> Self {
        let a = [
            0.050_262_764_400_392,
            0.413_514_300_428_344,
            0.045_079_889_794_397_7,
            -0.188_054_853_819_569,
            0.541_960_678_450_780,
        ];
        let b = [
            0.148_816_447_901_042,
            -0.132_385_865_767_784,
            0.067_307_604_692_185,
            0.432_666_402_578_175,
        ];
        let a6 = 1.0 - 2.0 * a.iter().sum::<f64>();
        let b5 = 0.5 - b.iter().sum::<f64>();
        Self::symmetric(
            "sp6",
            6,
            "Blanes & Moan, J. Comput. Appl. Math. 142 (2002) 313–330, Table 3 (S10, order 6)",
            &[a[0], a[1], a[2], a[3], a[4], a6],
            &[b[0], b[1], b[2], b[3], b5],
        )
    }

    /// Whether every sub-step is positive: then the discrete map is passive for any
    /// passive split (paper Prop. 2.2).
    pub fn all_positive(&self) -> bool {
        self.substeps.iter().all(|&(_, c)| c > 0.0)
    }

    /// Coefficients of the sub-steps of flow `A` (`true`) or `B` (`false`).
    pub fn coefficients(&self, of_a: bool) -> Vec<f64> {
        self.substeps
            .iter()
            .filter(|s| s.0 == of_a)
            .map(|s| s.1)
            .collect()
    }

    /// The largest ratio `σmax/σmin` for which the method stays energy-dissipative on a
    /// quadratic system when the dissipative flow takes the sub-steps of `A` (`true`) or `B`
    /// (paper Prop. 2.5): `Σ_{c>0} c / Σ_{c<0} (−c)`, infinite if no coefficient is negative.
    pub fn dissipation_ratio_bound(&self, dissipative_is_a: bool) -> f64 {
        let c = self.coefficients(dissipative_is_a);
        let pos: f64 = c.iter().filter(|v| **v > 0.0).sum();
        let neg: f64 = -c.iter().filter(|v| **v < 0.0).sum::<f64>();
        if neg == 0.0 {
            f64::INFINITY
        } else {
            pos / neg
        }
    }
}

/// Merge adjacent sub-steps of the same flow and drop zero-length ones.
fn merge(raw: Vec<(bool, f64)>) -> Vec<(bool, f64)> {
    let mut out: Vec<(bool, f64)> = Vec::with_capacity(raw.len());
    for (f, c) in raw {
        if c == 0.0 {
            continue;
        }
        match out.last_mut() {
            Some(last) if last.0 == f => last.1 += c,
            _ => out.push((f, c)),
        }
    }
    out
}
