"""An independent reference for the dynamic pipe (the vessel file's [pipe] table with
``model = "lumped_mass"``), for the tests: a lumped-mass line hanging from the hang-off point
of the vessel to an anchor on the seabed, written in numpy and coupled to the vessel of
tests/reference.py (eq. (39) of the paper, docs/model.md §2 and §5), the whole integrated by
scipy's Radau at tight tolerance.

Nothing here calls phsplit or shares its code; only the parameters and the initial state are
shared. From reference.py it takes the vessel's field (``Field``), untouched: the pipe's force
and moment at the hang-off point are added to the vessel's momentum equations exactly as
reference.py adds its other loads (a body-frame force ``f_b`` and its moment ``r_h x f_b``).

Sources of the formulas:

* The line: MoorDyn's lumped-mass model, M. Hall & A. Goupee, "Validation of a lumped-mass
  mooring line model with DeepCwind semisubmersible model test data", Ocean Engineering 104
  (2015) 590-603, §2 (nodes 0..N, segment length l = L/N, axial tension
  T = EA (l_j - l)/l in tension only, submerged weight per node, Morison drag on the velocity
  relative to the water split normal / tangential to the node's tangent
  unit(q_{i+1} - q_{i-1}), the seabed as a vertical spring-damper acting on the penetration,
  the node's added mass; here the added mass is taken isotropic,
  m_n = (mu + Ca rho pi d^2/4) l, and the tangential drag on the pipe's circumference
  pi d l). Bending, torsion and internal damping are left out.
* The static check: the inelastic catenary with seabed contact, M. Irvine, Cable Structures
  (1981) §1.2, and O. M. Faltinsen, Sea Loads on Ships and Offshore Structures (1990) §8.2:
  with w the submerged weight per metre, a = H/w and h the height of the top above the
  seabed, the suspended length s = sqrt(h^2 + 2 h a), its span a asinh(s/a), the top tension
  T = H + w h; the part on the bottom is straight and carries H.

The model (SI, z up; Q the attitude body -> spatial, x the vessel's position):
    q_0 = x + Q r_h (on the vessel), q_N = (a_x, a_y, -D) (fixed), free nodes 1..N-1,
    m_n dv_i/dt = T_i t_i - T_{i-1} t_{i-1} - W e3 + F_drag,i + F_seabed,i,   dq_i/dt = v_i,
    the vessel's load F = T_0 t_0 (spatial), f_b = Q^T F, m_b = r_h x f_b.
Storage of the pipe: sum 1/2 m_n |v_i|^2 + sum psi(l_j) + sum W z_i + sum 1/2 kb d l pen_i^2,
psi = EA (l_j - l)^2 / (2 l) where taut (always with ``compression``).

Functions:
    pipe_params(pipe, vessel_params)          -> the derived constants (a dict)
    pipe_forces(P, q0, q, v, uc)              -> forces on the free nodes, the force on the vessel
    static_shape(pipe, vessel_params, top)    -> free nodes' positions at static equilibrium
    catenary_closed_form(pipe, vessel_params, top) -> the inelastic catenary's numbers
    elastic_catenary_closed_form(pipe, vessel_params, top) -> the same with the stretch EA
    static_summary(pipe, vessel_params, top, q) -> top tension, horizontal tension, touchdown
    initial_pipe(vessel_params, pipe, y0_vessel) -> the static shape under the vessel's y0
    CoupledField(vessel_params, pipe, control_on, hold_vessel=False): y' and energy(y)
    solve_coupled(vessel_params, pipe, y0_vessel, pipe_nodes0, t_end, ...) -> (t, y, q, v)

Checks made when this was written (the paper's vessel, the line below with r_h = (-60, 0, -10)):
* statics, depth 200 m, top (0, 0, -10), anchor (-539, 0, -200), L = 600, d = 0.3, mu = 120,
  EA = 3e9: Newton converges in 6-7 iterations to round-off (residual 1e-5..1e-4 N). Against the
  inelastic catenary (H = 165016 N, T = 253639 N, s = 412.96 m, TDP x = -351.96) at
  N = 25/50/100/200: H -2.6e-3/-1.3e-3/-1.5e-3/-1.5e-3, top tension (segment 0's, l/2 below the
  top) -1.8e-2/-9.2e-3/-5.2e-3/-3.1e-3, suspended length (V_0/w + l/2) -1.2e-3/-5.1e-4/-6.5e-4/
  -6.1e-4; the floors are the stretch (against the elastic catenary: H -1.2e-3/+1.4e-4/-5.7e-5/
  +2.3e-5, s -5.2e-4/+1.2e-4/-2.3e-5/+1.6e-5).
* the static shape under a held vessel stays put: |v| < 4e-14 m/s over 20 s (N = 10).
* without drag, seabed damping and the vessel's damping and control, the total energy from a
  disturbed state (random node offsets 5 cm and velocities 0.2 m/s, vessel momenta) changes by
  0.03 J over 20 s (7.7e-10 of |E|, 3e-8 of the 1e6 J the vessel exchanges); with drag, seabed
  contact and a current, dE/dt = -(dissipation) + (current's work) to 1e-9.
* cost (2 cores, one run at a time, rtol 1e-11, controller on, damping on, static line):
  2 s take 10 s at N = 10 and 15 s at N = 20; 20 s take ~90 s and ~150 s (~200k and ~250k
  evaluations; reference.py's Field is 2/3 of an evaluation). The final momentum agrees to
  1.3e-12 between rtol 1e-9, 1e-10 and 1e-11: the velocities' round-off floor of atol sets the step.
"""
from __future__ import annotations

