"""The controller on the observer's estimates through thrusters: ``control.feedback =
"observer"`` with ``[thrusters]`` (docs/explanation/components/observer.md, "With thrusters").

The demand from the estimates is allocated to the thrusters within their limits; the hull gets
what they deliver, and the observer's low-frequency model is driven by it (Fossen 2021, §13.5:
τ in the velocity estimate's equation is the applied thrust); with back-calculation the
integral states are pulled towards what is delivered (Åström and Hägglund, *Advanced PID
Control*, 2006, §3.5).

References: test_observer.py's independent model of the vessel, the observer and the controller
on its estimates, extended here with reference.py's allocation (written again with numpy, not
the core's) and the same back-calculation law, solved by DOP853; the allocation's contract
(inside the capacity the thrusters deliver the demand); and the ledger's own balance."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import phsplit
from checks import within_passivity_bound
from reference import euler_zyx
from test_observer import ObserverField, observer_vessel, rot
from test_operation import OSV_THRUSTERS


def start_estimate():
    """The paper's start (80 m off the set point) as measured: position and heading."""
    y = np.asarray(phsplit.Vessel.paper().initial_state(), float)
    return [float(y[18]), float(y[19]), float(euler_zyx(y[6:15].reshape(3, 3, order="F"))[2])]


def with_thrusters(units=None, **control):
    """The paper's vessel with the observer (test_observer.py's, with a wrong bias; its initial
    estimate the measured start, so the demand keeps its direction while the estimate settles)
    and the OSV's four thrusters (or `units`), its start 80 m off the set point."""
    _, d = observer_vessel()
    d["observer"]["initial_estimate"] = start_estimate()
    d["thrusters"] = dict(OSV_THRUSTERS, unit=[dict(u) for u in (units or OSV_THRUSTERS["unit"])])
    d["control"] = dict(d["control"], **control)
    return phsplit.Vessel.from_dict(d), d


class ThrustObserverField(ObserverField):
    """test_observer.py's model with the controller's demand allocated to the thrusters (those
    not yet lost at t) by reference.py's ``Field.thrust``: the hull gets the delivered wrench,
    the velocity estimate ``M nu^' = ... + tau_delivered``, and with back-calculation
    ``q' = e - diag(1/(Ki Tt)) R (tau_delivered - tau_demand)`` on the axes with Ki > 0."""

    def __init__(self, d):
        super().__init__(d)
        self.units = [dict(u) for u in d["thrusters"]["unit"]]
        c = d["control"]
        g = self.gains
        self.back = np.zeros(3)
        if c.get("anti_windup") == "back_calculation":
            for i in range(3):
                if g["ki"][i] > 0:
                    tt = c.get("tracking_time")
                    if tt is None:
                        tt = math.sqrt(g["kd"][i] / g["ki"][i]) if g["kd"][i] > 0 else g["kp"][i] / g["ki"][i]
                    self.back[i] = 1.0 / (g["ki"][i] * tt)

    def demand(self, y):
        Q = y[6:15].reshape(3, 3, order="F")
        psi = euler_zyx(Q)[2]
        psi = self.ref[2] + (psi - self.ref[2] + math.pi) % (2 * math.pi) - math.pi
        n = 27
        eta, nu, q = y[n + 6:n + 9], y[n + 12:n + 15], y[n + 15:n + 18]
        R = rot(psi)
        g = self.gains
        return -R.T @ (g["kp"] * (eta - self.ref) + g["ki"] * q) - R.T @ (g["kd"] * (R @ nu)), R

    def delivered(self, t, tau):
        self.hull.thr_units = [u for u in self.units if u.get("lost_at") is None or t < u["lost_at"]]
        return self.hull.thrust(np.array([tau[0], tau[1], 0.0]), np.array([0.0, 0.0, tau[2]]))

    def __call__(self, t, y):
        dy = super().__call__(t, y)           # with the demand on the hull and in nu^
        tau, R = self.demand(y)
        force, moment = self.delivered(t, tau)
        dy[0:3] += force - np.array([tau[0], tau[1], 0.0])
        dy[3:6] += moment - np.array([0.0, 0.0, tau[2]])
        gap = np.array([force[0] - tau[0], force[1] - tau[1], moment[2] - tau[2]])
        n = 27
        dy[n + 12:n + 15] += gap / self.M
        dy[n + 15:n + 18] -= self.back * (R @ gap)
        return dy


def reference_end(d, v, t_end, breaks=()):
    """The independent model's state at t_end (DOP853, rtol 1e-11), restarted at `breaks` (a
    thruster lost)."""
    f = ThrustObserverField(d)
    x = np.zeros(18)
    x[6:9] = d["observer"]["initial_estimate"]
    x[9:12] = d["observer"]["initial_bias"]
    y = np.concatenate([np.asarray(v.initial_state(), float)[:27], x])
    edges = [0.0, *breaks, t_end]
    for a, b in zip(edges, edges[1:]):
        sol = solve_ivp(f, (a, b), y, method="DOP853", rtol=1e-11, atol=np.maximum(np.abs(y), 1.0) * 1e-14)
        assert sol.success
        y = sol.y[:, -1]
    return y, f


