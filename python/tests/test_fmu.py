"""The vessel as an FMI 2.0 co-simulation FMU (docs/fmu.md), run in the hosts the
industry uses: FMPy (validation, simulation, the low-level slave API) and OSP's libcosim through
libcosimpy. The references are phsplit.simulate on the same vessel and settings (the FMU must give
its numbers) and, for the coupled run, FMPy fed with the load written out here."""
from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from fmpy import extract

import phsplit
from phsplit import fmu
from phsplit.cli import main as cli_main

ROOT = Path(__file__).resolve().parents[2]

OUTPUTS = ["position.x", "position.y", "position.z", "euler.roll", "euler.pitch", "euler.yaw",
           "quaternion.w", "quaternion.x", "velocity.u", "velocity.v", "angular_velocity.r",
           "control_force.x", "control_force.y", "control_moment.z", "energy.stored",
           "energy.supplied", "energy.dissipated", "ledger.control", "ledger.damping",
           "ledger.control_damping"]


@pytest.fixture(scope="module")
def fig2_fmu(tmp_path_factory) -> Path:
    return fmu.export(None, tmp_path_factory.mktemp("fmu") / "fig2.fmu")


def reference_columns(sol: phsplit.Solution, t: np.ndarray) -> dict[str, np.ndarray]:
    """The FMU's outputs as phsplit.simulate gives them, at the times t (saved times of sol)."""
    i = np.searchsorted(sol.t, t)
    assert np.array_equal(sol.t[i], t)
    v = sol.v[i]
    w = sol.w[i]
    led = {k: np.concatenate([[0.0], np.cumsum(b[1:])])[i] for k, b in sol.ledger.by_account.items()}
    return {
        "position.x": sol.x[i, 0], "position.y": sol.x[i, 1], "position.z": sol.x[i, 2],
        "euler.roll": sol.euler[i, 0], "euler.pitch": sol.euler[i, 1], "euler.yaw": sol.euler[i, 2],
        "quaternion.w": sol.quaternion[i, 0], "quaternion.x": sol.quaternion[i, 1],
        "velocity.u": v[:, 0], "velocity.v": v[:, 1], "angular_velocity.r": w[:, 2],
        "control_force.x": sol.control_force[i, 0], "control_force.y": sol.control_force[i, 1],
        "control_moment.z": sol.control_moment[i, 2], "energy.stored": sol.energy[i],
        "energy.supplied": np.cumsum(sol.ledger.supplied)[i],
        "energy.dissipated": np.cumsum(sol.ledger.dissipated)[i],
        "ledger.control": led["control"], "ledger.damping": led["damping"],
        "ledger.control_damping": led["control_damping"],
    }


def assert_close(got, want, rtol, what=""):
    for k, ref in want.items():
        scale = max(np.abs(ref).max(), 1e-300)
        err = np.abs(np.asarray(got[k]) - ref).max() / scale
        assert err <= rtol, f"{what}{k}: relative difference {err:.3e} > {rtol:g}"


def test_the_fmu_validates_and_describes_the_vessel(fig2_fmu, tmp_path):
    assert validate_fmu(str(fig2_fmu)) == []
    md = read_model_description(str(fig2_fmu))
    assert md.fmiVersion == "2.0" and md.coSimulation.modelIdentifier == "phsplit_fmu"
    cs = md.coSimulation
    assert cs.canHandleVariableCommunicationStepSize and cs.canGetAndSetFMUstate
    names = {v.name: v for v in md.modelVariables}
    for out in OUTPUTS + ["quaternion.z", "ledger.external", "energy.supplied"]:
        assert names[out].causality == "output", out
    for inp in ["external_force.x", "external_moment.z", "setpoint.x", "setpoint.heading", "current.y"]:
        assert names[inp].causality == "input", inp
    # Parameters start at the scenario's values: the paper's vessel and Fig. 2 settings.
    assert names["method"].start == "sp4" and float(names["h"].start) == 0.5
    assert float(names["control_start"].start) == 50.0
    assert float(names["vessel.mass"].start) == 6.3622085e6
    assert float(names["setpoint.x"].start) == 780.0
    assert names["position.x"].unit == "m" and names["control_moment.z"].unit == "N.m"
    # The second FMU of the co-simulation example, and a shipped scenario with waves and wind.
    assert validate_fmu(str(fmu.export_load(tmp_path / "load.fmu", force_mean=[1, 2, 3]))) == []
    assert validate_fmu(str(fmu.export("dp-weather", tmp_path / "dp.fmu"))) == []


