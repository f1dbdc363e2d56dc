"""The ``phsplit`` command line."""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

EXAMPLES = """examples:
  phsplit simulate                         # the paper's Fig. 2 scenario (SP4, h = 0.5, [0, 200])
  phsplit simulate scenario.toml --out runs/
  phsplit simulate --method sp2 --h 0.25 --t-end 400
  phsplit methods                          # methods with order, stages and passivity guarantee
  phsplit reproduce --out paper/           # the paper's Figs. 2-4, stability sweep and report
  phsplit reproduce --quick                # the same in a few seconds, with coarser references
"""


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="phsplit",
        description="Passivity-preserving splitting simulation of a vessel under DP control.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    s = sub.add_parser(
        "simulate",
        help="run a scenario (default: the paper's Fig. 2) and write NetCDF + PNG",
        description="Run a scenario and write <out>/<name>.nc (xarray/NetCDF) and <out>/<name>.png.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    s.add_argument("scenario", nargs="?", help="scenario TOML file (default: the paper's Fig. 2)")
    s.add_argument("--out", default="out", help="output folder (default: ./out)")
    s.add_argument("--method", help="override the method")
    s.add_argument("--h", type=float, help="override the step size, s")
    s.add_argument("--t-end", type=float, help="override the end time, s")
    s.add_argument("--no-plot", action="store_true", help="skip the PNG")
    sub.add_parser("methods", help="list the integration methods")
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
    return p


class UsageError(Exception):
    pass


def _simulate(args) -> int:
    import phsplit
    from . import scenario as scn
    from .plotting import plot_positions, publish, reference_of

    sc = scn.load(args.scenario) if args.scenario else scn.Scenario.paper_fig2()
    if args.method:
        sc.method = args.method
    if args.h is not None:
        sc.h = args.h
    if args.t_end is not None:
        sc.t_span = (sc.t_span[0], args.t_end)
    out = args.out
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"cannot create output folder {out!r}: {e.strerror}") from None
    if not os.access(out, os.W_OK):
        raise UsageError(f"output folder {out!r} is not writable")
    print(f"phsplit {phsplit.__version__}: {sc.name}: {sc.method} h={sc.h:g} s on "
          f"[{sc.t_span[0]:g}, {sc.t_span[1]:g}] s, controller from t={sc.control_start}", flush=True)
    t0 = time.perf_counter()
    sol = phsplit.simulate(sc.vessel, t_span=sc.t_span, h=sc.h, method=sc.method,
                           control_start=sc.control_start, outer=sc.outer, save_every=sc.save_every)
    dt = time.perf_counter() - t0
    ds = sol.to_xarray()
    ds.attrs["scenario"] = args.scenario or "paper Fig. 2 (built in)"
    nc = os.path.join(out, f"{sc.name}.nc")
    fd, tmp = tempfile.mkstemp(dir=out, prefix=".tmp-", suffix=".nc")
    os.close(fd)
    try:
        ds.to_netcdf(tmp)
        publish(tmp, nc)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    files = [nc]
    if not args.no_plot:
        png = os.path.join(out, f"{sc.name}.png")
        plot_positions(sol, png, reference_of(sc.vessel))
        files.append(png)
    e = sol.euler[-1]
    rr = sol.ledger.relative_residual()
    print(f"{sol.status}: {sol.steps} steps in {dt:.3f} s")
    print(f"t = {sol.t[-1]:g} s: x = ({sol.x[-1, 0]:.3f}, {sol.x[-1, 1]:.3f}, {sol.x[-1, 2]:.4f}) m, "
          f"roll/pitch/yaw = ({e[0]:.5f}, {e[1]:.5f}, {e[2]:.5f}) rad")
    print(f"energy H: {sol.energy[0]:.6e} -> {sol.energy[-1]:.6e} J; worst relative ledger residual {rr.max():.2e}")
    for f in files:
        print(f"wrote {os.path.abspath(f)}")
    if sol.status != "completed":
        print(f"error: the run failed: {sol.failure}", file=sys.stderr)
        return 1
    return 0


def _reproduce(args) -> int:
    from .reproduce import reproduce, summary_table

    out = args.out
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise UsageError(f"cannot create output folder {out!r}: {e.strerror}") from None
    if not os.access(out, os.W_OK | os.X_OK):
        raise UsageError(f"output folder {out!r} is not writable")
    t0 = time.perf_counter()
    try:
        res = reproduce(out, quick=args.quick, progress=not args.no_progress and sys.stderr.isatty())
    except PermissionError as e:
        raise UsageError(str(e)) from None
    print(summary_table(res))
    held = sum(c.holds for c in res.claims)
    print(f"\n{held} of {len(res.claims)} claims hold; {time.perf_counter() - t0:.1f} s")
    print(f"wrote figures, data and report to {os.path.abspath(out)} (report.md, report.html)")
    return 0 if held == len(res.claims) else 1


def _methods() -> int:
    import phsplit

    print(f"{'name':6} {'order':>5} {'stages':>6}  {'passive (Prop. 2.2)':20} citation")
    for n in phsplit.METHODS:
        i = phsplit.method_info(n)
        print(f"{n:6} {i['order']:>5} {i['stages']:>6}  {str(i['all_positive']):20} {i['citation']}")
    return 0


def _sigterm(signum, frame):
    raise KeyboardInterrupt


def main(argv: list[str] | None = None) -> int:
    import signal

    if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None):
        signal.signal(signal.SIGTERM, _sigterm)  # clean up staging files as on Ctrl-C
    parser = _parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 2
    import phsplit

    try:
        if args.command == "simulate":
            return _simulate(args)
        if args.command == "reproduce":
            return _reproduce(args)
        return _methods()
    except (UsageError, phsplit.InvalidInputError, phsplit.ScenarioParseError) as e:
        print(f"phsplit: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("phsplit: interrupted; no partial output was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
