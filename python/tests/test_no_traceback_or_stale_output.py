"""No traceback, no hang, no stale or lost result.

* a fuzz/property pass over the CLI itself (arguments and scenario files);
* signals at random moments of a long run (SIGINT and SIGTERM; ``PHSPLIT_SIGNAL_RUNS`` runs,
  default 6 here; the acceptance is 50 in a row: ``PHSPLIT_SIGNAL_RUNS=50``);
* two processes writing the same output;
* the step-size warning against the vessel's natural periods; one default for control_start.
"""
from __future__ import annotations

import contextlib
import io
import math
import os
import random
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest
import xarray as xr
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import phsplit
from phsplit.cli import main

# ----------------------------------------------------------------------------------------------
# fuzzing the CLI: any arguments, any scenario file

NUMBERS = ["1", "2", "10", "0.5", "0.25", "-5", "0", "0.1", "nan", "inf", "-inf", "1e308", "250", "1e-300", "abc",
           "", "1e3", "3.7"]
OPTIONS = {"--method": ["sp2", "sp4", "lie", "rk4", "euler", "RK4", "sp8", ""],
           "--h": NUMBERS, "--t-end": NUMBERS, "--save-every": ["1", "3", "0", "-1", "1.5", "x", "1000000"],
           "--control-start": ["0", "5", "never", "-1", "nan", "soon", ""],
           "--linear-flow": ["exact", "gauss", "pade"]}
SCENARIO_LINES = [
    "[simulation]", 't_span = [0.0, 5.0]', "t_span = [0, inf]", "t_span = [5, 0]", "t_span = [0, 1e308]",
    "h = 1.0", "h = 0", "h = true", 'h = "1"', 'method = "sp2"', 'method = "nope"', "control_start = 2.0",
    'control_start = "never"', 'control_start = "50"', "save_every = 2", "save_every = true",
    'name = "../../escape"', 'name = "a/b"', 'name = ""', 'name = "ok-name"', 'name = ".hidden"',
    "[control]", "kp_translational = [1.0, 1.0, 0.0]", "kp_translational = [-1.0, 0.0, 0.0]",
    "[vessel]", "mass = 7e6", "mass = -1", "[external]", "force = [1e5, 0.0, 0.0]", 'frame = "ned"',
    "[initial]", "euler = [0.1, 0.0, 0.0]", 'euler = "abc"', "[simulaton]", 'vessel = "nowhere.toml"',
    "garbage = = =", "\x00\x01", "\ufeff[simulation]", "ledger = false", 'linear_flow = "gauss"',
    # the newer tables: the operation, drag, current, the sea
    "[pipe]", "submerged_weight = 800.0", "water_depth = 300.0", "water_depth = 1e6", "hang_off = [-60.0, 0.0, 3.0]",
    "horizontal_tension = 5e5", "departure_angle = 1e-9", "departure_angle = 45.0", "lay_direction = 0.0",
    "lay_direction = 720.0", "[setpoint]", "natural_frequency = 0.05", "times = [0.0, 60.0]", "times = [0.0, 1e12]",
    "positions = [[780.0, 20.0, 0.0], [800.0, 20.0, 0.0]]", "headings = [30.94, 30.94]", "headings = [0.5, 0.5]",
    "speed = 0.5", "[thrusters]", "hull_length = 83.0", "hull_length = 8300.0", "hull_beam = 18.0",
    "[[thrusters.unit]]", 'kind = "tunnel"', 'kind = "azimuth"', "position = [37.0, 0.0, -3.0]",
    "position = [-41.5, 7.0, -3.0]", "max_thrust = 3e5", "thrust_rate = 3e4", "turn_rate = 10.0",
    "[crossflow_drag]", "draft = 4.5", "draft = 5000.0", "drag_coefficient = 1.0", "x_aft = -36.0", "x_fore = 40.0",
    "[current]", "velocity = [0.5, 0.0, 0.0]", "[environment.current]", "direction_towards = 90.0",
    "[environment.waves]", "hs = 2.0", "hs = -1.0", "tp = 8.0", "direction = 270.0", "symmetric = \"no\"",
    "[environment.wind]", "frontal_area = 200.0",
    # the DP system, adaptive steps, the dynamic pipe, roll damping and subsystems
    'feedback = "observer"', 'feedback = "true"', 'anti_windup = "back_calculation"', 'anti_windup = "yes"',
    "tracking_time = 60.0", "tracking_time = -1.0", "lost_at = 100.0", "lost_at = nan", "lost_at = 1e20",
    "[observer]", "wave_frequency = 0.8", "wave_frequency = 80.0", "damping = [3.5e4, 1.2e5, 3.2e8]",
    "damping = [-1.0, 0.0, 0.0]", "notch_damping = 0.05", "cutoff_frequency = 0.5", "initial_estimate = [1e6, 0.0, 0.0]",
    "[sensors]", "gnss_rate = 1.0", "gnss_rate = 0.0", "gyro_rate = 10.0", "gnss_noise = -0.1", "seed = -3",
    "gnss_dropout = [[10.0, 20.0]]", "gnss_dropout = [[20.0, 10.0]]", "gyro_bias = 7.0",
    "rtol = 1e-4", "atol = 1e-20", "h_max = 0.0", "h_max = 5.0",
    'model = "lumped_mass"', 'model = "fem"', "segments = 20", "segments = 0", "length = 400.0",
    "bending_stiffness = 3.79e7", "bending_stiffness = -1.0",
    "[roll_damping]", "linear = 1e6", "quadratic = -5.0", "fraction_of_critical = 0.05", "fraction_of_critical = 3.0",
    "[port_hamiltonian]", 'name = "tank"', "J = [[0.0]]", "R = [[-1.0]]", "Q = [[1.0]]", "x0 = [0.0, 1.0]",
]


