"""The fairlead spring (docs/model.md §5.16): a linear spring from a point of the hull to an
anchor, whose moment about the body origin depends on the position, a coupling of translation
and rotation written as booked rows of the linear flow S2. It keeps the exact S2 (no forcing, no
collocation fallback); SP2 and SP4 keep their orders against the independent numpy model
(tests/reference.py, DOP853 at rtol 1e-13); the ledger books the spring as a port and closes per
step; SP2 stays within its passivity bound over an hour at a long step."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import phsplit
from checks import fitted_order, within_passivity_bound

SPRING = {"fairlead": [30.0, -8.0, 2.0], "anchor": [700.0, -20.0, -5.0], "stiffness": 4.0e4}


def moored(**spring) -> phsplit.Vessel:
    d = phsplit.Vessel.paper().to_dict()
    d["spring"] = {**SPRING, **spring}
    return phsplit.Vessel.from_dict(d)


def test_the_spring_is_a_port_and_keeps_the_exact_flow():
    v = moored()
    assert "spring" in v.components and ("spring", "supplied") in v.accounts
    with warnings.catch_warnings():
        warnings.simplefilter("error", phsplit.SettingWarning)  # the exact flow acts: no warning
        s = phsplit.simulate(v, (0.0, 100.0), 0.5, "sp2", control_start=0.0, linear_flow="exact")
    assert s.to_xarray().attrs["s2_solver"] == "exact"
    # The booked force is the spring written out, F = -k (x + Q r - a) turned to the body frame.
    k = SPRING["stiffness"]
    r, a = (np.array(SPRING[n], float) for n in ("fairlead", "anchor"))
    F = -k * (s.x + np.einsum("nij,j->ni", s.Q, r) - a)
    fb = np.einsum("nji,nj->ni", s.Q, F)
    np.testing.assert_allclose(s.force("spring"), fb, rtol=1e-12, atol=1e-6 * np.abs(fb).max())
    np.testing.assert_allclose(s.moment("spring"), np.cross(r, fb), rtol=1e-12, atol=1e-6 * np.abs(fb).max() * 31)
    np.testing.assert_allclose(s.outputs["spring_tension"][2], np.linalg.norm(F, axis=1), rtol=1e-12)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
@pytest.mark.parametrize("linear_flow", ["exact", "gauss"])
def test_orders_with_the_spring_against_the_independent_model(method, order, linear_flow):
    v = moored()
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]
    y0[3:6] = [1e6, 2e6, -3e6]
    slope, errs, _ = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6), linear_flow=linear_flow)
    assert abs(slope - order) < 0.2, (slope, errs)


@pytest.mark.parametrize("method", ["sp2", "sp4", "lie"])
@pytest.mark.parametrize("linear_flow", ["exact", "gauss"])
def test_the_ledger_books_the_spring_and_closes_per_step(method, linear_flow):
    s = phsplit.simulate(moored(), (0.0, 600.0), 0.5, method, control_start=0.0, linear_flow=linear_flow)
    assert s.status == "completed"
    assert s.ledger.relative_residual().max() < 1e-10
    assert np.abs(s.ledger.by_account["spring"]).max() > 1e3


def test_sp2_within_its_passivity_bound_for_an_hour_at_a_long_step():
    with pytest.warns(phsplit.StepSizeWarning):  # h beyond half the shortest period, on purpose
        s = phsplit.simulate(moored(), (0.0, 3600.0), 20.0, "sp2", control_start=0.0, linear_flow="exact")
    assert s.status == "completed" and within_passivity_bound(s)
    assert s.ledger.relative_residual().max() < 1e-10


@pytest.mark.parametrize("table,words", [
    ({"anchor": [0.0, 0.0, 0.0], "stiffness": 1.0}, "spring.fairlead"),
    ({**SPRING, "stiffness": 0.0}, "spring.stiffness"),
    ({**SPRING, "stiffness": -5.0}, "spring.stiffness"),
    ({**SPRING, "fairlead": [3000.0, 0.0, 0.0]}, "spring.fairlead[0] must lie within 1000 m"),
    ({**SPRING, "lenght": 3.0}, "lenght"),
])
def test_bad_spring_tables_name_the_key(table, words):
    d = phsplit.Vessel.paper().to_dict()
    d["spring"] = table
    with pytest.raises(phsplit.InvalidInputError, match=words.replace("[", r"\[").replace("]", r"\]")):
        phsplit.Vessel.from_dict(d)
