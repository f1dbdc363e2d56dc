"""Viscous roll damping, ``[roll_damping]``: the roll moment ``-B1 p - B2 |p| p`` (ITTC 7.5-02-07-04.5;
docs/explanation/components/roll-damping.md). References: the paper's vessel in pure roll is one
degree of freedom, ``I44 phi'' + (Dr + B1) phi' + B2 |phi'| phi' + W GM_T sin(phi) cos(phi) = 0``
(its restoring store is ``1/2 W GM_T sin^2 phi``, docs/model.md §2.3; its inertia is diagonal and
its centre of gravity at the origin, so nothing else moves), solved here by DOP853 at rtol 1e-12;
the logarithmic decrement of a linear oscillator, ``exp(-2 pi zeta / sqrt(1 - zeta^2))`` a period;
and the ledger's own balance."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import phsplit
from checks import within_passivity_bound

ZETA, B2 = 0.05, 4.0e9   # 5 % of critical; B2 in N m s^2 (kg m^2)


def vessel(table, own_roll_damping=None):
    d = phsplit.Vessel.paper().to_dict()
    if own_roll_damping is not None:
        d["vessel"]["damping_rotational"][0] = own_roll_damping
    d["roll_damping"] = table
    return phsplit.Vessel.from_dict(d)


def one_dof(p, table, phi0, t_end, t_eval):
    """The pure-roll equation by DOP853, with the booked dissipation as a third state."""
    W = p["mass"] * p["gravity"]
    c44 = W * p["gm_transverse"]
    i44 = p["inertia"][0]
    b1 = table.get("linear", 2 * table.get("critical_fraction", 0.0) * math.sqrt(i44 * c44))
    b2 = table.get("quadratic", 0.0)
    d0 = p["damping_rotational"][0]

    def f(_t, y):
        phi, r, _ = y
        m = -(d0 + b1) * r - b2 * abs(r) * r - c44 * math.sin(phi) * math.cos(phi)
        return [r, m / i44, b1 * r * r + b2 * abs(r) ** 3]

    sol = solve_ivp(f, (0.0, t_end), [phi0, 0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-15, t_eval=t_eval)
    return sol.y


def run(v, phi0, t_end, h, method="sp4", **kw):
    y0 = v.initial_state(euler=[phi0, 0.0, 0.0], position=[0.0, 0.0, 0.0])
    return phsplit.simulate(v, (0.0, t_end), h, method, control_start=None, initial=y0, **kw)


def test_roll_decay_is_the_one_degree_of_freedom_equation():
    """Linear (from the critical fraction) and quadratic parts: SP4 at h = 0.05 s against the
    1-DOF equation over 120 s from 10 degrees, the roll and the booked energy."""
    table = {"critical_fraction": ZETA, "quadratic": B2}
    v = vessel(table)
    s = run(v, math.radians(10.0), 120.0, 0.05, save_every=20)
    phi, _, booked = one_dof(v.to_dict()["vessel"], table, math.radians(10.0), 120.0, s.t)
    assert np.max(np.abs(s.euler[:, 0] - phi)) < 1e-7
    assert np.max(np.abs(s.x)) < 1e-9 and np.max(np.abs(s.euler[:, 1:])) < 1e-9   # pure roll
    got = np.cumsum(s.ledger.by_account["roll_damping"])
    assert np.max(np.abs(got - booked)) < 1e-7 * booked[-1], (got[-1], booked[-1])
    assert s.ledger.relative_residual().max() < 1e-10
    assert s.ledger.by_account["roll_damping"][1:].min() >= 0
    assert within_passivity_bound(s)


@pytest.mark.parametrize("method,order,hs", [("sp2", 2, [0.4, 0.2, 0.1, 0.05]), ("sp4", 4, [1.0, 0.5, 0.25, 0.125])])
def test_orders_against_the_one_degree_of_freedom_equation(method, order, hs):
    """The largest roll error over 20 s from 8 degrees, sampled each second; the runs keep the
    paper's scheme (no projection onto the restoring invariant), as the reference has none."""
    table = {"linear": 2.0e7, "quadratic": B2}
    v = vessel(table)
    te = np.arange(0.0, 20.0 + 1e-9, 1.0)
    ref = one_dof(v.to_dict()["vessel"], table, math.radians(8.0), 20.0, te)[0]
    errs = [np.max(np.abs(run(v, math.radians(8.0), 20.0, h, method, ledger=False, project_invariants=False,
                              save_at=te).euler[:, 0] - ref)) for h in hs]
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - order) < 0.2, (slope, errs)


