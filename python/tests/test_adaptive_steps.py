"""Adaptive steps for the splitting methods (``rtol``, ``atol``; ``solve/adaptive.rs``): step
doubling with a PI controller, every accepted step two ordinary steps of the method.

References are independent of the code under test: the paper's vessel written again in numpy
(``reference.py``) and solved by scipy's DOP853 at rtol 1e-12."""
from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import phsplit
from phsplit import results

import reference as ref

V = phsplit.Vessel.paper()
Y0 = V.initial_state()
T_END = 400.0
TS = np.arange(20.0, T_END + 1e-9, 20.0)


@pytest.fixture(scope="module")
def exact_positions() -> np.ndarray:
    """The position at TS of the independent model, DP on from t = 0."""
    f = ref.Field(V.to_dict(), True)
    scale = np.maximum(np.abs(Y0), 1.0)
    sol = solve_ivp(f, (0.0, T_END), Y0, method="DOP853", rtol=1e-12, atol=1e-12 * scale, t_eval=TS)
    assert sol.success
    return sol.y[18:21].T


def _adaptive(method: str, tol: float, **kw) -> phsplit.Solution:
    return phsplit.simulate(V, (0.0, T_END), 0.5, method, control_start=0.0, rtol=tol, atol=tol, save_at=TS, **kw)


@pytest.mark.parametrize("method, p, outer", [("sp2", 2, "dissipative"), ("sp4", 4, "dissipative"),
                                              ("sp2", 2, "conservative")])
def test_the_error_falls_with_the_tolerance_against_an_independent_model(exact_positions, method, p, outer):
    """Error-per-step control: the global error ~ tol^(p/(p+1)) (fitted slope), falling and below 20 tol at
    each tolerance (40 tol with S1 outermost, whose splitting error is the larger at the same steps: measured
    2.6 tol at 1e-2 to 25 tol at 1e-5), and the runs land on every output time exactly."""
    tols = np.array([1e-2, 1e-3, 1e-4, 1e-5])
    errs = []
    for tol in tols:
        sol = _adaptive(method, tol, outer=outer)
        assert sol.status == "completed"
        np.testing.assert_array_equal(sol.t, TS)  # exactly the rows asked for, as with fixed steps
        errs.append(float(np.linalg.norm(sol.x - exact_positions, axis=1).max()))
    errs = np.array(errs)
    slope = np.polyfit(np.log(tols), np.log(errs), 1)[0]
    assert 0.4 < slope < 1.2, (slope, errs)
    bound = 20 if outer == "dissipative" else 40
    assert np.all(np.diff(errs) < 0) and np.all(errs < bound * tols), errs


def test_every_saved_interval_balances_its_ledger_and_dissipates():
    """Each accepted step is two positive steps of SP2: ΔH = supplied − dissipated per saved
    interval to round-off, and the damping's booking is never negative."""
    sol = phsplit.simulate(V, (0.0, 600.0), 0.5, "sp2", control_start=50.0, atol=1e-3)
    led = sol.ledger
    resid = np.abs(led.dH - (led.supplied - led.dissipated))[1:]
    assert resid.max() < 1e-10 * np.abs(sol.energy).max(), resid.max()
    assert np.all(led.by_account["damping"][1:] >= 0.0)
    assert sol.meta["rejected"] >= 0 and sol.steps == len(sol.t) - 1


def test_steps_land_on_the_controller_switch_and_lengthen_when_settled():
    sol = phsplit.simulate(V, (0.0, 3600.0), 0.5, "sp4", control_start=50.0, atol=1e-3)
    assert 50.0 in sol.t  # the switch is a step boundary, not the next one after it
    dt = np.diff(sol.t)
    early = np.median(dt[(sol.t[:-1] > 50.0) & (sol.t[:-1] < 200.0)])
    late = np.median(dt[sol.t[:-1] > 3000.0])
    assert late > 3 * early, (early, late)
    assert sol.steps < 3600 / 0.5 / 4


def test_h_max_bounds_the_steps_and_the_result_says_what_ran():
    sol = phsplit.simulate(V, (0.0, 300.0), 0.5, "sp2", control_start=0.0, atol=1e-2, h_max=4.0)
    assert np.diff(sol.t).max() <= 4.0 + 1e-12
    ds = sol.to_xarray()
    assert ds.attrs["step_size_s"] == "adaptive" and ds.attrs["atol"] == 1e-2 and ds.attrs["rtol"] == 1e-3
    assert ds.attrs["rejected_steps"] == sol.meta["rejected"]
    settings = results.settings_of(ds)
    assert (settings.atol, settings.rtol, settings.h_max) == (1e-2, None, 4.0)


