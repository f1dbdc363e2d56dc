"""An independent reference for a general vessel, for the tests: Fossen's equations of
motion in the body velocities,

    M nu' + C(nu) nu + D nu + d_cf(nu) + g(eta) = tau_pid,    Q' = Q S(w),    x' = Q v,

written in numpy from the handbook's form (T. I. Fossen, *Handbook of Marine Craft Hydrodynamics
and Motion Control*, 2nd ed., Wiley 2021): M = M_RB + M_A with M_RB of eq. 3.44 (centre of gravity
r_g, inertia I_g about it), C(nu) from M in the velocity-independent parametrisation of a
symmetric M (Fossen 2021, eq. 6.43 for M_A; the same form for M_RB, Theorem 3.2),
C(nu) = [[0, -S(M11 nu1 + M12 nu2)], [-S(M11 nu1 + M12 nu2), -S(M21 nu1 + M22 nu2)]]; cross-flow
drag by strip theory (eq. 6.99-6.100, by Gauss-Legendre quadrature exact on each piece); restoring in the paper's form
with the heave spring at the centre of flotation x_F (docs/model.md §2, §5.15: the potential
V = c/2 (z + x_F q3_x)^2 + q3^T G q3 / 2, c = rho g A_wp, G = m g (GM_L, GM_T, 0), q3 = Q^T e3;
heave force -dV/dz along q3, moment q3 x dV/dq3); the PID of the paper's eqs. 29-33. Integrated by scipy's DOP853 at tight tolerance.

Nothing here calls phsplit's integrators or vector field, and the state is not phsplit's (nu, not
the momenta; no restoring variable mu): only the vessel file's numbers and the initial state are
shared."""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp


# The cross-product matrix, ZYX Euler angles and Pi_e: the small kinematic helpers of the
# other independent model (tests/reference.py), shared; the dynamics below are not.
from reference import euler_zyx, hat as S  # noqa: E402
from reference import pi_e as euler_rate_inverse  # noqa: E402


def rot_zyx(th):
    (cf, sf), (ct, st), (cp, sp) = [(np.cos(a), np.sin(a)) for a in th]
    rx = np.array([[1, 0, 0], [0, cf, -sf], [0, sf, cf]])
    ry = np.array([[ct, 0, st], [0, 1, 0], [-st, 0, ct]])
    rz = np.array([[cp, -sp, 0], [sp, cp, 0], [0, 0, 1]])
    return rz @ ry @ rx


