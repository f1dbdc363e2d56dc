"""Wave filtering of the passive observer in the dp-weather scenario (docs/explanation/components/observer.md).

Runs the shipped ``dp-weather`` scenario twice over the same sea, wind and current: the
controller on the vessel's state (the paper's), and on the estimates of the observer
(``control.feedback = "observer"``, wave frequency 2π/Tp, the observer's model damping the
vessel's). Prints and writes (benchmarks/results/observer_wave_filtering.md) the controller's
force spectrum in the wave band (Welch, 0.45-1.3 rad/s, after a 300 s transient) in surge, sway
and yaw, the ratio in dB, and the horizontal position excursion (max, RMS; whole and below
0.35 rad/s), for two controllers, each the same in both runs: the paper's PID of dp-weather
(a bandwidth of 0.25 rad/s, stiff enough to damp the wave motion itself), and a PID placed for
an observer in the loop by Fossen's pole placement (Fossen 2021, §15.3: ``Kp = m ωn²``,
``Kd = 2ζωn m − d``, ``Ki = ωn Kp / 10``, with the vessel's mass matrix and damping; ωn 0.06
rad/s and ζ 0.9 in surge and sway, 0.1 rad/s and 1 in yaw). Usage:
``python benchmarks/observer_wave_filtering.py [--t-end 3600] [--bias-bandwidth W]``."""
from __future__ import annotations

import argparse
import datetime
import math
import platform
import tempfile
from pathlib import Path

import numpy as np
from scipy.signal import butter, filtfilt, welch

import phsplit
from phsplit import scenario

BAND = (0.45, 1.3)   # rad/s: the sea's spectrum (Tp 9 s, JONSWAP) above 5 % of its peak
LOW = 0.35           # rad/s: below the wave band


#: Pole placement (Fossen 2021, §15.3) in surge and sway, and in yaw: (ωn rad/s, ζ).
PLACED = {"surge_sway": (0.06, 0.9), "yaw": (0.1, 1.0)}


def placed_gains(d: dict, mass_matrix: np.ndarray) -> dict:
    """``Kp = m ωn²``, ``Kd = 2ζωn m − d`` (at least 0), ``Ki = ωn Kp / 10`` per DOF."""
    v = d["vessel"]
    out = {k: [0.0, 0.0, 0.0] for k in ("kp_translational", "kd_translational", "ki_translational",
                                         "kp_rotational", "kd_rotational", "ki_rotational")}
    for i, (kind, m, dmp) in enumerate([("surge_sway", mass_matrix[0, 0], v["damping_translational"][0]),
                                         ("surge_sway", mass_matrix[1, 1], v["damping_translational"][1]),
                                         ("yaw", mass_matrix[5, 5], v["damping_rotational"][2])]):
        wn, zeta = PLACED[kind]
        kp, kd = m * wn ** 2, max(2 * zeta * wn * m - dmp, 0.0)
        part, j = ("translational", i) if i < 2 else ("rotational", 2)
        out[f"kp_{part}"][j], out[f"kd_{part}"][j], out[f"ki_{part}"][j] = kp, kd, wn * kp / 10
    return out


def run(feedback: str, t_end: float, bias_bandwidth: float | None, controller: str = "paper"):
    sc = scenario.load("dp-weather")
    d = sc.vessel.to_dict()
    if controller == "placed":
        d["control"].update(placed_gains(d, sc.vessel.mass_matrix))
    if feedback == "observer":
        d["control"]["feedback"] = "observer"
        v = d["vessel"]
        d["observer"] = {"wave_frequency": 2 * math.pi / 9.0,
                         "damping": [v["damping_translational"][0], v["damping_translational"][1],
                                     v["damping_rotational"][2]]}
        if bias_bandwidth:
            d["observer"]["bias_bandwidth"] = bias_bandwidth
    vessel = phsplit.Vessel.from_dict(d)
    s = phsplit.simulate(vessel, (0.0, t_end), 0.5, "sp4", control_start=0.0, save_every=1)
    return s, np.array(d["control"]["position_reference"][:2])


def measure(s, ref):
    keep = s.t >= 300.0
    dt = s.t[1] - s.t[0]
    out = {}
    for name, sig in (("surge", s.control_force[keep, 0]), ("sway", s.control_force[keep, 1]),
                      ("yaw", s.control_moment[keep, 2])):
        f, p = welch(sig - sig.mean(), fs=1.0 / dt, nperseg=512)
        w = 2 * math.pi * f
        out[name] = float(p[(w >= BAND[0]) & (w <= BAND[1])].sum())
    x = s.x[keep, :2]
    d = np.hypot(x[:, 0] - ref[0], x[:, 1] - ref[1])
    b, a = butter(4, (LOW / (2 * math.pi)) / (0.5 / dt), "low")
    lf = np.column_stack([filtfilt(b, a, x[:, i]) for i in range(2)])
    dl = np.hypot(lf[:, 0] - ref[0], lf[:, 1] - ref[1])
    out.update(max=float(d.max()), rms=float(np.sqrt(np.mean(d ** 2))), lf_max=float(dl.max()),
               lf_rms=float(np.sqrt(np.mean(dl ** 2))))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=3600.0)
    ap.add_argument("--bias-bandwidth", type=float, default=None)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "observer_wave_filtering.md"))
    a = ap.parse_args()
    lines = [f"# Wave filtering of the passive observer, dp-weather ({a.t_end:.0f} s, sp4, h = 0.5 s)", "",
             f"{datetime.date.today()}, {platform.machine()} {platform.system()}, phsplit {phsplit.__version__}; "
             f"`python benchmarks/observer_wave_filtering.py --t-end {a.t_end:.0f}"
             + (f" --bias-bandwidth {a.bias_bandwidth}" if a.bias_bandwidth else "") + "`", ""]
    for controller, title in (("paper", "the paper's PID (dp-weather's gains)"),
                              ("placed", "a PID placed for the observer (Fossen 2021 §15.3: surge and sway "
                                         f"ωn {PLACED['surge_sway'][0]} rad/s ζ {PLACED['surge_sway'][1]}, yaw ωn "
                                         f"{PLACED['yaw'][0]} rad/s ζ {PLACED['yaw'][1]})")):
        true_state, ref = run("true_state", a.t_end, None, controller)
        observer, _ = run("observer", a.t_end, a.bias_bandwidth, controller)
        mt, mo = measure(true_state, ref), measure(observer, ref)
        lines += [f"## The same controller in both runs: {title}", "",
                  f"Controller force power in the wave band {BAND[0]}-{BAND[1]} rad/s (Welch, after 300 s):", "",
                  "| | true state | observer | drop |", "|---|---|---|---|"]
        for k in ("surge", "sway", "yaw"):
            lines.append(f"| {k} | {mt[k]:.3e} | {mo[k]:.3e} | {10 * math.log10(mt[k] / mo[k]):.1f} dB |")
        lines += ["", "Horizontal excursion from the set point (m):", "",
                  "| | true state | observer | ratio |", "|---|---|---|---|"]
        for k, label in (("max", "max"), ("rms", "RMS"), ("lf_max", f"max below {LOW} rad/s"),
                         ("lf_rms", f"RMS below {LOW} rad/s")):
            lines.append(f"| {label} | {mt[k]:.3f} | {mo[k]:.3f} | {mo[k] / mt[k]:.2f} |")
        lines.append("")
    text = "\n".join(lines)
    print(text)
    out = Path(a.out)
    with tempfile.NamedTemporaryFile("w", dir=out.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    Path(f.name).replace(out)


if __name__ == "__main__":
    main()
