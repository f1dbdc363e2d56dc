//! A lumped-mass line and its passive step (docs/model.md §5.18): the mechanics of the dynamic
//! pipe, with nothing of the vessel in it but the top node's motion ([`Top`]).
//!
//! The line of unstretched length `L` is cut into `N` segments of length `l = L/N`; node 0 is
//! the top (held by a body or moved as given), node `N` the anchor (fixed), nodes `1..N−1` are
//! free, each with the mass of one segment and its added mass, `m = (μ + C_a ρ π d²/4) l`
//! (isotropic), and its submerged weight `W = (μ − ρ π d²/4) g l`; the top carries half a
//! segment's weight, the anchor the other half (the lumped-mass line of
//! M. Hall, A. Goupee, Ocean Eng. 104 (2015) 590–603, MoorDyn's model; the added mass isotropic,
//! MoorDyn's with `CaAx = Ca`). Each segment is an axial spring of stiffness `EA`, tension
//! `T = EA (l_j − l)/l` while stretched (and while compressed only with `compression`); the
//! seabed a vertical spring–damper under each free node (MoorDyn's `kbot d l`, `cbot d l`);
//! Morison drag at each free node on the velocity relative to the water, normal and
//! tangential to the line (MoorDyn's `½ ρ C_dn d l |v_n| v_n`, `½ ρ C_dt π d l |v_t| v_t`, the
//! tangent from the neighbours); optionally an axial damping of the segments (MoorDyn's `BA`,
//! a force `BA l'/l` along each).
//!
//! **The step** is the discrete-gradient method for a port-Hamiltonian system
//! `y' = (J − R(y)) ∇H + input` (O. Gonzalez, J. Nonlinear Sci. 6 (1996) 449–467; for
//! port-Hamiltonian systems E. Celledoni, E. H. Høiseth, J. Comput. Appl. Math. 2017, and the
//! paper's §2): `y₁ − y₀ = h (J − R(ȳ)) ∇̄H(y₀, y₁)` with Gonzalez's discrete gradient of each
//! term of `H` in its own variables (a segment's spring in its extension `Δ = q_{j+1} − q_j`:
//! `∇̄ψ = ψ'(l̄)/l̄ · Δ̄` with `l̄ = (l₀ + l₁)/2` for the quadratic spring, exactly; the seabed's
//! spring in `z`), so that `H(y₁) − H(y₀) = −h ∇̄Hᵀ R ∇̄H + h (inputs)` holds to the Newton
//! tolerance whatever `h`: the axial waves (periods of milliseconds) bound neither stability nor
//! energy, only accuracy. The kinetic energy is quadratic, so `∇̄_p H = p̄/m`; the momenta are
//! eliminated (`p₁ = 2m (q₁ − q₀)/h − p₀`) and Newton's method runs on the node positions and
//! the top's, a block-tridiagonal system of 3×3 blocks solved by block elimination.

use super::bending::Banded;
use nalgebra::{Matrix3, Vector3};

type V3 = Vector3<f64>;
type M3 = Matrix3<f64>;

/// The line's mechanics, per node and segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// Number of segments `N` (≥ 2).
    pub segments: usize,
    /// Unstretched segment length `l` (m).
    pub rest: f64,
    /// Axial stiffness `EA` (N).
    pub ea: f64,
    /// Whether a segment also pushes when shorter than `l`.
    pub compression: bool,
    /// Node mass with added mass (kg) and submerged weight (N).
    pub mass: f64,
    pub weight: f64,
    /// Axial (internal) damping per segment, `BA/l` (N s/m): MoorDyn's `BA`.
    pub axial_damping: f64,
    /// Bending stiffness `EI` (N m²): a rotational spring `(EI/l)(1 − cos θ)` at each free node,
    /// `θ` the turn between its segments (0: none).
    pub bending: f64,
    /// Drag factors `½ ρ C_dn d l` and `½ ρ C_dt π d l` (kg/m).
    pub drag_normal: f64,
    pub drag_tangential: f64,
    /// The seabed's height `z_b` (m), stiffness `k_b d l` (N/m) and damping `c_b d l` (N s/m).
    pub seabed: f64,
    pub seabed_stiffness: f64,
    pub seabed_damping: f64,
    /// The anchor (m, spatial) and the water's velocity (m/s, spatial).
    pub anchor: V3,
    pub current: V3,
}