import numpy as np
from reference import Field, control_segments, full_initial
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.sparse import csc_matrix, lil_matrix

DEFAULTS = {"drag_normal": 1.2, "drag_tangential": 0.008, "added_mass": 1.0, "seabed_stiffness": 3.0e6,
            "seabed_damping": 3.0e5, "compression": False}


def pipe_params(pipe: dict, vessel_params: dict) -> dict:
    """The constants of the line from the [pipe] table and the vessel's gravity and density."""
    p = {**DEFAULTS, **{k: v for k, v in pipe.items()}}
    h = vessel_params["vessel"]
    g, rho = float(h["gravity"]), float(h["water_density"])
    N = int(p["segments"])
    if N < 2:
        raise ValueError("pipe.segments must be >= 2")
    L, d, mu = float(p["length"]), float(p["diameter"]), float(p["mass"])
    l = L / N
    area = np.pi * d * d / 4.0
    D = float(p["water_depth"])
    cur = vessel_params.get("current")
    return {
        "N": N, "L": L, "l": l, "EA": float(p["axial_stiffness"]), "d": d, "D": D, "rho": rho, "g": g,
        "mn": (mu + float(p["added_mass"]) * rho * area) * l,
        "W": (mu - rho * area) * g * l,
        "w": (mu - rho * area) * g,
        "r_h": np.array(p["hang_off"], float),
        "anchor": np.array([p["anchor"][0], p["anchor"][1], -D], float),
        "cn": 0.5 * rho * d * l * float(p["drag_normal"]),
        "ct": 0.5 * rho * np.pi * d * l * float(p["drag_tangential"]),
        "kb": float(p["seabed_stiffness"]) * d * l,
        "cb": float(p["seabed_damping"]) * d * l,
        "compression": bool(p["compression"]),
        "vc": np.array(cur.get("velocity", [0.0] * 3), float) if cur else np.zeros(3),
        "vc_table": (np.array(cur["times"], float), np.array(cur["velocities"], float))
        if cur and "times" in cur else None,
    }


def current_at(P: dict, t: float) -> np.ndarray:
    """The current's spatial velocity at t (the same rule as reference.py's Field)."""
    if P["vc_table"] is None:
        return P["vc"]
    ts, vs = P["vc_table"]
    return np.array([np.interp(t, ts, vs[:, i]) for i in range(3)])


def _segments(P, q0, q):
    nodes = np.vstack([q0, q, P["anchor"]])
    dq = np.diff(nodes, axis=0)
    lj = np.linalg.norm(dq, axis=1)
    t = dq / lj[:, None]
    T = P["EA"] * (lj - P["l"]) / P["l"]
    if not P["compression"]:
        T = np.where(lj > P["l"], T, 0.0)
    return nodes, dq, lj, t, T


