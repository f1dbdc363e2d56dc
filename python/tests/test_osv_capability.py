"""DP capability of the OSV preset with its own thrusters (the shipped osv-capability scenario;
docs/how-to/dp-capability.md): intact and each single failure from the loads the core uses, and
the time-domain check of the static limit (phsplit.capability.hold): held at the limit, the
vessel keeps a 5 m watch circle; 10 % beyond it, it does not."""
import os
import subprocess
import sys

import numpy as np
import pytest

import phsplit
from phsplit import scenario
from phsplit.capability import LEVEL1, hold

SHIPPED = os.path.join(os.path.dirname(phsplit.__file__), "scenarios")
WATCH_CIRCLE = 5.0  # m


@pytest.fixture(scope="module")
def vessel(tmp_path_factory):
    """The osv-capability vessel without the fluid memory: the capability needs its drift tables
    and mean loads, not the memory's fit."""
    with open(os.path.join(SHIPPED, "osv-capability.toml"), encoding="utf-8") as f:
        text = f.read()
    assert "fluid_memory = true" in text
    text = text.replace("fluid_memory = true", "fluid_memory = false").replace(
        '"osv_capytaine.nc"', repr(os.path.join(SHIPPED, "osv_capytaine.nc")).replace("'", '"'))
    p = tmp_path_factory.mktemp("osv") / "osv-capability.toml"
    p.write_text(text, encoding="utf-8")
    return scenario.load(str(p)).vessel


@pytest.fixture(scope="module")
def result(vessel):
    return phsplit.capability(vessel)


def test_intact_and_each_single_failure(result):
    assert list(result["case_name"].values) == ["intact"] + [f"thruster {i} lost" for i in range(4)]
    assert result.attrs["wave_drift_included"] == 1
    assert result.attrs["load_accounts"] == "crossflow_current, current, wind"
    u = result["wind_speed_limit"].values
    tol = result.attrs["tolerance_m_s"]
    assert np.all(u[:, 1:] <= u[:, :1] + tol)
    # Intact, the 1.7 MN of osv.m's thrusters hold the table's last row from every direction; a bow
    # tunnel lost halves the bow's sway thrust and the limit falls below it from off the beam.
    assert result["at_table_top"].values[:, 0].all()
    worst = result["worst_failure_wind_speed"].values
    k = int(worst.argmin())
    d = float(result.direction[k])
    assert 45.0 <= d <= 135.0 or 225.0 <= d <= 315.0, d
    assert worst[k] < LEVEL1[-1][1] - 1.0
    assert float(result["utilisation_at_limit"].values[k, 1:].max()) == pytest.approx(1.0, abs=1e-2)


def _worst(result):
    u = result["wind_speed_limit"].values
    i, j = np.unravel_index(np.argmin(np.where(result["at_table_top"].values, np.inf, u)), u.shape)
    lost = [int(x) for x in str(result["case_name"].values[j]).split()[1:2]] if j else []
    return float(result.direction[i]), lost, float(u[i, j])


def test_the_worst_failure_held_at_its_limit_keeps_the_watch_circle_and_ten_percent_more_does_not(vessel, result):
    d, lost, u = _worst(result)
    assert lost, "the worst point is a failure case"
    sol, r = hold(vessel, d, u, lost=lost)
    util = sol.outputs["thrust_utilisation"][2]
    assert sol.status == "completed"
    assert r.max() < 0.2 * WATCH_CIRCLE, r.max()
    assert util.max() > 0.99, util.max()           # at the limit: a thruster works at its capacity
    assert np.all(sol.outputs[f"thruster{lost[0]}_available"][2] == 0.0)
    sol, r = hold(vessel, d, 1.1 * u, lost=lost)
    assert r[-1] > WATCH_CIRCLE, r[-1]
    assert util.max() <= 1.0 + 1e-9 and sol.outputs["thrust_utilisation"][2].max() <= 1.0 + 1e-9


def test_intact_limit_beyond_the_table_is_held_and_ten_percent_more_is_not(vessel):
    """Intact, the limit lies beyond the level-1 table; a table extended by one row (the
    Beaufort-11 sea and current with the wind up to 60 m/s) finds it from the beam."""
    env = [list(r) for r in LEVEL1] + [[12, 60.0, LEVEL1[-1][2], LEVEL1[-1][3], LEVEL1[-1][4]]]
    ds = phsplit.capability(vessel, directions=[90.0], failures="none", environment=env, tolerance=1e-3)
    assert not ds["at_table_top"].values[0, 0]
    u = float(ds["wind_speed_limit"].values[0, 0])
    assert LEVEL1[-1][1] < u < 60.0
    _, r = hold(vessel, 90.0, u, environment=env)
    assert r.max() < 0.2 * WATCH_CIRCLE, r.max()
    _, r = hold(vessel, 90.0, 1.1 * u, environment=env)
    assert r[-1] > WATCH_CIRCLE, r[-1]


@pytest.mark.parametrize("kw, word", [
    (dict(direction=400.0, wind_speed=10.0), "directions"),
    (dict(direction=90.0, wind_speed=-1.0), "wind_speed"),
    (dict(direction=90.0, wind_speed=True), "wind_speed"),
    (dict(direction=90.0, wind_speed=10.0, lost=[7]), "lost"),
    (dict(direction=90.0, wind_speed=10.0, lost="0"), "lost"),
    (dict(direction=90.0, wind_speed=10.0, lost=[0, 0]), "lost"),
    (dict(direction=90.0, wind_speed=10.0, t_end=0.0), "t_end"),
])
def test_bad_hold_arguments_name_the_argument(vessel, kw, word):
    with pytest.raises(phsplit.InvalidInputError, match=word):
        hold(vessel, **kw)


def test_the_command_draws_the_shipped_scenario(tmp_path):
    exe = os.path.join(os.path.dirname(sys.executable), "phsplit")
    out = subprocess.run([exe, "capability", "osv-capability", "--step", "30", "--out", str(tmp_path)],
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert sorted(os.listdir(tmp_path)) == ["osv-capability-capability.nc", "osv-capability-capability.png"]
