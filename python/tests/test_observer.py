"""The nonlinear passive observer with wave filtering and the controller on its estimates,
``control.feedback = "observer"`` (Fossen & Strand, Automatica 35 (1999) 3-16; Fossen 2021 §13.5;
docs/explanation/components/observer.md).

References: the observer and the controller on its estimates written again here from the
equations of the docs, on top of reference.py's vessel (its own PID off), solved by DOP853 at
rtol 1e-12; the observer's gains from their published formulas, computed here; the ledger's own
balance; and the observer's theory: on a calm sea under a constant load, from a wrong initial
estimate, the estimates converge on the position, the heading and the load (the bias), and the
controller holds the set point."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import phsplit
import reference as ref
from checks import within_passivity_bound

W0 = 0.7                                        # rad/s, the wave model's frequency
DAMPING = [3.53933789e4, 1.1781388e5, 3.15094664584e8]  # the paper's surge, sway, yaw damping
WRONG = [790.0, 28.0, 0.6]                      # m, m, rad: the initial estimate
BIAS0 = [2e4, -1e4, 5e5]                        # N, N, N m: the initial bias estimate


def observer_vessel(extra=None, external=None):
    d = phsplit.Vessel.paper().to_dict()
    d["control"]["feedback"] = "observer"
    d["observer"] = {"wave_frequency": W0, "damping": DAMPING, "initial_estimate": WRONG,
                     "initial_bias": BIAS0, **(extra or {})}
    if external is not None:
        d["external"] = external
    return phsplit.Vessel.from_dict(d), d


def rot(psi):
    c, s = math.cos(psi), math.sin(psi)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


class ObserverField:
    """The vessel (reference.py, its PID off) with the observer and the PID on its estimates:
    18 states after the vessel's 27, (xi1, xi2, eta_hat, b_hat, nu_hat, q) in surge, sway, yaw."""

    def __init__(self, d):
        params = {k: (dict(v) if isinstance(v, dict) else v) for k, v in d.items()}
        c = params["control"]
        self.gains = {k: np.array(c[k][:2] + [0.0], float) for k in ("kp_translational", "kd_translational", "ki_translational")}
        for k in ("kp", "kd", "ki"):
            self.gains[k] = np.array([c[f"{k}_translational"][0], c[f"{k}_translational"][1], c[f"{k}_rotational"][2]])
        self.ref = np.array([c["position_reference"][0], c["position_reference"][1], c["euler_reference"][2]])
        params["control"] = {**c, **{k: [0.0] * 3 for k in c if k.startswith(("kp_", "kd_", "ki_"))}}
        self.hull = ref.Field(params, False)
        o = d["observer"]
        lam, zeta, T = 0.1, 1.0, 1000.0
        wc = 1.1 / 0.8976 * W0
        wb = W0 / 5.0
        v = d["vessel"]
        M = np.array([v["mass"], v["mass"], v["inertia"][2]])
        D = np.array(o["damping"])
        self.k1a, self.k1b, self.k2 = -2 * (zeta - lam) * wc / W0, 2 * W0 * (zeta - lam), wc
        self.k3 = wc * M * wb ** 2
        self.k4 = wc * (2 * M * wb - D)
        # the same in x and y: the mean of the surge and sway placements (the docs)
        self.k3[:2] = self.k3[:2].mean()
        self.k4[:2] = self.k4[:2].mean()
        self.lam, self.T, self.M, self.D = lam, T, M, D

    def __call__(self, t, y):
        dy = np.zeros_like(y)
        n = 27
        dy[:n] = self.hull(t, y[:n])
        Q = y[6:15].reshape(3, 3, order="F")
        psi = ref.euler_zyx(Q)[2]
        psi = self.ref[2] + (psi - self.ref[2] + math.pi) % (2 * math.pi) - math.pi
        meas = np.array([y[18], y[19], psi])
        xi1, xi2, eta, b, nu, q = (y[n + 3 * i:n + 3 * i + 3] for i in range(6))
        R = rot(psi)
        yt = meas - eta - xi2
        e = eta - self.ref
        g = self.gains
        tau = -R.T @ (g["kp"] * e + g["ki"] * q) - R.T @ (g["kd"] * (R @ nu))
        dy[n:n + 3] = xi2 + self.k1a * yt
        dy[n + 3:n + 6] = -W0 ** 2 * xi1 - 2 * self.lam * W0 * xi2 + self.k1b * yt
        dy[n + 6:n + 9] = R @ nu + self.k2 * yt
        dy[n + 9:n + 12] = -b / self.T + self.k3 * yt
        dy[n + 12:n + 15] = (-self.D * nu + R.T @ b + tau + R.T @ (self.k4 * yt)) / self.M
        dy[n + 15:n + 18] = e
        # the controller's force on the hull (body frame): surge, sway and the yaw moment
        dy[0] += tau[0]
        dy[1] += tau[1]
        dy[5] += tau[2]
        return dy


def observer_initial(v):
    x = np.zeros(18)
    x[6:9] = WRONG
    x[9:12] = BIAS0
    return np.concatenate([np.asarray(v.initial_state(), float)[:27], x])


