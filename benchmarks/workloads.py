#!/usr/bin/env python3
"""Time to accuracy on the users' workloads: phsplit's splitting methods (fixed and adaptive
steps), its RK4, and the classical solvers on the core's compiled field, in one run.

Run with ``.venv/bin/python benchmarks/workloads.py [--quick]`` (part of ``make bench``).
Writes ``benchmarks/results/workloads.md`` (the tables) and ``workloads.csv`` (every run).

Workloads, one hour each, the controller on from t = 0:

* ``paper``: the paper's vessel (App. D) from its initial state to its set point;
* ``osv``: MSS's OSV (``Vessel.preset("osv")``) in a 0.5 m/s current, from 5 m off its set
  point and 10° off its heading;
* ``dp-weather``: the shipped scenario's vessel (150 wave and 100 gust components) holding
  position;
* ``pipe-lay``: the shipped ``pipelay`` scenario's vessel (the catenary pipe of docs/model.md
  §5.9, the moving set point along the lay route from t = 600 s). The dynamic pipe
  (``pipelay-dynamic``) is not a workload here: its nodes are states of the pipe that flow S2
  integrates, and the compiled field of the 27 vessel states cannot carry them, so no
  classical peer can run it.

Error: the largest distance between the computed and the reference position over the samples
every 10 s (m). Reference: scipy's DOP853 at rtol 1e-12 with the absolute tolerances below
times 1e-12, on the compiled field (a different integrator from everything timed; for the
paper's vessel, the independent numpy model of ``python/tests/reference.py`` agrees with it,
checked at the start); for ``pipe-lay``, whose field needs about 12 million evaluations at that
tolerance, the compiled DOP853 at the same tolerances (about 20 s instead of a minute).

Tolerances of the classical solvers, as a careful user sets them: one rtol ``τ`` from the same
grid as phsplit's adaptive runs (``TOLS``: half decades from 3e-2 down to 1e-5, then decades to
1e-8) and, per group of states, ``atol = τ × scale``: position 1 m, attitude (the entries of Q)
1, momentum ``m × 1 m/s`` and ``I × 1 rad/s``, the restoring variable ``μ`` its initial size (at least
1 N m), the controller's integrals 10 m s. phsplit's adaptive steps weigh position, attitude,
body velocities and integrals in their own units (docs/numerics.md): ``rtol = atol = τ``.

phsplit's fixed steps: each method with S2 outermost (the default) and its linear flows, and
for ``sp2`` and ``mcl2`` also S1 outermost (``outer="conservative"``) with two or three Gauss
stages in S2. Adaptive steps: each method with the default flows, and ``sp2`` also with two
Gauss stages and with S1 outermost.

Timing: the wall time of the call a user makes (``phsplit.simulate``, ``solve_ivp``, the
compiled DOP853, CVODE's ``solve``), the minimum of repeats, BLAS pinned to one thread, every
contender in the same process; the ledger off for phsplit (the peers have none).
"""
from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import csv  # noqa: E402
import datetime  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import phsplit  # noqa: E402
from phsplit import _core  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
T = 3600.0
DT = 10.0
TS = np.arange(DT, T + 1e-9, DT)
TARGETS = (1e-2, 1e-3)
#: Every adaptive contender's tolerances, from one grid (half decades where the targets are met).
TOLS = (1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6, 1e-7, 1e-8)


def workloads() -> dict[str, phsplit.Vessel]:
    paper = phsplit.Vessel.paper()
    osv = phsplit.Vessel.from_toml_str(phsplit.Vessel.preset("osv").to_toml() + "\n[current]\nvelocity = [0.5, 0.0, 0.0]\n")
    d = osv.to_dict()
    ref = np.array(d["control"]["position_reference"])
    psi = d["control"]["euler_reference"][2]
    x0 = ref + 5.0 * np.array([math.cos(0.7), math.sin(0.7), 0.0])
    osv = phsplit.with_parameters(osv, {"initial.position[0]": x0[0], "initial.position[1]": x0[1],
                                        "initial.euler[2]": psi + math.radians(10.0)})
    weather = phsplit.scenario.load(phsplit.scenario.resolve("dp-weather")).vessel
    pipelay = phsplit.scenario.load(phsplit.scenario.resolve("pipelay")).vessel
    return {"paper": paper, "osv": osv, "dp-weather": weather, "pipe-lay": pipelay}


def atol_of(v: phsplit.Vessel, y0: np.ndarray, tau: float) -> np.ndarray:
    d = v.to_dict()["vessel"]
    a = np.empty(_core.STATE_DIM)
    a[0:3] = d["mass"]
    a[3:6] = np.asarray(d["inertia"], dtype=float)
    a[6:15] = 1.0
    a[15:18] = max(1.0, float(np.abs(y0[15:18]).max()))
    a[18:21] = 1.0
    a[21:27] = 10.0
    return tau * a


def outermost(outer: str) -> str:
    """What a contender's label says of its outer flow (nothing for the default, S2 outermost)."""
    return " S1 outermost" if outer == "conservative" else ""


