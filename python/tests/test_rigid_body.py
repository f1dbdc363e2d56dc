"""phsplit.rigid_body against mpmath (the core's checked-in table, written by
scripts/gen_rigid_body_refs.py: closed form at 50 digits, checked against mpmath's ODE solver at
30 digits), invariants, and an input next to the middle axis."""
from __future__ import annotations

import csv
import doctest
import math
import pathlib

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import phsplit
from phsplit import rigid_body, so3
from phsplit.rigid_body import FreeRigidBody

DATA = pathlib.Path(__file__).resolve().parents[2] / "crates" / "phsplit-core" / "tests" / "data"
EPS = np.finfo(np.float64).eps


def table() -> list[dict]:
    with (DATA / "rigid_body_ref.csv").open() as f:
        rows = list(csv.DictReader(f))
    out = []
    for r in rows:
        out.append({
            "case": r["case"],
            "inertia": [float(r[k]) for k in ("T1", "T2", "T3")],
            "m0": np.array([float(r[k]) for k in ("m1", "m2", "m3")]),
            "t": float(r["t"]),
            "want": np.array([float(r[k]) for k in ("ref1", "ref2", "ref3")]),
            "sens": float(r["sensitivity"]),
        })
    return out


def test_exact_momentum_within_four_times_the_problems_sensitivity():
    rows = table()
    assert len(rows) >= 100
    worst = 0.0
    for r in rows:
        body = FreeRigidBody(r["inertia"])
        got = body.momentum(r["m0"], r["t"])
        bound = 4 * max(r["sens"], EPS * np.linalg.norm(r["m0"]))
        err = np.linalg.norm(got - r["want"])
        worst = max(worst, err / bound)
        assert err <= bound, (r["case"], r["t"], got, r["want"])
    assert worst <= 1.0


def test_an_input_next_to_the_middle_axis():
    # T = (1, 2, 3), m0 = (1e-7, 1, 2e-7), k'^2 = 1.3e-14; mpmath ODE (30 digits). The third
    # component was 1.76977477e-7 at t = 0.5 (error 2.3e-11 |m|), off by 1.9e-5 |m| at t = 50.
    body = FreeRigidBody([1.0, 2.0, 3.0])
    t = np.array([0.5, 5.0, 50.0])
    want = np.array([
        [8.431887902349233e-08, 1.0000000000000058, 1.7700005672127622e-07],
        [-7.318189973321318e-09, 1.00000000000002, 1.0080013746745022e-07],
        [-0.014350705855544625, 0.9995880296231195, 0.02485615166648064],
    ])
    got = body.momentum([1e-7, 1.0, 2e-7], t)
    assert np.all(np.linalg.norm(got - want, axis=-1) <= 4 * EPS)
    k2, k1 = body.elliptic_parameter([1e-7, 1.0, 2e-7])
    assert k1 == pytest.approx(1.3333333333332621e-14, rel=4 * EPS)


