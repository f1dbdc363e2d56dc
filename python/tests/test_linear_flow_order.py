"""Flow S2 by Gauss collocation of a fixed order, whatever the method (``linear_flow = "gauss4"``,
``"gauss6"``; docs/how-to/choose-method-step-flow.md, "The linear flow S2"). References: the
independent numpy model (tests/reference.py, the waves written again from docs/model.md 5.9)
by DOP853; the ledger's closure and the discrete passivity inequality."""
from __future__ import annotations

import numpy as np
import pytest

import phsplit
from checks import fitted_order, within_passivity_bound
from phsplit import sea
from test_waves import vessel_with_waves


def sea_with_drift_and_current():
    ss = sea.SeaState(hs=2.0, tp=8.0, seed=3, components=25, direction=150.0, spreading=8.0)
    v = vessel_with_waves(ss.realise(), drift=True, current={"velocity": [0.3, 0.1, 0.0]})
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]  # moving, so the relative velocity matters
    return v, y0


def test_sp2_with_gauss4_keeps_order_two_with_a_smaller_error_in_a_sea():
    """The composition stays of order 2 (its splitting error), and the error that the one-stage
    midpoint rule adds in S2 (the sea's forcing, the damping, the controller) is gone: against
    the independent model, the error at every step is at least five times smaller than with
    ``"gauss"`` (measured: about 9.3 times)."""
    v, y0 = sea_with_drift_and_current()
    hs = 2.0 ** -np.arange(1, 6)
    slope2, errs2, _ = fitted_order(v, y0, "sp2", hs, linear_flow="gauss")
    slope4, errs4, _ = fitted_order(v, y0, "sp2", hs, linear_flow="gauss4")
    assert abs(slope2 - 2.0) < 0.2 and abs(slope4 - 2.0) < 0.2, (slope2, slope4)
    assert np.all(errs4 < errs2 / 5.0), (errs4, errs2)


def test_sp4_with_gauss6_keeps_order_four():
    v, y0 = sea_with_drift_and_current()
    slope, errs, _ = fitted_order(v, y0, "sp4", 2.0 ** -np.arange(1, 5), linear_flow="gauss6")
    assert abs(slope - 4.0) < 0.25, (slope, errs)


def test_a_fixed_order_takes_at_least_the_methods_stages():
    """sp4 needs two Gauss stages: ``"gauss4"`` is then ``"gauss"`` to the bit; with sp2 (one
    stage for ``"gauss"``) the two differ."""
    v, y0 = sea_with_drift_and_current()
    run = lambda m, lf: phsplit.simulate(v, (0.0, 20.0), 0.5, m, control_start=0.0, initial=y0, linear_flow=lf)
    a, b = run("sp4", "gauss"), run("sp4", "gauss4")
    assert np.array_equal(a.p, b.p) and b.meta["s2_solver"] == "gauss4"
    c, d = run("sp2", "gauss"), run("sp2", "gauss4")
    assert not np.array_equal(c.p, d.p)


@pytest.mark.parametrize("method", ["sp2", "mcl2"])
def test_the_ledger_closes_and_the_run_stays_passive_for_an_hour(method):
    """H_n <= H_0 + supplied_n at every step (every dissipation >= 0, the ledger closed to
    1e-10): Gauss collocation with any number of stages is dissipative on S2 (algebraically
    stable), and the compositions' steps are positive."""
    ss = sea.SeaState(hs=4.0, tp=10.0, seed=9, components=100, direction=210.0)
    v = vessel_with_waves(ss.realise(), drift=True)
    s = phsplit.simulate(v, (0.0, 3600.0), 2.0, method, control_start=0.0, linear_flow="gauss4")
    assert s.status == "completed" and s.meta["s2_solver"] == "gauss4"
    assert np.all(s.ledger.relative_residual() < 1e-10)
    assert within_passivity_bound(s)
