#!/usr/bin/env python3
"""Write the mpmath reference table for the exact free-rigid-body momentum.

Output: crates/phsplit-core/tests/data/rigid_body_ref.csv, one row per (body, m0, t):

    case,T1,T2,T3,m1,m2,m3,t,ref1,ref2,ref3,sensitivity

* ``ref`` is the body angular momentum m(t) of m' = m x T^-1 m, evaluated on exactly the double
  inputs by the closed form of Landau & Lifshitz, *Mechanics*, section 37 (energy E and |m|^2,
  not the formulation of the Rust code), with mpmath at 50 digits;
* ``sensitivity`` is the problem's own conditioning: the largest |m'(t) - m(t)| (2-norm) when one
  input (an inertia, a component of m0, or t) moves one ulp either way, by the same closed form.

The closed form is checked against mpmath's ODE solver (``mp.odefun``, Taylor series, 30
digits) at every row with t <= 50 and at the rows marked for it at t = 1000; the script stops if
they differ by more than 1e-20 relative to |m0| (or the sensitivity's tenth part, whichever is
larger).

Cases: a start next to the unstable middle axis (T = (1, 2, 3), m0 = (1e-7, 1, 2e-7)); random bodies; near-symmetric
bodies (relative inertia gaps 1e-6 ... 1e-14, the middle inertia next to either end); states
next to the separatrix (k'^2 from 1e-4 to 1e-15, either side); states next to the middle axis
(and the other two); t from 0.5 to 1000.

Run: python3 scripts/gen_rigid_body_refs.py [--no-ode]   (a few minutes with the ODE checks)
"""
from __future__ import annotations

import argparse
import csv
import math
import pathlib
import random

import mpmath as mp

DPS = 50
OUT = (pathlib.Path(__file__).resolve().parent.parent
       / "crates/phsplit-core/tests/data/rigid_body_ref.csv")
TIMES = [0.5, 5.0, 50.0, 1000.0]


def closed_form(inertia, m0, t):
    """m(t) by Landau-Lifshitz section 37, at the current mpmath precision. Inputs are exact
    (mpf or float) and need three distinct inertias."""
    T = [mp.mpf(x) for x in inertia]
    m = [mp.mpf(x) for x in m0]
    t = mp.mpf(t)
    order = sorted(range(3), key=lambda i: T[i])
    i1, i2, i3 = order
    I1, I2, I3 = T[i1], T[i2], T[i3]
    M1, M2, M3 = m[i1], m[i2], m[i3]
    E2 = M1**2 / I1 + M2**2 / I2 + M3**2 / I3  # 2E
    MM = M1**2 + M2**2 + M3**2  # |m|^2
    p = E2 * I3 - MM  # 2E I3 - M^2 >= 0
    q = MM - E2 * I1  # M^2 - 2E I1 >= 0
    if p == 0 or q == 0 or (M1 == 0 and M3 == 0):
        return [mp.mpf(x) for x in m0]  # a steady rotation about a principal axis
    if MM >= E2 * I2:
        # the momentum circles the axis of largest inertia: m3 keeps its sign
        A1 = mp.sqrt(I1 * p / (I3 - I1))
        A2 = mp.sqrt(I2 * p / (I3 - I2))
        A3 = mp.sqrt(I3 * q / (I3 - I1))
        k2 = (I2 - I1) * p / ((I3 - I2) * q)
        w = mp.sqrt((I3 - I2) * q / (I1 * I2 * I3))
        s_keep = 1 if M3 >= 0 else -1
        cn0, sn0 = M1 / A1, M2 / A2
        c_axis, d_axis, Ac, Ad = i1, i3, A1, A3
    else:
        # the momentum circles the axis of smallest inertia: m1 keeps its sign
        A3 = mp.sqrt(I3 * q / (I3 - I1))
        A2 = mp.sqrt(I2 * q / (I2 - I1))
        A1 = mp.sqrt(I1 * p / (I3 - I1))
        k2 = (I3 - I2) * q / ((I2 - I1) * p)
        w = mp.sqrt((I2 - I1) * p / (I1 * I2 * I3))
        s_keep = 1 if M1 >= 0 else -1
        cn0, sn0 = M3 / A3, M2 / A2
        c_axis, d_axis, Ac, Ad = i3, i1, A3, A1
    # The direction of the phase: match the vector field at t = 0, m' = m x T^-1 m, on the
    # sn axis (m_sn' = A2 cn dn w sigma) or, where cn dn vanishes, on the cn axis
    # (m_cn' = -Ac sn dn w sigma).
    om = [m[i] / T[i] for i in range(3)]
    rhs = [m[1] * om[2] - m[2] * om[1], m[2] * om[0] - m[0] * om[2], m[0] * om[1] - m[1] * om[0]]
    dn0 = abs(m[d_axis]) / Ad
    if abs(cn0 * dn0) > abs(sn0 * dn0):
        sigma = 1 if rhs[i2] * cn0 * dn0 > 0 else -1
    else:
        sigma = 1 if -rhs[c_axis] * sn0 * dn0 > 0 else -1
    phi0 = mp.atan2(sn0, cn0)
    tau0 = mp.ellipf(phi0, k2)
    tau = tau0 + sigma * w * t
    sn, cn, dn = (mp.ellipfun(k, tau, m=k2) for k in ("sn", "cn", "dn"))
    out = [mp.mpf(0)] * 3
    out[c_axis] = Ac * cn
    out[i2] = A2 * sn
    out[d_axis] = s_keep * Ad * dn
    return out