def test_orders_two_and_four_against_an_independent_model():
    """SP2 and SP4 (exact flow S2, no projection) on the vessel with the observer and the
    controller on its estimates, from a wrong estimate, against DOP853 on the model written
    here: the fitted slopes of the final momentum's and estimates' error are 2 and 4."""
    v, d = observer_vessel()
    y0 = observer_initial(v)
    t_end = 20.0
    f = ObserverField(d)
    sol = solve_ivp(f, (0.0, t_end), y0, method="DOP853", rtol=1e-12, atol=np.maximum(np.abs(y0), 1.0) * 1e-15)
    assert sol.success
    want = sol.y[:, -1]
    for method, hs, order in (("sp2", [0.4, 0.2, 0.1, 0.05], 2.0), ("sp4", [0.8, 0.4, 0.2, 0.1], 4.0)):
        errs = []
        for h in hs:
            s = phsplit.simulate(v, (0.0, t_end), h, method, control_start=0.0, ledger=False,
                                 project_invariants=False, linear_flow="exact")
            got_p = s.p[-1]
            got_eta = s.own[-1][6:9]
            errs.append(np.linalg.norm(got_p - want[0:3]) / np.linalg.norm(want[0:3])
                        + np.linalg.norm(got_eta - want[33:36]) / np.linalg.norm(want[33:36]))
        slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
        assert abs(slope - order) < 0.25, (method, slope, errs)
        assert errs[-1] < (1e-5 if order == 2 else 1e-7), (method, errs)


def test_the_estimates_converge_on_a_calm_sea():
    """A constant spatial load (as a steady wind and current would be) and a wrong initial
    estimate (10 m, 8 m, 0.5 rad off, a wrong bias): the estimates converge, exponentially
    (Fossen & Strand 1999, Theorem 1: the error dynamics are globally exponentially stable), on
    the observer's equilibrium, which its bias model with a finite time constant T offsets from
    the truth: with the load F balanced, ``b = T K3 y~``, ``nu^ = -K2 R^T y~`` and
    ``b + (K4 + K2 R D R^T) y~ = F``; the wave state ``xi2 = -K1a y~`` and the estimate
    ``eta^ - eta = -(1 - K1a) y~`` (its docs); the vessel holds the set point under the load."""
    load = [6e4, -3e4, 0.0]
    moment = [0.0, 0.0, 2e6]
    v, d = observer_vessel(external={"force": load, "moment": moment, "frame": "spatial"})
    f = ObserverField(d)
    F = np.array([load[0], load[1], moment[2]])
    R = rot(f.ref[2])
    yt = np.linalg.solve(np.diag(f.T * f.k3 + f.k4) + f.k2 * R @ np.diag(f.D) @ R.T, F)
    s = phsplit.simulate(v, (0.0, 1500.0), 0.5, "sp4", control_start=0.0, save_every=10)
    err = s.outputs["observer_position_error"][2]
    herr = s.outputs["observer_heading_error"][2]
    assert err[0] > 5.0 and abs(herr[0]) > 0.4
    late = s.t >= 1200.0
    np.testing.assert_allclose(err[late], (1 - f.k1a) * np.hypot(yt[0], yt[1]), rtol=0.02)
    np.testing.assert_allclose(herr[late], -(1 - f.k1a) * yt[2], rtol=0.02)
    np.testing.assert_allclose(s.own[-1][9:12], f.T * f.k3 * yt, rtol=1e-3)
    # the controller (its integral's time kp/ki = 400 s) holds the vessel within 1 cm
    off = np.hypot(s.x[-1, 0] - 780.0, s.x[-1, 1] - 20.0)
    assert off < 0.01
    # exponential: the distance from the equilibrium over successive 150 s windows falls by a
    # steady factor
    gap = np.abs(err - err[-1])
    env = [np.max(gap[(s.t >= a) & (s.t < a + 150.0)]) for a in (150.0, 300.0, 450.0, 600.0)]
    assert all(b < 0.5 * a for a, b in zip(env, env[1:])), env


def test_the_ledger_closes_with_the_controller_on_estimates():
    """The observer stores nothing of H; the controller's force on the hull is the port
    ``control``: the balance closes to round-off and the discrete passivity bound holds."""
    v, _ = observer_vessel(external={"force": [6e4, -3e4, 0.0], "frame": "spatial"})
    s = phsplit.simulate(v, (0.0, 300.0), 0.5, "sp4", control_start=0.0, save_every=4)
    assert set(s.ledger.by_account) == {"damping", "control", "external"}
    assert s.ledger.kinds["control"] == "supplied"
    assert np.max(s.ledger.relative_residual()) < 1e-10
    assert within_passivity_bound(s)
    # the controller's reported force is the one the ledger books: its work is F . v summed
    booked = np.sum(s.ledger.by_account["control"])
    assert abs(booked) > 1e3


def test_the_controller_is_off_before_control_start_while_the_observer_runs():
    v, _ = observer_vessel()
    s = phsplit.simulate(v, (0.0, 100.0), 0.5, "sp2", control_start=60.0, save_every=2)
    before = s.t < 59.0
    assert np.all(s.control_force[before] == 0.0)
    assert np.all(s.own[before][:, 15:18] == 0.0)        # the integral waits for the controller
    assert s.outputs["observer_position_error"][2][np.argmax(s.t >= 50.0)] < 0.5 * 12.8
    assert np.any(s.control_force[s.t > 61.0] != 0.0)


@pytest.mark.parametrize("change, needle", [
    ({"notch_damping": 0.05}, "notch_damping"),
    ({"cutoff_frequency": 0.5}, "cutoff_frequency"),
    ({"velocity_gain": [1e5, 1e5, 1e8], "bias_gain": [1e5, 1e5, 1e8]}, "bias_gain[0] / velocity_gain[0]"),
    ({"bias_bandwidth": 0.01}, "bias_bandwidth"),
    ({"wave_frequency": -1.0}, "observer.wave_frequency"),
])
def test_bad_observer_tables_are_refused_by_name(change, needle):
    d = phsplit.Vessel.paper().to_dict()
    d["control"]["feedback"] = "observer"
    d["observer"] = {"wave_frequency": W0, "damping": DAMPING, **change}
    with pytest.raises(phsplit.InvalidInputError, match=needle.replace("[", r"\[").replace("]", r"\]")):
        phsplit.Vessel.from_dict(d)
