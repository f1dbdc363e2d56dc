"""The passive U-tube anti-roll tank of the shipped scenario anti-roll-tank: its coefficients from
the geometry, its port-Hamiltonian matrices, and the measurement of the roll it removes.

    python scripts/anti_roll_tank.py            # the coefficients, the matrices, the TOML tables
    python scripts/anti_roll_tank.py --measure  # and the roll with and without the tank

The model (docs/explanation/components/anti-roll-tank.md) is Lloyd's linear U-tube (A. R. J. M.
Lloyd, Seakeeping: Ship Behaviour in Rough Weather, 1989, ch. 13), as restated by Fossen
(Handbook of Marine Craft Hydrodynamics and Motion Control, 2011) and derived by Lagrange's
equations by Holden, Perez & Fossen (Ocean Engineering 38 (2011) 341-359), with its coupling to
the hull's sway kept. With the tank angle tau (the line through the two free surfaces, relative
to the hull), the roll angle phi and v_d = v_y + r_d phi' the duct's lateral velocity:

    a_tt tau'' + b_tt tau' + c_tt tau = -Q_t v_d' - Q_t h_r phi'' - c_tp phi

    Q_t  = rho_t w_r x_t W^2 / 2
    a_tt = Q_t (W w_r / (2 h_d) + h_r),  c_tt = c_tp = Q_t g,  b_tt = 2 zeta_t sqrt(a_tt c_tt)

(with the sway dropped, a_tp = Q_t (r_d + h_r) is Lloyd's roll coupling). The hull carries the
added mass of its sway-roll block from the Capytaine data of the box that stands in for it, at
its roll frequency; the tank is tuned to the roll period of that hull.
"""
from __future__ import annotations

import math
import sys
from importlib import resources

import numpy as np

# The paper's vessel (crates/phsplit-core/data/paper_vessel.toml) and the Capytaine box standing
# in for its hull (scripts/gen_capytaine_box.py): 76.2 x 18.2 m, draught 4.49 m, the centre of
# gravity 1.759 m above the waterline.
MASS = 6.3622085e6            # kg
ROLL_INERTIA = 2.873071e8     # kg m^2, the rigid body's (the paper's T1)
GM_T = 2.1440                 # m
G = 9.81                      # m/s^2
BEAM, DRAUGHT, CG_ABOVE_WATERLINE = 18.2, 4.49, 1.759
SWAY, ROLL = 1, 3

# The tank (the design rule of Lloyd ch. 13 / Fossen: its natural period on the ship's roll period,
# with a fluid mass of a few per cent of the displacement). Sea water.
TANK = dict(
    rho=1025.0,       # kg/m^3, the tank fluid: sea water
    W=16.0,           # m, between the centrelines of the two reservoirs (inside the 18.2 m beam)
    w_r=2.0,          # m, width of each reservoir
    h_r=3.0,          # m, fluid height in the reservoirs above the duct's centreline, at rest
    x_t=6.0,          # m, length of the tank along the ship
    zeta=0.20,        # the tank's damping ratio (its duct resistance)
)


def hull_added_mass(omega: float) -> np.ndarray:
    """The 6x6 added mass of the scenario's hull: Capytaine's sway-roll block of the box
    (paper_box_capytaine.nc, at ``omega``, moved to the centre of gravity by the loader),
    symmetrised; the other degrees of freedom keep the paper's rigid-body values."""
    from phsplit import hydro

    nc = resources.files("phsplit").joinpath("scenarios/paper_box_capytaine.nc")
    a = np.asarray(hydro.from_capytaine(str(nc), omega=omega, symmetric=True)["added_mass"], float)
    out = np.zeros((6, 6))
    for i in (SWAY, ROLL):
        for j in (SWAY, ROLL):
            out[i, j] = 0.5 * (a[i, j] + a[j, i])
    return out


def roll_period(added: np.ndarray | None = None, inertia: float = ROLL_INERTIA, gm: float = GM_T) -> float:
    """2 pi sqrt(I_eff / (m g GM_T)), with I_eff = I + A44 - A24^2 / (m + A22) (the sway free)."""
    a = np.zeros((6, 6)) if added is None else added
    i_eff = inertia + a[ROLL, ROLL] - a[SWAY, ROLL] ** 2 / (MASS + a[SWAY, SWAY])
    return 2.0 * math.pi * math.sqrt(i_eff / (MASS * G * gm))