def test_vectorised_over_times_and_states():
    body = FreeRigidBody([2.5, 0.7, 1.6])
    m0 = np.array([0.3, -0.8, 0.5])
    t = np.linspace(-20.0, 20.0, 41)
    many = body.momentum(m0, t)
    assert many.shape == (41, 3)
    one_by_one = np.array([body.momentum(m0, ti) for ti in t])
    np.testing.assert_array_equal(many, one_by_one)
    assert body.momentum(m0, 1.0).shape == (3,)
    assert body.momentum(m0, np.zeros((2, 5))).shape == (2, 5, 3)
    states = np.array([[0.3, -0.8, 0.5], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    grid = body.momentum(states, t[:, None])
    assert grid.shape == (41, 3, 3)
    np.testing.assert_array_equal(grid[:, 0], many)
    np.testing.assert_array_equal(grid[:, 1], np.tile([1.0, 0.0, 0.0], (41, 1)))  # fixed point
    # invariants: |m| and the energy
    np.testing.assert_allclose(np.linalg.norm(many, axis=-1), np.linalg.norm(m0), rtol=4 * EPS)
    np.testing.assert_allclose(body.kinetic_energy(many), body.kinetic_energy(m0), rtol=8 * EPS)


def test_agrees_with_an_independent_integration():
    # scipy's DOP853 on m' = m x T^-1 m, at tight tolerances
    inertia = np.array([1.3, 2.1, 0.8])
    m0 = np.array([-0.4, 0.9, 0.3])
    t = np.linspace(0.0, 30.0, 7)
    sol = solve_ivp(lambda _, m: np.cross(m, m / inertia), (0, 30), m0, method="DOP853",
                    t_eval=t, rtol=1e-13, atol=1e-15)
    got = FreeRigidBody(inertia).momentum(m0, t)
    np.testing.assert_allclose(got, sol.y.T, atol=1e-11)


def test_flow_conserves_the_spatial_momentum_and_lands_on_the_exact_momentum():
    body = FreeRigidBody([1.0, 1.7, 2.9])
    m0 = np.array([0.6, -0.8, 0.9])
    Q0 = so3.exp([0.3, -0.2, 0.4])
    for order in (2, 4, 6):
        m, Q = m0, Q0
        for _ in range(50):
            m, Q = body.flow(m, Q, 0.1, magnus_order=order)
        assert np.linalg.norm(Q.T @ Q - np.eye(3)) < 1e-14
        np.testing.assert_allclose(m, body.momentum(m0, 5.0), atol=1e-13)
        spatial_err = np.linalg.norm(Q @ m - Q0 @ m0)
        assert spatial_err < {2: 1e-3, 4: 1e-6, 6: 1e-8}[order]
    # one long step lands on the exact momentum too
    m, _ = body.flow(m0, Q0, 7.0, 6)
    np.testing.assert_allclose(m, body.momentum(m0, 7.0), atol=4 * EPS * np.linalg.norm(m0))


def test_period():
    body = FreeRigidBody([1.0, 2.0, 3.0])
    m0 = np.array([0.3, -0.8, 0.5])
    T = body.period(m0)
    assert isinstance(T, float) and T > 0
    np.testing.assert_allclose(body.momentum(m0, [T, 2 * T]), [m0, m0], atol=1e-14)
    half = body.momentum(m0, T / 2)
    assert not np.allclose(half, m0, atol=1e-3)
    # near the middle axis the period is long, but finite; fixed points have none
    assert 200 < body.period([1e-7, 1.0, 2e-7]) < 300
    assert body.period([0.0, 1.0, 0.0]) is None
    assert body.period([0.0, 0.0, 0.0]) is None
    assert FreeRigidBody([2.0, 2.0, 2.0]).period([0.3, 0.1, 0.2]) is None
    # on the separatrix of T = (1, 4, 16): m1^2 |J1 - J2| = m3^2 |J2 - J3| is 3/4 = 4 * 3/16,
    # exact in floating point; the momentum tends to the middle axis and never returns
    sep = FreeRigidBody([1.0, 4.0, 16.0])
    assert sep.period([1.0, 0.3, 2.0]) == math.inf
    assert sep.elliptic_parameter([1.0, 0.3, 2.0]) == (1.0, 0.0)
    m = sep.momentum([1.0, 0.3, 2.0], [0.0, 50.0, 100.0])
    mid = np.linalg.norm([1.0, 0.3, 2.0])
    assert abs(m[-1, 1]) == pytest.approx(mid, rel=1e-9)


def test_bad_inputs_are_clear_errors():
    with pytest.raises(phsplit.InvalidInputError, match="inertia T2 must be finite and > 0"):
        FreeRigidBody([1.0, -2.0, 3.0])
    with pytest.raises(phsplit.InvalidInputError, match=r"shape \(3,\)"):
        FreeRigidBody([1.0, 2.0])
    body = FreeRigidBody([1.0, 2.0, 3.0])
    with pytest.raises(phsplit.InvalidInputError, match="m0 must have shape"):
        body.momentum([1.0, 2.0], 1.0)
    with pytest.raises(phsplit.InvalidInputError, match="m0 must be finite"):
        body.momentum([1.0, np.nan, 0.0], 1.0)
    with pytest.raises(phsplit.InvalidInputError, match="t must be finite"):
        body.momentum([1.0, 0.1, 0.0], np.inf)
    with pytest.raises(phsplit.InvalidInputError, match="magnus_order must be 2, 4 or 6"):
        body.flow([0.1, 0.2, 0.3], np.eye(3), 0.1, magnus_order=3)
    with pytest.raises(phsplit.InvalidInputError, match="magnus_order must be 2, 4 or 6"):
        body.flow([0.1, 0.2, 0.3], np.eye(3), 0.1, magnus_order=4.0)  # type: ignore[arg-type]
    with pytest.raises(phsplit.InvalidInputError, match=r"Q0 must have shape \(3, 3\)"):
        body.flow([0.1, 0.2, 0.3], np.eye(2), 0.1)
    with pytest.raises(phsplit.InvalidInputError, match="h must be finite"):
        body.flow([0.1, 0.2, 0.3], np.eye(3), np.nan)
    assert np.isnan(body.momentum([0.1, 0.2, 0.3], np.nan)).all()


def test_docstring_examples_run():
    result = doctest.testmod(rigid_body, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted >= 10