def _cheap(argv: list[str]) -> list[str]:
    """Bound the run's work: at most about 2,000 steps whatever the fuzzer chose (huge step
    counts are caught by the core's limit; between 2e3 and 2e9 steps would only be slow)."""
    def val(opt, default):
        if opt in argv:
            i = argv.index(opt)
            if i + 1 < len(argv):
                try:
                    return float(argv[i + 1])
                except ValueError:
                    return default
        return default

    h, t = val("--h", 0.5), val("--t-end", 200.0)
    if all(math.isfinite(x) for x in (h, t)) and h > 0 and t > 0 and 2e3 < t / h < 2e9:
        argv += ["--t-end", repr(2e3 * h)]
    return argv


@st.composite
def cli_inputs(draw):
    opts = draw(st.lists(st.sampled_from(sorted(OPTIONS)), max_size=4, unique=True))
    argv = ["simulate"]
    files: dict[str, bytes] = {}
    if draw(st.booleans()):
        lines = draw(st.lists(st.sampled_from(SCENARIO_LINES), max_size=8))
        raw = "\n".join(lines).encode("utf-8", "surrogatepass")
        if draw(st.booleans()):
            raw += draw(st.binary(max_size=12))
        files["s.toml"] = raw
        argv.append("s.toml")
    argv += ["--out", draw(st.sampled_from(["out", "out/sub", "s.toml", "."])), "--no-plot"]
    for o in opts:
        argv += [o, draw(st.sampled_from(OPTIONS[o]))]
    if draw(st.booleans()):
        argv.append(draw(st.sampled_from(["--bogus", "extra-positional", "--h"])))
    return _cheap(argv), files