def test_a_scenario_with_a_tolerance_runs_from_the_cli_and_reruns_bit_for_bit(tmp_path):
    (tmp_path / "a.toml").write_text('[simulation]\nt_span = [0.0, 200.0]\nh = 0.5\nmethod = "sp4"\n'
                                     'control_start = 0.0\natol = 1e-4\nname = "a"\n')
    exe = os.path.join(os.path.dirname(sys.executable), "phsplit")
    r = subprocess.run([exe, "simulate", "a.toml", "--out", "out", "--no-plot", "--h-max", "10"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    (f,) = (tmp_path / "out").iterdir()
    ds = results.open_dataset(f)
    assert ds.attrs["atol"] == 1e-4 and np.diff(ds["time"].values.astype(float)).max() <= 10.0 + 1e-9
    assert results.compare(ds, results.rerun(ds)) == []


def test_steps_land_on_the_sensors_samples_and_on_a_thruster_loss():
    """A sampled-data loop: with GNSS at 1 Hz and a gyro at 2 Hz the adaptive steps end on every
    sample instant (the samples are taken where they are due, not at a later step end), and on
    the time a thruster is lost."""
    d = phsplit.Vessel.paper().to_dict()
    d["control"]["feedback"] = "observer"
    d["observer"] = {"wave_frequency": 0.7, "damping": [3.53933789e4, 1.1781388e5, 3.15094664584e8],
                     "initial_estimate": [790.0, 28.0, 0.6]}
    d["sensors"] = {"gnss_rate": 1.0, "gyro_rate": 2.0, "gnss_noise": 0.5, "gyro_noise": 0.002, "seed": 3}
    sol = phsplit.simulate(phsplit.Vessel.from_dict(d), (0.0, 60.0), 0.5, "sp4", control_start=0.0, atol=1e-2)
    assert sol.status == "completed"
    assert set(np.arange(0.0, 60.01, 0.5)) <= set(np.round(sol.t, 9))
    from phsplit import scenario

    sc = scenario.load("pipelay")
    d = sc.vessel.to_dict()
    d["thrusters"]["unit"][0]["lost_at"] = 123.4
    sol = phsplit.simulate(phsplit.Vessel.from_dict(d), (0.0, 200.0), 0.5, "sp2", control_start=0.0, atol=1e-2)
    assert sol.status == "completed" and 123.4 in sol.t


@pytest.mark.parametrize("outer", ["dissipative", "conservative"])
def test_save_at_rows_keep_the_ledger_between_them(outer):
    """The rows asked for, and the energy booked between consecutive ones summed over the steps
    between them: ΔH = supplied − dissipated per row to round-off, with either flow outermost."""
    ts = np.arange(60.0, 601.0, 60.0)
    sol = phsplit.simulate(V, (0.0, 600.0), 0.5, "sp2", control_start=0.0, atol=1e-3, save_at=ts, outer=outer)
    np.testing.assert_array_equal(sol.t, ts)
    assert np.max(sol.ledger.relative_residual()) < 1e-12
    assert sol.ledger.dH[0] == 0.0 and np.all(sol.ledger.by_account["damping"][1:] > 0.0)


def test_events_on_adaptive_steps_against_an_independent_model():
    """The paper's vessel entering a 30 m circle about its set point (DP on from t = 0): the
    crossing time of adaptive SP2 against scipy's DOP853 event on the independent numpy model,
    closer at the tighter tolerance; the run ends there with its ledger closed; a non-terminal
    event is recorded and the run goes on to the end, saving every accepted step."""
    f = ref.Field(V.to_dict(), True)
    xr = f.xr

    def inside(t, y):
        return np.hypot(y[18] - xr[0], y[19] - xr[1]) - 30.0

    inside.terminal, inside.direction = True, -1
    scale = np.maximum(np.abs(Y0), 1.0)
    exact = solve_ivp(f, (0.0, 200.0), Y0, method="DOP853", rtol=1e-12, atol=1e-12 * scale, events=inside)
    t_exact = float(exact.t_events[0][0])
    errs = []
    for tol in (1e-3, 1e-6):
        sol = phsplit.simulate(V, (0.0, 200.0), 0.5, "sp2", control_start=0.0, rtol=tol, atol=tol,
                               events=[phsplit.events.watch_circle(30.0, direction="enter")])
        assert sol.status == "event" and sol.t[-1] == sol.meta["events"][0].t
        errs.append(abs(sol.t[-1] - t_exact))
        assert np.hypot(*(sol.x[-1, :2] - xr[:2])) == pytest.approx(30.0, abs=1e-9)
        assert np.max(sol.ledger.relative_residual()) < 1e-10
    assert errs[1] < errs[0] and errs[1] < 1e-5, (errs, t_exact)
    marked = phsplit.simulate(V, (0.0, 200.0), 0.5, "sp2", control_start=0.0, atol=1e-4,
                              events=[phsplit.events.watch_circle(30.0, direction="enter", terminal=False)])
    plain = phsplit.simulate(V, (0.0, 200.0), 0.5, "sp2", control_start=0.0, atol=1e-4)
    assert marked.status == "completed" and len(marked.meta["events"]) == 1
    np.testing.assert_array_equal(marked.t, plain.t)
    assert abs(marked.meta["events"][0].t - t_exact) < 1e-2


def test_states_between_an_adaptive_runs_rows_follow_its_tolerance(exact_positions):
    """``Solution.at`` on an adaptive run steps adaptively, to the run's tolerance, from the last
    saved state: against the independent model the error falls with the tolerance and stays
    below 20·tol (as the run's own rows do)."""
    errs = []
    for tol in (1e-3, 1e-5):
        sol = phsplit.simulate(V, (0.0, T_END), 0.5, "sp2", control_start=0.0, rtol=tol, atol=tol)
        assert not np.isin(TS, sol.t).all()  # the times asked for are not all rows of the run
        at = sol.at(TS)
        np.testing.assert_array_equal(at.t, TS)
        errs.append(float(np.linalg.norm(at.x - exact_positions, axis=1).max()))
        assert errs[-1] < 20 * tol, (tol, errs)
    assert errs[1] < errs[0] / 10, errs