def pipe_forces(P: dict, q0, q, v, uc):
    """The forces on the free nodes (N-1, 3) at positions q and velocities v, top at q0, current
    uc; and the spatial force of the line on the vessel at node 0, T_0 t_0."""
    nodes, _, _, t, T = _segments(P, q0, q)
    f = T[:, None] * t
    F = f[1:] - f[:-1]
    F[:, 2] -= P["W"]
    tan = nodes[2:] - nodes[:-2]
    tan = tan / np.linalg.norm(tan, axis=1)[:, None]
    vr = v - uc
    vt = np.sum(vr * tan, axis=1)[:, None] * tan
    vn = vr - vt
    F -= P["cn"] * np.linalg.norm(vn, axis=1)[:, None] * vn + P["ct"] * np.linalg.norm(vt, axis=1)[:, None] * vt
    pen = -P["D"] - q[:, 2]
    on = pen > 0
    F[:, 2] += np.where(on, P["kb"] * pen - P["cb"] * v[:, 2], 0.0)
    # the top half segment's weight rides on the vessel with the hang-off point (as phsplit's
    # lumped line carries it, docs/model.md §5.18; MoorDyn's coupled point likewise)
    return F, f[0] - np.array([0.0, 0.0, 0.5 * P["W"]])


def pipe_energy(P: dict, q0, q, v) -> float:
    """The line's storage: kinetic, axial, weight (relative to z = 0) and seabed spring."""
    _, _, lj, _, _ = _segments(P, q0, q)
    st = lj - P["l"]
    if not P["compression"]:
        st = np.maximum(st, 0.0)
    pen = np.maximum(-P["D"] - q[:, 2], 0.0)
    return (0.5 * P["mn"] * np.sum(v * v) + P["EA"] / (2 * P["l"]) * np.sum(st * st)
            + P["W"] * np.sum(q[:, 2]) + 0.5 * P["W"] * q0[2] + 0.5 * P["kb"] * np.sum(pen * pen))


def pipe_dissipation(P: dict, q0, q, v, uc):
    """(dissipated, current's work) rates of the line, W: drag on the relative velocity and the
    seabed damper dissipate; the drag's work against the current's velocity is supplied."""
    nodes = np.vstack([q0, q, P["anchor"]])
    tan = nodes[2:] - nodes[:-2]
    tan = tan / np.linalg.norm(tan, axis=1)[:, None]
    vr = v - uc
    vt = np.sum(vr * tan, axis=1)[:, None] * tan
    vn = vr - vt
    Fd = -(P["cn"] * np.linalg.norm(vn, axis=1)[:, None] * vn + P["ct"] * np.linalg.norm(vt, axis=1)[:, None] * vt)
    on = (-P["D"] - q[:, 2]) > 0
    sb = np.sum(np.where(on, P["cb"] * v[:, 2] ** 2, 0.0))
    return -np.sum(Fd * vr) + sb, float(np.sum(Fd * uc))


# ----------------------------------------------------------------------------------------------
# statics


def catenary_closed_form(pipe: dict, vessel_params: dict, top) -> dict:
    """The inelastic catenary with seabed contact between ``top`` and the anchor (Irvine 1981
    §1.2): a = H/w solves s(a) - a asinh(s(a)/a) = L - X with s = sqrt(h^2 + 2 h a); X the
    horizontal distance anchor-top, h the top's height above the seabed. Raises ValueError
    when the line has no part on the bottom (X >= L or L - X >= h or s > L)."""
    P = pipe_params(pipe, vessel_params)
    top = np.asarray(top, float)
    rel = top[:2] - P["anchor"][:2]
    X, h, L, w = np.hypot(*rel), top[2] + P["D"], P["L"], P["w"]
    if not (0.0 < L - X < h):
        raise ValueError("no catenary with seabed contact for this geometry")
    def gap(la):
        a = np.exp(la)
        s = np.sqrt(h * h + 2 * h * a)
        return s - a * np.arcsinh(s / a) - (L - X)

    a = np.exp(brentq(gap, -40.0, 60.0, xtol=1e-15, rtol=1e-15))
    s = np.sqrt(h * h + 2 * h * a)
    if s > L:
        raise ValueError("the catenary lifts off at the anchor")
    H = w * a
    e = rel / X
    td = P["anchor"][:2] + e * (L - s)
    return {"a": a, "H": H, "top_tension": H + w * h, "vertical_tension": w * s, "suspended_length": s,
            "span": a * np.arcsinh(s / a), "touchdown": td, "on_bottom": L - s, "direction": e}


