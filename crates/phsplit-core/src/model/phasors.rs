//! Time factors `e^{i(ω_k t + φ_k)}` of many regular components at one time, without a sine and
//! cosine per component (docs/explanation/fast-sea.md).
//!
//! Time is cut on a lattice of powers of two: `t = jΔ + mδ + r` with `Δ = M δ`, `0 ≤ m < M`,
//! `0 ≤ r < δ`, and `δ` the largest power of two with `ω_max δ ≤ 1/4`. Then
//!
//! `e^{i(ω t + φ)} = e^{i(ω jΔ + φ)} · e^{i ω mδ} · e^{i ω r}`:
//!
//! - the anchor `e^{i(ω jΔ + φ)}` by the library's sine and cosine, once per lattice interval
//!   `Δ` (tens of steps), kept in a per-thread memo;
//! - the row `e^{i ω mδ}` from a table of `M` rows built once with the component;
//! - `e^{i ω r}`, `|ω r| ≤ 1/4`, by its Taylor polynomials to degree 12 (cosine) and 13 (sine),
//!   whose first omitted terms are below `4·10⁻²⁰`.
//!   They depend on `r` alone, and a step commensurate with `δ` meets a few offsets `r` over
//!   and over (with `h = 0.5 s`, the midpoint rule's stage times are multiples of `1/8 s`): the
//!   per-thread memo keeps the last few sets as computed.
//!
//! Because `Δ` and `δ` are powers of two, `jΔ`, `t − jΔ`, `mδ` and `r` are exact in floating
//! point, every factor is a function of `t` alone computed the same way whatever was evaluated
//! before, and nothing is carried from one time to the next: there is no recurrence whose
//! round-off grows. (The rotation recurrence `z_{n+1} = z_n e^{iωh}` is the "repeated
//! multiplication" way of computing the weights of a Fourier transform, whose error grows
//! linearly in `n`, against the unit round-off of a direct call per weight; C. F. Van Loan,
//! *Computational Frameworks for the Fast Fourier Transform*, SIAM, 1992, §1.4. The lattice is
//! a direct call per anchor and per table row, and a product of three factors.) Each factor is
//! within a few units in the
//! last place of its exact value, and the anchor's phase `ω jΔ + φ` is rounded as the direct
//! `ω t + φ` is: the product agrees with the direct `cos, sin(ω t + φ)` to the round-off of the
//! direct phase, `≈ ε |ω t|`. The memo makes the results bitwise independent of the order of
//! evaluation, of threads and of where a run is cut into pieces.

use super::kept::Identity;
use std::cell::RefCell;

/// Rows of the table per lattice interval.
const ROWS: usize = 64;
/// The bound on `|ω r|` that the Taylor polynomials are accurate to round-off on.
const REDUCED: f64 = 0.25;
/// Anchors, and remainders, a thread keeps (a few seas evaluated in turn, each at a few times).
const MEMO: usize = 8;

/// Regular components' frequencies and phases, with the lattice and table of their fast time
/// factors.
#[derive(Debug, Clone, PartialEq)]
pub struct Phasors {
    /// Private: the memo keys on the identity of the components, which must not change.
    omega: Vec<f64>,
    phase: Vec<f64>,
    /// `δ` and `Δ = ROWS δ` (s), powers of two.
    delta: f64,
    span: f64,
    /// `e^{i ω_k m δ}`, row `m` at `[m K .. (m + 1) K]`.
    row_re: Vec<f64>,
    row_im: Vec<f64>,
    key: Identity,
}

/// Factors of one set of components kept by a thread: an anchor `e^{i(ω_k jΔ + φ_k)}` (`at` = `j`)
/// or the remainders `e^{i ω_k r}` at one offset (`at` = the bits of `r`).
#[derive(Default)]
struct Kept {
    key: u64,
    at: u64,
    re: Vec<f64>,
    im: Vec<f64>,
}

/// A thread's memo: recently used anchors and remainders, each the oldest replaced first (its
/// buffers reused), and the result buffers.
struct Memo {
    anchors: Vec<Kept>,
    next: usize,
    rems: Vec<Kept>,
    next_rem: usize,
    re: Vec<f64>,
    im: Vec<f64>,
}

thread_local! {
    static MEMO_ANCHORS: RefCell<Memo> = const {
        RefCell::new(Memo {
            anchors: Vec::new(),
            next: 0,
            rems: Vec::new(),
            next_rem: 0,
            re: Vec::new(),
            im: Vec::new(),
        })
    };
}

