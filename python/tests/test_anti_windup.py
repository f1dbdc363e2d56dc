"""Back-calculation anti-windup of the controller's integral states while thrusters saturate
(docs/explanation/components/thrusters.md, "Anti-windup"; Åström and Hägglund, *Advanced PID
Control*, 2006, §3.5), against the independent model of ``reference.py``."""
from __future__ import annotations

import numpy as np
import pytest

import phsplit
import reference as ref
from test_operation import OSV_THRUSTERS, operation_vessel


def paper_with_thrusters(**control):
    d = phsplit.Vessel.paper().to_dict()
    d["thrusters"] = OSV_THRUSTERS
    d["control"] = dict(d["control"], **control)
    return phsplit.Vessel.from_dict(d)


def test_back_calculation_follows_the_independent_model_through_saturation():
    """The paper's start, 80 m off the set point, through the OSV's thrusters: the transient's
    demand is far beyond their capacity. With back-calculation the integral states are pulled
    towards what the thrusters deliver; the trajectory follows the independent model (DOP853 on
    the equations written again with numpy), and differs from the run without anti-windup."""
    T, at = 40.0, np.arange(0.0, 41.0, 10.0)
    v = paper_with_thrusters(anti_windup="back_calculation")
    plain = paper_with_thrusters()
    y0 = v.initial_state()
    _, yr = ref.solve(v.to_dict(), y0, T, 0.0, t_eval=at, rtol=1e-10)
    errs = {}
    for h in (0.5, 0.25):
        s = phsplit.simulate(v, (0.0, T), h, "sp4", control_start=0.0, save_at=at)
        errs[h] = np.abs(s.x - yr[:, 18:21]).max()
        assert np.all(s.ledger.relative_residual() < 1e-10)
    assert errs[0.25] < 1e-4 and errs[0.25] < errs[0.5], errs
    util = s.outputs["thrust_utilisation"][2]
    assert (util >= 1.0 - 1e-12).sum() >= 2, util
    # the integral states: the reference's and phsplit's agree, and differ from the plain run's
    np.testing.assert_allclose(s.phi_x[-1], yr[-1][24:27], rtol=0, atol=1e-3 * np.abs(yr[-1][24:27]).max())
    w = phsplit.simulate(plain, (0.0, T), 0.25, "sp4", control_start=0.0, save_at=at)
    assert np.abs(w.phi_x[-1] - s.phi_x[-1]).max() > 100.0
    assert np.abs(w.x - s.x).max() > 1.0


def test_limits_that_never_bind_leave_the_run_as_it_was():
    """Near the set point the thrusters deliver the demand: back-calculation adds nothing (the
    deficits are zero to round-off), so the run equals the one without it."""
    v = operation_vessel(True, speed=0.05)
    d = v.to_dict()
    d["control"] = dict(d["control"], anti_windup="back_calculation")
    va = phsplit.Vessel.from_dict(d)
    y0 = v.initial_state(position=[779.0, 19.5, 0.0], euler=[0.05, -0.02, 0.5])
    a = phsplit.simulate(v, (0.0, 20.0), 0.125, "sp4", control_start=0.0, initial=y0)
    b = phsplit.simulate(va, (0.0, 20.0), 0.125, "sp4", control_start=0.0, initial=y0)
    assert np.all(a.outputs["thrust_utilisation"][2] < 1.0)
    ya = np.concatenate([a.x, a.v, a.w, a.phi_x, a.phi_th], axis=1)
    yb = np.concatenate([b.x, b.v, b.w, b.phi_x, b.phi_th], axis=1)
    assert np.abs(ya - yb).max() <= 1e-9 * np.abs(ya).max()


def test_the_tracking_time_rule_and_the_override():
    """`T_t = √(K_d/K_i)` per axis by default (√(T_i T_d)); `tracking_time` sets every axis.
    A longer tracking time pulls the integral back more slowly."""
    at = np.array([0.0, 30.0])
    runs = {}
    for tt in (None, 5.0, 500.0):
        extra = {} if tt is None else {"tracking_time": tt}
        v = paper_with_thrusters(anti_windup="back_calculation", **extra)
        runs[tt] = phsplit.simulate(v, (0.0, 30.0), 0.25, "sp4", control_start=0.0, save_at=at).phi_x[-1]
    plain = phsplit.simulate(paper_with_thrusters(), (0.0, 30.0), 0.25, "sp4", control_start=0.0, save_at=at).phi_x[-1]
    # the slower the tracking, the nearer the plain integral
    assert np.linalg.norm(runs[500.0] - plain) < np.linalg.norm(runs[5.0] - plain)
    c = phsplit.Vessel.paper().to_dict()["control"]
    # the paper's surge and sway: √(K_d/K_i) = 63 s, so the rule's run is neither override's
    rule = np.sqrt(np.asarray(c["kd_translational"][:2]) / np.asarray(c["ki_translational"][:2]))
    np.testing.assert_allclose(rule, 63.2455532, rtol=1e-8)
    assert np.linalg.norm(runs[None] - runs[5.0]) > 1.0 and np.linalg.norm(runs[None] - runs[500.0]) > 1.0


@pytest.mark.parametrize("control,words", [
    ({"anti_windup": "clamp"}, r"control.anti_windup must be one of 'none', 'back_calculation', got .clamp."),
    ({"tracking_time": 10.0}, r"tracking_time .* needs control.anti_windup"),
    ({"anti_windup": "back_calculation", "tracking_time": -1.0}, r"control.tracking_time"),
])
def test_bad_anti_windup_keys_are_refused_by_name(control, words):
    with pytest.raises(phsplit.InvalidInputError, match=words):
        paper_with_thrusters(**control)


def test_anti_windup_without_thrusters_is_refused():
    d = phsplit.Vessel.paper().to_dict()
    d["control"] = dict(d["control"], anti_windup="back_calculation")
    with pytest.raises(phsplit.InvalidInputError, match=r"without \[thrusters\] the controller's force is unlimited"):
        phsplit.Vessel.from_dict(d)
