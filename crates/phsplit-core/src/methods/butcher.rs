//! Explicit Runge–Kutta methods as data (Butcher tableaus): the baselines of the paper's §4.

/// An explicit Runge–Kutta method given by its Butcher tableau.
#[derive(Debug, Clone, PartialEq)]
pub struct ButcherTableau {
    pub name: &'static str,
    pub order: usize,
    pub citation: &'static str,
    /// Strictly lower-triangular `a[i][j]`, `j < i`.
    pub a: Vec<Vec<f64>>,
    pub b: Vec<f64>,
    pub c: Vec<f64>,
}

impl ButcherTableau {
    /// Forward Euler.
    pub fn euler() -> Self {
        Self {
            name: "euler",
            order: 1,
            citation: "Euler (1768)",
            a: vec![vec![]],
            b: vec![1.0],
            c: vec![0.0],
        }
    }
    /// Heun's method, the "Improved Euler" method of the paper's Fig. 4.
    pub fn heun() -> Self {
        Self {
            name: "heun",
            order: 2,
            citation: "Heun (1900); the paper's Improved Euler (§4, footnote 2)",
            a: vec![vec![], vec![1.0]],
            b: vec![0.5, 0.5],
            c: vec![0.0, 1.0],
        }
    }
    /// The classical fourth-order Runge–Kutta method.
    pub fn rk4() -> Self {
        Self {
            name: "rk4",
            order: 4,
            citation: "Kutta (1901)",
            a: vec![vec![], vec![0.5], vec![0.0, 0.5], vec![0.0, 0.0, 1.0]],
            b: vec![1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
            c: vec![0.0, 0.5, 0.5, 1.0],
        }
    }
    /// Number of stages.
    pub fn stages(&self) -> usize {
        self.b.len()
    }
}