class Vessel:
    """The right-hand side on y = (nu (6), Q col-major (9), x (3), phi_th (3), phi_x (3))."""

    def __init__(self, params: dict, control_on: bool = True):
        h = params["vessel"]
        m = h["mass"]
        rg = np.array(h.get("center_of_gravity", [0.0, 0.0, 0.0]), float)
        Ig = np.diag(h["inertia"])
        mrb = np.block([[m * np.eye(3), -m * S(rg)], [m * S(rg), Ig - m * S(rg) @ S(rg)]])
        self.M = mrb + np.array(h.get("added_mass", np.zeros((6, 6))), float)
        if "damping_matrix" in h:
            self.D = np.array(h["damping_matrix"], float)
        else:
            self.D = np.diag(np.concatenate([h["damping_translational"], h["damping_rotational"]]))
        self.heave = h["gravity"] * h["water_density"] * h["waterplane_area"]
        w = m * h["gravity"]
        self.G = np.array([w * h["gm_longitudinal"], w * h["gm_transverse"], 0.0])
        # the heave spring acts at the centre of flotation (x_F, y_F, 0)
        self.rf = np.array([h.get("flotation_center_x", 0.0), h.get("flotation_center_y", 0.0), 0.0])
        c = params["control"]
        k = 1.0 if control_on else 0.0
        self.K = {n: k * np.diag(c[n]) for n in ("kp_translational", "kd_translational", "ki_translational",
                                                    "kp_rotational", "kd_rotational", "ki_rotational")}
        self.xr, self.thr, self.on = np.array(c["position_reference"]), np.array(c["euler_reference"]), control_on
        cf = params.get("crossflow_drag")
        self.cf = None
        if cf:
            self.cf = (0.5 * h["water_density"] * cf["draft"] * cf["drag_coefficient"], cf["x_aft"], cf["x_fore"])
        dq = params.get("damping_quadratic")
        self.cq = np.array(dq["coefficients"], float) if dq else np.zeros(6)

    def coriolis(self, nu):
        a = self.M[:3] @ nu
        b = self.M[3:] @ nu
        return np.block([[np.zeros((3, 3)), -S(a)], [-S(a), -S(b)]])

    def crossflow(self, nu):
        """Strip theory: -k int |v + x r| (v + x r) (1, x) dx over the hull, by Gauss-Legendre on
        the pieces either side of the zero of v + x r, where the integrands are polynomials of
        degree 2 and 3 (four nodes are exact)."""
        if self.cf is None:
            return np.zeros(6)
        k, xa, xf = self.cf
        v, r = nu[1], nu[5]
        cuts = [xa, xf]
        if r != 0 and xa < -v / r < xf:
            cuts = [xa, -v / r, xf]
        nodes, weights = np.polynomial.legendre.leggauss(4)
        y = n = 0.0
        for a, b in zip(cuts[:-1], cuts[1:]):
            xx = 0.5 * (b - a) * nodes + 0.5 * (a + b)
            s = np.abs(v + xx * r) * (v + xx * r)
            y += 0.5 * (b - a) * weights @ s
            n += 0.5 * (b - a) * weights @ (xx * s)
        return np.array([0.0, -k * y, 0.0, 0.0, 0.0, -k * n])

    def __call__(self, t, y):
        nu, Q = y[0:6], y[6:15].reshape(3, 3, order="F")
        x, phth, phx = y[15:18], y[18:21], y[21:24]
        v, w = nu[:3], nu[3:]
        q3 = Q.T @ np.array([0.0, 0.0, 1.0])
        th = euler_zyx(Q)
        W = np.linalg.solve(euler_rate_inverse(th), Q)
        K = self.K
        tau = np.concatenate([
            -Q.T @ (K["kp_translational"] @ (x - self.xr) + K["kd_translational"] @ (Q @ v) + K["ki_translational"] @ phx),
            -W.T @ (K["kp_rotational"] @ (th - self.thr) + K["kd_rotational"] @ (W @ w) + K["ki_rotational"] @ phth),
        ])
        # V = c/2 (z + r_F . q3)^2 + q3^T G q3 / 2: z_F is the height of the centre of flotation
        zf = x[2] + self.rf @ q3
        dv_dq3 = self.G * q3 + self.heave * zf * self.rf
        g = np.concatenate([q3 * self.heave * zf, np.cross(dv_dq3, q3)])
        rhs = tau - self.coriolis(nu) @ nu - self.D @ nu - self.cq * np.abs(nu) * nu + self.crossflow(nu) - g
        dy = np.empty(24)
        dy[0:6] = np.linalg.solve(self.M, rhs)
        dy[6:15] = (Q @ S(w)).reshape(-1, order="F")
        dy[15:18] = Q @ v
        dy[18:21] = (th - self.thr) if self.on else 0.0
        dy[21:24] = (x - self.xr) if self.on else 0.0
        return dy


def initial(euler, position, velocity, angular_velocity) -> np.ndarray:
    return np.concatenate([velocity, angular_velocity, rot_zyx(np.asarray(euler, float)).reshape(-1, order="F"),
                           position, np.zeros(6)])


def solve(params: dict, y0: np.ndarray, t_end: float, rtol: float = 1e-12) -> np.ndarray:
    """The state at t_end, controller on throughout."""
    atol = np.maximum(np.abs(y0), 1e-3) * rtol * 1e-2
    sol = solve_ivp(Vessel(params, True), (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=atol,
                    t_eval=[t_end])
    assert sol.success, sol.message
    return sol.y[:, -1]


def errors_against(vessel, init: dict, method: str, hs, t_end: float = 16.0, check=None):
    """Relative end errors of phsplit's `method` at the steps `hs` against this model (DOP853 at
    rtol 1e-13), controller on from t = 0: the largest of the body velocities', the attitude's
    and the position's. `check(solution)` is called on each run."""
    import phsplit

    ref = solve(vessel.to_dict(), initial(**init), t_end, rtol=1e-13)
    nu_ref, q_ref, x_ref = ref[0:6], ref[6:15].reshape(3, 3, order="F"), ref[15:18]
    y0 = vessel.initial_state(**init)
    errs = []
    for h in hs:
        s = phsplit.simulate(vessel, (0.0, t_end), h, method, control_start=0.0, initial=y0,
                             ledger=check is not None)
        assert s.status == "completed", s.failure
        if check is not None:
            check(s)
        nu = np.concatenate([s.v[-1], s.w[-1]])
        errs.append(max(np.linalg.norm(nu - nu_ref) / np.linalg.norm(nu_ref),
                        np.linalg.norm(s.Q[-1] - q_ref) / np.sqrt(3),
                        np.linalg.norm(s.x[-1] - x_ref) / np.linalg.norm(x_ref)))
    return np.array(errs)