/// How the top node moves over a step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Top {
    /// Held by a body of momenta `u`, velocity `ν = M⁻¹u`: `r' = B ν`, `u' = Bᵀ F` (`F` the
    /// line's pull on the top). `drift = B M⁻¹ u₀` is the top's velocity where the step starts
    /// (m/s) and `c = B M⁻¹ Bᵀ` its inverse apparent mass (1/kg, symmetric positive definite).
    Body { drift: V3, c: M3 },
    /// Moved to this position at the end of the step (m, spatial).
    Given(V3),
}

/// What one step books (J), and the line's mean pull on the top over it (N, spatial).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StepWork {
    /// Dissipated by the drag on the velocity relative to the water, `h Σ v̄_rᵀ R v̄_r`.
    pub drag: f64,
    /// Dissipated by the segments' axial damping.
    pub axial: f64,
    /// Supplied by the current through the drag, `h Σ u_c·F_drag`.
    pub current: f64,
    /// Dissipated by the seabed's damping.
    pub seabed: f64,
    /// Done on the line at its top, `−F̄·(r₁ − r₀)`.
    pub top: f64,
    /// `F̄`, the discrete gradient's force of the line on the top (segment 0's pull and the top
    /// half segment's weight): the body's momentum changes by `h Bᵀ F̄`.
    pub pull: V3,
}

/// Newton's iterations of one step at most; its tolerance on the positions, relative to the
/// line's length.
const MAX_NEWTON: usize = 60;
const NEWTON_TOL: f64 = 1e-14;

impl Chain {
    /// Free nodes, `N − 1`.
    pub fn free(&self) -> usize {
        self.segments - 1
    }
    /// Own states: the top (3), the free nodes' positions and momenta (`3(N−1)` each).
    pub fn dim(&self) -> usize {
        3 + 6 * self.free()
    }
    pub fn length(&self) -> f64 {
        self.rest * self.segments as f64
    }
    fn v(x: &[f64], i: usize) -> V3 {
        V3::new(x[i], x[i + 1], x[i + 2])
    }
    /// Node `i`'s position in the states `x` (0 the top, `N` the anchor).
    pub fn node(&self, x: &[f64], i: usize) -> V3 {
        if i == self.segments {
            self.anchor
        } else {
            Self::v(x, 3 * i)
        }
    }
    /// Free node `i`'s momentum (`1 ≤ i < N`).
    pub fn momentum(&self, x: &[f64], i: usize) -> V3 {
        Self::v(x, 3 + 3 * self.free() + 3 * (i - 1))
    }
    fn active(&self, l: f64) -> bool {
        self.compression || l > self.rest
    }
    fn psi(&self, l: f64) -> f64 {
        if self.active(l) {
            0.5 * self.ea / self.rest * (l - self.rest).powi(2)
        } else {
            0.0
        }
    }
    /// The line's force on its top (N, spatial): its top segment's pull and the top half
    /// segment's weight.
    pub fn top_force(&self, x: &[f64]) -> V3 {
        let d = self.node(x, 1) - self.node(x, 0);
        let l = d.norm();
        let pull = if l > 0.0 {
            d * (self.tension(l) / l)
        } else {
            V3::zeros()
        };
        pull - V3::z() * (0.5 * self.weight)
    }

