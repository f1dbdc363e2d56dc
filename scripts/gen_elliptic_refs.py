#!/usr/bin/env python3
"""Write the mpmath reference tables for the core's elliptic functions.

Outputs (all under crates/phsplit-core/tests/data/), every argument printed as a round-trip
double (`repr`) and every value evaluated by mpmath at 60 significant digits on exactly those
doubles, checked against a second evaluation at 90 digits, then rounded once to the nearest
double:

* ``elliptic_ref.csv``: the original grid, ``m`` in [0, 1], ``|u| <= 50`` (function,x,m,value).
* ``jacobi_ref.csv``: sn, cn, dn (set,u,m,sn,cn,dn) at
  - the inputs of Boost.Math's published test tables ``jacobi_elliptic``,
    ``jacobi_elliptic_small``, ``jacobi_large_phi`` and ``jacobi_near_1`` (Boost tabulates
    ``(u, k)``; the parameter here is ``m = fl(k*k)``, so ``jacobi_near_1`` gives ``m > 1``);
  - an adversarial grid (set ``edge``): ``m`` from 0, 5e-324, 1e-300 ... through 1 - 1e-3 ...
    1 - 2**-53, 1 (and a few ``m < 0``, ``m > 1``), ``u`` from +-0 and subnormals to 1e15,
    including ``fl(n K(m))`` and its neighbours one ulp away, and the inputs of the edge cases (tests/exact_at_the_edges.rs).
* ``ellint_ref.csv``: K and F (set,function,phi,m,value,sensitivity) at the inputs of Boost.Math's
  ``ellint_k_data`` (``m = fl(k*k)``) and ``ellint_f_data`` (``(phi, m = fl(k*k))``), and an
  adversarial grid (set ``edge``). ``sensitivity`` is F's own conditioning limit: the largest
  change of F when ``phi`` or ``m`` moves one ulp (0 for K, whose argument is taken exact).

Only the *inputs* of the Boost tables are used; their values are recomputed here. The inputs are
read from a checkout of boostorg/math when ``--boost DIR`` (its ``test`` directory) is given, and
otherwise from the checked-in ``jacobi_ref.csv`` / ``ellint_ref.csv``, so a rerun reproduces the
tables without Boost.

Run: python3 scripts/gen_elliptic_refs.py [--boost PATH/TO/boost-math/test]
(needs mpmath; `make elliptic-refs` runs it in the venv).
"""
from __future__ import annotations

import argparse
import csv
import math
import pathlib
import re

import mpmath as mp

DPS, DPS_CHECK = 60, 90
DATA = pathlib.Path(__file__).resolve().parent.parent / "crates/phsplit-core/tests/data"

# ---------------------------------------------------------------- the original grid (m in [0, 1])
M = [0.0, 1e-300, 1e-16, 1e-12, 1e-8, 1e-4, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999,
     1 - 1e-4, 1 - 1e-6, 1 - 1e-8, 1 - 1e-10, 1 - 1e-12, 1 - 1e-14, 1 - 2**-52, 1.0]
U = [-47.3, -20.0, -7.5, -3.0, -1.0, -0.25, -1e-9, 0.0, 1e-12, 1e-6, 0.125, 0.5, 1.0, 1.5, 2.0,
     3.0, 4.5, 6.0, 9.0, 13.0, 21.0, 33.3, 50.0]
PHI = [-9.0, -3.0, -1.5, -0.7, -1e-8, 0.0, 1e-10, 0.1, 0.5, 1.0, 1.2, 1.5, 1.5707, 2.0, 3.0,
       4.0, 7.0, 12.5]

# ---------------------------------------------------------------- the adversarial grid
M_EDGE = [0.0, 5e-324, 1e-300, 1e-200, 1e-100, 1e-30, 1e-16, 2.0**-53, 1e-8, 1e-3, 0.1, 0.5,
          0.7, 0.9, 0.99, math.nextafter(0.999, 0.0), 0.999, 0.9990000000000001, 0.9995,
          0.9999, 1 - 1e-5, 1 - 1e-6, 1 - 1e-8, 1 - 1e-10, 1 - 1e-12, 1 - 1e-14,
          1 - 2.0**-52, 1 - 2.0**-53, 1.0]
# outside [0, 1]: supported through the reciprocal- and imaginary-modulus transformations
M_OUTSIDE = [-5e-324, -1e-300, -1e-8, -0.5, -1.0, -10.0, -1e6, 1.0 + 2.0**-52, 1.0000001,
             1.5, 4.0, 100.0]
U_EDGE = [0.0, -0.0, 5e-324, -5e-324, 1e-310, 1e-300, 1e-20, 1e-8, -1e-8, 2.0**-26, 1e-4, 0.1,
          0.5, -0.5, 1.0, 2.0, 3.0, -3.0, 7.5, 10.0, 20.0, 50.0, 100.0, 375.0, 625.0, 709.0,
          -709.0, 711.0, 1000.0, 3000.0, 1e4, 1e5, 1e6, 1e8, 1e10, 1e12, 1e15, -1e15]
