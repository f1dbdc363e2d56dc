"""The catalogue of bad inputs: each entry makes one mistake a user can make, and states the
exception it must raise and the words its message must contain (the offending field, and what
is allowed). ``test_bad_inputs.py`` checks every entry; ``scripts/gen_error_catalogue.py`` turns
the same table into ``docs/errors.md`` with the actual messages."""
from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass
from typing import Callable

import numpy as np

import phsplit

PAPER = phsplit.Vessel.paper_toml()


@dataclass
class Bad:
    what: str
    make: Callable[[], object]
    error: type
    must_say: tuple[str, ...]


def vessel_with(old: str, new: str) -> Callable[[], object]:
    assert old in PAPER, old
    return lambda: phsplit.Vessel.from_toml_str(PAPER.replace(old, new, 1))


def sim(**kw) -> Callable[[], object]:
    return lambda: phsplit.simulate(phsplit.Vessel.paper(), **{"t_span": (0.0, 10.0), "h": 0.5, **kw})


def scenario(text: str) -> Callable[[], object]:
    def run():
        from phsplit import scenario as scn

        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "bad.toml")
            with open(p, "w") as f:
                f.write(text)
            return scn.load(p)

    return run


def initial_with(index: slice | int, value) -> Callable[[], object]:
    def run():
        y = phsplit.Vessel.paper().initial_state()
        y[index] = value
        return phsplit.simulate(phsplit.Vessel.paper(), (0.0, 1.0), 0.5, initial=y)

    return run


def _reflected():
    y = phsplit.Vessel.paper().initial_state()
    y[12:15] *= -1.0  # third column of Q negated: det Q = -1
    return y


class CliError(Exception):
    """What the CLI printed for a bad input: its one-line error (exit status 2, no traceback)."""


def cli(*args: str, files: dict[str, bytes | None] | None = None) -> Callable[[], object]:
    """Run ``phsplit <args>`` in a fresh folder (holding ``files``; ``None`` for a folder) with
    ``--out out``-style arguments relative to it. Raises :class:`CliError` with the message when
    the CLI exits 2 with one line on stderr and no traceback, wrote nothing outside the folder and
    left no file in it besides ``files``; anything else (exit 0, a traceback, a stray or leftover
    file) is returned or raised as an AssertionError, which the catalogue's test reports."""

    def run():
        import contextlib
        import io

        from phsplit.cli import main

        here = os.getcwd()
        with tempfile.TemporaryDirectory() as top:
            d = os.path.join(top, "work")
            os.makedirs(d)
            for name, data in (files or {}).items():
                if data is None:
                    os.makedirs(os.path.join(d, name))
                    continue
                with open(os.path.join(d, name), "wb") as f:
                    f.write(data)
            before = _files_under(d)
            err, out = io.StringIO(), io.StringIO()
            os.chdir(d)
            try:
                with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
                    try:
                        code = main(list(args))
                    except SystemExit as e:  # argparse's usage errors
                        code = e.code
            finally:
                os.chdir(here)
            stray = [n for n in os.listdir(top) if n != "work"]
            left = sorted(_files_under(d) - before)
            lines = err.getvalue().strip().splitlines()
        assert not stray, f"wrote outside the working folder: {stray}"
        if code == 2:
            assert not left, f"a refused command left files behind: {left}"
        assert "Traceback" not in err.getvalue(), err.getvalue()
        if code == 2 and len(lines) == 1 and lines[0].startswith("phsplit: error: "):
            raise CliError(lines[0][len("phsplit: error: "):])
        return code, err.getvalue()

    return run


def _files_under(d: str) -> set[str]:
    """Every file below ``d`` (hidden ones too), relative to it."""
    return {os.path.relpath(os.path.join(r, f), d) for r, _, fs in os.walk(d) for f in fs}


E = phsplit.InvalidInputError
P = phsplit.ScenarioParseError
C = CliError
SIM = ("simulate", "--out", "out", "--no-plot")

CATALOGUE: list[Bad] = [
    # vessel parameters
    Bad("negative mass", vessel_with("mass = 6.3622085e6", "mass = -1.0"), E, ("vessel.mass", "> 0", "kg")),
    Bad("zero mass", vessel_with("mass = 6.3622085e6", "mass = 0.0"), E, ("vessel.mass", "> 0")),
    Bad("NaN mass", vessel_with("mass = 6.3622085e6", "mass = nan"), E, ("vessel.mass", "finite")),
    Bad("negative inertia", vessel_with("2.726143e9", "-2.726143e9"), E, ("vessel.inertia[1]", "> 0", "kg m^2")),
    Bad("inertia with two entries", vessel_with("[2.873071e8, 2.726143e9, 2.90000e9]", "[2.873071e8, 2.726143e9]"),
        P, ("inertia", "3")),
    Bad("negative heave damping", vessel_with("1.4566249e6]", "-1.4566249e6]"), E,
        ("vessel.damping_translational[2]", "≥ 0")),
    Bad("infinite roll damping", vessel_with("9.329153987e6", "inf"), E, ("vessel.damping_rotational[0]", "finite")),
    Bad("zero metacentric height GM_T", vessel_with("gm_transverse = 2.1440", "gm_transverse = 0.0"), E,
        ("vessel.gm_transverse", "> 0", "m")),
    Bad("negative GM_L", vessel_with("gm_longitudinal = 103.628", "gm_longitudinal = -103.6"), E,
        ("vessel.gm_longitudinal", "> 0")),
    Bad("zero gravity", vessel_with("gravity = 9.81", "gravity = 0.0"), E, ("vessel.gravity", "[9.7, 9.9]")),
    Bad("negative water density", vessel_with("water_density = 1.025e3", "water_density = -1.025e3"), E,
        ("vessel.water_density", "[950, 1250]")),
    Bad("zero water-plane area", vessel_with("waterplane_area = 1.3834e3", "waterplane_area = 0.0"), E,
        ("vessel.waterplane_area", "> 0", "m^2")),
    Bad("negative proportional gain", vessel_with("kp_translational = [4e5", "kp_translational = [-4e5"), E,
        ("control.kp_translational[0]", "≥ 0")),
    Bad("NaN derivative gain", vessel_with("kd_rotational = [0.0, 0.0, 1e9]", "kd_rotational = [0.0, 0.0, nan]"),
        E, ("control.kd_rotational[2]", "finite")),
    Bad("infinite set point", vessel_with("position_reference = [780.0", "position_reference = [inf"), E,
        ("control.position_reference[0]", "finite")),
    Bad("NaN initial roll", vessel_with("euler = [0.05", "euler = [nan"), E, ("initial.euler[0]", "finite")),
    Bad("misspelt key", vessel_with("gravity =", "gravitty ="), P, ("gravitty", "did you mean 'gravity'")),
    Bad("missing key", vessel_with("gravity = 9.81", ""), P, ("gravity", "missing")),
    Bad("text where a number belongs", vessel_with("mass = 6.3622085e6", 'mass = "heavy"'), P, ("mass",)),
    Bad("TOML syntax error", vessel_with("[control]", "[control"), P, ("line", "column")),
    # the external load (a component's own table)
    Bad("external force with two entries", vessel_with("[initial]", "[external]\nforce = [1.0, 2.0]\n[initial]"), P,
        ("external.force", "3 numbers")),
    Bad("NaN external moment", vessel_with("[initial]", "[external]\nmoment = [0.0, nan, 0.0]\n[initial]"), E,
        ("external.moment[1]", "finite")),
    Bad("unknown external frame", vessel_with("[initial]", '[external]\nframe = "ned"\n[initial]'), E,
        ("external.frame", "'body', 'spatial'")),
    Bad("external load kilometres off the hull", vessel_with("[initial]", "[external]\npoint = [0.0, 0.0, 5e3]\n[initial]"),
        E, ("external.point[2]", "within 1000 m")),
    Bad("misspelt external key", vessel_with("[initial]", "[external]\nforse = [1.0, 0.0, 0.0]\n[initial]"), P,
        ("forse", "did you mean 'force'")),
    Bad("current faster than 10 m/s", vessel_with("[initial]", "[current]\nvelocity = [15.0, 0.0, 0.0]\n[initial]"),
        E, ("current.velocity[0]", "10 m/s")),
    Bad("current given as a speed without a direction", vessel_with("[initial]", "[current]\nspeed = 1.0\n[initial]"), E,
        ("current.speed", "current.direction", "direction_from")),
    Bad("current given by a speed and its velocity", vessel_with("[initial]", "[current]\nspeed = 1.0\ndirection = 90.0\n"
                                                                 "velocity = [0.5, 0.0, 0.0]\n[initial]"), E,
        ("[current]", "velocity", "speed with a direction", "not both")),
    Bad("current direction without a speed", vessel_with("[initial]", "[current]\ndirection_from = 20.0\n[initial]"), E,
        ("current.direction_from", "current.speed", "current.velocity")),
    Bad("pipe with a negative submerged weight",
        vessel_with("[initial]", "[pipe]\nsubmerged_weight = -800.0\nwater_depth = 300.0\nhang_off = [-60.0, 0.0, 3.0]\n"
                    "horizontal_tension = 5e5\nlay_direction = 0.0\n[initial]"), E,
        ("pipe.submerged_weight", "> 0", "N/m")),
    Bad("pipe hung off kilometres above the deck",
        vessel_with("[initial]", "[pipe]\nsubmerged_weight = 800.0\nwater_depth = 300.0\nhang_off = [-60.0, 0.0, 3000.0]\n"
                    "horizontal_tension = 5e5\nlay_direction = 0.0\n[initial]"), E,
        ("pipe.hang_off[2]", "1000 m")),
    Bad("pipe with two tensions",
        vessel_with("[initial]", "[pipe]\nsubmerged_weight = 800.0\nwater_depth = 300.0\nhang_off = [-60.0, 0.0, 3.0]\n"
                    "horizontal_tension = 5e5\ntop_tension = 8e5\nlay_direction = 0.0\n[initial]"), E,
        ("exactly one of", "horizontal_tension", "top_tension")),
    Bad("pipe top tension below the hanging weight",
        vessel_with("[initial]", "[pipe]\nsubmerged_weight = 800.0\nwater_depth = 300.0\nhang_off = [-60.0, 0.0, 3.0]\n"
                    "top_tension = 1e5\nlay_direction = 0.0\n[initial]"), E,
        ("pipe.top_tension", "must exceed")),
    Bad("pipe without a lay direction",
        vessel_with("[initial]", "[pipe]\nsubmerged_weight = 800.0\nwater_depth = 300.0\nhang_off = [-60.0, 0.0, 3.0]\n"
                    "departure_angle = 45.0\n[initial]"), E,
        ("lay_direction", "[pipe]", "degrees")),
    Bad("set-point times not increasing",
        vessel_with("[initial]", "[setpoint]\nnatural_frequency = 0.05\ntimes = [0.0, 60.0, 30.0]\n"
                    "positions = [[780.0, 20.0, 0.0], [800.0, 20.0, 0.0], [820.0, 20.0, 0.0]]\n[initial]"), E,
        ("setpoint.times", "increase strictly")),
    Bad("thruster outside the hull",
        vessel_with("[initial]", "[thrusters]\nhull_length = 83.0\nhull_beam = 18.0\n"
                    "[[thrusters.unit]]\nkind = \"tunnel\"\nposition = [37.0, 0.0, -3.0]\nmax_thrust = 3e5\n"
                    "[[thrusters.unit]]\nkind = \"azimuth\"\nposition = [-41.5, 12.0, -3.0]\nmax_thrust = 4.2e5\n"
                    "[initial]"), E,
        ("thrusters.unit[1].position[1]", "outside the hull's box")),
    Bad("thrusters that cannot turn the vessel",
        vessel_with("[initial]", "[thrusters]\nhull_length = 83.0\nhull_beam = 18.0\n"
                    "[[thrusters.unit]]\nkind = \"azimuth\"\nposition = [-41.5, 0.0, -3.0]\nmax_thrust = 4.2e5\n"
                    "[initial]"), E,
        ("cannot produce surge, sway and yaw", "rank < 3")),
    Bad("set point with both times and a speed",
        vessel_with("[initial]", "[setpoint]\nnatural_frequency = 0.05\ntimes = [0.0, 60.0]\nspeed = 0.5\n"
                    "positions = [[780.0, 20.0, 0.0], [800.0, 20.0, 0.0]]\n[initial]"), E,
        ("[setpoint]", "times", "speed")),
    Bad("misspelt component table", vessel_with("[initial]", "[externl]\nforce = [1.0, 0.0, 0.0]\n[initial]"), P,
        ("externl", "did you mean 'external'")),
    # simulation arguments
    Bad("zero step", sim(h=0.0), E, ("h", "> 0")),
    Bad("negative step", sim(h=-0.5), E, ("h", "> 0")),
    Bad("NaN step", sim(h=math.nan), E, ("h", "finite")),
    Bad("infinite step", sim(h=math.inf), E, ("h", "finite")),
    Bad("reversed time span", sim(t_span=(10.0, 0.0)), E, ("t_span", "t1 > t0")),
    Bad("NaN in time span", sim(t_span=(0.0, math.nan)), E, ("t_span", "finite")),
    Bad("time span that is not two numbers", sim(t_span="ten"), E, ("t_span", "two numbers")),
    Bad("step longer than the span", sim(h=20.0), E, ("h", "longer than t_span")),
    Bad("too many steps", sim(t_span=(0.0, 1e9), h=1e-3), E, ("steps", "at most")),
    Bad("unknown method", sim(method="rk45"), E, ("method", "rk45", "sp4", "rk4")),
    Bad("unknown outer flow", sim(outer="middle"), E, ("outer", "dissipative", "conservative")),
    Bad("save_every zero", sim(save_every=0), E, ("save_every", ">= 1")),
    Bad("save_every not an integer", sim(save_every=1.5), E, ("save_every", "integer")),
    Bad("unknown linear flow", sim(linear_flow="pade"), E, ("linear_flow", "exact", "gauss", "gauss4")),
    Bad("linear flow of an order below the method's", sim(method="sp6", linear_flow="gauss4"), E,
        ("linear_flow", "gauss4", "order 4", "order 6", "gauss6")),
    Bad("NaN controller start", sim(control_start=math.nan), E, ("control_start", "finite")),
    Bad("step given as a boolean", sim(h=True), E, ("h", "number")),
    Bad("controller start given as text", sim(control_start="50"), E, ("control_start", "number")),
    Bad("vessel that is not a Vessel", lambda: phsplit.simulate({"mass": 1.0}), E, ("vessel", "phsplit.Vessel")),
    # initial state
    Bad("initial Euler angles with two entries", sim(initial={"euler": [0.0, 0.0]}), E, ("euler", "3 components")),
    Bad("unknown initial-state field", sim(initial={"speed": [1.0, 0.0, 0.0]}), E, ("speed", "allowed")),
    Bad("flat initial state of the wrong length", sim(initial=np.zeros(26)), E, ("27", "got 26")),
    Bad("NaN in the initial state", initial_with(18, math.nan), E, ("initial state", "finite", "entry 18 (x)")),
    Bad("restoring state with a yaw component", initial_with(17, 1e6), E, ("entry 17", "mu[2]", "must be 0")),
    Bad("flat initial state given as a matrix", sim(initial=np.zeros((3, 9))), E, ("1-D", "(3, 9)")),
    Bad("reflection as initial attitude, projected", lambda: phsplit.simulate(
        phsplit.Vessel.paper(), (0.0, 1.0), 0.5, initial=_reflected(), orthonormalize=True), E, ("det Q", "reflection")),
    Bad("initial attitude that is not a rotation", initial_with(slice(6, 15), 2 * np.eye(3).reshape(-1)), E,
        ("attitude", "not a rotation", "orthonormalize")),
    # scenario files
    Bad("misspelt scenario key", scenario('[simulation]\nmethdo = "sp2"\n'), P,
        ("methdo", "did you mean 'method'", "[simulation]")),
    Bad("unknown scenario table", scenario("[simulaton]\nh = 1.0\n"), P, ("simulaton", "did you mean 'simulation'")),
    Bad("scenario t_span with one entry", scenario("[simulation]\nt_span = [1.0]\n"), P,
        ("simulation.t_span", "two numbers")),
    Bad("scenario step as text", scenario('[simulation]\nh = "fast"\n'), P, ("simulation.h", "step size, s")),
    Bad("scenario vessel file missing", scenario('vessel = "nowhere.toml"\n[simulation]\nh = 1.0\n'), E,
        ("nowhere.toml", "cannot read")),
    Bad("scenario TOML syntax error", scenario("[simulation\nh = 1\n"), P, ("line", "column")),
    Bad("scenario with weather", scenario("[environment.weather]\nspeed = 15.0\n"), P,
        ("[environment.weather]", "allowed: current, waves, wind")),
    Bad("wind without its windage", scenario("[environment.wind]\nspeed = 15.0\ndirection = 0.0\n"), P,
        ("missing field `frontal_area` in [wind]",)),
    Bad("wind coefficients for an unknown ship type",
        scenario('[environment.wind]\nspeed = 15.0\nship_type = "yacht"\nfrontal_area = 10.0\nlateral_area = 30.0\n'
                 'length = 20.0\nair_density = 1.225\n'), E, ("unknown ship type 'yacht'", "offshore supply vessel")),
    Bad("wind with an unknown gust spectrum",
        scenario('[environment.wind]\nspeed = 15.0\nspectrum = "kaimal"\n'), E, ("spectrum must be one of", "npd")),
    Bad("sea state without a peak period", scenario("[environment.waves]\nhs = 2.0\n"), P,
        ("missing field 'tp'", "[environment.waves]", "peak period, s")),
    Bad("sea state with a negative height", scenario("[environment.waves]\nhs = -2.0\ntp = 8.0\n"), E,
        ("hs must be a number > 0", "m")),
    Bad("sea state with an unknown spectrum", scenario('[environment.waves]\nhs = 2.0\ntp = 8.0\nspectrum = "ochi"\n'),
        E, ("spectrum must be one of", "jonswap")),
    Bad("sea state whose hydrodynamic file is missing",
        scenario('[environment.waves]\nhs = 2.0\ntp = 8.0\nhydro = "nowhere.nc"\n'), E,
        ("environment.waves.hydro", "does not exist")),
    Bad("scenario controller start as a list", scenario("[simulation]\ncontrol_start = [1.0]\n"), P,
        ("simulation.control_start", "never")),
    Bad("scenario gain that is not a gain", scenario("[control]\nkp_translational = [-1.0, 0.0, 0.0]\n"), E,
        ("control.kp_translational[0]", "≥ 0")),
    # the API
    Bad("save_every given as a boolean", sim(save_every=True), E, ("save_every", "integer")),
    Bad("Euler angles given as text", sim(initial={"euler": "abc"}), E, ("euler", "3 numbers")),
    Bad("time span beyond what doubles resolve", sim(t_span=(1e17, 1e17 + 10.0)), E, ("h", "resolve", "t_span")),
    Bad("time span to 1e308", sim(t_span=(0.0, 1e308)), E, ("steps", "at most")),
    Bad("infinite end time", sim(t_span=(0.0, math.inf)), E, ("t_span", "finite")),
    Bad("progress that is not a callable", sim(progress="yes"), E, ("progress", "callable")),
    Bad("scenario name with a slash", scenario('[simulation]\nname = "a/b"\n'), E, ("simulation.name", "a/b")),
    Bad("scenario name escaping the output folder", scenario('[simulation]\nname = "../../escape"\n'), E,
        ("simulation.name", "inside the output folder")),
    Bad("empty scenario name", scenario('[simulation]\nname = ""\n'), E, ("simulation.name", "1 to 100")),
    Bad("scenario t_span to infinity", scenario("[simulation]\nt_span = [0.0, inf]\n"), E, ("t_span", "finite")),
    Bad("scenario save_every as a boolean", scenario("[simulation]\nsave_every = true\n"), P,
        ("save_every", "integer")),
    # the command line (one line on stderr, exit status 2, nothing written outside)
    Bad("CLI: negative end time", cli(*SIM, "--t-end", "-5"), C, ("t_span", "t1 > t0")),
    Bad("CLI: zero end time", cli(*SIM, "--t-end", "0"), C, ("t_span", "t1 > t0")),
    Bad("CLI: end time shorter than a step", cli(*SIM, "--t-end", "0.1"), C, ("h = 0.5 s", "longer than t_span")),
    Bad("CLI: step longer than the span", cli(*SIM, "--h", "250"), C, ("h = 250 s", "longer than t_span")),
    Bad("CLI: zero step", cli(*SIM, "--h", "0"), C, ("h", "> 0")),
    Bad("CLI: NaN end time", cli(*SIM, "--t-end", "nan"), C, ("t_span", "finite")),
    Bad("CLI: infinite end time", cli(*SIM, "--t-end", "inf"), C, ("t_span", "finite")),
    Bad("CLI: end time 1e308", cli(*SIM, "--t-end", "1e308"), C, ("steps", "at most")),
    Bad("CLI: save every 0th step", cli(*SIM, "--save-every", "0"), C, ("save_every", ">= 1")),
    Bad("CLI: unknown method", cli(*SIM, "--method", "rk45"), C, ("method", "rk45", "rk4")),
    Bad("CLI: controller start as a word", cli(*SIM, "--control-start", "soon"), C,
        ("--control-start", "'never'")),
    Bad("CLI: binary scenario file", cli("simulate", "s.toml", "--out", "out", files={"s.toml": b"\x00\x01\xff\xfe"}),
        C, ("s.toml", "UTF-8")),
    Bad("CLI: scenario name escaping the output folder",
        cli("simulate", "s.toml", "--out", "out", files={"s.toml": b'[simulation]\nname = "../../escape"\n'}), C,
        ("simulation.name", "inside the output folder")),
    Bad("CLI: scenario with t_span to infinity",
        cli("simulate", "s.toml", "--out", "out", files={"s.toml": b"[simulation]\nt_span = [0, inf]\n"}), C,
        ("t_span", "finite")),
    Bad("CLI: missing scenario file", cli("simulate", "nowhere.toml", "--out", "out"), C, ("nowhere.toml",)),
    Bad("CLI: output folder that is a file", cli(*SIM[:-3], "--out", "f", "--t-end", "1", files={"f": b"x"}), C,
        ("output folder", "f")),
    Bad("CLI: step that is not a number", cli(*SIM, "--h", "abc"), C, ("--h", "invalid float value", "--help")),
    Bad("CLI: unknown command", cli("simulat"), C, ("invalid choice", "simulate")),
    Bad("CLI: option without its value", cli(*SIM, "--method"), C, ("--method", "expected one argument")),
    Bad("CLI: rerun of a file that is not phsplit's", cli("rerun", "x.nc", files={"x.nc": b"CDF\x01junk"}), C,
        ("x.nc", "not a NetCDF file")),
    Bad("CLI: plot with a negative watch circle", cli("plot", "x.nc", "--watch-circle", "-5"), C, ("--watch-circle", "(0, 1e6)")),
    Bad("CLI: sweep without [sweep]", cli("sweep", "s.toml", "--out", "st", files={"s.toml": b"[simulation]\nh = 1.0\n"}),
        C, ("[sweep]",)),
]

