"""Step costs of two builds of the core, measured in one run: criterion's vessel-step benches
(``crates/phsplit-core/benches/flows.rs``, group ``vessels``: one SP2 step of the paper's vessel
and of the OSV preset, exact and Gauss S2, with the ledger) of build A and build B, run in turn
``--rounds`` times so that both see the same machine, and the ratio B / A of the medians.

Build each tree's bench executable first (``cargo bench -p phsplit-core --bench flows
--no-run`` prints its path), then:

    python benchmarks/step_cost_ab.py A_EXE B_EXE [--rounds 3] [--out FILE.md]
"""
from __future__ import annotations

import argparse
import datetime
import platform
import re
import statistics
import subprocess
import sys

FILTER = "^(paper|osv): "
UNITS = {"ns": 1e-3, "µs": 1.0, "us": 1.0, "ms": 1e3, "s": 1e6}
LINE = re.compile(r"^(?P<name>\S.*?)\s+time:\s+\[\S+ \S+ (?P<est>[0-9.]+) (?P<unit>ns|µs|us|ms|s) ")


def measure(exe: str) -> dict[str, float]:
    """Criterion's estimate (µs per 1,000 steps, so ns per step) of each bench in the group."""
    p = subprocess.run([exe, "--bench", FILTER], capture_output=True, text=True, check=True)
    out: dict[str, float] = {}
    name = None
    for line in p.stdout.splitlines():
        m = LINE.match(line)
        if m:
            out[m["name"].strip()] = float(m["est"]) * UNITS[m["unit"]]
            continue
        if line and not line.startswith(" ") and "time:" not in line:
            name = line.strip()
        elif name and "time:" in line:
            est = re.search(r"\[\S+ \S+ ([0-9.]+) (ns|µs|us|ms|s) ", line)
            if est:
                out[name] = float(est[1]) * UNITS[est[2]]
    if not out:
        sys.exit(f"no measurement in the output of {exe}:\n{p.stdout[-2000:]}")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--out")
    args = ap.parse_args()
    runs: dict[str, dict[str, list[float]]] = {"a": {}, "b": {}}
    for r in range(args.rounds):
        for side, exe in (("a", args.a), ("b", args.b)):
            for k, v in measure(exe).items():
                runs[side].setdefault(k, []).append(v)
            print(f"round {r + 1}/{args.rounds}: {side} done", file=sys.stderr)
    rows = ["| bench (1,000 steps) | A median (µs) | B median (µs) | B / A | A runs | B runs |",
            "|---|---|---|---|---|---|"]
    for k in runs["a"]:
        a, b = statistics.median(runs["a"][k]), statistics.median(runs["b"].get(k, [float("nan")]))
        rows.append(f"| {k} | {a:.1f} | {b:.1f} | {b / a:.3f} | "
                    f"{', '.join(f'{x:.0f}' for x in runs['a'][k])} | {', '.join(f'{x:.0f}' for x in runs['b'][k])} |")
    head = (f"Measured {datetime.date.today().isoformat()} on {platform.machine()} "
            f"({platform.processor() or platform.platform()}), {args.rounds} alternating rounds; "
            f"A = {args.a}, B = {args.b}.\n\n")
    text = head + "\n".join(rows) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
