"""Batches and sweeps: in-process threads, and dask.distributed LocalClusters with worker
processes on loopback (resume, a failing case, a worker killed mid-sweep)."""
from __future__ import annotations

import os
import signal
import threading
import time

import numpy as np
import pytest
import xarray as xr

import phsplit
from phsplit.batch import Settings, Sweep, done_cases, load_sweep, run_sweep
from phsplit.cli import main

SHORT = Settings(t_span=(0.0, 100.0), h=0.5, method="sp2", control_start=0.0)


def test_simulate_many_labels_cases_and_keeps_going_past_a_bad_one():
    cases = [{"control.kp_rotational[2]": k, "vessel.mass": m} for k in (5e7, 1e8) for m in (6e6, 7e6)]
    cases.append({"vessel.mass": -1.0})
    ds = phsplit.simulate_many(cases, settings=SHORT)
    assert ds.sizes["case"] == 5 and ds.sizes["time"] == 201
    np.testing.assert_array_equal(ds["control_kp_rotational_2"].values[:4], [5e7, 5e7, 1e8, 1e8])
    assert list(ds["status"].values) == ["completed"] * 4 + ["invalid"]
    assert "vessel.mass must be > 0" in ds["error"].values[4]
    assert np.isnan(ds["position"].values[4]).all()
    # each case equals a direct simulation of the same vessel
    v = phsplit.with_parameters(phsplit.Vessel.paper(), cases[2])
    direct = phsplit.simulate(v, (0.0, 100.0), 0.5, "sp2", control_start=0.0)
    np.testing.assert_array_equal(ds["position"].values[2], direct.x)
    assert (ds["position_error_m"].values[:4] < 60).all() and ds["peak_moment_Nm"].values[0] > 0


def test_with_parameters_rejects_unknown_paths():
    with pytest.raises(phsplit.InvalidInputError, match="unknown parameter 'vessel.mas'"):
        phsplit.with_parameters(phsplit.Vessel.paper(), {"vessel.mas": 1.0})
    with pytest.raises(phsplit.InvalidInputError, match="3-vector"):
        phsplit.with_parameters(phsplit.Vessel.paper(), {"vessel.inertia": 1.0})


SWEEP_TOML = """
[simulation]
t_span = [0.0, {t_end}]
h = {h}
method = "sp2"
control_start = 0.0
save_every = 10

[sweep]
mode = "grid"

[sweep.parameters]
"control.kp_translational[0]" = [2e5, 4e5, 8e5]
"vessel.mass" = [5e6, 6e6, 7e6]
"""


def test_sweep_cli_stores_every_case_once_and_resumes(tmp_path):
    f = tmp_path / "grid.toml"
    f.write_text(SWEEP_TOML.format(t_end=50.0, h=0.5))
    store = tmp_path / "grid.store"
    assert main(["sweep", str(f), "--out", str(store), "--workers", "2", "--no-progress"]) == 0
    sw = load_sweep(str(f))
    ids = {sw.case_id(i) for i in range(9)}
    assert done_cases(str(store)) == ids
    with phsplit.open_dataset(store / "summary.nc") as s:
        status = list(s["status"].values)
    assert status.count("completed") == 9
    # the summary written from the results in memory is the one the case files give back
    written = (store / "summary.csv").read_text()
    from phsplit.batch import write_summary
    write_summary(str(store), [sw.case_id(i) for i in range(9)])
    assert (store / "summary.csv").read_text() == written and written.count("\n") == 10
    import netCDF4
    with netCDF4.Dataset(store / "cases" / f"{sw.case_id(4)}.nc") as one:  # one chunk per variable
        assert one["position"].chunking() == list(one["position"].shape)
    # the computed cases as one lazy dataset with a case dimension
    with phsplit.open_sweep(store) as all_cases:
        assert all_cases.sizes["case"] == 9 and all_cases["position"].chunks is not None
        ran = [sw.case_id(i) for i in range(9)]
        assert list(all_cases["case_id"].values) == ran
        i = 4  # the case's own file holds the same numbers
        with phsplit.open_dataset(store / "cases" / f"{ran[i]}.nc") as one:
            np.testing.assert_array_equal(all_cases["position"].isel(case=i).values, one["position"].values)
        np.testing.assert_array_equal(all_cases["vessel_mass"].values, [5e6, 6e6, 7e6] * 3)
    # a second run reuses everything
    t0 = time.monotonic()
    res = run_sweep(sw, str(store), n_workers=2, progress=False)
    assert res["computed"] == 0 and res["reused"] == 9 and time.monotonic() - t0 < 20
    # a lost case is recomputed, and only that one
    os.unlink(store / "cases" / f"{sw.case_id(4)}.nc")
    res = run_sweep(sw, str(store), n_workers=2, progress=False)
    assert res["computed"] == 1 and done_cases(str(store)) == ids