CATALOGUE += [
    # more API mistakes, each an InvalidInputError
    Bad("method given as None", sim(method=None), E, ("method", "None")),
    Bad("settings that are not a Settings", lambda: phsplit.simulate(phsplit.Vessel.paper(), settings={"h": 1.0}), E,
        ("settings", "phsplit.Settings")),
    Bad("parameter value that is not a number", lambda: phsplit.with_parameters(phsplit.Vessel.paper(),
                                                                                {"vessel.mass": "heavy"}), E,
        ("vessel.mass", "number")),
    Bad("cases that are not a list of mappings", lambda: phsplit.simulate_many(5), E, ("cases", "sequence of mappings")),
    Bad("save_at outside the span", sim(save_at=[-1.0, 5.0]), E, ("save_at", "within t_span")),
    Bad("watch circle of negative radius", lambda: phsplit.events.watch_circle(-5.0), E, ("radius", "> 0")),
    Bad("open_dataset of a missing file", lambda: phsplit.open_dataset("/nonexistent/run.nc"), E, ("does not exist",)),
]

CATALOGUE += [
    # the FMU exporter
    Bad("CLI: FMU file without .fmu", cli("fmu", "export", "-o", "vessel.zip"), C, ("must end in .fmu",)),
    Bad("CLI: FMU binary for an unknown platform", cli("fmu", "export", "-o", "v.fmu", "--binary", "beos=x.so"), C,
        ("binary platform", "linux64", "win64")),
    Bad("CLI: FMU binary without its platform", cli("fmu", "export", "-o", "v.fmu", "--binary", "x.so"), C,
        ("--binary", "PLATFORM=PATH")),
    Bad("CLI: FMU binary that does not exist", cli("fmu", "export", "-o", "v.fmu", "--binary", "win64=nowhere.dll"), C,
        ("win64 binary", "nowhere.dll")),
    Bad("CLI: fmu without a command", cli("fmu"), C, ("'export' or 'load'",)),
    Bad("CLI: load FMU with a zero period", cli("fmu", "load", "-o", "l.fmu", "--period", "0"), C,
        ("--period", "[1e-3, 1e7]")),
    Bad("CLI: load FMU with a period of a picosecond", cli("fmu", "load", "-o", "l.fmu", "--period", "1e-12"), C,
        ("--period", "[1e-3, 1e7]")),
    Bad("CLI: load FMU with a force beyond any vessel's", cli("fmu", "load", "-o", "l.fmu", "--force-mean", "1e300", "0", "0"),
        C, ("--force-mean", "±1e+10")),
    Bad("CLI: rerun of a capability result", lambda: _rerun_capability(), C, ("DP capability", "nothing to repeat")),
    Bad("load FMU with a 2-vector", lambda: __import__("phsplit.fmu").fmu.export_load("l.fmu", force_mean=[1, 2]), E,
        ("force_mean", "3 finite numbers")),
    Bad("FMU of a missing scenario", cli("fmu", "export", "nowhere.toml", "-o", "v.fmu"), C, ("nowhere.toml",)),
]

CATALOGUE += [
    # quadratic damping
    Bad("quadratic damping with 2 coefficients",
        vessel_with("[control]", "[damping_quadratic]\ncoefficients = [1.0, 2.0]\n\n[control]"), E, ("6 numbers",)),
    Bad("quadratic damping with a negative coefficient",
        vessel_with("[control]", "[damping_quadratic]\ncoefficients = [1, -2, 0, 0, 0, 0]\n\n[control]"), E,
        ("damping_quadratic.coefficients[1]", "≥ 0")),
]

CATALOGUE += [
    # cross-flow drag
    Bad("cross-flow drag with the hull's ends reversed",
        vessel_with("[control]", "[crossflow_drag]\ndraft = 4.5\ndrag_coefficient = 1.0\nx_aft = 40.0\nx_fore = -36.0\n\n[control]"),
        E, ("x_aft < x_fore",)),
    Bad("cross-flow drag without its draught",
        vessel_with("[control]", "[crossflow_drag]\ndrag_coefficient = 1.0\nx_aft = -36.0\nx_fore = 40.0\n\n[control]"),
        (phsplit.InvalidInputError, phsplit.ScenarioParseError), ("draft",)),
]

_ROW = "[0.0, 0.0, 0.0, 0.0, 0.0, 0.0]"
CATALOGUE += [
    # the general mass matrix and the presets
    Bad("added mass that is not symmetric",
        vessel_with("gravity = 9.81", "gravity = 9.81\nadded_mass = [" + ", ".join(
            [_ROW] + ["[0.0, 0.0, 0.0, 0.0, 0.0, 1.0e6]"] + [_ROW] * 4) + "]"), E,
        ("vessel.added_mass must be symmetric", "entry [1][5]")),
    Bad("added mass that makes M indefinite",
        vessel_with("gravity = 9.81", "gravity = 9.81\nadded_mass = [" + ", ".join(
            ["[-7.0e6, 0.0, 0.0, 0.0, 0.0, 0.0]"] + [_ROW] * 5) + "]"), E,
        ("M = M_RB + M_A", "positive definite", "smallest eigenvalue is -")),
    Bad("added mass with 5 rows", vessel_with("gravity = 9.81", "gravity = 9.81\nadded_mass = [" + ", ".join([_ROW] * 5) + "]"),
        E, ("6 rows of 6",)),
    Bad("unknown vessel preset", lambda: phsplit.Vessel.preset("osw"), E, ("unknown vessel preset 'osw'", "'osv'")),
    Bad("CLI: unknown vessel", cli(*SIM, "--vessel", "osw"), C, ("neither a file nor a shipped vessel", "osv")),
]

CATALOGUE += [
    Bad("centre of flotation far off the hull", vessel_with("gravity = 9.81", "gravity = 9.81\nflotation_center_x = 5000.0"),
        E, ("vessel.flotation_center_x", "±1000 m")),
    Bad("restoring matrix singular to working precision",
        lambda: phsplit.Vessel.from_toml_str(
            PAPER.replace("gravity = 9.81", "gravity = 9.81\nflotation_center_x = 1.0\nflotation_center_y = 1.0", 1)
            .replace("gm_transverse = 2.1440", "gm_transverse = 1e-30", 1)
            .replace("gm_longitudinal = 103.628", "gm_longitudinal = 1e-30", 1)),
        E, ("singular to working precision", "gm_transverse")),
    Bad("centre of flotation far off the centreline",
        vessel_with("gravity = 9.81", "gravity = 9.81\nflotation_center_y = -2500.0"),
        E, ("vessel.flotation_center_y", "±1000 m")),
]

CATALOGUE += [
    Bad("centre of gravity far off the hull", vessel_with("gravity = 9.81", "gravity = 9.81\ncenter_of_gravity = [0.0, 1.0e8, 0.0]"),
        E, ("vessel.center_of_gravity[1]", "±1000 m")),
    Bad("nearly singular mass matrix",
        vessel_with("gravity = 9.81", "gravity = 9.81\nadded_mass = [" + ", ".join(
            [_ROW] + ["[0.0, -6.3622084999999e6, 0.0, 0.0, 0.0, 0.0]"] + [_ROW] * 4) + "]"), E,
        ("nearly singular", "condition number")),
]

# rate-limited thrusters
_RATED = ("[thrusters]\nhull_length = 83.0\nhull_beam = 18.0\n"
          "[[thrusters.unit]]\nkind = \"tunnel\"\nposition = [37.0, 0.0, -3.0]\nmax_thrust = 3e5\n{tunnel}"
          "[[thrusters.unit]]\nkind = \"azimuth\"\nposition = [-41.5, 7.0, -3.0]\nmax_thrust = 4.2e5\n{azimuth}"
          "[[thrusters.unit]]\nkind = \"azimuth\"\nposition = [-41.5, -7.0, -3.0]\nmax_thrust = 6.55e5\n"
          "[initial]")


def _rated(tunnel: str = "", azimuth: str = "thrust_rate = 4.2e4\nturn_rate = 10.0\n") -> str:
    return _RATED.format(tunnel=tunnel, azimuth=azimuth)


CATALOGUE += [
    Bad("negative thrust rate", vessel_with("[initial]", _rated(tunnel="thrust_rate = -3e4\n")), E,
        ("thrusters.unit[0].thrust_rate", "> 0", "N/s")),
    Bad("turning rate for a tunnel thruster", vessel_with("[initial]", _rated(tunnel="turn_rate = 10.0\n")), P,
        ("turn_rate", "thrusters.unit[0]")),
    Bad("rate-limited thrusters with a Runge-Kutta method",
        lambda: phsplit.simulate(vessel_with("[initial]", _rated())(), (0.0, 5.0), 0.5, "rk4", control_start=0.0), E,
        ("rate-limited thrusters", "splitting method")),
]

CATALOGUE += [
    Bad("CLI: sweep over a string", cli("sweep", "s.toml", "--out", "st", files={
        "s.toml": b'[simulation]\nh = 1.0\n[sweep]\nmode = "grid"\n[sweep.parameters]\n"vessel.mass" = ["a", "b"]\n'}),
        C, ("sweep.parameters.vessel.mass must hold numbers", "'a'")),
    Bad("symmetric matrix entry set twice, differently",
        lambda: phsplit.with_parameters(phsplit.Vessel.preset("osv"),
                                        {"vessel.added_mass[1][5]": 1.0, "vessel.added_mass[5][1]": 2.0}), E,
        ("vessel.added_mass[1][5]", "vessel.added_mass[5][1]", "different values")),
]


def _small_store() -> str:
    """A sweep store of one computed case (a fresh temporary folder)."""
    from phsplit.batch import Settings, Sweep, run_sweep

    d = os.path.join(tempfile.mkdtemp(), "store")
    sw = Sweep(Settings(t_span=(0.0, 1.0), h=0.5, method="sp2"), phsplit.Vessel.paper(), [{"vessel.mass": 6e6}])
    run_sweep(sw, d, n_workers=1, progress=False)
    return d


