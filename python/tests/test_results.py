"""Files people can use. Every NetCDF file phsplit writes passes the IOOS
compliance checker's CF-1.8 test with no errors and no warnings; a file records what reruns it,
and `phsplit rerun` reproduces it to the last bit; `phsplit.open_dataset` round-trips every
variable and attribute."""
from __future__ import annotations

import contextlib
import io
import json
import os

import numpy as np
import pytest

import phsplit
from phsplit.cli import main


def cf_problems(path) -> list[str]:
    """The errors and warnings of `compliance-checker --test cf:1.8` on ``path``."""
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite().load_all_available_checkers()
    out = str(path) + ".cf.json"
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
        ComplianceChecker.run_checker(str(path), ["cf:1.8"], 0, "normal", output_filename=out, output_format="json")
    with open(out) as f:
        r = json.load(f)["cf:1.8"]
    os.unlink(out)
    bad = [f"{p['name']}: {m}" for p in r["all_priorities"] if p["weight"] >= 2 for m in p["msgs"]]
    assert (r["high_count"] + r["medium_count"] == 0) == (not bad) or bad, r
    assert "exceptions occurred" not in buf.getvalue(), buf.getvalue()
    return bad


@pytest.fixture(scope="module")
def cli_file(tmp_path_factory):
    """A chunked CLI run (three calls of the core) with a scenario file and an external load."""
    d = tmp_path_factory.mktemp("cli")
    sc = d / "pushed.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 1500.0]\nh = 0.05\nmethod = "sp2"\ncontrol_start = 10.0\n'
                  'save_every = 9\n\n[external]\nforce = [1.0e5, 0.0, 0.0]\npoint = [-40.0, 0.0, 3.0]\n')
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["simulate", str(sc), "--out", str(d), "--no-plot"]) == 0
    return d / "pushed.nc", sc


def test_the_cli_file_is_cf_compliant(cli_file):
    assert cf_problems(cli_file[0]) == []


def test_api_sweep_and_batch_files_are_cf_compliant(tmp_path):
    v = phsplit.Vessel.paper()
    sol = phsplit.simulate(v, (0.0, 20.0), 0.5, "sp4", control_start=0.0)
    sol.to_xarray().to_netcdf(tmp_path / "api.nc")
    assert cf_problems(tmp_path / "api.nc") == []
    ds = phsplit.simulate_many([{"vessel.mass": 6e6}, {"vessel.mass": -1.0}], settings=phsplit.Settings(
        t_span=(0.0, 10.0), h=0.5, method="sp2"))
    ds.to_netcdf(tmp_path / "many.nc")
    assert cf_problems(tmp_path / "many.nc") == []
    from phsplit.batch import _write_case, write_summary

    os.makedirs(tmp_path / "store" / "cases")
    _write_case(str(tmp_path / "store"), "case_00000_x", {"status": "completed", "case": {"vessel.mass": 6e6},
                                                          "summary": {"energy_final_J": 1.0}, "dataset": sol.to_xarray()})
    _write_case(str(tmp_path / "store"), "case_00001_y", {"status": "invalid", "error": "bad", "case": {"vessel.mass": -1.0}})
    write_summary(str(tmp_path / "store"), ["case_00000_x", "case_00001_y"])
    for f in ("cases/case_00000_x.nc", "cases/case_00001_y.nc", "summary.nc"):
        assert cf_problems(tmp_path / "store" / f) == [], f


def test_rerun_reproduces_the_cli_file_to_the_last_bit(cli_file):
    path, sc = cli_file
    with phsplit.open_dataset(path) as ds:
        chunks = [int(c) for c in ds.attrs["phsplit_chunks"].split()]
        assert len(chunks) == 2 and sum(chunks) == 30000 and chunks[0] % 9 == 0
        assert ds.attrs["phsplit_scenario"] == sc.read_text()
        assert ds.attrs["phsplit_scenario_path"] == str(sc)
        assert phsplit.results.compare(ds, phsplit.rerun(ds)) == []
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["rerun", str(path)]) == 0
    assert "identical" in out.getvalue()


def test_rerun_detects_a_changed_number(cli_file, tmp_path):
    import netCDF4

    path, _ = cli_file
    bad = tmp_path / "changed.nc"
    bad.write_bytes(path.read_bytes())
    with netCDF4.Dataset(bad, "a") as f:
        f.variables["position"][7, 0] = f.variables["position"][7, 0] + 1e-9
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        assert main(["rerun", str(bad)]) == 1
    assert "position" in err.getvalue()


