#!/usr/bin/env python3
"""The energy error of the default flow S2 (Gauss collocation) against the exact S2, and the
time each takes to a given energy accuracy: the paper's Fig. 4 experiment (§4) with the library
defaults otherwise (projection on, ledger on).

Run with ``.venv/bin/python benchmarks/energy_accuracy.py`` (part of ``make bench``). Writes
``benchmarks/results/energy_accuracy.md``.

Experiment: the paper's vessel, the controller on from t = 0, SP2 over [0, 50] s and SP4 over
[0, 100] s (Fig. 4's spans), at the steps of Fig. 4 (SP2 h = 2/3 s, SP4 h = 1.9375 s) and a
range of others. Error: the largest ``|H(t_n) − H_ref(t_n)| / H_0`` over the steps, with the
reference from scipy's DOP853 at rtol 1e-12 on the core's compiled field (a different
integrator). Time: the wall time of ``phsplit.simulate``, the minimum of repeats.
"""
from __future__ import annotations

import datetime
import os
import platform
import time
import warnings

import numpy as np
from scipy.integrate import solve_ivp

import phsplit
from phsplit import _core

HERE = os.path.dirname(os.path.abspath(__file__))
V = phsplit.Vessel.paper()
Y0 = V.initial_state()
CASES = (("sp2", 2.0 / 3.0, 50.0), ("sp4", 1.9375, 100.0))
STEPS = (2.0, 1.9375, 1.0, 2.0 / 3.0, 0.5, 0.25, 0.125, 0.0625)
LEVELS = (1e-2, 1e-3, 1e-4, 1e-5)


def reference(t_end: float, h: float) -> np.ndarray:
    n = int(round(t_end / h))
    ts = np.linspace(0.0, n * h, n + 1)
    f = _core.VectorField(V._inner, 0.0)
    atol = 1e-12 * np.maximum(np.abs(Y0), 1.0)
    sol = solve_ivp(f, (0.0, ts[-1]), Y0, method="DOP853", rtol=1e-12, atol=atol, t_eval=ts)
    assert sol.success
    return np.array([V.energy(y) for y in sol.y.T])


def main() -> int:
    warnings.simplefilter("ignore")
    rows = []
    for method, h_fig, span in CASES:
        for h in sorted(set(STEPS) | {h_fig}, reverse=True):
            n = int(np.floor(span / h * (1 + 1e-12)))
            t_end = n * h
            H = reference(t_end, h)
            for flow in ("gauss", "exact"):
                best = np.inf
                for _ in range(5):
                    t = time.perf_counter()
                    sol = phsplit.simulate(V, (0.0, t_end), h, method, control_start=0.0, linear_flow=flow)
                    best = min(best, time.perf_counter() - t)
                err = float(np.abs(sol.energy - H).max() / H[0])
                rows.append((method, flow, h, h == h_fig, best, err))
                print(f"{method} {flow:5s} h={h:.4g} {best * 1e3:.3f} ms energy error {err:.2e}", flush=True)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    L = ["# The energy error of the default S2 (Gauss) against the exact S2", "",
         f"Written by `benchmarks/energy_accuracy.py` on {now}, {platform.machine()} ({platform.platform()}, "
         f"{os.cpu_count()} cores). The paper's Fig. 4 experiment (controller on from t = 0; SP2 on [0, 50] s, "
         "SP4 on [0, 100] s) with the library's other defaults; error: max |H − H_ref| / H₀ over the steps, "
         "reference DOP853 at rtol 1e-12.", "", "## At Fig. 4's steps", "",
         "| method | h [s] | Gauss: energy error | exact: energy error | ratio |", "|---|---|---|---|---|"]
    for method, h_fig, _ in CASES:
        g = next(r for r in rows if r[0] == method and r[1] == "gauss" and r[3])
        e = next(r for r in rows if r[0] == method and r[1] == "exact" and r[3])
        L.append(f"| {method} | {h_fig:.4g} | {g[5]:.2e} | {e[5]:.2e} | {g[5] / e[5]:.1f}× |")
    L += ["", "## Time to an energy accuracy (fastest sampled step)", "",
          "| method | energy error ≤ | Gauss | exact | exact / Gauss time |", "|---|---|---|---|---|"]
    for method, _, _ in CASES:
        for lvl in LEVELS:
            best = {}
            for flow in ("gauss", "exact"):
                ok = [r for r in rows if r[0] == method and r[1] == flow and r[5] <= lvl]
                best[flow] = min(ok, key=lambda r: r[4]) if ok else None
            cell = {f: ("not reached" if r is None else f"{r[4] * 1e3:.3f} ms (h {r[2]:.4g})") for f, r in best.items()}
            ratio = (f"{best['exact'][4] / best['gauss'][4]:.2f}" if best["gauss"] and best["exact"] else "–")
            L.append(f"| {method} | {lvl:g} | {cell['gauss']} | {cell['exact']} | {ratio} |")
    L.append("")
    out = os.path.join(HERE, "results", "energy_accuracy.md")
    with open(out, "w") as fh:
        fh.write("\n".join(L))
    print("\n".join(L))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