def _batch_file() -> str:
    """A batch file of two cases, as a large sweep writes them."""
    from phsplit.batch import Settings, _run_cases

    d = tempfile.mkdtemp()
    os.makedirs(os.path.join(d, "cases"))
    _run_cases(phsplit.Vessel.paper().to_dict(), Settings(t_span=(0.0, 1.0), h=0.5, method="sp2"),
               [{"vessel.mass": 6e6}, {"vessel.mass": 7e6}], d, ["case_00000_a", "case_00001_b"])
    return os.path.join(d, "cases", os.listdir(os.path.join(d, "cases"))[0])


CATALOGUE += [
    Bad("a case id the sweep store does not hold",
        lambda: phsplit.results.sweep_case(_small_store(), "case_00007_0000000000000000"), E,
        ("holds no case", "case_00007_0000000000000000")),
    Bad("rerun of a sweep's batch file", lambda: phsplit.rerun(_batch_file()), E,
        ("cases of a sweep", "sweep_case")),
]


def _cli_on_batch(*args: str) -> Callable[[], object]:
    """``phsplit <args> batch.nc`` on a batch file of a sweep store."""
    def run():
        with open(_batch_file(), "rb") as f:
            data = f.read()
        return cli(*args, "batch.nc", files={"batch.nc": data})()
    return run


CATALOGUE += [
    Bad("CLI: rerun of a sweep's batch file", _cli_on_batch("rerun"), C, ("cases of a sweep", "sweep_case")),
    Bad("CLI: plot of a sweep's batch file", _cli_on_batch("plot"), C, ("cases of a sweep", "sweep_case")),
]

# ------------------------------------------------------------------------------------------
# sweep files and the cluster (nothing written, nothing started)

_SWEEP_HEAD = b'[simulation]\nh = 1.0\nt_span = [0.0, 2.0]\n[sweep]\n'
_MASS_RANGE = b'[sweep.parameters]\n"vessel.mass" = {low = 6e6, high = 7e6}\n'
_MASS_GRID = b'[sweep.parameters]\n"vessel.mass" = [6e6, 7e6]\n'


def sweep_cli(sweep: bytes, *extra: str) -> Callable[[], object]:
    """``phsplit sweep s.toml --out st <extra>`` on a sweep file."""
    return cli("sweep", "s.toml", "--out", "st", "--no-progress", *extra, files={"s.toml": sweep})


def _random(lines: bytes, params: bytes = _MASS_RANGE) -> bytes:
    return _SWEEP_HEAD + b'mode = "random"\n' + lines + params


_GOOD_RANDOM = _random(b"samples = 2\nseed = 1\n")


def _load_sweep_text(text: bytes) -> Callable[[], object]:
    def run():
        from phsplit.batch import load_sweep

        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "s.toml")
            with open(p, "wb") as f:
                f.write(text)
            return load_sweep(p)
    return run


def _folder(name: str) -> str:
    """A fresh folder ``name`` in a temporary folder."""
    p = os.path.join(tempfile.mkdtemp(), name)
    os.makedirs(p)
    return p


def _run_sweep(**kw) -> Callable[[], object]:
    def run():
        from phsplit.batch import load_sweep, run_sweep

        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "s.toml")
            with open(p, "wb") as f:
                f.write(_GOOD_RANDOM)
            store = os.path.join(d, "st")
            try:
                return run_sweep(load_sweep(p), store, progress=False, **kw)
            finally:
                assert not os.path.exists(store), "a refused sweep created its store"
    return run


CATALOGUE += [
    Bad("CLI: sweep with a negative seed", sweep_cli(_random(b"samples = 2\nseed = -1\n")), C,
        ("sweep.seed", "integer from 0", "-1")),
    Bad("CLI: sweep with a fractional seed", sweep_cli(_random(b"samples = 2\nseed = 1.5\n")), C,
        ("sweep.seed", "integer", "1.5")),
    Bad("CLI: sweep with a boolean seed", sweep_cli(_random(b"samples = 2\nseed = true\n")), C,
        ("sweep.seed", "integer", "True")),
    Bad("CLI: sweep with a boolean sample count", sweep_cli(_random(b"samples = true\n")), C,
        ("sweep.samples", "integer from 1", "True")),
    Bad("CLI: sweep with a fractional sample count", sweep_cli(_random(b"samples = 2.5\n")), C,
        ("sweep.samples", "integer", "2.5")),
    Bad("CLI: sweep with zero samples", sweep_cli(_random(b"samples = 0\n")), C, ("sweep.samples", "from 1")),
    Bad("CLI: sweep range with low above high",
        sweep_cli(_random(b"samples = 2\n", b'[sweep.parameters]\n"vessel.mass" = {low = 7e6, high = 6e6}\n')), C,
        ("sweep.parameters.vessel.mass", "low <= high", "7000000.0")),
    Bad("CLI: sweep range to infinity",
        sweep_cli(_random(b"samples = 2\n", b'[sweep.parameters]\n"vessel.mass" = {low = 6e6, high = inf}\n')), C,
        ("sweep.parameters.vessel.mass", "finite", "inf")),
    Bad("CLI: sweep range with a misspelt bound",
        sweep_cli(_random(b"samples = 2\n", b'[sweep.parameters]\n"vessel.mass" = {low = 6e6, hihg = 7e6}\n')), C,
        ("sweep.parameters.vessel.mass", "low = ..., high = ...", "hihg")),
    Bad("CLI: binary sweep file", sweep_cli(b"\x00\x01\xff\xfe\x80"), C, ("s.toml", "UTF-8")),
    Bad("CLI: sweep file that is a folder", cli("sweep", "d", "--out", "st", files={"d": None}), C,
        ("sweep file", "'d'", "folder")),
    Bad("CLI: sweep file that does not exist", cli("sweep", "nowhere.toml", "--out", "st"), C,
        ("nowhere.toml", "does not exist")),
    Bad("CLI: sweep with an unknown mode", sweep_cli(_SWEEP_HEAD + b'mode = "latin"\n' + _MASS_GRID), C,
        ("sweep.mode", "'grid' or 'random'", "latin")),
    Bad("CLI: grid sweep with a seed", sweep_cli(_SWEEP_HEAD + b'mode = "grid"\nseed = 3\n' + _MASS_GRID), C,
        ("sweep.seed", "random")),
    Bad("CLI: grid sweep of ten million cases", sweep_cli(
        _SWEEP_HEAD + b'mode = "grid"\n[sweep.parameters]\n' + b"".join(
            f'"control.kp_translational[{i}]" = [{", ".join(str(1e5 * (k + 1)) for k in range(10))}]\n'.encode()
            for i in range(3)) + b"".join(
            f'"control.kd_translational[{i}]" = [{", ".join(str(1e6 * (k + 1)) for k in range(10))}]\n'.encode()
            for i in range(3)) + b'"control.kp_rotational[2]" = [' + ", ".join(
            str(1e8 * (k + 1)) for k in range(10)).encode() + b"]\n"), C, ("10000000 cases", "at most 1000000")),
    Bad("CLI: sweep with -2 workers", sweep_cli(_GOOD_RANDOM, "--workers", "-2"), C,
        ("--workers", "integer from 1", "-2")),
    Bad("CLI: sweep with no workers", sweep_cli(_GOOD_RANDOM, "--workers", "0"), C, ("--workers", "from 1")),
    Bad("CLI: sweep with a million workers", sweep_cli(_GOOD_RANDOM, "--workers", "1000000"), C,
        ("--workers", "to 512")),
    Bad("CLI: sweep on a scheduler where nothing listens",
        sweep_cli(_GOOD_RANDOM, "--scheduler", "tcp://127.0.0.1:1"), C,
        ("cannot reach the scheduler", "tcp://127.0.0.1:1")),
    Bad("CLI: sweep on a scheduler address without a port", sweep_cli(_GOOD_RANDOM, "--scheduler", "tcp://localhost"),
        C, ("--scheduler", "tcp://host:8786", "tcp://localhost")),
    Bad("CLI: sweep on an http address", sweep_cli(_GOOD_RANDOM, "--scheduler", "http://127.0.0.1:8787"), C,
        ("--scheduler", "tcp, tls")),
    Bad("CLI: sweep with both workers and a scheduler",
        sweep_cli(_GOOD_RANDOM, "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"), C,
        ("--workers", "--scheduler", "not both")),
    Bad("CLI: sweep store that is a file",
        cli("sweep", "s.toml", "--out", "st", files={"s.toml": _GOOD_RANDOM, "st": b"x"}), C,
        ("store", "'st'", "is a file")),
    Bad("sweep file that is a folder", lambda: __import__("phsplit.batch").batch.load_sweep(_folder("sweeps.toml")), E,
        ("sweep file", "sweeps.toml", "is a folder")),
    Bad("CLI: sweep with a zero step", sweep_cli(_GOOD_RANDOM.replace(b"h = 1.0", b"h = 0.0")), C,
        ("s.toml", "h must be finite and > 0")),
    Bad("sweep with a list as its seed", _load_sweep_text(_random(b"samples = 2\nseed = [1, 2]\n")), E,
        ("sweep.seed", "integer", "[1, 2]")),
    Bad("run_sweep with -2 workers", _run_sweep(n_workers=-2), E, ("workers", "integer from 1", "-2")),
    Bad("run_sweep with workers given as a boolean", _run_sweep(n_workers=True), E, ("workers", "integer", "True")),
    Bad("run_sweep on an unreachable scheduler", _run_sweep(scheduler="tcp://127.0.0.1:1"), E,
        ("cannot reach the scheduler", "127.0.0.1:1")),
]

# ------------------------------------------------------------------------------------------
# result files read back: rerun and plot check what they need, and where they write, first


def _result_bytes(attrs: dict | None = None, drop: tuple[str, ...] = ()) -> bytes:
    """A small run's result file, with ``attrs`` replaced and the variables ``drop`` removed."""
    sol = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 1.0), 0.5, "sp2")
    ds = sol.to_xarray().drop_vars(list(drop))
    ds.attrs.update(attrs or {})
    with tempfile.TemporaryDirectory() as d:
        p = os.path.join(d, "r.nc")
        ds.to_netcdf(p)
        with open(p, "rb") as f:
            return f.read()


def on_result(*args: str, attrs: dict | None = None, drop: tuple[str, ...] = (),
              more: dict[str, bytes | None] | None = None) -> Callable[[], object]:
    """``phsplit <args>`` with ``r.nc``, a run's file (damaged by ``attrs`` and ``drop``)."""
    def run():
        return cli(*args, files={"r.nc": _result_bytes(attrs, drop), **(more or {})})()
    return run


def rerun_damaged(attrs: dict | None = None, drop: tuple[str, ...] = ()) -> Callable[[], object]:
    def run():
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "r.nc")
            with open(p, "wb") as f:
                f.write(_result_bytes(attrs, drop))
            with phsplit.open_dataset(p) as ds:
                return phsplit.rerun(ds)
    return run


CATALOGUE += [
    Bad("CLI: rerun of a file whose settings are not TOML", on_result("rerun", "r.nc", attrs={
        "phsplit_settings": "[simulation\nh = "}), C, ("phsplit_settings", "damaged", "TOML syntax error")),
    Bad("CLI: rerun of a file whose settings have no [simulation]", on_result("rerun", "r.nc", attrs={
        "phsplit_settings": "h = 0.5\n"}), C, ("phsplit_settings", "no [simulation] table")),
    Bad("CLI: rerun of a file whose step is text", on_result("rerun", "r.nc", attrs={
        "phsplit_settings": '[simulation]\nt_span = [0.0, 1.0]\nh = "fast"\nmethod = "sp2"\nouter = "dissipative"\n'
                            'save_every = 1\nlinear_flow = "gauss"\nledger = true\n'}), C,
        ("phsplit_settings", "simulation.h", "fast")),
    Bad("CLI: rerun of a file whose settings lack a key", on_result("rerun", "r.nc", attrs={
        "phsplit_settings": '[simulation]\nt_span = [0.0, 1.0]\nh = 0.5\n'}), C,
        ("phsplit_settings", "simulation.method is missing")),
    Bad("CLI: rerun of a file whose settings are out of range", on_result("rerun", "r.nc", attrs={
        "phsplit_settings": '[simulation]\nt_span = [0.0, 1.0]\nh = -0.5\nmethod = "sp2"\nouter = "dissipative"\n'
                            'save_every = 1\nlinear_flow = "gauss"\nledger = true\n'}), C,
        ("phsplit_settings", "h", "> 0")),
    Bad("CLI: rerun of a file whose chunks are words", on_result("rerun", "r.nc", attrs={"phsplit_chunks": "two steps"}),
        C, ("phsplit_chunks", "damaged", "step counts")),
    Bad("CLI: rerun of a file whose chunks do not add up", on_result("rerun", "r.nc", attrs={"phsplit_chunks": "1 7"}),
        C, ("phsplit_chunks", "add up to 8", "2 steps")),
    Bad("CLI: rerun of a file whose vessel is damaged", on_result("rerun", "r.nc", attrs={
        "phsplit_vessel": "[vessel]\nmass = -1\n"}), C, ("phsplit_vessel", "damaged")),
    Bad("CLI: rerun of a file without its initial state", on_result("rerun", "r.nc", drop=("initial_state",)), C,
        ("initial_state",)),
    Bad("CLI: rerun into a folder that is a file", on_result("rerun", "r.nc", "--out", "f", more={"f": b"x"}), C,
        ("--out", "'f'", "is a file")),
    Bad("CLI: rerun onto a folder of the file's name", on_result("rerun", "r.nc", "--out", "o", more={"o": None,
                                                                                                    "o/r.nc": None}),
        C, ("o/r.nc", "folder of that name")),
    Bad("CLI: rerun over its own file", on_result("rerun", "r.nc", "--out", "."), C,
        ("would overwrite", "r.nc")),
    Bad("CLI: plot of a result without energy", on_result("plot", "r.nc", drop=("energy",)), C,
        ("no 'energy' variable", "position, euler, energy")),
    Bad("CLI: plot of a result without its trajectory", on_result("plot", "r.nc", drop=("position",)), C,
        ("no variable position", "trajectory")),
    Bad("CLI: plot into an existing folder", on_result("plot", "r.nc", "--out", "img.png", more={"img.png": None}), C,
        ("--out", "img.png", "is a folder")),
    Bad("CLI: plot over the result file", on_result("plot", "r.nc", "--out", "r.nc"), C,
        ("--out must end in .png",)),
    Bad("CLI: plot of a result whose vessel is damaged", on_result("plot", "r.nc", attrs={
        "phsplit_vessel": "[control\n"}), C, ("phsplit_vessel", "damaged")),
    Bad("rerun of a result whose settings are damaged", rerun_damaged({"phsplit_settings": "not = [toml"}), E,
        ("phsplit_settings", "damaged")),
    Bad("rerun of a result whose chunks are negative", rerun_damaged({"phsplit_chunks": "-2"}), E,
        ("phsplit_chunks", "step counts >= 1")),
    Bad("rerun of a result whose control start is a word", rerun_damaged({
        "phsplit_settings": '[simulation]\nt_span = [0.0, 1.0]\nh = 0.5\nmethod = "sp2"\nouter = "dissipative"\n'
                            'save_every = 1\nlinear_flow = "gauss"\nledger = true\ncontrol_start = "soon"\n'}), E,
        ("simulation.control_start", "soon", "'never'")),
    Bad("plot of a result without energy",
        lambda: __import__("phsplit.plotting").plotting.check_plottable(
            phsplit.simulate(phsplit.Vessel.paper(), (0.0, 1.0), 0.5).to_xarray().drop_vars("energy")), E,
        ("'energy'", "DP figure needs")),
]

# ------------------------------------------------------------------------------------------
# lengths, angles and times beyond any vessel or sea (the physical ranges), guessed defaults

_PIPE = ("[pipe]\nsubmerged_weight = 800.0\nwater_depth = {depth}\nhang_off = [-60.0, 0.0, 3.0]\n{fix}\n"
         "lay_direction = {direction}\n[initial]")


def _pipe(depth: str = "300.0", fix: str = "horizontal_tension = 5e5", direction: str = "0.0") -> str:
    return _PIPE.format(depth=depth, fix=fix, direction=direction)