def hull() -> tuple[np.ndarray, float]:
    """The hull's added mass at its own roll frequency (a fixed point) and that roll period."""
    period = roll_period()
    for _ in range(6):
        added = hull_added_mass(2.0 * math.pi / period)
        period = roll_period(added)
    return added, period


def tuned_duct_height(W: float, w_r: float, h_r: float, period: float, g: float = G) -> float:
    """h_d that puts the tank's natural period, 2 pi sqrt((h_r + W w_r / (2 h_d)) / g), on ``period``."""
    return W * w_r / (2.0 * (g * (period / (2.0 * math.pi)) ** 2 - h_r))


def coefficients(rho, W, w_r, h_r, x_t, zeta, period, h_d=None, r_d=None, g=G):
    """Lloyd's coefficients from the geometry (SI), the tank tuned to ``period``. The duct lies
    on the keel unless r_d (its centreline's depth below the centre of gravity) is given."""
    if h_d is None:
        h_d = tuned_duct_height(W, w_r, h_r, period, g)
    if r_d is None:
        r_d = DRAUGHT + CG_ABOVE_WATERLINE - h_d / 2.0
    Qt = rho * w_r * x_t * W ** 2 / 2.0
    a_tt = Qt * (W * w_r / (2.0 * h_d) + h_r)
    c_tt = Qt * g
    b_tt = 2.0 * zeta * math.sqrt(a_tt * c_tt)
    mass = rho * x_t * (2.0 * w_r * h_r + W * h_d)   # the two columns and the duct
    return dict(h_d=h_d, r_d=r_d, h_r=h_r, W=W, Q_t=Qt, a_tt=a_tt, b_tt=b_tt, c_tt=c_tt,
                a_tp=Qt * (r_d + h_r), c_tp=Qt * g, fluid_mass=mass,
                period=2.0 * math.pi * math.sqrt(a_tt / c_tt), tau_limit=2.0 * (h_r - h_d / 2.0) / W)


def port_hamiltonian(k: dict) -> tuple[dict, np.ndarray]:
    """The tank as ẋ = (J − R) Q x + (G − P) u, y = (G + P)ᵀ Q x + (N + S) u, with u = (the
    duct's sway velocity, the roll rate), the sway input at the duct's point (0, 0, -r_d), and -y
    the tank's loads on the reduced hull: x = (η, π), η = τ + φ, π = a_tt τ' + a · u with
    a = Q_t (1, h_r). Returns the matrices and the hull's mass-matrix correction (6x6):
    minus b bᵀ / a_tt with b = Q_t (0, 1, 0, r_d + h_r, 0, 0)."""
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
    b[SWAY], b[ROLL] = k["Q_t"], k["Q_t"] * (k["r_d"] + k["h_r"])
    return ph, -np.outer(b, b) / A


def port_hamiltonian_roll_only(k: dict) -> dict:
    """The simplification with the sway dropped: u the roll rate alone, η = τ + φ,
    π = a_tt τ' + a_tp φ'; the hull's roll inertia then loses a_tp² / a_tt."""
    A, B, C, a, c = k["a_tt"], k["b_tt"], k["c_tt"], k["a_tp"], k["c_tp"]
    return dict(J=[[0.0, 1.0], [-1.0, 0.0]], R=[[0.0, 0.0], [0.0, B]], Q=[[C, 0.0], [0.0, 1.0 / A]],
                G=[[c / C - a / A], [0.0]], P=[[0.0], [-a * B / A]], S=[[a * a * B / (A * A)]])


def vessel_with_tank(k: dict, added: np.ndarray) -> dict:
    """What the vessel file holds once the tank's fluid is a subsystem: the hull's added mass less
    b bᵀ / a_tt, and the metacentric height less the free surface's c_tp² / (c_tt m g) = Q_t / m."""
    return dict(added_mass=added + port_hamiltonian(k)[1],
                gm_transverse=GM_T - k["c_tp"] ** 2 / (k["c_tt"] * MASS * G))