def ode(inertia, m0, t):
    T = [mp.mpf(x) for x in inertia]

    def f(_, m):
        w = [m[i] / T[i] for i in range(3)]
        return [m[1] * w[2] - m[2] * w[1], m[2] * w[0] - m[0] * w[2], m[0] * w[1] - m[1] * w[0]]

    with mp.workdps(30):
        sol = mp.odefun(f, 0, [mp.mpf(x) for x in m0])
        return sol(mp.mpf(t))


def norm(v):
    return mp.sqrt(sum(x * x for x in v))


def sensitivity(inertia, m0, t, ref) -> float:
    worst = mp.mpf(0)
    inputs = list(inertia) + list(m0) + [t]
    for i in range(7):
        for direction in (-math.inf, math.inf):
            x = list(inputs)
            x[i] = math.nextafter(x[i], direction)
            v = closed_form(x[:3], x[3:6], x[6])
            worst = max(worst, norm([a - b for a, b in zip(v, ref)]))
    return float(worst)


def cases() -> list[tuple[str, tuple, tuple, list[float], bool]]:
    """(label, inertia, m0, times, check t = 1000 against the ODE too)."""
    out = [("near the middle axis", (1.0, 2.0, 3.0), (1e-7, 1.0, 2e-7), TIMES, True)]
    rng = random.Random(16)
    for k in range(6):
        inertia = tuple(rng.uniform(0.2, 5.0) for _ in range(3))
        m0 = tuple(rng.uniform(-2.0, 2.0) for _ in range(3))
        out.append((f"random {k}", inertia, m0, TIMES, k == 0))
    for gap in (1e-6, 1e-10, 1e-14):
        m0 = (0.3, -0.8, 0.5)
        out.append((f"near-symmetric lo~mid {gap:g}", (1.0, 1.0 + gap, 3.0), m0, TIMES, False))
        out.append((f"near-symmetric mid~hi {gap:g}", (1.0, 3.0 * (1.0 - gap), 3.0), m0, TIMES,
                    False))
        out.append((f"near-sphere {gap:g}", (2.0, 2.0 * (1.0 + gap), 2.0 * (1.0 + 2.0 * gap)),
                    (0.4, 0.7, -0.6), TIMES, False))
    # Next to the separatrix of T = (1, 2, 3): m_lo^2 (J1 - J2) = m_hi^2 (J2 - J3), i.e.
    # m_hi = m_lo sqrt(3); k'^2 ~ the relative offset.
    for off in (1e-4, 1e-8, 1e-12, 1e-15):
        for side in (1.0, -1.0):
            m_hi = 0.3
            m_lo = m_hi / math.sqrt(3.0) * (1.0 + side * off)
            out.append((f"separatrix {side * off:+g}", (1.0, 2.0, 3.0), (m_lo, 1.0, m_hi), TIMES,
                        False))
    # Next to the middle axis, for two orderings of the axes.
    for eps in (1e-3, 1e-10, 1e-13):
        out.append((f"middle axis {eps:g}", (1.0, 2.0, 3.0), (eps, 1.0, -2.0 * eps), TIMES,
                    False))
        out.append((f"middle axis yaw {eps:g}", (2.5, 0.7, 1.6), (-eps, 3.0 * eps, 1.2), TIMES,
                    False))
    out.append(("next to the stable axis", (1.0, 2.0, 3.0), (1.0, 1e-8, 1e-9), TIMES, False))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--no-ode", action="store_true", help="skip the check against mp.odefun")
    args = ap.parse_args()
    rows = []
    mp.mp.dps = DPS
    for label, inertia, m0, times, long_ode in cases():
        scale = norm([mp.mpf(x) for x in m0])
        for t in times:
            ref = closed_form(inertia, m0, t)
            sens = sensitivity(inertia, m0, t, ref)
            if not args.no_ode and (t <= 50.0 or long_ode):
                other = ode(inertia, m0, t)
                diff = norm([a - b for a, b in zip(other, ref)])
                if diff > max(1e-20 * scale, 0.1 * sens):
                    raise RuntimeError(f"{label} t={t}: closed form and ODE differ by {diff}")
            rows.append([label, *map(repr, inertia), *map(repr, m0), repr(t),
                         *(repr(float(x)) for x in ref), repr(sens)])
            print(f"{label:32} t={t:7} sensitivity {sens / float(scale):.2e} |m0|")
    with OUT.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "T1", "T2", "T3", "m1", "m2", "m3", "t", "ref1", "ref2", "ref3",
                    "sensitivity"])
        w.writerows(rows)
    print(f"wrote {len(rows)} rows to {OUT}")


if __name__ == "__main__":
    main()