impl Phasors {
    /// Components of frequencies `omega` (rad/s, finite) and phases `phase` (rad).
    pub fn new(omega: Vec<f64>, phase: Vec<f64>) -> Self {
        assert_eq!(omega.len(), phase.len());
        let wmax = omega.iter().fold(0.0f64, |a, w| a.max(w.abs()));
        // The largest power of two δ with ω_max δ ≤ 1/4.
        let mut delta = 1.0f64;
        if wmax > 0.0 {
            delta = 2f64.powi((REDUCED / wmax).log2().floor() as i32);
            while wmax * delta > REDUCED {
                delta *= 0.5;
            }
            while wmax * delta * 2.0 <= REDUCED && delta < 1.0e6 {
                delta *= 2.0;
            }
        }
        let k = omega.len();
        let mut row_re = vec![0.0; ROWS * k];
        let mut row_im = vec![0.0; ROWS * k];
        for m in 0..ROWS {
            let tm = m as f64 * delta;
            for (i, w) in omega.iter().enumerate() {
                let (s, c) = (w * tm).sin_cos();
                row_re[m * k + i] = c;
                row_im[m * k + i] = s;
            }
        }
        Self {
            omega,
            phase,
            delta,
            span: delta * ROWS as f64,
            row_re,
            row_im,
            key: Identity::new(),
        }
    }

    /// The identity the per-thread memos key on (equal for copies).
    pub fn identity(&self) -> Identity {
        self.key
    }

    pub fn len(&self) -> usize {
        self.omega.len()
    }

    pub fn is_empty(&self) -> bool {
        self.omega.is_empty()
    }

    /// The direct `(cos, sin)(ω_k t + φ_k)`, into `re` and `im`: the reference.
    pub fn direct(&self, t: f64, re: &mut [f64], im: &mut [f64]) {
        for k in 0..self.len() {
            let (s, c) = (self.omega[k] * t + self.phase[k]).sin_cos();
            re[k] = c;
            im[k] = s;
        }
    }

    /// `f(re, im)` with `re + i im = e^{i(ω_k t + φ_k)}` by the lattice (module documentation).
    pub fn with_at<R>(&self, t: f64, f: impl FnOnce(&[f64], &[f64]) -> R) -> R {
        let k = self.len();
        let jf = (t / self.span).floor();
        let j = jf as i64;
        let r = t - jf * self.span;
        let m = ((r / self.delta).floor() as usize).min(ROWS - 1);
        let r = r - m as f64 * self.delta;
        MEMO_ANCHORS.with(|cell| {
            let mut memo = cell.borrow_mut();
            let Memo {
                anchors,
                next,
                rems,
                next_rem,
                re,
                im,
            } = &mut *memo;
            let tj = jf * self.span;
            let a = kept(anchors, next, self.key.get(), j as u64, k, |i| {
                let (s, c) = (self.omega[i] * tj + self.phase[i]).sin_cos();
                (c, s)
            });
            // The remainder factors depend on `r` alone: a step size commensurate with `δ`
            // (h = 0.5 s, 0.25 s, 1 s, … and the midpoint rule's nodes) meets a few offsets
            // again and again, which are kept as computed.
            let q = kept(rems, next_rem, self.key.get(), r.to_bits(), k, |i| {
                taylor(self.omega[i] * r)
            });
            re.resize(k, 0.0);
            im.resize(k, 0.0);
            let an = &anchors[a];
            let (ar, ai) = (&an.re[..k], &an.im[..k]);
            let (cr, ci) = (&rems[q].re[..k], &rems[q].im[..k]);
            let (tr, ti) = (
                &self.row_re[m * k..(m + 1) * k],
                &self.row_im[m * k..(m + 1) * k],
            );
            let (re, im) = (&mut re[..k], &mut im[..k]);
            for i in 0..k {
                let (c, s) = (cr[i], ci[i]);
                // anchor · row · e^{iωr}
                let pr = ar[i] * tr[i] - ai[i] * ti[i];
                let pi = ar[i] * ti[i] + ai[i] * tr[i];
                re[i] = pr * c - pi * s;
                im[i] = pr * s + pi * c;
            }
            f(re, im)
        })
    }
}

/// The index of the entry of `entries` kept for `(key, at)`; if there is none, one made with
/// `factor(i)` for `i < k` (the `(cos, sin)` of component `i`), in place of the oldest when the
/// memo holds [`MEMO`] entries (`next` its index), whose buffers it reuses: no allocation once
/// the memo is full, however often it misses.
fn kept(
    entries: &mut Vec<Kept>,
    next: &mut usize,
    key: u64,
    at: u64,
    k: usize,
    factor: impl Fn(usize) -> (f64, f64),
) -> usize {
    if let Some(i) = entries.iter().position(|e| e.key == key && e.at == at) {
        return i;
    }
    let i = if entries.len() < MEMO {
        entries.push(Kept::default());
        entries.len() - 1
    } else {
        let i = *next;
        *next = (i + 1) % MEMO;
        i
    };
    let e = &mut entries[i];
    (e.key, e.at) = (key, at);
    e.re.resize(k, 0.0);
    e.im.resize(k, 0.0);
    for c in 0..k {
        (e.re[c], e.im[c]) = factor(c);
    }
    i
}

