#!/usr/bin/env python3
"""Cases per second for 1,000 one-hour SP2 cases (paper's vessel, controller on from t = 0,
h = 0.5 s, every 20th step saved), in-process (phsplit.simulate_many, threads) and on a Dask
LocalCluster (phsplit sweep: worker processes, each case written to the store).

Run: .venv/bin/python benchmarks/sweep_throughput.py [--cases N] [--linear-flow exact|gauss]
Writes benchmarks/results/sweep_throughput.md (the default flow S2), or
sweep_throughput_<flow>.md when --linear-flow is given.
"""
from __future__ import annotations

import argparse
import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import shutil  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import phsplit  # noqa: E402
from phsplit.batch import Settings, Sweep, run_sweep  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", type=int, default=1000)
    ap.add_argument("--linear-flow", choices=("exact", "gauss"), default=None,
                    help="flow S2 of every case (default: the library's default)")
    args = ap.parse_args()
    n = args.cases
    rng = np.random.default_rng(1)
    cases = [{"control.kp_translational[0]": float(k), "control.kp_rotational[2]": float(r)}
             for k, r in zip(rng.uniform(2e5, 8e5, n), rng.uniform(5e7, 2e8, n))]
    extra = {} if args.linear_flow is None else {"linear_flow": args.linear_flow}
    settings = Settings(t_span=(0.0, 3600.0), h=0.5, method="sp2", control_start=0.0, save_every=20, **extra)
    cores = os.cpu_count() or 2
    rows = []
    for workers in (1, cores):
        t0 = time.perf_counter()
        ds = phsplit.simulate_many(cases, settings=settings, max_workers=workers)
        dt = time.perf_counter() - t0
        assert (ds["status"].values == "completed").all()
        rows.append((f"in-process, {workers} thread(s)", dt, n / dt))
        print(rows[-1], flush=True)
    store = tempfile.mkdtemp(prefix="phsplit-sweep-bench-")
    try:
        sw = Sweep(settings=settings, base=phsplit.Vessel.paper(), cases=cases, name="bench")
        t0 = time.perf_counter()
        res = run_sweep(sw, store, n_workers=cores, progress=False)
        dt = time.perf_counter() - t0
        rows.append((f"LocalCluster, {cores} worker processes (incl. start-up and writing every case)", dt, n / dt))
        print(rows[-1], res["computed"], flush=True)
    finally:
        shutil.rmtree(store, ignore_errors=True)
    lines = ["# Sweep throughput", "",
             f"{n} one-hour SP2 cases (h = 0.5 s, 7,200 steps each, S2 {settings.linear_flow}"
             f"{' (the default)' if args.linear_flow is None else ''}, ledger on, every 20th step saved, "
             f"summary per case; default settings, so with the projection onto the restoring invariant, "
             f"docs/model.md §3.6), {cores} logical cores.", "", "| how | wall time [s] | cases per second |",
             "|---|---|---|"]
    lines += [f"| {a} | {b:.1f} | {c:.1f} |" for a, b, c in rows]
    text = "\n".join(lines) + "\n"
    os.makedirs(os.path.join(HERE, "results"), exist_ok=True)
    name = "sweep_throughput.md" if args.linear_flow is None else f"sweep_throughput_{args.linear_flow}.md"
    with open(os.path.join(HERE, "results", name), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