def test_the_export_is_reproducible(fig2_fmu, tmp_path):
    again = fmu.export(None, tmp_path / "again.fmu")
    assert again.read_bytes() == fig2_fmu.read_bytes()
    # A different vessel is a different FMU (another GUID).
    s = phsplit.scenario.Scenario.paper_fig2().replace(h=0.25)
    other = fmu.export(s, tmp_path / "other.fmu")
    assert read_model_description(str(other)).guid != read_model_description(str(fig2_fmu)).guid


def test_fig2_in_fmpy_is_phsplit_simulate(fig2_fmu):
    """Communication step 1 s, twice the internal step: the FMU gives simulate's numbers."""
    r = simulate_fmu(str(fig2_fmu), output_interval=1.0, output=OUTPUTS)
    assert r["time"][0] == 0.0 and r["time"][-1] == 200.0
    sol = phsplit.simulate(phsplit.Vessel.paper(), linear_flow="exact")  # the Fig. 2 scenario's
    assert_close(r, reference_columns(sol, r["time"]), 1e-12)


def _slave(path: Path, tmp: Path, name: str = "v", start: dict | None = None):
    d = extract(str(path), unzipdir=str(tmp / name))
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier="phsplit_fmu", instanceName=name)
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    for k, v in (start or {}).items():
        if isinstance(v, str):
            s.setString([vr[k]], [v])
        else:
            s.setReal([vr[k]], [float(v)])
    s.exitInitializationMode()
    return s, vr


def test_variable_communication_steps_follow_simulate(fig2_fmu, tmp_path):
    """Communication steps of 1, 0.5 and 1.5 s (multiples of h = 0.5) in turn."""
    s, vr = _slave(fig2_fmu, tmp_path)
    t, times, rows = 0.0, [0.0], [s.getReal([vr[k] for k in OUTPUTS])]
    for k in range(120):
        dt = (1.0, 0.5, 1.5)[k % 3]
        s.doStep(t, dt)
        t += dt
        times.append(t)
        rows.append(s.getReal([vr[k] for k in OUTPUTS]))
    s.terminate()
    s.freeInstance()
    got = dict(zip(OUTPUTS, np.array(rows).T))
    sol = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, t), linear_flow="exact")
    assert_close(got, reference_columns(sol, np.array(times)), 1e-12)


def test_a_communication_step_that_is_not_a_multiple_of_h(fig2_fmu, tmp_path):
    """0.75 s = 0.5 + a last step of 0.25: a different grid, so SP4's own error separates it
    from simulate at h = 0.5; both must agree with a fine SP4 run (h = 0.05) to its accuracy."""
    r = simulate_fmu(str(fig2_fmu), output_interval=0.75, stop_time=150.0, output=["position.x", "euler.pitch"])
    assert np.allclose(r["time"], 0.75 * np.arange(len(r)))
    fine = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, 150.0), h=0.05)
    x = np.interp(r["time"], fine.t, fine.x[:, 0])
    assert np.abs(r["position.x"] - x).max() < 1e-3  # m, on a ~60 m transient


def test_inputs_act_like_the_vessel_file(tmp_path):
    """A constant external load (spatial frame, and the same in NED), a moved set point and a
    current as FMU inputs give simulate's run of the vessel file with those values."""
    t_end = 60.0
    base = phsplit.Vessel.paper().to_dict()
    tables = dict(base)
    tables["external"] = {"force": [2e5, -1e5, 3e4], "moment": [1e6, 0.0, -2e6], "point": [-40.0, 5.0, 3.0],
                          "frame": "spatial"}
    tables["control"] = dict(base["control"], position_reference=[790.0, 25.0, 0.0],
                             euler_reference=[0.0, 0.0, 0.2])
    tables["current"] = {"velocity": [0.3, -0.2, 0.0]}
    sol = phsplit.simulate(phsplit.Vessel.from_dict(tables), t_span=(0.0, t_end), linear_flow="exact")
    path = fmu.export(None, tmp_path / "v.fmu")
    common = {"external.point[0]": -40.0, "external.point[1]": 5.0, "external.point[2]": 3.0,
              "setpoint.x": 790.0, "setpoint.y": 25.0, "setpoint.heading": 0.2,
              "current.x": 0.3, "current.y": -0.2, "external_moment.x": 1e6, "external_moment.z": -2e6}
    spatial = dict(common, external_frame="spatial", **{"external_force.x": 2e5, "external_force.y": -1e5,
                                                        "external_force.z": 3e4})
    # NED = (x, −y, −z) of the spatial frame (north-west-up): the same load.
    ned = dict(common, external_frame="ned", **{"external_force.x": 2e5, "external_force.y": 1e5,
                                                "external_force.z": -3e4, "external_moment.x": 1e6,
                                                "external_moment.z": 2e6})
    cols = ["position.x", "position.y", "euler.yaw", "euler.roll", "ledger.external", "ledger.current"]
    for name, start in (("spatial", spatial), ("ned", ned)):
        r = simulate_fmu(str(path), stop_time=t_end, output_interval=1.0, start_values=start, output=cols)
        i = np.searchsorted(sol.t, r["time"])
        want = {"position.x": sol.x[i, 0], "position.y": sol.x[i, 1], "euler.yaw": sol.euler[i, 2],
                "euler.roll": sol.euler[i, 0],
                "ledger.external": np.cumsum(sol.ledger.by_account["external"])[i],
                "ledger.current": np.cumsum(sol.ledger.by_account["current"])[i]}
        assert_close(r, want, 1e-12, f"{name}: ")


