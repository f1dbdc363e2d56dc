//! How flow S2 is integrated: its names (`linear_flow` in the settings) and the Gauss stages
//! each takes under a composition of a given order (docs/explanation/split-and-flows.md §3.3–3.4).

use crate::error::{Error, Result};

/// How flow S2 (linear) is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LinearFlow {
    /// The exact flow: a matrix exponential per sub-step (paper §3.4.2).
    #[default]
    Exact,
    /// Gauss–Legendre collocation (the diagonal Padé approximant of the exponential) with as
    /// many stages as the composition needs (`⌈order/2⌉`): cheaper, of the composition's order,
    /// and still energy-dissipative on S2, so the passivity of the composition is kept (paper
    /// Remark 2.3). The ledger stays exact (Gauss quadrature of a quadratic storage).
    Gauss,
    /// Gauss collocation with two stages (order 4) whatever the composition's order (at least
    /// its `⌈order/2⌉`): S2 more accurate than the composition needs. Where the error of a
    /// second-order method comes mostly from S2 (a sea's forcing, or the linear damping and
    /// controller, which the one-stage midpoint rule follows to second order), this removes
    /// most of it for about 1.6 times the cost of a step (docs/how-to/choose-method-step-flow.md).
    /// Passive as [`LinearFlow::Gauss`] (Gauss collocation is algebraically stable, any stages).
    Gauss4,
    /// Gauss collocation with three stages (order 6) whatever the composition's order.
    Gauss6,
}

impl std::str::FromStr for LinearFlow {
    type Err = Error;
    fn from_str(s: &str) -> Result<Self> {
        LinearFlow::ALL
            .into_iter()
            .find(|f| f.name() == s)
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "linear_flow must be {}, got {s:?}",
                    LinearFlow::CHOICES
                ))
            })
    }
}

impl LinearFlow {
    /// Every flow, by name.
    pub const ALL: [LinearFlow; 4] = [
        LinearFlow::Exact,
        LinearFlow::Gauss,
        LinearFlow::Gauss4,
        LinearFlow::Gauss6,
    ];
    /// The flows by name, with what each does, for messages.
    pub const CHOICES: &'static str = "'exact' (matrix exponential), 'gauss' (Gauss collocation / diagonal Padé of the method's order), 'gauss4' or 'gauss6' (Gauss collocation of order 4 or 6 whatever the method)";
    pub fn name(self) -> &'static str {
        match self {
            LinearFlow::Exact => "exact",
            LinearFlow::Gauss => "gauss",
            LinearFlow::Gauss4 => "gauss4",
            LinearFlow::Gauss6 => "gauss6",
        }
    }
    /// Whether S2 is collocated (any of the Gauss flows).
    pub fn is_gauss(self) -> bool {
        self != LinearFlow::Exact
    }
    /// The Gauss stages of S2 for a composition of `order` (those of [`LinearFlow::Gauss`] where
    /// S2 is collocated for want of the exact flow).
    pub fn stages(self, order: usize) -> usize {
        let of_order = order.div_ceil(2).max(1);
        match self {
            LinearFlow::Exact | LinearFlow::Gauss => of_order,
            LinearFlow::Gauss4 => of_order.max(2),
            LinearFlow::Gauss6 => of_order.max(3),
        }
    }
    /// The order S2 is integrated to, where it is fixed whatever the method.
    pub fn fixed_order(self) -> Option<usize> {
        match self {
            LinearFlow::Gauss4 => Some(4),
            LinearFlow::Gauss6 => Some(6),
            LinearFlow::Exact | LinearFlow::Gauss => None,
        }
    }
}
