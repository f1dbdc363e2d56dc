"""The passive U-tube anti-roll tank of the shipped scenario anti-roll-tank: its coefficients from
the geometry, its port-Hamiltonian matrices, and the measurement of the roll it removes.

    python scripts/anti_roll_tank.py            # the coefficients, the matrices, the TOML tables
    python scripts/anti_roll_tank.py --measure  # and the roll with and without the tank

The model (docs/explanation/components/anti-roll-tank.md) is Lloyd's linear U-tube (A. R. J. M.
Lloyd, Seakeeping: Ship Behaviour in Rough Weather, 1989, ch. 13), as restated by Fossen
(Handbook of Marine Craft Hydrodynamics and Motion Control, 2011) and derived by Lagrange's
equations by Holden, Perez & Fossen (Ocean Engineering 38 (2011) 341-359). With the tank angle
tau (the line through the two free surfaces, relative to the hull) and the roll angle phi:

    a_tt tau'' + b_tt tau' + c_tt tau = -a_tp phi'' - c_tp phi
    (roll moment of the tank on the hull whose fluid is frozen)  = -a_tp tau'' - c_tp tau

    Q_t  = rho_t w_r x_t W^2 / 2
    a_tt = Q_t (W w_r / (2 h_d) + h_r),  c_tt = Q_t g
    a_tp = Q_t (r_d + h_r),              c_tp = Q_t g

The damping b_tt is given here by the tank's damping ratio, b_tt = 2 zeta_t sqrt(a_tt c_tt): in a
real tank it is set by the duct's flow resistance (valves, orifices), which the linear model
lumps into this one number.
"""
from __future__ import annotations

import math
import sys

import numpy as np

# The paper's vessel (crates/phsplit-core/data/paper_vessel.toml) and the Capytaine box standing
# in for its hull (scripts/gen_capytaine_box.py): 76.2 x 18.2 m, draught 4.49 m, the centre of
# gravity 1.759 m above the waterline.
MASS = 6.3622085e6            # kg
ROLL_INERTIA = 2.873071e8     # kg m^2, the rigid body's (the paper's T1)
GM_T = 2.1440                 # m
G = 9.81                      # m/s^2
BEAM, DRAUGHT, CG_ABOVE_WATERLINE = 18.2, 4.49, 1.759

# The tank (the design rule of Lloyd ch. 13 / Fossen: its natural period on the ship's roll period,
# with a fluid mass of a few per cent of the displacement). Sea water.
TANK = dict(
    rho=1025.0,       # kg/m^3, the tank fluid: sea water
    W=16.0,           # m, between the centrelines of the two reservoirs (inside the 18.2 m beam)
    w_r=2.0,          # m, width of each reservoir
    h_r=3.0,          # m, fluid height in the reservoirs above the duct's centreline, at rest
    x_t=6.0,          # m, length of the tank along the ship
    zeta=0.10,        # the tank's damping ratio (its duct resistance)
)


def tuned_duct_height(W: float, w_r: float, h_r: float, period: float, g: float = G) -> float:
    """h_d that puts the tank's natural period, 2 pi sqrt((h_r + W w_r / (2 h_d)) / g), on ``period``."""
    return W * w_r / (2.0 * (g * (period / (2.0 * math.pi)) ** 2 - h_r))


def roll_period(inertia: float = ROLL_INERTIA, gm: float = GM_T) -> float:
    return 2.0 * math.pi * math.sqrt(inertia / (MASS * G * gm))


def coefficients(rho, W, w_r, h_r, x_t, zeta, h_d=None, r_d=None, g=G):
    """Lloyd's coefficients from the geometry (SI). The duct lies on the keel unless r_d (its
    centreline's depth below the roll axis, the centre of gravity) is given."""
    if h_d is None:
        h_d = tuned_duct_height(W, w_r, h_r, roll_period(), g)
    if r_d is None:
        r_d = DRAUGHT + CG_ABOVE_WATERLINE - h_d / 2.0
    Qt = rho * w_r * x_t * W ** 2 / 2.0
    a_tt = Qt * (W * w_r / (2.0 * h_d) + h_r)
    c_tt = Qt * g
    a_tp = Qt * (r_d + h_r)
    c_tp = Qt * g
    b_tt = 2.0 * zeta * math.sqrt(a_tt * c_tt)
    mass = rho * x_t * (2.0 * w_r * h_r + W * h_d)   # the two columns and the duct
    return dict(h_d=h_d, r_d=r_d, h_r=h_r, Q_t=Qt, a_tt=a_tt, b_tt=b_tt, c_tt=c_tt, a_tp=a_tp, c_tp=c_tp,
                fluid_mass=mass, period=2.0 * math.pi * math.sqrt(a_tt / c_tt))


def port_hamiltonian(k: dict) -> dict:
    """The tank as ẋ = (J − R) Q x + (G − P) u, y = (G + P)ᵀ Q x + (N + S) u with u the roll rate
    and y minus the roll moment on the hull: x = (η, π), η = τ + (c/C) φ, π = A τ' + a φ'."""
    A, B, C, a, c = k["a_tt"], k["b_tt"], k["c_tt"], k["a_tp"], k["c_tp"]
    return dict(
        J=[[0.0, 1.0], [-1.0, 0.0]],
        R=[[0.0, 0.0], [0.0, B]],
        Q=[[C, 0.0], [0.0, 1.0 / A]],
        G=[[c / C - a / A], [0.0]],
        P=[[0.0], [-a * B / A]],
        S=[[a * a * B / (A * A)]],
    )