/// `(cos x, sin x)` for `|x| ≤ 1/4` by the Taylor polynomials of degrees 12 and 13 (Horner in
/// `x²`).
#[inline(always)]
fn taylor(x: f64) -> (f64, f64) {
    // 1/((2n−1)(2n)) and 1/((2n)(2n+1)).
    const C: [f64; 6] = [
        1.0 / 2.0,
        1.0 / 12.0,
        1.0 / 30.0,
        1.0 / 56.0,
        1.0 / 90.0,
        1.0 / 132.0,
    ];
    const S: [f64; 6] = [
        1.0 / 6.0,
        1.0 / 20.0,
        1.0 / 42.0,
        1.0 / 72.0,
        1.0 / 110.0,
        1.0 / 156.0,
    ];
    let y = x * x;
    let mut c = 1.0;
    let mut s = 1.0;
    for n in (0..6).rev() {
        c = 1.0 - y * C[n] * c;
        s = 1.0 - y * S[n] * s;
    }
    (c, x * s)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A deterministic sequence in [0, 1) (a linear congruential generator, Knuth's MMIX
    /// constants); also the sea's tests' (`forces/waves.rs`).
    pub(crate) fn uniform(state: &mut u64) -> f64 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn the_lattice_gives_each_time_factor_to_the_round_off_of_its_phase() {
        let mut st = 7;
        let omega: Vec<f64> = (0..120).map(|_| 0.001 + 2.5 * uniform(&mut st)).collect();
        let phase: Vec<f64> = (0..120).map(|_| 6.283 * uniform(&mut st)).collect();
        let p = Phasors::new(omega.clone(), phase.clone());
        let copy = p.clone();
        // Stage times of an hour and beyond, Gauss nodes included, in a random order, and the
        // same times again after others (the memo must not change a result).
        let mut times: Vec<f64> = (0..3000).map(|_| 7200.0 * uniform(&mut st)).collect();
        // The stage times of the midpoint rule with h = 0.5 s and of two-stage Gauss, which
        // meet a few offsets again and again (the memo of remainders).
        for n in 0..400 {
            let t0 = 0.25 * n as f64;
            times.extend([t0 + 0.125, t0 + 0.25 * (0.5 - 3f64.sqrt() / 6.0)]);
        }
        times.extend([
            0.0,
            3600.0,
            3599.999999,
            0.5 * (1.0 - 1.0 / 3f64.sqrt()),
            1e5 + 0.3,
        ]);
        let mut first = Vec::new();
        for (n, &t) in times.iter().enumerate() {
            let (re, im) = p.with_at(t, |r, i| (r.to_vec(), i.to_vec()));
            for k in 0..omega.len() {
                // The direct formula, written out.
                let th = omega[k] * t + phase[k];
                let tol = 4.0 * f64::EPSILON * (th.abs() + 1.0);
                assert!(
                    (re[k] - th.cos()).abs() <= tol && (im[k] - th.sin()).abs() <= tol,
                    "t = {t}, ω = {}: {} {} vs {} {}",
                    omega[k],
                    re[k],
                    im[k],
                    th.cos(),
                    th.sin()
                );
                let m = re[k] * re[k] + im[k] * im[k];
                assert!((m - 1.0).abs() <= 8.0 * f64::EPSILON, "modulus {m}");
            }
            if n < 50 {
                first.push((t, re, im));
            }
        }
        for (t, re, im) in first {
            let again = copy.with_at(t, |r, i| (r.to_vec(), i.to_vec()));
            assert_eq!(
                again,
                (re, im),
                "t = {t}: bitwise the same whatever came before"
            );
        }
    }

    #[test]
    fn the_taylor_polynomials_are_the_sine_and_cosine_to_round_off() {
        for i in -1000..=1000 {
            let x = 0.25 * i as f64 / 1000.0;
            let (c, s) = taylor(x);
            assert!((c - x.cos()).abs() <= 2.5e-16, "{x}: {c} vs {}", x.cos());
            assert!((s - x.sin()).abs() <= 2.5e-16, "{x}: {s} vs {}", x.sin());
        }
    }
}
