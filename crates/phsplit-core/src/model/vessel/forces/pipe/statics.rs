//! The static shape of the lumped-mass line (docs/model.md §5.18): Newton's method on the
//! equilibrium of its weight, its segments and the seabed, directly (no dynamic relaxation), from
//! the natural catenary with seabed contact.

use super::bending::Banded;
use super::chain::Chain;
use nalgebra::{Matrix3, Vector3};

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

impl Chain {
    /// The static shape under the top at `top` (free nodes' positions), by Newton's method on
    /// the equilibrium of the weight, the segments and the seabed, from the natural catenary
    /// with seabed contact (or a straight line for a taut one).
    pub fn static_shape(&self, top: &V3) -> Result<Vec<V3>, String> {
        // A continuation in the axial stiffness: the guess's chords are a little shorter than
        // its arcs (by `(lκ)²/24`), which leaves a stiff line slack or compressed there, with
        // no transverse stiffness or a negative one for Newton's method. Solved first with the
        // line stretched by about 1 % under its weight, then stiffer by tens up to `EA`, each
        // from the last.
        let mut p = self.catenary_guess(top)?;
        let scale = self.weight * self.segments as f64 + self.seabed_stiffness * 1e-3;
        let mut soft = self.clone();
        soft.ea = self.ea.min(100.0 * scale.max(f64::MIN_POSITIVE));
        loop {
            // The bending stiffness in proportion: the line's shape changes smoothly along.
            soft.bending = self.bending * soft.ea / self.ea;
            p = soft.static_from(p)?;
            if soft.ea >= self.ea {
                return Ok(p[1..self.segments].to_vec());
            }
            soft.ea = (soft.ea * 10.0).min(self.ea);
        }
    }

    /// Newton's method on the static equilibrium from the nodes `p` (`0..=N`).
    fn static_from(&self, mut p: Vec<V3>) -> Result<Vec<V3>, String> {
        let n = self.segments;
        let top = p[0];
        let scale = self.length() + top.norm() + self.anchor.norm();
        let (mut f, mut diag, mut off, mut far) = (
            vec![V3::zeros(); n],
            vec![M3::zeros(); n],
            vec![M3::zeros(); n],
            vec![M3::zeros(); n],
        );
        let mut g = vec![V3::zeros(); n];
        let residual =
            |s: &Self, p: &[V3], f: &mut [V3], d: &mut [M3], o: &mut [M3], fa: &mut [M3]| {
                // The static forces: the discrete gradient at coinciding ends is the gradient, and
                // its derivative in one end half the stiffness; no drag (a huge h).
                s.static_forces(p, f, d, o, fa);
                (1..n).map(|i| f[i].norm_squared()).sum::<f64>().sqrt()
            };
        let mut norm = residual(self, &p, &mut f, &mut diag, &mut off, &mut far);
        let (mut band, mut delta) = (Banded::default(), vec![V3::zeros(); n]);
        for _ in 0..200 {
            for i in 1..n {
                g[i] = -f[i];
            }
            g[0] = V3::zeros();
            diag[0] = M3::identity();
            off[0] = M3::zeros();
            far[0] = M3::zeros();
            // A little transverse stiffness for slack segments (their tangent stiffness is 0):
            // it only changes Newton's path, not the equilibrium.
            let eps = 1e-9 * self.ea / self.rest;
            for d in diag.iter_mut().skip(1) {
                *d += M3::identity() * eps;
            }
            if !band.solve(&diag, &off, &far, &g, &mut delta) {
                return Err("the static pipe's Newton system is singular".into());
            }
            let mut lambda = 1.0;
            let mut trial = p.clone();
            loop {
                for i in 1..n {
                    trial[i] = p[i] - delta[i] * lambda;
                }
                let r = residual(self, &trial, &mut f, &mut diag, &mut off, &mut far);
                if r < norm || lambda < 1e-6 {
                    norm = r;
                    break;
                }
                lambda *= 0.5;
            }
            let size = (1..n).map(|i| delta[i].amax()).fold(0.0, f64::max) * lambda;
            p.clone_from(&trial);
            if size <= 1e-13 * scale {
                return Ok(p);
            }
        }
        Err(format!(
            "the static shape of the pipe did not converge (force residual {norm:.3e} N): check pipe.length, pipe.anchor and the hang-off point"
        ))
    }

