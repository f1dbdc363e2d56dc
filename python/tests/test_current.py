"""A uniform ocean current, through the relative velocity in the
damping. References: closed forms (steady drift with the current; the integral action that
holds position against it) and the independent numpy model (tests/reference.py) by DOP853."""
from __future__ import annotations

import numpy as np
import pytest

import phsplit
from checks import fitted_order

VC = [0.4, -0.3, 0.0]  # m/s, spatial: towards +x and -y


def with_current(velocity=VC):
    d = phsplit.Vessel.paper().to_dict()
    d["current"] = {"velocity": list(velocity)}
    return phsplit.Vessel.from_dict(d)


def test_without_control_the_vessel_drifts_with_the_current():
    """m v' = -D_t (v - Q^T V_c) horizontally: the spatial velocity tends to V_c (time constants
    mv/D_t = 180 s and 54 s), the heading stays."""
    v = with_current()
    s = phsplit.simulate(v, (0.0, 5000.0), 0.5, "sp2", control_start=None, save_every=100)
    vel = np.einsum("ij,j->i", s.Q[-1], s.v[-1])
    np.testing.assert_allclose(vel[:2], VC[:2], rtol=0, atol=1e-9)
    assert s.ledger.by_account["current"][1:].sum() > 0  # the current did work on the vessel
    assert np.all(s.ledger.relative_residual() < 1e-10)


def test_the_controller_holds_position_against_the_current():
    """At rest at the set point, the integral action balances the current's drag: the
    controller's spatial force -Ki phi_x cancels the drag Q D_t Q^T V_c, so Ki phi_x equals the
    drag (x, y), as for a constant external force (test_external.py)."""
    v = with_current()
    d = v.to_dict()
    s = phsplit.simulate(v, (0.0, 8000.0), 1.0, "sp2", control_start=0.0, linear_flow="gauss", save_every=100)
    ki = np.array(d["control"]["ki_translational"])
    xr = np.array(d["control"]["position_reference"])
    # the drag force in the spatial frame: D_t acts in the body frame on the current's components
    Q = s.Q[-1]
    drag_spatial = Q @ (np.array(d["vessel"]["damping_translational"]) * (Q.T @ np.array(VC)))
    np.testing.assert_allclose(ki[:2] * s.phi_x[-1, :2], drag_spatial[:2], rtol=1e-3)
    assert np.linalg.norm(s.x[-1, :2] - xr[:2]) < 1e-2


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_the_current_against_the_independent_model(method, order):
    v = with_current()
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]  # moving, so the relative velocity matters
    slope, errs, y_end = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    xe = y_end[18:21]
    assert abs(slope - order) < 0.2, (slope, errs)
    s = phsplit.simulate(v, (0.0, 2.0), 2.0**-5, method, control_start=0.0, ledger=False, initial=y0,
                         linear_flow="exact")
    assert np.linalg.norm(s.x[-1] - xe) < 1e-5


def test_the_ledger_books_the_current_as_a_port_and_closes():
    v = with_current()
    assert ("current", "supplied") in v.accounts
    for method, lf in (("lie", "exact"), ("sp2", "exact"), ("sp2", "gauss")):
        s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=20.0, linear_flow=lf)
        assert np.all(s.ledger.relative_residual() < 1e-10), (method, lf)
        assert np.all(s.ledger.dissipated[1:] >= 0)  # positive steps: passive with respect to the ports


def test_bad_current_tables():
    base = phsplit.Vessel.paper().to_dict()
    for table, words in (({"velocity": [1.0, 2.0]}, "3 numbers"), ({"velocity": [0.0, float("nan"), 0.0]}, "finite"),
                         ({"velocity": [12.0, 0.0, 0.0]}, "10 m/s"), ({"speed": 1.0}, r"current.speed needs exactly one of current.direction"),
                         ({"sped": 1.0}, r"unknown field `sped` in \[current\]")):
        d = dict(base, current=table)
        with pytest.raises(phsplit.InvalidInputError, match=words):
            phsplit.Vessel.from_dict(d)