@settings(max_examples=int(os.environ.get("PHSPLIT_CLI_FUZZ", "60")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(cli_inputs())
def test_no_cli_input_gives_a_traceback_a_stray_file_or_a_corrupt_one(tmp_path_factory, inp):
    argv, files = inp
    top = tmp_path_factory.mktemp("fuzz")
    work = top / "work"
    work.mkdir()
    for name, data in files.items():
        (work / name).write_bytes(data)
    err, out = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(work)
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            try:
                code = main(argv)
            except SystemExit as e:  # argparse's own usage errors
                code = e.code
    finally:
        os.chdir(here)
    text = err.getvalue()
    assert "Traceback" not in text and "panicked" not in text, (argv, text)
    assert code in (0, 1, 2), (argv, code, text)
    if code == 2 and "usage:" not in text:
        lines = text.strip().splitlines()
        assert lines and lines[-1].startswith("phsplit: error: "), (argv, text)
    assert sorted(p.name for p in top.iterdir()) == ["work"], (argv, list(top.iterdir()))
    for f in work.rglob("*"):
        assert not f.name.endswith(".part"), (argv, f)
        if f.suffix == ".nc":
            with phsplit.open_dataset(f) as ds:
                assert ds.attrs["status"] in ("completed", "failed") and ds.sizes["time"] >= 1


# ----------------------------------------------------------------------------------------------
# fuzzing sweep files: each example also names a cluster that cannot work, so that none starts
# workers; every one must be refused in one line, before anything is written

SWEEP_LINES = [
    "[simulation]", "h = 1.0", "t_span = [0.0, 2.0]", "h = 0", "[sweep]", 'mode = "grid"', 'mode = "random"',
    'mode = "latin"', "mode = 3", "samples = 2", "samples = 0", "samples = true", "samples = 2.5", "samples = -3",
    "seed = 1", "seed = -1", "seed = 1.5", "seed = true", 'seed = "x"', "seed = [1]", "[sweep.parameters]",
    '"vessel.mass" = [6e6, 7e6]', '"vessel.mass" = {low = 6e6, high = 7e6}', '"vessel.mass" = {low = 7e6, high = 6e6}',
    '"vessel.mass" = {low = 6e6, high = inf}', '"vessel.mass" = {low = 6e6}', '"vessel.mass" = ["a"]',
    '"vessel.mass" = []', '"vessel.mas" = [1.0]', '"control.kp_translational[7]" = [1.0]', "parameters = 3",
    "garbage = = =", "\x00\xff",
]
BAD_CLUSTERS = [["--workers", "-2"], ["--workers", "0"], ["--workers", "x"], ["--workers", "99999"],
                ["--scheduler", "tcp://127.0.0.1:1"], ["--scheduler", "nope"], ["--scheduler", "http://127.0.0.1:80"],
                ["--scheduler", "tcp://127.0.0.1:1", "--workers", "2"], ["--scheduler", ""]]


@st.composite
def sweep_inputs(draw):
    lines = draw(st.lists(st.sampled_from(SWEEP_LINES), max_size=10))
    files = {}
    target = draw(st.sampled_from(["s.toml", "s.toml", "d", "nowhere.toml"]))
    if target == "s.toml":
        files["s.toml"] = "\n".join(lines).encode("utf-8", "surrogatepass")
    elif target == "d":
        files["d"] = None
    argv = ["sweep", target, "--no-progress"]
    if draw(st.booleans()):
        argv += ["--out", draw(st.sampled_from(["st", "s.toml", "sub/st"]))]
    return argv + draw(st.sampled_from(BAD_CLUSTERS)), files


@settings(max_examples=int(os.environ.get("PHSPLIT_SWEEP_FUZZ", "40")), deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(sweep_inputs())
def test_no_sweep_file_or_cluster_argument_gives_a_traceback_or_leaves_a_file(tmp_path_factory, inp):
    argv, files = inp
    top = tmp_path_factory.mktemp("sweepfuzz")
    work = top / "work"
    work.mkdir()
    for name, data in files.items():
        if data is None:
            (work / name).mkdir()
        else:
            (work / name).write_bytes(data)
    before = sorted(p.relative_to(work) for p in work.rglob("*"))
    err, out = io.StringIO(), io.StringIO()
    here = os.getcwd()
    os.chdir(work)
    t0 = time.monotonic()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            try:
                code = main(argv)
            except SystemExit as e:
                code = e.code
    finally:
        os.chdir(here)
    text = err.getvalue()
    assert time.monotonic() - t0 < 10.0, (argv, "took too long")
    assert "Traceback" not in text and "panicked" not in text, (argv, text)
    assert code == 2, (argv, code, text)
    lines = text.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("phsplit: error: "), (argv, text)
    assert sorted(p.relative_to(work) for p in work.rglob("*")) == before, (argv, "wrote files")
    assert sorted(p.name for p in top.iterdir()) == ["work"], (argv, list(top.iterdir()))


# ----------------------------------------------------------------------------------------------
# signals at random moments

LONG = ["--no-plot", "--t-end", "400000", "--h", "0.05", "--save-every", "200", "--linear-flow", "gauss"]
NAME = "fig2-h0.05-t400000-s200-gauss"


def _check_output(out, code, err):
    parts = list(out.glob("*.part"))
    assert not parts, parts
    nc = out / f"{NAME}.nc"
    if code == 130:
        assert "interrupted" in err, err
        assert "Traceback" not in err, err
    if not nc.exists():
        assert any(w in err for w in ("no file was written", "no partial output", "nothing was written")), err
        return 0
    with phsplit.open_dataset(nc) as ds:
        assert ds.attrs["status"] in ("interrupted", "completed")
        t = ds["time"].values
        assert np.all(np.diff(t) > 0) and t[0] == 0.0
        assert np.all(np.isfinite(ds["position"].values)) and np.all(np.isfinite(ds["energy"].values))
        assert ds.attrs["steps"] == round(t[-1] / 0.05)
        if ds.attrs["status"] == "interrupted":
            assert f"interrupted after {ds.attrs['steps']} of" in err, err
        return ds.sizes["time"]


def test_signals_at_random_moments_leave_no_file_or_a_valid_one(tmp_path):
    runs = int(os.environ.get("PHSPLIT_SIGNAL_RUNS", "6"))
    rng = random.Random(int(os.environ.get("PHSPLIT_SIGNAL_SEED", "13")))
    rows = []
    for k in range(runs):
        out = tmp_path / f"run{k}"
        sig = (signal.SIGINT, signal.SIGTERM)[k % 2]
        p = subprocess.Popen([sys.executable, "-m", "phsplit", "simulate", "--out", str(out), *LONG],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if k % 4 < 2:
            # From the header line on (validation done), up to 2.5 s later: the first chunk's
            # integration and its writing.
            header = p.stdout.readline()
            assert header.startswith("phsplit "), (header, p.stderr.read())
            time.sleep(rng.uniform(0.0, 2.5))
        else:
            # From the process start: the interpreter's start, phsplit's import, the parsing.
            time.sleep(rng.uniform(0.05, 1.5))
        p.send_signal(sig)
        t_sig = time.monotonic()
        try:
            _, err = p.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            p.kill()
            pytest.fail(f"run {k}: no exit within 30 s of {sig.name}")
        waited = time.monotonic() - t_sig
        assert waited < 2.0 + 1.0, f"run {k}: exit {waited:.2f} s after {sig.name}"  # 2 s + process exit
        if p.returncode == -sig:  # before the interpreter ran any of phsplit: the default action
            assert err == "" and not any(out.iterdir()) if out.exists() else True, (k, err)
            rows.append("killed at start")
            continue
        assert p.returncode == 130, (k, p.returncode, err)
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1, (k, err)
        rows.append(_check_output(out, p.returncode, err))
    print(f"\n{runs} runs, rows in the files: {rows}")


# ----------------------------------------------------------------------------------------------
# two writers of one output


def test_a_second_writer_of_the_same_output_is_refused_and_the_first_file_is_valid(tmp_path):
    """The first writer runs long (8e6 steps); the second, started while it runs, is refused;
    the first is then stopped by SIGTERM and leaves a valid file; the lock is free again."""
    args = [sys.executable, "-m", "phsplit", "simulate", "--out", str(tmp_path), *LONG]
    a = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert a.stdout.readline().startswith("phsplit ")  # a holds the lock from here on
    b = subprocess.run(args, capture_output=True, text=True, timeout=120)
    assert a.poll() is None, "the first run ended before the second started: make it longer"
    a.send_signal(signal.SIGTERM)
    _, err_a = a.communicate(timeout=60)
    assert a.returncode == 130, err_a
    assert b.returncode == 2 and "another phsplit run is writing" in b.stderr, b.stderr
    assert "Traceback" not in b.stderr and len(b.stderr.strip().splitlines()) == 1
    files = sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith("."))
    assert files == [f"{NAME}.nc"]
    assert not list(tmp_path.glob("*.part")) and not list(tmp_path.glob(".*.part"))
    with phsplit.open_dataset(tmp_path / files[0]) as ds:
        assert ds.attrs["status"] == "interrupted" and ds.sizes["time"] >= 1
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"{NAME}.nc"]  # no lock file either
    from phsplit.files import PartialFile

    PartialFile(str(tmp_path / f"{NAME}.nc")).discard()  # free again


def test_runs_with_different_options_do_not_overwrite_each_other(tmp_path):
    for m in ("sp2", "rk4"):
        assert main(["simulate", "--out", str(tmp_path), "--no-plot", "--method", m, "--t-end", "10"]) == 0
    names = sorted(p.name for p in tmp_path.glob("*.nc"))
    assert names == ["fig2-rk4-t10.nc", "fig2-sp2-t10.nc"]
    with phsplit.open_dataset(tmp_path / names[0]) as a, phsplit.open_dataset(tmp_path / names[1]) as b:
        assert a.attrs["method"] == "rk4" and b.attrs["method"] == "sp2"


def test_names_from_file_names_are_confined_to_safe_characters(tmp_path):
    f = tmp_path / "my run (1).toml"
    f.write_text("[simulation]\nt_span = [0.0, 1.0]\n")
    out = tmp_path / "o"
    assert main(["simulate", str(f), "--out", str(out), "--no-plot"]) == 0
    assert [p.name for p in out.glob("*.nc")] == ["my_run__1_.nc"]


# ----------------------------------------------------------------------------------------------
# the time grid and the step size


def test_the_run_reaches_t1_with_a_last_shorter_step():
    s = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 1.0), 0.3)
    np.testing.assert_allclose(s.t, [0.0, 0.3, 0.6, 0.9, 1.0], rtol=0, atol=1e-15)
    assert s.t[-1] == 1.0 and s.steps == 4