    /// The touchdown point and the unstretched length from the top to it, from the last
    /// suspended segment (nodes `k − 1`, `k`; `k + 1` is the first in the seabed): its slope `s`
    /// is the catenary's at its midpoint (a discrete chain's segment carries the weight of the
    /// nodes below it), and the catenary `z' = sinh(ξ/a)`, `a = H/w` (`H` the segment's
    /// horizontal tension), reaches the seabed tangentially `a asinh(s)` on horizontally, an arc
    /// `a s` on. The anchor and the whole length when no node touches.
    pub fn touchdown(&self, x: &[f64]) -> (V3, f64) {
        let n = self.segments;
        let w = self.weight / self.rest;
        for k in 1..n {
            if self.node(x, k + 1).z >= self.seabed || self.node(x, k).z < self.seabed {
                continue;
            }
            // Node k is the last above the seabed.
            if k < 2 {
                let mut td = self.node(x, k);
                td.z = self.seabed;
                return (td, k as f64 * self.rest);
            }
            let (a, b) = (self.node(x, k - 1), self.node(x, k));
            let d = b - a;
            let run = (d.x * d.x + d.y * d.y).sqrt();
            let len = d.norm();
            if run <= 0.0 || w <= 0.0 || len <= 0.0 {
                let mut td = b;
                td.z = self.seabed;
                return (td, k as f64 * self.rest);
            }
            let h = self.tension(len) * run / len;
            let cat = h / w;
            let slope = ((a.z - b.z) / run).max(0.0);
            // At most two segments on from the midpoint.
            let on = (cat * slope.asinh()).min(2.0 * self.rest);
            let mid = 0.5 * (a + b);
            let mut td = mid + V3::new(d.x / run, d.y / run, 0.0) * on;
            td.z = self.seabed;
            let arc = (cat * slope).min(2.0 * self.rest);
            return (td, ((k as f64 - 0.5) * self.rest + arc).min(self.length()));
        }
        (self.anchor, self.length())
    }

    /// A segment's strain energy at extension `d` (J).
    pub fn segment_energy(&self, d: &V3) -> f64 {
        self.psi(d.norm())
    }
    /// A segment's tension at length `l` (N).
    pub fn tension(&self, l: f64) -> f64 {
        if self.active(l) {
            self.ea / self.rest * (l - self.rest)
        } else {
            0.0
        }
    }
    /// Gonzalez's discrete gradient of a segment's spring between its extensions `d0`, `d1`,
    /// as the pull `c Δ̄` on its upper node, and its derivative in `d1`.
    pub(super) fn segment(&self, d0: &V3, d1: &V3) -> (V3, M3) {
        let (l0, l1) = (d0.norm(), d1.norm());
        let db = 0.5 * (d0 + d1);
        let k = self.ea / self.rest;
        let (c, dc) = if self.active(l0) == self.active(l1) {
            if self.active(l0) {
                // The quadratic spring: (ψ₁ − ψ₀)/((l₁² − l₀²)/2) = ψ'(l̄)/l̄ exactly.
                let lm = 0.5 * (l0 + l1);
                (k * (1.0 - self.rest / lm), 0.5 * k * self.rest / (lm * lm))
            } else {
                (0.0, 0.0)
            }
        } else {
            // Across the slack point (l₀ ≠ l₁ there): the difference quotient.
            let den = 0.5 * (l1 * l1 - l0 * l0);
            let dpsi = self.psi(l1) - self.psi(l0);
            let c = dpsi / den;
            (c, (self.tension(l1) * den - dpsi * l1) / (den * den))
        };
        let grad = if l1 > 0.0 { d1 / l1 } else { V3::zeros() };
        (
            c * db,
            M3::identity() * (0.5 * c) + db * (grad * dc).transpose(),
        )
    }
    /// The seabed spring's energy at height `z`.
    fn bed(&self, z: f64) -> f64 {
        let d = self.seabed - z;
        if d > 0.0 {
            0.5 * self.seabed_stiffness * d * d
        } else {
            0.0
        }
    }
    /// Its discrete gradient in `z` between `z0` and `z1`, and the derivative in `z1`.
    fn bed_gradient(&self, z0: f64, z1: f64) -> (f64, f64) {
        let k = self.seabed_stiffness;
        let (in0, in1) = (z0 < self.seabed, z1 < self.seabed);
        match (in0, in1) {
            (true, true) => (-k * (self.seabed - 0.5 * (z0 + z1)), 0.5 * k),
            (false, false) => (0.0, 0.0),
            _ => {
                let dz = z1 - z0;
                let dv = self.bed(z1) - self.bed(z0);
                let d1 = -k * (self.seabed - z1).max(0.0);
                (dv / dz, (d1 * dz - dv) / (dz * dz))
            }
        }
    }