def test_the_critical_fraction_is_the_logarithmic_decrement():
    """Linear only, the vessel's own roll damping zeroed, from 0.5 degrees (where sin cos is the
    linear spring to 1e-4): successive maxima a period apart fall by exp(-2 pi zeta / sqrt(1 - zeta^2))."""
    v = vessel({"critical_fraction": ZETA}, own_roll_damping=0.0)
    s = run(v, math.radians(0.5), 60.0, 0.01, save_every=1)
    phi = s.euler[:, 0]
    peaks = [i for i in range(1, len(phi) - 1) if phi[i - 1] < phi[i] >= phi[i + 1] and phi[i] > 0]
    ratios = phi[peaks[1:]] / phi[peaks[:-1]]
    want = math.exp(-2 * math.pi * ZETA / math.sqrt(1 - ZETA ** 2))
    assert len(ratios) >= 3
    assert np.max(np.abs(ratios / want - 1)) < 2e-3, (ratios, want)


def test_linear_only_keeps_the_exact_linear_flow():
    """Without a quadratic part the component is linear: the exact S2 runs (no collocation), and
    the result is the collocated one to the method's accuracy."""
    v = vessel({"linear": 2.0e7})
    a = run(v, 0.1, 30.0, 0.1, linear_flow="exact")
    b = run(v, 0.1, 30.0, 0.1, linear_flow="gauss")
    assert abs(a.euler[-1, 0] - b.euler[-1, 0]) < 1e-6
    assert a.ledger.relative_residual().max() < 1e-10


@pytest.mark.parametrize("table,needle", [
    ({"linear": 1e7, "critical_fraction": 0.05}, "not both"),
    ({"critical_fraction": 1.0}, "roll_damping.critical_fraction must be in [0, 1)"),
    ({"quadratic": -1.0}, "roll_damping.quadratic"),
    ({}, "[roll_damping] needs"),
    ({"linear": 0.0}, "[roll_damping] needs"),
    ({"linear": "big"}, "roll_damping.linear must be a number"),
    ({"lineer": 1e7, "quadratic": 1.0}, "lineer"),
])
def test_bad_tables_are_refused_naming_the_key(table, needle):
    with pytest.raises(phsplit.InvalidInputError) as e:
        vessel(table)
    assert needle in str(e.value), str(e.value)
    assert "\n" not in str(e.value)


def test_regular_wave_roll_against_the_equivalent_linear_damping():
    """Beam seas of 0.1 m on the paper's vessel with the box's fluid memory, about its roll
    resonance: the time-domain roll amplitude with B1 and B2 against the frequency domain with
    the harmonic equivalent damping B1 + (8/3 pi) omega phi_a B2 (iterated on phi_a), within 5 %;
    the quadratic part cuts the resonant roll by more than half."""
    d = phsplit.Vessel.paper().to_dict()
    plain = phsplit.rao(phsplit.Vessel.from_dict(d), [0.56], heading=90.0, amplitude=0.1, dofs=("roll",))
    d["roll_damping"] = {"critical_fraction": 0.02, "quadratic": B2}
    ds = phsplit.rao(phsplit.Vessel.from_dict(d), [0.44, 0.56, 0.68], heading=90.0, amplitude=0.1, dofs=("roll",))
    assert np.max(np.abs(ds.roll_deviation.values)) < 0.05, ds.roll_deviation.values
    assert float(ds.roll_amplitude[1]) < 0.5 * float(plain.roll_amplitude[0])
    assert np.all(ds.ledger_residual.values < 1e-10)
