#!/usr/bin/env python3
"""phsplit's lumped-mass pipe against the stored MoorDyn peer run.

The line and the prescribed top motion of benchmarks/pipe_moordyn.py (both its
cases: the top level "slack" case, Ax = 2 m, Az = 1 m, and its "taut" section,
Ax = 0.5 m, Az = 0.25 m), driven with ``phsplit.pipe.drive`` at the steps
STEPS (the ramped motion sampled at those times), N = 25, 50, 100. Over
t in [50, 100] s the top segment's tension (``segment_tension``, MoorDyn's
GetLineFairTen) gives the mean, the harmonic amplitudes at the forcing period
(the estimator of pipe_moordyn.py: trapezoidal Fourier integrals over the
window's samples), (max-min)/2 and the slack fraction.

Convergence: a step h is converged when the run at h/2 changes the mean and
the first harmonic by < 0.1 % (the change of (max-min)/2 is recorded too: it
does not settle, in either code, as it samples the undamped axial ringing); every step of STEPS is therefore run with its
half too, and when none of STEPS is converged the halving goes on from the
smallest (EXTRA_HALVINGS more at most). Stability: h = 1.0 s runs.
Energy: max |diff(storage) - (top_work + current - drag - axial_damping -
seabed)| / max |storage| over every step of every run.

Needs benchmarks/results/pipe/moordyn.json (run pipe_moordyn.py first).
Writes benchmarks/results/pipe/comparison.json and comparison.md.

Run: `make bench` (or `.venv/bin/python benchmarks/pipe_vs_moordyn.py`).
"""
from __future__ import annotations

import json
import math
import os
import platform
import subprocess
import time
from importlib import metadata
from pathlib import Path

import numpy as np
import phsplit

HERE = Path(__file__).resolve().parent
RES = HERE / "results" / "pipe"
MD = RES / "moordyn.json"

STEPS = (0.5, 0.2, 0.1, 0.05, 0.02)
EXTRA_HALVINGS = 7
NS = (25, 50, 100)
TOL = 1e-3
TAUT = (0.5, 0.25)  # pipe_moordyn.TAUT's amplitudes (checked against moordyn.json's)


def pipe_table(p: dict, n: int) -> dict:
    ax, ay, _ = p["anchor"]
    return dict(model="lumped_mass", length=p["L"], segments=n, axial_stiffness=p["EA"],
                mass=p["mu"], diameter=p["d"], water_depth=p["depth"],
                hang_off=list(p["fairlead"]), anchor=[ax, ay], drag_normal=p["Cd"],
                drag_tangential=p["CdAx"], added_mass=p["Ca"], seabed_stiffness=p["kbot"],
                seabed_damping=p["cbot"], axial_damping=p["BA"])


def vessel(p: dict, n: int) -> phsplit.Vessel:
    """The paper vessel as the carrier of the line's [pipe] table."""
    tables = phsplit.Vessel.preset("paper").to_dict()
    g, rho = tables["vessel"]["gravity"], tables["vessel"]["water_density"]
    assert (g, rho) == (p["g"], p["rho_w"]), (g, rho)
    tables["pipe"] = pipe_table(p, n)
    # at the origin, upright: the hang-off point (MoorDyn's fairlead) is where the drive starts
    tables["initial"].update(position=[0.0, 0.0, 0.0], euler=[0.0, 0.0, 0.0])
    return phsplit.Vessel.from_dict(tables)


def motion(p: dict, amp, h: float):
    """The ramped top positions at t = k h (pipe_moordyn.top_motion's)."""
    n = int(round(p["t_end"] / h))
    t = np.arange(n + 1) * h
    tr = p["t_ramp"]
    r = np.where(t < tr, 0.5 * (1 - np.cos(np.pi * t / tr)), 1.0)
    s = np.sin(2 * np.pi * t / p["T"])
    x0, y0, z0 = p["fairlead"]
    return t, np.column_stack([x0 + r * amp[0] * s, y0 + 0 * t, z0 + r * amp[1] * s])