def best_of(fn, repeats: int, budget: float):
    """The minimum wall time of at least ``repeats`` calls, more while under ``budget`` s."""
    times, out, spent = [], None, 0.0
    while len(times) < repeats or spent < budget and len(times) < 20:
        t = time.perf_counter()
        out = fn()
        dt = time.perf_counter() - t
        times.append(dt)
        spent += dt
    return min(times), out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer settings and repeats (a smoke run)")
    ap.add_argument("--only", help="one workload: paper, osv, dp-weather or pipe-lay")
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    args = ap.parse_args()
    repeats, budget = (1, 0.0) if args.quick else (3, 0.5)
    rows = []
    warnings.simplefilter("ignore")
    for name, v in workloads().items():
        if args.only and name != args.only:
            continue
        y0 = v.initial_state()
        f = _core.VectorField(v._inner, 0.0)
        t = time.perf_counter()
        if name == "pipe-lay":
            out, nfev, _ = f.solve_dop853((0.0, T), y0, 1e-12, atol_of(v, y0, 1e-12), TS)
            X = out.reshape(-1, _core.STATE_DIM)[:, 18:21]
        else:
            ref = solve_ivp(f, (0.0, T), y0, method="DOP853", rtol=1e-12, atol=atol_of(v, y0, 1e-12), t_eval=TS)
            assert ref.success, ref.message
            X, nfev = ref.y[18:21].T, ref.nfev
        print(f"{name}: reference in {time.perf_counter() - t:.1f} s ({nfev} evaluations)", flush=True)
        if name == "paper":
            import sys
            sys.path.insert(0, os.path.join(HERE, "..", "python", "tests"))
            import reference as numpy_model

            g = numpy_model.Field(v.to_dict(), True)
            ind = solve_ivp(g, (0.0, T), y0, method="DOP853", rtol=1e-12, atol=atol_of(v, y0, 1e-12), t_eval=TS)
            gap = float(np.linalg.norm(ind.y[18:21].T - X, axis=1).max())
            print(f"  the independent numpy model agrees to {gap:.1e} m", flush=True)
            assert gap < 1e-5

        def err(x):
            return float(np.linalg.norm(np.asarray(x) - X, axis=1).max())

        def add(solver, setting, sec, e, extra=""):
            rows.append({"workload": name, "solver": solver, "setting": setting, "seconds": sec, "error": e,
                         "extra": extra})
            print(f"  {solver:28s} {setting:14s} {sec * 1e3:9.2f} ms  error {e:.2e} m {extra}", flush=True)

        heavy = name in ("dp-weather", "pipe-lay")
        hs = [10.0, 5.0, 2.5, 2.0, 1.0, 0.5] if not heavy else [5.0, 2.5, 2.0, 1.0, 0.5]
        methods = ["sp2", "mcl2", "sp4"] if not args.quick else ["sp2", "sp4"]
        for m in methods:
            # S2 of order 4 whatever the method: a different method only where the method's own
            # Gauss stages are fewer (sp2, mcl2: one).
            flows = ["gauss", "exact"] if name == "paper" else ["gauss"]
            flows += ["gauss4"] if m in ("sp2", "mcl2") else []
            settings = [(flow, "dissipative") for flow in flows]
            # S1 outermost: one S2 a step, over the whole step, where S2 outermost takes two
            # halves; three Gauss stages then cost fewer evaluations of the forcing a step
            # than two stages in each half.
            settings += [("gauss4", "conservative"), ("gauss6", "conservative")] if m in ("sp2", "mcl2") else []
            for flow, outer in settings:
                label = f"phsplit {m} {flow}" + outermost(outer)
                for h in hs:
                    sec, sol = best_of(lambda: phsplit.simulate(v, (0.0, T), h, m, control_start=0.0, ledger=False,
                                                                save_every=int(round(DT / h)), linear_flow=flow,
                                                                outer=outer),
                                       repeats, budget)
                    add(label, f"h={h:g}", sec, err(sol.x[1:]))
            taus = [t for t in TOLS if t >= 1e-5] if not args.quick else [1e-2, 1e-4]
            adaptive = [("auto", "dissipative")]
            if m == "sp2":
                adaptive += [("gauss4", "dissipative"), ("auto", "conservative"), ("gauss4", "conservative")]
            for flow, outer in adaptive:
                for tau in taus:
                    sec, sol = best_of(lambda: phsplit.simulate(v, (0.0, T), 1.0, m, control_start=0.0, ledger=False,
                                                                rtol=tau, atol=tau, save_at=TS, linear_flow=flow,
                                                                outer=outer),
                                       repeats, budget)
                    assert len(sol.t) == len(TS)
                    label = f"phsplit {m} adaptive" + ("" if flow == "auto" else f" {flow}") + outermost(outer)
                    add(label, f"tol={tau:g}", sec, err(sol.x), f"({sol.steps} steps, {sol.meta['rejected']} rejected)")
        for h in ([2.0, 1.0, 0.5, 0.25] if not heavy else [1.0, 0.5, 0.25]):
            sec, sol = best_of(lambda: phsplit.simulate(v, (0.0, T), h, "rk4", control_start=0.0, ledger=False,
                                                        save_every=int(round(DT / h))), repeats, budget)
            add("phsplit rk4", f"h={h:g}", sec, err(sol.x[1:]) if sol.status == "completed" else math.inf)
        taus = [t for t in TOLS if t <= 3e-2] if not args.quick else [1e-3, 1e-5]
        for tau in taus:
            at = atol_of(v, y0, tau)
            for method in ("LSODA", "DOP853"):
                sec, r = best_of(lambda: solve_ivp(f, (0.0, T), y0, method=method, rtol=tau, atol=at, t_eval=TS),
                                 repeats, budget)
                add(f"scipy {method}", f"rtol={tau:g}", sec, err(r.y[18:21].T) if r.success else math.inf,
                    f"({r.nfev} evaluations)")
            sec, out = best_of(lambda: f.solve_dop853((0.0, T), y0, tau, at, TS), repeats, budget)
            add("compiled DOP853", f"rtol={tau:g}", sec, err(out[0].reshape(-1, _core.STATE_DIM)[:, 18:21]),
                f"({out[1]} evaluations)")
            try:
                from sksundae.cvode import CVODE

                def cvode():
                    s = CVODE(lambda t, y, yp: f.into(t, y, yp), method="BDF", rtol=tau, atol=at,
                              max_num_steps=10**6)
                    return s.solve(np.concatenate([[0.0], TS]), y0)

                sec, r = best_of(cvode, repeats, budget)
                add("CVODE BDF", f"rtol={tau:g}", sec, err(np.asarray(r.y)[1:, 18:21]) if r.success else math.inf)
            except ImportError:
                pass
    write(rows, args.out)
    return 0


