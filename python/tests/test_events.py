"""Output at chosen times and events, against independent references
(tests/reference.py: eq. (39) in numpy, scipy DOP853 at tight tolerance, no phsplit code)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import phsplit
import reference as ref

V = phsplit.Vessel.paper()
P = V.to_dict()


def test_save_at_is_a_run_stepped_exactly_to_those_times():
    ts = [0.0, 0.5, 3.3, 10.0, 17.123, 40.0]
    s = phsplit.simulate(V, (0.0, 40.0), 0.5, "sp4", control_start=5.0, save_at=ts)
    np.testing.assert_array_equal(s.t, ts)
    for i, t in enumerate(ts[1:], 1):
        r = phsplit.simulate(V, (0.0, t), 0.5, "sp4", control_start=5.0)
        np.testing.assert_array_equal(s.state(i), r.state(-1), err_msg=f"t = {t}")
        assert s.energy[i] == r.energy[-1]
    # the ledger closes between the chosen times as between grid points
    assert np.all(s.ledger.relative_residual() < 1e-10)
    assert s.status == "completed"


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_save_at_values_converge_at_the_methods_order(method, order):
    """Off-grid times 0.37 and 0.81 s (controller on): the relative error of (p, m, x) against the
    reference falls at the method's order."""
    ts = np.array([0.37, 0.81])
    y0 = V.initial_state()
    _, yr = ref.solve(P, y0, 1.0, 0.0, t_eval=ts, rtol=1e-13)
    hs = 2.0 ** -np.arange(2, 7)
    errs = []
    for h in hs:
        s = phsplit.simulate(V, (0.0, 1.0), h, method, control_start=0.0, ledger=False, save_at=ts)
        e = 0.0
        for i in range(2):
            for sl in (slice(0, 3), slice(3, 6), slice(18, 21)):
                e = max(e, np.linalg.norm(s.state(i)[sl] - yr[i][sl]) / np.linalg.norm(yr[i][sl]))
        errs.append(e)
    errs = np.array(errs)
    keep = errs > 1e-13
    slope = np.polyfit(np.log(hs[keep]), np.log(errs[keep]), 1)[0]
    assert abs(slope - order) < 0.3, (slope, errs)


def test_a_watch_circle_crossing_is_located_to_1e_8_s():
    """Entering a 30 m circle about the set point, controller on from t = 0; reference: the
    numpy model by DOP853 at rtol 1e-13 with scipy's event location."""
    ref_x = np.array(P["control"]["position_reference"])
    field = ref.Field(P, True)
    y0 = V.initial_state()

    def g(t, y):
        return np.hypot(y[18] - ref_x[0], y[19] - ref_x[1]) - 30.0

    g.terminal, g.direction = True, -1
    r = solve_ivp(field, (0.0, 60.0), y0, method="DOP853", rtol=1e-13,
                  atol=np.maximum(np.abs(y0), 1.0) * 1e-16, events=g)
    t_ref = float(r.t_events[0][0])
    s = phsplit.simulate(V, (0.0, 60.0), 0.01, "sp4", control_start=0.0,
                         events=[phsplit.events.watch_circle(30.0, direction="enter")])
    assert s.status == "event" and len(s.events) == 1
    hit = s.events[0]
    assert abs(hit.t - t_ref) < 1e-8, (hit.t, t_ref)
    assert s.t[-1] == hit.t and abs(np.hypot(*(s.x[-1, :2] - ref_x[:2])) - 30.0) < 1e-9
    assert np.all(s.ledger.relative_residual() < 1e-10)


def test_non_terminal_events_are_recorded_and_the_run_goes_on():
    ev = [phsplit.events.watch_circle(30.0, direction="enter", terminal=False),
          phsplit.events.roll_beyond(1.0, terminal=False)]
    s = phsplit.simulate(V, (0.0, 60.0), 0.5, "sp2", control_start=0.0, events=ev)
    assert s.status == "completed" and s.t[-1] == 60.0
    names = [e.name for e in s.events]
    assert "watch_circle_30m_enter" in names and any(n.startswith("roll_beyond") for n in names)
    times = [e.t for e in s.events]
    assert times == sorted(times)
    # each recorded crossing is a crossing: the roll there is 1 degree
    for e in s.events:
        if e.name.startswith("roll"):
            q = e.state[6:15].reshape(3, 3, order="F")
            assert abs(abs(phsplit.so3.euler_zyx(q)[0]) - np.radians(1.0)) < 1e-9


def test_energy_event_and_bad_arguments():
    s = phsplit.simulate(V, (0.0, 100.0), 0.5, "sp2", control_start=0.0,
                         events=[phsplit.events.energy_above(2.0e6)])
    assert s.status == "event" and abs(s.energy[-1] - 2.0e6) < 1e-3
    for kw, words in (({"save_at": [5.0, 1.0]}, "increasing"), ({"save_at": [-1.0]}, "within t_span"),
                      ({"save_at": []}, "empty"), ({"events": ["watch"]}, "Event objects"),
                      ({"save_at": [1.0], "events": [phsplit.events.energy_above(1.0)]}, "not both")):
        with pytest.raises(phsplit.InvalidInputError, match=words):
            phsplit.simulate(V, (0.0, 10.0), 0.5, "sp2", **kw)
    for make, words in ((lambda: phsplit.events.watch_circle(-1.0), "radius"),
                        (lambda: phsplit.events.watch_circle(5.0, direction="out"), "direction"),
                        (lambda: phsplit.events.roll_beyond(float("nan")), "limit")):
        with pytest.raises(phsplit.InvalidInputError, match=words):
            make()