def window_stats(p: dict, t, T) -> dict:
    """pipe_moordyn.run's estimator, on the same window."""
    w0, w1 = p["window"]
    m = (t >= w0 - 1e-9) & (t <= w1 + 1e-9)
    tw, Tw = t[m], T[m]
    om = 2 * math.pi / p["T"]
    out = dict(T_mean=float(Tw.mean()), T_amp=float(0.5 * (Tw.max() - Tw.min())),
               T_max=float(Tw.max()), T_min=float(Tw.min()),
               slack_fraction=float(np.mean(Tw <= 0.0)))
    for k in (1, 2, 3):
        c = 2 * np.trapezoid(Tw * np.cos(k * om * tw), tw) / (tw[-1] - tw[0])
        s_ = 2 * np.trapezoid(Tw * np.sin(k * om * tw), tw) / (tw[-1] - tw[0])
        out[f"H{k}_amp"] = float(math.hypot(c, s_))
        out[f"H{k}_phase_deg"] = float(math.degrees(math.atan2(-c, s_)))
    return out


def drive(p, amp, n, h, v):
    t, tops = motion(p, amp, h)
    w = time.perf_counter()
    try:
        r = phsplit.pipe.drive(v, t, tops)
    except Exception as e:  # the implicit step's Newton iteration failing: no result
        return dict(N=n, h=h, steps=len(t) - 1, wall_s=time.perf_counter() - w, finite=False,
                    failed=f"{type(e).__name__}: {e}")
    wall = time.perf_counter() - w
    T = r["segment_tension"]
    ok = bool(np.all(np.isfinite(T)))
    out = dict(N=n, h=h, steps=len(t) - 1, wall_s=wall, finite=ok,
               T_top_initial=float(T[0]), top_tension_initial=float(r["top_tension"][0]))
    if ok:
        out.update(window_stats(p, t, T))
        out["top_tension_mean"] = float(window_stats(p, t, r["top_tension"])["T_mean"])
        books = r["top_work"] + r["current"] - r["drag"] - r["axial_damping"] - r["seabed"]
        err = np.abs(np.diff(r["storage"]) - books[1:])
        out["energy_residual_rel"] = float(err.max() / np.abs(r["storage"]).max())
        out["dissipated_drag_J"] = float(r["drag"].sum())
        out["dissipated_seabed_J"] = float(r["seabed"].sum())
        out["top_work_J"] = float(r["top_work"].sum())
    return out


def rel(a, b):
    return None if a is None or b is None else a / b - 1.0


def converged(runs: dict, h: float) -> dict | None:
    a, b = runs.get(h), runs.get(h / 2)
    if a is None or b is None or not (a["finite"] and b["finite"]):
        return None
    return dict(mean=abs(rel(b["T_mean"], a["T_mean"])),
                H1=abs(rel(b["H1_amp"], a["H1_amp"])),
                amp=abs(rel(b["T_amp"], a["T_amp"])))


def ok(c, also_amp):
    return bool(c) and c["mean"] < TOL and c["H1"] < TOL and (not also_amp or c["amp"] < TOL)


def study(p, amp, n, also_amp=False):
    v = vessel(p, n)
    runs = {}
    for h in sorted({*STEPS, *(s / 2 for s in STEPS)}, reverse=True):
        runs[h] = drive(p, amp, n, h, v)
    conv_h = next((h for h in STEPS if ok(converged(runs, h), also_amp)), None)
    h = min(STEPS) / 2
    k = 0
    while conv_h is None and k < EXTRA_HALVINGS:
        runs[h / 2] = drive(p, amp, n, h / 2, v)
        if ok(converged(runs, h), also_amp):
            conv_h = h
        h /= 2
        k += 1
    for hh in runs:
        runs[hh]["change_at_half_step"] = converged(runs, hh)
    big = drive(p, amp, n, 1.0, v)
    return dict(N=n, runs=[runs[h] for h in sorted(runs, reverse=True)], converged_h=conv_h,
                converged=conv_h is not None,
                h_used=conv_h if conv_h is not None else min(runs),
                h1_run=big)