def _closed_form_periods(d):
    v = d["vessel"]
    m, g = v["mass"], v["gravity"]
    heave = 2 * math.pi * math.sqrt(m / (g * v["water_density"] * v["waterplane_area"]))
    roll = 2 * math.pi * math.sqrt(v["inertia"][0] / (m * g * v["gm_transverse"]))
    pitch = 2 * math.pi * math.sqrt(v["inertia"][1] / (m * g * v["gm_longitudinal"]))
    return sorted([heave, roll, pitch])


def test_natural_periods_are_the_closed_forms():
    v = phsplit.Vessel.paper()
    up = {"euler": [0.0, 0.0, 0.3]}  # upright: the three oscillators decouple
    np.testing.assert_allclose(v.natural_periods(False, **up), _closed_form_periods(v.to_dict()), rtol=1e-9)
    # heeled by the initial state's 0.05 rad roll and 0.02 rad pitch they couple a little
    np.testing.assert_allclose(v.natural_periods(control=False), _closed_form_periods(v.to_dict()), rtol=2e-3)
    d = v.to_dict()
    d["vessel"]["waterplane_area"] *= 4.0  # stiffer heave: its period halves and becomes the shortest
    v2 = phsplit.Vessel.from_dict(d)
    np.testing.assert_allclose(v2.natural_periods(False, **up), _closed_form_periods(d), rtol=1e-9)