    /// The share of a step in which a node moving linearly from height `z0` to `z1` is in the
    /// seabed.
    fn contact_share(&self, z0: f64, z1: f64) -> f64 {
        let (lo, hi) = (z0.min(z1), z0.max(z1));
        if hi <= self.seabed {
            1.0
        } else if lo >= self.seabed {
            0.0
        } else {
            (self.seabed - lo) / (hi - lo)
        }
    }

    /// The energy the line stores (J): kinetic, the segments' strain, the weight (from `z = 0`)
    /// and the seabed's springs.
    pub fn storage(&self, x: &[f64]) -> f64 {
        let mut e = 0.0;
        for i in 1..self.segments {
            let q = self.node(x, i);
            e += 0.5 * self.momentum(x, i).norm_squared() / self.mass
                + self.weight * q.z
                + self.bed(q.z);
        }
        for j in 0..self.segments {
            e += self.psi((self.node(x, j + 1) - self.node(x, j)).norm());
        }
        for i in 1..self.segments {
            e += self.bend(&self.node(x, i - 1), &self.node(x, i), &self.node(x, i + 1));
        }
        // The top half segment's weight, carried at the top.
        e + 0.5 * self.weight * self.node(x, 0).z
    }

    /// The drag at a free node of velocity `v` and unit tangent `t`: the force, and the
    /// dissipation rate `v_rᵀ R v_r` on the relative velocity.
    fn drag(&self, v: &V3, t: &V3) -> (V3, f64, M3) {
        let rel = v - self.current;
        let vt = t * rel.dot(t);
        let vn = rel - vt;
        let (an, at) = (
            self.drag_normal * vn.norm(),
            self.drag_tangential * vt.norm(),
        );
        let f = -an * vn - at * vt;
        let tt = t * t.transpose();
        let mut jac = (M3::identity() - tt) * an + tt * at;
        if vn.norm() > 0.0 {
            jac += vn * vn.transpose() * (self.drag_normal / vn.norm());
        }
        if vt.norm() > 0.0 {
            jac += vt * vt.transpose() * (self.drag_tangential / vt.norm());
        }
        (f, -rel.dot(&f), jac)
    }

    pub(super) fn tangent(a: &V3, b: &V3) -> V3 {
        let d = b - a;
        let n = d.norm();
        if n > 0.0 {
            d / n
        } else {
            V3::z()
        }
    }

