"""The cost of one SP2 step of the paper's vessel in the shipped ``dp-weather`` sea (waves, gusts,
current) against the same step in calm water (the same vessel file without its ``[waves]`` and
``[wind]`` tables), with the ledger and the controller on, h = 0.5 s.

Two measures of the same steps, taken in one run: the instructions per step counted by
valgrind's callgrind (deterministic: the difference between runs of ``--steps`` and of
``--steps / 2`` steps, so the setup cancels), and the wall-clock time per step (the median of
``--rounds`` alternating runs of ``--wall-steps`` steps). Build the example first:

    cargo build --release -p phsplit-core --example sea_steps
    .venv/bin/python benchmarks/sea_cost.py [--out benchmarks/results/sea_cost.md]

The sea's run is also measured with S2 by two Gauss stages (``linear_flow = "gauss4"``), and
both with S1 outermost (``outer = "conservative"``).
"""
from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

import phsplit

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "target", "release", "examples", "sea_steps")


def vessel_files(d: str) -> dict[str, str]:
    """The scenario's vessel in its sea, the same vessel in calm water, and in the mean wind
    alone (no gusts, no waves: what flow S2's collocation costs without the sea's sums)."""
    sc = phsplit.scenario.load("dp-weather")
    tables = sc.vessel.to_dict()
    calm = {k: v for k, v in tables.items() if k not in ("waves", "wind")}
    wind = {k: v for k, v in tables["wind"].items() if not k.startswith("gust_")}
    mean_wind = {**calm, "wind": wind}
    out = {}
    for name, text in (("weather", sc.vessel.to_toml()), ("calm", phsplit.Vessel.from_dict(calm).to_toml()),
                       ("mean_wind", phsplit.Vessel.from_dict(mean_wind).to_toml())):
        p = os.path.join(d, f"{name}.toml")
        with open(p, "w") as f:
            f.write(text)
        out[name] = p
    return out


def instructions(exe: str, path: str, steps: int, d: str, flow: list[str]) -> int:
    """Instructions callgrind counts for a run of ``steps`` steps (setup included)."""
    f = os.path.join(d, f"cg.{os.path.basename(path)}.{steps}.{''.join(flow)}")
    subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={f}", exe, path, "0.5", str(steps), *flow],
                   check=True, capture_output=True)
    with open(f) as fh:
        for line in fh:
            if line.startswith("summary:"):
                return int(line.split()[1])
    sys.exit(f"no summary in {f}")


def wall(exe: str, path: str, steps: int, flow: list[str]) -> float:
    """Microseconds per step the example reports."""
    p = subprocess.run([exe, path, "0.5", str(steps), *flow], check=True, capture_output=True, text=True)
    return float(re.search(r": ([0-9.]+) us per step", p.stdout)[1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--exe", default=EXE)
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--wall-steps", type=int, default=7200)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--out")
    args = ap.parse_args()
    if shutil.which("valgrind") is None:
        sys.exit("valgrind is needed for the instruction counts")
    with tempfile.TemporaryDirectory() as d:
        files = vessel_files(d)
        # (file, flow S2): each with the core's flow (exact where it acts, else Gauss of the
        # method's order, one stage for SP2), and the sea with two stages (linear_flow "gauss4",
        # what "auto" takes for SP2 at fixed steps in a sea).
        runs = {name: (p, []) for name, p in files.items()}
        runs["weather_gauss4"] = (files["weather"], ["gauss4"])
        # S1 outermost (outer "conservative"): one S2 a step; the sea with one and three stages
        # (three: the workloads' fastest setting to 1 cm in dp-weather).
        runs["calm_s1"] = (files["calm"], ["exact", "conservative"])
        runs["weather_s1"] = (files["weather"], ["gauss", "conservative"])
        runs["weather_gauss6_s1"] = (files["weather"], ["gauss6", "conservative"])
        per_step = {}
        for name, (p, flow) in runs.items():
            n1, n2 = args.steps // 2, args.steps
            per_step[name] = (instructions(args.exe, p, n2, d, flow) - instructions(args.exe, p, n1, d, flow)) / (n2 - n1)
        times: dict[str, list[float]] = {k: [] for k in runs}
        for _ in range(args.rounds):
            for name, (p, flow) in runs.items():
                times[name].append(wall(args.exe, p, args.wall_steps, flow))
    med = {k: statistics.median(v) for k, v in times.items()}
    text = (
        f"Measured {datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')} on "
        f"{platform.machine()} ({platform.processor() or platform.platform()}, {os.cpu_count()} cores); "
        f"`python benchmarks/sea_cost.py` with {args.exe}.\n\n"
        "One SP2 step (h = 0.5 s, ledger, controller on) of the paper's vessel in dp-weather's sea "
        "(150 wave components with drift, 100 gust components, current) and in calm water "
        "(the same vessel file without [waves] and [wind]); "
        "mean wind only: the same vessel with the wind's mean load but no gusts and no waves. "
        "Flow S2: exact in calm water, Gauss of the method's order (one stage) with a forcing; "
        "dp-weather (gauss4): two stages, what linear_flow = \"auto\" takes for SP2 at fixed steps in a sea.\n\n"
        "| | calm | mean wind only | dp-weather | dp-weather (gauss4) | dp-weather / calm | mean wind / calm |\n"
        "|---|---|---|---|---|---|---|\n"
        f"| instructions per step (callgrind, {args.steps // 2} steps' difference) | {per_step['calm']:.0f} | "
        f"{per_step['mean_wind']:.0f} | {per_step['weather']:.0f} | {per_step['weather_gauss4']:.0f} | "
        f"{per_step['weather'] / per_step['calm']:.2f} | {per_step['mean_wind'] / per_step['calm']:.2f} |\n"
        f"| wall clock per step (µs, median of {args.rounds} alternating runs of {args.wall_steps} steps) | "
        f"{med['calm']:.2f} | {med['mean_wind']:.2f} | {med['weather']:.2f} | {med['weather_gauss4']:.2f} | "
        f"{med['weather'] / med['calm']:.2f} | {med['mean_wind'] / med['calm']:.2f} |\n"
        f"\nWall-clock runs (µs per step): calm {', '.join(f'{x:.2f}' for x in times['calm'])}; "
        f"mean wind {', '.join(f'{x:.2f}' for x in times['mean_wind'])}; "
        f"dp-weather {', '.join(f'{x:.2f}' for x in times['weather'])}; "
        f"dp-weather (gauss4) {', '.join(f'{x:.2f}' for x in times['weather_gauss4'])}.\n"
        "\nThe same steps with S1 outermost (outer = \"conservative\": S1 half steps around one S2 "
        "over the whole step); flow S2 exact in calm water, one Gauss stage in the sea, and three "
        "(gauss6, the workloads' fastest setting to 1 cm in dp-weather).\n\n"
        "| S1 outermost | calm | dp-weather | dp-weather (gauss6) | dp-weather / calm |\n"
        "|---|---|---|---|---|\n"
        f"| instructions per step | {per_step['calm_s1']:.0f} | {per_step['weather_s1']:.0f} | "
        f"{per_step['weather_gauss6_s1']:.0f} | {per_step['weather_s1'] / per_step['calm_s1']:.2f} |\n"
        f"| wall clock per step (µs) | {med['calm_s1']:.2f} | {med['weather_s1']:.2f} | "
        f"{med['weather_gauss6_s1']:.2f} | {med['weather_s1'] / med['calm_s1']:.2f} |\n"
    )
    print(text)
    if args.out:
        with open(args.out, "a") as f:
            f.write(text + "\n")


if __name__ == "__main__":
    main()