def elastic_catenary_closed_form(pipe: dict, vessel_params: dict, top) -> dict:
    """The elastic catenary with frictionless seabed contact (Irvine 1981 §2.2 with the grounded
    part of §2.3): with s the unstretched suspended length and a = H/w, the suspended part spans
    a asinh(s/a) + H s/EA and rises a (sqrt(1 + (s/a)^2) - 1) + w s^2/(2 EA); the grounded part,
    carrying H, is stretched by (1 + H/EA). Solved for (H, s) by nested root finding."""
    P = pipe_params(pipe, vessel_params)
    top = np.asarray(top, float)
    rel = top[:2] - P["anchor"][:2]
    X, h, L, w, EA = np.hypot(*rel), top[2] + P["D"], P["L"], P["w"], P["EA"]

    def s_of(a):
        return brentq(lambda s: a * (np.sqrt(1 + (s / a) ** 2) - 1) + w * s * s / (2 * EA) - h, 0.0,
                      1.001 * np.sqrt(h * h + 2 * h * a),
                      xtol=1e-14, rtol=1e-15)

    def gap(la):
        a = np.exp(la)
        s = s_of(a)
        H = w * a
        return a * np.arcsinh(s / a) + H * s / EA + (L - s) * (1 + H / EA) - X

    a0 = catenary_closed_form(pipe, vessel_params, top)["a"]
    a = np.exp(brentq(gap, np.log(a0) - 5.0, np.log(a0) + 5.0, xtol=1e-15, rtol=1e-15))
    s = s_of(a)
    H = w * a
    e = rel / X
    on = (L - s) * (1 + H / EA)
    return {"a": a, "H": H, "top_tension": np.hypot(H, w * s), "suspended_length": s, "touchdown": P["anchor"][:2] + e * on,
            "on_bottom": on}


def _initial_guess(P, pipe, vessel_params, top):
    """Free nodes on the inelastic catenary at their unstretched arc lengths, the on-bottom
    ones at the seabed spring's static penetration; straight (chords) when there is no
    catenary with contact. Also the catenary's tension per segment (the Newton's floor of the
    geometric stiffness)."""
    N, l = P["N"], P["l"]
    sig = P["L"] - l * np.arange(1, N)  # arc length from the anchor of nodes 1..N-1
    try:
        c = catenary_closed_form(pipe, vessel_params, top)
    except ValueError:
        fr = sig / P["L"]
        return P["anchor"] + fr[:, None] * (np.asarray(top, float) - P["anchor"]), np.full(N, 0.25 * abs(P["w"]) * P["L"])
    e3 = np.array([c["direction"][0], c["direction"][1], 0.0])
    q = np.empty((N - 1, 3))
    tdp = np.array([c["touchdown"][0], c["touchdown"][1], -P["D"]])
    pen0 = P["W"] / P["kb"] if P["kb"] > 0 else 0.0
    for k, sg in enumerate(sig):
        if sg <= c["on_bottom"]:
            q[k] = P["anchor"] + sg * e3
            q[k, 2] = -P["D"] - pen0
        else:
            u = sg - c["on_bottom"]
            q[k] = tdp + c["a"] * np.arcsinh(u / c["a"]) * e3
            q[k, 2] = -P["D"] + np.sqrt(c["a"] ** 2 + u * u) - c["a"]
    # the catenary's tension at the segments' middles: H on the bottom, sqrt(H^2 + (w u)^2) above
    u = np.maximum(P["L"] - l * (np.arange(N) + 0.5) - c["on_bottom"], 0.0)
    return q, np.hypot(c["H"], P["w"] * u)


