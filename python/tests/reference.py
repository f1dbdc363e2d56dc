"""An independent reference for the vessel, for the tests: eq. (39) of the paper written again in
numpy, from docs/model.md §2 (and the loads of §5), integrated by scipy's DOP853 at
tight tolerance. A linear port-Hamiltonian subsystem with states of its own (the vessel file's
[port_hamiltonian] table) is written from van der Schaft & Jeltsema, Port-Hamiltonian Systems
Theory (2014), §4.1: the input-state-output system with feedthrough.

Nothing here calls phsplit's integrators or its Rust vector field; only the initial state and
the parameters are shared. The tests use it to check the splitting methods against a
computation that shares no code with them."""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq


def hat(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def euler_zyx(Q):
    return np.array([np.arctan2(Q[2, 1], Q[2, 2]),
                     np.arctan2(-Q[2, 0], np.hypot(Q[0, 0], Q[1, 0])),
                     np.arctan2(Q[1, 0], Q[0, 0])])


def pi_e(th):
    _, t, p = th
    return np.array([[np.cos(t) * np.cos(p), -np.sin(p), 0.0],
                     [np.cos(t) * np.sin(p), np.cos(p), 0.0],
                     [-np.sin(t), 0.0, 1.0]])


class Field:
    """y' of eq. (39) with the PID control (29)–(33); y = (p, m, Q col-major, mu, x, phi_th, phi_x),
    then the set point's filter (18, with a [setpoint]), then a port-Hamiltonian subsystem's
    states (n, with a [port_hamiltonian])."""

    def __init__(self, params: dict, control_on: bool):
        h, c = params["vessel"], params["control"]
        self.mv = h["mass"]
        self.T = np.array(h["inertia"])
        # the general vessel's added mass (docs §5.14) about the centre of gravity at the body
        # origin: the momenta (p, m) = M nu with M = diag(m, m, m, I) + A, and Kirchhoff's
        # equations p' = p x w + F, m' = m x w + p x v + T (Lamb, Hydrodynamics, §126)
        self.Minv = None
        if "added_mass" in h:
            if np.any(np.array(h.get("center_of_gravity", [0.0] * 3), float) != 0.0):
                raise NotImplementedError("the reference takes added mass only with the centre of gravity at the origin")
            M = np.diag(np.concatenate([[self.mv] * 3, self.T])) + np.array(h["added_mass"], float)
            self.Minv = np.linalg.inv(M)
        if "damping_matrix" in h:  # a full 6x6 linear damping on (v - v_c, w)
            self.D = np.array(h["damping_matrix"], float)
        else:
            self.D = np.diag(np.concatenate([h["damping_translational"], h["damping_rotational"]]))
        self.Dt = np.diag(self.D)[:3]
        self.lam = np.array([0.0, 0.0, h["gravity"] * h["water_density"] * h["waterplane_area"]])
        w = self.mv * h["gravity"]
        self.G = np.array([w * h["gm_longitudinal"], w * h["gm_transverse"], 0.0])
        self.Gp = np.where(self.G > 0, 1.0 / np.where(self.G > 0, self.G, 1.0), 0.0)
        k = 1.0 if control_on else 0.0
        self.K = {n: k * np.diag(c[n]) for n in ("kp_translational", "kd_translational", "ki_translational",
                                                    "kp_rotational", "kd_rotational", "ki_rotational")}
        self.xr = np.array(c["position_reference"])
        self.thr = np.array(c["euler_reference"])
        self.on = control_on
        # back-calculation anti-windup (Astrom & Hagglund, Advanced PID Control, 2006, 3.5): the
        # integral term I = Ki phi follows I' = Ki e + (v - u)/Tt, with the command u and the
        # delivered v in the controller's coordinates (Y in tau = -Q^T Y, -W^T Y) and
        # Tt = sqrt(Ti Td) = sqrt(kd/ki) per axis (Ti = kp/ki where kd = 0), or control.tracking_time
        self.aw = None
        if c.get("anti_windup", "none") == "back_calculation":
            def tt(kp, kd, ki):
                kp, kd, ki = (np.asarray(c[n], float) for n in (kp, kd, ki))
                t = c.get("tracking_time")
                k1 = np.where(ki > 0, ki, 1.0)
                rule = np.where(kd > 0, np.sqrt(kd / k1), kp / k1)
                tr = np.full(3, float(t)) if t is not None else rule
                return np.where(ki > 0, 1.0 / (k1 * np.where(tr > 0, tr, 1.0)), 0.0)
            self.aw = (tt("kp_translational", "kd_translational", "ki_translational"),
                       tt("kp_rotational", "kd_rotational", "ki_rotational"))
        ext = params.get("external")
        self.ext = None
        if ext:
            self.ext = (np.array(ext.get("force", [0.0] * 3), float), np.array(ext.get("moment", [0.0] * 3), float),
                        np.array(ext.get("point", [0.0] * 3), float), ext.get("frame", "body"))
        wd = params.get("wind")
        self.wind = dict(wd) if wd else None
        wv = params.get("waves")
        self.waves = dict(wv) if wv else None
        self.g = h["gravity"]
        thr = params.get("thrusters")
        self.thr_units = list(thr["unit"]) if thr else None
        pipe = params.get("pipe")
        self.pipe = dict(pipe) if pipe else None
        spr = params.get("spring")
        # a linear spring from the fairlead r (body) to the anchor a (spatial): F = -k (x + Q r - a)
        self.spring = (np.array(spr["fairlead"], float), np.array(spr["anchor"], float), float(spr["stiffness"])) \
            if spr else None
        sp = params.get("setpoint")
        # the moving set point: the third-order filter's states are integrated with the vessel
        # (y[27:45]: x_d, x_d', x_d'' for the six channels), driven by the set point r(t)
        self.sp = dict(sp) if sp else None
        cf = params.get("crossflow_drag")
        # cross-flow drag by strip theory, integrated numerically here (the core integrates exactly)
        self.cf = None
        if cf:
            self.cf = (0.5 * h["water_density"] * cf["draft"] * cf["drag_coefficient"], cf["x_aft"], cf["x_fore"])
        dq = params.get("damping_quadratic")
        # Fossen's diagonal quadratic damping, c_i |nu_i| nu_i, on the velocity relative to the water
        self.cq = np.array(dq["coefficients"], float) if dq else np.zeros(6)
        cur = params.get("current")
        # a uniform current V_c (spatial): the translational damping acts on v - Q^T V_c
        self.vc = np.array(cur.get("velocity", [0.0] * 3), float) if cur else np.zeros(3)
        # a slowly varying current: linear between the rows of its time table, constant outside
        self.vc_table = (np.array(cur["times"], float), np.array(cur["velocities"], float)) \
            if cur and "times" in cur else None
        ph = params.get("port_hamiltonian")
        # a linear port-Hamiltonian subsystem (van der Schaft & Jeltsema 2014, §4.1), its n states
        # after the set point's filter: x' = (J - R) Qc x + (G - P) u, y = (G + P)^T Qc x + (N + S) u,
        # its input u = B nu the hull's velocities at its point (v + w x r) and about its axes, and
        # its load on the hull tau = -B^T y (the force at the point, its moment r x f)
        self.ph = None
        if ph:
            n = len(ph["states"])
            k = len(ph["input"])
            mat = lambda key, shape: np.array(ph[key], float).reshape(shape) if key in ph else np.zeros(shape)  # noqa: E731
            r = np.array(ph.get("point", [0.0] * 3), float)
            B = np.zeros((k, 6))
            for i, dof in enumerate(ph["input"]):
                j = ("surge", "sway", "heave", "roll", "pitch", "yaw").index(dof)
                if j < 3:
                    B[i, :3], B[i, 3:] = np.eye(3)[j], -hat(r)[j]
                else:
                    B[i, j] = 1.0
            self.ph = {"J": mat("J", (n, n)), "R": mat("R", (n, n)), "Q": mat("Q", (n, n)), "G": mat("G", (n, k)),
                       "P": mat("P", (n, k)), "S": mat("S", (k, k)), "N": mat("N", (k, k)), "B": B,
                       "at": 45 if sp else 27, "n": n}

    def external(self, Q):
        """Body-frame force and moment (about the body origin) of the constant external load."""
        if self.ext is None:
            return np.zeros(3), np.zeros(3)
        f, m, r, frame = self.ext
        if frame == "spatial":
            f, m = Q.T @ f, Q.T @ m
        return f, m + np.cross(r, f)

    def pipe_force(self, t, x, Q):
        """The catenary's spatial force at the hang-off point (docs/model.md 5.6), written again:
        the span to the touchdown point gives a = H/w by root finding on X = a acosh(1 + d/a)."""
        pp = self.pipe
        w, r = pp["submerged_weight"], np.array(pp["hang_off"], float)
        top = x + Q @ r
        d = pp["water_depth"] + top[2]
        ang = np.radians(pp.get("lay_direction", 0.0))
        e_lay = np.array([np.cos(ang), np.sin(ang)])
        if "touchdown" in pp:
            tdp = np.array(pp["touchdown"], float) + e_lay * pp.get("lay_speed", 0.0) * max(t, 0.0)
            rh = top[:2] - tdp
            X = np.hypot(*rh)
            e = rh / X
            a = np.exp(brentq(lambda la: np.exp(la) * np.arccosh(1 + d / np.exp(la)) - X, -30.0, 40.0,
                              xtol=1e-15, rtol=1e-15))
        else:
            e = e_lay
            a = pp["horizontal_tension"] / w
        s = np.sqrt(d * d + 2 * a * d)
        H = w * a
        return np.array([-H * e[0], -H * e[1], -w * s])

    def wave_loads(self, t, x, Q):
        """First-order force (6) and drift (surge, sway, yaw) of docs/model.md 5.9, written again:
        frequency interpolation by np.interp per direction, then periodic np.interp in direction."""
        wv = self.waves
        psi = euler_zyx(Q)[2]
        om, a = np.array(wv["frequencies"], float), np.array(wv["amplitudes"], float)
        ph, di = np.array(wv["phases"], float), np.radians(np.array(wv["directions"], float))
        kappa = om ** 2 / self.g
        # the phase point: the vessel, or the fixed reference (the controller's set point)
        px = x if wv.get("phase_at", "reference") == "vessel" else self.xr
        theta = om * t - kappa * (px[0] * np.cos(di) + px[1] * np.sin(di)) + ph
        rf, rd = np.array(wv["rao_frequencies"], float), np.radians(np.array(wv["rao_directions"], float))
        tabs = [np.array(wv["force_rao_real"], float), np.array(wv["force_rao_imag"], float)]
        drift = np.array(wv["drift_coefficients"], float) if "drift_coefficients" in wv else None

        def interp(tab, w, beta):
            along = np.array([[np.interp(w, rf, tab[i, :, n]) for n in range(tab.shape[2])]
                              for i in range(tab.shape[0])])
            if len(rd) == 1:
                return along[0]
            return np.array([np.interp(beta, rd, along[:, n], period=2 * np.pi) for n in range(tab.shape[2])])

        first, s, mean = np.zeros(6), np.zeros(3), np.zeros(3)
        for k in range(len(om)):
            beta = di[k] - psi
            re, im = interp(tabs[0], om[k], beta), interp(tabs[1], om[k], beta)
            first += a[k] * (re * np.cos(theta[k]) - im * np.sin(theta[k]))
            if drift is not None:
                d = interp(drift, om[k], beta)
                s += a[k] * np.sqrt(np.abs(d)) * np.cos(theta[k])
                mean += a[k] ** 2 * d
        return first, 2.0 * np.sign(mean) * s ** 2

    def wind_loads(self, t, v, Q):
        """Body-frame wind force and moment (docs/model.md 5.10), written again."""
        wd = self.wind
        u = wd["speed"] + sum(a * np.cos(w * t + p) for w, a, p in
                              zip(wd.get("gust_frequencies", []), wd.get("gust_amplitudes", []), wd.get("gust_phases", [])))
        d = np.radians(wd["direction"])
        rel = Q.T @ (u * np.array([np.cos(d), np.sin(d), 0.0])) - v
        gamma = np.arctan2(rel[1], rel[0])
        ang = np.radians(np.array(wd["angles"], float))
        c = [np.interp(gamma, ang, np.array(wd[k], float), period=2 * np.pi) for k in ("cx", "cy", "cn")]
        q = 0.5 * wd["air_density"] * (rel[0] ** 2 + rel[1] ** 2)
        return (np.array([q * wd["frontal_area"] * c[0], q * wd["lateral_area"] * c[1], 0.0]),
                np.array([0.0, 0.0, q * wd["lateral_area"] * wd["length"] * c[2]]))

    def thrust(self, tau_t, tau_r):
        """The thrusters' delivered force and moment (body) for the demand (X, Y, N): weighted
        least-norm allocation B f = tau in the extended thrust formulation, scaled into the
        limits (docs/model.md 5.8), written again with numpy."""
        cols, owner, w = [], [], []
        for i, u in enumerate(self.thr_units):
            lx, ly = u["position"][0], u["position"][1]
            if u["kind"] == "azimuth":
                dirs = [(1.0, 0.0), (0.0, 1.0)]
            else:
                a = np.radians(u.get("angle", 90.0 if u["kind"] == "tunnel" else 0.0))
                dirs = [(np.cos(a), np.sin(a))]
            for c, s_ in dirs:
                cols.append([c, s_, lx * s_ - ly * c])
                owner.append((i, c, s_))
                w.append(u.get("weight", 1.0))
        B, Wi = np.array(cols).T, np.diag(1.0 / np.array(w))
        tau = np.array([tau_t[0], tau_t[1], tau_r[2]])
        f = Wi @ B.T @ np.linalg.solve(B @ Wi @ B.T, tau)
        F = np.zeros((len(self.thr_units), 2))
        for fj, (i, c, s_) in zip(f, owner):
            F[i] += fj * np.array([c, s_])
        scale = 1.0
        for i, u in enumerate(self.thr_units):
            if u["kind"] == "azimuth":
                mag = np.hypot(*F[i])
                if mag > u["max_thrust"]:
                    scale = min(scale, u["max_thrust"] / mag)
            else:
                a = np.radians(u.get("angle", 90.0 if u["kind"] == "tunnel" else 0.0))
                along = F[i] @ np.array([np.cos(a), np.sin(a)])
                lo = u.get("min_thrust", -u["max_thrust"])
                if along > u["max_thrust"]:
                    scale = min(scale, u["max_thrust"] / along)
                elif along < lo:
                    scale = min(scale, lo / along)
        force, moment = np.zeros(3), np.zeros(3)
        for i, u in enumerate(self.thr_units):
            fi = np.array([F[i, 0], F[i, 1], 0.0]) * scale
            force += fi
            moment += np.cross(np.array(u["position"], float), fi)
        return force, moment

    def r_of(self, t):
        """The set point (6 channels) and its slope at t: waypoints passed at the given speed."""
        sp = self.sp
        pos = np.array(sp["positions"], float)
        t0 = sp.get("start_time", 0.0)
        seg = np.hypot.reduce(np.diff(pos, axis=0), axis=1) if len(pos) > 1 else np.zeros(0)
        times = t0 + np.concatenate([[0.0], np.cumsum(seg / sp["speed"])])
        yaw = np.array(sp.get("headings", [self.thr[2]] * len(pos)), float)
        rows = np.column_stack([pos, np.tile(self.thr[:2], (len(pos), 1)), yaw])
        k = max(0, min(np.searchsorted(times, t, side="right") - 1, len(times) - 1))
        if k + 1 < len(times):
            slope = (rows[k + 1] - rows[k]) / (times[k + 1] - times[k])
        else:
            slope = np.zeros(6)
        return rows[k] + slope * max(t - times[k], 0.0), slope

    def velocities(self, y):
        """The body velocities (v, w) of the momenta y[0:6]."""
        if self.Minv is None:
            return y[0:3] / self.mv, y[3:6] / self.T
        nu = self.Minv @ y[0:6]
        return nu[:3], nu[3:]

    def ph_port(self, y):
        """The subsystem's (x, Qc x, u, y) at state y: its states, co-energy variables, input and output."""
        c = self.ph
        xc = y[c["at"]:c["at"] + c["n"]]
        e = c["Q"] @ xc
        u = c["B"] @ np.concatenate(self.velocities(y))
        return xc, e, u, (c["G"] + c["P"]).T @ e + (c["N"] + c["S"]) @ u

    def ph_dissipation(self, y):
        """The subsystem's dissipation rate [Qc x; u]^T [[R, P], [P^T, S]] [Qc x; u], W."""
        c = self.ph
        _, e, u, _ = self.ph_port(y)
        return e @ c["R"] @ e + 2.0 * e @ c["P"] @ u + u @ c["S"] @ u

    def __call__(self, t, y):
        p, m, Q = y[0:3], y[3:6], y[6:15].reshape(3, 3, order="F")
        mu, x, phth, phx = y[15:18], y[18:21], y[21:24], y[24:27]
        v, w = self.velocities(y)
        q3 = Q.T @ np.array([0.0, 0.0, 1.0])
        th = euler_zyx(Q)
        W = np.linalg.solve(pi_e(th), Q)
        K = self.K
        xr, thr, vd, thd = self.xr, self.thr, np.zeros(3), np.zeros(3)
        n = 27
        if self.sp is not None:
            om, ze = self.sp["natural_frequency"], self.sp.get("relative_damping", 1.0)
            f = y[27:45].reshape(3, 6)  # rows: value, rate, acceleration
            xr, thr, vd, thd = f[0, :3], f[0, 3:], f[1, :3], f[1, 3:]
            r, _ = self.r_of(t)
            jerk = om ** 3 * (r - f[0]) - (2 * ze + 1) * om ** 2 * f[1] - (2 * ze + 1) * om * f[2]
            n = 45
        if self.ph is not None:
            c = self.ph
            xc, e, u, yc = self.ph_port(y)
            n = c["at"] + c["n"]
        tau_t = -Q.T @ (K["kp_translational"] @ (x - xr) + K["kd_translational"] @ (Q @ v - vd)
                        + K["ki_translational"] @ phx)
        tau_r = -W.T @ (K["kp_rotational"] @ (th - thr) + K["kd_rotational"] @ (W @ w - thd)
                        + K["ki_rotational"] @ phth)
        aw_t, aw_r = np.zeros(3), np.zeros(3)
        if self.thr_units is not None and self.on:
            dem_t, dem_r = tau_t, tau_r
            tau_t, tau_r = self.thrust(tau_t, tau_r)
            if self.aw is not None:
                # the deficits of what is delivered in surge, sway and yaw, as commands Y
                y_t = -Q @ np.array([tau_t[0] - dem_t[0], tau_t[1] - dem_t[1], 0.0])
                y_r = -np.linalg.solve(W.T, np.array([0.0, 0.0, tau_r[2] - dem_r[2]]))
                aw_t, aw_r = self.aw[0] * y_t, self.aw[1] * y_r
        fe, me = self.external(Q)
        if self.wind is not None:
            fw, mw = self.wind_loads(t, v, Q)
            fe, me = fe + fw, me + mw
        if self.waves is not None:
            first, dr = self.wave_loads(t, x, Q)
            psi = euler_zyx(Q)[2]
            rz = np.array([[np.cos(psi), -np.sin(psi), 0.0], [np.sin(psi), np.cos(psi), 0.0], [0.0, 0.0, 1.0]])
            tb = Q.T @ rz  # seakeeping frame (heading-aligned, z up) to body
            fe = fe + tb @ (first[:3] + np.array([dr[0], dr[1], 0.0]))
            me = me + tb @ (first[3:] + np.array([0.0, 0.0, dr[2]]))
        if self.pipe is not None:
            fp = Q.T @ self.pipe_force(t, x, Q)
            fe, me = fe + fp, me + np.cross(np.array(self.pipe["hang_off"], float), fp)
        if self.spring is not None:
            r, a, k = self.spring
            fs = Q.T @ (-k * (x + Q @ r - a))
            fe, me = fe + fs, me + np.cross(r, fs)
        if self.ph is not None:
            tau = -c["B"].T @ yc
            fe, me = fe + tau[:3], me + tau[3:]
        dy = np.empty(n)
        if self.sp is not None:
            dy[27:45] = np.concatenate([f[1], f[2], jerk])
        if self.ph is not None:
            dy[c["at"]:n] = (c["J"] - c["R"]) @ e + (c["G"] - c["P"]) @ u
        vc = self.vc if self.vc_table is None else np.array(
            [np.interp(t, self.vc_table[0], self.vc_table[1][:, i]) for i in range(3)])
        vr = v - Q.T @ vc
        if self.cf is not None:
            from scipy.integrate import quad

            k, xa, xf = self.cf
            s = lambda xx: abs(vr[1] + xx * w[2]) * (vr[1] + xx * w[2])  # noqa: E731
            knot = [-vr[1] / w[2]] if w[2] != 0 and xa < -vr[1] / w[2] < xf else None
            fy = -k * quad(s, xa, xf, points=knot, epsabs=1e-12, epsrel=1e-13, limit=200)[0]
            mz = -k * quad(lambda xx: xx * s(xx), xa, xf, points=knot, epsabs=1e-12, epsrel=1e-13, limit=200)[0]
            fe = fe + np.array([0.0, fy, 0.0])
            me = me + np.array([0.0, 0.0, mz])
        fd = self.D @ np.concatenate([vr, w])
        dy[0:3] = -np.cross(w, p) - (fd[:3] + self.cq[:3] * np.abs(vr) * vr + Q.T @ (self.lam * x) - tau_t) + fe
        dy[3:6] = -np.cross(w, m) - (np.cross(v, p) if self.Minv is not None else 0.0) - (fd[3:] + self.cq[3:] * np.abs(w) * w + np.cross(mu, q3) - tau_r) + me
        dy[6:15] = (Q @ hat(w)).reshape(-1, order="F")
        dy[15:18] = -self.G * np.cross(w, q3)
        dy[18:21] = Q @ v
        dy[21:24] = (th - thr + aw_r) if self.on else 0.0
        dy[24:27] = (x - xr + aw_t) if self.on else 0.0
        return dy

    def control_torque(self, y):
        """The rotational control input tau_r (body frame, N m) at state y (zero when off)."""
        Q, phth = y[6:15].reshape(3, 3, order="F"), y[21:24]
        w = self.velocities(y)[1]
        th = euler_zyx(Q)
        W = np.linalg.solve(pi_e(th), Q)
        K = self.K
        return -W.T @ (K["kp_rotational"] @ (th - self.thr) + K["kd_rotational"] @ W @ w
                       + K["ki_rotational"] @ phth)

    def energy(self, y):
        p, m, mu, x = y[0:3], y[3:6], y[15:18], y[18:21]
        v, w = self.velocities(y)
        h = 0.5 * m @ w + 0.5 * p @ v + 0.5 * mu @ (self.Gp * mu) + 0.5 * self.lam[2] * x[2] ** 2
        if self.ph is not None:  # the subsystem's storage, 1/2 x^T Qc x
            xc, e, _, _ = self.ph_port(y)
            h += 0.5 * xc @ e
        return h


def full_initial(params: dict, y0) -> np.ndarray:
    """The whole initial state of ``y0`` (the 27 numbers, or the 27 then the subsystem's states):
    then the set point's filter at rest on the first set point, the subsystem at its ``initial``."""
    y = np.array(y0, dtype=float)
    ph = params.get("port_hamiltonian")
    nc = len(ph["states"]) if ph else 0
    own = np.array(ph.get("initial", [0.0] * nc), float) if nc else None
    if nc and len(y) == 27 + nc:
        y, own = y[:27], y[27:]
    if "setpoint" in params and len(y) == 27:
        # the filter starts at rest on the first set point
        r0, _ = Field(params, True).r_of(params["setpoint"].get("start_time", 0.0))
        y = np.concatenate([y, r0, np.zeros(12)])
    if nc and len(y) in (27, 45):
        y = np.concatenate([y, own])
    return y


def control_segments(control_start, t_end: float) -> list[tuple[float, float, bool]]:
    """The pieces of [0, t_end] with the controller off and on, (start, end, on): the reference
    is integrated piecewise, so that the switch is a node and not a kink inside a step."""
    segments = []
    cs = control_start if control_start is not None else np.inf
    if cs > 0:
        segments.append((0.0, min(cs, t_end), False))
    if cs < t_end:
        segments.append((max(cs, 0.0), t_end, True))
    return segments


def solve(params: dict, y0: np.ndarray, t_end: float, control_start: float | None, t_eval=None,
          rtol: float = 1e-13) -> tuple[np.ndarray, np.ndarray]:
    """Reference solution on [0, t_end]: DOP853 with rtol 1e-13, split at the controller switch.
    Returns (t, y) with y of shape (len(t), 27), then the set point's filter (18) and the
    port-Hamiltonian subsystem's states (n) where the vessel has them. ``y0`` is the 27 numbers,
    or the 27 then the subsystem's states (phsplit's layout of a state that continues a run); the
    filter starts at rest on the first set point, the subsystem at its ``initial``."""
    segments = control_segments(control_start, t_end)
    t_eval = np.asarray(t_eval) if t_eval is not None else np.array([t_end])
    ts, ys = [], []
    y = full_initial(params, y0)
    atol = np.maximum(np.abs(y), 1.0) * rtol * 1e-3
    for a, b, on in segments:
        f = Field(params, on)
        last = b == t_end
        sel = t_eval[(t_eval >= a) & ((t_eval < b) | (last & (t_eval <= b)))]
        sol = solve_ivp(f, (a, b), y, method="DOP853", rtol=rtol, atol=atol,
                        t_eval=np.unique(np.concatenate([sel, [b]])), dense_output=False)
        assert sol.success, sol.message
        keep = np.isin(sol.t, sel)
        ts.append(sol.t[keep])
        ys.append(sol.y.T[keep])
        y = sol.y[:, -1]
    return np.concatenate(ts), np.concatenate(ys)