_SETPOINT = ("[setpoint]\nnatural_frequency = 0.05\n{when}\npositions = [[780.0, 20.0, 0.0], [800.0, 20.0, 0.0]]\n"
             "{extra}[initial]")
_THRUSTERS = ("[thrusters]\nhull_length = {length}\nhull_beam = {beam}\n"
              "[[thrusters.unit]]\n{kind}position = [37.0, 0.0, -3.0]\nmax_thrust = 3e5\n{tunnel}"
              "[[thrusters.unit]]\nkind = \"azimuth\"\nposition = [-41.5, 7.0, -3.0]\nmax_thrust = 4.2e5\n{azimuth}"
              "[[thrusters.unit]]\nkind = \"azimuth\"\nposition = [-41.5, -7.0, -3.0]\nmax_thrust = 6.55e5\n"
              "[initial]")


def _thrusters(length="83.0", beam="18.0", kind='kind = "tunnel"\n', tunnel="", azimuth="") -> str:
    return _THRUSTERS.format(length=length, beam=beam, kind=kind, tunnel=tunnel, azimuth=azimuth)


_DRAG = "[crossflow_drag]\ndraft = {draft}\ndrag_coefficient = 1.0\nx_aft = -36.0\nx_fore = 40.0\n\n[control]"

CATALOGUE += [
    Bad("cross-flow drag with a draught of 5 km", vessel_with("[control]", _DRAG.format(draft="5000.0")), E,
        ("crossflow_drag.draft", "(0, 40]", "no ship draws more than 40 m", "5000")),
    Bad("pipe in water 1000 km deep", vessel_with("[initial]", _pipe(depth="1e6")), E,
        ("pipe.water_depth", "(0, 11000]", "1000000")),
    Bad("pipe leaving the vessel at 1e-9 degrees",
        vessel_with("[initial]", _pipe(fix="departure_angle = 1e-9")), E,
        ("pipe.departure_angle", "[5, 90)", "20 water depths", "got 0.000000001")),
    Bad("pipe laid towards 720 degrees", vessel_with("[initial]", _pipe(direction="720.0")), E,
        ("pipe.lay_direction", "[-360, 360]", "720")),
    Bad("thrusters on a hull 8.3 km long", vessel_with("[initial]", _thrusters(length="8300.0")), E,
        ("thrusters.hull_length", "(0, 500]", "8300")),
    Bad("thrusters on a hull 1.8 km wide", vessel_with("[initial]", _thrusters(beam="1800.0")), E,
        ("thrusters.hull_beam", "(0, 150]", "1800")),
    Bad("thruster without its kind", vessel_with("[initial]", _thrusters(kind="")), P,
        ("missing field `kind`", "thrusters.unit[0]", "'tunnel', 'azimuth', 'fixed'")),
    Bad("tunnel thruster at 450 degrees", vessel_with("[initial]", _thrusters(tunnel="angle = 450.0\n")), E,
        ("thrusters.unit[0].angle", "[-360, 360]", "450")),
    Bad("set-point headings in degrees", vessel_with("[initial]", _SETPOINT.format(
        when="times = [0.0, 60.0]", extra="headings = [30.94, 30.94]\n")), E,
        ("setpoint.headings[0]", "±2π", "degrees", "30.94")),
    Bad("heading reference in degrees", vessel_with("euler_reference = [0.0, 0.0, 0.54]",
                                                    "euler_reference = [0.0, 0.0, 30.94]"), E,
        ("control.euler_reference[2]", "radians", "30.94")),
    Bad("set-point time 1e12 s", vessel_with("[initial]", _SETPOINT.format(when="times = [0.0, 1e12]", extra="")), E,
        ("setpoint.times[1]", "1e9 s", "got 1e12")),
    Bad("set-point start 1e12 s", vessel_with("[initial]", _SETPOINT.format(
        when="speed = 0.5\nstart_time = 1e12", extra="")), E, ("setpoint.start_time", "1e9 s")),
    Bad("current table at 1e12 s", vessel_with("[initial]", "[current]\ntimes = [0.0, 1e12]\n"
                                               "velocities = [[0.5, 0.0, 0.0], [0.5, 0.0, 0.0]]\n[initial]"), E,
        ("current.times[1]", "1e9 s")),
    Bad("CLI: vessel file with a 5 km draught",
        cli(*SIM, "--t-end", "1", "--vessel", "v.toml", files={"v.toml": PAPER.replace(
            "[control]", _DRAG.format(draft="5000.0"), 1).encode()}), C, ("crossflow_drag.draft", "40 m")),
    Bad("CLI: scenario whose pipe leaves at 1e-9 degrees",
        cli(*SIM, "--t-end", "1", "--vessel", "v.toml", files={"v.toml": PAPER.replace(
            "[initial]", _pipe(fix="departure_angle = 1e-9"), 1).encode()}), C, ("pipe.departure_angle", "[5, 90)")),
    Bad("CLI: rate-limited thrusters with rk4",
        cli(*SIM, "--t-end", "1", "--method", "rk4", "--vessel", "v.toml", files={"v.toml": PAPER.replace(
            "[initial]", _rated(), 1).encode()}), C, ("rate-limited thrusters", "splitting method")),
]

# ------------------------------------------------------------------------------------------
# save_at and events


def _events(*events) -> Callable[[], object]:
    return sim(events=list(events))


def _event(**kw) -> Callable[[], object]:
    return lambda: phsplit.events.Event(**{"name": "e", "g": lambda t, y, v: y[18], **kw})


CATALOGUE += [
    Bad("save_at given as True", sim(save_at=True), E, ("save_at", "numbers", "True")),
    Bad("save_at holding a boolean", sim(save_at=[1.0, False]), E, ("save_at", "numbers")),
    Bad("save_at given as text", sim(save_at="5"), E, ("save_at", "numbers", "'5'")),
    Bad("roll event beyond 400 degrees", lambda: phsplit.events.roll_beyond(400.0), E,
        ("roll_beyond", "below 180", "never fire", "400")),
    Bad("pitch event beyond 95 degrees", lambda: phsplit.events.pitch_beyond(95.0), E,
        ("pitch_beyond", "below 90", "95")),
    Bad("watch circle whose terminal is text", lambda: phsplit.events.watch_circle(5.0, terminal="no"), E,
        ("watch_circle", "terminal must be True or False", "'no'")),
    Bad("roll event whose terminal is a number", lambda: phsplit.events.roll_beyond(10.0, terminal=0), E,
        ("roll_beyond", "terminal must be True or False", "0")),
    Bad("event whose terminal is text", _event(terminal="no"), E, ("event 'e'", "terminal", "'no'")),
    Bad("event without a name", _event(name=""), E, ("name", "non-empty string")),
    Bad("event condition that is always NaN", _events(phsplit.events.Event("never", lambda t, y, v: math.nan)), E,
        ("event 'never'", "finite number", "nan")),
    Bad("event condition that fails", _events(phsplit.events.Event("broken", lambda t, y, v: y[99])), E,
        ("event 'broken'", "raised IndexError")),
    Bad("orthonormalize given as text", sim(orthonormalize="no"), E, ("orthonormalize", "True or False", "'no'")),
    Bad("running_max given as a number", sim(running_max=1), E, ("running_max", "True or False")),
    Bad("dense output at a word", lambda: phsplit.simulate(phsplit.Vessel.paper(), (0.0, 5.0), 0.5).at("a"), E,
        ("times", "numbers", "'a'")),
    Bad("event condition that returns text", _events(phsplit.events.Event("wordy", lambda t, y, v: "far")), E,
        ("event 'wordy'", "finite number", "'far'")),
]

# ------------------------------------------------------------------------------------------
# hydrodynamic data: no extrapolation over directions

_BARGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "box_barge_capytaine.nc")


def _waves_from(direction: float, extra: str = "") -> Callable[[], object]:
    return scenario(f'[simulation]\nt_span = [0.0, 1.0]\nh = 0.5\n[environment.waves]\nhs = 2.0\ntp = 8.0\n'
                    f'omega_range = [0.35, 1.9]\nhydro = "{_BARGE}"\nhydro_checks = "warn"\n'
                    f'direction = {direction}\n{extra}')


CATALOGUE += [
    Bad("waves from outside the dataset's directions", _waves_from(270.0), E,
        ("environment.waves", "270 degrees", "outside the directions", "symmetric = true")),
    Bad("spread waves reaching outside the dataset's directions", _waves_from(0.0, "spreading = 4.0\n"), E,
        ("environment.waves", "outside the directions", "0, 22.5, 45")),
]

# ------------------------------------------------------------------------------------------
# the FMU exporter checks what it packs

_HOST_SO = os.path.join(os.path.dirname(phsplit.__file__), "_fmu", "binaries", "linux64", "phsplit_fmu.so")


def _fmu_with(plat: str, data: bytes | None, name: str = "b.bin") -> Callable[[], object]:
    return cli("fmu", "export", "-o", "v.fmu", "--binary", f"{plat}={name}", files={name: data})


def _host_so() -> bytes:
    with open(_HOST_SO, "rb") as f:
        return f.read()


CATALOGUE += [
    Bad("CLI: FMU with a text file as the Windows DLL", _fmu_with("win64", b"this is not a DLL\n"), C,
        ("win64 binary", "not a shared library", "Windows DLL (PE), 64-bit")),
    Bad("CLI: FMU with a Linux library as the Windows DLL", lambda: _fmu_with("win64", _host_so())(), C,
        ("win64 binary", "64-bit an ELF shared object", "Windows DLL")),
    Bad("CLI: FMU with a 64-bit library as linux32", lambda: _fmu_with("linux32", _host_so())(), C,
        ("linux32 binary", "64-bit", "32-bit")),
    Bad("CLI: FMU with a folder as a binary", _fmu_with("darwin64", None, "lib"), C,
        ("darwin64 binary", "is a folder")),
    Bad("CLI: FMU with a shared library that is no FMU", _fmu_with(
        "linux64", b"\x7fELF\x02\x01\x01" + b"\x00" * 9 + b"\x03\x00" + b"\x00" * 64), C,
        ("linux64 binary", "fmi2Instantiate")),
    Bad("FMU export with a script as the macOS binary", lambda: __import__("phsplit.fmu").fmu.export(
        None, os.path.join(tempfile.mkdtemp(), "v.fmu"), binaries={"darwin64": _script()}), E,
        ("darwin64 binary", "Mach-O dynamic library")),
]


def _script() -> str:
    p = os.path.join(tempfile.mkdtemp(), "run.sh")
    with open(p, "w") as f:
        f.write("#!/bin/sh\necho hello\n")
    return p


# ------------------------------------------------------------------------------------------
# hydrodynamic datasets named by a scenario


def _hydro_file(data: bytes, extra: str = "") -> Callable[[], object]:
    def run():
        from phsplit import scenario as scn

        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "h.nc"), "wb") as f:
                f.write(data)
            p = os.path.join(d, "s.toml")
            with open(p, "w") as f:
                f.write(f'[environment.waves]\nhs = 2.0\ntp = 8.0\nhydro = "h.nc"\n{extra}')
            return scn.load(p)
    return run


def _barge_bytes() -> bytes:
    with open(_BARGE, "rb") as f:
        return f.read()


CATALOGUE += [
    Bad("hydrodynamic file that is text", _hydro_file(b"omega, added_mass\n1, 2\n"), E,
        ("environment.waves.hydro", "not a NetCDF file")),
    Bad("hydrodynamic file cut short", lambda: _hydro_file(_barge_bytes()[:4000])(), E,
        ("environment.waves.hydro", "cannot read")),
    Bad("hydrodynamic dataset with symmetric as text", lambda: _hydro_file(_barge_bytes(), 'symmetric = "no"\n')(), P,
        ("environment.waves.symmetric", "true or false", "'no'")),
    Bad("hydrodynamic checks of an unknown mode", lambda: _hydro_file(_barge_bytes(), 'hydro_checks = "maybe"\n')(), P,
        ("environment.waves.hydro_checks", "'refuse'", "'maybe'")),
    Bad("hydrodynamic file given as a number", scenario("[environment.waves]\nhs = 2.0\ntp = 8.0\nhydro = 5\n"), P,
        ("environment.waves.hydro", "file path", "5")),
]

# ------------------------------------------------------------------------------------------
# the sea's own ranges

CATALOGUE += [
    Bad("sea state peaking at 1000 s", scenario("[environment.waves]\nhs = 2.0\ntp = 1000.0\n"), E,
        ("waves.tp", "[0.5, 40]", "1000")),
    Bad("waves travelling towards 720 degrees", scenario("[environment.waves]\nhs = 2.0\ntp = 8.0\ndirection = 720.0\n"),
        E, ("waves.direction", "[-360, 360]", "720")),
    Bad("wind from 1000 degrees", scenario("[environment.wind]\nspeed = 10.0\ndirection_from = 1000.0\n"
                                          "spectrum = \"none\"\n"), E,
        ("environment.wind.direction_from", "[-360, 360]", "1000")),
    Bad("wind measured 5 km up", scenario("[environment.wind]\nspeed = 10.0\nheight = 5000.0\n"), E,
        ("wind.height", "[0.1, 500]", "5000")),
    Bad("Blendermann windage of a hull 8 km long",
        scenario('[environment.wind]\nspeed = 15.0\nship_type = "offshore supply vessel"\nfrontal_area = 200.0\n'
                 'lateral_area = 600.0\nlength = 8000.0\n'), E, ("environment.wind.length", "500 m", "8000")),
]

# ------------------------------------------------------------------------------------------
# a linear port-Hamiltonian subsystem (van der Schaft & Jeltsema 2014, §4.1): its matrices

_PH = {"states": '["q", "pi"]', "J": "[[0.0, -1.0], [1.0, 0.0]]", "R": "[[0.0, 0.0], [0.0, 0.1]]",
       "Q": "[[2.0, 0.0], [0.0, 1.0]]", "G": "[[1.0], [0.0]]", "input": '["roll"]'}


def _ph(**keys: str) -> Callable[[], object]:
    """The paper's vessel with a [port_hamiltonian] table: a valid two-state subsystem on roll,
    with ``keys`` (TOML values as text) in place of or besides its own."""
    table = "".join(f"{k} = {v}\n" for k, v in {**_PH, **keys}.items())
    return vessel_with("[initial]", f"[port_hamiltonian]\n{table}[initial]")


CATALOGUE += [
    Bad("port-Hamiltonian Q with entries beyond any subsystem's scale", _ph(Q="[[1e308, 0.0], [0.0, 1e308]]"), E,
        ("port_hamiltonian.Q[0][0]", "within")),
    Bad("port-Hamiltonian J that is not skew", _ph(J="[[0.0, -1.0], [0.5, 0.0]]"), E, ("port_hamiltonian.J", "skew")),
    Bad("port-Hamiltonian R that is not symmetric", _ph(R="[[0.0, 0.1], [0.0, 0.1]]"), E,
        ("port_hamiltonian.R", "symmetric")),
    Bad("port-Hamiltonian R that is not positive semidefinite", _ph(R="[[0.0, 0.0], [0.0, -0.1]]"), E,
        ("port_hamiltonian.R", "semidefinite")),
    Bad("port-Hamiltonian Q that is only semidefinite", _ph(Q="[[2.0, 0.0], [0.0, 0.0]]"), E,
        ("port_hamiltonian.Q", "positive definite")),
    Bad("port-Hamiltonian Q that is not symmetric", _ph(Q="[[2.0, 0.5], [0.0, 1.0]]"), E,
        ("port_hamiltonian.Q", "symmetric")),
    Bad("port-Hamiltonian G with a row per state too many", _ph(G="[[1.0], [0.0], [0.0]]"), E,
        ("port_hamiltonian.G", "2")),
    Bad("port-Hamiltonian J of another size than the states", _ph(J="[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]"),
        E, ("port_hamiltonian.J", "2")),
    Bad("port-Hamiltonian input of an unknown degree of freedom", _ph(input='["rol"]'), E,
        ("port_hamiltonian.input", "rol", "sway")),
    Bad("port-Hamiltonian states named twice", _ph(states='["q", "q"]'), E, ("port_hamiltonian.states", "q")),
    Bad("port-Hamiltonian dissipation block [[R, P], [Pᵀ, S]] that is indefinite",
        _ph(P="[[0.0], [1.0]]", S="[[1.0]]"), E, ("port_hamiltonian", "P", "S", "semidefinite")),
]

# the subsystem's outputs against the results' own variables, and a record that does not fit