def _static_residual_jacobian(P, q0, q):
    """Static force balance R(q) (N-1, 3) and its dense Jacobian dR/dq (3(N-1))^2 (block
    tridiagonal: segment j's stiffness K_j = k_ax t t^T + T/l_j (I - t t^T))."""
    zero = np.zeros_like(q)
    R, _ = pipe_forces(P, q0, q, zero, np.zeros(3))
    _, _, lj, t, T = _segments(P, q0, q)
    # exact where the segments carry more than half the catenary's tension (so at the solution);
    # elsewhere the axial stiffness EA/l and the geometric stiffness of half the catenary's
    # tension stand in (a modified Newton: the unstretched guess has chords a little short of l,
    # so no tension, and a segment without tension has no transverse stiffness)
    kax = P["EA"] / P["l"]
    Tt = np.maximum(T, P["T_floor"])
    I3 = np.eye(3)
    K = [kax * np.outer(t[j], t[j]) + Tt[j] / lj[j] * (I3 - np.outer(t[j], t[j])) for j in range(P["N"])]
    n = P["N"] - 1
    J = np.zeros((3 * n, 3 * n))
    for i in range(n):  # free node i+1 lies between segments i (above) and i+1 (below)
        s = slice(3 * i, 3 * i + 3)
        J[s, s] = -K[i] - K[i + 1]
        if i > 0:
            J[s, 3 * i - 3:3 * i] = K[i]
        if i < n - 1:
            J[s, 3 * i + 3:3 * i + 6] = K[i + 1]
        if -P["D"] - q[i, 2] > 0:
            J[3 * i + 2, 3 * i + 2] -= P["kb"]
    return R, J


def _newton(P, q0, q, tol, maxit=100):
    scale = max(abs(P["W"]), 1.0)
    R, J = _static_residual_jacobian(P, q0, q)
    r = np.abs(R).max()
    for it in range(maxit):
        if r < tol * scale:
            return q, it, r
        dq = np.linalg.solve(J, -R.ravel()).reshape(q.shape)
        if np.abs(dq).max() < 1e-12 * P["L"]:  # at round-off: the residual's floor is ~eps EA L / l
            q = q + dq
            R, _ = _static_residual_jacobian(P, q0, q)
            return q, it + 1, np.abs(R).max()
        lam = 1.0
        while True:  # backtracking on the largest residual
            qn = q + lam * dq
            Rn, Jn = _static_residual_jacobian(P, q0, qn)
            rn = np.abs(Rn).max()
            if rn < r or lam < 1e-6:
                break
            lam *= 0.5
        q, R, J, r = qn, Rn, Jn, rn
    raise RuntimeError(f"static Newton did not converge: residual {r:.3e} N after {maxit} iterations")


def static_shape(pipe: dict, vessel_params: dict, top, tol: float = 1e-11, return_info: bool = False):
    """The free nodes' positions (N-1, 3) in static equilibrium (zero velocity, all forces of
    the model) with node 0 at ``top`` (spatial), by Newton's method on the force balance with
    the dense (block-tridiagonal) Jacobian, from the inelastic catenary (``_initial_guess``).
    The first pass takes the axial springs as two-sided (smooth, regular Jacobian); if the
    model is tension-only and some segment is slack there, a second pass follows with the
    tension-only law. Converged when the largest nodal force residual is below tol times the
    node's submerged weight, or when the Newton step is below 1e-12 L (round-off: the residual
    cannot go below about eps EA L / l). With ``return_info`` also (iterations, residual in N)."""
    P = pipe_params(pipe, vessel_params)
    top = np.asarray(top, float)
    q, Tc = _initial_guess(P, pipe, vessel_params, top)
    P["T_floor"] = 0.5 * Tc
    q, it, r = _newton({**P, "compression": True}, top, q, tol)
    if not P["compression"]:
        q, it2, r = _newton(P, top, q, tol)
        it += it2
    return (q, (it, r)) if return_info else q


def static_summary(pipe: dict, vessel_params: dict, top, q) -> dict:
    """Top tension T_0 (segment 0's), its horizontal part |T_0 t_0,h|, and the touchdown point:
    the last node in contact from the top (``touchdown_node``, its x, y) and a touchdown
    interpolated on sqrt(height) between the first two lifted nodes (the catenary's
    z - z_td ~ (x - x_td)^2 / (2a) near the seabed), as (x, y) and the distance from the anchor;
    and the suspended length from the vertical tension, V_0 / w + l/2."""
    P = pipe_params(pipe, vessel_params)
    top = np.asarray(top, float)
    nodes, _, _, t, T = _segments(P, top, q)
    out = {"top_tension": T[0], "horizontal_tension": T[0] * np.hypot(t[0, 0], t[0, 1]),
           "vertical_tension": -T[0] * t[0, 2], "tensions": T, "nodes": nodes,
           # node 1 carries the line from l/2 to 3l/2 below the top: the weight above the
           # seabed is w (s - l/2)
           "suspended_length": -T[0] * t[0, 2] / P["w"] + P["l"] / 2}
    z = nodes[:, 2] + P["D"]
    on = np.nonzero(z[1:-1] < 0)[0] + 1  # free nodes in contact
    if len(on):
        k = on.min()  # the contact node nearest the top
        out["touchdown_node"] = nodes[k, :2]
        a, b = nodes[k - 1], nodes[max(k - 2, 0)]
        ha, hb = max(a[2] + P["D"], 0.0), max(b[2] + P["D"], 0.0)
        e = (top[:2] - P["anchor"][:2]) / np.linalg.norm(top[:2] - P["anchor"][:2])
        xa, xb = (a[:2] - P["anchor"][:2]) @ e, (b[:2] - P["anchor"][:2]) @ e
        xt = xa - np.sqrt(ha) * (xb - xa) / (np.sqrt(hb) - np.sqrt(ha))
        out["touchdown"] = P["anchor"][:2] + xt * e
        out["touchdown_from_anchor"] = xt
    return out