def test_state_save_and_restore_is_bit_identical(fig2_fmu, tmp_path):
    s, vr = _slave(fig2_fmu, tmp_path)
    refs = [vr[k] for k in OUTPUTS]
    t = 0.0
    for _ in range(60):  # through the controller's start at 50 s
        s.doStep(t, 1.0)
        t += 1.0
    state = s.getFMUstate()
    first = []
    for k in range(5):
        s.doStep(t + k, 1.0)
        first.append(s.getReal(refs))
    s.setFMUstate(state)
    again = []
    for k in range(5):
        s.doStep(t + k, 1.0)
        again.append(s.getReal(refs))
    assert first == again  # the same floats, bit for bit
    s.freeFMUstate(state)
    s.terminate()
    s.freeInstance()


class Log:
    """The FMU's log, through callbacks of our own (FMPy's ``simulate_fmu(logger=...)`` leaves a
    dangling pointer in its logging proxy once the call returns, which crashes the next FMU that
    logs through FMPy's default callbacks). The FMU passes messages without format arguments,
    with ``%`` doubled."""

    def __init__(self):
        from fmpy.fmi2 import (calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                               fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)

        self.messages: list[str] = []

        def log(env, name, status, category, message):
            self.messages.append(message.decode().replace("%%", "%"))

        self._log = fmi2CallbackLoggerTYPE(log)  # kept alive with the callbacks
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = self._log
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)


def _run_logged(path: Path, unzipped: str, start: dict) -> list[str]:
    """Instantiate, set ``start``, initialise and step the FMU; return its log."""
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    log = Log()
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier="phsplit_fmu", instanceName="bad")
    try:
        s.instantiate(callbacks=log.callbacks)
    except Exception:
        return log.messages
    try:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        for k, v in start.items():
            if isinstance(v, str):
                s.setString([vr[k]], [v])
            elif isinstance(v, bool):
                s.setBoolean([vr[k]], [v])
            else:
                s.setReal([vr[k]], [float(v)])
        with pytest.raises(Exception):
            s.exitInitializationMode()
            s.doStep(0.0, 1.0)
    finally:
        s.freeInstance()
    return log.messages


@pytest.mark.parametrize("start, needle", [
    ({"vessel.mass": -1.0}, "vessel.mass"),
    ({"method": "rk5"}, "method"),
    ({"h": -0.5}, "h must be"),
    ({"linear_flow": "pade"}, "linear_flow"),
    ({"external_frame": "north"}, "external_frame must be 'body', 'spatial' or 'ned'"),
    ({"vessel.inertia[1]": 0.0}, "vessel.inertia"),
])
def test_bad_parameters_fail_initialisation_with_a_message(fig2_fmu, tmp_path, start, needle):
    msgs = _run_logged(fig2_fmu, extract(str(fig2_fmu), unzipdir=str(tmp_path / "u")), start)
    assert any("fmi2ExitInitializationMode" in m and needle in m for m in msgs), msgs


def test_bad_resources_fail_instantiation_with_a_message(fig2_fmu, tmp_path):
    d = Path(extract(str(fig2_fmu), unzipdir=str(tmp_path / "broken")))
    (d / "resources" / "vessel.toml").write_text("[vessel]\nmass = -5\n")
    messages = _run_logged(fig2_fmu, str(d), {})
    assert any("fmi2Instantiate" in m and "vessel.mass" in m for m in messages), messages
    (d / "resources" / "fmu.toml").unlink()
    messages = _run_logged(fig2_fmu, str(d), {})
    assert any("fmi2Instantiate" in m and "fmu.toml" in m for m in messages), messages