def fastest(rows, workload, pred, target):
    ok = [r for r in rows if r["workload"] == workload and pred(r["solver"]) and r["error"] <= target]
    return min(ok, key=lambda r: r["seconds"]) if ok else None


def write(rows: list[dict], out: str) -> None:
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "workloads.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    lines = ["# Time to accuracy on the users' workloads", "",
             f"Written by `benchmarks/workloads.py` on {now}, {platform.machine()} "
             f"({platform.platform()}, {os.cpu_count()} cores), phsplit {_core.__version__}. "
             "One hour; error: the largest position error over samples every 10 s against DOP853 at rtol 1e-12; "
             "wall time of the user's call, minimum of repeats, same process. Tolerances and setup: the script's "
             "docstring.", ""]
    groups = {
        "phsplit splitting, fixed h": lambda s: s.startswith("phsplit") and "adaptive" not in s and "rk4" not in s,
        "phsplit splitting, adaptive": lambda s: s.startswith("phsplit") and "adaptive" in s,
        "phsplit rk4": lambda s: s == "phsplit rk4",
        "scipy LSODA": lambda s: s == "scipy LSODA",
        "scipy DOP853": lambda s: s == "scipy DOP853",
        "compiled DOP853": lambda s: s == "compiled DOP853",
        "CVODE BDF": lambda s: s == "CVODE BDF",
    }
    peers = ("phsplit rk4", "scipy LSODA", "scipy DOP853", "compiled DOP853", "CVODE BDF")
    for target in TARGETS:
        lines += [f"## Time to {target * 100:g} cm" if target >= 1e-2 else f"## Time to {target * 1000:g} mm", "",
                  "| workload | " + " | ".join(groups) + " | best passive / fastest peer |",
                  "|---" * (len(groups) + 2) + "|"]
        for wl in dict.fromkeys(r["workload"] for r in rows):
            cells, best = [], {}
            for g, pred in groups.items():
                r = fastest(rows, wl, pred, target)
                best[g] = r
                cells.append("–" if r is None else f"{r['seconds'] * 1e3:.2f} ms ({r['solver'].replace('phsplit ', '')}"
                             f" {r['setting']})".replace("scipy LSODA ", "").replace("scipy DOP853 ", "")
                             .replace("compiled DOP853 ", "").replace("CVODE BDF ", "").replace("rk4 ", ""))
            passive = [best[g] for g in ("phsplit splitting, fixed h", "phsplit splitting, adaptive") if best[g]]
            peer = [best[g] for g in peers if best[g]]
            if passive and peer:
                p, q = min(passive, key=lambda r: r["seconds"]), min(peer, key=lambda r: r["seconds"])
                ratio = q["seconds"] / p["seconds"]
                verdict = f"{ratio:.2f}× ({'faster' if ratio >= 1 else 'slower'} than {q['solver']})"
            else:
                verdict = "–"
            lines.append(f"| {wl} | " + " | ".join(cells) + f" | {verdict} |")
        lines.append("")
    with open(os.path.join(out, "workloads.md"), "w") as fh:
        fh.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    raise SystemExit(main())