# ----------------------------------------------------------------------------------------------
# the coupled vessel and line


def _vessel_only(vessel_params: dict) -> dict:
    """The vessel's parameters without the [pipe] table (reference.py's Field reads a [pipe]
    table as the quasi-static catenary of §5.6)."""
    return {k: v for k, v in vessel_params.items() if k != "pipe"}


def _pipe_table(vessel_params, pipe):
    if pipe is None:
        pipe = vessel_params["pipe"]
    if pipe.get("model", "lumped_mass") != "lumped_mass":
        raise ValueError("reference_pipe models the [pipe] table with model = 'lumped_mass'")
    return pipe


class CoupledField:
    """y' of the vessel (reference.py's Field) and the line: y = (the vessel's states, as in
    reference.py: 27, then the set point's filter (18) and a port-Hamiltonian subsystem's
    states where the vessel has them; then the free nodes' positions (N-1)x3 row by row, then
    their velocities (N-1)x3). With ``hold_vessel`` the vessel's states are frozen (y' = 0)."""

    def __init__(self, vessel_params: dict, pipe: dict | None, control_on: bool, nv: int, hold_vessel: bool = False):
        pipe = _pipe_table(vessel_params, pipe)
        self.vessel = Field(_vessel_only(vessel_params), control_on)
        self.P = pipe_params(pipe, vessel_params)
        self.nv = nv
        self.n = self.P["N"] - 1
        self.hold = hold_vessel

    def split(self, y):
        nv, n = self.nv, self.n
        return y[:nv], y[nv:nv + 3 * n].reshape(n, 3), y[nv + 3 * n:].reshape(n, 3)

    def top(self, yv):
        Q = yv[6:15].reshape(3, 3, order="F")
        return yv[18:21] + Q @ self.P["r_h"], Q

    def __call__(self, t, y):
        yv, q, v = self.split(y)
        q0, Q = self.top(yv)
        F, Fv = pipe_forces(self.P, q0, q, v, current_at(self.P, t))
        dy = np.empty_like(y)
        if self.hold:
            dy[:self.nv] = 0.0
        else:
            dyv = self.vessel(t, yv)
            fb = Q.T @ Fv
            dyv[0:3] += fb  # on the momentum equations, as reference.py adds its loads
            dyv[3:6] += np.cross(self.P["r_h"], fb)
            dy[:self.nv] = dyv
        dy[self.nv:self.nv + 3 * self.n] = v.ravel()
        dy[self.nv + 3 * self.n:] = (F / self.P["mn"]).ravel()
        return dy

    def energy(self, y) -> float:
        """The vessel's H (reference.py) plus the line's storage."""
        yv, q, v = self.split(y)
        q0, _ = self.top(yv)
        return self.vessel.energy(yv) + pipe_energy(self.P, q0, q, v)

    def pipe_rates(self, t, y):
        """(dissipated, current's work) of the line at (t, y), W."""
        yv, q, v = self.split(y)
        q0, _ = self.top(yv)
        return pipe_dissipation(self.P, q0, q, v, current_at(self.P, t))

    def sparsity(self):
        """The Jacobian's pattern: the vessel block dense, and its rows on node 1's position;
        a node's acceleration on the positions of its neighbours and itself and on its own
        velocity; node 1's also on the vessel's attitude and position."""
        nv, n = self.nv, self.n
        S = lil_matrix((nv + 6 * n, nv + 6 * n), dtype=np.int8)
        S[:nv, :nv] = 1
        S[:nv, nv:nv + 3] = 1
        for i in range(n):
            rp, rv = nv + 3 * i, nv + 3 * n + 3 * i
            S[rp:rp + 3, rv:rv + 3] = 1
            for k in (i - 1, i, i + 1):
                if 0 <= k < n:
                    S[rv:rv + 3, nv + 3 * k:nv + 3 * k + 3] = 1
            S[rv:rv + 3, rv:rv + 3] = 1
        S[nv + 3 * n:nv + 3 * n + 3, 6:15] = 1
        S[nv + 3 * n:nv + 3 * n + 3, 18:21] = 1
        return S.tocsc()

    def jacobian(self, scale, dense=None):
        """A forward-difference Jacobian on the pattern of ``sparsity``, columns grouped greedily
        so that no two in a group share a row; column k stepped by sqrt(eps) max(|y_k|, scale_k).
        Returned dense up to 400 states (Radau then uses dense LU), else sparse.
        (scipy's own finite differences grow their step without bound on the columns with no
        effect, the integral states with the controller off, and overflow.)"""
        S = self.sparsity().tocsc()
        n = S.shape[0]
        dense = n <= 400 if dense is None else dense  # Radau's dense LU is the quicker one here
        rows = [S.indices[S.indptr[k]:S.indptr[k + 1]] for k in range(n)]
        groups, used = [], []
        for k in range(n):
            for g, u in zip(groups, used):
                if not u[rows[k]].any():
                    g.append(k)
                    u[rows[k]] = True
                    break
            else:
                u = np.zeros(n, bool)
                u[rows[k]] = True
                groups.append([k])
                used.append(u)
        groups = [np.array(g) for g in groups]
        scale = np.asarray(scale, float)
        Sc = S.tocoo()

        def jac(t, y):
            f0 = self(t, y)
            dy = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(y), scale)
            dy = (y + dy) - y
            vals = np.empty(Sc.nnz)
            col_group = np.empty(n, int)
            diffs = []
            for gi, g in enumerate(groups):
                yp = y.copy()
                yp[g] += dy[g]
                diffs.append(self(t, yp) - f0)
                col_group[g] = gi
            for idx, (r, c) in enumerate(zip(Sc.row, Sc.col)):
                vals[idx] = diffs[col_group[c]][r] / dy[c]
            J = csc_matrix((vals, (Sc.row, Sc.col)), shape=(n, n))
            return J.toarray() if dense else J

        return jac


