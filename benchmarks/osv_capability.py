"""DP capability of the OSV preset with its own thrusters (the shipped ``osv-capability``
scenario; docs/how-to/dp-capability.md), intact and with each single failure, and the
time-domain check of its limits (``phsplit.capability.hold``): the worst single failure's limit
and the intact limit from the beam (the level-1 table extended by one row), each held at the
limit and 10 % beyond it. Prints and writes benchmarks/results/osv_capability.md and the polar
plot docs/figures/osv-capability.png. Usage: ``python benchmarks/osv_capability.py``."""
from __future__ import annotations

import datetime
import platform
import tempfile
from pathlib import Path

import numpy as np

import phsplit
from phsplit.capability import LEVEL1, hold, polar_plot

ROOT = Path(__file__).resolve().parent.parent
WATCH_CIRCLE = 5.0  # m


def atomic_write(path: Path, text: str) -> None:
    with tempfile.NamedTemporaryFile("w", dir=path.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    Path(f.name).replace(path)


def main() -> None:
    sc = phsplit.load_scenario("osv-capability")
    v = sc.vessel
    ds = phsplit.capability(v)
    png = ROOT / "docs" / "figures" / "osv-capability.png"
    tmp = png.with_suffix(".tmp.png")
    polar_plot(ds, str(tmp), title="osv-capability: static DP capability (DNV-ST-0111 level 1 style)")
    tmp.replace(png)
    u = ds["wind_speed_limit"].values
    top = ds["at_table_top"].values
    lines = ["# DP capability of the OSV (osv-capability)", "",
             f"{datetime.date.today()}, {platform.machine()} {platform.system()}, phsplit {phsplit.__version__}; "
             "`python benchmarks/osv_capability.py`", "",
             "Static limits every 10 degrees (level-1 table, drift included):", "",
             "| case | smallest limit (m/s) | from (deg) | Beaufort | directions at the table's top |",
             "|---|---|---|---|---|"]
    for j, name in enumerate(ds["case_name"].values):
        k = int(u[:, j].argmin())
        lines.append(f"| {name} | {u[k, j]:.2f}{' (table top)' if top[k, j] else ''} | {float(ds.direction[k]):.0f} | "
                     f"{int(ds['beaufort_limit'][k, j])} | {int(top[:, j].sum())} of {len(ds.direction)} |")
    worst = np.where(top, np.inf, u)
    i, j = np.unravel_index(np.argmin(worst), u.shape)
    d, lost = float(ds.direction[i]), [int(str(ds["case_name"].values[j]).split()[1])]
    env = [list(r) for r in LEVEL1] + [[12, 60.0, LEVEL1[-1][2], LEVEL1[-1][3], LEVEL1[-1][4]]]
    intact = phsplit.capability(v, directions=[90.0], failures="none", environment=env, tolerance=1e-3)
    ui = float(intact["wind_speed_limit"].values[0, 0])
    lines += ["", f"Time domain (`hold`, 1200 s, sp2, h = 0.5 s; mean loads, integral states balanced at the start; "
              f"watch circle {WATCH_CIRCLE:g} m):", "",
              "| case | from (deg) | wind (m/s) | of the limit | max excursion (m) | at the end (m) | max utilisation |",
              "|---|---|---|---|---|---|---|"]
    lim = phsplit.capability(v, directions=[d], failures=[lost], tolerance=1e-3)
    uw = float(lim["wind_speed_limit"].values[0, 1])
    for name, dd, ul, lo, e in ((f"thruster {lost[0]} lost", d, uw, lost, LEVEL1),
                                ("intact (table + 60 m/s row)", 90.0, ui, [], env)):
        for f in (1.0, 1.1):
            sol, r = hold(v, dd, f * ul, lost=lo, environment=e)
            lines.append(f"| {name} | {dd:.0f} | {f * ul:.2f} | {f:.0%} | {r.max():.3f} | {r[-1]:.3f} | "
                         f"{sol.outputs['thrust_utilisation'][2].max():.3f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    atomic_write(ROOT / "benchmarks" / "results" / "osv_capability.md", text)


if __name__ == "__main__":
    main()
