"""Cummins' fluid memory of the shipped Capytaine box (paper_box_capytaine.nc, the dp-weather
dataset) on the paper's vessel: the fit report, the passivity check, and the regular-wave
response in the time domain against the frequency-domain RAO of the same dataset
(docs/explanation/components/fluid-memory.md).

    .venv/bin/python scripts/fluid_memory.py            # fit report, passivity, RAO table
    .venv/bin/python scripts/fluid_memory.py --figure   # and docs/figures/fluid_memory_rao.png

The time-domain vessel: the paper's (mass, inertia, linear damping D and restoring C of its
App. D), its added mass A∞ (Capytaine's infinite-frequency added mass of the box, moved to the
centre of gravity), and the memory as the subsystem ``radiation``; controller off, one regular
wave of 0.1 m, SP4 at h = 0.5 s for 600 s; the amplitudes by a least-squares sinusoid over the
last ten periods. The reference: ξ = [−ω²(M + A(ω)) + iω(B(ω) + D) + C]⁻¹ F(ω) (Fossen 2021,
ch. 5: the frequency-domain equation of motion), with A, B, F the dataset's at the dataset's own
frequencies (no interpolation)."""
from __future__ import annotations

import math
import os
import sys
import time

import numpy as np
import phsplit
from phsplit import radiation, seakeeping
from phsplit.seakeeping import frequency_rao, waves_table

HERE = os.path.dirname(os.path.abspath(__file__))
DATASET = os.path.join(HERE, "..", "python", "src", "phsplit", "scenarios", "paper_box_capytaine.nc")
#: Dataset frequencies in 0.4–1.5 rad/s (the roll resonance 0.56, the heave resonance 1.04) and the two headings (degrees, relative to the bow:
#: 90 = beam seas, 180 = head seas).
OMEGAS = (0.44, 0.56, 0.68, 1.04, 1.4)
DIRECTIONS = (90.0, 180.0)
AMPLITUDE = 0.1       # m
T_END, STEP = 600.0, 0.5


def time_rao(vessel_with_memory, waves_table, omega: float, direction: float, h: float = STEP,
             t_end: float = T_END, amplitude: float = AMPLITUDE):
    """Heave (m/m), roll and pitch (rad/m) amplitudes after the transients, and the solution
    (phsplit.seakeeping.time_rao)."""
    got, s = seakeeping.time_rao(vessel_with_memory, waves_table, omega, direction, amplitude=amplitude, h=h,
                                 t_end=t_end, dofs=("heave", "roll", "pitch"))
    return np.abs([got["heave"], got["roll"], got["pitch"]]), s


def passivity(fm, omega=None) -> float:
    """min over a dense grid of the smallest eigenvalue of Re K(iω), relative to the largest."""
    omega = np.geomspace(1e-3, 1e3, 20001) if omega is None else omega
    F = fm.transfer(omega).real
    ev = np.linalg.eigvalsh(0.5 * (F + np.transpose(F, (0, 2, 1))))
    return float(ev.min() / np.abs(ev).max())


