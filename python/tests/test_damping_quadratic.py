"""Quadratic hydrodynamic damping, Fossen's diagonal D_n(nu) nu
(Handbook of Marine Craft Hydrodynamics and Motion Control, 2nd ed., 2021, §6.4), on the velocity
relative to the water. References: the independent numpy model (tests/reference.py) by DOP853, a
closed form (the terminal speed under a constant force), and the ledger's own balance."""
from __future__ import annotations

import numpy as np
import pytest

import phsplit
from checks import fitted_order, within_passivity_bound

# Surge, sway, heave (kg/m); roll, pitch, yaw (kg m^2): about rho/2 C_d A for the paper's hull
# (76 m x 18 m x 4.5 m draught: C_d ~ 0.1 in surge, ~ 1 in sway), and the strip integrals of the
# same drag for the rotations.
COEFFICIENTS = [4.0e3, 1.75e5, 2.0e5, 3.0e8, 4.0e9, 2.0e10]


def vessel(current=None, coefficients=COEFFICIENTS):
    d = phsplit.Vessel.paper().to_dict()
    d["damping_quadratic"] = {"coefficients": list(coefficients)}
    if current is not None:
        d["current"] = {"velocity": list(current)}
    return phsplit.Vessel.from_dict(d)


def test_the_terminal_speed_is_the_closed_form():
    """A constant surge force F on the upright vessel, controller off: it ends at the speed where
    D_t u + c |u| u = F, u = (-D_t + sqrt(D_t^2 + 4 c F)) / (2 c)."""
    d = vessel().to_dict()
    force = 3e5
    d["external"] = {"force": [force, 0.0, 0.0]}
    v = phsplit.Vessel.from_dict(d)
    y0 = v.initial_state(euler=[0.0, 0.0, 0.0], position=[0.0, 0.0, 0.0])
    s = phsplit.simulate(v, (0.0, 4000.0), 1.0, "sp2", control_start=None, initial=y0, save_every=100)
    dt, c = d["vessel"]["damping_translational"][0], COEFFICIENTS[0]
    u = (-dt + np.sqrt(dt**2 + 4 * c * force)) / (2 * c)
    assert abs(s.v[-1, 0] - u) < 1e-9 * u, (s.v[-1, 0], u)
    assert s.ledger.by_account["damping_quadratic"][1:].min() >= 0


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
@pytest.mark.parametrize("current", [None, [0.5, -0.4, 0.0]])
def test_orders_against_the_independent_model(method, order, current):
    v = vessel(current)
    y0 = v.initial_state()
    y0[0:3] = [6e6, -3e6, 1e6]   # about 1 m/s forward and 0.5 m/s sideways
    y0[3:6] = [2e7, -1e8, 5e8]   # turning
    slope, errs, _ = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    assert abs(slope - order) < 0.2, (slope, errs)


def test_the_ledger_closes_and_books_a_dissipation():
    v = vessel([0.5, -0.4, 0.0])
    assert ("damping_quadratic", "dissipated") in v.accounts
    for method, lf in (("sp2", "exact"), ("sp4", "gauss"), ("lie", "exact")):
        s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=20.0, linear_flow=lf)
        assert s.status == "completed"
        assert np.all(s.ledger.relative_residual() < 1e-10), (method, np.abs(s.ledger.relative_residual()).max())
        assert s.ledger.by_account["damping_quadratic"][1:].min() >= 0
        assert s.ledger.by_account["damping_quadratic"][1:].sum() > 0


@pytest.mark.parametrize("h", [5.0, 10.0, 20.0])
def test_sp2_stays_within_its_passivity_bound_at_long_steps(h):
    """The paper's DP run (controller from 50 s, one hour) with quadratic damping and a current:
    SP2 completes within its passivity bound at steps far beyond the natural periods."""
    v = vessel([0.5, -0.4, 0.0])
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        s = phsplit.simulate(v, (0.0, 3600.0), h, "sp2")
    assert s.status == "completed", s.failure
    assert within_passivity_bound(s)


def test_bad_coefficients_are_named():
    base = phsplit.Vessel.paper().to_dict()
    for table, words in (({"coefficients": [1.0, 2.0]}, "6 numbers"),
                         ({"coefficients": [1.0, -2.0, 0, 0, 0, 0]}, r"damping_quadratic.coefficients\[1\] must be ≥ 0"),
                         ({}, "missing field `coefficients`"),
                         ({"coefficient": [0] * 6}, "did you mean 'coefficients'")):
        with pytest.raises((phsplit.InvalidInputError, phsplit.ScenarioParseError), match=words):
            phsplit.Vessel.from_dict(dict(base, damping_quadratic=table))