CATALOGUE += [
    Bad("port-Hamiltonian output named as a ledger variable", _ph(name='"energy"', states='["dissipated", "pi"]'), E,
        ("energy_dissipated", "port_hamiltonian.name", "port_hamiltonian.states")),
    Bad("port-Hamiltonian output named as a state variable", _ph(name='"phi"', states='["theta", "pi"]'), E,
        ("phi_theta", "rename")),
    Bad("rerun of a result whose vessel gained a port-Hamiltonian subsystem",
        rerun_damaged({"phsplit_vessel": PAPER.replace("[initial]", "[port_hamiltonian]\n" + "".join(
            f"{k} = {v}\n" for k, v in _PH.items()) + "[initial]", 1)}), E,
        ("initial_state", "29", "own states", "port_hamiltonian_q")),
    Bad("CLI: rerun of a result whose vessel gained a port-Hamiltonian subsystem",
        on_result("rerun", "r.nc", attrs={"phsplit_vessel": PAPER.replace("[initial]", "[port_hamiltonian]\n" + "".join(
            f"{k} = {v}\n" for k, v in _PH.items()) + "[initial]", 1)}), C, ("initial_state", "27 numbers", "29")),
    Bad("port-Hamiltonian vessel run with a Runge–Kutta method", lambda: phsplit.simulate(_ph()(), (0.0, 1.0), 0.5, "rk4"),
        E, ("port_hamiltonian", "splitting method")),
    Bad("port-Hamiltonian state vector one own state short",
        lambda: phsplit.simulate(_ph()(), (0.0, 1.0), 0.5, initial=np.r_[phsplit.Vessel.paper().initial_state(), 0.0]), E,
        ("27", "29", "got 28")),
]

# ------------------------------------------------------------------------------------------
# the static DP capability (phsplit.capability, phsplit capability)


def _hold(**kw) -> Callable[[], object]:
    from phsplit.capability import hold

    return lambda: hold("dp-capability", **{"direction": 90.0, "wind_speed": 10.0, **kw})


def _hold_external() -> object:
    from phsplit.capability import hold

    t = phsplit.load_scenario("dp-capability").vessel.to_dict()
    t["external"] = {"force": [1.0, 0.0, 0.0]}
    return hold(phsplit.Vessel.from_dict(t), 90.0, 10.0)


def _cap(**kw) -> Callable[[], object]:
    return lambda: phsplit.capability("dp-capability", **{"directions": [0.0], "failures": "none", **kw})


def _level1(col: int, row: int | slice, value: float) -> list[list[float]]:
    from phsplit.capability import LEVEL1

    t = [list(r) for r in LEVEL1]
    for r in (range(len(t))[row] if isinstance(row, slice) else [row]):
        t[r][col] = value
    return t


CATALOGUE += [
    Bad("capability directions given as text", _cap(directions=["0", "90"]), E, ("directions", "numbers")),
    Bad("capability directions given as booleans", _cap(directions=[True]), E, ("directions", "numbers")),
    Bad("capability direction of 360 degrees", _cap(directions=[360.0]), E, ("directions", "[0, 360)")),
    Bad("capability failure case named twice", _cap(failures=[[0], [0]]), E, ("failures", "[0]", "twice")),
    Bad("capability failure of a thruster that does not exist", _cap(failures=[[9]]), E,
        ("failures", "9", "0..3")),
    Bad("capability tolerance of zero", _cap(tolerance=0.0), E, ("tolerance", "[1e-9, 1]")),
    Bad("capability environment with Beaufort numbers that are not whole", _cap(environment=_level1(0, slice(None), 0.5)), E,
        ("environment", "Beaufort", "whole numbers")),
    Bad("capability environment with a sea state of no peak period", _cap(environment=_level1(3, 5, 0.0)), E,
        ("environment", "Beaufort 5", "Tp 0", "calm row")),
    Bad("capability environment with a peak period of 100 s", _cap(environment=_level1(3, 5, 100.0)), E,
        ("environment", "Beaufort 5", "[0.5, 40]")),
    Bad("capability environment with a current of 20 m/s", _cap(environment=_level1(4, 11, 20.0)), E,
        ("environment", "current", "10 m/s")),
    Bad("capability environment with winds to 100 m/s", _cap(environment=_level1(1, 11, 100.0)), E,
        ("environment", "wind", "80 m/s")),
    Bad("capability of a vessel without wind coefficients", lambda: phsplit.capability(phsplit.Vessel.paper()), E,
        ("vessel", "[wind]")),
    Bad("CLI: capability of a scenario without thrusters", cli("capability", "dp-weather", "--no-plot"), C,
        ("[thrusters]",)),
    Bad("CLI: capability into a folder that is a file", cli("capability", "dp-capability", "--out", "f", files={"f": b"x"}),
        C, ("--out", "'f'", "is a file")),
    Bad("CLI: capability onto a folder of the file's name",
        cli("capability", "dp-capability", "--out", "o", files={"o": None, "o/dp-capability-capability.nc": None}),
        C, ("dp-capability-capability.nc", "folder of that name")),
    Bad("CLI: capability with a step that does not divide 360", cli("capability", "dp-capability", "--step", "7"), C,
        ("--step", "divide 360", "7")),
    Bad("capability time-domain check of a thruster that does not exist", _hold(lost=[4]), E,
        ("lost", "0..3", "[4]")),
    Bad("capability time-domain check at a negative wind speed", _hold(wind_speed=-5.0), E, ("wind_speed", "[0, 80]")),
    Bad("capability time-domain check of no duration", _hold(t_end=0.0), E, ("t_end", "(0, 86400]")),
    Bad("capability time-domain check of a vessel with an external load", _hold_external, E,
        ("[external]", "mean wave drift")),
]

# ------------------------------------------------------------------------------------------
# the fluid memory (phsplit.radiation, fluid_memory = true)

_BOX = os.path.join(os.path.dirname(phsplit.__file__), "scenarios", "paper_box_capytaine.nc")


def _fm(**kw) -> Callable[[], object]:
    from phsplit import radiation

    return lambda: radiation.fluid_memory(_BOX, **kw)


def _with_fm(vessel: Callable[[], object], **kw) -> Callable[[], object]:
    from phsplit import radiation

    return lambda: radiation.with_fluid_memory(vessel(), _BOX, **kw)


_FM_SCENARIO = ('[simulation]\nt_span = [0.0, 2.0]\nh = 0.5\n[environment.waves]\nhs = 2.0\ntp = 8.0\n'
                'omega_range = [0.35, 2.0]\nsymmetric = true\n')

CATALOGUE += [
    Bad("fluid memory with a negative coupling tolerance", _fm(coupling_tolerance=-1.0), E,
        ("coupling_tolerance", "[0, 1)")),
    Bad("fluid memory with a coupling tolerance as text", _fm(coupling_tolerance="small"), E,
        ("coupling_tolerance", "[0, 1)", "small")),
    Bad("fluid memory with no starting points", _fm(starts=0), E, ("starts", "1 to 100")),
    Bad("fluid memory with refine as text", _fm(refine="yes"), E, ("refine", "true or false")),
    Bad("fluid memory named with a space", _fm(name="my memory"), E, ("name", "letters, digits and underscores")),
    Bad("fluid memory blocks for a group the dataset does not have", _fm(blocks={"sway_yaw": 2}), E,
        ("blocks", "sway_yaw", "sway_roll")),
    Bad("fluid memory blocks as text", _fm(blocks="many"), E, ("blocks", "'oscillator'", "many")),
    Bad("fluid memory of a dataset without radiation damping",
        lambda: __import__("phsplit.radiation").radiation.fluid_memory(
            __import__("xarray").open_dataset(_BOX).drop_vars("radiation_damping")), E, ("radiation_damping",)),
    Bad("fluid memory added to a vessel that has a subsystem", _with_fm(_ph()), E,
        ("already has a port-Hamiltonian subsystem",)),
    Bad("fluid memory with damping given as text", _with_fm(phsplit.Vessel.paper, damping={"damping_rotational": "x"}), E,
        ("damping['damping_rotational']", "3 numbers")),
    Bad("fluid memory of an existing fit with the fit's keywords",
        lambda: __import__("phsplit.radiation").radiation.with_fluid_memory(
            phsplit.Vessel.paper(), _BOX, memory=__import__("phsplit.radiation").radiation.fluid_memory(_BOX), starts=2),
        E, ("memory", "starts", "fluid_memory()")),
    Bad("scenario fluid memory given as text", scenario(_FM_SCENARIO + 'fluid_memory = "yes"\n'), P,
        ("environment.waves.fluid_memory", "true or false", "yes")),
    Bad("scenario fluid memory without a hydrodynamic dataset", scenario(_FM_SCENARIO + "fluid_memory = true\n"), P,
        ("environment.waves.fluid_memory", "environment.waves.hydro")),
    Bad("scenario fluid memory with an added mass of its own",
        lambda: _scenario_beside_box(_FM_SCENARIO + f'fluid_memory = true\nhydro = "{_BOX}"\n[vessel]\nfrom = "paper"\n'
                                     'added_mass = [[1e5, 0, 0, 0, 0, 0], [0, 1e5, 0, 0, 0, 0], [0, 0, 1e5, 0, 0, 0], '
                                     '[0, 0, 0, 1e6, 0, 0], [0, 0, 0, 0, 1e6, 0], [0, 0, 0, 0, 0, 1e6]]\n'), E,
        ("fluid_memory", "added_mass", "remove one")),
]


def _scenario_beside_box(text: str):
    return scenario(text)()


def _ph_dict(**keys) -> Callable[[], object]:
    """The paper's vessel as a Python dict with a [port_hamiltonian] table (``keys`` replacing its own)."""
    def run():
        d = phsplit.Vessel.paper().to_dict()
        d["port_hamiltonian"] = {"states": ["q", "pi"], "J": [[0.0, -1.0], [1.0, 0.0]], "R": [[0.0, 0.0], [0.0, 0.1]],
                                 "Q": [[2.0, 0.0], [0.0, 1.0]], "G": [[1.0], [0.0]], "input": ["roll"], **keys}
        return phsplit.Vessel.from_dict(d)
    return run


CATALOGUE += [
    Bad("port-Hamiltonian Q with an integer beyond any float (Python dict)", _ph_dict(Q=[[10 ** 400, 0.0], [0.0, 1.0]]), E,
        ("port_hamiltonian.Q[0][0]", "finite number", "too large")),
    Bad("port-Hamiltonian J with a boolean (Python dict)", _ph_dict(J=[[False, -1.0], [1.0, 0.0]]), E,
        ("port_hamiltonian.J[0][0]", "finite number")),
]


def _lumped(**keys) -> Callable[[], object]:
    """The paper's vessel with a dynamic pipe (``keys`` replacing the valid table's own)."""
    def run():
        d = phsplit.Vessel.paper().to_dict()
        d["pipe"] = {"model": "lumped_mass", "length": 600.0, "segments": 30, "axial_stiffness": 3.0e9, "mass": 120.0,
                     "diameter": 0.3, "water_depth": 200.0, "hang_off": [-40.0, 0.0, -10.0], "anchor": [143.8, -4.0],
                     **keys}
        return phsplit.Vessel.from_dict(d)
    return run


CATALOGUE += [
    Bad("dynamic pipe with one segment", _lumped(segments=1), E, ("pipe.segments", "integer from 2")),
    Bad("dynamic pipe with a fractional number of segments", _lumped(segments=2.5), E, ("pipe.segments", "integer")),
    Bad("dynamic pipe with a negative axial stiffness", _lumped(axial_stiffness=-3.0e9), E,
        ("pipe.axial_stiffness", "> 0", "N")),
    Bad("dynamic pipe shorter than the depth", _lumped(length=150.0), E, ("pipe.length", "seabed")),
    Bad("dynamic pipe hung off below the seabed", _lumped(hang_off=[-40.0, 0.0, -250.0]), E,
        ("pipe.hang_off[2]", "below the seabed")),
    Bad("dynamic pipe that floats", _lumped(mass=50.0), E, ("pipe.mass", "floats", "displaced water")),
    Bad("dynamic pipe with its anchor as one number", _lumped(anchor=[1.0]), E, ("pipe.anchor", "2 numbers")),
    Bad("dynamic pipe that would lie slack on the seabed", _lumped(length=2000.0), E,
        ("pipe.length", "slack", "anchor")),
    Bad("pipe of an unknown model", _lumped(model="fem"), E, ("pipe.model", "catenary", "lumped_mass")),
    Bad("dynamic pipe with a negative bending stiffness", _lumped(bending_stiffness=-1.0e6), E,
        ("pipe.bending_stiffness", "≥ 0")),
    Bad("dynamic pipe with sp4", lambda: phsplit.simulate(_lumped()(), (0.0, 10.0), 0.5, "sp4"), E,
        ("Strang", "order 2", "sp2")),
    Bad("driving a vessel without a dynamic pipe",
        lambda: phsplit.pipe.drive(phsplit.Vessel.paper(), [0.0, 1.0], [[0.0, 0.0, -10.0], [0.0, 0.0, -10.0]]), E,
        ("lumped_mass",)),
]


CATALOGUE += [
    Bad("port-Hamiltonian J given as None (Python dict)", _ph_dict(J=None), E,
        ("port_hamiltonian.J is None", "leave the key out")),
    Bad("port-Hamiltonian state in a unit CF does not know", _ph_dict(units=["furlongs", "kg m2 s-1"]), E,
        ("port_hamiltonian.units[0]", "furlongs", "CF unit")),
]


CATALOGUE += [
    # viscous roll damping
    Bad("roll damping with both linear and critical_fraction",
        vessel_with("[control]", "[roll_damping]\nlinear = 1.0e7\ncritical_fraction = 0.05\n\n[control]"), E,
        ("[roll_damping]", "not both")),
    Bad("roll damping at critical or beyond",
        vessel_with("[control]", "[roll_damping]\ncritical_fraction = 1.2\n\n[control]"), E,
        ("roll_damping.critical_fraction", "[0, 1)")),
    Bad("roll damping with a negative quadratic coefficient",
        vessel_with("[control]", "[roll_damping]\nquadratic = -4.0e9\n\n[control]"), E,
        ("roll_damping.quadratic", "≥ 0")),
    Bad("roll damping table with nothing in it",
        vessel_with("[control]", "[roll_damping]\nlinear = 0.0\n\n[control]"), E, ("[roll_damping] needs",)),
    Bad("CLI: RAO at a heading the dataset does not have", cli("rao", "--headings", "100", "--no-plot"), C,
        ("heading 100 deg is not a direction of the dataset",)),
    Bad("CLI: RAO of a vessel without a shipped dataset", cli("rao", "--vessel", "supply", "--no-plot"), C,
        ("--vessel supply", "no shipped dataset", "--dataset")),
]


def _rao_call(**kw) -> Callable[[], object]:
    def call():
        args = {"frequencies": [0.56], "heading": 90.0} | kw
        return phsplit.rao(phsplit.Vessel.paper(), args.pop("frequencies"), args.pop("heading"), **args)
    return call


CATALOGUE += [
    Bad("RAO at a frequency given as a string", _rao_call(frequencies=["0.56"]), E, ("frequencies must be positive numbers",)),
    Bad("RAO with a boolean amplitude", _rao_call(amplitude=True), E, ("amplitude must be a positive number",)),
    Bad("RAO heading given as a string", _rao_call(heading="90"), E, ("heading must be a number",)),
    Bad("RAO heading beyond a turn", _rao_call(heading=720.0), E, ("heading", "±360")),
    Bad("RAO at a frequency twice", _rao_call(frequencies=[0.56, 0.56]), E, ("frequencies must be distinct",)),
    Bad("RAO with dofs None", _rao_call(dofs=None), E, ("dofs must be distinct names",)),
    Bad("RAO with a step that cannot follow the wave", _rao_call(h=100.0, t_end=300.0), E,
        ("h = 100 s cannot follow the wave", "a quarter of its period")),
    Bad("RAO with a step so short the runs never end", _rao_call(h=1e-6, t_end=300.0), E, ("steps per frequency", "2e6")),
    Bad("RAO fitted over a tenth of a period", _rao_call(periods=0.1), E, ("periods must be at least 1",)),
    Bad("RAO with check_only as a string", _rao_call(check_only="no"), E, ("check_only must be True or False",)),
    Bad("CLI: RAO at the same heading twice", cli("rao", "--headings", "90", "90", "--no-plot"), C,
        ("--headings must be distinct",)),
    Bad("CLI: capability at a step of a nanodegree", cli("capability", "dp-capability", "--step", "1e-9", "--no-plot"), C,
        ("--step must be at least 0.1 degrees",)),
    Bad("CLI: capability with both directions and a step",
        cli("capability", "dp-capability", "--directions", "0", "90", "--step", "7", "--no-plot"), C,
        ("either --directions or --step",)),
    Bad("port-Hamiltonian name of 300 letters", _ph_dict(name="a" * 300), E, ("port_hamiltonian.name", "at most 64")),
]


