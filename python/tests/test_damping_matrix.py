"""A full 6x6 linear damping matrix D_L (Fossen's handbook, §6.4),
symmetric positive semidefinite, as a vessel may have it with the sway-yaw couplings Y_r, N_v.
References: the paper's vessel written with its diagonal as a matrix (the same numbers), the
independent numpy model (tests/reference.py) by DOP853, and the ledger."""
from __future__ import annotations

import numpy as np
import pytest

import phsplit
from checks import fitted_order, within_passivity_bound


def with_matrix(d: np.ndarray, current=None):
    tables = phsplit.Vessel.paper().to_dict()
    v = tables["vessel"]
    del v["damping_translational"], v["damping_rotational"]
    v["damping_matrix"] = [list(map(float, row)) for row in d]
    if current is not None:
        tables["current"] = {"velocity": list(current)}
    return phsplit.Vessel.from_dict(tables)


def paper_diagonal() -> np.ndarray:
    v = phsplit.Vessel.paper().to_dict()["vessel"]
    return np.diag(v["damping_translational"] + v["damping_rotational"])


def coupled() -> np.ndarray:
    """The paper's diagonal with a sway-yaw coupling (Y_r = N_v, kg m/s) and a heave-pitch one,
    still positive definite."""
    d = paper_diagonal()
    d[1, 5] = d[5, 1] = 3.0e6
    d[2, 4] = d[4, 2] = -5.0e6
    assert np.linalg.eigvalsh(d).min() > 0
    return d


@pytest.mark.parametrize("method", ["lie", "sp2", "sp4", "sp6", "rk4"])
def test_the_paper_vessel_as_a_matrix_is_the_paper_vessel(method):
    a = phsplit.simulate(phsplit.Vessel.paper(), method=method)
    b = phsplit.simulate(with_matrix(paper_diagonal()), method=method)
    for k in ("x", "euler", "p", "m", "energy"):
        ref = getattr(a, k)
        assert np.abs(getattr(b, k) - ref).max() <= 1e-12 * np.abs(ref).max(), k
    np.testing.assert_allclose(b.ledger.by_account["damping"], a.ledger.by_account["damping"], rtol=1e-12, atol=1e-6)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
@pytest.mark.parametrize("current", [None, [0.4, -0.3, 0.0]])
def test_orders_with_couplings_against_the_independent_model(method, order, current):
    v = with_matrix(coupled(), current)
    y0 = v.initial_state()
    y0[0:3] = [2e6, -3e6, 1e6]
    y0[3:6] = [1e7, -5e7, 9e7]
    slope, errs, _ = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    assert abs(slope - order) < 0.2, (slope, errs)


def test_the_ledger_closes_and_the_couplings_dissipate():
    v = with_matrix(coupled(), [0.4, -0.3, 0.0])
    for method, lf in (("sp2", "exact"), ("sp4", "gauss")):
        s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=20.0, linear_flow=lf)
        assert s.status == "completed"
        assert np.all(s.ledger.relative_residual() < 1e-10)
        assert s.ledger.by_account["damping"][1:].min() >= 0
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        s = phsplit.simulate(v, (0.0, 3600.0), 10.0, "sp2")
    assert s.status == "completed" and within_passivity_bound(s)


def test_bad_damping_matrices_are_named():
    d = coupled()
    d[1, 5] = 4.0e6  # not symmetric
    with pytest.raises(phsplit.InvalidInputError, match=r"damping_matrix must be symmetric: entry \[1\]\[5\]"):
        with_matrix(d)
    d = paper_diagonal()
    d[1, 5] = d[5, 1] = 1e9  # indefinite
    with pytest.raises(phsplit.InvalidInputError, match="positive semidefinite.*smallest eigenvalue is -"):
        with_matrix(d)
    tables = phsplit.Vessel.paper().to_dict()
    tables["vessel"]["damping_matrix"] = paper_diagonal().tolist()
    with pytest.raises(phsplit.InvalidInputError, match="either damping_matrix"):
        phsplit.Vessel.from_dict(tables)
    tables = phsplit.Vessel.paper().to_dict()
    del tables["vessel"]["damping_translational"], tables["vessel"]["damping_rotational"]
    tables["vessel"]["damping_matrix"] = paper_diagonal()[:5].tolist()
    with pytest.raises(phsplit.InvalidInputError, match="6 rows of 6"):
        phsplit.Vessel.from_dict(tables)