def error(s, want):
    """The final momentum's, position estimate's and integral states' relative errors."""
    return sum(np.linalg.norm(got - want[a:a + 3]) / np.linalg.norm(want[a:a + 3])
               for got, a in ((s.p[-1], 0), (s.own[-1][6:9], 33), (s.own[-1][15:18], 42)))


T_END = 12.0
RUNS = (("sp2", [0.2, 0.1, 0.05], 2.0, 5e-6), ("sp4", [0.4, 0.2, 0.1], 4.0, 1e-9))


def slopes(v, want):
    out = {}
    for method, hs, order, small in RUNS:
        errs = []
        for h in hs:
            s = phsplit.simulate(v, (0.0, T_END), h, method, control_start=0.0, ledger=False,
                                 project_invariants=False, save_at=[0.0, T_END])
            errs.append(error(s, want))
        slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
        out[method] = (slope, errs)
        assert abs(slope - order) < 0.3, (method, slope, errs)
        assert errs[-1] < small, (method, errs)
    return out


@pytest.mark.parametrize("anti_windup", ["none", "back_calculation"])
def test_orders_two_and_four_through_saturated_thrusters(anti_windup):
    """From 80 m off the demand is far beyond the thrusters' capacity over the whole run (the
    same thruster binds throughout, so the field is smooth): SP2 and SP4 follow the independent
    model at fitted slopes 2 and 4, with and without back-calculation."""
    v, d = with_thrusters(anti_windup=anti_windup)
    want, f = reference_end(d, v, T_END)
    s = phsplit.simulate(v, (0.0, T_END), 0.1, "sp4", control_start=0.0, save_every=1)
    util = s.outputs["thrust_utilisation"][2]
    assert np.all(util[1:] >= 1.0 - 1e-12), util.min()
    slopes(v, want)
    if anti_windup == "back_calculation":
        # the law acts: the integral differs from the run without it
        plain, _ = with_thrusters()
        w = phsplit.simulate(plain, (0.0, T_END), 0.1, "sp4", control_start=0.0, save_every=1)
        assert np.abs(w.own[-1][15:18] - s.own[-1][15:18]).max() > 1e-2 * np.abs(w.own[-1][15:18]).max()


def test_a_thruster_lost_mid_run():
    """The bow tunnel thruster lost at 6 s: its availability drops to 0 there, it delivers
    nothing after, the others take the demand (the run follows the independent model, which
    allocates over the thrusters left), and the ledger still closes."""
    units = [dict(u) for u in OSV_THRUSTERS["unit"]]
    units[0]["lost_at"] = 6.0
    v, d = with_thrusters(units)
    t_end = 12.0
    want, _ = reference_end(d, v, t_end, breaks=(6.0,))
    s = phsplit.simulate(v, (0.0, t_end), 0.1, "sp4", control_start=0.0, save_every=1)
    assert s.t[-1] == pytest.approx(t_end)
    avail = s.outputs["thruster0_available"][2]
    assert np.all(avail[s.t < 6.0 - 1e-9] == 1.0) and np.all(avail[s.t >= 6.0] == 0.0)
    assert np.all(s.outputs["thruster0_thrust"][2][s.t >= 6.0] == 0.0)
    assert np.all(np.abs(s.outputs["thruster1_thrust"][2][s.t >= 6.0]) > 1e3)
    for i in (2, 3):
        assert np.all(s.outputs[f"thruster{i}_available"][2] == 1.0)
    assert error(s, want) < 1e-8
    assert np.max(s.ledger.relative_residual()) < 1e-10


def test_the_ledger_books_what_the_thrusters_deliver():
    """The observer stores nothing of H; the hull's ledger books the delivered thrust as the
    supplied account ``thrusters``: the balance closes to round-off, the passivity bound holds,
    and the account's force is the delivered surge, sway and yaw the outputs report."""
    v, _ = with_thrusters(anti_windup="back_calculation")
    s = phsplit.simulate(v, (0.0, 60.0), 0.25, "sp4", control_start=0.0, save_every=4)
    assert set(s.ledger.by_account) == {"damping", "thrusters"}
    assert s.ledger.kinds["thrusters"] == "supplied"
    assert np.max(s.ledger.relative_residual()) < 1e-10
    assert within_passivity_bound(s)
    k = list(s.ledger.by_account).index("thrusters")
    got = np.column_stack([s.account_force[:, k, 0], s.account_force[:, k, 1], s.account_moment[:, k, 2]])
    want = np.column_stack([s.outputs[f"delivered_{n}"][2] for n in ("surge", "sway", "yaw")])
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max())
    # saturated at the start: the demand the outputs report is beyond what is delivered
    assert s.outputs["thrust_utilisation"][2][1] >= 1.0 - 1e-12
    assert abs(s.outputs["commanded_surge"][2][1]) > abs(s.outputs["delivered_surge"][2][1])