def test_open_dataset_round_trips_every_variable_and_attribute(tmp_path):
    sol = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 10.0), 0.5, "sp2", control_start=2.0, save_every=3)
    ds = sol.to_xarray()
    ds.to_netcdf(tmp_path / "r.nc")
    with phsplit.open_dataset(tmp_path / "r.nc") as back:
        assert set(back.variables) == set(ds.variables)
        for name in ds.variables:
            np.testing.assert_array_equal(back[name].values, ds[name].values, err_msg=name)
            assert back[name].attrs == ds[name].attrs, name
        for k, v in ds.attrs.items():
            assert np.all(back.attrs[k] == v), k
        # and what it records rebuilds the run
        assert phsplit.results.vessel_of(back).to_toml() == phsplit.Vessel.paper().to_toml()
        assert phsplit.results.settings_of(back) == phsplit.Settings(
            t_span=(0.0, 10.0), h=0.5, method="sp2", control_start=2.0, save_every=3)
        np.testing.assert_array_equal(back["initial_state"].values, phsplit.Vessel.paper().initial_state())


def test_the_file_holds_velocities_and_the_control_wrench(tmp_path):
    sol = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 60.0), 0.5, "sp2", control_start=0.0)
    ds = sol.to_xarray()
    np.testing.assert_array_equal(ds["velocity"].values, sol.p / sol.meta["mass"])
    np.testing.assert_allclose(ds["velocity_spatial"].values, np.einsum("nij,nj->ni", sol.Q, sol.v), rtol=1e-15)
    np.testing.assert_array_equal(ds["control_force"].values, sol.control_force)
    assert ds["velocity"].attrs["units"] == "m s-1" and ds["time"].attrs["standard_name"] == "time"


@pytest.mark.parametrize("bad,words", [("missing.nc", "does not exist"), ("text.nc", "not a NetCDF file"),
                                       ("foreign.nc", "not written by phsplit")])
def test_open_dataset_refuses_what_is_not_a_phsplit_file(tmp_path, bad, words):
    import xarray as xr

    (tmp_path / "text.nc").write_text("hello")
    xr.Dataset({"a": ("x", [1.0])}).to_netcdf(tmp_path / "foreign.nc")
    with pytest.raises(phsplit.InvalidInputError, match=words):
        phsplit.open_dataset(tmp_path / bad)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert main(["rerun", str(tmp_path / bad)]) == 2
    assert err.getvalue().startswith("phsplit: error:") and words in err.getvalue()


def test_plot_draws_the_dp_figure_of_a_file(cli_file, tmp_path):
    import matplotlib.image as mpimg

    path, _ = cli_file
    png = tmp_path / "dp.png"
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["plot", str(path), "--watch-circle", "5", "--out", str(png)]) == 0
    img = mpimg.imread(png)
    assert img.shape[0] > 600 and img.shape[1] > 1000 and img.std() > 0.05  # drawn, not blank
    for args, words in ((["--watch-circle", "-1"], "--watch-circle"), (["--out", str(tmp_path / "x.txt")], ".png"),
                        (["--out", str(tmp_path / "nowhere" / "a.png")], "does not exist")):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            assert main(["plot", str(path), *args]) == 2
        assert words in err.getvalue() and "Traceback" not in err.getvalue()


@pytest.mark.parametrize("args", [["--method", "heun", "--h", "0.05", "--t-end", "1005"],
                                  ["--method", "lie", "--h", "0.1", "--t-end", "2000.05"]],
                         ids=["rk-continues", "last-chunk-one-short-step"])
def test_chunked_runs_complete_and_rerun_bit_for_bit(tmp_path, args):
    """Found by review: a Runge–Kutta run cut into calls, and a last call holding only the final
    shorter step, stopped with an error and published a file labelled completed."""
    with contextlib.redirect_stdout(io.StringIO()):
        assert main(["simulate", "--out", str(tmp_path), "--no-plot", *args]) == 0
    (path,) = list(tmp_path.glob("*.nc"))
    with phsplit.open_dataset(path) as ds:
        assert ds.attrs["status"] == "completed" and float(ds["time"][-1]) == float(args[-1])
        again = phsplit.rerun(ds)
        assert phsplit.results.compare(ds, again) == []
    # a written rerun reruns again
    again.to_netcdf(tmp_path / "again.nc")
    with phsplit.open_dataset(tmp_path / "again.nc") as ds2:
        assert phsplit.results.compare(ds2, phsplit.rerun(ds2)) == []