    /// The forces on the free nodes and the top at the new positions `p1` (nodes `0..=N`), and,
    /// the blocks of the residual's Jacobian. Returns the dissipation of the drag and of the
    /// seabed, the current's work and the axial damping's dissipation, per unit time.
    #[allow(clippy::too_many_arguments)]
    fn forces(
        &self,
        p0: &[V3],
        p1: &[V3],
        h: f64,
        f: &mut [V3],
        diag: &mut [M3],
        off: &mut [M3],
        far: &mut [M3],
    ) -> (f64, f64, f64, f64) {
        let n = self.segments;
        for v in f.iter_mut() {
            *v = V3::zeros();
        }
        for m in diag.iter_mut().chain(off.iter_mut()).chain(far.iter_mut()) {
            *m = M3::zeros();
        }
        self.add_bending(p0, p1, 0.5, f, diag, off, far);
        let mut axial = 0.0;
        for j in 0..n {
            let (d0, d1) = (p0[j + 1] - p0[j], p1[j + 1] - p1[j]);
            let (mut pull, mut k) = self.segment(&d0, &d1);
            if self.axial_damping > 0.0 {
                // `BA l'/l` along the segment's mean direction, on its rate of extension.
                let t = Self::tangent(&V3::zeros(), &(0.5 * (d0 + d1)));
                let rate = t.dot(&(d1 - d0)) / h;
                pull += t * (self.axial_damping * rate);
                k += t * t.transpose() * (self.axial_damping / h);
                axial += self.axial_damping * rate * rate;
            }
            f[j] += pull;
            diag[j] += k;
            if j + 1 < n {
                f[j + 1] -= pull;
                diag[j + 1] += k;
                // ∂G_j/∂X_{j+1} = −K (and ∂G_{j+1}/∂X_j = −K, the same block).
                off[j] -= k;
            }
        }
        f[0].z -= 0.5 * self.weight;
        let (mut drag, mut bed, mut cur) = (0.0, 0.0, 0.0);
        for i in 1..n {
            f[i].z -= self.weight;
            let (g, dg) = self.bed_gradient(p0[i].z, p1[i].z);
            f[i].z -= g;
            diag[i][(2, 2)] += dg;
            let v = (p1[i] - p0[i]) / h;
            // The seabed's damping over the part of the step the node spends in contact (its
            // height linear in time): continuous in the new position, so Newton's method does
            // not cycle on a node at the touchdown.
            let share = self.contact_share(p0[i].z, p1[i].z);
            if share > 0.0 {
                let c = self.seabed_damping * share;
                f[i].z -= c * v.z;
                bed += c * v.z * v.z;
            }
            // `share · (z₁ − z₀)` grows with `z₁` exactly while the node ends in contact.
            if p1[i].z < self.seabed {
                diag[i][(2, 2)] += self.seabed_damping / h;
            }
            let t = Self::tangent(
                &(0.5 * (p0[i - 1] + p1[i - 1])),
                &(0.5 * (p0[i + 1] + p1[i + 1])),
            );
            let (fd, d, jd) = self.drag(&v, &t);
            f[i] += fd;
            diag[i] += jd / h;
            drag += d;
            cur += self.current.dot(&fd);
        }
        (drag, bed, cur, axial)
    }