def test_a_scenario_file_adds_a_current(tmp_path, capsys):
    from phsplit.cli import main

    sc = tmp_path / "current.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 60.0]\nh = 0.5\nmethod = "sp2"\n\n[current]\nvelocity = [0.5, 0.0, 0.0]\n')
    assert phsplit.load_scenario(str(sc)).vessel.components[-1] == "current"
    assert main(["simulate", str(sc), "--out", str(tmp_path), "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "current supplied" in out and "components: damping, restoring, pid, current" in out


def with_current_table():
    d = phsplit.Vessel.paper().to_dict()
    d["current"] = {"times": [0.0, 1.0, 600.0], "velocities": [[0.0, 0.0, 0.0], [0.2, -0.1, 0.0], [0.5, 0.2, 0.0]]}
    return phsplit.Vessel.from_dict(d)


def test_a_current_time_table_drifts_the_vessel_to_its_last_row():
    """After the table's last row the current stays there: controller off, the spatial velocity
    tends to it (closed form, as for a constant current)."""
    s = phsplit.simulate(with_current_table(), (0.0, 6000.0), 0.5, "sp2", control_start=None, save_every=200)
    vel = np.einsum("ij,j->i", s.Q[-1], s.v[-1])
    np.testing.assert_allclose(vel[:2], [0.5, 0.2], rtol=0, atol=1e-9)
    assert np.all(s.ledger.relative_residual() < 1e-10)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_a_current_time_table_against_the_independent_model(method, order):
    """The table shifted by -0.2 s: its rows at -0.2, 0.8 and 599.8 s. The current's slope jumps at
    0.8 s, which h = 0.8 / 2^k puts on the step grid (a kink inside a step would cost order)."""
    v = with_current_table()
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]
    d = v.to_dict()
    d["current"] = {"times": [t - 0.2 for t in d["current"]["times"]], "velocities": d["current"]["velocities"]}
    slope, errs, _ = fitted_order(phsplit.Vessel.from_dict(d), y0, method, 0.8 / 2.0 ** np.arange(0, 5))
    assert abs(slope - order) < 0.2, (slope, errs)


def test_bad_current_time_tables():
    base = phsplit.Vessel.paper().to_dict()
    for table, words in (({"times": [0.0, 1.0]}, "needs both"),
                         ({"times": [0.0, 0.0], "velocities": [[0, 0, 0], [1, 0, 0]]}, "increase strictly"),
                         ({"times": [0.0], "velocities": [[12.0, 0, 0]]}, r"current.velocities\[0\]\[0\] must be within"),
                         ({"times": [0.0], "velocities": [[1.0, 0, 0]], "velocity": [1.0, 0, 0]}, "not both")):
        with pytest.raises(phsplit.InvalidInputError, match=words):
            phsplit.Vessel.from_dict(dict(base, current=table))


def test_a_vessel_files_current_by_speed_and_direction_in_either_convention():
    """[current] speed with direction / direction_towards (where it flows) or direction_from
    (where it comes from), degrees from x towards y: the velocity written out, recorded as
    `velocity` in the normalised file (which reads back the same); the two conventions half a
    turn apart; bad combinations refused naming the keys."""
    import math

    def current(table):
        d = phsplit.Vessel.paper().to_dict()
        d["current"] = table
        return phsplit.Vessel.from_dict(d)

    want = [0.5 * math.cos(math.radians(190.0)), 0.5 * math.sin(math.radians(190.0)), 0.0]
    for table in ({"speed": 0.5, "direction": 190.0}, {"speed": 0.5, "direction_towards": 190.0},
                  {"speed": 0.5, "direction_from": 10.0}):
        v = current(table)
        got = v.to_dict()["current"]
        assert set(got) == {"velocity"}
        assert np.allclose(got["velocity"], want, rtol=0, atol=1e-15), (table, got)
        assert phsplit.Vessel.from_toml_str(v.to_toml()).to_dict()["current"] == got
    for table, words in [({"speed": 0.5}, "exactly one of current.direction"),
                         ({"direction": 3.0}, "current.direction gives the direction of current.speed"),
                         ({"speed": 0.5, "direction": 1.0, "direction_from": 2.0}, "got direction and direction_from"),
                         ({"speed": -1.0, "direction": 0.0}, "current.speed must be within 0 to 10 m/s"),
                         ({"speed": 0.5, "direction": 0.0, "velocity": [0.1, 0.0, 0.0]}, "either velocity"),
                         ({"speed": 0.5, "direction": 1000.0}, "within ±360 degrees")]:
        with pytest.raises(phsplit.InvalidInputError, match=words):
            current(table)