def port_hamiltonian_sway_roll(k: dict) -> tuple[dict, list]:
    """The same tank with its coupling to the hull's lateral acceleration (Holden, Perez & Fossen
    2011 keep it; the roll-only form drops it): inputs u = (the sway velocity of the duct's
    centre, the roll rate), the sway input at the point (0, 0, -r_d). The fluid's kinetic
    coupling is then tau' (a_1 u_1 + a_2 u_2) with a = Q_t (1, h_r), its potential coupling
    c_tp tau phi as before. Returns the table's matrices and the hull's mass-matrix correction
    (as vessel.added_mass, 6x6): minus b b^T / a_tt with b = Q_t (0, 1, 0, r_d + h_r, 0, 0)."""
    A, B, C = k["a_tt"], k["b_tt"], k["c_tt"]
    a = np.array([k["Q_t"], k["Q_t"] * k["h_r"]])
    c = np.array([0.0, k["c_tp"]])
    ph = dict(
        J=[[0.0, 1.0], [-1.0, 0.0]],
        R=[[0.0, 0.0], [0.0, B]],
        Q=[[C, 0.0], [0.0, 1.0 / A]],
        G=[list(c / C - a / A), [0.0, 0.0]],
        P=[[0.0, 0.0], list(-B * a / A)],
        S=[list(r) for r in B * np.outer(a, a) / A ** 2],
    )
    b = np.zeros(6)
    b[1], b[3] = k["Q_t"], k["Q_t"] * (k["r_d"] + k["h_r"])
    return ph, [list(r) for r in -np.outer(b, b) / A]


def vessel_with_tank(k: dict) -> dict:
    """What the vessel file holds once the tank's fluid is a subsystem: the rigid body's roll
    inertia less a_tp²/a_tt, and the metacentric height less the free surface's c_tp²/(c_tt m g)."""
    return dict(roll_inertia=ROLL_INERTIA - k["a_tp"] ** 2 / k["a_tt"],
                gm_transverse=GM_T - k["c_tp"] ** 2 / (k["c_tt"] * MASS * G))


def _fmt(x: float) -> str:
    s = repr(float(x))
    return s if any(ch in s for ch in ".en") else s + ".0"


def toml_tables(k: dict) -> str:
    ph, v = port_hamiltonian(k), vessel_with_tank(k)
    rows = lambda M: "[" + ", ".join("[" + ", ".join(_fmt(e) for e in r) + "]" for r in M) + "]"
    return "\n".join([
        "[vessel]",
        f"inertia = [{_fmt(v['roll_inertia'])}, 2.726143e9, 2.90000e9]",
        f"gm_transverse = {_fmt(v['gm_transverse'])}",
        "",
        "[port_hamiltonian]",
        'name = "tank"',
        'states = ["eta", "pi"]',
        'units = ["rad", "kg m2 s-1"]',
        'input = ["roll"]',
        *(f"{n} = {rows(ph[n])}" for n in ("J", "R", "Q", "G", "P", "S")),
    ])


def measure(path: str, t_skip: float = 300.0) -> dict:
    """Roll RMS and max (degrees) after ``t_skip`` of the scenario with its tank, and of the same
    scenario with the tank's fluid frozen (the paper's vessel: no subsystem, the rigid body's
    inertia and metacentric height), same sea, same seed."""
    import copy

    import phsplit
    from phsplit import scenario

    data = scenario._read_toml(scenario.resolve(path), "scenario file")
    frozen = copy.deepcopy(data)
    frozen.pop("port_hamiltonian", None)
    frozen["vessel"] = {"from": "paper"}
    k = coefficients(**TANK)
    ph, added = port_hamiltonian_sway_roll(k)
    sway = copy.deepcopy(data)
    sway["vessel"] = {"from": "paper", "gm_transverse": data["vessel"]["gm_transverse"], "added_mass": added}
    sway["port_hamiltonian"] = {**{n: v for n, v in data["port_hamiltonian"].items() if n not in ph},
                                **ph, "input": ["sway", "roll"], "point": [0.0, 0.0, -k["r_d"]]}
    out = {}
    for label, d in (("without the tank", frozen), ("with the tank", data), ("with the tank, sway-coupled", sway)):
        sc = scenario.from_dict(d, scenario.resolve(path))
        sol = phsplit.simulate(sc.vessel, settings=sc.settings)
        keep = sol.t >= t_skip
        roll = np.degrees(sol.euler[keep, 0])
        out[label] = dict(rms=float(np.sqrt(np.mean(roll ** 2))), max=float(np.abs(roll).max()), sol=sol)
    return out


if __name__ == "__main__":
    k = coefficients(**TANK)
    print(f"roll period of the paper's vessel: {roll_period():.3f} s")
    for n in ("h_d", "r_d", "Q_t", "a_tt", "b_tt", "c_tt", "a_tp", "c_tp", "fluid_mass", "period"):
        print(f"{n:>10} = {k[n]:.6g}")
    print(f"fluid mass / displacement = {k['fluid_mass'] / MASS:.4f}")
    v = vessel_with_tank(k)
    print(f"roll inertia {ROLL_INERTIA:.6g} -> {v['roll_inertia']:.6g} kg m^2; GM_T {GM_T} -> {v['gm_transverse']:.6g} m;"
          f" the reduced hull's roll period {roll_period(v['roll_inertia'], v['gm_transverse']):.3f} s")
    print()
    print(toml_tables(k))
    if "--measure" in sys.argv:
        r = measure("anti-roll-tank")
        print()
        print("| | roll RMS (deg) | max roll (deg) |")
        print("|---|---|---|")
        for label in r:
            print(f"| {label} | {r[label]['rms']:.3f} | {r[label]['max']:.3f} |")
        base = r["without the tank"]
        for label in list(r)[1:]:
            print(f"{label}: RMS {100 * (r[label]['rms'] / base['rms'] - 1):+.1f} %,"
                  f" max {100 * (r[label]['max'] / base['max'] - 1):+.1f} %")