    fn static_forces(
        &self,
        p: &[V3],
        f: &mut [V3],
        diag: &mut [M3],
        off: &mut [M3],
        far: &mut [M3],
    ) {
        let n = self.segments;
        let mut full: Vec<V3> = p.to_vec();
        full.truncate(n);
        full.push(self.anchor);
        for v in f.iter_mut() {
            *v = V3::zeros();
        }
        for m in diag.iter_mut().chain(off.iter_mut()).chain(far.iter_mut()) {
            *m = M3::zeros();
        }
        // The bending springs at coinciding ends: their gradient, and the Hessian's stand-in.
        self.add_bending(&full, &full, 1.0, f, diag, off, far);
        for j in 0..n {
            let d = full[j + 1] - full[j];
            let (pull, k) = self.segment(&d, &d);
            let k = k * 2.0;
            f[j] += pull;
            diag[j] += k;
            if j + 1 < n {
                f[j + 1] -= pull;
                diag[j + 1] += k;
                off[j] -= k;
            }
        }
        for i in 1..n {
            f[i].z -= self.weight;
            let depth = self.seabed - full[i].z;
            if depth >= 0.0 {
                f[i].z += self.seabed_stiffness * depth;
                diag[i][(2, 2)] += self.seabed_stiffness;
            }
        }
    }

    /// Nodes `0..N` (the top and anchor included) on the inelastic natural catenary with its
    /// seabed contact between `top` and the anchor (horizontal tension from the line's length:
    /// suspended length `s = √(h² + 2 h a)`, span `a asinh(s/a)`, `a = H/w`; Irvine, *Cable
    /// Structures*, 1981, §1.3), or on the straight line when that is no longer than `L`.
    fn catenary_guess(&self, top: &V3) -> Result<Vec<V3>, String> {
        let n = self.segments;
        // The length as given (the segments' sum carries a round-off in its last digit).
        let length = (self.length() * 1e9).round() / 1e9;
        let ht = top.z - self.seabed;
        let horiz = nalgebra::Vector2::new(self.anchor.x - top.x, self.anchor.y - top.y);
        let span = horiz.norm();
        let dir = if span > 0.0 {
            horiz / span
        } else {
            nalgebra::Vector2::x()
        };
        let straight = (self.anchor - top).norm();
        let along = |i: usize, at: &dyn Fn(f64) -> (f64, f64)| {
            let (sx, z) = at(i as f64 * self.rest);
            V3::new(top.x + dir.x * sx, top.y + dir.y * sx, z)
        };
        if straight > length {
            return Err(format!(
                "pipe.anchor is {straight:.1} m from the hang-off point where the run starts, farther than pipe.length = {length} m: the pipe would start stretched beyond its length; lengthen it or move the anchor closer"
            ));
        }
        if straight >= length || ht <= 0.0 || self.weight <= 0.0 {
            return Ok((0..=n)
                .map(|i| top + (self.anchor - top) * (i as f64 / n as f64))
                .collect());
        }
        if length > ht + span {
            return Err(format!(
                "pipe.length = {length} m is longer than the depth below the hang-off point ({ht:.1} m) and the horizontal distance to pipe.anchor ({span:.1} m) together: the pipe would lie slack on the seabed; shorten it or move the anchor away"
            ));
        }
        let fit = |a: f64| {
            let s = (ht * ht + 2.0 * ht * a).sqrt();
            (length - s) - (span - a * (s / a).asinh())
        };
        let (mut lo, mut hi) = (1e-6 * ht, 1e3 * (length + ht));
        if fit(hi) < 0.0 {
            return Ok((0..=n)
                .map(|i| top + (self.anchor - top) * (i as f64 / n as f64))
                .collect());
        }
        for _ in 0..200 {
            let mid = (lo * hi).sqrt();
            if fit(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let a = 0.5 * (lo + hi);
        let s = (ht * ht + 2.0 * ht * a).sqrt();
        let xs = a * (s / a).asinh();
        let zb = self.seabed;
        Ok((0..=n)
            .map(|i| {
                if i == n {
                    return self.anchor;
                }
                along(i, &|sigma: f64| {
                    let from_td = s - sigma;
                    if from_td > 0.0 {
                        let xi = a * (from_td / a).asinh();
                        (xs - xi, zb + a * ((xi / a).cosh() - 1.0))
                    } else {
                        // On the seabed, pressed in by its weight.
                        (
                            xs - from_td,
                            zb - self.weight / self.seabed_stiffness.max(f64::MIN_POSITIVE),
                        )
                    }
                })
            })
            .collect())
    }
}
