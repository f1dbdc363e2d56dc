"""The driven lumped-mass pipe against a stored MoorDyn peer result.

The peer result is benchmarks/results/pipe/moordyn.json, written by benchmarks/pipe_moordyn.py
with MoorDyn 2.7.2 (the ``moordyn`` wheel's Python API, RK4, ``Step`` called every dtM with the
fairlead a "Coupled" point at the exact prescribed position and velocity; initial state from
MoorDyn's catenary and its stationary IC solve): one line (L = 600 m, d = 0.3 m, mu = 120 kg/m,
EA = 3e9 N, BA = 0, Cd 1.2, CdAx 0.008, Ca = CaAx = 1, kbot 3e6, cbot 3e5, depth 200 m, anchor
(-539, 0, -200)) with its top moved about (0, 0, -10) by x = Ax sin(2 pi t/10),
z = -10 + Az sin(2 pi t/10), ramped over 20 s; two cases, "slack" (Ax = 2, Az = 1 m, the top
segment slack ~44 % of the time) and "taut" (Ax = 0.5, Az = 0.25 m). MoorDyn's converged run at
N = 50 (its smallest dtM) gives the mean and the first harmonic at the forcing period of the top
segment's tension (GetLineFairTen) over t in [50, 100] s, and in the taut case (max - min)/2.

phsplit's ``pipe.drive`` at N = 50 must match them within 5 %: the taut case at h = 20 ms
(converged: halving changes mean and first harmonic by < 0.01 %), the slack case at
h = 0.625 ms (the snap loads need the axial waves resolved; its halving changes mean and first
harmonic by 0.17 % and 0.16 %, and further halvings keep wandering by 0.1-0.3 %, as MoorDyn's
do: benchmarks/results/pipe/comparison.md, written by benchmarks/pipe_vs_moordyn.py).
The statistics are those of pipe_moordyn.py (trapezoidal Fourier integrals over the samples).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

import phsplit

MD = Path(__file__).resolve().parents[2] / "benchmarks" / "results" / "pipe" / "moordyn.json"
STEP = {"slack": 0.000625, "taut": 0.02}
N = 50
TOL = 0.05


@pytest.fixture(scope="module")
def md():
    if not MD.exists():
        pytest.skip(f"no stored MoorDyn result at {MD}")
    d = json.loads(MD.read_text())
    if "taut" not in d:
        pytest.skip("the stored MoorDyn result has no taut case")
    return d


def vessel(p):
    tables = phsplit.Vessel.preset("paper").to_dict()
    assert tables["vessel"]["gravity"] == p["g"] and tables["vessel"]["water_density"] == p["rho_w"]
    # at the origin, upright: the hang-off point (MoorDyn's fairlead) is where the drive starts
    tables["initial"].update(position=[0.0, 0.0, 0.0], euler=[0.0, 0.0, 0.0])
    tables["pipe"] = dict(model="lumped_mass", length=p["L"], segments=N, axial_stiffness=p["EA"],
                          mass=p["mu"], diameter=p["d"], water_depth=p["depth"],
                          hang_off=list(p["fairlead"]), anchor=p["anchor"][:2], drag_normal=p["Cd"],
                          drag_tangential=p["CdAx"], added_mass=p["Ca"], seabed_stiffness=p["kbot"],
                          seabed_damping=p["cbot"])
    return phsplit.Vessel.from_dict(tables)


def stats(p, t, T):
    m = (t >= p["window"][0] - 1e-9) & (t <= p["window"][1] + 1e-9)
    tw, Tw = t[m], T[m]
    om = 2 * math.pi / p["T"]
    c = 2 * np.trapezoid(Tw * np.cos(om * tw), tw) / (tw[-1] - tw[0])
    s = 2 * np.trapezoid(Tw * np.sin(om * tw), tw) / (tw[-1] - tw[0])
    return Tw.mean(), math.hypot(c, s), 0.5 * (Tw.max() - Tw.min())


@pytest.mark.parametrize("case", ["slack", "taut"])
def test_drive_matches_moordyn(md, case):
    p = md["params"]
    ax, az = (p["Ax"], p["Az"]) if case == "slack" else (md["taut"]["Ax"], md["taut"]["Az"])
    ref = (md["runs"] if case == "slack" else md["taut"]["runs"])[str(N)]
    h = STEP[case]
    t = np.arange(int(round(p["t_end"] / h)) + 1) * h
    ramp = np.where(t < p["t_ramp"], 0.5 * (1 - np.cos(np.pi * t / p["t_ramp"])), 1.0)
    s = np.sin(2 * np.pi * t / p["T"])
    x0, y0, z0 = p["fairlead"]
    tops = np.column_stack([x0 + ramp * ax * s, y0 + 0 * t, z0 + ramp * az * s])
    r = phsplit.pipe.drive(vessel(p), t, tops)
    mean, h1, amp = stats(p, t, r["segment_tension"])
    got = {"mean": mean, "H1": h1}
    want = {"mean": ref["T_mean"], "H1": ref["harmonics"]["H1_amp"]}
    if case == "taut":
        got["(max-min)/2"], want["(max-min)/2"] = amp, ref["T_amp"]
    bad = {k: (got[k], want[k]) for k in got if abs(got[k] / want[k] - 1) > TOL}
    assert not bad, f"{case}: phsplit vs MoorDyn (N, {N}), h {h}: {bad}"