CATALOGUE += [
    Bad("fluid memory on a vessel with an added mass of its own", lambda: phsplit.radiation.with_fluid_memory(
        phsplit.Vessel.from_dict({**phsplit.Vessel.paper().to_dict(), "vessel": {
            **phsplit.Vessel.paper().to_dict()["vessel"], "added_mass": [[1e5 if i == j else 0.0 for j in range(6)]
                                                                          for i in range(6)]}}),
        phsplit.seakeeping.DEFAULT_DATASET), E, ("vessel.added_mass", "infinite-frequency added mass")),
    Bad("fluid memory with an unknown keyword", lambda: phsplit.radiation.with_fluid_memory(
        phsplit.Vessel.paper(), phsplit.seakeeping.DEFAULT_DATASET, bogus=3), E, ("unknown keyword 'bogus'",)),
    Bad("roll damping of 1e300", vessel_with("[control]", "[roll_damping]\nlinear = 1e300\n\n[control]"), E,
        ("roll_damping.linear must be at most",)),
    Bad("motion statistics after a string", lambda: phsplit.simulate(phsplit.Vessel.paper(), (0.0, 2.0), 0.5, "sp2")
        .motion_statistics(after="5"), E, ("after must be a time in seconds",)),
    Bad("driving a pipe of no vessel", lambda: phsplit.pipe.drive(None, [0.0, 1.0], [[0.0, 0.0, -10.0]] * 2), E,
        ("vessel must be a phsplit.Vessel",)),
    Bad("driving a pipe over no times", lambda: phsplit.pipe.drive(phsplit.Vessel.paper(), [], []), E,
        ("times must be at least two",)),
    Bad("scenario waves with symmetric but no dataset",
        scenario("[simulation]\nt_span = [0.0, 1.0]\n[environment.waves]\nhs = 1.0\ntp = 8.0\nsymmetric = true\n"), P,
        ("environment.waves.symmetric", "needs environment.waves.hydro")),
    Bad("scenario waves with no transfer functions",
        scenario("[simulation]\nt_span = [0.0, 1.0]\n[environment.waves]\nhs = 1.0\ntp = 8.0\n"), E,
        ("environment.waves needs the hull's transfer functions",)),
]


CATALOGUE += [
    Bad("event whose condition fails later in the run", lambda: phsplit.simulate(
        phsplit.Vessel.paper(), (0.0, 5.0), 0.5, "sp2",
        events=[phsplit.events.Event("late", lambda t, y, v: 1.0 if t < 1.0 else 1.0 / 0.0)]), E,
        ("event 'late'", "raised ZeroDivisionError at t =")),
]


CATALOGUE += [
    Bad("scenario sea whose omega_range reaches past its dataset", scenario(
        open(phsplit.scenario.resolve("dp-weather")).read().replace(
            "omega_range = [0.35, 2.0]", "omega_range = [0.05, 5.0]").replace(
            'hydro = "paper_box_capytaine.nc"', f'hydro = "{phsplit.seakeeping.DEFAULT_DATASET}"')), E,
        ("environment.waves.omega_range = [0.05, 5]", "outside the dataset's 0.2-2 rad/s")),
]


CATALOGUE += [
    Bad("two events of the same name", lambda: phsplit.simulate(
        phsplit.Vessel.paper(), (0.0, 5.0), 0.5, "sp2",
        events=[phsplit.events.roll_beyond(30.0), phsplit.events.roll_beyond(30.0)]), E, ("named", "twice")),
    Bad("save_at together with save_every", lambda: phsplit.simulate(
        phsplit.Vessel.paper(), (0.0, 5.0), 0.5, "sp2", save_at=[1.0, 2.0], save_every=2), E,
        ("save_at", "save_every = 2 would not be used")),
    Bad("sea seed beyond 2^63", lambda: phsplit.sea.SeaState(hs=2.0, tp=9.0, seed=2 ** 70), E,
        ("seed must be an integer in [0, 2^63)",)),
]


_OBS = "[observer]\nwave_frequency = 0.7\ndamping = [3.5e4, 1.2e5, 3.2e8]\n"


def _observer(extra: str = "", feedback: str = 'feedback = "observer"\n') -> Callable[[], object]:
    return vessel_with("[control]\n", _OBS + extra + "\n[control]\n" + feedback)


CATALOGUE += [
    # the passive observer and the controller on its estimates
    Bad("observer table without the controller's feedback on it", _observer(feedback=""), E,
        ("[observer]", "control.feedback")),
    Bad("controller on an observer that is not there",
        vessel_with("[control]\n", '[control]\nfeedback = "observer"\n'), E,
        ("control.feedback", "[observer]", "wave_frequency")),
    Bad("anti-windup of an unknown kind",
        vessel_with("[control]\n", '[control]\nanti_windup = "clamp"\n'), E,
        ("control.anti_windup", "'none'", "'back_calculation'")),
    Bad("anti-windup without thrusters to saturate",
        vessel_with("[control]\n", '[control]\nanti_windup = "back_calculation"\n'), E,
        ("control.anti_windup", "[thrusters]", "unlimited")),
    Bad("anti-windup tracking time without anti-windup",
        vessel_with("[control]\n", '[control]\ntracking_time = 30.0\n'), E,
        ("control.tracking_time", "back_calculation")),
    Bad("anti-windup tracking time of zero",
        lambda: phsplit.Vessel.from_toml_str(
            PAPER.replace("[control]\n", '[control]\nanti_windup = "back_calculation"\ntracking_time = 0.0\n', 1)
            .replace("[initial]", _RATED.format(tunnel="", azimuth=""), 1)), E,
        ("control.tracking_time", "> 0")),
    Bad("controller feedback of an unknown kind",
        vessel_with("[control]\n", '[control]\nfeedback = "estimates"\n'), E,
        ("control.feedback", "'true_state'", "'observer'")),
    Bad("observer notch damped less than its wave model", _observer("notch_damping = 0.05\n"), E,
        ("observer.notch_damping", "wave_damping")),
    Bad("observer cut-off below its wave frequency", _observer("cutoff_frequency = 0.5\n"), E,
        ("observer.cutoff_frequency", "wave_frequency")),
    Bad("observer gains outside Fossen's rule",
        _observer("velocity_gain = [1e5, 1e5, 1e8]\nbias_gain = [1e5, 1e5, 1e8]\n"), E,
        ("bias_gain[0] / velocity_gain[0]", "1/bias_time_constant", "wave_frequency")),
    Bad("observer bias bandwidth below what its model damping allows", _observer("bias_bandwidth = 0.01\n"), E,
        ("observer", "bias_bandwidth", "velocity_gain")),
    Bad("observer with a wave frequency of zero",
        vessel_with("[control]\n", "[observer]\nwave_frequency = 0.0\ndamping = [1.0, 1.0, 1.0]\n\n[control]\nfeedback = \"observer\"\n"), E,
        ("observer.wave_frequency", "> 0")),
    Bad("observer without its model damping",
        vessel_with("[control]\n", "[observer]\nwave_frequency = 0.7\n\n[control]\nfeedback = \"observer\"\n"), E,
        ("observer.damping",)),
    Bad("observer with a key it does not take", _observer("wave_period = 9.0\n"), E,
        ("wave_period", "[observer]")),
    Bad("controller on the observer with rate-limited thrusters",
        lambda: phsplit.Vessel.from_toml_str(
            PAPER.replace("[control]\n", _OBS + '\n[control]\nfeedback = "observer"\n', 1)
            .replace("[initial]", _rated(), 1)), E,
        ("control.feedback", "thrusters that keep a memory", "thrust_rate", "true_state")),
    Bad("controller on the observer with a thruster that sticks",
        lambda: phsplit.Vessel.from_toml_str(
            PAPER.replace("[control]\n", _OBS + '\n[control]\nfeedback = "observer"\n', 1)
            .replace("[initial]", _rated(azimuth="stuck_at = 5.0\n"), 1)), E,
        ("control.feedback", "stuck_at", "lost_at")),
    Bad("controller on the observer with a moving set point",
        lambda: phsplit.Vessel.from_toml_str(
            PAPER.replace("[control]\n", _OBS + '\n[control]\nfeedback = "observer"\n', 1)
            .replace("[initial]", _SETPOINT.format(when="speed = 0.5", extra=""), 1)), E,
        ("control.feedback", "[setpoint]", "true_state")),
]



def _sensors(body: str, observer: bool = True) -> Callable[[], object]:
    table = "[sensors]\n" + body
    if observer:
        return vessel_with("[control]\n", _OBS + table + '\n[control]\nfeedback = "observer"\n')
    return vessel_with("[control]\n", table + "\n[control]\n")


_RATES = "gnss_rate = 1.0\ngyro_rate = 10.0\n"

CATALOGUE += [
    # the sensors the observer reads
    Bad("sensors without the observer that reads them", _sensors(_RATES, observer=False), E,
        ("[sensors]", "control.feedback", "observer")),
    Bad("sensors without a GNSS sample rate", _sensors("gyro_rate = 10.0\n"), E, ("sensors.gnss_rate",)),
    Bad("sensors sampling at no rate", _sensors("gnss_rate = 0.0\ngyro_rate = 10.0\n"), E,
        ("sensors.gnss_rate", "> 0")),
    Bad("sensors sampling 5000 times a second", _sensors("gnss_rate = 1.0\ngyro_rate = 5000.0\n"), E,
        ("sensors.gyro_rate", "1000")),
    Bad("GNSS noise of a negative standard deviation", _sensors(_RATES + "gnss_noise = -0.5\n"), E,
        ("sensors.gnss_noise", "[0, 100]")),
    Bad("gyro bias in degrees", _sensors(_RATES + "gyro_bias = 2.0\n"), E,
        ("sensors.gyro_bias", "degrees")),
    Bad("GNSS bias of three numbers", _sensors(_RATES + "gnss_bias = [0.1, 0.2, 0.3]\n"), E,
        ("sensors.gnss_bias", "2 numbers")),
    Bad("sensor dropout that ends before it starts", _sensors(_RATES + "gnss_dropout = [[60.0, 30.0]]\n"), E,
        ("sensors.gnss_dropout[0]", "end > start")),
    Bad("sensor dropouts that overlap", _sensors(_RATES + "gyro_dropout = [[10.0, 30.0], [20.0, 40.0]]\n"), E,
        ("sensors.gyro_dropout[1]", "time order")),
    Bad("sensor dropout as a single pair of times", _sensors(_RATES + "gnss_dropout = [10.0, 20.0]\n"), E,
        ("sensors.gnss_dropout", "rows of 2")),
    Bad("sensor seed that is negative", _sensors(_RATES + "seed = -1\n"), E, ("sensors.seed", "whole number")),
    Bad("sensor seed that is not whole", _sensors(_RATES + "seed = 1.5\n"), E, ("sensors.seed", "whole number")),
    Bad("sensors with a key they do not take", _sensors(_RATES + "gnss_nosie = 0.5\n"), E,
        ("gnss_nosie", "gnss_noise")),
]


def _one_line_syntax_error() -> object:
    try:
        phsplit.Vessel.from_toml_str("[vessel\nmass = 1\n")
    except phsplit.ScenarioParseError as e:
        if "\n" in str(e):
            raise AssertionError(f"a syntax error over several lines: {e!r}") from None
        raise


CATALOGUE += [
    # outputs that cannot be written, found before anything runs (an administrator's run passes
    # the permission checks everywhere: the folder is tried)
    Bad("CLI: rao into a folder of /proc", cli("rao", "--frequencies", "0.56", "--headings", "90", "--dofs", "roll",
                                               "--t-end", "240", "--out", "/proc/rao"), C,
        ("--out", "/proc", "not a writable folder")),
    Bad("CLI: capability into /sys/kernel", cli("capability", "dp-capability", "--directions", "0", "--failures",
                                                "none", "--out", "/sys/kernel"), C,
        ("--out", "/sys/kernel", "not a writable folder")),
    Bad("CLI: simulate into a folder of /proc", cli("simulate", "--t-end", "1", "--out", "/proc/run"), C,
        ("/proc/run",)),
    Bad("vessel file with a syntax error, said on one line", _one_line_syntax_error, P,
        ("TOML syntax error", "line 1", "column")),
    Bad("dynamic pipe anchored farther away than its length", _lumped(anchor=[5000.0, 0.0]), E,
        ("pipe.anchor", "farther than pipe.length", "600")),
]


def _pipelay_lost(*lost: int, value: object = 300.0) -> Callable[[], object]:
    def make():
        from phsplit import scenario as scn

        d = scn.load("pipelay").vessel.to_dict()
        for i in lost:
            d["thrusters"]["unit"][i]["lost_at"] = value
        return phsplit.Vessel.from_dict(d)
    return make


def _footprint(**kw) -> Callable[[], object]:
    def make():
        from phsplit import dp

        v = phsplit.Vessel.paper()
        s = phsplit.simulate(v, (0.0, 4.0), 0.5, "sp2")
        return dp.footprint(s, **{"vessel": v, **kw})
    return make


def _failures(**kw) -> Callable[[], object]:
    def make():
        from phsplit import dp
        from phsplit import scenario as scn

        sc = scn.load("pipelay")
        return dp.single_failures(**{"vessel": sc.vessel, "settings": sc.settings, "at": 300.0, **kw})
    return make


CATALOGUE += [
    # thruster failures and the DP footprint
    Bad("thrusters lost that leave no surge", _pipelay_lost(2, 3), E,
        ("thrusters.unit[*].lost_at", "thruster(s) 2, 3", "surge, sway and yaw")),
    Bad("thruster lost at a time that is a word", _pipelay_lost(1, value="noon"), P,
        ("thrusters.unit[1].lost_at", "number")),
    Bad("footprint after a time given as a word", _footprint(after="late"), E,
        ("footprint", "after", "finite time")),
    Bad("footprint after the run's end", _footprint(after=10.0), E,
        ("footprint", "fewer than two saved states", "ends at 4")),
    Bad("footprint without a set point to measure from", _footprint(vessel=None), E,
        ("footprint", "control.position_reference", "reference")),
    Bad("footprint from a reference of two numbers", _footprint(reference=(780.0, 20.0)), E,
        ("footprint", "reference must be 3 finite numbers")),
    Bad("single failures after the run's end", _failures(at=5000.0), E,
        ("single_failures", "at must be a time within", "[0, 3600)")),
    Bad("single failures of a vessel without thrusters", _failures(vessel=phsplit.Vessel.paper()), E,
        ("single_failures", "no [thrusters]")),
    Bad("CLI: failures of a scenario without thrusters", cli("failures", "dp-weather", "--at", "5"), C,
        ("vessel", "no [thrusters]")),
    Bad("CLI: failures without the time of the failure", cli("failures", "pipelay"), C,
        ("--at",)),
]


def _pipelay_with_loss(t: float = 100.0) -> bytes:
    from phsplit import scenario as scn

    with open(os.path.join(scn.SHIPPED_DIR, "pipelay.toml"), encoding="utf-8") as f:
        text = f.read()
    marker = "max_thrust = 6.55e5"
    assert marker in text
    return text.replace(marker, f"{marker}\nlost_at = {t}").encode()


def _rerun_capability() -> object:
    import tempfile as tf

    from phsplit.capability import capability

    with tf.TemporaryDirectory() as d:
        p = os.path.join(d, "cap.nc")
        capability("dp-capability", directions=[0.0], failures="none").to_netcdf(p)
        with open(p, "rb") as f:
            data = f.read()
    return cli("rerun", "cap.nc", files={"cap.nc": data})()


def _capability_lost() -> object:
    from phsplit import scenario as scn

    d = scn.load("dp-capability").vessel.to_dict()
    d["thrusters"]["unit"][3]["lost_at"] = 100.0
    return phsplit.Vessel.from_dict(d)


def _seakeeping(fn: str, *args, **kw) -> Callable[[], object]:
    def run():
        from phsplit import seakeeping

        return getattr(seakeeping, fn)(*args, **kw)
    return run