def main(figure: bool = False) -> None:
    base = phsplit.Vessel.paper()
    t0 = time.perf_counter()
    fm = radiation.fluid_memory(DATASET, vessel=base)
    vessel = radiation.with_fluid_memory(base, DATASET, memory=fm)
    t_fit = time.perf_counter() - t0
    print(f"fit: {fm.n_states} states, {t_fit:.1f} s; A_inf: {fm.a_inf_source}")
    print(fm.report_table())
    print("dropped couplings (largest |K_ab| / sqrt(max|K_aa| max|K_bb|)):",
          ", ".join(f"{k} {v:.1e}" for k, v in fm.dropped.items()))
    for g, bl in fm.blocks.items():
        print(f"  {g}: " + "; ".join(f"{kd} (" + ", ".join(f"{x:.4g}" for x in p) + ")" for kd, p in bl))
    print(f"passivity: min eig Re K(iw) / max |eig| over 1e-3..1e3 rad/s (20001 points) = {passivity(fm):.3e}")
    wt = waves_table(base)
    rows = ["| heading | ω (rad/s) | DOF | frequency domain | time domain | deviation | ≥ 5 % of peak |",
            "|---|---|---|---|---|---|---|"]
    results = []
    t_sim = 0.0
    for beta in DIRECTIONS:
        ref = {w: np.abs(frequency_rao(base, w, beta)[[2, 3, 4]]) for w in OMEGAS}
        peak = np.max([ref[w] for w in OMEGAS], axis=0)
        for w in OMEGAS:
            t1 = time.perf_counter()
            got, sol = time_rao(vessel, wt, w, beta)
            t_sim += time.perf_counter() - t1
            res = sol.ledger.relative_residual().max()
            rad = sol.ledger.by_account["radiation"].sum()
            for k, dof in enumerate(("heave", "roll", "pitch")):
                # a DOF the heading does not excite (zero by the hull's symmetry) has no peak
                significant = peak[k] > 1e-6 and ref[w][k] >= 0.05 * peak[k]
                dev = got[k] / ref[w][k] - 1 if ref[w][k] > 0 else float("nan")
                unit = "m/m" if dof == "heave" else "deg/m"
                f = 1.0 if dof == "heave" else 180 / math.pi
                results.append((beta, w, dof, ref[w][k], got[k], dev, significant))
                if peak[k] > 1e-6:
                    rows.append(f"| {'beam' if beta == 90 else 'head'} | {w:.2f} | {dof} | {f * ref[w][k]:.4g} {unit} | "
                                f"{f * got[k]:.4g} {unit} | {100 * dev:+.2f} % | {'yes' if significant else 'no'} |")
            print(f"  {beta:g} deg {w:.2f} rad/s: ledger residual {res:.1e}, radiation booked {rad:.4g} J")
    print(f"time-domain runs: {len(DIRECTIONS) * len(OMEGAS)} x {T_END:g} s at h = {STEP} s (SP4), {t_sim:.1f} s in all")
    print("\n".join(rows))
    bad = [r for r in results if r[6] and abs(r[5]) > 0.05]
    print(f"beyond 5 %: {len(bad)}" + "".join(f"; {r[0]:g} deg {r[1]} rad/s {r[2]} {100 * r[5]:+.1f} %" for r in bad))
    if figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        wf = np.asarray(radiation.retardation_data(DATASET, vessel=base)[0])
        wf = wf[(wf >= 0.3) & (wf <= 1.8)]
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True)
        for ax, beta in zip(axes, DIRECTIONS):
            curves = np.array([np.abs(frequency_rao(base, w, beta)[[2, 3, 4]]) for w in wf])
            for k, (dof, col) in enumerate((("heave (m/m)", "C0"), ("roll (deg/m)", "C1"), ("pitch (deg/m)", "C2"))):
                f = 1.0 if k == 0 else 180 / math.pi
                if np.max(curves[:, k]) < 1e-6:
                    continue
                ax.plot(wf, f * curves[:, k], "-", color=col, label=f"{dof}, frequency domain")
                pts = [(r[1], r[4]) for r in results if r[0] == beta and r[2] == dof.split()[0]]
                ax.plot([p[0] for p in pts], [f * p[1] for p in pts], "o", color=col, label=f"{dof}, time domain")
            ax.set_title(f"{'beam' if beta == 90 else 'head'} seas ({beta:g} deg)")
            ax.set_xlabel("ω (rad/s)")
            ax.legend(fontsize=7)
        out = os.path.join(HERE, "..", "docs", "figures", "fluid_memory_rao.png")
        fig.savefig(out, dpi=110)
        print(f"wrote {os.path.normpath(out)}")


if __name__ == "__main__":
    main(figure="--figure" in sys.argv)