def machine():
    cpu = None
    for ln in open("/proc/cpuinfo"):
        if ln.startswith("model name"):
            cpu = ln.split(":", 1)[1].strip()
            break
    return dict(platform=platform.platform(), python=platform.python_version(), cpu=cpu,
                n_cpu=os.cpu_count())


def fmt_k(x):
    return "–" if x is None else f"{x / 1e3:.1f}"


def fmt_pct(x):
    return "–" if x is None else f"{100 * x:+.2f} %"


def fmt_h(h):
    return f"{h * 1e3:.3g} ms" if h < 0.1 else f"{h:g} s"


def main():
    t0 = time.perf_counter()
    # The line and the motion (params are the same in every version of the peer file); the
    # peer's results are read after phsplit's runs.
    p = json.loads(MD.read_text())["params"]
    amps = {"slack": (p["Ax"], p["Az"]), "taut": TAUT}
    studies = {}
    for name, amp in amps.items():
        studies[name] = {}
        for n in NS:
            s = study(p, amp, n)
            studies[name][str(n)] = s
            ph = next(r for r in s["runs"] if r["h"] == s["h_used"])
            print(f"{name} N={n}: h_conv={s['converged_h']} mean={ph['T_mean']:.1f} "
                  f"H1={ph['H1_amp']:.1f} amp={ph['T_amp']:.1f} "
                  f"h=1 finite={s['h1_run']['finite']}", flush=True)
    md = json.loads(MD.read_text())
    if "taut" not in md:
        raise SystemExit(f"{MD} has no 'taut' section: rerun benchmarks/pipe_moordyn.py")
    assert (md["taut"]["Ax"], md["taut"]["Az"]) == TAUT and md["params"] == p
    md_runs = {"slack": md["runs"], "taut": md["taut"]["runs"]}
    lim = md["dtM_max_stable_N50"]
    res = dict(
        code="phsplit", phsplit_version=metadata.version("phsplit"),
        moordyn_version=md["moordyn_version"], moordyn_date=md["date"],
        date=subprocess.run(["date", "-u", "+%Y-%m-%dT%H:%M:%SZ"], capture_output=True,
                            text=True).stdout.strip(),
        machine=machine(), params=p, steps=STEPS, tolerance=TOL,
        convergence="h is converged when the run at h/2 changes the mean and the first "
                    "harmonic by < 0.1 % (change_at_half_step records (max-min)/2's too)",
        tension="segment_tension: the top segment's tension, EA (l - l0)/l0 (MoorDyn's "
                "GetLineFairTen, |T[N-1] + Td[N-1]| with BA = 0); phsplit's top_tension "
                "(the force on the top, with half a segment's weight) is in top_tension_mean",
        cases={})
    for name, amp in amps.items():
        out = dict(Ax=amp[0], Az=amp[1], N={})
        for n in NS:
            s = studies[name][str(n)]
            mdr = md_runs[name][str(n)]
            ph = next(r for r in s["runs"] if r["h"] == s["h_used"])
            s["vs_moordyn"] = dict(
                mean=rel(ph["T_mean"], mdr["T_mean"]),
                H1=rel(ph["H1_amp"], mdr["harmonics"]["H1_amp"]),
                H2=rel(ph["H2_amp"], mdr["harmonics"]["H2_amp"]),
                amp=rel(ph["T_amp"], mdr["T_amp"]),
                T_top_initial=rel(ph["T_top_initial"], mdr["T_top_initial"]))
            s["moordyn"] = dict(dtM=mdr["dtM"], wall_s=mdr["wall_s"],
                                wall_init_s=mdr["wall_init_s"], T_mean=mdr["T_mean"],
                                T_amp=mdr["T_amp"], H1_amp=mdr["harmonics"]["H1_amp"],
                                H2_amp=mdr["harmonics"]["H2_amp"],
                                slack_fraction=mdr["slack_fraction"],
                                T_top_initial=mdr["T_top_initial"])
            out["N"][str(n)] = s
            print(f"{name} N={n}: vs MoorDyn {s['vs_moordyn']}", flush=True)
        res["cases"][name] = out
    all_runs = [r for c in res["cases"].values() for s in c["N"].values()
                for r in s["runs"] + [s["h1_run"]] if r["finite"]]
    res["energy_residual_rel_max"] = max(r["energy_residual_rel"] for r in all_runs)
    res["h1_all_finite"] = all(s["h1_run"]["finite"] for c in res["cases"].values()
                               for s in c["N"].values())
    res["script_wall_s"] = time.perf_counter() - t0
    (RES / "comparison.json").write_text(json.dumps(res, indent=1))
    write_md(res, md, lim)
    print(f"wrote {RES / 'comparison.json'} and comparison.md")