def test_the_osp_example_runs_in_libcosim_as_in_fmpy(tmp_path):
    """examples/osp/OspSystemStructure.xml: the vessel FMU driven by the load FMU in libcosim, the
    same vessel FMU in FMPy fed with the load's values at the communication points (written out
    here): the same trajectory."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver

    shutil.copy(ROOT / "examples" / "osp" / "OspSystemStructure.xml", tmp_path)
    assert cli_main(["fmu", "export", "-o", str(tmp_path / "vessel.fmu")]) == 0
    assert cli_main(["fmu", "load", "-o", str(tmp_path / "load.fmu"), "--force-mean", "2e5", "0", "0",
                     "--force-amplitude", "1e5", "5e4", "0", "--period", "40"]) == 0
    ex = CosimExecution.from_osp_config_file(osp_path=str(tmp_path))
    obs = CosimObserver.create_last_value()
    ex.add_observer(observer=obs)
    vi = ex.slave_index_from_instance_name("vessel")
    ref = {v.name.decode(): v.reference for v in ex.slave_variables(vi)}
    cols = ["position.x", "position.y", "euler.yaw", "ledger.external"]
    rows = []
    for _ in range(120):
        assert ex.step(step_count=1)
        rows.append(obs.last_real_values(slave_index=vi, variable_references=[ref[c] for c in cols]))
    cosim = np.array(rows)
    t = np.arange(0.0, 121.0)
    sig = np.zeros(len(t), dtype=[("time", float), ("external_force.x", float), ("external_force.y", float)])
    sig["time"] = t
    sig["external_force.x"] = 2e5 + 1e5 * np.sin(2 * np.pi * t / 40)
    sig["external_force.y"] = 5e4 * np.sin(2 * np.pi * t / 40)
    r = simulate_fmu(str(tmp_path / "vessel.fmu"), stop_time=120.0, output_interval=1.0, input=sig, output=cols)
    alone = np.column_stack([r[c] for c in cols])[1:]
    assert np.abs(alone - cosim).max(axis=0).max() <= 1e-12 * np.abs(alone).max()
    # The load did work on the vessel, and the ledger booked it: over the co-simulation the stored
    # energy changed by what came in through the ports less what was dissipated (SP4's split books
    # every port exactly; the FMU's initial H read at the start).
    assert abs(cosim[-1, 3]) > 1e3
    e = [ref[c] for c in ("energy.stored", "energy.supplied", "energy.dissipated")]
    h1, sup, dis = obs.last_real_values(slave_index=vi, variable_references=e)
    h0 = simulate_fmu(str(tmp_path / "vessel.fmu"), stop_time=1.0, output_interval=1.0,
                      output=["energy.stored"])["energy.stored"][0]
    assert abs((h1 - h0) - (sup - dis)) <= 1e-10 * (abs(h1 - h0) + sup + dis), (h1 - h0, sup - dis)


def test_cli_errors_are_one_line(tmp_path, capsys):
    assert cli_main(["fmu", "export", "-o", str(tmp_path / "v.zip")]) == 2
    assert "must end in .fmu" in capsys.readouterr().err
    assert cli_main(["fmu", "export", "-o", str(tmp_path / "v.fmu"), "--binary", "beos=x"]) == 2
    assert "binary platform must be one of" in capsys.readouterr().err
    assert cli_main(["fmu", "load", "-o", str(tmp_path / "l.fmu"), "--period", "0"]) == 2
    assert "--period must be a time in [1e-3, 1e7] s" in capsys.readouterr().err
    assert not any(p.name.endswith((".tmp", ".fmu")) for p in tmp_path.iterdir())


def test_the_standards_state_machine_is_kept(fig2_fmu, tmp_path):
    """After stepping, the experiment and initialisation cannot be redone (only after a reset);
    a stopTime is kept; a state saved before initialisation restores that mode."""
    d = extract(str(fig2_fmu), unzipdir=str(tmp_path / "sm"))
    md = read_model_description(str(fig2_fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier="phsplit_fmu", instanceName="sm")
    s.instantiate()
    before = s.getFMUstate()
    s.setupExperiment(startTime=0.0, stopTime=3.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.doStep(0.0, 2.0)
    for call in (lambda: s.setupExperiment(startTime=5.0), s.enterInitializationMode, s.exitInitializationMode):
        with pytest.raises(Exception):
            call()
    with pytest.raises(Exception):
        s.doStep(2.0, 2.0)  # past stopTime
    s.doStep(2.0, 1.0)
    # Back to before initialisation: parameters can be set again and the run starts anew.
    s.setFMUstate(before)
    s.setupExperiment(startTime=0.0)
    s.setReal([vr["h"]], [0.25])
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.doStep(0.0, 1.0)
    assert s.getReal([vr["euler.roll"]])[0] != 0.05
    # A set of values is kept whole or not at all.
    with pytest.raises(Exception):
        s.setReal([vr["external_force.x"], vr["position.x"]], [1e5, 1.0])
    assert s.getReal([vr["external_force.x"]])[0] == 0.0
    s.freeFMUstate(before)
    s.reset()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.doStep(0.0, 0.5)
    s.terminate()
    s.freeInstance()


def test_steps_near_a_multiple_of_h_at_large_times(fig2_fmu, tmp_path):
    """A communication step a sliver over a multiple of h, at t = 3.6e6 s, is taken as equal
    internal steps (a sliver of a last step could not be resolved by the time there)."""
    s, vr = _slave(fig2_fmu, tmp_path, "late")
    s.terminate()
    s.freeInstance()
    d = extract(str(fig2_fmu), unzipdir=str(tmp_path / "late2"))
    md = read_model_description(str(fig2_fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=d, modelIdentifier="phsplit_fmu", instanceName="late2")
    s.instantiate()
    s.setupExperiment(startTime=3.6e6)
    s.enterInitializationMode()
    s.exitInitializationMode()
    t = 3.6e6
    for _ in range(4):
        s.doStep(t, 0.5 + 1e-9)
        t += 0.5 + 1e-9
    assert np.isfinite(s.getReal([vr["position.x"]])[0])
    s.terminate()
    s.freeInstance()


def test_without_the_ledger_the_trajectory_is_the_same(fig2_fmu):
    """Without the ledger flow S2's exponential is taken without its Gramian: the same flow up to
    round-off; the ledger's outputs are NaN, not a misleading zero."""
    cols = ["position.x", "euler.pitch", "energy.stored", "energy.supplied", "ledger.control"]
    a = simulate_fmu(str(fig2_fmu), stop_time=80.0, output_interval=1.0, output=cols)
    b = simulate_fmu(str(fig2_fmu), stop_time=80.0, output_interval=1.0, output=cols, start_values={"ledger": False})
    sol = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, 80.0), ledger=False, linear_flow="exact")
    i = np.searchsorted(sol.t, b["time"])
    assert_close(b, {"position.x": sol.x[i, 0], "euler.pitch": sol.euler[i, 1], "energy.stored": sol.energy[i]},
                 1e-12, "ledger off vs simulate: ")
    assert_close(b, {c: a[c] for c in cols[:3]}, 1e-10, "ledger off vs on: ")
    assert np.isnan(b["energy.supplied"]).all() and np.isnan(b["ledger.control"]).all()
    assert np.isfinite(a["ledger.control"]).all()


