#!/usr/bin/env python3
"""Write the mpmath reference table for the core's elliptic functions.

Output: crates/phsplit-core/tests/data/elliptic_ref.csv, one row per (function, argument, m),
with the arguments printed as round-trip doubles (`repr`) and the values evaluated by mpmath at
50 significant digits on exactly those doubles, then rounded once to the nearest double.

Run: python3 scripts/gen_elliptic_refs.py   (needs mpmath; `make elliptic-refs` does it in the venv)
"""
from __future__ import annotations

import csv
import math
import pathlib

import mpmath as mp

mp.mp.dps = 50
OUT = pathlib.Path(__file__).resolve().parent.parent / "crates/phsplit-core/tests/data/elliptic_ref.csv"

# The whole parameter range, with the ends approached geometrically.
M = [0.0, 1e-300, 1e-16, 1e-12, 1e-8, 1e-4, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999,
     1 - 1e-4, 1 - 1e-6, 1 - 1e-8, 1 - 1e-10, 1 - 1e-12, 1 - 1e-14, 1 - 2**-52, 1.0]
U = [-47.3, -20.0, -7.5, -3.0, -1.0, -0.25, -1e-9, 0.0, 1e-12, 1e-6, 0.125, 0.5, 1.0, 1.5, 2.0,
     3.0, 4.5, 6.0, 9.0, 13.0, 21.0, 33.3, 50.0]
PHI = [-9.0, -3.0, -1.5, -0.7, -1e-8, 0.0, 1e-10, 0.1, 0.5, 1.0, 1.2, 1.5, 1.5707, 2.0, 3.0,
       4.0, 7.0, 12.5]


def main() -> None:
    rows = []
    for m in M:
        mm = mp.mpf(m)
        for u in U:
            uu = mp.mpf(u)
            for name in ("sn", "cn", "dn"):
                rows.append((name, repr(u), repr(m), repr(float(mp.ellipfun(name, uu, m=mm)))))
        if m < 1.0:
            rows.append(("K", "0.0", repr(m), repr(float(mp.ellipk(mm)))))
        for phi in PHI:
            if m == 1.0 and abs(phi) >= math.pi / 2:
                continue  # F(phi | 1) is infinite or complex there
            rows.append(("F", repr(phi), repr(m), repr(float(mp.ellipf(mp.mpf(phi), mm)))))
    OUT.parent.mkdir(parents=True, exist_ok=True)
    with OUT.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["function", "x", "m", "value"])
        w.writerows(rows)
    print(f"wrote {len(rows)} reference values to {OUT}")


if __name__ == "__main__":
    main()