def _held(*args, **kw) -> Callable[[], object]:
    def run():
        from phsplit import scenario as scn
        from phsplit.capability import held

        return held(scn.load("dp-capability").vessel, *args, **kw)
    return run


def _footprint_of(s_or_name, **kw) -> Callable[[], object]:
    def run():
        from phsplit import dp

        s = s_or_name
        if s == "run":
            s = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 4.0), 0.5, "sp2")
        return dp.footprint(s, **kw)
    return run


CATALOGUE += [
    # values that make no sense on the DP system's tables and functions
    Bad("observer initial heading estimate in degrees", _observer("initial_estimate = [780.0, 20.0, 30.0]\n"), E,
        ("observer.initial_estimate[2]", "degrees")),
    Bad("observer initial estimate far from any set point", _observer("initial_estimate = [1e300, 0.0, 0.0]\n"), E,
        ("observer.initial_estimate", "10000 m of the set point")),
    Bad("observer initial bias beyond any environment", _observer("initial_bias = [1e300, 0.0, 0.0]\n"), E,
        ("observer.initial_bias[0]", "10 GN")),
    Bad("observer cut-off frequency in other units", _observer("cutoff_frequency = 40.0\n"), E,
        ("observer.cutoff_frequency", "10", "rad/s")),
    Bad("thruster lost far in the future", _pipelay_lost(3, value=1e12), E, ("lost_at", "1e9 s")),
    Bad("CLI: failure study of a scenario that already loses a thruster",
        lambda: cli("failures", "pl.toml", "--at", "5", "--t-end", "10", files={"pl.toml": _pipelay_with_loss()})(), C,
        ("thrusters.unit[3].lost_at", "remove lost_at")),
    Bad("CLI: failure at the very end of the run", cli("failures", "pipelay", "--at", "3599.9"), C,
        ("--at", "fewer than two saved states")),
    Bad("capability of a vessel that already loses a thruster",
        lambda: phsplit.capability(_capability_lost(), directions=[0.0]), E,
        ("capability: vessel", "lost_at", "failures")),
    Bad("failure study on no workers", lambda: _failures(max_workers=-1)(), E, ("max_workers", "from 1 to 512")),
    Bad("footprint of a file name", _footprint_of("file.nc", reference=(0.0, 0.0, 0.0)), E,
        ("footprint", "phsplit.Solution", "str")),
    Bad("footprint about a heading in degrees", _footprint_of("run", reference=(780.0, 20.0, 31.0)), E,
        ("footprint", "heading", "degrees")),
    Bad("footprint about a reference given as text", _footprint_of("run", reference="here"), E,
        ("footprint: reference", "3 finite numbers")),
    Bad("allocation of a demand of two numbers", _held([1.0, 2.0]), E, ("capability: demand", "3 finite numbers")),
    Bad("allocation of a demand that is not a number", _held([float("nan"), 0.0, 0.0]), E,
        ("capability: demand", "3 finite numbers")),
    Bad("allocation without a fractional thruster", _held([1.0, 0.0, 0.0], lost=[0.5]), E,
        ("capability: lost", "whole numbers")),
    Bad("capability with failures of None", lambda: phsplit.capability("dp-capability", failures=None), E,
        ("capability: failures", "got None")),
    Bad("frequency-domain RAO from 720 degrees", _seakeeping("frequency_rao", phsplit.Vessel.paper(), 0.56, 720.0), E,
        ("frequency_rao: heading", "±360")),
    Bad("frequency-domain RAO at a frequency given as text", _seakeeping("frequency_rao", phsplit.Vessel.paper(), "0.5", 90.0), E,
        ("frequency_rao: omega", "positive number")),
    Bad("linear model of a mapping", _seakeeping("linear_model", {}), E, ("linear_model: vessel", "phsplit.Vessel")),
    Bad("RAO in a wave too steep to exist", _seakeeping("rao", phsplit.Vessel.paper(), [0.56], 90.0, amplitude=1e6,
                                                         check_only=True), E, ("amplitude", "1/7", "break")),
    Bad("roll damping with a misspelt key", vessel_with("[initial]", "[roll_damping]\nlinera = 1e8\n\n[initial]"), P,
        ("linera", "linear")),
    Bad("port-Hamiltonian subsystem starting with more energy than any vessel has",
        _ph(initial="[1e150, 0.0]"), E, ("port_hamiltonian.initial", "J", "units of Q")),
]


CATALOGUE += [
    # a sweep's values, each tried on the vessel before anything starts
    Bad("sweep over a mass no vessel can have",
        _load_sweep_text(_SWEEP_HEAD + b'[sweep.parameters]\n"vessel.mass" = [-6e6, 7e6]\n'), E,
        ("sweep.parameters.vessel.mass = -6e+06", "vessel.mass must be > 0")),
    Bad("sweep that lists a value twice",
        _load_sweep_text(_SWEEP_HEAD + b'[sweep.parameters]\n"vessel.mass" = [6e6, 6e6]\n'), E,
        ("sweep.parameters.vessel.mass", "twice")),
    Bad("sweep over a setting that is not a number",
        _load_sweep_text(_SWEEP_HEAD + b'[sweep.parameters]\n"control.feedback" = [0.0, 1.0]\n'), E,
        ("control.feedback", "not a number")),
    Bad("random sweep whose lower bound no vessel can have",
        _load_sweep_text(_SWEEP_HEAD + b'mode = "random"\nsamples = 2\n[sweep.parameters]\n"vessel.mass" = {low = -1.0, high = 7e6}\n'),
        E, ("sweep.parameters.vessel.mass = -1", "> 0")),
]


def _rao_of(scenario_name: str) -> Callable[[], object]:
    def run():
        from phsplit import scenario as scn
        from phsplit import seakeeping

        return seakeeping.rao(scn.load(scenario_name).vessel, [0.56], 90.0, check_only=True)
    return run


CATALOGUE += [
    Bad("RAO of a vessel held by a pipe", _rao_of("pipelay"), E, ("[pipe]", "without it")),
    Bad("RAO adding a fluid memory to a vessel with a subsystem",
        lambda: __import__("phsplit.seakeeping").seakeeping.rao(_ph_dict()(), [0.56], 90.0, check_only=True), E,
        ("port-Hamiltonian subsystem", "fluid_memory=False")),
]


CATALOGUE += [
    Bad("observer model damping beyond any ship's",
        vessel_with("[control]\n", "[observer]\nwave_frequency = 0.7\ndamping = [1e300, 1e300, 1e300]\n\n"
                    "[control]\nfeedback = \"observer\"\n"), E, ("observer.damping[0]", "1e13")),
    Bad("observer velocity gain beyond any placement's",
        _observer("velocity_gain = [1e300, 1e300, 1e300]\nbias_gain = [1e299, 1e299, 1e299]\n"), E,
        ("observer.velocity_gain[0]", "1e16")),
    Bad("dynamic pipe 50 m across", _lumped(diameter=50.0, mass=1e7), E, ("pipe.diameter", "(0, 5]")),
    Bad("CLI: Runge-Kutta on a scenario with a fluid memory, refused before the fit",
        cli("simulate", "osv-weather", "--method", "rk4", "--t-end", "2"), C,
        ("--method rk4", "fluid memory", "splitting method")),
    Bad("scenario adding a fluid memory to a vessel with a subsystem, refused before the fit",
        scenario('[simulation]\nt_span = [0.0, 1.0]\n[port_hamiltonian]\nstates = ["q", "pi"]\n'
                 'J = [[0.0, -1.0], [1.0, 0.0]]\nR = [[0.0, 0.0], [0.0, 0.1]]\nQ = [[2.0, 0.0], [0.0, 1.0]]\n'
                 'G = [[1.0], [0.0]]\ninput = ["roll"]\n[environment.waves]\nhs = 1.0\ntp = 9.0\n'
                 f'hydro = {os.path.join(os.path.dirname(phsplit.__file__), "scenarios", "paper_box_capytaine.nc")!r}\n'
                 'fluid_memory = true\n'.replace("'", '"')), E,
        ("fluid_memory", "already has a port-Hamiltonian subsystem")),
]


def _fmu_export_adaptive():
    from phsplit import fmu
    from phsplit.scenario import Scenario

    with tempfile.TemporaryDirectory() as d:
        fmu.export(Scenario(phsplit.Vessel.paper(), phsplit.Settings(rtol=1e-4)), os.path.join(d, "a.fmu"))


CATALOGUE += [
    Bad("adaptive rtol of zero", sim(rtol=0.0), E, ("rtol", "(0, 1]")),
    Bad("adaptive rtol above one", sim(rtol=2.0), E, ("rtol", "(0, 1]")),
    Bad("adaptive rtol below round-off", sim(rtol=1e-16), E, ("rtol", "1e-13")),
    Bad("negative adaptive atol", sim(atol=-1e-3), E, ("atol", "(0, 1e3]")),
    Bad("infinite adaptive atol", sim(atol=float("inf")), E, ("atol",)),
    Bad("h_max without a tolerance", sim(h_max=5.0), E, ("h_max", "rtol or atol")),
    Bad("zero h_max", sim(atol=1e-3, h_max=0.0), E, ("h_max", "> 0")),
    Bad("adaptive steps with Runge-Kutta", sim(method="rk4", atol=1e-3), E, ("rk4", "splitting methods")),
    Bad("adaptive save_at outside the span", sim(atol=1e-3, save_at=[5.0, 20.0]), E, ("save_at",)),
    Bad("adaptive settings given twice",
        lambda: phsplit.simulate(phsplit.Vessel.paper(), settings=phsplit.Settings(t_span=(0.0, 5.0)), atol=1e-3), E,
        ("atol", "would not be used", "Settings")),
    Bad("simulate_many with adaptive steps",
        lambda: phsplit.simulate_many([{"vessel.mass": 6e6}], settings=phsplit.Settings(t_span=(0.0, 5.0), atol=1e-3)),
        E, ("simulate_many", "time grid", "rtol and atol")),
    Bad("sweep file with adaptive steps", _load_sweep_text(
        b'[simulation]\nh = 1.0\nt_span = [0.0, 2.0]\natol = 1e-3\n[sweep]\n' + _MASS_GRID), P,
        ("a sweep", "time grid")),
    Bad("scenario rtol as text", scenario('[simulation]\nrtol = "tight"\n'), P, ("simulation.rtol", "number")),
    Bad("FMU export of an adaptive scenario", _fmu_export_adaptive, E, ("FMU", "fixed internal step", "rtol")),
    Bad("CLI: scenario with a zero rtol", cli(*SIM, "s.toml", files={
        "s.toml": b'[simulation]\nt_span = [0.0, 2.0]\nrtol = 0.0\n'}), C, ("rtol", "(0, 1]")),
]


CATALOGUE += [
    Bad("adaptive atol below round-off", sim(atol=1e-20), E, ("atol", "1e-12")),
    Bad("adaptive h_max asking for too many steps", sim(atol=1e-3, h_max=1e-9), E, ("h_max", "at most")),
    Bad("adaptive first step longer than h_max", sim(atol=1e-3, h=1.0, h_max=0.1), E, ("h_max", "h <= h_max")),
    Bad("save_at as a 2-D array", sim(save_at=[[1.0, 2.0], [3.0, 4.0]]), E, ("save_at", "flat")),
]


# arguments of the public functions (phsplit._arguments), simulate_many, run_sweep, result files
def _polar_plot(ds, path="cap.png"):
    def run():
        from phsplit.capability import polar_plot

        with tempfile.TemporaryDirectory() as d:
            return polar_plot(ds() if callable(ds) else ds, os.path.join(d, path))

    return run


def _not_a_capability_result():
    import xarray as xr

    return xr.Dataset({"energy": ("time", [1.0, 2.0])})


def _run_sweep(**kw):
    def run():
        from phsplit.batch import Sweep, run_sweep

        with tempfile.TemporaryDirectory() as d:
            sweep = Sweep(settings=phsplit.Settings(t_span=(0.0, 1.0)), base=phsplit.Vessel.paper(), cases=_ONE)
            return run_sweep(sweep, os.path.join(d, "store"), **kw)

    return run


def _open_text_as_result():
    with tempfile.TemporaryDirectory() as d:
        p = os.path.join(d, "notes.nc")
        with open(p, "w") as f:
            f.write("time,x\n0,1\n")
        return phsplit.open_dataset(p)


def _fluid_memory_damping(values):
    def run():
        from phsplit.radiation import with_fluid_memory
        from phsplit.seakeeping import DEFAULT_DATASET

        return with_fluid_memory(phsplit.Vessel.paper(), DEFAULT_DATASET, damping={"damping_translational": values})

    return run


_ONE = [{"vessel.mass": 6e6}]

CATALOGUE += [
    Bad("simulate with an unknown keyword", sim(t_spam=(0.0, 1.0)), E, ("t_spam", "did you mean t_span")),
    Bad("simulate without a vessel", lambda: phsplit.simulate(), E, ("simulate()", "vessel")),
    Bad("simulate with a step beside settings",
        lambda: phsplit.simulate(phsplit.Vessel.paper(), h=0.1, settings=phsplit.Settings(t_span=(0.0, 1.0))), E,
        ("h", "would not be used", "Settings")),
    Bad("simulate with a method beside settings",
        lambda: phsplit.simulate(phsplit.Vessel.paper(), method="sp2", settings=phsplit.Settings(t_span=(0.0, 1.0))),
        E, ("method", "would not be used")),
    Bad("rao with an unknown keyword", lambda: phsplit.rao(phsplit.Vessel.paper(), [0.5], 180.0, bogus=1), E,
        ("rao()", "'bogus'", "heading")),
    Bad("capability with an unknown keyword", lambda: phsplit.capability("dp-capability", direction=[0.0]), E,
        ("capability()", "'direction'", "did you mean directions")),
    Bad("with_fluid_memory with a negative damping", _fluid_memory_damping([-1.0, 0.0, 0.0]), E,
        ("damping", "damping_translational")),
    Bad("with_fluid_memory with an infinite damping", _fluid_memory_damping([float("inf"), 0.0, 0.0]), E,
        ("damping", "damping_translational")),
    Bad("simulate_many with no thread", lambda: phsplit.simulate_many(_ONE, max_workers=0, t_span=(0.0, 1.0)), E,
        ("max_workers", "from 1 to")),
    Bad("simulate_many with a negative thread count",
        lambda: phsplit.simulate_many(_ONE, max_workers=-1, t_span=(0.0, 1.0)), E, ("max_workers", "from 1 to")),
    Bad("simulate_many with a fractional thread count",
        lambda: phsplit.simulate_many(_ONE, max_workers=1.5, t_span=(0.0, 1.0)), E, ("max_workers", "whole number")),
    Bad("simulate_many with no case", lambda: phsplit.simulate_many([], t_span=(0.0, 1.0)), E, ("cases is empty",)),
    Bad("simulate_many with events", lambda: phsplit.simulate_many(
        _ONE, events=[phsplit.events.watch_circle(10.0)], t_span=(0.0, 1.0)), E, ("simulate_many", "events")),
    Bad("simulate_many with save_at", lambda: phsplit.simulate_many(_ONE, save_at=[0.5], t_span=(0.0, 1.0)), E,
        ("simulate_many", "save_at")),
    Bad("simulate_many with a misspelt setting", lambda: phsplit.simulate_many(_ONE, t_spam=(0.0, 1.0)), E,
        ("t_spam", "did you mean t_span")),
    Bad("simulate_many with a step beside settings",
        lambda: phsplit.simulate_many(_ONE, settings=phsplit.Settings(t_span=(0.0, 1.0)), h=0.1), E,
        ("h", "would not be used")),
    Bad("run_sweep with negative retries", _run_sweep(retries=-1), E, ("retries", "from 0 to 100")),
    Bad("run_sweep with retries as text", _run_sweep(retries="3"), E, ("retries", "whole number")),
    Bad("run_sweep with progress as text", _run_sweep(progress="yes"), E, ("progress", "True or False")),
    Bad("polar plot of a result that is not a capability", _polar_plot(_not_a_capability_result), E,
        ("polar_plot: ds", "not a capability result", "wind_speed_limit")),
    Bad("polar plot of a list", _polar_plot([1, 2, 3]), E, ("polar_plot: ds", "xarray.Dataset")),
    Bad("capability environment with a NaN", lambda: phsplit.capability(
        "dp-capability", environment=[[0, 0, 0, 0, 0], [1, float("nan"), 1, 5, 0.1]]), E,
        ("environment", "row 1", "nan", "wind speed")),
    Bad("open_dataset of a text file", _open_text_as_result, E, ("notes.nc", "not a NetCDF file")),
    Bad("open_dataset of a number", lambda: phsplit.open_dataset(42), E, ("path", "int")),
    Bad("initial state of the wrong length", sim(initial=np.zeros(5)), E, ("initial", "27 numbers", "got 5")),
    Bad("current faster than the component's range", scenario(
        'vessel = "paper"\n[environment.current]\nspeed = 20\ndirection_towards = 45\n'), E,
        ("environment.current.speed", "from 0 to 10 m/s")),
    Bad("CLI: rerun of a file that is text", cli("rerun", "x.nc", files={"x.nc": b"t,x\n0,1\n"}), C,
        ("x.nc", "not a NetCDF file")),
    Bad("CLI: plot of a file that is text", cli("plot", "x.nc", files={"x.nc": b"t,x\n0,1\n"}), C,
        ("x.nc", "not a NetCDF file")),
]