def _fmt(x: float) -> str:
    s = repr(float(x))
    return s if any(ch in s for ch in ".en") else s + ".0"


def toml_tables(k: dict, added: np.ndarray) -> str:
    ph, v = port_hamiltonian(k)[0], vessel_with_tank(k, added)
    rows = lambda M: "[" + ", ".join("[" + ", ".join(_fmt(e) for e in r) + "]" for r in M) + "]"
    am = "\n".join(f"  [{', '.join(_fmt(e) for e in r)}]," for r in v["added_mass"])
    return "\n".join([
        "[vessel]",
        'from = "paper"',
        f"gm_transverse = {_fmt(v['gm_transverse'])}",
        f"added_mass = [\n{am}\n]",
        "",
        "[port_hamiltonian]",
        'name = "tank"',
        'states = ["eta", "pi"]',
        'units = ["rad", "kg m2 s-1"]',
        'input = ["sway", "roll"]',
        f"point = [0.0, 0.0, {_fmt(-k['r_d'])}]",
        *(f"{n} = {rows(ph[n])}" for n in ("J", "R", "Q", "G", "P", "S")),
    ])


def linear_estimate(k: dict, added: np.ndarray, waves: dict, model: str) -> float:
    """The roll RMS (degrees) of the linear sway-roll(-tank) system in the frequency domain, an
    estimate independent of phsplit's integrator: for each component of the scenario's sea (same
    seed), the response to Capytaine's beam-sea sway force and roll moment, with the paper's
    damping and the DP's sway P and D gains; RMS² = Σ ½ a_k² |φ_k|². ``model``: "without",
    "sway" (the scenario) or "roll" (the simplification)."""
    from phsplit import hydro, sea

    nc = resources.files("phsplit").joinpath("scenarios/paper_box_capytaine.nc")
    hd = hydro.from_capytaine(str(nc), symmetric=True)["waves"]
    w_t, dirs = np.array(hd["rao_frequencies"]), np.array(hd["rao_directions"])
    F = np.array(hd["force_rao_real"]) + 1j * np.array(hd["force_rao_imag"])
    F = F[int(np.argmin(abs(dirs - 90.0)))]
    keys = ("hs", "tp", "gamma", "spectrum", "seed", "components", "omega_range")
    r = sea.SeaState(**{n: waves[n] for n in keys}, direction=90.0).realise()
    om, amp = np.array(r["frequencies"]), np.array(r["amplitudes"])
    Mh = np.array([[MASS + added[SWAY, SWAY], added[SWAY, ROLL]], [added[SWAY, ROLL], ROLL_INERTIA + added[ROLL, ROLL]]])
    d22, d44, kp, kd = 1.1781388e5, 9.329153987e6, 4e5, 4e6        # paper_vessel.toml
    K = MASS * G * GM_T
    b = np.array([k["Q_t"] if model == "sway" else 0.0, k["a_tp"]])
    phi = []
    for w in om:
        f = np.array([np.interp(w, w_t, F[:, d].real) + 1j * np.interp(w, w_t, F[:, d].imag) for d in (SWAY, ROLL)])
        if model == "without":
            Z = -w ** 2 * Mh + 1j * w * np.diag([d22 + kd, d44]) + np.diag([kp, K])
            phi.append(np.linalg.solve(Z, f)[1])
            continue
        M3 = np.block([[Mh, b[:, None]], [b[None, :], np.array([[k["a_tt"]]])]])
        K3 = np.array([[kp, 0.0, 0.0], [0.0, K, k["c_tp"]], [0.0, k["c_tp"], k["c_tt"]]])
        Z = -w ** 2 * M3 + 1j * w * np.diag([d22 + kd, d44, k["b_tt"]]) + K3
        phi.append(np.linalg.solve(Z, np.array([f[0], f[1], 0.0]))[1])
    return math.degrees(math.sqrt(np.sum(0.5 * amp ** 2 * np.abs(np.array(phi)) ** 2)))


