"""The shipped anti-roll tank (scenario anti-roll-tank; docs/explanation/components/anti-roll-tank.md):
Lloyd's linear U-tube (Seakeeping, 1989, ch. 13) with its coupling to sway (Holden, Perez &
Fossen, Ocean Engineering 38 (2011)), as a linear port-Hamiltonian subsystem on the duct's sway
velocity and the roll rate. The scenario's matrices follow from the tank's geometry and the
hull's added mass, written out here again; they pass the subsystem's checks and reproduce the
tank's equation and loads; the vessel file holds the hull less the fluid's share; in the beam sea
of the scenario the tank reduces the roll, and the ledger closes."""
from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources

import numpy as np
import phsplit
from phsplit import hydro, scenario

G_ACC = 9.81
PAPER = dict(mass=6.3622085e6, roll_inertia=2.873071e8, gm=2.1440)   # paper_vessel.toml
# The tank's geometry (the scenario's header): sea water; reservoirs 2 m wide, 16 m apart,
# fluid 3 m above the duct's centreline, 6 m long; the duct on the keel of the box that stands in
# for the hull (draught 4.49 m, centre of gravity 1.759 m above the waterline); damping ratio 0.2.
RHO, W, W_R, H_R, X_T, ZETA = 1025.0, 16.0, 2.0, 3.0, 6.0, 0.20
KEEL_BELOW_CG = 4.49 + 1.759


def scenario_tables() -> dict:
    return tomllib.loads(resources.files("phsplit").joinpath("scenarios/anti-roll-tank.toml").read_text())


def hull_added_mass() -> tuple[float, float, float, float]:
    """Capytaine's sway-roll added mass of the box at the hull's roll frequency (a fixed point,
    the sway free), and that roll period."""
    nc = str(resources.files("phsplit").joinpath("scenarios/paper_box_capytaine.nc"))
    m, I, K = PAPER["mass"], PAPER["roll_inertia"], PAPER["mass"] * G_ACC * PAPER["gm"]
    a22 = a24 = a44 = 0.0
    for _ in range(6):
        t_roll = 2 * math.pi * math.sqrt((I + a44 - a24 ** 2 / (m + a22)) / K)
        A = np.array(hydro.from_capytaine(nc, omega=2 * math.pi / t_roll, symmetric=True)["added_mass"])
        a22, a24, a44 = A[1, 1], 0.5 * (A[1, 3] + A[3, 1]), A[3, 3]
    return a22, a24, a44, 2 * math.pi * math.sqrt((I + a44 - a24 ** 2 / (m + a22)) / K)


def lloyd_coefficients() -> dict:
    a22, a24, a44, t_roll = hull_added_mass()
    h_d = W * W_R / (2 * (G_ACC * (t_roll / (2 * math.pi)) ** 2 - H_R))    # tuned on the roll period
    r_d = KEEL_BELOW_CG - h_d / 2
    q_t = RHO * W_R * X_T * W ** 2 / 2
    A = q_t * (W * W_R / (2 * h_d) + H_R)
    C = q_t * G_ACC
    return dict(A=A, C=C, a=np.array([q_t, q_t * H_R]), c=np.array([0.0, C]), B=2 * ZETA * math.sqrt(A * C),
                q_t=q_t, h_d=h_d, r_d=r_d, t_roll=t_roll, added=(a22, a24, a44),
                fluid_mass=RHO * X_T * (2 * W_R * H_R + W * h_d))


def matrices(table: dict) -> dict[str, np.ndarray]:
    n, k = len(table["states"]), len(table["input"])
    out = {name: np.array(table[name], float) for name in ("J", "R", "Q", "G")}
    out["P"] = np.array(table.get("P", np.zeros((n, k))), float)
    out["S"] = np.array(table.get("S", np.zeros((k, k))), float)
    out["N"] = np.array(table.get("N", np.zeros((k, k))), float)
    return out


