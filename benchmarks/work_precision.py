#!/usr/bin/env python3
"""Work-precision, stability and memory benchmarks of phsplit against scipy and SUNDIALS CVODE.

Run with ``make bench`` (or ``.venv/bin/python benchmarks/work_precision.py [--quick]``).
Writes into ``benchmarks/results/``:

* ``work_precision.csv``: one row per run: interval, solver, variant, right-hand side,
  step or tolerance, wall time (median of repeats, s), final error (``inf``: failed, or stopped
  at the cap of 20 s per external-solver run);
* ``stability.csv``: for every method and step size, whether the energy stayed below its
  passivity bound over [0, 3600] s;
* ``summary.md``: the tables, the targets of the speed issue with measured values, the machine
  and the versions;
* ``work_precision_T100.png``, ``work_precision_T3600.png``.

The scenario is the paper's vessel with the controller on from t = 0. The error is the largest,
over m, p, x and the attitude quaternion, of ``|g(T) - g_ref(T)| / max_t |g_ref(t)|``. The
reference is explicit RK4 in the core with h = 1e-3 s. It is independent of the splitting code.
Its own error is estimated against RK4 with h = 2e-3 s and stated. BLAS is pinned to one thread
for the Python baselines, and every ratio compares runs made in the same process.
"""
from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ[_v] = "1"

import argparse  # noqa: E402
import csv  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import resource  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

# The splitting runs measure the paper's scheme unless PHSPLIT_BENCH_PROJECT=1: with the default
# projection onto the restoring invariant (docs/model.md §3.6) a decimated run cannot merge the
# last S2 of a step with the first of the next, and pays for one more S2 per step.
PROJECT = os.environ.get("PHSPLIT_BENCH_PROJECT", "0") == "1"

import phsplit  # noqa: E402
from phsplit import _core  # noqa: E402
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python", "tests"))
import reference as ref  # noqa: E402  (the independent numpy model of eq. 39, a test oracle)

HERE = os.path.dirname(os.path.abspath(__file__))
VESSEL = phsplit.Vessel.paper()
PARAMS = VESSEL.to_dict()
Y0 = VESSEL.initial_state()
GROUPS = {"m": slice(3, 6), "p": slice(0, 3), "x": slice(18, 21)}


def _group_scale() -> np.ndarray:
    """Absolute tolerance per unit rtol, per group of states, as a careful user sets it: the
    rule of benchmarks/workloads.py (momentum ``m × 1 m/s`` and ``I × 1 rad/s``, attitude
    entries 1, the restoring variable its initial size, position 1 m, the controller's
    integrals 10 m s). One tolerance for every component scaled by ``|y0|``
    (``rtol × max(|y0|, 1) × 1e-3``, used before) asks ~1e-3 m of a 780 m position and made
    DOP853 take 13 M evaluations on the paper's hour at rtol 1e-8."""
    from workloads import atol_of

    return atol_of(VESSEL, Y0, 1.0)


