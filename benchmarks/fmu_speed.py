"""The vessel FMU's speed: a one-hour run of the paper's vessel (Fig. 2 settings, SP4,
the controller from 50 s) with 0.1 s communication steps and the internal step h = 0.1 s, in
FMPy (``simulate_fmu``, recording ten outputs, and a bare ``doStep`` loop through FMPy's
``FMU2Slave``, with constant inputs and with the external force changed every step, as a
coupling changes it), against ``phsplit.simulate`` of the same run (every step saved). Times are
wall-clock seconds of the best of ``--repeat`` runs, all measured in this run; BLAS pinned to one
thread. Prints a table and writes benchmarks/results/fmu_speed.json.

Run: `make bench` (or `.venv/bin/python benchmarks/fmu_speed.py [--quick]`)."""
from __future__ import annotations

import argparse
import json
import os
import tempfile
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from fmpy import extract, read_model_description, simulate_fmu  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

import phsplit  # noqa: E402
from phsplit import fmu  # noqa: E402

OUTPUTS = ["position.x", "position.y", "position.z", "euler.roll", "euler.pitch", "euler.yaw",
           "velocity.u", "velocity.v", "energy.stored", "control_force.x"]


def best(f, repeat):
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="a 360 s run instead of one hour")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(os.path.dirname(__file__), "results"))
    args = ap.parse_args()
    t_end, dt = (360.0 if args.quick else 3600.0), 0.1
    n = int(round(t_end / dt))
    work = tempfile.mkdtemp()
    scen = phsplit.scenario.Scenario.paper_fig2().replace(h=dt, t_span=(0.0, t_end))
    path = fmu.export(scen, os.path.join(work, "vessel.fmu"))

    def run_fmpy():
        return simulate_fmu(str(path), stop_time=t_end, output_interval=dt, output=OUTPUTS)

    md = read_model_description(str(path))
    unzipped = extract(str(path))

    force = {v.name: v.valueReference for v in md.modelVariables}["external_force.x"]

    def run_loop(changing: bool):
        """doStep over the run through FMPy's FMU2Slave; with ``changing``, a new external force
        before every step, as a coupling gives it. Returns the final position.x."""
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="v")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        for k in range(n):
            if changing:
                s.setReal([force], [1e5 * np.sin(0.05 * k * dt)])
            s.doStep(k * dt, dt)
        x = s.getReal([0])[0]
        s.terminate()
        s.freeInstance()
        return x

    def run_simulate():
        return phsplit.simulate(phsplit.Vessel.paper(), method="sp4", h=dt, t_span=(0.0, t_end))

    t_fmpy, r = best(run_fmpy, args.repeat)
    t_bare, x_bare = best(lambda: run_loop(False), args.repeat)
    t_sim, sol = best(run_simulate, args.repeat)
    t_changing, _ = best(lambda: run_loop(True), args.repeat)
    # The same numbers (the FMU test asserts this; here a guard that the runs are the same run).
    diff = abs(r["position.x"][-1] - sol.x[-1, 0]) / abs(sol.x[-1, 0])
    assert diff < 1e-12 and abs(x_bare - sol.x[-1, 0]) < 1e-9 * abs(sol.x[-1, 0]), diff
    rows = [
        ("phsplit.simulate (every step saved)", t_sim),
        ("FMU in FMPy simulate_fmu (10 outputs recorded)", t_fmpy),
        ("FMU in FMPy FMU2Slave, doStep loop only", t_bare),
        ("FMU2Slave, external force changed every step", t_changing),
    ]
    print(f"one {'hour' if not args.quick else '360 s'} run, {n} communication steps of {dt} s, SP4, h = {dt} s")
    print(f"{'run':48} {'total s':>9} {'us/step':>9} {'vs simulate':>12}")
    for name, t in rows:
        print(f"{name:48} {t:9.3f} {1e6 * t / n:9.1f} {t / t_sim:12.2f}")
    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "fmu_speed.json"), "w") as f:
        json.dump({"t_end": t_end, "communication_step": dt, "h": dt, "method": "sp4", "steps": n,
                   "seconds": {name: t for name, t in rows},
                   "microseconds_per_step": {name: 1e6 * t / n for name, t in rows}}, f, indent=2)


if __name__ == "__main__":
    main()