def test_with_sensors_and_adaptive_steps():
    """Sampled, noisy sensors with a GNSS dropout, and a thruster lost between the steps of a
    fixed grid: the ledger closes with fixed and adaptive steps, and adaptive steps land on the
    loss."""
    units = [dict(u) for u in OSV_THRUSTERS["unit"]]
    units[0]["lost_at"] = 15.3
    _, d = with_thrusters(units, anti_windup="back_calculation")
    d["sensors"] = {"gnss_rate": 1.0, "gyro_rate": 2.0, "gnss_noise": 0.5, "gyro_noise": 0.002,
                    "gnss_bias": [0.3, -0.2], "gyro_bias": 0.001, "gnss_dropout": [[10.0, 20.0]], "seed": 3}
    v = phsplit.Vessel.from_dict(d)
    s = phsplit.simulate(v, (0.0, 40.0), 0.25, "sp4", control_start=0.0, save_every=4)
    assert np.max(s.ledger.relative_residual()) < 1e-10
    a = phsplit.simulate(v, (0.0, 40.0), 0.25, "sp4", control_start=0.0, rtol=1e-6)
    assert np.max(a.ledger.relative_residual()) < 1e-10
    k = int(np.argmin(np.abs(a.t - 15.3)))
    assert a.t[k] == pytest.approx(15.3, abs=1e-12)
    avail = a.outputs["thruster0_available"][2]
    assert avail[k - 1] == 1.0 and np.all(avail[k:] == 0.0)


def test_limits_that_never_bind_are_the_plain_observer_run():
    """Thrusters in the plane of the origin (no heel or trim from their arms) and far beyond any
    demand deliver the demand exactly: the run is the observer's without thrusters (the same
    Gauss collocation of flow S2) to round-off, with and without back-calculation."""
    units = [dict(u, position=[u["position"][0], u["position"][1], 0.0], max_thrust=1e12)
             for u in OSV_THRUSTERS["unit"]]
    _, d = with_thrusters()
    del d["thrusters"]
    plain = phsplit.Vessel.from_dict(d)
    a = phsplit.simulate(plain, (0.0, 20.0), 0.2, "sp4", control_start=0.0, linear_flow="gauss", ledger=False)
    ya = np.concatenate([a.p, a.m, a.x, a.own], axis=1)
    for aw in ("none", "back_calculation"):
        v, _ = with_thrusters(units, anti_windup=aw)
        b = phsplit.simulate(v, (0.0, 20.0), 0.2, "sp4", control_start=0.0, ledger=False)
        assert np.all(b.outputs["thrust_utilisation"][2] < 1e-3)
        yb = np.concatenate([b.p, b.m, b.x, b.own], axis=1)
        rel = np.abs(ya - yb).max(axis=0) / np.maximum(np.abs(ya).max(axis=0), 1e-300)
        assert rel[np.abs(ya).max(axis=0) > 0].max() < 1e-8, rel


def test_the_exact_flow_is_reported_and_gauss_used():
    """The thrusters' forcing cannot enter the exact flow S2: an explicit linear_flow = "exact"
    warns and the run is collocated."""
    v, _ = with_thrusters()
    with pytest.warns(UserWarning, match="linear_flow = 'exact' cannot act on this vessel"):
        s = phsplit.simulate(v, (0.0, 2.0), 0.5, "sp2", control_start=0.0, linear_flow="exact")
    g = phsplit.simulate(v, (0.0, 2.0), 0.5, "sp2", control_start=0.0, linear_flow="gauss")
    np.testing.assert_array_equal(s.p, g.p)


@pytest.mark.parametrize("change, words", [
    ("rates", r"does not take thrusters that keep a memory \(thrusters.unit\[\*\].thrust_rate, turn_rate, stuck_at\)"),
    ("setpoint", r"does not yet take \[setpoint\]"),
])
def test_what_the_observer_refuses_with_thrusters(change, words):
    _, d = observer_vessel()
    d["thrusters"] = dict(OSV_THRUSTERS, unit=[dict(u) for u in OSV_THRUSTERS["unit"]])
    if change == "rates":
        d["thrusters"]["unit"][0]["thrust_rate"] = 1e5
    else:
        d["setpoint"] = {"natural_frequency": 0.1, "positions": [[780.0, 20.0, 0.0], [790.0, 20.0, 0.0]],
                         "speed": 0.5}
    with pytest.raises(phsplit.InvalidInputError, match=words) as e:
        phsplit.Vessel.from_dict(d)
    assert "[thrusters]" not in str(e.value) or change == "rates"