def _vessel_y0(vessel_params: dict, y0) -> np.ndarray:
    """The vessel's full initial state as reference.py's solve builds it."""
    return full_initial(_vessel_only(vessel_params), y0)


def initial_pipe(vessel_params: dict, pipe: dict | None, y0_vessel, **kw) -> np.ndarray:
    """The static shape (N-1, 3) under the hang-off point of the vessel's state y0_vessel."""
    pipe = _pipe_table(vessel_params, pipe)
    y = np.asarray(y0_vessel, float)
    Q = y[6:15].reshape(3, 3, order="F")
    return static_shape(pipe, vessel_params, y[18:21] + Q @ np.array(pipe["hang_off"], float), **kw)


def default_atol(vessel_params, pipe, y, rtol):
    """Per group of states, rtol times the group's size: p, m, Q, mu, x, phi_th, phi_x, the
    filter, the subsystem, the nodes' positions (their size, at least the line's length) and
    velocities (at least 1 m/s, and at least the accelerations' round-off: below)."""
    pipe = _pipe_table(vessel_params, pipe)
    n = int(pipe["segments"]) - 1
    nv = len(y) - 6 * n
    h = vessel_params["vessel"]
    groups = [(0, 3, h["mass"] * 1.0), (3, 6, max(h["inertia"]) * 0.01), (6, 15, 1.0), (15, 18, 1.0),
              (18, 21, 1.0), (21, 24, 1.0), (24, 27, 1.0)]
    if nv > 27:
        groups.append((27, nv, 1.0))
    groups += [(nv, nv + 3 * n, float(pipe["length"])), (nv + 3 * n, nv + 6 * n, 1.0)]
    atol = np.empty(len(y))
    for a, b, floor in groups:
        atol[a:b] = rtol * max(np.abs(y[a:b]).max(), floor)
    # The nodes' accelerations carry a round-off of about eps (EA/l) |q| / m_n (the tension of a
    # difference of positions of size |q|); a velocity tolerance below it over ~1 s stalls
    # Radau's Newton iteration. So the velocities' atol is at least twice that (times 1 s).
    P = pipe_params(pipe, vessel_params)
    qmax = max(np.abs(y[nv:nv + 3 * n]).max(), np.abs(y[18:21]).max() + np.linalg.norm(P["r_h"]))
    floor_v = 2.0 * np.finfo(float).eps * P["EA"] / P["l"] * qmax / P["mn"] * 1.0
    # (This floor, ~1.4e-9 m/s at N = 10, sets Radau's step: 20 s at N = 10 costs about the same
    # at rtol 1e-9 and 1e-11. Loosening the velocities' atol to the positions' times the fastest
    # axial frequency saved 40 % of the evaluations but cost the vessel's momentum 1e-10 of
    # accuracy, against ~1e-12 with this floor.)
    atol[nv + 3 * n:] = np.maximum(atol[nv + 3 * n:], floor_v)
    return atol


