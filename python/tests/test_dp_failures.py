"""Thruster failures (``thrusters.unit[i].lost_at``, docs/model.md §5.8), the DP footprint and the
worst single failure (``phsplit.dp``, docs/how-to/dp-failures.md). References: the allocation's
own contract (inside the capacity the delivered surge, sway and yaw are the demand), the
weighted least-norm allocation written again here for the thrusters left, and the ledger."""
from __future__ import annotations

import dataclasses
import subprocess
import sys

import numpy as np
import pytest

import phsplit
from phsplit import dp, scenario

AT = 300.0


@pytest.fixture(scope="module")
def pipelay():
    sc = scenario.load("pipelay")
    return sc, dataclasses.replace(sc.settings, t_span=(0.0, 600.0), save_every=1)


def lose(sc, i, at=AT):
    d = sc.vessel.to_dict()
    d["thrusters"]["unit"][i]["lost_at"] = at
    return phsplit.Vessel.from_dict(d)


def least_norm(units, lost, tau):
    """The weighted least-norm split of tau = (X, Y, N) over the thrusters not lost (extended
    thrust: a tunnel one force along its axis, an azimuth two), each unit's (fx, fy)."""
    cols, owner = [], []
    for i, u in enumerate(units):
        if i in lost:
            continue
        x, y = u["position"][0], u["position"][1]
        dirs = [(1.0, 0.0), (0.0, 1.0)] if u["kind"] == "azimuth" else [
            (np.cos(np.radians(u.get("angle", 90.0))), np.sin(np.radians(u.get("angle", 90.0))))]
        for dx, dy in dirs:
            cols.append([dx, dy, x * dy - y * dx])
            owner.append((i, dx, dy, 1.0 / u.get("weight", 1.0)))
    B = np.array(cols).T
    W = np.diag([o[3] for o in owner])
    f = W @ B.T @ np.linalg.solve(B @ W @ B.T, tau)
    out = {i: np.zeros(2) for i in range(len(units))}
    for fj, (i, dx, dy, _) in zip(f, owner):
        out[i] += fj * np.array([dx, dy])
    return out


def test_a_lost_thruster_is_redistributed_within_a_step(pipelay):
    """The stern azimuth of 655 kN lost at 300 s in the pipe-lay scenario: from the first saved
    state at or after the loss it delivers nothing and reports itself unavailable, the others
    deliver the whole demand (inside their capacity) as the least-norm split over them, the run
    completes, the ledger closes, and the loss is in the written file."""
    sc, st = pipelay
    v = lose(sc, 3)
    s = st.run(v)
    assert s.status == "completed"
    o = s.outputs
    after = s.t >= AT
    assert np.all(o["thruster3_thrust"][2][after] == 0.0)
    assert np.all(o["thruster3_available"][2][after] == 0.0)
    assert np.all(o["thruster3_available"][2][~after] == 1.0)
    assert np.all(o["thruster3_thrust"][2][(s.t > 100.0) & ~after] > 1e5)
    k = int(np.argmax(after))
    for dof in ("surge", "sway", "yaw"):
        np.testing.assert_allclose(o[f"delivered_{dof}"][2][k], o[f"commanded_{dof}"][2][k], rtol=1e-12, atol=1e-6)
    tau = np.array([o[f"commanded_{d}"][2][k] for d in ("surge", "sway", "yaw")])
    want = least_norm(v.to_dict()["thrusters"]["unit"], {3}, tau)
    for i in range(3):
        got = o[f"thruster{i}_thrust"][2][k]
        assert abs(abs(got) - np.linalg.norm(want[i])) < 1e-6 * max(1.0, np.linalg.norm(want[i]))
    assert np.max(s.ledger.relative_residual()) < 1e-9
    ds = s.to_xarray()
    assert float(ds["thruster3_available"].sel(time=ds.time[k]).values) == 0.0


def test_the_worst_single_failure_of_the_pipelay_scenario(pipelay):
    """Each thruster lost in turn at 300 s: every case completes; within their capacity the
    thrusters left hold the vessel exactly as the intact ones do, so the worst failure is the one
    that leaves the least capacity, the 655 kN stern azimuth (utilisation 0.97 against 0.48)."""
    sc, st = pipelay
    study = dp.single_failures(sc.vessel, st, at=AT)
    assert [r["case"] for r in study.rows] == ["intact"] + [f"thruster {i} lost" for i in range(4)]
    assert all(r["status"] == "completed" for r in study.rows)
    intact = study.rows[0]
    for r in study.rows[1:]:
        assert abs(r["max_excursion"] - intact["max_excursion"]) < 1e-6
    assert study.worst["case"] == "thruster 3 lost"
    assert study.worst["utilisation_max"] > 1.9 * intact["utilisation_max"]
    assert "thruster 3 lost" in study.table()


def test_footprint_of_a_station_keeping_run():
    """The footprint's numbers against the saved states they summarise."""
    v = phsplit.Vessel.paper()
    s = phsplit.simulate(v, (0.0, 200.0), 0.5, "sp4", control_start=50.0, save_every=2)
    f = dp.footprint(s, vessel=v, after=100.0)
    keep = s.t >= 100.0
    r = np.hypot(s.x[keep, 0] - 780.0, s.x[keep, 1] - 20.0)
    assert f["max_excursion"] == pytest.approx(r.max())
    assert f["rms_excursion"] == pytest.approx(np.sqrt(np.mean(r ** 2)))
    assert f["max_heading_deviation"] == pytest.approx(np.degrees(np.abs(s.euler[keep, 2] - 0.54).max()))
    assert "utilisation_max" not in f     # no thrusters