def test_the_fmu_file_is_readable_as_the_umask_allows(tmp_path):
    old = os.umask(0o022)
    try:
        p = fmu.export(None, tmp_path / "m.fmu")
    finally:
        os.umask(old)
    assert (p.stat().st_mode & 0o777) == 0o644


def test_an_input_changed_mid_run_is_simulate_in_two_legs(fig2_fmu, tmp_path):
    """The external force switched on at 60 s (a partial rebuild of the vessel's input
    components inside the FMU) against two simulate runs: the vessel without it to 60 s, then
    the vessel file with it from the state reached."""
    s, vr = _slave(fig2_fmu, tmp_path, "legs")
    cols = ["position.x", "position.y", "euler.yaw", "energy.stored"]
    t, got = 0.0, []
    for k in range(100):
        if k == 60:
            s.setReal([vr["external_force.x"], vr["external_force.y"]], [2e5, -1e5])
        s.doStep(t, 1.0)
        t += 1.0
        got.append(s.getReal([vr[c] for c in cols]))
    s.terminate()
    s.freeInstance()
    first = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, 60.0), linear_flow="exact")
    tables = phsplit.Vessel.paper().to_dict()
    tables["external"] = {"force": [2e5, -1e5, 0.0]}
    second = phsplit.simulate(phsplit.Vessel.from_dict(tables), t_span=(60.0, 100.0), initial=first.state(-1), linear_flow="exact",
                              _continuing=True)
    got = np.array(got)
    i = np.searchsorted(second.t, np.arange(61.0, 101.0))
    want = np.column_stack([second.x[i, 0], second.x[i, 1], second.euler[i, 2], second.energy[i]])
    assert (np.abs(got[60:] - want).max(axis=0) <= 1e-12 * np.abs(want).max(axis=0)).all()
    i = np.searchsorted(first.t, np.arange(1.0, 61.0))
    assert np.abs(got[:60, 0] - first.x[i, 0]).max() <= 1e-12 * 800