def quat_of(y: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    x, yy, z, w = Rotation.from_matrix(y[6:15].reshape(3, 3, order="F")).as_quat()
    q = np.array([w, x, yy, z])
    return q if q[0] >= 0 else -q


def flat(sol, i: int = -1) -> np.ndarray:
    return np.concatenate([sol.p[i], sol.m[i], sol.Q[i].reshape(-1, order="F"), sol.mu[i], sol.x[i],
                           sol.phi_th[i], sol.phi_x[i]])


class Reference:
    def __init__(self, T: float):
        t0 = time.perf_counter()
        fine = phsplit.simulate(VESSEL, (0.0, T), 1e-3, "rk4", control_start=0.0, ledger=False,
                                save_every=1000)
        coarse = phsplit.simulate(VESSEL, (0.0, T), 2e-3, "rk4", control_start=0.0, ledger=False,
                                  save_every=10**9)
        self.seconds = time.perf_counter() - t0
        self.end = flat(fine)
        self.scale = {k: float(np.max(np.linalg.norm(getattr(fine, k), axis=1))) for k in GROUPS}
        self.T = T
        self.accuracy = self.error(flat(coarse)) / 15.0  # RK4: e(2h) ≈ 16 e(h)

    def error(self, y: np.ndarray) -> float:
        errs = [np.linalg.norm(y[s] - self.end[s]) / self.scale[k] for k, s in GROUPS.items()]
        errs.append(np.linalg.norm(quat_of(y) - quat_of(self.end)))
        return float(max(errs)) if all(np.isfinite(errs)) else math.inf


def timed(fn, min_repeats: int = 3, budget: float = 1.0):
    """Median wall time of repeated calls (at least `min_repeats`, more while under `budget` s)."""
    times, out = [], None
    t_start = time.perf_counter()
    while len(times) < min_repeats or (time.perf_counter() - t_start < budget and len(times) < 15):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if times[-1] > 5.0:
            break
    return statistics.median(times), out


def fixed_step_runs(ref_: Reference, quick: bool) -> list[dict]:
    rows = []
    T = ref_.T
    methods = [("sp2", "exact"), ("sp2", "gauss"), ("sp4", "exact"), ("sp4", "gauss"), ("sp6", "exact"),
               ("sp6", "gauss"), ("heun", "-"), ("rk4", "-")]
    all_hs = [2.0, 1.0, 0.5, 0.25, 0.125, 0.0625, 0.03125, 0.015625]
    for meth, lf in methods:
        hs = all_hs
        # On [0, 3600] only SP2 needs the two shortest steps to reach a final error of 1e-6
        # (the speed target; second order, 4.3e-6 at h = 1/16 with the exact S2).
        if T > 1000 and meth != "sp2":
            hs = hs[:6]
        if quick:
            hs = hs[1:5]
        for h in hs:
            kw = {} if lf == "-" else {"linear_flow": lf, "project_invariants": PROJECT}

            def run():
                return phsplit.simulate(VESSEL, (0.0, T), h, meth, control_start=0.0, ledger=False,
                                        save_every=10**9, **kw)

            sec, sol = timed(run, min_repeats=3 if T < 1000 else 1, budget=0.5)
            err = ref_.error(flat(sol)) if sol.status == "completed" else math.inf
            rows.append({"T": T, "solver": f"phsplit {meth}", "variant": lf, "rhs": "core", "param": h,
                         "seconds": sec, "error": err})
    return rows


class OverBudget(Exception):
    pass


def capped(f, seconds: float, arity: int = 2):
    """Wrap a right-hand side so that a run stops once it has used `seconds` of wall time.
    `arity` 2 is scipy's f(t, y); 3 is CVODE's f(t, y, yp), whose signature it inspects."""
    start = [0.0]

    def check():
        if time.perf_counter() - start[0] > seconds:
            raise OverBudget

    if arity == 2:
        def g(t, y):
            check()
            return f(t, y)
    else:
        def g(t, y, yp):
            check()
            return f(t, y, yp)

    def arm():
        start[0] = time.perf_counter()

    g.arm = arm  # type: ignore[attr-defined]
    return g


CAP = 20.0  # seconds per external-solver run (5 with --quick)


def scipy_runs(ref_: Reference, quick: bool) -> list[dict]:
    from scipy.integrate import solve_ivp

    rows = []
    T = ref_.T
    rhs = {"numpy": ref.Field(PARAMS, True), "core": _core.VectorField(VESSEL._inner, 0.0)}
    scale = _group_scale()
    tols = [1e-4, 1e-6, 1e-8, 1e-10] if not quick else [1e-5, 1e-7]
    cap = 5.0 if quick else CAP
    for method in ("RK45", "DOP853", "LSODA", "Radau"):
        for name, f0 in rhs.items():
            for rtol in tols:
                f = capped(f0, cap)

                def run():
                    f.arm()
                    try:
                        return solve_ivp(f, (0.0, T), Y0, method=method, rtol=rtol, atol=rtol * scale)
                    except (OverBudget, ValueError, ArithmeticError, RuntimeError, np.linalg.LinAlgError):
                        return None  # over the time cap, or the solver failed (recorded as error inf)

                sec, sol = timed(run, min_repeats=1, budget=0.0)
                err = ref_.error(sol.y[:, -1]) if sol is not None and sol.success else math.inf
                rows.append({"T": T, "solver": f"scipy {method}", "variant": "-", "rhs": name, "param": rtol,
                             "seconds": sec, "error": err})
                if sec > (10.0 if not quick else 2.0):
                    break  # tighter tolerances only take longer
    return rows


def cvode_runs(ref_: Reference, quick: bool) -> list[dict]:
    try:
        from sksundae.cvode import CVODE
    except ImportError:
        print("scikit-sundae is not installed: CVODE skipped", file=sys.stderr)
        return []
    rows = []
    T = ref_.T
    f_np = ref.Field(PARAMS, True)
    f_core = _core.VectorField(VESSEL._inner, 0.0)

    def rhs_numpy(t, y, yp):
        yp[:] = f_np(t, y)

    def rhs_core(t, y, yp):
        f_core.into(t, y, yp)

    scale = _group_scale()
    tols = [1e-4, 1e-6, 1e-8, 1e-10] if not quick else [1e-5, 1e-7]
    cap = 5.0 if quick else CAP
    for method in ("Adams", "BDF"):
        for name, f0 in (("numpy", rhs_numpy), ("core", rhs_core)):
            for rtol in tols:
                f = capped(f0, cap, arity=3)

                def run():
                    f.arm()
                    solver = CVODE(f, method=method, rtol=rtol, atol=rtol * scale, max_num_steps=10**7)
                    try:
                        return solver.solve(np.array([0.0, T]), Y0)
                    except Exception:  # OverBudget raised inside the callback surfaces here
                        return None

                sec, sol = timed(run, min_repeats=1, budget=0.0)
                ok = sol is not None and bool(getattr(sol, "success", False))
                err = ref_.error(np.asarray(sol.y)[-1]) if ok else math.inf
                rows.append({"T": T, "solver": f"CVODE {method}", "variant": "-", "rhs": name, "param": rtol,
                             "seconds": sec, "error": err})
                if sec > (10.0 if not quick else 2.0):
                    break
    return rows


def compiled_runs(ref_: Reference, quick: bool) -> list[dict]:
    """DOP853 in Rust (the `differential-equations` crate) on phsplit's compiled field, no Python
    in the loop (`phsplit._core.VectorField.solve_dop853`): the compiled classical peer."""
    rows = []
    T = ref_.T
    f = _core.VectorField(VESSEL._inner, 0.0)
    scale = _group_scale()
    tols = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10] if not quick else [1e-5, 1e-7]
    for rtol in tols:
        def run():
            try:
                return f.solve_dop853((0.0, T), Y0, rtol, rtol * scale)
            except phsplit.PhsplitError:
                return None

        sec, out = timed(run)
        err = ref_.error(out[0]) if out is not None else math.inf
        rows.append({"T": T, "solver": "compiled DOP853", "variant": "-", "rhs": "core", "param": rtol,
                     "seconds": sec, "error": err})
    return rows