def solve_coupled(vessel_params: dict, pipe: dict | None, y0_vessel, pipe_nodes0, t_end: float,
                  control_start: float | None = None, t_eval=None, rtol: float = 1e-11, atol=None,
                  hold_vessel: bool = False, return_solution_stats: bool = False):
    """The vessel and the line on [0, t_end] by scipy's Radau (the axial springs are stiff), with
    the finite-difference Jacobian on the sparsity pattern of ``CoupledField.sparsity``, split
    at the controller's switch like reference.py's solve.

    ``pipe`` is the [pipe] table (None: vessel_params["pipe"]); ``y0_vessel`` the vessel's state
    as reference.py's solve takes it; ``pipe_nodes0`` the free nodes' positions (N-1, 3) (at
    rest), or a pair (positions, velocities). ``atol``: None for ``default_atol``, a number or
    an array over the whole state. Returns (t, y, q, v): t the times of t_eval (default
    [t_end]), y the vessel's states there (as reference.py's solve), q and v the free nodes'
    positions and velocities there, shape (len(t), N-1, 3). With ``return_solution_stats``
    a fifth item: a list of scipy's results per segment (nfev, njev, nlu, ...)."""
    pipe = _pipe_table(vessel_params, pipe)
    yv = _vessel_y0(vessel_params, y0_vessel)
    if isinstance(pipe_nodes0, (tuple, list)) and len(pipe_nodes0) == 2:
        q0, v0 = (np.asarray(a, float) for a in pipe_nodes0)
    else:
        q0 = np.asarray(pipe_nodes0, float)
        v0 = np.zeros_like(q0)
    n = int(pipe["segments"]) - 1
    assert q0.shape == (n, 3) and v0.shape == (n, 3), (q0.shape, n)
    y = np.concatenate([yv, q0.ravel(), v0.ravel()])
    nv = len(yv)
    if atol is None:
        atol = default_atol(vessel_params, pipe, y, rtol)
    segments = control_segments(control_start, t_end)
    t_eval = np.asarray(t_eval, float) if t_eval is not None else np.array([t_end])
    ts, ys, stats = [], [], []
    for a, b, on in segments:
        f = CoupledField(vessel_params, pipe, on, nv, hold_vessel=hold_vessel)
        last = b == t_end
        sel = t_eval[(t_eval >= a) & ((t_eval < b) | (last & (t_eval <= b)))]
        sol = solve_ivp(f, (a, b), y, method="Radau", rtol=rtol, atol=atol, jac=f.jacobian(atol / rtol),
                        t_eval=np.unique(np.concatenate([sel, [b]])))
        assert sol.success, sol.message
        keep = np.isin(sol.t, sel)
        ts.append(sol.t[keep])
        ys.append(sol.y.T[keep])
        stats.append(sol)
        y = sol.y[:, -1]
    t, Y = np.concatenate(ts), np.concatenate(ys)
    out = (t, Y[:, :nv], Y[:, nv:nv + 3 * n].reshape(-1, n, 3), Y[:, nv + 3 * n:].reshape(-1, n, 3))
    return out + (stats,) if return_solution_stats else out