def test_a_step_beyond_half_the_shortest_period_warns_once_and_otherwise_not(tmp_path):
    v = phsplit.Vessel.paper()
    shortest = min(_closed_form_periods(v.to_dict()))  # pitch, 4.08 s
    with warnings.catch_warnings():
        warnings.simplefilter("error", phsplit.StepSizeWarning)
        phsplit.simulate(v, (0.0, 20.0), 0.5)
        phsplit.simulate(v, (0.0, 20.0), 0.49 * shortest)
    with pytest.warns(phsplit.StepSizeWarning, match=r"shortest natural period \(4.08 s"):
        phsplit.simulate(v, (0.0, 20.0), 0.51 * shortest)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        assert main(["simulate", "--out", str(tmp_path), "--no-plot", "--h", "5"]) == 0
    lines = [ln for ln in err.getvalue().splitlines() if "warning" in ln]
    assert len(lines) == 1 and lines[0].startswith("phsplit: warning: h = 5 s"), err.getvalue()


def test_one_default_for_the_controller_start_everywhere(tmp_path):
    default = phsplit.Settings().control_start
    assert default == 50.0
    assert phsplit.simulate(phsplit.Vessel.paper(), (0.0, 1.0), 0.5).control_start == default
    f = tmp_path / "empty.toml"
    f.write_text("")
    assert phsplit.load_scenario(str(f)).control_start == default
    assert main(["simulate", str(f), "--out", str(tmp_path), "--no-plot", "--t-end", "1",
                 "--control-start", "never"]) == 0
    with phsplit.open_dataset(tmp_path / "empty-t1-cnever.nc") as ds:
        assert "never" in str(ds.attrs.get("control_start", "never"))


def test_an_interrupt_that_left_evaluated_code_still_ends_with_status_130(tmp_path):
    """CPython ends ``python -m`` by SIGINT, not the returned status, once a KeyboardInterrupt
    has left code evaluated through PyRun_String (netCDF4 and cftime run code that way); the
    command clears that note after an interrupt. Without the clearing the same module dies by
    SIGINT (status -2), so the check can fail."""
    mod = tmp_path / "interrupted_command.py"
    mod.write_text(
        "import ctypes, sys\n"
        "from phsplit import _signals\n"
        "ctypes.pythonapi.PyRun_SimpleStringFlags(b'raise KeyboardInterrupt', None)\n"
        "if sys.argv[1] == 'clear':\n"
        "    _signals.forget_escaped_interrupt()\n"
        "sys.exit(130)\n")
    codes = {how: subprocess.run([sys.executable, "-m", "interrupted_command", how], cwd=tmp_path,
                                 capture_output=True).returncode for how in ("clear", "keep")}
    assert codes == {"clear": 130, "keep": -signal.SIGINT}