def test_the_matrices_follow_from_the_geometry_and_pass_the_checks():
    k = lloyd_coefficients()
    A, B, C, a, c = k["A"], k["B"], k["C"], k["a"], k["c"]
    table = scenario_tables()["port_hamiltonian"]
    assert table["input"] == ["sway", "roll"]
    np.testing.assert_allclose(table["point"], [0.0, 0.0, -k["r_d"]], rtol=1e-12)
    m = matrices(table)
    want = dict(J=[[0, 1], [-1, 0]], R=[[0, 0], [0, B]], Q=[[C, 0], [0, 1 / A]], G=[c / C - a / A, [0, 0]],
                P=[[0, 0], -B * a / A], S=B * np.outer(a, a) / A ** 2)
    for name, value in want.items():
        np.testing.assert_allclose(m[name], value, rtol=1e-10, atol=0, err_msg=name)
    J, R, Q, P, S = m["J"], m["R"], m["Q"], m["P"], m["S"]
    np.testing.assert_array_equal(J, -J.T)
    np.testing.assert_array_equal(R, R.T)
    np.testing.assert_array_equal(Q, Q.T)
    assert np.linalg.eigvalsh(Q).min() > 0
    big = np.block([[R, P], [P.T, S]])
    assert np.linalg.eigvalsh(big).min() >= -1e-12 * np.abs(big).max()
    # The design rule: the tank's natural period on the roll period (the hull with its added
    # mass), a few per cent of the displacement in the tank; the box's beam holds it.
    assert math.isclose(2 * math.pi * math.sqrt(A / C), k["t_roll"], rel_tol=1e-12)
    assert 11.0 < k["t_roll"] < 11.2
    assert 0.01 < k["fluid_mass"] / PAPER["mass"] < 0.05
    assert W + W_R < 18.2


def test_the_port_hamiltonian_form_is_the_tank_with_sway():
    """At random states: ẋ of the PH form is the tank's equation, −y is the tank's loads on the
    reduced hull (the sway force at the duct, the roll moment), the storage plus the reduced
    hull's energy is the whole energy, and the dissipation booked is b τ'²."""
    k = lloyd_coefficients()
    A, B, C, a, c = k["A"], k["B"], k["C"], k["a"], k["c"]
    m = matrices(scenario_tables()["port_hamiltonian"])
    # The hull's sway-roll mass matrix in u's coordinates: u = T (v_y, φ'), the duct's point.
    T = np.array([[1.0, k["r_d"]], [0.0, 1.0]])
    Mu = np.linalg.inv(T).T @ np.diag([PAPER["mass"], PAPER["roll_inertia"]]) @ np.linalg.inv(T)
    K = PAPER["mass"] * G_ACC * PAPER["gm"]
    rng = np.random.default_rng(7)
    for phi, tau, dtau, *rest in rng.normal(scale=[0.05, 0.1, 0.05, 0.3, 0.03, 0.1, 0.02], size=(20, 7)):
        u, du = np.array(rest[:2]), np.array(rest[2:])
        ddtau = (-a @ du - c[1] * phi - B * dtau - C * tau) / A            # the tank's equation
        x = np.array([tau + phi, A * dtau + a @ u])
        xdot = (m["J"] - m["R"]) @ m["Q"] @ x + (m["G"] - m["P"]) @ u
        np.testing.assert_allclose(xdot, [dtau + u[1], A * ddtau + a @ du], rtol=1e-9, atol=1e-9 * abs(x[1]))
        y = (m["G"] + m["P"]).T @ m["Q"] @ x + (m["N"] + m["S"]) @ u
        # The loads on the hull with the fluid frozen are −a τ'' − c τ; on the reduced hull
        # (mass less a aᵀ/A, roll stiffness less c²/C) they are that less (a aᵀ/A) u' + (c c/C) φ.
        load = -a * ddtau - c * tau - np.outer(a, a) / A @ du - c * (c[1] / C) * phi
        np.testing.assert_allclose(-y, load, rtol=1e-9, atol=1e-6)
        whole = 0.5 * u @ Mu @ u + dtau * (a @ u) + 0.5 * A * dtau ** 2 + 0.5 * K * phi ** 2 + C * tau * phi + 0.5 * C * tau ** 2
        reduced = 0.5 * u @ (Mu - np.outer(a, a) / A) @ u + 0.5 * (K - C) * phi ** 2
        assert math.isclose(0.5 * x @ m["Q"] @ x + reduced, whole, rel_tol=1e-12)
        z = np.concatenate([m["Q"] @ x, u])
        big = np.block([[m["R"], m["P"]], [m["P"].T, m["S"]]])
        assert math.isclose(z @ big @ z, B * dtau ** 2, rel_tol=1e-8, abs_tol=1e-9 * B * dtau ** 2 + 1e-9)