def test_the_cases_warnings_come_back_to_the_cli_once_each(tmp_path, capfd):
    """A warning raised in a worker's case is said by the client, once per distinct message, as
    the CLI's one line with how often the cases raised it; no worker prints its own (a raw
    Python warning line with a source location). Here h = 20 s is beyond half each mass's
    shortest period, which differs by case: three messages."""
    f = tmp_path / "grid.toml"
    f.write_text(SWEEP_TOML.format(t_end=100.0, h=20.0).replace(
        '"control.kp_translational[0]" = [2e5, 4e5, 8e5]\n', ""))
    assert main(["sweep", str(f), "--out", str(tmp_path / "s"), "--workers", "2", "--no-progress"]) == 0
    err = capfd.readouterr().err.splitlines()
    said = [e for e in err if e.startswith("phsplit: warning: sweep (1 time in 3 cases): h = 20 s is more than half")]
    assert len(said) == 3 and len(set(said)) == 3, err
    assert not any("Warning:" in e or ".py:" in e for e in err), err


def test_a_sweep_file_with_a_value_the_vessel_refuses_starts_nothing(tmp_path, capsys):
    """Each value of a sweep file is tried on the vessel before anything is written or started
    (a case refused only by its combination of values is stored as invalid, as simulate_many
    does)."""
    f = tmp_path / "grid.toml"
    f.write_text(SWEEP_TOML.format(t_end=50.0, h=0.5).replace("[5e6, 6e6, 7e6]", "[-1.0, 6e6, 7e6]"))
    store = tmp_path / "grid.store"
    assert main(["sweep", str(f), "--out", str(store), "--workers", "2", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "sweep.parameters.vessel.mass = -1" in err and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["grid.toml"]


def test_a_worker_killed_mid_sweep_loses_no_case(tmp_path):
    from dask.distributed import Client, LocalCluster

    f = tmp_path / "grid.toml"
    f.write_text(SWEEP_TOML.format(t_end=600.0, h=0.05).replace('[5e6, 6e6, 7e6]', '[5e6, 6e6, 7e6, 8e6]'))
    sw = load_sweep(str(f))
    store = tmp_path / "store"
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                           dashboard_address=None)
    killed = []

    def killer():
        with Client(cluster.scheduler_address, set_as_default=False) as c:
            deadline = time.monotonic() + 120
            while len(done_cases(str(store))) < 2 and time.monotonic() < deadline:
                time.sleep(0.05)
            pids = c.run(os.getpid)
            pid = sorted(pids.values())[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    try:
        th = threading.Thread(target=killer)
        th.start()
        res = run_sweep(sw, str(store), scheduler=cluster.scheduler_address, progress=False)
        th.join()
    finally:
        cluster.close()
    assert killed, "no worker was killed"
    assert res["cases"] == 12
    ids = [sw.case_id(i) for i in range(12)]
    files = sorted(os.listdir(store / "cases"))
    assert files == sorted(f"{i}.nc" for i in ids)  # every case exactly once, no temporary files
    with phsplit.open_dataset(store / "summary.nc") as s:
        assert list(s["status"].values) == ["completed"] * 12


# A case's identity covers everything that determines its result.
OTHER_VALUE = {"t_span": (0.0, 20.0), "h": 0.25, "method": "rk4", "control_start": None, "outer": "conservative",
               "save_every": 5, "linear_flow": "exact", "ledger": False, "project_invariants": False}
#: Adaptive steps, which sweeps refuse (their cases share one time grid): no case has them.
REFUSED_IN_SWEEPS = {"rtol", "atol", "h_max"}


def test_every_setting_vessel_and_version_enters_the_case_id(monkeypatch):
    base = Sweep(SHORT, phsplit.Vessel.paper(), [{"vessel.mass": 6e6}, {"vessel.mass": 7e6}])
    ids = {base.case_id(i) for i in range(2)}
    assert set(OTHER_VALUE) | REFUSED_IN_SWEEPS == set(Settings.__dataclass_fields__), "a new setting needs a value here"
    from dataclasses import replace

    for k, v in OTHER_VALUE.items():
        other = Sweep(replace(SHORT, **{k: v}), base.base, base.cases)
        assert other.settings.checked()[k] != base.settings.checked()[k]
        assert ids.isdisjoint(other.case_id(i) for i in range(2)), f"changing {k} reused a case"
    # an alias of the same method is the same run, and keeps its ids
    assert {Sweep(replace(SHORT, method="strang"), base.base, base.cases).case_id(i) for i in range(2)} == ids
    d = base.base.to_dict()
    d["control"]["kd_translational"] = [1.0, 1.0, 1.0]
    assert ids.isdisjoint(Sweep(SHORT, phsplit.Vessel.from_dict(d), base.cases).case_id(i) for i in range(2))
    d = base.base.to_dict()
    d["external"] = {"force": [1e3, 0.0, 0.0]}
    assert ids.isdisjoint(Sweep(SHORT, phsplit.Vessel.from_dict(d), base.cases).case_id(i) for i in range(2))
    monkeypatch.setattr(phsplit.batch._core, "__version__", "0.0.0-other")
    assert ids.isdisjoint(base.case_id(i) for i in range(2))


def test_a_sweep_rerun_with_other_settings_recomputes_every_case(tmp_path):
    """A store reused with other settings: sp2 on [0, 100], then rk4 on [0, 20] in the same store."""
    f = tmp_path / "gains.toml"
    f.write_text(SWEEP_TOML.format(t_end=100.0, h=0.5).replace("[5e6, 6e6, 7e6]", "[6e6]"))
    store = tmp_path / "gains.store"
    assert main(["sweep", str(f), "--out", str(store), "--workers", "1", "--no-progress"]) == 0
    f.write_text(f.read_text().replace('"sp2"', '"rk4"').replace("[0.0, 100.0]", "[0.0, 20.0]"))
    sw = load_sweep(str(f))
    res = run_sweep(sw, str(store), n_workers=1, progress=False)
    assert res["computed"] == 3 and res["reused"] == 0
    for i in range(3):
        with phsplit.open_dataset(store / "cases" / f"{sw.case_id(i)}.nc") as ds:
            assert float(ds["time"][-1]) == 20.0
    import json

    assert json.loads((store / "sweep.json").read_text())["settings"]["method"] == "rk4"


def test_the_yaw_error_is_wrapped():
    """A set point at +3.1 rad reached from the other side (-3.1 rad) is 0.083 rad away."""
    from phsplit.batch import summarize

    d = phsplit.Vessel.paper().to_dict()
    d["control"]["euler_reference"] = [0.0, 0.0, 3.1]
    d["initial"]["euler"] = [0.0, 0.0, -3.1]
    v = phsplit.Vessel.from_dict(d)
    s = phsplit.simulate(v, (0.0, 1.0), 0.5, "sp2", control_start=None)
    assert abs(summarize(v, s)["yaw_error_rad"] - (2 * np.pi - 6.2)) < 1e-3


def test_summary_peaks_cover_every_step_not_only_the_saved_ones():
    """With every 50th state saved, the summary's peak force is still the peak over
    every step (the run that saves every step, computed independently from its saved states)."""
    from phsplit.batch import summarize

    v = phsplit.Vessel.paper()
    every = phsplit.simulate(v, (0.0, 100.0), 0.25, "sp2", control_start=10.0)
    peak = float(np.max(np.linalg.norm(every.control_force, axis=1)))
    sparse = phsplit.simulate(v, (0.0, 100.0), 0.25, "sp2", control_start=10.0, save_every=50, running_max=True)
    assert abs(summarize(v, sparse)["peak_force_N"] - peak) <= 1e-12 * peak
    sampled = float(np.max(np.linalg.norm(sparse.control_force, axis=1)))
    assert sampled < peak  # what the saved states alone would report
    ds = phsplit.simulate_many([{"vessel.mass": 6.3622085e6}], settings=phsplit.Settings(
        t_span=(0.0, 100.0), h=0.25, method="sp2", control_start=10.0, save_every=50))
    assert abs(float(ds["peak_force_N"][0]) - peak) <= 1e-12 * peak


def test_a_task_lost_outside_its_case_is_reported_not_stored(tmp_path, monkeypatch):
    """A task that fails for a reason outside its case (here: its function raises, as Dask's
    KilledWorker does after a worker died again and again) is listed in the summary as an error
    but not stored, so the next run of the sweep computes it."""
    from dask.distributed import LocalCluster

    import phsplit.batch as batch

    f = tmp_path / "grid.toml"
    f.write_text(SWEEP_TOML.format(t_end=20.0, h=0.5).replace("[5e6, 6e6, 7e6]", "[6e6]"))
    sw = load_sweep(str(f))
    store = tmp_path / "store"
    real = batch._run_case
    lost_id = sw.case_id(1)

    def flaky(base_tables, settings, case, store=None, cid=None):
        if cid == lost_id:
            raise RuntimeError("worker lost")
        return real(base_tables, settings, case, store, cid)

    monkeypatch.setattr(batch, "_run_case", flaky)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster:
        res = run_sweep(sw, str(store), scheduler=cluster.scheduler_address, progress=False)
        assert res["lost"] == 1 and res["computed"] == 2
        assert done_cases(str(store)) == {sw.case_id(0), sw.case_id(2)}
        with phsplit.open_dataset(store / "summary.nc") as s:
            assert list(s["status"].values) == ["completed", "error", "completed"]
            assert "worker lost" in str(s["error"].values[1]) and "run the sweep again" in str(s["error"].values[1])
        monkeypatch.setattr(batch, "_run_case", real)
        res = run_sweep(sw, str(store), scheduler=cluster.scheduler_address, progress=False)
    assert res["computed"] == 1 and res["lost"] == 0 and res["reused"] == 2
    assert done_cases(str(store)) == {sw.case_id(i) for i in range(3)}


def test_a_large_sweep_stores_its_cases_in_batches_and_reads_them_back_as_cases(tmp_path):
    """From 16 cases a worker, a task runs up to 32 cases and writes them as one file stacked
    along ``case`` (a netCDF4 file costs about as much per variable as it holds). The store still
    holds every case once: resume, the summary read back from the files, open_sweep in the sweep's
    order, each case equal to its own simulation, and a lost batch file computed again."""
    from phsplit.batch import _batch_size, store_index, write_summary

    assert [_batch_size(n, 2) for n in (9, 15, 16, 40, 1000)] == [1, 1, 1, 2, 32]
    settings = Settings(t_span=(0.0, 10.0), h=0.5, method="sp2", control_start=0.0, save_every=4)
    gains = np.linspace(2e5, 8e5, 37)
    cases = [{"control.kp_translational[0]": float(k)} for k in gains[:20]]
    cases.append({"vessel.mass": -1.0})  # refused: stored with its error, no run
    cases += [{"control.kp_translational[0]": float(k)} for k in gains[20:]]
    sw = Sweep(settings, phsplit.Vessel.paper(), cases, name="batches")
    store = tmp_path / "store"
    res = run_sweep(sw, str(store), n_workers=1, progress=False)
    ids = [sw.case_id(i) for i in range(len(cases))]
    assert res["computed"] == 38 and done_cases(str(store)) == set(ids)
    files = sorted(os.listdir(store / "cases"))
    assert len(files) == 10 and all(f.startswith("batch_") for f in files)  # 38 cases, 4 a file (the last 2)
    index = store_index(str(store))
    sizes = []
    for f in files:
        with phsplit.open_dataset(store / "cases" / f) as b:
            sizes.append(b.sizes["case"])
    assert sorted(i for _, i in index.values()) == sorted(j for n in sizes for j in range(n))
    with phsplit.open_dataset(store / "summary.nc") as s:
        assert list(s["status"].values).count("invalid") == 1 and list(s["status"].values)[20] == "invalid"
    written = (store / "summary.csv").read_text()
    write_summary(str(store), ids)
    assert (store / "summary.csv").read_text() == written
    with phsplit.open_sweep(store) as all_cases:
        assert list(all_cases["case_id"].values) == ids[:20] + ids[21:]
        for i in (0, 19, 36):
            case = cases[i if i < 20 else i + 1]
            direct = phsplit.simulate(phsplit.with_parameters(phsplit.Vessel.paper(), case), settings=settings)
            np.testing.assert_array_equal(all_cases["position"].values[i], direct.x)
            np.testing.assert_array_equal(all_cases["energy"].values[i], direct.energy)
        np.testing.assert_array_equal(all_cases["control_kp_translational_0"].values, gains)
    # A batch file holds the run's record: what the cases share as attributes, what differs (the
    # vessel with the case's parameters) along case.
    with phsplit.open_dataset(store / "cases" / files[0]) as b:
        assert b.attrs["method"] == "sp2" and "phsplit_batch" in b.attrs
        k = int(np.flatnonzero(b["case_status"].values == "completed")[0])
        assert str(b["case_id"].values[k]) in ids
        v = phsplit.Vessel.from_toml_str(str(b["run_phsplit_vessel"].values[k]))
        assert v.to_dict()["control"]["kp_translational"][0] == json_case(b, k)["control.kp_translational[0]"]
    # one case of a batch as the result of its own run: reruns to the bit
    one = phsplit.results.sweep_case(store, ids[25])
    assert float(one["time"][-1]) == 10.0 and one.attrs["case_status"] == "completed"
    assert phsplit.results.compare(one, phsplit.rerun(one)) == []
    with pytest.raises(phsplit.InvalidInputError, match="sweep_case"):
        phsplit.rerun(store / "cases" / files[0])
    # a second run reuses everything; a lost batch is computed again, and only its cases
    assert run_sweep(sw, str(store), n_workers=1, progress=False)["computed"] == 0
    lost = store / "cases" / files[3]
    with phsplit.open_dataset(lost) as b:
        n_lost = b.sizes["case"]
    os.unlink(lost)
    res = run_sweep(sw, str(store), n_workers=1, progress=False)
    assert res["computed"] == n_lost and res["reused"] == len(cases) - n_lost and done_cases(str(store)) == set(ids)


def json_case(b, k):
    import json

    return json.loads(str(b["case_parameters"].values[k]))


def test_batches_keep_each_case_whole_where_cases_differ(tmp_path):
    """From a review of the batch files: a case that diverges inside a batch comes back with its
    own saved times and reruns to the bit; a refused case says it did not run; cases whose
    variables differ in shape (rate-limited thrusters keep a memory in the state) are written a
    file each; long runs saved densely are not batched; open_sweep's dataset closes its files, so
    the store opens again."""
    import tomllib

    from phsplit.batch import _batch_size, _run_cases, _saved_rows, store_index

    assert _batch_size(1000, 2, _saved_rows(Settings(t_span=(0.0, 3600.0), h=0.05, save_every=1))) == 1
    assert _batch_size(1000, 2, _saved_rows(Settings(t_span=(0.0, 3600.0), h=0.5, save_every=20))) == 32
    store = tmp_path / "mixed"
    (store / "cases").mkdir(parents=True)
    settings = Settings(t_span=(0.0, 200.0), h=1.0, method="rk4", save_every=3)
    cases = [{"vessel.mass": m} for m in (6e6, 1e5, 7e6, -1.0)]  # 1e5 kg diverges; -1 is refused
    cids = [f"case_{i:05d}_x" for i in range(4)]
    rows = _run_cases(phsplit.Vessel.paper().to_dict(), settings, cases, str(store), cids)
    assert [r["row"]["status"] for r in rows] == ["completed", "failed", "completed", "invalid"]
    assert rows[1]["row"]["diverged"]
    assert len(os.listdir(store / "cases")) == 1
    short = phsplit.results.sweep_case(store, cids[1])
    assert len(short["time"]) < len(phsplit.results.sweep_case(store, cids[0])["time"])
    assert phsplit.results.compare(short, phsplit.rerun(short)) == []
    with pytest.raises(phsplit.InvalidInputError, match="did not run"):
        phsplit.results.sweep_case(store, cids[3])
    # rate-limited thrusters on one case only: the states differ in length, each case its own file
    scenario = tomllib.loads(open(os.path.join(os.path.dirname(phsplit.__file__), "scenarios",
                                               "pipelay.toml")).read())
    base = phsplit.Vessel.paper().to_dict()
    for k in ("setpoint", "pipe", "thrusters"):
        base[k] = scenario[k]
    other = tmp_path / "thrusters"
    (other / "cases").mkdir(parents=True)
    cids = ["case_00000_a", "case_00001_b", "case_00002_c"]
    _run_cases(base, Settings(t_span=(0.0, 2.0), h=0.5, method="sp2", control_start=0.0),
               [{"vessel.mass": 6.4e6}, {"thrusters.unit[0].thrust_rate": 1e5}, {"vessel.mass": 6.5e6}],
               str(other), cids)
    assert sorted(os.listdir(other / "cases")) == sorted(f"{c}.nc" for c in cids)
    assert set(store_index(str(other))) == set(cids)
    # open_sweep's dataset closes what it opened: the store opens again
    sw = Sweep(Settings(t_span=(0.0, 4.0), h=0.5, method="sp2"), phsplit.Vessel.paper(),
               [{"vessel.mass": float(m)} for m in np.linspace(6e6, 7e6, 20)], name="reopen")
    run_sweep(sw, str(tmp_path / "reopen"), n_workers=1, progress=False)
    for _ in range(2):
        with phsplit.open_sweep(tmp_path / "reopen") as ds:
            assert ds.sizes["case"] == 20 and float(ds["energy"].isel(case=3, time=-1)) > 0
