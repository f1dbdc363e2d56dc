//! sn, cn, dn, K and F against mpmath over the whole domain: at the inputs of
//! Boost.Math's published test tables and on an adversarial grid (m from 0 and 5e-324 to
//! 1 − 2⁻⁵³ and 1, a few m outside [0, 1]; u from ±0 and subnormals to 1e15, with n·K ± 1 ulp).
//!
//! Tables: `tests/data/jacobi_ref.csv` and `tests/data/ellint_ref.csv`, written by
//! `scripts/gen_elliptic_refs.py` (mpmath at 60 digits, confirmed at 90).
//!
//! Bounds:
//! * sn, cn, dn: within 8 ulp of the value, or within `4 ε |u|` absolute, the error that the
//!   argument reduction of a function of slope ≤ 1 may cost (ε = 2⁻⁵²). Outside `0 ≤ m ≤ 1`
//!   the slopes reach `max(1, |m|)` (`dn' = −m sn cn`), and the absolute allowance is scaled
//!   by it: `4 ε |u| max(1, |m|)`;
//! * K: within 4 ulp;
//! * F: within 8 ulp, or twice its own conditioning limit (the table's `sensitivity`: how far F
//!   moves when φ or m moves one ulp) where that is larger.
use phsplit_core::flows::rigid_body::{jacobi_short, SHORT_ADVANCE};
use phsplit_core::lie::elliptic::{ellipf, ellipk, try_jacobi};
use std::collections::BTreeMap;

const EPS: f64 = f64::EPSILON;

/// The spacing of doubles at `x` (the smallest subnormal at 0).
fn ulp(x: f64) -> f64 {
    let a = x.abs();
    if !a.is_finite() {
        return f64::NAN;
    }
    f64::from_bits(a.to_bits() + 1) - a
}

fn parse(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("not a number: {s}"))
}

/// The worst case of one (set, function): its score (error over the allowance; ≤ 1 passes),
/// its error in ulps, and a description.
#[derive(Default)]
struct Worst {
    score: f64,
    ulps: f64,
    what: String,
    count: usize,
}

impl Worst {
    fn record(&mut self, score: f64, ulps: f64, what: impl FnOnce() -> String) {
        self.count += 1;
        let score = if score.is_nan() { f64::INFINITY } else { score };
        if score > self.score {
            self.score = score;
            self.ulps = ulps;
            self.what = what();
        }
    }
}

fn report(title: &str, worst: &BTreeMap<(String, String), Worst>) -> Vec<String> {
    println!("{title}");
    let mut failures = Vec::new();
    for ((set, f), w) in worst {
        println!(
            "  {set:32} {f:2}  n = {:5}  worst score {:8.3}  ({:9.2} ulp)  {}",
            w.count, w.score, w.ulps, w.what
        );
        if w.score > 1.0 {
            failures.push(format!("{set} {f}: score {:.3}: {}", w.score, w.what));
        }
    }
    failures
}

#[test]
fn jacobi_functions_within_the_issue_16_bounds_over_the_whole_domain() {
    let text = include_str!("data/jacobi_ref.csv");
    let mut worst: BTreeMap<(String, String), Worst> = BTreeMap::new();
    for line in text.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let (set, u, m) = (c[0], parse(c[1]), parse(c[2]));
        let want = [parse(c[3]), parse(c[4]), parse(c[5])];
        let got = try_jacobi(u, m).unwrap_or((f64::NAN, f64::NAN, f64::NAN));
        for (k, name) in ["sn", "cn", "dn"].iter().enumerate() {
            let g = [got.0, got.1, got.2][k];
            let e = (g - want[k]).abs();
            let rel = e / (8.0 * ulp(want[k]));
            let abs = e / (4.0 * EPS * u.abs() * m.abs().max(1.0));
            let score = if g == want[k] { 0.0 } else { rel.min(abs) };
            worst
                .entry((set.to_string(), name.to_string()))
                .or_default()
                .record(score, e / ulp(want[k]), || {
                    format!("{name}({u:e} | {m:e}) = {g:e}, mpmath {:e}", want[k])
                });
        }
    }
    let failures = report(
        "sn, cn, dn: score = error / max(8 ulp, 4 eps |u| max(1, |m|))",
        &worst,
    );
    assert!(worst.values().map(|w| w.count).sum::<usize>() > 15_000);
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn elliptic_integrals_within_the_issue_16_bounds_over_the_whole_domain() {
    let text = include_str!("data/ellint_ref.csv");
    let mut worst: BTreeMap<(String, String), Worst> = BTreeMap::new();
    for line in text.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let (set, f, phi, m) = (c[0], c[1], parse(c[2]), parse(c[3]));
        let (want, sens) = (parse(c[4]), parse(c[5]));
        let (got, allowance) = if f == "K" {
            (ellipk(m).unwrap_or(f64::NAN), 4.0 * ulp(want))
        } else {
            (
                ellipf(phi, m).unwrap_or(f64::NAN),
                (8.0 * ulp(want)).max(2.0 * sens),
            )
        };
        let e = (got - want).abs();
        let score = if got == want { 0.0 } else { e / allowance };
        worst
            .entry((set.to_string(), f.to_string()))
            .or_default()
            .record(score, e / ulp(want), || {
                format!("{f}({phi:e} | {m:e}) = {got:e}, mpmath {want:e}")
            });
    }
    let failures = report("K, F: score = error / allowance", &worst);
    assert!(worst.values().map(|w| w.count).sum::<usize>() > 1_500);
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The flow's short path (the Maclaurin series of sn, cn, dn for the small phase
/// advances of a step) against mpmath, on every row of the table with `0 < |u| ≤ 0.01` and
/// `0 ≤ m ≤ 1`: within 1 ulp (the AGM path's bound is 8, its measured worst 3).
#[test]
fn the_short_path_is_within_one_ulp_of_mpmath() {
    let text = include_str!("data/jacobi_ref.csv");
    let (mut n, mut worst) = (0, 0.0f64);
    for line in text.lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect();
        let (u, m) = (parse(c[1]), parse(c[2]));
        if !(u != 0.0 && u.abs() <= SHORT_ADVANCE && (0.0..=1.0).contains(&m)) {
            continue;
        }
        n += 1;
        let (s, cn, d) = jacobi_short(u, m);
        for (x, r) in [(s, parse(c[3])), (cn, parse(c[4])), (d, parse(c[5]))] {
            worst = worst.max((x - r).abs() / ulp(r));
        }
    }
    println!("short path: {n} rows, worst {worst:.2} ulp");
    assert!(n > 1000, "{n} rows");
    assert!(worst <= 1.0, "worst {worst} ulp");
}