    /// One step of length `h` (> 0) of the line's states `x` with its top moving as `top`:
    /// `None` if Newton's method does not converge.
    pub fn step(&self, x: &mut [f64], h: f64, top: &Top) -> Option<StepWork> {
        let n = self.segments;
        let p0: Vec<V3> = (0..=n).map(|i| self.node(x, i)).collect();
        let mom: Vec<V3> = (0..n)
            .map(|i| {
                if i == 0 {
                    V3::zeros()
                } else {
                    self.momentum(x, i)
                }
            })
            .collect();
        let mut p1 = p0.clone();
        p1[0] = match top {
            Top::Body { drift, .. } => p0[0] + drift * h,
            Top::Given(r) => *r,
        };
        for i in 1..n {
            p1[i] = p0[i] + mom[i] * (h / self.mass);
        }
        let cinv = match top {
            Top::Body { c, .. } => Some(c.try_inverse()? * (2.0 / (h * h))),
            Top::Given(_) => None,
        };
        let inertia = 2.0 * self.mass / (h * h);
        let (mut f, mut diag, mut off, mut far) = (
            vec![V3::zeros(); n],
            vec![M3::zeros(); n],
            vec![M3::zeros(); n],
            vec![M3::zeros(); n],
        );
        let mut g = vec![V3::zeros(); n];
        let scale = self.length() + p0[0].norm() + self.anchor.norm();
        // The residual (force units) and its Jacobian at `p1`; its norm.
        let residual = |p1: &[V3],
                        f: &mut [V3],
                        diag: &mut [M3],
                        off: &mut [M3],
                        far: &mut [M3],
                        g: &mut [V3]| {
            self.forces(&p0, p1, h, f, diag, off, far);
            for i in 1..n {
                g[i] = (p1[i] - p0[i]) * inertia - mom[i] * (2.0 / h) - f[i];
                diag[i] += M3::identity() * inertia;
            }
            match (top, cinv) {
                (Top::Body { drift, .. }, Some(ci)) => {
                    g[0] = ci * (p1[0] - p0[0] - drift * h) - f[0];
                    diag[0] += ci;
                }
                _ => {
                    g[0] = V3::zeros();
                    diag[0] = M3::identity();
                    off[0] = M3::zeros();
                    far[0] = M3::zeros();
                }
            }
            g.iter().map(|v| v.norm_squared()).sum::<f64>().sqrt()
        };
        let mut norm = residual(&p1, &mut f, &mut diag, &mut off, &mut far, &mut g);
        let (mut band, mut delta) = (Banded::default(), vec![V3::zeros(); n]);
        let mut converged = false;
        let mut trial = p1.clone();
        for _ in 0..MAX_NEWTON {
            if !band.solve(&diag, &off, &far, &g, &mut delta) {
                return None;
            }
            // Newton's step, halved while it does not lower the residual (a node crossing the
            // seabed or a segment going slack is a kink of the forces, where full steps can
            // cycle).
            let mut lambda = 1.0;
            loop {
                for i in 0..n {
                    trial[i] = p1[i] - delta[i] * lambda;
                }
                let r = residual(&trial, &mut f, &mut diag, &mut off, &mut far, &mut g);
                if r < norm || lambda < 1.0 / 1024.0 || !r.is_finite() {
                    norm = r;
                    break;
                }
                lambda *= 0.5;
            }
            let size = delta.iter().map(|d| d.amax()).fold(0.0, f64::max) * lambda;
            p1.clone_from(&trial);
            if !size.is_finite() {
                return None;
            }
            if size <= NEWTON_TOL * scale {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        let (drag, bed, cur, axial) =
            self.forces(&p0, &p1, h, &mut f, &mut diag, &mut off, &mut far);
        let pull = f[0];
        for i in 0..n {
            x[3 * i..3 * i + 3].copy_from_slice(p1[i].as_slice());
        }
        let base = 3 + 3 * self.free();
        for i in 1..n {
            let p = (p1[i] - p0[i]) * (2.0 * self.mass / h) - mom[i];
            x[base + 3 * (i - 1)..base + 3 * i].copy_from_slice(p.as_slice());
        }
        Some(StepWork {
            drag: h * drag,
            axial: h * axial,
            current: h * cur,
            seabed: h * bed,
            top: -pull.dot(&(p1[0] - p0[0])),
            pull,
        })
    }

    /// The rates of the states `x` (the top moving at `top_velocity`) and the line's force on
    /// the top (N, spatial: segment 0's pull and the top half segment's weight): the line's vector field, for the vessel's (eq. 39) and its tests.
    pub fn rates(&self, x: &[f64], top_velocity: &V3, rates: &mut [f64]) -> V3 {
        let n = self.segments;
        let p: Vec<V3> = (0..=n).map(|i| self.node(x, i)).collect();
        let mut f = vec![V3::zeros(); n + 1];
        let vel = |i: usize| {
            if i == 0 {
                *top_velocity
            } else if i == n {
                V3::zeros()
            } else {
                self.momentum(x, i) / self.mass
            }
        };
        for j in 0..n {
            let d = p[j + 1] - p[j];
            let l = d.norm();
            let t = d / l;
            let pull = t * (self.tension(l) + self.axial_damping * t.dot(&(vel(j + 1) - vel(j))));
            f[j] += pull;
            f[j + 1] -= pull;
        }
        for i in 1..n {
            let g = self.bend_gradient(&p[i - 1], &p[i], &p[i + 1]);
            for k in 0..3 {
                f[i - 1 + k] -= g[k];
            }
        }
        f[0].z -= 0.5 * self.weight;
        rates[..3].copy_from_slice(top_velocity.as_slice());
        let base = 3 + 3 * self.free();
        for i in 1..n {
            let v = self.momentum(x, i) / self.mass;
            let mut fi = f[i] - V3::z() * self.weight;
            if p[i].z < self.seabed {
                fi.z += self.seabed_stiffness * (self.seabed - p[i].z) - self.seabed_damping * v.z;
            }
            fi += self.drag(&v, &Self::tangent(&p[i - 1], &p[i + 1])).0;
            rates[3 * i..3 * i + 3].copy_from_slice(v.as_slice());
            rates[base + 3 * (i - 1)..base + 3 * i].copy_from_slice(fi.as_slice());
        }
        f[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The line of the MoorDyn comparison (benchmarks/pipe_moordyn.py): 600 m, d 0.3 m,
    /// 120 kg/m, EA 3e9 N, 200 m of water, top 10 m below the surface, anchor 539 m away.
    fn line(segments: usize, ea: f64) -> Chain {
        let (rho, g, d, mu, length) = (1025.0, 9.81, 0.3, 120.0, 600.0);
        let area = std::f64::consts::PI * d * d / 4.0;
        let l = length / segments as f64;
        Chain {
            segments,
            rest: l,
            ea,
            compression: false,
            axial_damping: 0.0,
            bending: 0.0,
            mass: (mu + rho * area) * l,
            weight: (mu - rho * area) * g * l,
            drag_normal: 0.5 * rho * 1.2 * d * l,
            drag_tangential: 0.5 * rho * 0.008 * std::f64::consts::PI * d * l,
            seabed: -200.0,
            seabed_stiffness: 3e6 * d * l,
            seabed_damping: 3e5 * d * l,
            anchor: V3::new(-539.0, 0.0, -200.0),
            current: V3::zeros(),
        }
    }

    const TOP: V3 = V3::new(0.0, 0.0, -10.0);

    /// The inextensible catenary with seabed contact for the same geometry, written out here
    /// (Irvine, Cable Structures, 1981, §1.3): the horizontal tension `H = w a` from
    /// `L − s = X − a asinh(s/a)`, `s = √(h² + 2 h a)`; the top tension `w (a + h)`.
    fn closed_form(w: f64) -> (f64, f64) {
        let (h, x, length) = (190.0f64, 539.0f64, 600.0f64);
        let f = |a: f64| {
            let s = (h * h + 2.0 * h * a).sqrt();
            (length - s) - (x - a * (s / a).asinh())
        };
        let (mut lo, mut hi) = (1.0f64, 1e5f64);
        for _ in 0..200 {
            let m = 0.5 * (lo + hi);
            if f(m) < 0.0 {
                lo = m;
            } else {
                hi = m;
            }
        }
        let a = 0.5 * (lo + hi);
        let s = (h * h + 2.0 * h * a).sqrt();
        (w * (a + h), a * (s / a).asinh())
    }

    /// With `EA` large the static shape's top tension and touchdown converge to the natural
    /// catenary as the segments shrink: the top tension within 0.1 % from 50 segments (its
    /// error falling with their number), and so the touchdown (printed: docs/model.md §5.18
    /// quotes them).
    #[test]
    fn the_static_shape_converges_to_the_catenary() {
        let mut last = f64::INFINITY;
        let mut errors = Vec::new();
        for n in [25, 50, 100, 200] {
            let c = line(n, 1e13);
            let x = c.static_shape(&TOP).unwrap();
            let mut full = vec![0.0; c.dim()];
            full[..3].copy_from_slice(TOP.as_slice());
            for (i, q) in x.iter().enumerate() {
                full[3 + 3 * i..6 + 3 * i].copy_from_slice(q.as_slice());
            }
            let top = c.top_force(&full).norm();
            let (t_exact, span) = closed_form(c.weight / c.rest);
            let (td, _) = c.touchdown(&full);
            let (e_t, e_td) = (
                (top - t_exact).abs() / t_exact,
                (td.x.abs() - span).abs() / span,
            );
            println!("N = {n}: top tension {top:.1} N (closed form {t_exact:.1}): {e_t:.2e}; touchdown {:.2} m from the top ({span:.2}): {e_td:.2e}", td.x.abs());
            if n >= 50 {
                assert!(e_t < 1e-3, "top tension at N = {n}: {e_t:e}");
                assert!(e_td < 1e-3, "touchdown at N = {n}: {e_td:e}");
            }
            assert!(e_t < last, "the top tension's error falls with N");
            last = e_t;
            errors.push((n as f64, e_t, e_td));
        }
        // Both converge at about second order in the segment length: the slope of the errors'
        // logarithms against the segment count's, fitted by least squares.
        let fit = |e: &dyn Fn(&(f64, f64, f64)) -> f64| {
            let pts: Vec<(f64, f64)> = errors.iter().map(|p| (p.0.ln(), e(p).ln())).collect();
            let (mx, my) = (
                pts.iter().map(|p| p.0).sum::<f64>() / pts.len() as f64,
                pts.iter().map(|p| p.1).sum::<f64>() / pts.len() as f64,
            );
            let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
            let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
            -sxy / sxx
        };
        let (st, std) = (fit(&|p| p.1), fit(&|p| p.2));
        println!("order in 1/N: top tension {st:.2}, touchdown {std:.2}");
        assert!(st > 1.7 && std > 1.7, "orders {st}, {std}");
    }

    /// One step's energy identity: what the line stores changes by the work done at its top,
    /// less the drag, axial and seabed dissipation, plus the current's work, to round-off,
    /// whatever the step (the discrete gradient); a static shape stays put.
    #[test]
    fn a_step_books_the_line_energy_exactly() {
        let mut c = line(40, 3e9);
        c.axial_damping = 1e6 / c.rest;
        // A 12-inch steel pipe's EI (207 GPa, 323.9 by 15.9 mm).
        c.bending = 3.8e7;
        c.current = V3::new(0.5, -0.3, 0.0);
        let nodes = c.static_shape(&TOP).unwrap();
        let mut x = vec![0.0; c.dim()];
        x[..3].copy_from_slice(TOP.as_slice());
        for (i, q) in nodes.iter().enumerate() {
            x[3 + 3 * i..6 + 3 * i].copy_from_slice(q.as_slice());
        }
        // Still water and a fixed top: the static shape stays.
        let mut c0 = c.clone();
        c0.current = V3::zeros();
        let mut y = x.clone();
        let w = c0.step(&mut y, 0.5, &Top::Given(TOP)).unwrap();
        let moved = (3..3 + 3 * c.free())
            .map(|i| (y[i] - x[i]).abs())
            .fold(0.0, f64::max);
        assert!(moved < 1e-9, "the static shape moved {moved} m");
        assert!(w.drag.abs() < 1e-9 && w.top == 0.0);
        // The top moved about, with the current: each step's balance.
        for h in [0.01, 0.5, 2.0] {
            let mut y = x.clone();
            for k in 0..20 {
                let t = (k + 1) as f64 * h;
                let r = TOP
                    + V3::new(
                        2.0 * (0.6 * t).sin(),
                        0.5 * (0.3 * t).cos() - 0.5,
                        (0.6 * t).sin(),
                    );
                let e0 = c.storage(&y);
                let w = c.step(&mut y, h, &Top::Given(r)).unwrap();
                let e1 = c.storage(&y);
                let booked = w.top + w.current - w.drag - w.axial - w.seabed;
                let scale = e0.abs() + w.drag.abs() + w.top.abs();
                assert!(
                    ((e1 - e0) - booked).abs() <= 1e-12 * scale,
                    "h = {h}, step {k}: ΔH = {} J, booked {booked} J",
                    e1 - e0
                );
                assert!(w.drag >= 0.0 && w.axial >= 0.0 && w.seabed >= 0.0);
            }
        }
    }
    /// The bending spring's gradient is its energy's, by central differences.
    #[test]
    fn the_bending_springs_gradient_is_its_energys() {
        let mut c = line(10, 3e9);
        c.bending = 3.8e7;
        let pts = [
            V3::new(0.0, 0.0, 0.0),
            V3::new(10.0, 1.0, -2.0),
            V3::new(19.0, 3.0, -6.0),
        ];
        let g = c.bend_gradient(&pts[0], &pts[1], &pts[2]);
        for k in 0..3 {
            for j in 0..3 {
                let (mut p, mut m) = (pts, pts);
                p[k][j] += 1e-6;
                m[k][j] -= 1e-6;
                let fd = (c.bend(&p[0], &p[1], &p[2]) - c.bend(&m[0], &m[1], &m[2])) / 2e-6;
                assert!(
                    (g[k][j] - fd).abs() < 1e-6 * g[k].norm(),
                    "{k} {j}: {} vs {fd}",
                    g[k][j]
                );
            }
        }
    }
}
