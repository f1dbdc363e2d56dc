"""Cross-flow drag by strip theory (Fossen, Handbook of Marine Craft
Hydrodynamics and Motion Control, 2nd ed., 2021, §6.4.3), on the sway velocity relative to the
water. References: the independent numpy model (tests/reference.py, its strip integrals by scipy's
quad) by DOP853, a closed form (the terminal sway speed under a constant force), and the ledger."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import phsplit
from checks import fitted_order, within_passivity_bound

# The paper's hull: 76.2 m long (docs/model.md §5.9's box), 4.49 m draught, the body origin 2 m
# aft of midships; C_d = 1.0 (Hoerner's curve at B/2T = 2.0 gives about 0.9).
CROSSFLOW = {"draft": 4.49, "drag_coefficient": 1.0, "x_aft": -36.1, "x_fore": 40.1}


def vessel(current=None):
    d = phsplit.Vessel.paper().to_dict()
    d["crossflow_drag"] = dict(CROSSFLOW)
    if current is not None:
        d["current"] = {"velocity": list(current)}
    return phsplit.Vessel.from_dict(d)


def test_the_terminal_sway_speed_is_the_closed_form():
    """A constant sway force F at the origin on a hull symmetric about it (so the drag has no
    yaw moment), controller off, upright: the vessel ends at the sway speed where
    D_t v + k L |v| v = F, k = rho T C_d / 2."""
    d = vessel().to_dict()
    d["crossflow_drag"].update(x_aft=-38.1, x_fore=38.1)
    force = 2e5
    d["external"] = {"force": [0.0, force, 0.0]}
    v = phsplit.Vessel.from_dict(d)
    y0 = v.initial_state(euler=[0.0, 0.0, 0.0], position=[0.0, 0.0, 0.0])
    s = phsplit.simulate(v, (0.0, 3000.0), 1.0, "sp2", control_start=None, initial=y0, save_every=100)
    rho = d["vessel"]["water_density"]
    k = 0.5 * rho * CROSSFLOW["draft"] * CROSSFLOW["drag_coefficient"] * 76.2
    dt = d["vessel"]["damping_translational"][1]
    want = (-dt + np.sqrt(dt**2 + 4 * k * force)) / (2 * k)
    assert abs(s.v[-1, 1] - want) < 1e-9 * want, (s.v[-1, 1], want)
    assert abs(s.euler[-1, 2]) < 1e-9
    assert s.ledger.by_account["crossflow_drag"][1:].min() >= 0


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
@pytest.mark.parametrize("current", [None, [0.3, -0.6, 0.0]])
def test_orders_against_the_independent_model(method, order, current):
    v = vessel(current)
    y0 = v.initial_state()
    y0[0:3] = [3e6, -4e6, 0.0]   # sway 0.6 m/s
    y0[3:6] = [0.0, 0.0, 8e7]    # yaw rate 0.028 rad/s: the zero of v + x r inside the hull
    slope, errs, _ = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    assert abs(slope - order) < 0.2, (slope, errs)


def test_the_ledger_closes_and_books_the_drag_and_the_current():
    v = vessel([0.3, -0.6, 0.0])
    assert ("crossflow_drag", "dissipated") in v.accounts and ("crossflow_current", "supplied") in v.accounts
    for method, lf in (("sp2", "exact"), ("sp4", "gauss"), ("lie", "exact")):
        s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=20.0, linear_flow=lf)
        assert s.status == "completed"
        assert np.all(s.ledger.relative_residual() < 1e-10), (method, s.ledger.relative_residual().max())
        assert s.ledger.by_account["crossflow_drag"][1:].min() >= 0
        assert abs(s.ledger.by_account["crossflow_current"][1:].sum()) > 0


@pytest.mark.parametrize("h", [5.0, 20.0])
def test_sp2_stays_within_its_passivity_bound_at_long_steps(h):
    v = vessel([0.3, -0.6, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        s = phsplit.simulate(v, (0.0, 3600.0), h, "sp2")
    assert s.status == "completed", s.failure
    assert within_passivity_bound(s)


def test_bad_crossflow_tables():
    base = phsplit.Vessel.paper().to_dict()
    for table, words in ((dict(CROSSFLOW, draft=-1.0), "crossflow_drag.draft must be > 0"),
                         (dict(CROSSFLOW, x_aft=50.0), "x_aft < x_fore"),
                         (dict(CROSSFLOW, drag_coefficient=12.0), "at most 5"),
                         ({k: v for k, v in CROSSFLOW.items() if k != "x_fore"}, "x_fore")):
        with pytest.raises((phsplit.InvalidInputError, phsplit.ScenarioParseError), match=words):
            phsplit.Vessel.from_dict(dict(base, crossflow_drag=table))