U_OUTSIDE = [0.0, 1e-300, 1e-8, 0.5, -0.5, 1.0, 2.0, 3.0, 7.5, 20.0, 100.0, 1e4]
N_PERIODS = [1, 2, 3, 4, 5, 8, 101, 1001, 10**6 + 1, 10**12 + 3, 10**14 + 1]
# the edge-case inputs (tests/exact_at_the_edges.rs)
U_ISSUE = [(709.0, 0.9990000000000001), (605.1505233912122, 0.9999), (375.0, 0.9999),
           (625.0, 0.9999999999999999), (711.0, 0.9990000000000001), (1e15, 0.9999)]

PHI_EDGE = [0.0, 5e-324, 1e-300, 1e-8, 0.5, 1.0, 1.5, 1.5707, math.nextafter(math.pi / 2, 0.0),
            math.pi / 2, math.nextafter(math.pi / 2, 4.0), 2.0, 3.0, math.pi, 4.0, 7.0, 10.0,
            -3.0, 100.0, 1e4, -1e4, 1e8, 1e15]
M_F_EDGE = [m for m in M_EDGE] + [-1e-300, -0.5, -10.0, -1e6, -1e300]
M_K_EDGE = [m for m in M_EDGE if m < 1.0] + [-1e-300, -1e-8, -0.5, -1.0, -10.0, -1e6, -1e300]


def f2s(x: float) -> str:
    return repr(float(x))


def jacobi_mp(u: float, m: float) -> tuple:
    """(sn, cn, dn)(u | m) at the current mpmath precision, m any real."""
    uu, mm = mp.mpf(u), mp.mpf(m)
    if uu == 0:
        return (mp.mpf(0), mp.mpf(1), mp.mpf(1))
    if mm > 1:
        # reciprocal modulus (DLMF 22.17.2-4): sn(u|m) = sn(u sqrt m | 1/m)/sqrt m, cn <-> dn
        r = mp.sqrt(mm)
        v, mi = uu * r, 1 / mm
        return (mp.ellipfun("sn", v, m=mi) / r, mp.ellipfun("dn", v, m=mi),
                mp.ellipfun("cn", v, m=mi))
    return tuple(mp.ellipfun(k, uu, m=mm) for k in ("sn", "cn", "dn"))


def digits_for(x: float) -> int:
    """Extra digits for a tiny argument: mpmath's theta-function sums carry an absolute error
    near 10^-dps, so sn(1e-300) needs 300 more digits to come out to relative precision."""
    return 0 if x == 0.0 or abs(x) >= 1.0 else int(-math.log10(abs(x))) + 5


def checked(fn, *args):
    """fn(*args) at DPS, confirmed at DPS_CHECK to 1e-30 relative; returns real mpf values.
    The first argument sets the extra precision (see digits_for); a value with an imaginary
    part is an error (the input is outside the real domain)."""
    extra = digits_for(args[0])
    with mp.workdps(DPS + extra):
        a = fn(*args)
    with mp.workdps(DPS_CHECK + extra):
        b = fn(*args)
    single = not isinstance(a, tuple)
    a, b = ((a,), (b,)) if single else (a, b)
    out = []
    for x, y in zip(a, b):
        if abs(mp.im(y)) > mp.mpf(10) ** (-30) * abs(y):
            raise ValueError(f"complex value at {args}: {y}")
        x, y = mp.re(x), mp.re(y)
        if abs(x - y) > mp.mpf(10) ** (-30) * abs(y):
            raise RuntimeError(f"mpmath disagrees with itself at {args}: {x} vs {y}")
        out.append(y)
    return out[0] if single else tuple(out)


def k_mp(m: float):
    return mp.ellipk(mp.mpf(m))


def f_mp(phi: float, m: float):
    return mp.ellipf(mp.mpf(phi), mp.mpf(m))


def f_sensitivity(phi: float, m: float, value) -> float:
    """max |F(phi', m') - F(phi, m)| over the neighbours one ulp away in phi or in m (staying in
    the real domain): the error that rounding the inputs alone would cause."""
    worst = mp.mpf(0)
    with mp.workdps(DPS):
        for p2, m2 in ((math.nextafter(phi, -math.inf), m), (math.nextafter(phi, math.inf), m),
                       (phi, math.nextafter(m, -math.inf)), (phi, math.nextafter(m, math.inf))):
            if m2 > 1.0 and m2 * math.sin(p2) ** 2 >= 1.0 or m2 == 1.0 and abs(p2) > math.pi / 2:
                continue
            v = mp.ellipf(mp.mpf(p2), mp.mpf(m2))
            if abs(mp.im(v)) > 1e-30 * abs(v):
                continue
            worst = max(worst, abs(mp.re(v) - value))
    return float(worst)


# ---------------------------------------------------------------- Boost inputs
BOOST_JACOBI = ["jacobi_elliptic", "jacobi_elliptic_small", "jacobi_large_phi", "jacobi_near_1"]