# a thruster that fails as set (thrusters.unit[i].stuck_at) and the failure study's modes
def _pipelay_stuck(*stuck: int, value: object = 300.0, lost: bool = False) -> Callable[[], object]:
    def make():
        from phsplit import scenario as scn

        d = scn.load("pipelay").vessel.to_dict()
        for i in stuck:
            d["thrusters"]["unit"][i]["stuck_at"] = value
            if lost:
                d["thrusters"]["unit"][i]["lost_at"] = value
        return phsplit.Vessel.from_dict(d)
    return make


def _study_of_stuck():
    from phsplit import dp, scenario as scn

    sc = scn.load("pipelay")
    return dp.single_failures(_pipelay_stuck(1)(), sc.settings, at=600.0)


CATALOGUE += [
    Bad("thruster both lost and stuck", _pipelay_stuck(1, lost=True), E,
        ("thrusters.unit[1]", "lost_at", "stuck_at", "not both")),
    Bad("thruster stuck at a time that is a word", _pipelay_stuck(1, value="noon"), P,
        ("thrusters.unit[1].stuck_at", "number")),
    Bad("thruster stuck at a NaN time", _pipelay_stuck(1, value=float("nan")), E, ("thrusters.unit[1].stuck_at",)),
    Bad("thruster stuck beyond a billion seconds", _pipelay_stuck(1, value=2e9), E, ("thrusters.unit[1].stuck_at",)),
    Bad("thrusters stuck that leave no surge", _pipelay_stuck(2, 3), E,
        ("stuck_at", "2 (stuck), 3 (stuck)", "surge, sway and yaw")),
    Bad("single failures in an unknown mode", _failures(mode="jammed"), E, ("single_failures", "mode", "lost, stuck, both")),
    Bad("single failures of a vessel that already sticks a thruster", _study_of_stuck, E,
        ("thrusters.unit[1].stuck_at", "remove stuck_at")),
    Bad("CLI: failures in an unknown mode", cli("failures", "pipelay", "--at", "5", "--mode", "jammed"), C,
        ("--mode", "jammed")),
]

CATALOGUE += [
    # the GNSS antenna's lever arm and the MRU that refers the fix to the body origin
    Bad("GNSS antenna 900 m up", _sensors(_RATES + "gnss_antenna = [0.0, 0.0, -900.0]\n"), E,
        ("sensors.gnss_antenna", "250")),
    Bad("GNSS antenna of two numbers", _sensors(_RATES + "gnss_antenna = [1.0, 2.0]\n"), E, ("sensors.gnss_antenna",)),
    Bad("MRU bias of one number", _sensors(_RATES + "gnss_antenna = [0.0, 0.0, -20.0]\nmru_bias = [0.01]\n"), E,
        ("sensors.mru_bias must be 2 numbers",)),
    Bad("MRU bias in degrees", _sensors(_RATES + "gnss_antenna = [0.0, 0.0, -20.0]\nmru_bias = [5.7, 0.0]\n"), E,
        ("sensors.mru_bias", "0.1")),
    Bad("negative MRU noise", _sensors(_RATES + "gnss_antenna = [0.0, 0.0, -20.0]\nmru_noise = -0.01\n"), E,
        ("sensors.mru_noise",)),
    Bad("MRU errors without an antenna offset", _sensors(_RATES + "mru_noise = 0.001\n"), E,
        ("mru_noise", "with the antenna at the origin nothing reads it", "gnss_antenna")),
]


# magnitudes no vessel, sea or planet has (the physical ranges of the vessel's own keys)
CATALOGUE += [
    Bad("a mass of 1e20 kg", vessel_with("mass = ", "mass = 1e20 #"), E, ("vessel.mass", "1e9")),
    Bad("an inertia of 1e20 kg m^2", vessel_with("inertia = [2.873071e8", "inertia = [1e20"), E, ("vessel.inertia[0]", "1e14")),
    Bad("gravity of 1000 m/s^2", vessel_with("gravity = 9.81", "gravity = 1000.0"), E, ("vessel.gravity", "on Earth")),
    Bad("water of 1e6 kg/m^3", vessel_with("water_density = 1.025e3", "water_density = 1e6"), E,
        ("vessel.water_density", "[950, 1250]")),
    Bad("a metacentric height of 100 km", vessel_with("gm_transverse = 2.1440", "gm_transverse = 1e5"), E,
        ("vessel.gm_transverse", "2000")),
    Bad("an initial position 1e12 m away", vessel_with("position = [723.0", "position = [1e12"), E,
        ("initial.position[0]", "1e7")),
]


def _fmu_export(**kw):
    def run():
        import phsplit.fmu as fmu

        with tempfile.TemporaryDirectory() as d:
            return fmu.export(None, os.path.join(d, "v.fmu"), **kw)

    return run


def _fmu_load(**kw):
    def run():
        import phsplit.fmu as fmu

        with tempfile.TemporaryDirectory() as d:
            return fmu.export_load(os.path.join(d, "l.fmu"), **kw)

    return run


def _capability_plot(path):
    def run():
        from phsplit.capability import polar_plot

        ds = phsplit.capability("dp-capability", directions=[0.0, 90.0], failures="none")
        with tempfile.TemporaryDirectory() as d:
            return polar_plot(ds, os.path.join(d, path))

    return run


def _windy(**wind):
    body = "".join(f"{k} = {v}\n" for k, v in wind.items())
    return scenario('vessel = "paper"\n[environment.wind]\nspeed = 10.0\nfrontal_area = 200.0\n' + body)


def _hydro_cog():
    from phsplit import hydro
    from phsplit.seakeeping import DEFAULT_DATASET

    return hydro.from_capytaine(DEFAULT_DATASET, center_of_gravity=[0.0, 0.0])


CATALOGUE += [
    Bad("single failures on a million threads", _failures(max_workers=10 ** 6), E,
        ("single_failures", "max_workers", "from 1 to 512")),
    Bad("RAO by Runge-Kutta with the fluid memory",
        lambda: phsplit.rao(phsplit.Vessel.paper(), [0.56], 90.0, method="rk4", check_only=True), E,
        ("method = 'rk4'", "fluid memory", "fluid_memory=False")),
    Bad("regular wave of negative amplitude", lambda: phsplit.sea.regular(-1.0, 1.0), E, ("regular: amplitude",)),
    Bad("regular wave of zero frequency", lambda: phsplit.sea.regular(1.0, 0.0), E, ("regular: omega", "(0, 10]")),
    Bad("Blendermann's table of a negative frontal area",
        lambda: phsplit.sea.blendermann("offshore supply vessel", -100.0, 300.0, 50.0), E,
        ("blendermann: frontal_area", "> 0")),
    Bad("Harris's drag with the NPD spectrum", _windy(drag=0.003), E,
        ("environment.wind.drag", "'harris'", "'npd'")),
    Bad("NPD's height with the Harris spectrum", _windy(height=20.0, spectrum='"harris"'), E,
        ("environment.wind.height", "'npd'")),
    Bad("FMU of an empty model name", _fmu_export(model_name=""), E, ("model_name", "non-empty string")),
    Bad("load FMU of a period given as text", _fmu_load(period="60"), E, ("period", "number of seconds")),
    Bad("load FMU of a mean given as text", _fmu_load(force_mean=["1", "0", "0"]), E, ("force_mean", "3 numbers")),
    Bad("polar plot into a text file", _capability_plot("cap.txt"), E, ("polar_plot: path", "cap.txt", ".png")),
    Bad("simulate_many on a vessel's name", lambda: phsplit.simulate_many(_ONE, base="osvv", t_span=(0.0, 1.0)), E,
        ("base must be a phsplit.Vessel", "'osvv'")),
    Bad("Settings with a misspelt field", lambda: phsplit.Settings(t_spn=(0.0, 5.0)), E,
        ("Settings()", "'t_spn'", "did you mean t_span")),
    Bad("rerun of a number", lambda: phsplit.rerun(42), E, ("rerun", "path", "int")),
    Bad("the dynamic pipe with SP4", lambda: phsplit.simulate(
        phsplit.load_scenario("pipelay-dynamic").vessel, (0.0, 1.0), 0.5, "sp4"), E,
        ("simulation.method", "order 4", "lie or sp2")),
    Bad("hydrodynamic data placed at a centre of gravity of two numbers", _hydro_cog, E,
        ("center_of_gravity", "three finite numbers")),
    Bad("a scenario key given twice", scenario('[simulation]\nh = 1.0\nh = 0.5\n'), P,
        ("the key h of [simulation] is given twice", "line 3")),
    Bad("a scenario table given twice", scenario('[simulation]\nh = 1.0\n[simulation]\nmethod = "sp2"\n'), P,
        ("the table [simulation] is given twice", "line 3")),
]


def _sol():
    return phsplit.simulate(phsplit.Vessel.paper(), (0.0, 5.0), 0.5, "sp2")


def _garbage_sweep_store():
    with tempfile.TemporaryDirectory() as d:
        os.makedirs(os.path.join(d, "store"))
        with open(os.path.join(d, "store", "sweep.json"), "w") as f:
            f.write("garbage{")
        return phsplit.open_sweep(os.path.join(d, "store"))


_WAVES = ('vessel = "paper"\n[environment.waves]\nhydro = "paper_box_capytaine.nc"\nsymmetric = true\n'
          'omega_range = [0.35, 1.9]\ndirection = 180.0\nseed = 1\ncomponents = 20\n')

CATALOGUE += [
    Bad("observer bias bandwidth beside both gains", _observer(
        "bias_bandwidth = 0.1\nvelocity_gain = [1e6, 1e6, 1e9]\nbias_gain = [1e4, 1e4, 1e7]\n"), E,
        ("observer.bias_bandwidth", "would not act")),
    Bad("wind centroid without a ship type", _windy(centroid_x=5.0), E, ("environment.wind.centroid_x", "ship_type")),
    Bad("gust components without a gust spectrum", _windy(spectrum='"none"', components=50), E,
        ("environment.wind.components", "spectrum = 'none'")),
    Bad("JONSWAP's gamma with Pierson-Moskowitz", scenario(
        _WAVES + 'hs = 2.0\ntp = 9.0\nspectrum = "pierson-moskowitz"\ngamma = 2.0\n'), E,
        ("environment.waves.gamma", "'pierson-moskowitz'")),
    Bad("a sea steeper than breaking waves", scenario(_WAVES + "hs = 25.0\ntp = 3.0\n"), E,
        ("environment.waves", "steepness", "1/7")),
    Bad("an unknown way of sampling the directions", scenario(
        _WAVES + 'hs = 2.0\ntp = 9.0\nspreading = 5.0\ndirection_sampling = "sobol"\n'), E,
        ("direction_sampling", "'quasi_random', 'random'", "'sobol'")),
    Bad("direction sampling of a long-crested sea", scenario(_WAVES + 'hs = 2.0\ntp = 9.0\ndirection_sampling = "random"\n'),
        E, ("environment.waves.direction_sampling", "needs spreading")),
    Bad("random directions without spreading", lambda: phsplit.sea.SeaState(hs=2.0, tp=9.0, direction_sampling="random"),
        E, ("direction_sampling = 'random' needs spreading",)),
    Bad("capability failure naming a thruster twice", _cap(failures=[[0, 0]]), E, ("failures", "twice in one")),
    Bad("frequency-domain RAO of a negative amplitude", lambda: phsplit.seakeeping.frequency_rao(
        phsplit.Vessel.paper(), 0.56, 90.0, amplitude=-1.0), E, ("frequency_rao: amplitude", "positive")),
    Bad("time-domain RAO over half a period", lambda: phsplit.seakeeping.time_rao(
        phsplit.Vessel.paper(), {}, 0.56, 90.0, periods=0.5), E, ("time_rao: periods", ">= 1")),
    Bad("Harris spectrum of a negative wind", lambda: phsplit.sea.harris(np.array([0.01]), -5.0), E,
        ("harris: speed", "> 0")),
    Bad("NPD spectrum below the sea", lambda: phsplit.sea.npd(np.array([0.01]), 10.0, height=-1.0), E,
        ("npd: height", "> 0")),
    Bad("fluid-memory block of an unknown kind", lambda: phsplit.radiation.block_matrices("spring", [1, 2, 0.5, 0.1]),
        E, ("kind", "oscillator, ladder", "'spring'")),
    Bad("natural periods with the controller as text", lambda: phsplit.Vessel.paper().natural_periods(control="yes"),
        E, ("natural_periods: control", "True or False")),
    Bad("compare a result with text", lambda: phsplit.results.compare(_sol().to_xarray(), "x"), E,
        ("compare: b", "xarray.Dataset", "str")),
    Bad("a sweep store whose sweep.json is damaged", _garbage_sweep_store, E, ("sweep.json", "damaged")),
    Bad("shift matrix of two numbers", lambda: phsplit.hydro.shift_matrix([1.0, 2.0]), E,
        ("shift_matrix: r", "three finite numbers")),
    Bad("drift over a zero frequency", lambda: phsplit.seakeeping.drift(_sol(), 0.0, 10.0), E,
        ("drift: omega", "positive")),
    Bad("a state past the saved ones", lambda: _sol().state(100), E, ("state: i", "from -11 to 10", "100")),
    Bad("a state at a fractional index", lambda: _sol().state(1.5), E, ("state: i", "whole number", "1.5")),
    Bad("method information of a number", lambda: phsplit.method_info(42), E, ("method_info", "sp4", "int")),
    Bad("a scenario that is a number", lambda: phsplit.load_scenario(42), E, ("scenario", "str", "int")),
    Bad("rerun of a capability result", lambda: phsplit.rerun(
        phsplit.capability("dp-capability", directions=[0.0], failures="none")), E,
        ("DP capability", "nothing to repeat")),
]


def _fmu_at(path, make_dir=None, file=None, load=False, **kw):
    def run():
        import phsplit.fmu as fmu

        with tempfile.TemporaryDirectory() as d:
            if make_dir:
                os.mkdir(os.path.join(d, make_dir))
            if file:
                with open(os.path.join(d, file), "w") as f:
                    f.write("x")
            out = os.path.join(d, path) if isinstance(path, str) else path
            return fmu.export_load(out, **kw) if load else fmu.export(None, out, **kw)

    return run


CATALOGUE += [
    Bad("FMU under a file", _fmu_at("f/x.fmu", file="f"), E, ("out", "is a file, not a folder")),
    Bad("load FMU under a file", _fmu_at("f/l.fmu", file="f", load=True), E, ("out", "is a file, not a folder")),
    Bad("FMU onto a folder", _fmu_at("adir.fmu", make_dir="adir.fmu"), E, ("out", "is a folder")),
    Bad("load FMU onto a folder", _fmu_at("adir.fmu", make_dir="adir.fmu", load=True), E, ("out", "is a folder")),
    Bad("FMU at a number", _fmu_at(42), E, ("out must be the .fmu file's path", "42")),
    Bad("FMU binaries as the CLI's text", _fmu_at("v.fmu", binaries="win64=x.dll"), E,
        ("binaries must be a mapping", "--binary")),
    Bad("load FMU binaries as text", _fmu_at("l.fmu", load=True, binaries="win64=x.dll"), E,
        ("binaries must be a mapping",)),
    Bad("FMU binary path that is a number", _fmu_at("v.fmu", binaries={"win64": 42}), E,
        ("binaries must be a mapping", "path")),
]

CATALOGUE += [
    Bad("the index of a sweep store that does not exist", lambda: __import__("phsplit.sweepstore").sweepstore.store_index("no-such-store"), E,
        ("sweep store", "'no-such-store'", "not a folder")),
]