def write_md(res, md, lim):
    L = []
    m = res["machine"]
    L.append("# phsplit's lumped-mass pipe against MoorDyn\n")
    L.append(f"Date: {res['date']} (MoorDyn peer run: {res['moordyn_date']}). "
             f"Machine: {m['platform']}, CPU {m['cpu']} ({m['n_cpu']} logical CPUs), "
             f"Python {m['python']}. Versions: phsplit {res['phsplit_version']}, "
             f"MoorDyn {res['moordyn_version']} (the `moordyn` wheel, RK4).\n")
    p = res["params"]
    L.append(f"The line: L = {p['L']:g} m, d = {p['d']:g} m, mu = {p['mu']:g} kg/m, "
             f"EA = {p['EA']:.3g} N, BA = {p['BA']:g}, Cd = {p['Cd']:g}, CdAx = {p['CdAx']:g}, "
             f"Ca = CaAx = {p['Ca']:g}, kbot = {p['kbot']:.3g} Pa/m, cbot = {p['cbot']:.3g} "
             f"Pa s/m, depth {p['depth']:g} m, anchor {p['anchor']}, fairlead mean "
             f"{p['fairlead']}; top motion x = Ax sin(2 pi t/{p['T']:g}), z = -10 + Az sin(...), "
             f"ramp 0.5(1 - cos(pi t/{p['t_ramp']:g})) over {p['t_ramp']:g} s, t in [0, "
             f"{p['t_end']:g}] s. Statistics of the top segment's tension (MoorDyn's "
             f"GetLineFairTen; phsplit's `segment_tension`) over t in {p['window']} s, "
             f"harmonics by the same trapezoidal Fourier integrals over each code's own "
             f"samples (every step).\n")
    L.append("Step used: MoorDyn, the smallest dtM of its N = 50 halving (converged to 0.1 % "
             "where stated) scaled by 50/N; phsplit, the largest h whose halving changes the mean "
             "and the first harmonic by < 0.1 %, else the smallest h run ('not conv.'); "
             "(max-min)/2 is reported at that step and does not converge to 0.1 % in either code "
             "(it samples the undamped axial ringing: MoorDyn's halving still changes it by "
             "0.4 % (taut) and 6 % (slack) at its smallest step, phsplit's by 0.1-5 % (taut) "
             "in the sweep below). MoorDyn's stability limit is measured at N = 50 "
             "(bisection, 100 s runs); at N = 25 and 100 it is the same CFL limit scaled by "
             "50/N, not measured. Wall times: the time stepping alone (MoorDyn: without its "
             "initial-condition solve, given apart; phsplit: `drive`, its static solve "
             "included). Differences: phsplit / MoorDyn - 1 at the same N.\n")
    hdr = ("| case | code | N | step used | stability limit | wall [s] | mean [kN] | "
           "H1 [kN] | H2 [kN] | (max-min)/2 [kN] | slack | d mean | d H1 | d H2 | "
           "d (max-min)/2 |")
    L.append(hdr)
    L.append("|" + "---|" * (hdr.count("|") - 1))
    for name, c in res["cases"].items():
        for n, s in c["N"].items():
            mdr = s["moordyn"]
            n_ = int(n)
            stab = (f"{lim['stable'] * 1e3:.2f} ms (measured)" if n_ == 50 else
                    f"~{lim['stable'] * 1e3 * 50 / n_:.2f} ms (scaled)")
            conv = (md["dtM_converged_N50"] if name == "slack"
                    else md["taut"]["dtM_converged_N50"])["converged"]
            L.append(f"| {name} | MoorDyn | {n} | {fmt_h(mdr['dtM'])}"
                     f"{'' if conv else ' (not conv.)'} | {stab} | {mdr['wall_s']:.2f} "
                     f"(+{mdr['wall_init_s']:.1f} IC) | {fmt_k(mdr['T_mean'])} | "
                     f"{fmt_k(mdr['H1_amp'])} | {fmt_k(mdr['H2_amp'])} | "
                     f"{fmt_k(mdr['T_amp'])} | {100 * mdr['slack_fraction']:.0f} % | | | | |")
            ph = next(r for r in s["runs"] if r["h"] == s["h_used"])
            hmax = max(r["h"] for r in s["runs"] if r["finite"])
            stab = ("none found up to 1 s" if s["h1_run"]["finite"]
                    else f"none found up to {hmax:g} s; h = 1 s: Newton fails")
            d = s["vs_moordyn"]
            L.append(f"| {name} | phsplit | {n} | {fmt_h(s['h_used'])}"
                     f"{'' if s['converged'] else ' (not conv.)'} | {stab} | "
                     f"{ph['wall_s']:.2f} | {fmt_k(ph['T_mean'])} | {fmt_k(ph['H1_amp'])} | "
                     f"{fmt_k(ph['H2_amp'])} | {fmt_k(ph['T_amp'])} | "
                     f"{100 * ph['slack_fraction']:.0f} % | {fmt_pct(d['mean'])} | "
                     f"{fmt_pct(d['H1'])} | {fmt_pct(d['H2'])} | "
                     f"{fmt_pct(d['amp']) if name == 'taut' else '(not converged)'} |")
    L.append("")
    L.append(f"phsplit's energy closes per step: max |diff(storage) - (top_work + current - "
             f"drag - axial_damping - seabed)| / max|storage| = "
             f"{res['energy_residual_rel_max']:.2e} over every step of every run "
             f"(h from 1 s down). All h = 1 s runs completed with finite tensions: "
             f"{res['h1_all_finite']}.\n")
    for name, c in res["cases"].items():
        for n, s in c["N"].items():
            for r in s["runs"] + [s["h1_run"]]:
                if "failed" in r:
                    L.append(f"- {name}, N = {n}, h = {r['h']:g} s: {r['failed']}\n")
    L.append("## phsplit's step sweep (N = 50)\n")
    L.append("| case | h | wall [s] | mean [kN] | H1 [kN] | H2 [kN] | (max-min)/2 [kN] | "
             "slack | change of mean / H1 / (max-min)/2 at h/2 |")
    L.append("|---|---|---|---|---|---|---|---|---|")
    for name, c in res["cases"].items():
        s = c["N"]["50"]
        for r in s["runs"] + [s["h1_run"]]:
            ch = r.get("change_at_half_step")
            chs = "–" if not ch else (f"{100 * ch['mean']:.3f} % / {100 * ch['H1']:.3f} % / "
                                      f"{100 * ch['amp']:.2f} %")
            L.append(f"| {name} | {fmt_h(r['h'])} | {r['wall_s']:.3f} | {fmt_k(r.get('T_mean'))} | "
                     f"{fmt_k(r.get('H1_amp'))} | {fmt_k(r.get('H2_amp'))} | "
                     f"{fmt_k(r.get('T_amp'))} | {100 * r.get('slack_fraction', 0):.0f} % | "
                     f"{chs} |")
    L.append("")
    (RES / "comparison.md").write_text("\n".join(L) + "\n")


if __name__ == "__main__":
    main()