def boost_rows(test_dir: pathlib.Path, name: str, width: int) -> list[list[float]]:
    text = (test_dir / f"{name}.ipp").read_text()
    vals = [float(x) for x in re.findall(r"SC_\(\s*([-+0-9.eE]+)\s*\)", text)]
    if len(vals) % width:
        raise RuntimeError(f"{name}: {len(vals)} numbers is not a multiple of {width}")
    return [vals[i:i + width] for i in range(0, len(vals), width)]


def boost_inputs(test_dir: pathlib.Path | None) -> tuple[list, list]:
    """(jacobi inputs [(set, u, m)], ellint inputs [(set, function, phi, m)])."""
    if test_dir is None:
        with (DATA / "jacobi_ref.csv").open() as f:
            jac = [(r["set"], float(r["u"]), float(r["m"])) for r in csv.DictReader(f)
                   if r["set"] != "edge"]
        with (DATA / "ellint_ref.csv").open() as f:
            ell = [(r["set"], r["function"], float(r["phi"]), float(r["m"]))
                   for r in csv.DictReader(f) if r["set"] != "edge"]
        return jac, ell
    jac = []
    for name in BOOST_JACOBI:
        # Boost's columns: u, k, sn, cn, dn
        jac += [(f"boost_{name}", u, k * k) for u, k, *_ in boost_rows(test_dir, name, 5)]
    ell = [("boost_ellint_k_data", "K", 0.0, k * k)
           for k, _ in boost_rows(test_dir, "ellint_k_data", 2)]
    # Boost's columns: phi, k, F
    ell += [("boost_ellint_f_data", "F", phi, k * k)
            for phi, k, _ in boost_rows(test_dir, "ellint_f_data", 3)]
    return jac, ell


def edge_jacobi_inputs() -> list[tuple]:
    pts = set()
    for m in M_EDGE:
        for u in U_EDGE:
            pts.add((u, m))
        if m < 1.0:
            with mp.workdps(DPS):
                k = float(mp.ellipk(mp.mpf(m)))
            for n in N_PERIODS:
                x = float(n * mp.mpf(k))
                if x <= 2e15:
                    for y in (math.nextafter(x, 0.0), x, math.nextafter(x, math.inf)):
                        pts.add((y, m))
                        if n < 10:
                            pts.add((-y, m))
    for m in M_OUTSIDE:
        for u in U_OUTSIDE:
            pts.add((u, m))
    pts.update(U_ISSUE)
    # -0.0 and 0.0 compare equal in a set: keep both explicitly
    rows = [("edge", u, m) for u, m in sorted(pts, key=lambda p: (p[1], p[0]))]
    rows += [("edge", -0.0, m) for m in M_EDGE]
    return rows


def edge_ellint_inputs() -> list[tuple]:
    rows = [("edge", "K", 0.0, m) for m in M_K_EDGE]
    for m in M_F_EDGE:
        for phi in PHI_EDGE:
            if m == 1.0 and abs(phi) > math.pi / 2:
                continue  # F(phi | 1) is infinite for |phi| > pi/2 (phi = fl(pi/2) < pi/2 is kept)
            rows.append(("edge", "F", phi, m))
    # m > 1: F is real for m sin^2 phi <= 1
    for m in (1.0 + 2.0**-52, 1.5, 4.0, 100.0):
        with mp.workdps(DPS):
            lim = float(mp.asin(1 / mp.sqrt(mp.mpf(m))))
        for phi in (1e-300, 1e-8, 0.25 * lim, 0.5 * lim, 0.9 * lim, -0.5 * lim,
                    math.nextafter(lim, 0.0) * (1 - 1e-12)):
            rows.append(("edge", "F", phi, m))
    return rows


def write_original() -> None:
    rows = []
    mp.mp.dps = 50  # as when the table was first written
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
    out = DATA / "elliptic_ref.csv"
    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["function", "x", "m", "value"])
        w.writerows(rows)
    print(f"wrote {len(rows)} reference values to {out}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--boost", type=pathlib.Path, default=None,
                    help="boostorg/math's test directory (to re-extract the table inputs)")
    args = ap.parse_args()
    DATA.mkdir(parents=True, exist_ok=True)
    write_original()

    jac_in, ell_in = boost_inputs(args.boost)
    jac_in += edge_jacobi_inputs()
    ell_in += edge_ellint_inputs()

    out = DATA / "jacobi_ref.csv"
    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["set", "u", "m", "sn", "cn", "dn"])
        for s, u, m in jac_in:
            w.writerow([s, f2s(u), f2s(m), *(f2s(v) for v in checked(jacobi_mp, u, m))])
    print(f"wrote {len(jac_in)} (sn, cn, dn) triples to {out}")

    out = DATA / "ellint_ref.csv"
    with out.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["set", "function", "phi", "m", "value", "sensitivity"])
        for s, fn, phi, m in ell_in:
            if fn == "K":
                v, sens = checked(k_mp, m), 0.0
            else:
                v = checked(f_mp, phi, m)
                sens = f_sensitivity(phi, m, v)
            w.writerow([s, fn, f2s(phi), f2s(m), f2s(v), f2s(sens)])
    print(f"wrote {len(ell_in)} values of K and F to {out}")


if __name__ == "__main__":
    main()