def time_at_error(rows: list[dict], target: float) -> float:
    """Wall time to reach `target` error, interpolated log-log between the bracketing runs."""
    pts = sorted((r["error"], r["seconds"]) for r in rows if math.isfinite(r["error"]) and r["error"] > 0)
    best = math.inf
    for (e1, s1), (e2, s2) in zip(pts, pts[1:]):
        if e1 <= target <= e2:
            w = (math.log(target) - math.log(e2)) / (math.log(e1) - math.log(e2))
            best = min(best, math.exp(math.log(s2) + w * (math.log(s1) - math.log(s2))))
    for e, s in pts:  # a run that is already at least as accurate
        if e <= target:
            best = min(best, s)
    return best


def stability(quick: bool) -> list[dict]:
    """Largest h at which the energy stays below its passivity bound over [0, 3600] s:
    H_n <= H_0 + (energy supplied through the port up to step n), with a round-off allowance."""
    T = 3600.0
    hs = [0.25, 0.5, 1.0, 1.5, 1.9375, 2.5, 4.0, 6.0, 10.0, 16.0, 25.0, 40.0, 50.0]
    if quick:
        hs = [0.5, 1.9375, 4.0, 16.0, 50.0]
    rows = []
    for meth, lf in (("lie", "exact"), ("sp2", "exact"), ("sp2", "gauss"), ("sp4", "exact"), ("sp6", "exact"),
                     ("euler", "-"), ("heun", "-"), ("rk4", "-")):
        for h in hs:
            kw = {} if lf == "-" else {"linear_flow": lf, "project_invariants": PROJECT}
            n = math.floor(T / h)
            save = max(1, n // 2000)
            sol = phsplit.simulate(VESSEL, (0.0, T), h, meth, control_start=0.0, save_every=save, **kw)
            if sol.status != "completed":
                ok, excess = False, math.inf
            else:
                supplied = np.cumsum(sol.ledger.supplied)
                slack = 1e-9 * (sol.energy[0] + np.abs(sol.ledger.supplied).sum() + sol.ledger.dissipated.sum())
                excess = float(np.max(sol.energy - sol.energy[0] - supplied))
                ok = excess <= slack
            rows.append({"method": meth, "variant": lf, "h": h, "completed": sol.status == "completed",
                         "below_bound": ok, "max_excess_J": excess,
                         "H_end": float(sol.energy[-1]) if sol.status == "completed" else math.inf})
    return rows


MEM_CHILD = """
import time, phsplit
def hwm_kb():  # this process's own peak RSS (ru_maxrss would include the forking parent's)
    with open("/proc/self/status") as f:
        return int(next(l.split()[1] for l in f if l.startswith("VmHWM")))
v = phsplit.Vessel.paper()
t0 = time.perf_counter()
s = phsplit.simulate(v, (0.0, {T}), {h}, "sp2", control_start=0.0, ledger=True, save_every={k},
                     linear_flow="gauss", project_invariants={PROJECT})
dt = time.perf_counter() - t0
import numpy as np
print(s.steps, len(s.t), dt, hwm_kb(),
      float(s.orthogonality_defect.max()), float(s.ledger.relative_residual().max()))
"""


def memory(quick: bool) -> dict:
    n = 10**6 if quick else 10**7
    h = 0.01
    code = MEM_CHILD.format(T=n * h, h=h, k=10**4, PROJECT=PROJECT)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    steps, saved, sec, rss_kb, ortho, ledger = out
    return {"steps": int(steps), "saved": int(saved), "seconds": float(sec), "peak_rss_MB": int(rss_kb) / 1024,
            "orthogonality": float(ortho), "ledger": float(ledger)}


def per_step(quick: bool) -> dict[str, float]:
    """Mean time of one step (µs) in long runs (h = 0.1 s, controller on, no saving, no ledger)."""
    out = {}
    n = 20_000 if quick else 200_000
    for meth, lf in (("sp2", "exact"), ("sp2", "gauss"), ("sp4", "exact"), ("sp4", "gauss"), ("sp6", "exact"),
                     ("sp6", "gauss"), ("heun", "-"), ("rk4", "-")):
        kw = {} if lf == "-" else {"linear_flow": lf, "project_invariants": PROJECT}
        sec, _ = timed(lambda: phsplit.simulate(VESSEL, (0.0, n * 0.1), 0.1, meth, control_start=0.0, ledger=False,
                                                 save_every=10**9, **kw), min_repeats=3, budget=0.0)
        out[f"{meth} ({lf})" if lf != "-" else meth] = sec / n * 1e6
    return out


def versions() -> str:
    import scipy

    try:
        import sksundae

        sk = sksundae.__version__
    except ImportError:
        sk = "not installed"
    cpu = platform.machine()
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return (f"phsplit {phsplit.__version__}, Python {platform.python_version()}, numpy {np.__version__}, "
            f"scipy {scipy.__version__}, scikit-sundae {sk}; {cpu}, {os.cpu_count()} logical cores; "
            "BLAS pinned to 1 thread")


def plot(rows: list[dict], T: float, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9, 6), layout="constrained")
    keys = sorted({(r["solver"], r["variant"], r["rhs"]) for r in rows if r["T"] == T})
    for k in keys:
        pts = sorted((r["seconds"], r["error"]) for r in rows
                     if (r["solver"], r["variant"], r["rhs"]) == k and r["T"] == T and math.isfinite(r["error"]))
        if not pts:
            continue
        label = k[0] + ("" if k[1] == "-" else f" ({k[1]} S2)") + ("" if k[2] == "core" and k[0].startswith("phsplit") else f" [{k[2]} rhs]")
        style = "-o" if k[0].startswith("phsplit") else "--s"
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], style, ms=3.5, lw=1, label=label)
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("final error (relative, max over m, p, x, q)")
    ax.set_title(f"Work-precision on [0, {T:g}] s, paper's vessel, controller on")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer points, [0, 100] only, shorter runs")
    ap.add_argument("--out", default=os.path.join(HERE, "results"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    rows: list[dict] = []
    refs = {}
    for T in ((100.0,) if args.quick else (100.0, 3600.0)):
        print(f"reference on [0, {T:g}] ...", flush=True)
        refs[T] = Reference(T)
        print(f"  {refs[T].seconds:.1f} s, estimated accuracy {refs[T].accuracy:.1e}", flush=True)
        for fn in (fixed_step_runs, compiled_runs, scipy_runs, cvode_runs):
            print(f"  {fn.__name__} ...", flush=True)
            rows += fn(refs[T], args.quick)
    with open(os.path.join(args.out, "work_precision.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    for T in refs:
        plot(rows, T, os.path.join(args.out, f"work_precision_T{T:g}.png"))
    print("stability sweep ...", flush=True)
    stab = stability(args.quick)
    with open(os.path.join(args.out, "stability.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(stab[0]))
        w.writeheader()
        w.writerows(stab)
    print("per-step times ...", flush=True)
    steps = per_step(args.quick)
    print("memory of a long decimated run ...", flush=True)
    mem = memory(args.quick)

    # ---- summary
    L = ["# phsplit performance", "", f"Machine and versions: {versions()}.", "",
         "Splitting runs: " + ("with the projection onto the restoring invariant (the default)." if PROJECT else
                               "the paper's scheme, `project_invariants=False` (set PHSPLIT_BENCH_PROJECT=1 "
                               "for the default projection; its cost: docs/model.md §3.6)."), "",
         "Generated by `make bench` (`benchmarks/work_precision.py" + (" --quick" if args.quick else "") + "`).", ""]
    L += ["## One step (long runs, h = 0.1 s, controller on, no ledger)", "", "| method | µs per step |", "|---|---|"]
    L += [f"| {k} | {v:.2f} |" for k, v in steps.items()]
    L += ["", "Criterion micro-benchmarks of each flow: `cargo bench -p phsplit-core --bench flows`.", ""]
    target = 1e-6
    for T, r in refs.items():
        sub = [x for x in rows if x["T"] == T]
        L += [f"## Work-precision on [0, {T:g}] s", "",
              f"Reference: RK4, h = 1e-3 s, estimated accuracy {r.accuracy:.1e}.", "",
              f"![work-precision](work_precision_T{T:g}.png)", "",
              f"| solver | S2 | rhs | time to error {target:g} [s] |", "|---|---|---|---|"]
        groups = sorted({(x["solver"], x["variant"], x["rhs"]) for x in sub})
        best: dict[tuple, float] = {}
        for g in groups:
            tt = time_at_error([x for x in sub if (x["solver"], x["variant"], x["rhs"]) == g], target)
            best[g] = tt
            L.append(f"| {g[0]} | {g[1]} | {g[2]} | {'not reached' if not math.isfinite(tt) else f'{tt:.4g}'} |")
        L.append("")
        split = min(v for k, v in best.items() if k[0] in ("phsplit sp2", "phsplit sp4", "phsplit sp6"))
        rk4 = best.get(("phsplit rk4", "-", "core"), math.inf)
        dop = best.get(("compiled DOP853", "-", "core"), math.inf)
        L += [f"### Targets at final error 1e-6 on [0, {T:g}] s", "",
              "Ratios of times to the same final error, core against core, measured in the same run "
              "(the issue asks ≥ 1×, with 3× as the goal beyond it).", ""]
        if T > 1000:
            L += ["By the end of this run the vessel has settled: the final error measures whether a method "
                  "ends on the true equilibrium. Runge–Kutta methods do at any stable step, and so do the "
                  "splitting methods with the projection (docs/model.md §3.6); without it they end with a "
                  "false tilt. The transient's accuracy is what [0, 100] s measures.", ""]
        L += [
              "| fastest passive splitting against | ratio | ≥ 1× | ≥ 3× |", "|---|---|---|---|",
              f"| phsplit RK4 | {rk4 / split:.2f}× | {'yes' if rk4 / split >= 1 else 'no'} | "
              f"{'yes' if rk4 / split >= 3 else 'no'} |",
              f"| compiled DOP853 | {dop / split:.2f}× | {'yes' if dop / split >= 1 else 'no'} | "
              f"{'yes' if dop / split >= 3 else 'no'} |", ""]
        sp2 = {lf: best.get(("phsplit sp2", lf, "core"), math.inf) for lf in ("exact", "gauss")}
        L += ["SP2 reaches a final error of 1e-6 on [0, %g] s: " % T + "; ".join(
            f"{lf} S2 {'in ' + format(v * 1e3, '.4g') + ' ms' if math.isfinite(v) else 'not at the sampled steps'}"
            for lf, v in sp2.items()) + ".", ""]
        if T == 100.0:
            def fastest(prefix: str, rhs: str | None) -> float:
                vals = [v for k, v in best.items() if k[0].startswith(prefix) and (rhs is None or k[2] == rhs)]
                return min(vals or [math.inf])

            def row(text: str, ratio: float, need: float) -> str:
                shown = f"{ratio:.2f}×" if ratio < 10 else f"{ratio:.0f}×"
                return f"| {text} | {shown} | {'yes' if ratio >= need else 'no'} |"

            L += ["### Targets at final error 1e-6 on [0, 100] s", "",
                  "Ratios of times to the same final error, measured in the same run. \"numpy rhs\" is the "
                  "right-hand side a Python user writes; \"compiled rhs\" is the same field as phsplit's "
                  "compiled core (`phsplit._core.VectorField`), called from the Python solver.", "",
                  "| target | measured | met |", "|---|---|---|",
                  row("fastest splitting ≥ 3× faster than phsplit RK4", rk4 / split, 3),
                  row("≥ 100× faster than scipy DOP853, numpy rhs", fastest("scipy DOP853", "numpy") / split, 100),
                  row("≥ 100× faster than scipy DOP853, compiled rhs", fastest("scipy DOP853", "core") / split, 100),
                  row("≥ 100× faster than CVODE (fastest of Adams, BDF), numpy rhs",
                      fastest("CVODE", "numpy") / split, 100),
                  row("≥ 100× faster than CVODE (fastest of Adams, BDF), compiled rhs",
                      fastest("CVODE", "core") / split, 100),
                  ""]
    L += ["## Stability over [0, 3600] s", "",
          "Largest sampled h with the energy below its passivity bound H_n ≤ H_0 + supplied_n at every saved step, "
          "for this and every smaller sampled h:", "", "| method | S2 | largest stable h [s] | first failing h [s] |",
          "|---|---|---|---|"]
    for key in dict.fromkeys((r["method"], r["variant"]) for r in stab):
        rs = [r for r in stab if (r["method"], r["variant"]) == key]
        good = None
        fail = None
        for r in rs:
            if r["below_bound"] and fail is None:
                good = r["h"]
            elif fail is None:
                fail = r["h"]
        L.append(f"| {key[0]} | {key[1]} | {good if good is not None else '< ' + str(rs[0]['h'])} | "
                 f"{fail if fail is not None else 'none up to ' + str(rs[-1]['h'])} |")
    L += ["", "## Memory and long runs", "",
          f"SP2 (Gauss S2, ledger on), {mem['steps']:,} steps with every 10,000th saved ({mem['saved']:,} samples): "
          f"{mem['seconds']:.1f} s, peak RSS {mem['peak_rss_MB']:.0f} MB, max ‖QᵀQ − I‖ {mem['orthogonality']:.1e}, "
          f"worst relative ledger residual {mem['ledger']:.1e}.", ""]
    L += ["## Targets for one step", "", "| target | measured | met |", "|---|---|---|"]
    for name, lim in (("sp2", 1.0), ("sp4", 4.0), ("sp6", 8.0)):
        best_v = min(v for k, v in steps.items() if k.startswith(name))
        which = min((k for k in steps if k.startswith(name)), key=steps.get)
        L.append(f"| {name.upper()} ≤ {lim:g} µs | {best_v:.2f} µs ({which}) | {'yes' if best_v <= lim else 'no'} |")
    L.append(f"| RK4 ≤ 0.3 µs | {steps['rk4']:.2f} µs | {'yes' if steps['rk4'] <= 0.3 else 'no'} |")
    L.append(f"| 10^7-step decimated run < 200 MB | {mem['peak_rss_MB']:.0f} MB | {'yes' if mem['peak_rss_MB'] < 200 else 'no'} |")
    text = "\n".join(L) + "\n"
    with open(os.path.join(args.out, "summary.md"), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
