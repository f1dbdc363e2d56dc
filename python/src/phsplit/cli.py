"""The ``phsplit`` command line."""
from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time

from . import _signals


def _check_out_folder(out: str) -> None:
    """``--out`` names a folder that is there or can be made, checked before anything runs."""
    if os.path.exists(out) and not os.path.isdir(out):
        raise UsageError(f"--out {out!r} is a file, not a folder")
    parent, ok = _writable_ancestor(out)
    if not ok:
        raise UsageError(f"cannot write into --out {out!r}: {parent!r} is not a writable folder")


def _writable_ancestor(path: str) -> tuple[str, bool]:
    """The nearest existing folder of ``path`` (itself if it exists) and whether a file and a
    folder can be made in it: what an output that is not yet there needs. Tried, not asked of
    the permissions (which an administrator's run passes everywhere, /proc and /sys included);
    what the try makes is removed at once."""
    parent = path
    while not os.path.exists(parent):
        parent = os.path.dirname(os.path.abspath(parent))
    if not os.path.isdir(parent):
        return parent, False
    try:
        fd, probe = tempfile.mkstemp(dir=parent, prefix=".phsplit-probe-")
        os.close(fd)
        os.remove(probe)
        if not os.path.exists(path):
            made = tempfile.mkdtemp(dir=parent, prefix=".phsplit-probe-")
            os.rmdir(made)
    except OSError:
        return parent, False
    return parent, True


def _shipped() -> list[str]:
    from .scenario import shipped

    return shipped()


EXAMPLES = """examples:
  phsplit simulate                         # the paper's Fig. 2 scenario (SP4, h = 0.5, [0, 200])
  phsplit simulate scenario.toml --out runs/
  phsplit simulate pipelay                 # a shipped scenario: pipe-lay along a route, thrusters, 1 h
  phsplit simulate dp-weather              # a shipped scenario: station keeping in waves, wind, current, 1 h
  phsplit simulate pipelay-dynamic         # station keeping in waves over a dynamic (lumped-mass) pipe, 1 h
  phsplit simulate --method sp2 --h 0.25 --t-end 400
  phsplit simulate --control-start never   # the controller off throughout
  phsplit simulate --vessel osv --t-end 600  # Fossen's 83 m offshore supply vessel (MSS osv.m) in DP
  phsplit vessels                          # the shipped vessels and their sources
  phsplit methods                          # methods with order, stages and passivity guarantee
  phsplit reproduce --out paper/           # the paper's Figs. 2-4, stability sweep and report
  phsplit reproduce --quick                # the same in a few seconds, with coarser references
  phsplit sweep gains.toml --out gains.store                # a parameter sweep on a local Dask cluster
  phsplit sweep gains.toml --scheduler tcp://10.0.0.5:8786  # ... on an existing Dask cluster
  phsplit rerun out/fig2.nc                # rerun what a result file records, check it bit for bit
  phsplit plot out/fig2.nc --watch-circle 5  # the DP figure of a result file
  phsplit fmu export -o vessel.fmu         # an FMI 2.0 co-simulation FMU of the Fig. 2 vessel
  phsplit fmu export pipelay -o pipelay.fmu  # ... of a shipped scenario's vessel and settings
  phsplit capability dp-capability         # static DP capability (DNV-ST-0111 level 1 style), NetCDF + polar PNG
"""


class _Parser(argparse.ArgumentParser):
    """argparse with its usage errors on one line (``phsplit: error: …``), exit status 2."""

    def error(self, message):
        self.exit(2, f"phsplit: error: {self.prog}: {message} (see '{self.prog} --help')\n")