def measure(path: str = "anti-roll-tank", t_skip: float = 300.0) -> dict:
    """Roll RMS and max (degrees) after ``t_skip``, and the tank angle's: the scenario (the
    sway-coupled tank); the same hull with the tank's fluid frozen (no subsystem, the hull's added
    mass, the paper's GM_T); and the roll-only simplification. Same sea, same seed."""
    import copy

    import phsplit
    from phsplit import scenario

    data = scenario._read_toml(scenario.resolve(path), "scenario file")
    added, period = hull()
    k = coefficients(**TANK, period=period)
    v = vessel_with_tank(k, added)
    frozen = copy.deepcopy(data)
    frozen.pop("port_hamiltonian", None)
    frozen["vessel"] = {"from": "paper", "added_mass": added.tolist()}
    roll = copy.deepcopy(data)
    roll["vessel"] = {"from": "paper", "gm_transverse": v["gm_transverse"], "added_mass": added.tolist(),
                      "inertia": [ROLL_INERTIA - k["a_tp"] ** 2 / k["a_tt"], 2.726143e9, 2.90000e9]}
    roll["port_hamiltonian"] = {**{n: x for n, x in data["port_hamiltonian"].items() if n != "point"},
                                **port_hamiltonian_roll_only(k), "input": ["roll"]}
    out = {}
    for label, d, model in (("without the tank (fluid frozen)", frozen, "without"),
                            ("with the tank (the scenario)", data, "sway"),
                            ("with the tank, roll-only", roll, "roll")):
        sc = scenario.from_dict(d, scenario.resolve(path))
        sol = phsplit.simulate(sc.vessel, settings=sc.settings)
        keep = sol.t >= t_skip
        phi = np.degrees(sol.euler[keep, 0])
        row = dict(rms=float(np.sqrt(np.mean(phi ** 2))), max=float(np.abs(phi).max()), sol=sol,
                   residual=float(sol.ledger.relative_residual().max()),
                   linear=linear_estimate(k, added, data["environment"]["waves"], model))
        if "tank_eta" in sol.outputs:
            tau = np.degrees(sol.outputs["tank_eta"][2][keep]) - phi          # τ = η − φ
            row.update(tau_rms=float(np.sqrt(np.mean(tau ** 2))), tau_max=float(np.abs(tau).max()),
                       booked=float(sol.ledger.by_account["tank"].sum()))
        out[label] = row
    return out


if __name__ == "__main__":
    added, period = hull()
    k = coefficients(**TANK, period=period)
    print(f"the hull's added mass at its roll frequency {2 * math.pi / period:.4f} rad/s: "
          f"A22 = {added[SWAY, SWAY]:.5g} kg, A24 = {added[SWAY, ROLL]:.5g} kg m, A44 = {added[ROLL, ROLL]:.5g} kg m^2")
    print(f"roll period: {roll_period():.3f} s without the added mass, {period:.3f} s with it")
    for n in ("h_d", "r_d", "Q_t", "a_tt", "b_tt", "c_tt", "a_tp", "c_tp", "fluid_mass", "period"):
        print(f"{n:>10} = {k[n]:.6g}")
    print(f"fluid mass / displacement = {k['fluid_mass'] / MASS:.4f};"
          f" |tau| limit {math.degrees(k['tau_limit']):.1f} deg")
    print()
    print(toml_tables(k, added))
    if "--measure" in sys.argv:
        r = measure()
        print()
        print("| run | roll RMS | max roll | tank angle RMS, max | the tank's account | linear estimate | ledger |")
        print("|---|---|---|---|---|---|---|")
        base = r["without the tank (fluid frozen)"]
        for label, x in r.items():
            d = "" if x is base else f" ({100 * (x['rms'] / base['rms'] - 1):+.1f} %)"
            dm = "" if x is base else f" ({100 * (x['max'] / base['max'] - 1):+.1f} %)"
            tank = f"{x['tau_rms']:.2f}°, {x['tau_max']:.2f}° | {x['booked']:.3g} J" if "tau_rms" in x else "— | —"
            print(f"| {label} | {x['rms']:.3f}°{d} | {x['max']:.3f}°{dm} | {tank} | {x['linear']:.3f}° | {x['residual']:.1e} |")