def test_dense_output_on_request_is_a_run_stepped_to_each_time():
    s = phsplit.simulate(V, (0.0, 60.0), 0.5, "sp2", control_start=5.0, save_every=7)
    ts = [0.0, 3.3, 14.0, 33.71, 59.99, 60.0]
    d = s.at(ts)
    np.testing.assert_array_equal(d.t, ts)
    for i, t in enumerate(ts[1:], 1):
        r = phsplit.simulate(V, (0.0, t), 0.5, "sp2", control_start=5.0)
        np.testing.assert_allclose(d.state(i), r.state(-1), rtol=1e-12, atol=1e-9, err_msg=f"t = {t}")
    with pytest.raises(phsplit.InvalidInputError, match="within the run"):
        s.at([61.0])


def test_runge_kutta_runs_cut_into_calls_continue_from_their_own_state():
    """RK4 lets Q drift off SO(3) by its own error; the calls that continue a run take its state
    as it is (found by review: they refused it)."""
    s = phsplit.simulate(V, (0.0, 200.0), 0.5, "rk4", control_start=0.0, save_at=[100.25, 200.0])
    r = phsplit.simulate(V, (0.0, 100.25), 0.5, "rk4", control_start=0.0)
    np.testing.assert_array_equal(s.state(0), r.state(-1))
    full = phsplit.simulate(V, (0.0, 200.0), 0.5, "heun", control_start=0.0, save_every=9)
    np.testing.assert_allclose(full.at([150.1]).state(0),
                               phsplit.simulate(V, (0.0, 150.1), 0.5, "heun", control_start=0.0).state(-1),
                               rtol=1e-12, atol=1e-9)
    e = phsplit.simulate(V, (0.0, 200.0), 0.5, "rk4", control_start=0.0,
                         events=[phsplit.events.watch_circle(30.0, direction="enter")])
    assert e.status == "event"


def test_event_on_a_grid_point_and_a_reused_event():
    stop = phsplit.events.Event("t=600", lambda t, y, v: 600.0 - t, "fall")
    s = phsplit.simulate(V, (0.0, 1000.0), 0.5, "sp2", control_start=0.0, events=[stop])
    assert s.status == "event" and abs(s.events[0].t - 600.0) < 1e-9
    # one event object, two vessels with other set points: each run uses its own
    ev = phsplit.events.watch_circle(30.0, direction="enter")
    found = []
    for ref_x in (700.0, 600.0):
        d = V.to_dict()
        d["control"]["position_reference"] = [ref_x, 20.0, 0.0]
        s = phsplit.simulate(phsplit.Vessel.from_dict(d), (0.0, 60.0), 0.5, "sp2", control_start=0.0, events=ev)
        found.append(s.events[0].t if s.events else None)
    assert all(t is not None for t in found) and found[0] != found[1]


def test_save_at_on_a_run_that_fails_returns_what_it_has():
    s = phsplit.simulate(V, (0.0, 20000.0), 40.0, "sp6", control_start=0.0, save_at=[19990.0])
    assert s.status == "failed" and len(s.t) == 1 and np.all(np.isfinite(s.state(0)))


def test_the_ledger_between_rows_keeps_its_digits_over_a_settled_hour():
    """Rows assembled from several core calls (save_at, events) book each interval by its own
    sum: late in a settled hour the rows book a few joules after the transient booked millions,
    and a difference of running totals left residuals of 1e-3 of the terms there (measured)."""
    v = phsplit.Vessel.paper()
    runs = {
        "save_at on the grid": dict(save_at=np.arange(10.0, 3600.1, 10.0)),
        "save_at off the grid": dict(save_at=np.arange(10.0, 3600.1, 7.3)),
        "events, every 5th step": dict(save_every=5, events=[phsplit.events.watch_circle(30.0, "enter", False)]),
        "events, adaptive": dict(atol=1e-4, events=[phsplit.events.watch_circle(30.0, "enter", False)]),
    }
    for what, kw in runs.items():
        s = phsplit.simulate(v, (0.0, 3600.0), 0.5, "sp2", control_start=0.0, **kw)
        assert s.status == "completed", what
        assert np.max(s.ledger.relative_residual()) < 1e-10, (what, np.max(s.ledger.relative_residual()))


def test_progress_is_reported_over_the_whole_run_with_save_at_and_events():
    """``progress`` acts with save_at and events too (several core calls): the steps done grow
    over the whole run, not restarting at each call, and stay within the run's steps."""
    for kw in (dict(save_at=[100.0, 200.0, 299.9]),
               dict(events=[phsplit.events.watch_circle(1e4)]),
               dict(events=[phsplit.events.watch_circle(1e4)], atol=1e-9, rtol=1e-9)):
        calls = []
        s = phsplit.simulate(V, (0.0, 300.0), 0.002, "sp2", control_start=0.0, ledger=False,
                             progress=lambda done, n: calls.append((done, n)), **kw)
        assert s.status == "completed", kw
        assert calls, kw
        done = [d for d, _ in calls]
        assert all(b >= a for a, b in zip(done, done[1:])) and done[-1] > 150_000 // 2, (kw, done)
        assert all(n == 150_000 and 0 < d <= n for d, n in calls), (kw, calls[-3:])
