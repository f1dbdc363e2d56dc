"""Writes the Performance page (docs/performance.md runs it during the build) from the files
that `make bench` leaves in benchmarks/results/: the current figures, never copied by hand."""
from __future__ import annotations

import json
import re
from pathlib import Path

RESULTS = Path("benchmarks/results")


def _markdown(path: Path, level: int = 2) -> str:
    """A results summary as a section of the page: its title dropped, its headings moved down
    to ``level``, its images (which stay in benchmarks/results/) named instead of shown, and
    the targets named for what they are."""
    out = []
    for line in path.read_text().splitlines():
        if line.startswith("# "):
            continue
        m = re.match(r"^(#+) (.*)$", line)
        if m:
            line = "#" * (len(m.group(1)) + level - 2) + " " + m.group(2)
        img = re.match(r"^!\[[^\]]*\]\(([^)]+)\)$", line.strip())
        if img:
            line = f"(Plot: `{(path.parent / img.group(1)).as_posix()}`.)"
        line = re.sub(r"[Ii]ssue \d+'s targets", "Speed-up targets", line)
        line = line.replace("(the issue asks ≥ 1×, with 3× as the goal beyond it)",
                            "(the target is ≥ 1×, with 3× as the goal beyond it)")
        out.append(line)
    return "\n".join(out).strip() + "\n"


def _json_tables() -> str:
    parts = []
    gv = json.loads((RESULTS / "general_vessel.json").read_text())
    parts.append("### One step of a general vessel (`benchmarks/general_vessel.py`)\n")
    parts.append("| vessel | method | S2 | ledger | projection | µs per step |\n|---|---|---|---|---|---|")
    for r in gv["per_step"]:
        parts.append(f"| {r['vessel']} | {r['method']} | {r['linear_flow']} | {'on' if r['ledger'] else 'off'} | "
                     f"{'off' if r.get('project') is False else 'on'} | {r['us_per_step']:.2f} |")
    parts.append(f"\nOSV in DP over {gv['t_end']:.0f} s: RK4 stable up to h = {gv['rk4_stable_up_to_s']} s, "
                 f"diverges at {gv['rk4_diverges_at_s']} s.\n")
    fm = json.loads((RESULTS / "fmu_speed.json").read_text())
    parts.append(f"### The FMU (`benchmarks/fmu_speed.py`): {fm['method']} at h = {fm['h']} s, "
                 f"communication step {fm['communication_step']} s, {fm['t_end']:.0f} s\n")
    parts.append("| how | s | µs per step |\n|---|---|---|")
    for k, s in fm["seconds"].items():
        parts.append(f"| {k} | {s:.2f} | {fm['microseconds_per_step'][k]:.0f} |")
    ws = json.loads((RESULTS / "weather_stability.json").read_text())
    parts.append(f"\n### dp-weather over {ws['t_end']:.0f} s (`benchmarks/weather_stability.py`)\n")
    parts.append("| method | h [s] | stable | s |\n|---|---|---|---|")
    for r in ws["fixed_step"]:
        parts.append(f"| {r['method']} | {r['h']} | {r['stable']} | {r['seconds']:.2f} |")
    parts.append("\nLargest stable step: " + ", ".join(f"{k} {v:.2f} s" for k, v in ws["largest_stable_step"].items()) + ".\n")
    return "\n".join(parts) + "\n"


def render() -> str:
    return "\n".join([
        "## Time to accuracy on the users' workloads\n",
        _markdown(RESULTS / "workloads.md", 3),
        "## The default flow S2 and the energy accuracy\n",
        _markdown(RESULTS / "energy_accuracy.md", 3),
        "## Work per step, work-precision, stability and memory: the paper's scheme\n",
        _markdown(RESULTS / "summary.md", 3),
        "## The same with the default projection\n",
        _markdown(RESULTS / "projected" / "summary.md", 3),
        "## Sweep throughput\n",
        _markdown(RESULTS / "sweep_throughput.md", 3),
        "### With the exact S2\n",
        _markdown(RESULTS / "sweep_throughput_exact.md", 4),
        "## The general vessel, the FMU and the weather\n",
        _json_tables(),
    ])
