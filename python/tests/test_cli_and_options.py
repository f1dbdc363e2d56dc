"""The CLI's main job, scenario files, and the composition options."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

import phsplit
from phsplit.cli import main


def test_default_simulate_writes_netcdf_and_png(tmp_path, capsys):
    assert main(["simulate", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    nc, png = tmp_path / "fig2.nc", tmp_path / "fig2.png"
    assert nc.stat().st_size > 10_000 and png.stat().st_size > 10_000
    assert str(nc) in out and str(png) in out
    with phsplit.open_dataset(nc) as ds:
        assert ds.sizes["time"] == 401
        assert ds.attrs["method"] == "sp4"
        assert abs(float(ds["position"][-1, 0]) - 780.0) < 1.5
    assert not list(tmp_path.glob(".tmp-*")), "temporary files left behind"


def test_scenario_file_runs_instead(tmp_path):
    sc = tmp_path / "short.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 20.0]\nh = 0.25\nmethod = "sp2"\ncontrol_start = 5.0\n')
    assert main(["simulate", str(sc), "--out", str(tmp_path), "--no-plot"]) == 0
    with phsplit.open_dataset(tmp_path / "short.nc") as ds:
        assert ds.sizes["time"] == 81 and ds.attrs["method"] == "sp2"


@pytest.mark.parametrize(
    "text,needle",
    [
        ('[simulation]\nmethdo = "sp2"\n', "did you mean 'method'"),
        ('[simulation]\nh = "fast"\n', "simulation.h"),
        ('[simulation\nh = 1\n', "TOML syntax error"),
        ('[simulation]\nmethod = "rk45"\n', "valid methods"),
    ],
)
def test_bad_scenarios_exit_2_with_one_clear_line(tmp_path, text, needle):
    sc = tmp_path / "bad.toml"
    sc.write_text(text)
    r = subprocess.run([sys.executable, "-m", "phsplit", "simulate", str(sc), "--out", str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    assert needle in r.stderr and "Traceback" not in r.stderr
    assert not list(tmp_path.glob("*.nc"))


def test_help_has_examples():
    r = subprocess.run([sys.executable, "-m", "phsplit", "simulate", "--help"], capture_output=True, text=True)
    assert r.returncode == 0 and "examples:" in r.stdout


@pytest.mark.parametrize("outer", ["dissipative", "conservative"])
def test_either_flow_may_be_outermost(outer):
    """Both arrangements converge at order 2 (SP2, self-convergence against h/8) and close the
    ledger; they differ from each other at O(h^2)."""
    v = phsplit.Vessel.paper()
    ends = [phsplit.simulate(v, (0.0, 4.0), h, "sp2", control_start=0.0, outer=outer).m[-1]
            for h in (0.5, 0.25, 0.0625)]
    e1, e2 = np.linalg.norm(ends[0] - ends[2]), np.linalg.norm(ends[1] - ends[2])
    assert 3.0 < e1 / e2 < 5.5  # ratio of (1 - 1/64)/(1/4 - 1/64) * ... ≈ 4.3 for order 2
    s = phsplit.simulate(v, (0.0, 20.0), 0.5, "sp2", control_start=0.0, outer=outer)
    assert s.ledger.relative_residual().max() < 1e-10


def test_save_every_and_failures_are_reported():
    v = phsplit.Vessel.paper()
    s = phsplit.simulate(v, (0.0, 10.0), 0.5, "sp4", save_every=4)
    assert list(s.t) == [0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
    full = phsplit.simulate(v, (0.0, 10.0), 0.5, "sp4")
    np.testing.assert_allclose(s.x[-1], full.x[-1], rtol=1e-12)
    # RK4 far beyond its stability limit diverges: the run stops with a status, no NaN arrays.
    r = phsplit.simulate(v, (0.0, 2000.0), 4.0, "rk4", control_start=0.0, ledger=False)
    assert r.status == "failed" and "non-finite" in r.failure
    assert np.all(np.isfinite(r.x)) and np.all(np.isfinite(r.last_good_state))
    # ... while SP2 at the same step stays bounded (energy never above its start plus supply).
    s2 = phsplit.simulate(v, (0.0, 2000.0), 4.0, "sp2", control_start=0.0)
    assert s2.status == "completed" and np.all(np.isfinite(s2.energy))


@pytest.mark.parametrize(
    "kwargs,needle",
    [
        ({"h": -1.0}, "h must be"),
        ({"h": float("nan")}, "h must be"),
        ({"t_span": (5.0, 1.0)}, "t1 > t0"),
        ({"outer": "middle"}, "outer must be"),
        ({"save_every": 0}, "save_every"),
        ({"initial": {"euler": [0.0, 0.0]}}, "3 components"),
        ({"initial": {"speed": [0.0, 0.0, 0.0]}}, "allowed"),
    ],
)
def test_bad_arguments_raise_clear_errors(kwargs, needle):
    with pytest.raises(phsplit.InvalidInputError, match=needle):
        phsplit.simulate(phsplit.Vessel.paper(), **kwargs)


def test_bad_vessel_parameters_name_the_field():
    text = phsplit.Vessel.paper_toml().replace("mass = 6.3622085e6", "mass = -1.0")
    with pytest.raises(phsplit.InvalidInputError, match=r"vessel\.mass must be > 0"):
        phsplit.Vessel.from_toml_str(text)
    with pytest.raises(phsplit.ScenarioParseError, match="unknown field"):
        phsplit.Vessel.from_toml_str(phsplit.Vessel.paper_toml().replace("gravity", "gravitty"))


def test_diverging_runs_end_promptly_with_finite_output():
    """A diverging explicit run whose attitude grows huge before it becomes non-finite must
    still be post-processed (quaternions, Euler angles) in finite time: run it in a subprocess
    with a timeout."""
    code = ("import phsplit, numpy as np\n"
            "s = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 3600.0), 0.5, 'euler', control_start=0.0,"
            " save_every=4)\n"
            "print(s.status, len(s.t))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split()[0] in ("failed", "completed")


def test_vector_field_binding_matches_the_independent_model():
    from phsplit import _core
    import reference as ref

    v = phsplit.Vessel.paper()
    y = v.initial_state()
    y[0:3] = [1e6, 2e5, -3e4]
    y[3:6] = [1e6, -2e6, 5e5]
    f = _core.VectorField(v._inner, 0.0)
    g = ref.Field(v.to_dict(), True)
    np.testing.assert_allclose(f(1.0, y), g(1.0, y), rtol=0, atol=1e-13 * np.abs(g(1.0, y)).max())
    # strided input (scipy's Radau passes column views)
    Y = np.stack([y, y], axis=1)
    np.testing.assert_array_equal(f(1.0, Y[:, 0]), f(1.0, y))
    g0 = ref.Field(v.to_dict(), False)
    np.testing.assert_allclose(f(-1.0, y), g0(-1.0, y), rtol=0, atol=1e-13 * np.abs(g0(-1.0, y)).max())


def test_the_compiled_dop853_peer_matches_the_independent_model():
    """The work-precision study's compiled peer (DOP853 in Rust on the compiled field)
    against the numpy model by scipy's DOP853 at rtol 1e-13, across the controller's start, and
    its error falls with its tolerance."""
    from phsplit import _core
    import reference as ref

    v = phsplit.Vessel.paper()
    y0 = v.initial_state()
    _, yr = ref.solve(v.to_dict(), y0, 40.0, 10.0, rtol=1e-13)
    want = yr[-1]
    f = _core.VectorField(v._inner, 10.0)
    scale = np.maximum(np.abs(y0), 1.0)
    errs = []
    for rtol in (1e-5, 1e-8, 1e-11):
        y, nfev, steps = f.solve_dop853((0.0, 40.0), y0, rtol, rtol * scale * 1e-3)
        errs.append(np.linalg.norm(y[0:6] - want[0:6]) / np.linalg.norm(want[0:6]))
        assert nfev >= 11 * steps > 0
    assert errs[2] < 1e-8 and errs[0] > errs[1] > errs[2], errs
    with pytest.raises(phsplit.InvalidInputError, match="t_span"):
        f.solve_dop853((5.0, 1.0), y0, 1e-6, np.array([1e-9]))
    bad = y0.copy()
    bad[4] = np.nan
    with pytest.raises(phsplit.InvalidInputError, match="entry 4"):
        f.solve_dop853((0.0, 1.0), bad, 1e-6, np.array([1e-9]))


def test_no_compiled_field_for_a_vessel_whose_components_keep_states():
    """The compiled field is the 27 states' (eq. 39): for a vessel with a dynamic pipe (states of
    its own) it is refused by name when made, not failed inside when called."""
    from phsplit import _core

    v = phsplit.scenario.load(phsplit.scenario.resolve("pipelay-dynamic")).vessel
    with pytest.raises(phsplit.InvalidInputError, match="pipe.*states of its own"):
        _core.VectorField(v._inner, 0.0)


def test_chunked_cli_output_equals_one_simulate_call(tmp_path):
    assert main(["simulate", "--out", str(tmp_path), "--no-plot", "--save-every", "3"]) == 0
    s = phsplit.simulate(phsplit.Vessel.paper(), save_every=3, linear_flow="exact")  # the Fig. 2 scenario's
    with phsplit.open_dataset(tmp_path / "fig2-s3.nc") as ds:  # the command-line option is in the name
        np.testing.assert_array_equal(ds["time"].values, s.t)
        np.testing.assert_array_equal(ds["position"].values, s.x)
        np.testing.assert_array_equal(ds["energy_dissipated"].values, s.ledger.dissipated)
        assert ds.attrs["status"] == "completed"


def test_sigterm_during_simulate_leaves_a_valid_file_with_the_steps_so_far(tmp_path):
    import signal
    import time

    p = subprocess.Popen([sys.executable, "-m", "phsplit", "simulate", "--out", str(tmp_path), "--no-plot",
                          "--t-end", "400000", "--h", "0.05", "--save-every", "200", "--linear-flow", "gauss"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    name = "fig2-h0.05-t400000-s200-gauss"  # the command-line options are in the name
    parts = lambda: list(tmp_path.glob(f".{name}.nc.part"))  # noqa: E731 - the locked temporary file
    deadline = time.monotonic() + 120
    while not parts():
        assert p.poll() is None, p.communicate()
        assert time.monotonic() < deadline
        time.sleep(0.05)
    time.sleep(1.5)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert "interrupted after" in err
    assert not parts()
    with phsplit.open_dataset(tmp_path / f"{name}.nc") as ds:
        assert ds.attrs["status"] == "interrupted"
        n = ds.sizes["time"]
        assert 1 < n < 400000 / 0.05 / 200 + 1
        t = ds["time"].values
        assert np.all(np.diff(t) > 0) and np.isclose(t[1] - t[0], 10.0)
        assert np.all(np.isfinite(ds["position"].values))
        assert ds.attrs["steps"] == round(t[-1] / 0.05)


def test_passivity_warning_only_when_energy_is_created():
    import warnings

    v = phsplit.Vessel.paper()
    with warnings.catch_warnings():
        warnings.simplefilter("error", phsplit.PassivityWarning)
        phsplit.simulate(v, (0.0, 200.0), 0.5, "sp4", control_start=50.0)  # dissipates in every step
    with pytest.warns(phsplit.PassivityWarning, match="Prop. 2.5"):
        phsplit.simulate(v, (0.0, 200.0), 40.0, "sp6", control_start=50.0)