def _parser() -> argparse.ArgumentParser:
    from . import _core

    p = _Parser(
        prog="phsplit",
        description="Passivity-preserving splitting simulation of a vessel under DP control.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    s = sub.add_parser(
        "simulate",
        help="run a scenario (default: the paper's Fig. 2) and write NetCDF + PNG",
        description="Run a scenario and write <out>/<name>.nc (xarray/NetCDF) and <out>/<name>.png. "
        "Options given on the command line are appended to the name (fig2-rk4-h0.25.nc). "
        "The NetCDF file is built under a unique temporary name and renamed when closed: Ctrl-C or "
        "SIGTERM leaves either no file or a valid one with the steps computed so far; a second run "
        "writing the same output at the same time is refused.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s.add_argument("scenario", nargs="?", help="scenario TOML file, or the name of a shipped scenario "
                   f"({', '.join(_shipped())}; default: the paper's Fig. 2)")
    s.add_argument("--vessel", help="run the scenario with this vessel: a vessel file, or a shipped "
                   "vessel's name (see 'phsplit vessels')")
    s.add_argument("--out", default="out", help="output folder (default: ./out)")
    s.add_argument("--method", help="override the method")
    s.add_argument("--h", type=float, help="override the step size, s")
    s.add_argument("--t-end", type=float, help="override the end time, s")
    s.add_argument("--save-every", type=int, help="save every k-th step (decimation)")
    s.add_argument("--control-start", help="override the controller's start time, s, or 'never'")
    s.add_argument("--linear-flow", choices=["auto", *_core.LINEAR_FLOWS],
                   help="flow S2: 'auto' (the library's default: exact where it acts on a diagonal mass "
                   "matrix, else Gauss collocation), exactly (matrix exponentials, the paper's; the default "
                   "of the Fig. 2 scenario), by Gauss collocation of the method's order, or of order 4 or 6 "
                   "whatever the method (in a sea, sp2 with gauss4 reaches 1 cm at about four times the step)")
    s.add_argument("--rtol", type=float, help="adaptive steps to this relative tolerance (--h: the first step)")
    s.add_argument("--atol", type=float, help="adaptive steps to this absolute tolerance (m, rad, m/s, rad/s)")
    s.add_argument("--h-max", type=float, help="longest adaptive step, s")
    s.add_argument("--no-plot", action="store_true", help="skip the PNG")
    sub.add_parser("methods", help="list the integration methods")
    sub.add_parser("vessels", help="list the shipped vessels (phsplit.Vessel.preset) and their sources")
    r = sub.add_parser(
        "reproduce",
        help="regenerate the paper's Figs. 2, 3, 4 and the stability sweep, with a report",
        description="Run the experiments of the paper's §4 and write PNG/PDF figures, NetCDF data "
        "and report.md / report.html (a table of the paper's claims with what was measured).",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    r.add_argument("--out", default="reproduction", help="output folder (default: ./reproduction)")
    r.add_argument("--quick", action="store_true", help="coarser references and fewer steps (a few seconds)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    w = sub.add_parser(
        "sweep",
        help="run a grid or random parameter sweep on Dask, resumable",
        description="Expand [sweep.parameters] of SWEEP.toml into cases and run them on dask.distributed "
        "(a LocalCluster on 127.0.0.1, or --scheduler ADDRESS). Each finished case is stored as "
        "STORE/cases/<id>.nc; a rerun computes only the missing cases; STORE/summary.csv and "
        "summary.nc hold one row per case.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    rr = sub.add_parser(
        "rerun",
        help="rerun the simulation a phsplit NetCDF file records and check it bit for bit",
        description="Read the vessel, settings, initial state and chunking recorded in FILE.nc, run "
        "them again, and compare every variable with the file's. Exit status 0 when every number "
        "agrees to the last bit, 1 when some differ (they are listed).",
        epilog="examples:\n  phsplit rerun out/fig2.nc\n  phsplit rerun out/fig2.nc --out rerun/   # also write the rerun",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    rr.add_argument("file", help="a NetCDF file written by phsplit")
    rr.add_argument("--out", help="also write the rerun as <out>/<file name>")
    pl = sub.add_parser(
        "plot",
        help="draw the DP figure of a phsplit NetCDF file",
        description="Draw the main figure of a run from its file: the horizontal track with the set point "
        "(and a watch circle), distance and heading errors, roll, pitch and heave, the controller's force "
        "and moment, and the energy ledger by port. Angles in degrees.",
        epilog="examples:\n  phsplit plot out/fig2.nc\n  phsplit plot out/fig2.nc --watch-circle 5 --out fig2-dp.png",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    pl.add_argument("file", help="a NetCDF file written by phsplit")
    pl.add_argument("--out", help="the image to write (default: FILE with .png; .pdf and .svg work too)")
    pl.add_argument("--watch-circle", type=float, help="radius of the watch circle about the set point, m")
    fm = sub.add_parser(
        "fmu",
        help="export a vessel (or a load source) as an FMI 2.0 co-simulation FMU",
        description="Write an FMI 2.0 co-simulation FMU for FMPy, OSP's libcosim and other FMI hosts "
        "(docs/fmu.md). 'export' packs a scenario's vessel and settings with phsplit's compiled core "
        "(no Python inside); 'load' packs a periodic force and moment source to couple with it.",
        epilog="examples:\n  phsplit fmu export -o vessel.fmu\n  phsplit fmu export dp-weather -o dp.fmu\n"
        "  phsplit fmu export scenario.toml -o my.fmu --binary win64=target/x86_64-pc-windows-gnu/release/phsplit_fmu.dll\n"
        "  phsplit fmu load -o load.fmu --force-mean 2e5 0 0 --force-amplitude 1e5 5e4 0 --period 40",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    fsub = fm.add_subparsers(dest="fmu_command", metavar="FMU_COMMAND")
    fe = fsub.add_parser("export", help="a scenario's vessel and settings as an FMU")
    fe.add_argument("scenario", nargs="?", help="scenario TOML file or shipped scenario name (default: the paper's Fig. 2)")
    fe.add_argument("-o", "--out", default="vessel.fmu", help="the FMU to write (default: vessel.fmu)")
    fe.add_argument("--binary", action="append", default=[], metavar="PLATFORM=PATH",
                    help="add a binary built for another platform (win64, darwin64, linux32, ...); repeatable")
    fl = fsub.add_parser("load", help="a periodic load source FMU: mean + amplitude sin(2 pi t / period)")
    fl.add_argument("-o", "--out", default="load.fmu", help="the FMU to write (default: load.fmu)")
    for k, unit in (("force-mean", "N"), ("force-amplitude", "N"), ("moment-mean", "N m"), ("moment-amplitude", "N m")):
        fl.add_argument(f"--{k}", type=float, nargs=3, default=[0.0, 0.0, 0.0], metavar=("X", "Y", "Z"),
                        help=f"{k.replace('-', ' ')}, {unit} (default 0 0 0)")
    fl.add_argument("--period", type=float, default=60.0, help="period, s (default 60)")
    cp = sub.add_parser(
        "capability",
        help="static DP capability: the largest wind speed held per direction, intact and with each thruster lost",
        description="For each direction of a co-linear level-1 environment (DNV-ST-0111 (2021): wind with its "
        "sea state and current), the largest wind speed whose mean load the thrusters can balance within their "
        "limits (the core's allocation), intact and with each single thruster lost. Writes <out>/<name>-capability.nc "
        "and a polar plot <out>/<name>-capability.png (docs/how-to/dp-capability.md).",
        epilog="examples:\n  phsplit capability dp-capability\n  phsplit capability osv-capability\n  phsplit capability my-scenario.toml --step 15 --out cap/\n"
        "  phsplit capability dp-capability --directions 0 90 180 270 --failures none",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    cp.add_argument("scenario", help="scenario TOML file or shipped scenario name whose vessel has [wind] "
                    "coefficients and [thrusters] (e.g. dp-capability)")
    cp.add_argument("--vessel", help="use this vessel (a file or a shipped vessel's name) in the scenario")
    cp.add_argument("--directions", type=float, nargs="+", metavar="DEG",
                    help="directions the environment comes from, degrees off the bow, clockwise (default: every --step)")
    cp.add_argument("--step", type=float, default=10.0, help="spacing of the directions, degrees (default 10)")
    cp.add_argument("--failures", choices=["single", "none"], default="single",
                    help="'single': intact and each thruster lost in turn (default); 'none': intact only")
    cp.add_argument("--tolerance", type=float, default=0.01, help="bisection tolerance in wind speed, m/s (default 0.01)")
    cp.add_argument("--out", default="out", help="output folder (default: ./out)")
    cp.add_argument("--no-plot", action="store_true", help="skip the PNG")
    fa = sub.add_parser(
        "failures",
        help="the worst single thruster failure: the scenario run intact and with each thruster failed at a time",
        description="Runs the scenario intact and with each of its thrusters failed at --at (--mode lost: "
        "thrusters.unit[i].lost_at, it delivers nothing; --mode stuck: stuck_at, it keeps its thrust and angle; "
        "--mode both: each way; from then the allocation redistributes the demand over the others) and prints, "
        "per case, the footprint "
        "after the failure (largest and RMS excursion from the set point, heading deviation, thruster utilisation, "
        "time saturated) and the worst case (docs/how-to/dp-failures.md).",
        epilog="examples:\n  phsplit failures pipelay --at 600\n  phsplit failures pipelay --at 600 --t-end 1800\n"
        "  phsplit failures pipelay --at 600 --mode both",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    fa.add_argument("scenario", help="scenario TOML file or shipped scenario name whose vessel has [thrusters]")
    fa.add_argument("--at", type=float, required=True, help="time of the failure, s, within the run")
    fa.add_argument("--t-end", type=float, help="override the end time, s")
    fa.add_argument("--vessel", help="use this vessel (a file or a shipped vessel's name) in the scenario")
    fa.add_argument("--mode", choices=["lost", "stuck", "both"], default="lost",
                    help="how each thruster fails: lost (delivers nothing), stuck (keeps its thrust and angle), "
                    "or both (default: lost)")
    ra = sub.add_parser(
        "rao",
        help="motion RAOs in regular waves, time domain against the frequency domain of a Capytaine dataset",
        description="For each heading and frequency, the vessel from rest in one regular wave (controller off, "
        "with Cummins' fluid memory of the dataset unless --no-fluid-memory), the amplitude and phase of each DOF "
        "from a sinusoid fitted over the last periods, against [-w^2 (M + A(w)) + iw (B(w) + D) + C]^-1 F(w) of the "
        "same dataset. Writes <out>/<vessel>-rao.nc and a plot <out>/<vessel>-rao.png "
        "(docs/how-to/seakeeping-rao.md).",
        epilog="examples:\n  phsplit rao\n  phsplit rao --vessel osv --headings 90 180\n"
        "  phsplit rao --frequencies 0.44 0.56 0.68 --dofs roll --amplitude 0.05 --out rao/",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ra.add_argument("--vessel", default="paper", help="a vessel file or a shipped vessel's name (default: paper)")
    ra.add_argument("--dataset", help="Capytaine dataset (NetCDF) of the hull (default: the shipped vessel's own)")
    ra.add_argument("--headings", type=float, nargs="+", default=[90.0, 180.0], metavar="DEG",
                    help="wave directions relative to the bow, directions of the dataset (default: 90 180, beam and head)")
    ra.add_argument("--frequencies", type=float, nargs="+", metavar="RAD_S",
                    help="wave frequencies, rad/s (default: the dataset's within 0.3-1.9 rad/s)")
    ra.add_argument("--dofs", nargs="+", default=["heave", "roll", "pitch"],
                    choices=["surge", "sway", "heave", "roll", "pitch", "yaw"], help="DOFs (default: heave roll pitch)")
    ra.add_argument("--amplitude", type=float, default=0.1, help="wave amplitude, m (default 0.1)")
    ra.add_argument("--h", type=float, default=0.5, help="step, s (default 0.5)")
    ra.add_argument("--t-end", type=float, default=600.0, help="length of each run, s (default 600)")
    ra.add_argument("--no-fluid-memory", action="store_true", help="the vessel as it is: its own added mass and damping")
    ra.add_argument("--out", default="out", help="output folder (default: ./out)")
    ra.add_argument("--no-plot", action="store_true", help="skip the PNG")
    w.add_argument("sweep", help="sweep TOML file ([simulation] + [sweep])")
    w.add_argument("--out", help="result store (a folder; default: <sweep name>.store)")
    w.add_argument("--scheduler", help="address of an existing Dask scheduler, e.g. tcp://host:8786")
    w.add_argument("--workers", type=int, help="worker processes of the local cluster (default: cores)")
    w.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


class UsageError(Exception):
    pass


#: Seconds a run goes before its progress bar appears (a shorter run shows none).
PROGRESS_DELAY = 2.0


def _progress_bar(n: int):
    """The progress bar of a run of ``n`` steps, on a terminal: shown once the run has taken
    :data:`PROGRESS_DELAY` seconds, whatever its number of steps, and updated while the core
    integrates (not only between chunks)."""
    from tqdm import tqdm

    return tqdm(total=n, unit="step", unit_scale=True, disable=not sys.stderr.isatty(), delay=PROGRESS_DELAY,
                leave=False)


def _chunks(n: int, save_every: int, target: int = 100, min_steps: int = 20_000) -> list[int]:
    """Split n steps into at most about `target` chunks of at least `min_steps` steps (so a short
    run is one call), each a multiple of save_every (but the last)."""
    size = max(save_every, -(-n // target), min_steps)
    size = -(-size // save_every) * save_every
    out = []
    while n > 0:
        out.append(min(size, n))
        n -= out[-1]
    return out


def _vessel_stem(vessel: str) -> str:
    """A --vessel's name for output names: a preset's name, a vessel file's stem."""
    import re

    return re.sub(r"[^A-Za-z0-9._-]", "_", os.path.splitext(os.path.basename(vessel))[0]).lstrip("._-") or "vessel"


def _override_suffix(args) -> str:
    """What the command line changed, appended to the output name, so that runs of one scenario
    with different options do not overwrite each other (fig2-rk4-h0.25.nc). Numbers are written
    in their shortest exact form, so different values give different names."""
    import re

    def num(x: float) -> str:
        s = repr(float(x))
        return s[:-2] if s.endswith(".0") else s

    parts = []
    if getattr(args, "vessel", None) and getattr(args, "scenario", None):  # without one the name is the vessel's
        parts.append(_vessel_stem(args.vessel))
    if args.method:
        parts.append(args.method.lower())
    if args.h is not None:
        parts.append(f"h{num(args.h)}")
    if args.t_end is not None:
        parts.append(f"t{num(args.t_end)}")
    if args.save_every is not None:
        parts.append(f"s{args.save_every}")
    if args.linear_flow is not None:
        parts.append(args.linear_flow)
    for flag in ("rtol", "atol", "h_max"):
        if getattr(args, flag, None) is not None:
            parts.append(f"{flag.replace('_', '')}{num(getattr(args, flag))}")
    if args.control_start is not None:
        parts.append(f"c{args.control_start}")
    # Only the characters a scenario name may hold (the values were validated before this).
    return "".join("-" + re.sub(r"[^A-Za-z0-9._-]", "_", x) for x in parts)


class _DeferSignals:
    """Hold SIGINT and SIGTERM while a chunk is written and booked, then act on them: an
    interrupt never lands inside the NetCDF writer or between writing rows and counting them."""

    def __enter__(self):
        import signal

        self.got = None
        self.old = {}
        for sig in (signal.SIGINT, signal.SIGTERM):
            self.old[sig] = signal.signal(sig, self._hold)
        return self

    def _hold(self, signum, frame):
        self.got = signum

    def __exit__(self, *exc):
        import signal

        for sig, h in self.old.items():
            signal.signal(sig, h)
        if self.got is not None and exc[0] is None:
            raise KeyboardInterrupt
        return False


def _components(vessel) -> str:
    """The vessel's components for the summary, the controller's set point and thrusters named."""
    tables = vessel.to_dict()
    extra = [name for key, name in (("setpoint", "moving set point"), ("thrusters", "thrusters")) if key in tables]
    return ", ".join(f"pid ({', '.join(extra)})" if c == "pid" and extra else c for c in vessel.components)


def _simulate(args) -> int:
    import phsplit
    from . import cf
    from . import scenario as scn
    from .files import BusyError, PartialFile
    from .plotting import plot_dp

    if args.scenario and args.method in ("euler", "heun", "rk4"):
        # Refused before the scenario's fluid memory is fitted (tens of seconds): its states are
        # the splitting's to carry (the core refuses any other vessel with states of its own).
        raw = scn._read_toml(scn.resolve(args.scenario), "scenario file")
        waves = raw.get("environment", {}).get("waves", {}) if isinstance(raw.get("environment"), dict) else {}
        if isinstance(waves, dict) and waves.get("fluid_memory") is True:
            raise UsageError(f"--method {args.method}: the scenario's fluid memory (environment.waves.fluid_memory) "
                             "keeps states of its own, which the Runge–Kutta kernel does not carry: use a splitting "
                             "method (lie, sp2, sp4, ...)")
    if args.scenario:
        # --vessel replaces the scenario's vessel; its environment, operation and overrides stay.
        try:
            sc = scn.load(args.scenario, vessel=args.vessel)
        except (phsplit.InvalidInputError, phsplit.ScenarioParseError) as e:
            if not args.vessel:
                raise
            raise type(e)(f"--vessel {args.vessel} with scenario {args.scenario}: {e}") from None
        args.scenario = sc.path  # a shipped scenario's file
    else:
        sc = scn.Scenario.paper_fig2()
        if args.vessel:
            import dataclasses

            # The paper's Fig. 2 run with another vessel is named after that vessel, not "fig2".
            sc = dataclasses.replace(sc, vessel=scn.vessel_named(args.vessel), name=_vessel_stem(args.vessel))
    over = {}
    if args.method:
        over["method"] = args.method
    if args.h is not None:
        over["h"] = args.h
    if args.t_end is not None:
        over["t_span"] = (sc.t_span[0], args.t_end)
    if args.save_every is not None:
        over["save_every"] = args.save_every
    if args.linear_flow is not None:
        over["linear_flow"] = args.linear_flow
    for flag in ("rtol", "atol", "h_max"):
        if getattr(args, flag, None) is not None:
            over[flag] = getattr(args, flag)
    if args.control_start is not None:
        if args.control_start == "never":
            over["control_start"] = None
        else:
            try:
                over["control_start"] = float(args.control_start)
            except ValueError:
                raise UsageError(f"--control-start must be a time in s or 'never', got {args.control_start!r}") from None
    sc = sc.replace(**over)
    out = args.out
    # Validate everything (and learn the step count) before any file is touched.
    n = sc.settings.checked()["n_steps"]
    _first_step(sc)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"cannot create output folder {out!r}: {e.strerror}") from None
    if not _writable_ancestor(out)[1]:
        raise UsageError(f"output folder {out!r} is not writable")
    name = sc.name + _override_suffix(args)
    nc = os.path.join(out, f"{name}.nc")
    try:
        # The temporary file, locked: a second run writing the same output is refused, not mixed in.
        partial = PartialFile(nc)
    except BusyError:
        raise UsageError(f"another phsplit run is writing {nc} right now; "
                         "wait for it to finish, or choose another --out or scenario name") from None
    except OSError as e:
        raise UsageError(f"cannot create a file in {out!r}: {e.strerror}") from None
    t0, t1 = sc.t_span
    ctl = "never" if sc.control_start is None else f"t={sc.control_start:g} s"
    try:
        print(f"phsplit {phsplit.__version__}: {sc.name}: {sc.method} h={sc.h:g} s on "
              f"[{t0:g}, {t1:g}] s ({n} steps), controller from {ctl}; components: "
              f"{_components(sc.vessel)}", flush=True)
        if sc.environment:
            print(f"environment: {scn.describe_environment(sc.environment)}", flush=True)
    except BaseException:
        partial.discard()  # nothing was written yet
        raise
    part = partial.part
    t_start = time.perf_counter()
    done = 0
    status = "completed"
    sols = []
    nc_file = None
    from .chunks import run_chunks
    from .runner import warn_if_timed_settings_idle
    from .settings import settings_to_toml

    used = sc.settings.checked()
    warn_if_timed_settings_idle(sc.vessel, used["t_span"], stacklevel=2, control_start=used["control_start"],
                                used=used)
    bar = _progress_bar(n)
    try:
        # Adaptive steps run as one call: a cut would restart the step-size controller.
        chunks = [n] if sc.settings.adaptive else _chunks(n, sc.save_every)
        text = None
        if args.scenario:
            with open(args.scenario, "rb") as f:
                text = f.read().decode("utf-8", "replace")
        file_attrs = {  # the whole run's, over the first chunk's (phsplit rerun reads them)
            "phsplit_settings": settings_to_toml(sc.settings.checked()),
            "phsplit_chunks": " ".join(map(str, chunks)),
            "phsplit_scenario_path": args.scenario or "(built in: the paper's Fig. 2)",
            "phsplit_scenario": text if text is not None else "",
            "phsplit_environment": scn.describe_environment(sc.environment) if sc.environment else "calm water",
            "history": f"{cf.utc_now()} phsplit {phsplit.__version__}: phsplit {' '.join(args.argv)}",
        }
        for sol in run_chunks(sc.vessel, sc.settings, sc.vessel.initial_state(), chunks, progress=bar.update):
            with _DeferSignals():
                nc_file = _append(nc_file, part, sol, first=(done == 0), attrs=file_attrs)
                sols.append(sol)
                done += sol.steps
            if sol.status == "interrupted":  # the core stopped on a signal and returned what it had
                status = "interrupted"
                break
            if sol.status != "completed":
                status = "failed"
                break
    except KeyboardInterrupt:
        status = "interrupted"
    except BaseException:
        status = "failed"  # the file keeps the steps before the error, and says so
        raise
    finally:
        bar.close()
        with _DeferSignals():
            if nc_file is not None:
                if sols:
                    from .chunks import motion_of

                    _write_motion(nc_file, motion_of(sols))
                nc_file.setncattr("status", status)
                nc_file.setncattr("steps", done)
                nc_file.close()
                partial.publish()
            else:
                partial.discard()
    dt = time.perf_counter() - t_start
    if status == "interrupted":
        if sols:
            print(f"phsplit: interrupted after {done} of {n} steps; {os.path.abspath(nc)} holds them", file=sys.stderr)
        else:
            print("phsplit: interrupted before the first steps; no file was written", file=sys.stderr)
        return 130
    last = sols[-1]
    files = [nc]
    if not args.no_plot:
        png = os.path.join(out, f"{name}.png")
        from .chunks import joined

        ds_all = joined(sols)
        plot_dp(ds_all, png)
        files.append(png)
        if "pipe_node_position" in ds_all:
            from .plotting import plot_pipe

            pipe_png = os.path.join(out, f"{name}-pipe.png")
            plot_pipe(ds_all, pipe_png)
            files.append(pipe_png)
    e = last.euler[-1]
    rr = max(float(s_.ledger.relative_residual().max()) for s_ in sols)
    total = _seconds_since_start()
    print(f"{status}: {done} steps in {total:.2f} s in all (start-up, integration, writing, plotting); "
          f"integration and writing {dt:.3f} s")
    print(f"t = {last.t[-1]:g} s: x = ({last.x[-1, 0]:.3f}, {last.x[-1, 1]:.3f}, {last.x[-1, 2]:.4f}) m, "
          f"roll/pitch/yaw = ({e[0]:.5f}, {e[1]:.5f}, {e[2]:.5f}) rad")
    print(f"energy H: {sols[0].energy[0]:.6e} -> {last.energy[-1]:.6e} J; worst relative ledger residual {rr:.2e}")
    booked = {a: sum(float(s_.ledger.by_account[a].sum()) for s_ in sols) for a in last.ledger.by_account}
    print("ledger, J: " + ", ".join(f"{a} {last.ledger.kinds[a]} {v:.6e}" for a, v in booked.items()))
    if "waves" in sc.vessel.to_dict():
        from .chunks import motion_of

        m = motion_of(sols)
        deg = 180.0 / math.pi
        print(f"motion over the run: heave σ {m['heave'][1]:.3g} m (max {m['heave'][3]:.3g} m), "
              f"roll σ {deg * m['roll'][1]:.3g}° (max {deg * m['roll'][3]:.3g}°), "
              f"pitch σ {deg * m['pitch'][1]:.3g}° (max {deg * m['pitch'][3]:.3g}°); significant (4σ) "
              f"{m['heave'][4]:.3g} m, {deg * m['roll'][4]:.3g}°, {deg * m['pitch'][4]:.3g}°")
    for f in files:
        print(f"wrote {os.path.abspath(f)}")
    if status != "completed":
        print(f"error: the run failed: {last.failure}; the file holds the steps before it", file=sys.stderr)
        return 1
    return 0


def _first_step(sc) -> None:
    """Run the scenario's first step, before any file is touched: what the core refuses only
    when a run starts (a method the vessel's components cannot take) or what fails at once (a
    force that cannot be evaluated at the initial state) is then a usage error, with nothing
    written."""
    import dataclasses
    import warnings

    import phsplit

    t0 = sc.t_span[0]
    probe = dataclasses.replace(sc.settings, t_span=(t0, t0 + sc.h), save_every=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the run itself warns, once
        sol = phsplit.simulate(sc.vessel, settings=probe)
    if sol.status == "interrupted":  # the core returned on a signal: the user asked to stop
        raise KeyboardInterrupt
    if sol.status == "failed":
        raise UsageError(f"the run fails at its first step, so nothing was started: {sol.failure}")


def _seconds_since_start() -> float:
    """Wall-clock seconds since this process started (Linux: from /proc, so the interpreter's own
    start-up counts too), else since phsplit was imported."""
    import phsplit

    try:
        with open("/proc/self/stat") as f:
            after_name = f.read().rsplit(")", 1)[1].split()
        with open("/proc/uptime") as f:
            uptime = float(f.read().split()[0])
        return max(0.0, uptime - int(after_name[19]) / os.sysconf("SC_CLK_TCK"))  # field 22: start time
    except (OSError, ValueError, IndexError):  # pragma: no cover - systems without /proc
        return time.perf_counter() - phsplit._STARTED


def _write_motion(nc_file, m: dict) -> None:
    """The whole run's motion statistics into the file's ``<dof>_statistics`` (written by the
    first chunk with that chunk's)."""
    for k in m:
        if f"{k}_statistics" in nc_file.variables:
            nc_file.variables[f"{k}_statistics"][:] = m[k]


def _append(nc_file, path: str, sol, first: bool, attrs: dict):
    """Write a chunk: the first creates the file (time unlimited) with the run's ``attrs``, the
    others append their rows after the first (which repeats the previous chunk's last). Synced
    after every chunk, so the file on disk holds every finished chunk."""
    import netCDF4

    ds = sol.to_xarray()
    if first:
        ds.attrs.update(attrs)
        ds.to_netcdf(path, unlimited_dims=["time"])
        nc_file = netCDF4.Dataset(path, "a")
    else:
        n0 = len(nc_file.dimensions["time"])
        rows = ds.isel(time=slice(1, None))
        m = rows.sizes["time"]
        if m:
            nc_file.variables["time"][n0:n0 + m] = rows["time"].values
            for name, var in rows.data_vars.items():
                if var.dims and var.dims[0] == "time":
                    nc_file.variables[name][n0:n0 + m, ...] = var.values
    nc_file.sync()
    return nc_file


def _reproduce(args) -> int:
    from .reproduce import reproduce, summary_table

    out = args.out
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"cannot create output folder {out!r}: {e.strerror}") from None
    if not _writable_ancestor(out)[1]:
        raise UsageError(f"output folder {out!r} is not writable")
    t0 = time.perf_counter()
    try:
        res = reproduce(out, quick=args.quick, progress=not args.no_progress and sys.stderr.isatty())
    except PermissionError as e:
        raise UsageError(str(e)) from None
    print(summary_table(res))
    held = sum(c.holds for c in res.claims)
    partly = sum(bool(c.partly) and not c.holds for c in res.claims)
    failed = len(res.claims) - held - partly
    print(f"\n{held} of {len(res.claims)} claims hold, {partly} partly (see the report for why), {failed} do not; "
          f"{time.perf_counter() - t0:.1f} s")
    print(f"wrote figures, data and report to {os.path.abspath(out)} (report.md, report.html)")
    return 0 if failed == 0 else 1


def _sweep(args) -> int:
    import phsplit

    from .batch import check_cluster, load_sweep, run_sweep

    sw = load_sweep(args.sweep)
    try:
        check_cluster(args.scheduler, args.workers)
    except phsplit.InvalidInputError as e:
        raise UsageError(str(e).replace("workers must", "--workers must").replace("scheduler must", "--scheduler must")
                         .replace("give workers", "give --workers").replace("or a scheduler", "or --scheduler")) from None
    store = args.out or os.path.splitext(args.sweep)[0] + ".store"
    if os.path.exists(store) and not os.path.isdir(store):
        raise UsageError(f"the store {store!r} is a file, not a folder (--out names a folder)")
    parent, ok = _writable_ancestor(store)
    if not ok:
        raise UsageError(f"cannot create the store {store!r}: {parent!r} is not a writable folder")
    print(f"sweep {sw.name}: {len(sw.cases)} cases, {sw.settings.method} h={sw.settings.h:g} s on "
          f"[{sw.settings.t_span[0]:g}, {sw.settings.t_span[1]:g}] s; store {os.path.abspath(store)}", flush=True)
    res = run_sweep(sw, store, scheduler=args.scheduler, n_workers=args.workers,
                    progress=not args.no_progress and sys.stderr.isatty())
    import csv

    with open(res["summary"]) as f:
        rows = list(csv.DictReader(f))
    bad = [r for r in rows if r["status"] != "completed"]
    div = [r for r in rows if r.get("diverged") == "True"]
    print(f"{res['computed']} computed, {res['reused']} already in the store, in {res['seconds']:.1f} s; "
          f"{len(bad)} failed or invalid, {len(div)} diverged")
    if res["lost"]:
        print(f"{res['lost']} cases were lost with their workers and not stored: run the sweep again to compute them")
    print(f"summary: {os.path.abspath(res['summary'])}")
    return 0


def _rerun(args) -> int:
    from .files import publish
    from .results import check_record, compare, open_dataset, rerun

    dest = None
    if args.out:  # where the rerun goes, checked before it is computed
        if os.path.exists(args.out) and not os.path.isdir(args.out):
            raise UsageError(f"--out names a folder to write the rerun into, but {args.out!r} is a file")
        dest = os.path.join(args.out, os.path.basename(args.file))
        if os.path.isdir(dest):
            raise UsageError(f"cannot write the rerun to {dest!r}: a folder of that name is in the way")
        if os.path.exists(dest) and os.path.samefile(dest, args.file):
            raise UsageError(f"--out {args.out!r} would overwrite {args.file!r} with its rerun; choose another folder")
        parent, ok = _writable_ancestor(args.out)
        if not ok:
            raise UsageError(f"cannot create --out {args.out!r}: {parent!r} is not a writable folder")
    ds = open_dataset(args.file)
    if "wind_speed_limit" in ds:
        ds.close()
        raise UsageError(f"{args.file!r} is a DP capability (phsplit capability), not a run: there is nothing "
                         "to repeat; compute it again with phsplit capability")
    if "case" in ds.dims:
        ds.close()
        raise UsageError(f"{args.file!r} holds cases of a sweep (a batch file of a sweep store), not one run; "
                         "rerun one case in Python: phsplit.rerun(phsplit.results.sweep_case(STORE, CASE_ID))")
    if "time" not in ds.dims:
        ds.close()
        raise UsageError(f"{args.file!r} holds no run to repeat (no time dimension; a sweep summary or a case "
                         "that did not run)")
    try:
        check_record(ds)
    except BaseException:
        ds.close()
        raise
    try:
        t0 = time.perf_counter()
        print(f"rerunning {args.file}: phsplit {ds.attrs.get('phsplit_version')} {ds.attrs.get('method')} "
              f"h={ds.attrs.get('step_size_s')} s, {ds.sizes['time']} saved states, status "
              f"{ds.attrs.get('status')}", flush=True)
        again = rerun(ds)
        diffs = compare(ds, again)
    finally:
        ds.close()
    if dest is not None:
        try:
            os.makedirs(args.out, exist_ok=True)
        except OSError as e:
            raise UsageError(f"cannot create --out {args.out!r}: {e.strerror}") from None
        fd, tmp = tempfile.mkstemp(dir=args.out, prefix=".rerun-", suffix=".nc")
        os.close(fd)
        try:
            again.to_netcdf(tmp)
            publish(tmp, dest)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
        print(f"wrote {os.path.abspath(dest)}")
    dt = time.perf_counter() - t0
    if not diffs:
        print(f"identical: every number of {len(again.data_vars)} variables agrees to the last bit ({dt:.2f} s)")
        return 0
    print(f"{len(diffs)} variable(s) differ:", file=sys.stderr)
    for name, d in diffs:
        print(f"  {name}: largest difference {d:.3e}", file=sys.stderr)
    return 1


def _plot(args) -> int:
    from .plotting import check_plottable, plot_dp
    from .results import open_dataset

    if args.watch_circle is not None and not (args.watch_circle > 0 and args.watch_circle < 1e6):
        raise UsageError(f"--watch-circle must be a radius in m, in (0, 1e6), got {args.watch_circle}")
    out = args.out or os.path.splitext(args.file)[0] + ".png"
    if os.path.splitext(out)[1].lower() not in (".png", ".pdf", ".svg"):
        raise UsageError(f"--out must end in .png, .pdf or .svg, got {out!r}")
    d = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(d):
        raise UsageError(f"the folder of --out does not exist: {d!r}")
    if os.path.isdir(out):
        raise UsageError(f"--out {out!r} is a folder; name the image to write (.png, .pdf or .svg)")
    if os.path.exists(out) and os.path.exists(args.file) and os.path.samefile(out, args.file):
        raise UsageError(f"--out {out!r} would overwrite the result file itself")
    if not _writable_ancestor(d)[1]:
        raise UsageError(f"the folder of --out is not writable: {d!r}")
    with open_dataset(args.file) as ds:
        lacking = [k for k in ("position", "euler") if k not in ds]
        if lacking:
            raise UsageError(f"{args.file!r} has no variable {lacking[0]} (a run's trajectory): it is not a run's "
                             f"file, or a damaged one")
        if "case" in ds.dims:
            raise UsageError(f"{args.file!r} holds cases of a sweep (a batch file of a sweep store), not one run; "
                             "plot one case in Python: phsplit.plotting.plot_dp(phsplit.results.sweep_case("
                             "STORE, CASE_ID), OUT)")
        check_plottable(ds, args.file)
        plot_dp(ds, out, watch_circle=args.watch_circle)
    print(f"wrote {os.path.abspath(out)}")
    return 0


def _fmu(args) -> int:
    import phsplit
    from . import fmu

    if args.fmu_command is None:
        raise UsageError("fmu needs a command: 'export' or 'load' (see 'phsplit fmu --help')")
    try:
        if args.fmu_command == "export":
            extra = {}
            for b in args.binary:
                plat, sep, path = b.partition("=")
                if not sep or not plat or not path:
                    raise UsageError(f"--binary takes PLATFORM=PATH (e.g. win64=phsplit_fmu.dll), got {b!r}")
                extra[plat] = path
            out = fmu.export(args.scenario, args.out, binaries=extra)
        else:
            out = fmu.export_load(args.out, force_mean=args.force_mean, force_amplitude=args.force_amplitude,
                                  moment_mean=args.moment_mean, moment_amplitude=args.moment_amplitude,
                                  period=args.period)
    except phsplit.InvalidInputError as e:
        msg = str(e)
        if args.fmu_command != "export":  # said as the options it came from
            for k in ("force_mean", "force_amplitude", "moment_mean", "moment_amplitude", "period"):
                if msg.startswith(k):
                    raise UsageError("--" + k.replace("_", "-") + msg[len(k):]) from None
        raise
    except phsplit.PhsplitError as e:
        if isinstance(e, (phsplit.InvalidInputError, phsplit.ScenarioParseError)):
            raise
        print(f"phsplit: error: {e}", file=sys.stderr)
        return 1
    except OSError as e:
        raise UsageError(f"cannot write {args.out!r}: {e.strerror}") from None
    print(f"wrote {os.path.abspath(out)}")
    return 0


def _failures(args) -> int:
    import dataclasses

    import phsplit

    from . import scenario as scn
    from .dp import check_failure_study, single_failures

    sc = scn.load(args.scenario, vessel=args.vessel)
    st = sc.settings
    if args.t_end is not None:
        if not (math.isfinite(args.t_end) and args.t_end > st.t_span[0]):
            raise UsageError(f"--t-end must be a finite time after the start ({st.t_span[0]:g} s), got {args.t_end:g}")
        st = dataclasses.replace(st, t_span=(st.t_span[0], args.t_end))
    try:
        n = len(check_failure_study(sc.vessel, st, args.at, at_name="--at"))
    except phsplit.InvalidInputError as e:
        raise UsageError(str(e).removeprefix("single_failures: ")) from None
    ways = {"lost": "lost", "stuck": "stuck", "both": "lost and stuck"}[args.mode]
    runs = 1 + n * (2 if args.mode == "both" else 1)
    print(f"{sc.name}: {runs} runs on [{st.t_span[0]:g}, {st.t_span[1]:g}] s, each thruster {ways} in turn at "
          f"t = {args.at:g} s", flush=True)
    study = single_failures(sc.vessel, st, at=args.at, mode=args.mode)
    print(study.table())
    w = study.worst
    if w is None:
        print("no failure case completed", file=sys.stderr)
        return 1
    print(f"worst single failure: {w['case']} (largest excursion {w['max_excursion']:.3f} m after it, "
          f"utilisation up to {w.get('utilisation_max', float('nan')):.3f})")
    return 0


def _capability(args) -> int:
    from . import scenario as scn
    from .capability import capability, polar_plot

    if args.directions is not None and "--step" in args.argv:
        raise UsageError("give either --directions or --step, not both")
    if args.directions is None:
        if not (args.step >= 0.1 and args.step > 0 and args.step <= 180 and (360.0 / args.step) == round(360.0 / args.step)):
            raise UsageError(f"--step must be at least 0.1 degrees and divide 360 (e.g. 5, 10, 15), got {args.step:g}")
        directions = _angles(args.step)
    else:
        directions = args.directions
    import phsplit

    try:
        sc = scn.load(args.scenario, vessel=args.vessel)
    except (phsplit.InvalidInputError, phsplit.ScenarioParseError) as e:
        if not args.vessel:
            raise
        raise type(e)(f"--vessel {args.vessel} with scenario {args.scenario}: {e}") from None
    out = args.out
    # Every check of the output before the analysis runs (it may take minutes); the folder
    # itself is made only once there is something to write into it.
    _check_out_folder(out)
    stem = os.path.join(out, f"{sc.name}-capability")
    nc, png = stem + ".nc", stem + ".png"
    for f in (nc,) if args.no_plot else (nc, png):
        if os.path.isdir(f):
            raise UsageError(f"cannot write {f!r}: a folder of that name is in the way")
    ds = capability(sc.vessel, directions=directions, failures=args.failures, tolerance=args.tolerance)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"cannot create output folder {out!r}: {e.strerror}") from None
    from .files import publish, temporary_beside

    tmp = temporary_beside(nc, prefix=".capability-")
    try:
        ds.to_netcdf(tmp)
        publish(tmp, nc)  # the usual permissions (mkstemp's are the owner's only)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    u = ds["wind_speed_limit"]
    print(f"capability of {sc.name}: {ds.sizes['direction']} directions, cases: "
          f"{', '.join(map(str, ds['case_name'].values))}")
    print(f"intact: smallest wind speed held {float(u[:, 0].min()):.2f} m/s (Beaufort "
          f"{int(ds['beaufort_limit'][:, 0].min())})"
          + (f"; worst single failure: {float(ds['worst_failure_wind_speed'].min()):.2f} m/s (Beaufort "
             f"{int(ds['worst_failure_beaufort'].min())})" if "worst_failure_wind_speed" in ds else ""))
    if not ds.attrs["wave_drift_included"]:
        print("note: the vessel has no wave drift coefficients; the mean wave drift is left out")
    print(f"wrote {os.path.abspath(nc)}")
    if not args.no_plot:
        tmp = temporary_beside(png, prefix=".capability-")
        try:  # under a temporary name, renamed when complete: no half-drawn figure on Ctrl-C
            polar_plot(ds, tmp, title=f"{sc.name}: wind speed held (m/s)")
            publish(tmp, png)
        except BaseException:
            if os.path.exists(tmp):
                os.remove(tmp)
            raise
        print(f"wrote {os.path.abspath(png)}")
    return 0


def _rao(args) -> int:
    import numpy as np
    import xarray as xr

    from . import radiation, seakeeping
    from . import scenario as scn
    from .files import publish, temporary_beside
    from .plotting import plot_rao

    vessel = scn.vessel_named(args.vessel)
    name = _vessel_stem(args.vessel)
    dataset = args.dataset
    if dataset is None:
        if args.vessel not in seakeeping.DATASETS:
            raise UsageError(f"--vessel {args.vessel}: no shipped dataset for this vessel (shipped for: "
                             f"{', '.join(seakeeping.DATASETS)}); give --dataset")
        dataset = seakeeping.DATASETS[args.vessel]
    elif not os.path.isfile(dataset):
        raise UsageError(f"--dataset {dataset!r} is not a file")
    out = args.out
    _check_out_folder(out)
    nc, png = os.path.join(out, f"{name}-rao.nc"), os.path.join(out, f"{name}-rao.png")
    for f in (nc,) if args.no_plot else (nc, png):
        if os.path.isdir(f):
            raise UsageError(f"cannot write {f!r}: a folder of that name is in the way")
    data = radiation.retardation_data(dataset, vessel=vessel)
    freqs = args.frequencies
    if freqs is None:
        w = data[0]
        freqs = [float(x) for x in w if 0.3 - 1e-9 <= x <= 1.9 + 1e-9]
    # every argument checked (by a run-free call per heading) before the first run
    if len(set(args.headings)) != len(args.headings):
        raise UsageError(f"--headings must be distinct, got {' '.join(f'{x:g}' for x in args.headings)}")
    for hd in args.headings:
        seakeeping.rao(vessel, freqs, hd, tuple(args.dofs), amplitude=args.amplitude, dataset=dataset,
                       fluid_memory=not args.no_fluid_memory, h=args.h, t_end=args.t_end, check_only=True)
    memory = False if args.no_fluid_memory else radiation.fluid_memory(dataset, vessel=vessel)
    parts = []
    for hd in args.headings:
        print(f"rao of {name}: heading {hd:g} deg, {len(freqs)} frequencies ...", flush=True)
        parts.append(seakeeping.rao(vessel, freqs, hd, tuple(args.dofs), amplitude=args.amplitude, dataset=dataset,
                                    fluid_memory=memory, h=args.h, t_end=args.t_end))
    ds = xr.concat([p.expand_dims(heading=[float(p.attrs["heading"])]) for p in parts], dim="heading",
                   combine_attrs="override")
    ds["heading"].attrs.update({"units": "degree", "long_name": "wave direction relative to the bow (90 beam, 180 head seas)"})
    ds.attrs.pop("heading", None)
    ds.attrs["vessel"] = args.vessel
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"cannot create output folder {out!r}: {e.strerror}") from None
    tmp = temporary_beside(nc, prefix=".rao-")
    try:  # under a temporary name, renamed when complete: nothing half-written on Ctrl-C
        ds.to_netcdf(tmp)
        publish(tmp, nc)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
    if not args.no_plot:
        plot_rao(ds, png, title=f"{name}: RAO")   # written whole or not at all
    for hd in ds.heading.values:
        row = ds.sel(heading=hd)
        worst = []
        peak = {k: float(np.nanmax(row[f"{k}_amplitude_frequency_domain"].values)) for k in args.dofs}
        for k in args.dofs:
            fd = row[f"{k}_amplitude_frequency_domain"].values
            dev = np.abs(row[f"{k}_deviation"].values)
            kind = [j for j in args.dofs if (j in ("roll", "pitch", "yaw")) == (k in ("roll", "pitch", "yaw"))]
            if peak[k] < 0.01 * max(peak[j] for j in kind):   # pitch in beam seas, roll in head seas
                worst.append(f"{k} not excited")
                continue
            big = fd >= 0.05 * peak[k]
            worst.append(f"{k} {100 * float(np.nanmax(dev[big])):.1f} %")
        print(f"heading {hd:g} deg: largest deviation from the frequency domain where the RAO is >= 5 % of its "
              f"peak: {', '.join(worst)}; ledger residual <= {float(row['ledger_residual'].max()):.1e}")
    print(f"wrote {os.path.abspath(nc)}")
    if not args.no_plot:
        print(f"wrote {os.path.abspath(png)}")
    return 0


def _angles(step: float) -> list[float]:
    """0, step, 2 step, ... below 360 degrees."""
    return [i * step for i in range(int(round(360.0 / step)))]


def _methods() -> int:
    import phsplit

    print(f"{'name':6} {'order':>5} {'stages':>6}  {'passive (Prop. 2.2)':20} citation")
    for n in phsplit.METHODS:
        i = phsplit.method_info(n)
        print(f"{n:6} {i['order']:>5} {i['stages']:>6}  {str(i['all_positive']):20} {i['citation']}")
    return 0


def _vessels() -> int:
    import phsplit

    from .vessel import PRESET_ALIASES

    for name, (desc, _) in phsplit.presets().items():
        print(f"{name:12} {desc}")
    for old, new in PRESET_ALIASES.items():
        print(f"{old:12} the earlier name of {new}, still accepted")
    print("use: phsplit simulate --vessel NAME, vessel = \"NAME\" in a scenario, or phsplit.Vessel.preset(NAME)")
    return 0


def main(argv: list[str] | None = None) -> int:
    rc = _main(argv)
    if rc != 130 and _signals.received():  # the signal came where Python dropped it
        print("phsplit: interrupted as the command finished; what it wrote is complete", file=sys.stderr)
        rc = 130
    if rc == 130:
        _signals.forget_escaped_interrupt()
    return rc


def _main(argv: list[str] | None) -> int:
    import signal

    import phsplit

    try:
        if signal.getsignal(signal.SIGINT) is phsplit._early_signal:  # the command's own start
            signal.signal(signal.SIGINT, _signals.handler)
            signal.signal(signal.SIGTERM, _signals.handler)
        if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None):
            signal.signal(signal.SIGTERM, _signals.handler)  # clean up staging files as on Ctrl-C
        import warnings

        def _show(message, category, filename, lineno, file=None, line=None):
            print(f"phsplit: warning: {message}", file=sys.stderr)  # one line, no source location

        warnings.showwarning = _show
        parser = _parser()
        args = parser.parse_args(argv)
        args.argv = list(argv) if argv is not None else sys.argv[1:]
        if args.command is None:
            parser.print_help()
            return 2
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "reproduce":
            return _reproduce(args)
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "rerun":
            return _rerun(args)
        if args.command == "plot":
            return _plot(args)
        if args.command == "fmu":
            return _fmu(args)
        if args.command == "vessels":
            return _vessels()
        if args.command == "capability":
            return _capability(args)
        if args.command == "rao":
            return _rao(args)
        if args.command == "failures":
            return _failures(args)
        return _methods()
    except (UsageError, phsplit.InvalidInputError, phsplit.ScenarioParseError) as e:
        print(f"phsplit: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("phsplit: interrupted; no partial output was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
