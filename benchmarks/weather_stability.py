"""Stability under weather: the shipped dp-weather scenario (the paper's vessel in a
rough sea, a near gale and a current, one hour) with SP2 at h = 1 s against RK4 at the same step
and at its own largest stable step, and against scipy's DOP853 on phsplit's compiled vector field (`phsplit._core.VectorField`).

"Stable" here: the run completes, and the stored energy H stays below 1e3 times the largest H of
the SP2 run at h = 0.25 s (a blow-up grows it by many orders of magnitude). Times are wall-clock
seconds of one run each, on this machine; BLAS pinned to one thread. Prints a table and writes
benchmarks/results/weather_stability.json.

Run: `make bench` (or `.venv/bin/python benchmarks/weather_stability.py [--quick]`)."""
from __future__ import annotations

import argparse
import json
import os
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import warnings  # noqa: E402

import numpy as np  # noqa: E402

import phsplit  # noqa: E402

# The bisection goes far beyond the natural periods on purpose; the warning says so each time.
warnings.simplefilter("ignore", phsplit.StepSizeWarning)


def run(v, h, method, t_end):
    t0 = time.perf_counter()
    s = phsplit.simulate(v, (0.0, t_end), h, method, control_start=0.0, save_every=max(1, int(round(10 / h))),
                         ledger=False)
    return s, time.perf_counter() - t0


def stable(s, bound):
    return s.status == "completed" and bool(np.all(np.isfinite(s.energy))) and float(np.max(s.energy)) < bound


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="10 minutes instead of one hour")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "results"))
    args = ap.parse_args()
    t_end = 600.0 if args.quick else 3600.0
    v = phsplit.load_scenario("dp-weather").vessel
    ref, _ = run(v, 0.25, "sp2", t_end)
    bound = 1e3 * float(np.max(ref.energy))
    rows = []
    for method, h in (("sp2", 1.0), ("sp4", 1.0), ("rk4", 1.0)):
        s, dt = run(v, h, method, t_end)
        rows.append({"method": method, "h": h, "stable": stable(s, bound), "seconds": dt,
                     "max_H_J": float(np.nanmax(s.energy)) if len(s.energy) else float("nan")})
    # the largest stable step of each, by bisection between a stable and an unstable step
    largest = {}
    for method in ("rk4", "sp2"):
        lo, hi = 0.25, 20.0
        s, _ = run(v, hi, method, t_end)
        if stable(s, bound):
            largest[method] = f">= {hi}"
            continue
        for _ in range(8):
            mid = 0.5 * (lo + hi)
            s, _ = run(v, mid, method, t_end)
            lo, hi = (mid, hi) if stable(s, bound) else (lo, mid)
        largest[method] = lo
    # scipy DOP853 on the compiled vector field (phsplit.VectorField), adaptive
    from scipy.integrate import solve_ivp

    from phsplit import _core

    f = _core.VectorField(v._inner, 0.0)
    y0 = v.initial_state()
    dop = {}
    for rtol in (1e-6, 1e-9):
        t0 = time.perf_counter()
        sol = solve_ivp(lambda t, y: f(t, y), (0.0, t_end), y0, method="DOP853", rtol=rtol, atol=1e-9)
        dop[rtol] = {"success": bool(sol.success), "steps": int(sol.t.size - 1), "seconds": time.perf_counter() - t0,
                     "largest_step_s": float(np.max(np.diff(sol.t)))}
    print(f"dp-weather, [0, {t_end:g}] s; stable = completes with H below {bound:.3g} J")
    print(f"{'method':8} {'h [s]':>6} {'stable':>7} {'time [s]':>9} {'max H [J]':>11}")
    for r in rows:
        print(f"{r['method']:8} {r['h']:6g} {str(r['stable']):>7} {r['seconds']:9.3f} {r['max_H_J']:11.3e}")
    print("largest stable step (bisection, 0.25-20 s):", largest)
    for rtol, d in dop.items():
        print(f"scipy DOP853 rtol {rtol:g}: success {d['success']}, {d['steps']} steps, largest {d['largest_step_s']:.3f} s, "
              f"{d['seconds']:.2f} s")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "weather_stability.json"), "w") as fh:
        json.dump({"t_end": t_end, "bound_J": bound, "fixed_step": rows, "largest_stable_step": largest,
                   "dop853": {str(k): v for k, v in dop.items()}}, fh, indent=1)


if __name__ == "__main__":
    main()