def test_the_vessel_file_holds_the_hull_less_the_fluids_share():
    k = lloyd_coefficients()
    v = scenario_tables()["vessel"]
    assert v["from"] == "paper" and "inertia" not in v
    a22, a24, a44 = k["added"]
    b = np.zeros(6)
    b[1], b[3] = k["q_t"], k["q_t"] * (k["r_d"] + H_R)
    want = np.zeros((6, 6))
    want[1, 1], want[1, 3], want[3, 1], want[3, 3] = a22, a24, a24, a44
    want -= np.outer(b, b) / k["A"]
    np.testing.assert_allclose(v["added_mass"], want, rtol=1e-9, atol=0)
    assert math.isclose(v["gm_transverse"], PAPER["gm"] - k["q_t"] / PAPER["mass"], rel_tol=1e-12)   # the free surface


def _run(tables: dict, t_end: float):
    path = scenario.resolve("anti-roll-tank")
    sc = scenario.from_dict(tables, path).replace(t_span=(0.0, t_end))
    return phsplit.simulate(sc.vessel, settings=sc.settings)


def test_the_tank_reduces_the_roll_in_the_beam_sea():
    """Same sea, same seed: the scenario, and the same hull with the tank's fluid frozen (its
    added mass kept, no subsystem, the paper's GM_T). 30 minutes, the first 5 left out."""
    tables = scenario_tables()
    k = lloyd_coefficients()
    frozen = copy.deepcopy(tables)
    frozen.pop("port_hamiltonian")
    b = np.zeros(6)
    b[1], b[3] = k["q_t"], k["q_t"] * (k["r_d"] + H_R)
    frozen["vessel"] = {"from": "paper", "added_mass": (np.array(tables["vessel"]["added_mass"]) + np.outer(b, b) / k["A"]).tolist()}
    with_tank, without = _run(tables, 1800.0), _run(frozen, 1800.0)
    assert with_tank.status == without.status == "completed"
    keep = with_tank.t >= 300.0
    rms = lambda s: float(np.sqrt(np.mean(s.euler[keep, 0] ** 2)))
    assert rms(without) > np.radians(2.0)          # the sea does excite the roll
    assert rms(with_tank) < 0.9 * rms(without)
    # The tank angle stays inside the reservoirs (the duct uncovers at 2 (h_r − h_d/2) / W).
    tau = with_tank.outputs["tank_eta"][2][keep] - with_tank.euler[keep, 0]
    assert np.abs(tau).max() < 2 * (H_R - k["h_d"] / 2) / W
    # The ledger closes with the tank's dissipation booked, which is never negative.
    assert with_tank.ledger.relative_residual().max() < 1e-10
    booked = with_tank.ledger.by_account["tank"]
    assert booked.min() >= -1e-9 * np.abs(booked).max() and booked.sum() > 0
    # The subsystem's outputs: its storage, and its loads −y from its states and u (the duct's
    # sway velocity, the roll rate).
    A, C = k["A"], k["C"]
    eta, pi = with_tank.outputs["tank_eta"][2], with_tank.outputs["tank_pi"][2]
    np.testing.assert_allclose(with_tank.outputs["tank_storage"][2], 0.5 * C * eta ** 2 + 0.5 * pi ** 2 / A, rtol=1e-10)
    m = matrices(tables["port_hamiltonian"])
    u = np.stack([with_tank.v[:, 1] + k["r_d"] * with_tank.w[:, 0], with_tank.w[:, 0]])
    y = (m["G"] + m["P"]).T @ m["Q"] @ np.stack([eta, pi]) + (m["N"] + m["S"]) @ u
    for i, name in enumerate(("tank_force_sway", "tank_force_roll")):
        np.testing.assert_allclose(with_tank.outputs[name][2], -y[i], rtol=1e-9, atol=1e-9 * np.abs(y[i]).max())