def test_the_cli_reports_the_worst_failure():
    r = subprocess.run([sys.executable, "-m", "phsplit", "failures", "pipelay", "--at", "300", "--t-end", "600"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "worst single failure: thruster 3 lost" in r.stdout


def test_a_failure_after_the_run_or_a_dropout_outside_it_is_reported(pipelay):
    """A timed setting the run's span leaves without effect is said (SettingWarning), not dropped
    silently; one inside the span is not warned about."""
    sc, _ = pipelay
    late = lose(sc, 1, at=50.0)
    with pytest.warns(phsplit.SettingWarning, match=r"unit\[1\]\.lost_at = 50 s is after the run's end \(2 s\)"):
        phsplit.simulate(late, (0.0, 2.0), 0.5)
    d = sc.vessel.to_dict()
    d["thrusters"]["unit"][2]["stuck_at"] = 50.0
    with pytest.warns(phsplit.SettingWarning, match=r"unit\[2\]\.stuck_at = 50 s is after the run's end"):
        phsplit.simulate(phsplit.Vessel.from_dict(d), (0.0, 2.0), 0.5)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", phsplit.SettingWarning)
        phsplit.simulate(late, (0.0, 700.0), 0.5)  # lost within the run, the set point moving from 600 s: no warning
    obs = phsplit.load_scenario("dp-observer").vessel.to_dict()
    obs["sensors"]["gnss_dropout"] = [[-50.0, -10.0], [1.0, 1.5]]
    obs["sensors"]["gyro_dropout"] = [[30.0, 40.0]]
    v = phsplit.Vessel.from_dict(obs)
    with pytest.warns(phsplit.SettingWarning) as record:
        phsplit.simulate(v, (0.0, 2.0), 0.5)
    said = [str(w.message) for w in record if issubclass(w.category, phsplit.SettingWarning)]
    assert any("gnss_dropout[0] = [-50, -10] s lies wholly before the run's start" in m for m in said), said
    assert any("gyro_dropout[0] = [30, 40] s lies wholly after the run's end" in m for m in said), said
    assert not any("gnss_dropout[1]" in m for m in said), said


def test_a_stuck_thruster_keeps_its_thrust_and_the_others_take_the_rest(pipelay):
    """The stern azimuth stuck at 300 s (fails as set): from then it keeps the thrust and angle it
    delivered at the end of the step before (saved every step here), reports itself out of the
    allocation, and the others deliver the rest of the demand, tau - tau_stuck, as the
    least-norm split over them (computed again here with numpy); inside the capacity the total
    is the demand. The run completes, the ledger closes, and the vessel carries the memory."""
    sc, st = pipelay
    d = sc.vessel.to_dict()
    d["thrusters"]["unit"][3]["stuck_at"] = AT
    v = phsplit.Vessel.from_dict(d)
    s = st.run(v)
    assert s.status == "completed"
    o = s.outputs
    after = s.t >= AT
    before = int(np.argmax(after)) - 1
    thrust, angle = o["thruster3_thrust"][2], o["thruster3_angle"][2]
    assert thrust[before] > 1e5  # it was working
    np.testing.assert_array_equal(thrust[after], thrust[before])
    np.testing.assert_array_equal(angle[after], angle[before])
    assert np.all(o["thruster3_available"][2][after] == 0.0) and np.all(o["thruster3_available"][2][~after] == 1.0)
    # the demand moves on after the failure, so the stuck thruster is no longer what it asks
    tau_c = np.array([[o[f"commanded_{q}"][2][k] for q in ("surge", "sway", "yaw")] for k in range(len(s.t))])
    units = d["thrusters"]["unit"]
    a = np.radians(angle[before])
    fs = thrust[before] * np.array([np.cos(a), np.sin(a)])
    x3, y3 = units[3]["position"][:2]
    tau_s = np.array([fs[0], fs[1], x3 * fs[1] - y3 * fs[0]])
    checked = 0
    for k in np.flatnonzero(after)[::50]:
        want = least_norm(units, {3}, tau_c[k] - tau_s)
        if max(np.linalg.norm(want[i]) / units[i]["max_thrust"] for i in range(3)) >= 1.0:
            continue  # saturated: scaled, not this check
        for i in range(3):
            got = abs(o[f"thruster{i}_thrust"][2][k])
            assert abs(got - np.linalg.norm(want[i])) < 1e-6 * max(1.0, np.linalg.norm(want[i])), (k, i)
        for q, dof in enumerate(("surge", "sway", "yaw")):
            assert abs(o[f"delivered_{dof}"][2][k] - tau_c[k, q]) <= 1e-9 * max(1.0, abs(tau_c[k, q]))
        checked += 1
    assert checked >= 5
    assert np.max(s.ledger.relative_residual()) < 1e-9
    assert len(s.state(len(s.t) - 1)) > 27  # the thrusters' memory travels with the state
    with pytest.raises(phsplit.InvalidInputError, match=r"unit\[3\]: give lost_at .* or stuck_at .*not both"):
        d["thrusters"]["unit"][3]["lost_at"] = AT
        phsplit.Vessel.from_dict(d)
