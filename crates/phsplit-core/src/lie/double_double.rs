//! Double-double arithmetic (Dekker 1971; Knuth's two-sum): just what the elliptic functions
//! need for `K` by the AGM and for exact argument reductions (`lie::elliptic`). A value is
//! `hi + lo` with `|lo| ≤ ulp(hi)/2`.

use std::f64::consts::{FRAC_PI_2, PI};

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Dd {
    pub(crate) hi: f64,
    pub(crate) lo: f64,
}

/// π and π/2 as double-double.
pub(crate) const PI_DD: Dd = Dd {
    hi: PI,
    lo: 1.2246467991473532e-16,
};
pub(crate) const HALF_PI_DD: Dd = Dd {
    hi: FRAC_PI_2,
    lo: 6.123233995736766e-17,
};

#[inline]
pub(crate) fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    Dd {
        hi: s,
        lo: (a - (s - bb)) + (b - bb),
    }
}

/// [`two_sum`] for `|a| ≥ |b|`.
#[inline]
pub(crate) fn fast_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd {
        hi: s,
        lo: b - (s - a),
    }
}

#[inline]
pub(crate) fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd {
        hi: p,
        lo: a.mul_add(b, -p),
    }
}

impl Dd {
    pub(crate) fn new(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }
    pub(crate) fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let t = two_sum(self.lo, o.lo);
        let u = fast_two_sum(s.hi, s.lo + t.hi);
        fast_two_sum(u.hi, u.lo + t.lo)
    }
    pub(crate) fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
    pub(crate) fn mul(self, o: Dd) -> Dd {
        let p = two_prod(self.hi, o.hi);
        fast_two_sum(p.hi, p.lo + (self.hi * o.lo + self.lo * o.hi))
    }
    /// Times a power of two: exact.
    pub(crate) fn scale(self, k: f64) -> Dd {
        Dd {
            hi: self.hi * k,
            lo: self.lo * k,
        }
    }
    pub(crate) fn sqrt(self) -> Dd {
        if self.hi <= 0.0 {
            return Dd::new(0.0);
        }
        let s = self.hi.sqrt();
        let r = (-s).mul_add(s, self.hi) + self.lo; // exact residual hi − s², plus lo
        fast_two_sum(s, r / (2.0 * s))
    }
    pub(crate) fn div(self, o: Dd) -> Dd {
        let q1 = self.hi / o.hi;
        let r = self.add(o.mul(Dd::new(q1)).neg());
        let q2 = r.hi / o.hi;
        let r2 = r.add(o.mul(Dd::new(q2)).neg());
        let q3 = r2.hi / o.hi;
        let q = fast_two_sum(q1, q2);
        q.add(Dd::new(q3))
    }
}
