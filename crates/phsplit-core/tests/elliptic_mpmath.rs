//! sn, cn, dn, K and F against mpmath (50 digits), over the whole parameter range.
//!
//! The table is `tests/data/elliptic_ref.csv`, written by `scripts/gen_elliptic_refs.py`.
//!
//! Error measure: `|f − f_ref| / (ε · scale)`, in units of the double epsilon ε, with
//! `scale = max(|f_ref|, (1 + |x|) · δ)`. The second term is the unavoidable error of rounding the
//! argument: a function of slope ≤ 1 (sn, cn, dn, and the amplitude inside them) evaluated at
//! `x(1 ± ε)` moves by up to `|x| ε`; `δ` is 1 for sn/cn/dn and 0 for K and F, whose values are
//! bounded away from zero except at x = 0 (where both are exact).
use phsplit_core::lie::elliptic::{ellipf, ellipk, jacobi};

struct Row {
    f: String,
    x: f64,
    m: f64,
    value: f64,
}

fn table() -> Vec<Row> {
    let text = include_str!("data/elliptic_ref.csv");
    text.lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            Row {
                f: c[0].to_string(),
                x: c[1].parse().unwrap(),
                m: c[2].parse().unwrap(),
                value: c[3].parse().unwrap(),
            }
        })
        .collect()
}

fn ulps(got: f64, r: &Row, delta: f64) -> f64 {
    let scale = r.value.abs().max((1.0 + r.x.abs()) * delta);
    if got == r.value {
        return 0.0;
    }
    (got - r.value).abs() / (f64::EPSILON * scale)
}

#[test]
fn jacobi_functions_match_mpmath_to_a_few_ulps() {
    let rows = table();
    let mut worst: [(f64, String); 3] = Default::default();
    let mut count = 0;
    for r in rows
        .iter()
        .filter(|r| matches!(r.f.as_str(), "sn" | "cn" | "dn"))
    {
        let (s, c, d) = jacobi(r.x, r.m);
        let (k, got) = match r.f.as_str() {
            "sn" => (0, s),
            "cn" => (1, c),
            _ => (2, d),
        };
        let e = ulps(got, r, 1.0);
        if e > worst[k].0 {
            worst[k] = (
                e,
                format!("{}({} | {}) = {got:e}, mpmath {:e}", r.f, r.x, r.m, r.value),
            );
        }
        count += 1;
    }
    for (e, what) in &worst {
        println!("worst {e:.2} ulp: {what}");
    }
    assert!(count > 1500);
    for (e, what) in &worst {
        assert!(*e <= 4.0, "{e:.1} ulp: {what}");
    }
}

#[test]
fn complete_and_incomplete_integrals_match_mpmath() {
    let rows = table();
    let mut worst = (0.0f64, String::new());
    let mut count = 0;
    for r in rows.iter().filter(|r| r.f == "K" || r.f == "F") {
        let got = if r.f == "K" {
            ellipk(r.m).unwrap()
        } else {
            ellipf(r.x, r.m).unwrap()
        };
        let e = ulps(got, r, 0.0);
        if e > worst.0 {
            worst = (
                e,
                format!("{}({} | {}) = {got:e}, mpmath {:e}", r.f, r.x, r.m, r.value),
            );
        }
        count += 1;
    }
    println!("worst {:.2} ulp: {}", worst.0, worst.1);
    assert!(count > 350);
    assert!(worst.0 <= 4.0, "{:.1} ulp: {}", worst.0, worst.1);
}
