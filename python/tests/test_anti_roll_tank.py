"""The shipped anti-roll tank (scenario anti-roll-tank; docs/explanation/components/anti-roll-tank.md):
Lloyd's linear U-tube (Seakeeping, 1989, ch. 13; Holden, Perez & Fossen, Ocean Engineering 38
(2011)) as a linear port-Hamiltonian subsystem on the roll rate. The scenario's matrices follow
from the tank's geometry, written out here again; they pass the subsystem's checks and reproduce
Lloyd's tank equation and roll moment; the vessel file holds the rigid body less the fluid's
share; in the beam sea of the scenario the tank reduces the roll, and the ledger closes."""
from __future__ import annotations

import copy
import math
import tomllib
from importlib import resources

import numpy as np
import pytest

import phsplit
from phsplit import scenario

G_ACC = 9.81
PAPER = dict(mass=6.3622085e6, roll_inertia=2.873071e8, gm=2.1440)   # paper_vessel.toml
# The tank's geometry (the scenario's header): sea water; reservoirs 2 m wide, 16 m apart,
# fluid 3 m above the duct's centreline, 6 m long; the duct on the keel of the box that stands in
# for the hull (draught 4.49 m, centre of gravity 1.759 m above the waterline); damping ratio 0.1.
RHO, W, W_R, H_R, X_T, ZETA = 1025.0, 16.0, 2.0, 3.0, 6.0, 0.10
KEEL_BELOW_CG = 4.49 + 1.759


def scenario_tables() -> dict:
    return tomllib.loads(resources.files("phsplit").joinpath("scenarios/anti-roll-tank.toml").read_text())


def lloyd_coefficients() -> dict:
    t_roll = 2 * math.pi * math.sqrt(PAPER["roll_inertia"] / (PAPER["mass"] * G_ACC * PAPER["gm"]))
    h_d = W * W_R / (2 * (G_ACC * (t_roll / (2 * math.pi)) ** 2 - H_R))    # tuned on the roll period
    r_d = KEEL_BELOW_CG - h_d / 2
    q_t = RHO * W_R * X_T * W ** 2 / 2
    A = q_t * (W * W_R / (2 * h_d) + H_R)
    C = q_t * G_ACC
    return dict(A=A, C=C, a=q_t * (r_d + H_R), c=q_t * G_ACC, B=2 * ZETA * math.sqrt(A * C), q_t=q_t,
                h_d=h_d, t_roll=t_roll, fluid_mass=RHO * X_T * (2 * W_R * H_R + W * h_d))


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
    m = matrices(scenario_tables()["port_hamiltonian"])
    want = dict(J=[[0, 1], [-1, 0]], R=[[0, 0], [0, B]], Q=[[C, 0], [0, 1 / A]], G=[[c / C - a / A], [0]],
                P=[[0], [-a * B / A]], S=[[a * a * B / A ** 2]])
    for name, value in want.items():
        np.testing.assert_allclose(m[name], value, rtol=1e-12, atol=0, err_msg=name)
    J, R, Q, P, S = m["J"], m["R"], m["Q"], m["P"], m["S"]
    np.testing.assert_array_equal(J, -J.T)
    np.testing.assert_array_equal(R, R.T)
    np.testing.assert_array_equal(Q, Q.T)
    assert np.linalg.eigvalsh(Q).min() > 0
    big = np.block([[R, P], [P.T, S]])
    assert np.linalg.eigvalsh(big).min() >= -1e-12 * np.abs(big).max()
    # The design rule: the tank's natural period on the roll period, a few per cent of the
    # displacement in the tank.
    assert math.isclose(2 * math.pi * math.sqrt(A / C), k["t_roll"], rel_tol=1e-12)
    assert 0.01 < k["fluid_mass"] / PAPER["mass"] < 0.05


def test_the_port_hamiltonian_form_is_lloyds_tank():
    """At random states: ẋ of the PH form is Lloyd's tank equation, y is minus the tank's moment
    on the reduced hull, the storage plus the reduced hull's energy is the whole energy, and the
    dissipation booked is b τ'²."""
    k = lloyd_coefficients()
    A, B, C, a, c = k["A"], k["B"], k["C"], k["a"], k["c"]
    m = matrices(scenario_tables()["port_hamiltonian"])
    I, K = PAPER["roll_inertia"], PAPER["mass"] * G_ACC * PAPER["gm"]
    rng = np.random.default_rng(7)
    for phi, dphi, ddphi, tau, dtau in rng.normal(scale=[0.05, 0.03, 0.02, 0.1, 0.05], size=(20, 5)):
        ddtau = (-a * ddphi - c * phi - B * dtau - C * tau) / A        # Lloyd's tank equation
        x = np.array([tau + c / C * phi, A * dtau + a * dphi])
        u = np.array([dphi])
        xdot = (m["J"] - m["R"]) @ m["Q"] @ x + (m["G"] - m["P"]) @ u
        np.testing.assert_allclose(xdot, [dtau + c / C * dphi, A * ddtau + a * ddphi], rtol=1e-9, atol=1e-9 * abs(x[1]))
        y = (m["G"] + m["P"]).T @ m["Q"] @ x + (m["N"] + m["S"]) @ u
        # The moment on the hull with the fluid frozen is -a τ'' - c τ; on the reduced hull
        # (I - a²/A, K - c²/C) it is that less (a²/A) φ'' + (c²/C) φ, the terms the reduced
        # hull's inertia and stiffness no longer hold.
        moment = -a * ddtau - c * tau - a * a / A * ddphi - c * c / C * phi
        np.testing.assert_allclose(-y[0], moment, rtol=1e-9, atol=1e-6)
        whole = 0.5 * I * dphi ** 2 + a * dtau * dphi + 0.5 * A * dtau ** 2 + 0.5 * K * phi ** 2 + c * tau * phi + 0.5 * C * tau ** 2
        reduced = 0.5 * (I - a * a / A) * dphi ** 2 + 0.5 * (K - c * c / C) * phi ** 2
        assert math.isclose(0.5 * x @ m["Q"] @ x + reduced, whole, rel_tol=1e-12)
        z = np.concatenate([m["Q"] @ x, u])
        big = np.block([[m["R"], m["P"]], [m["P"].T, m["S"]]])
        assert math.isclose(z @ big @ z, B * dtau ** 2, rel_tol=1e-9, abs_tol=1e-9 * B * dtau ** 2 + 1e-12)


def test_the_vessel_file_holds_the_rigid_body_less_the_fluids_share():
    k = lloyd_coefficients()
    v = scenario_tables()["vessel"]
    assert v["from"] == "paper"
    assert math.isclose(v["inertia"][0], PAPER["roll_inertia"] - k["a"] ** 2 / k["A"], rel_tol=1e-12)
    assert math.isclose(v["gm_transverse"], PAPER["gm"] - k["c"] ** 2 / (k["C"] * PAPER["mass"] * G_ACC), rel_tol=1e-12)
    assert math.isclose(PAPER["gm"] - v["gm_transverse"], k["q_t"] / PAPER["mass"], rel_tol=1e-12)   # the free surface


def _run(tables: dict, t_end: float):
    path = scenario.resolve("anti-roll-tank")
    sc = scenario.from_dict(tables, path).replace(t_span=(0.0, t_end))
    return phsplit.simulate(sc.vessel, settings=sc.settings)


def test_the_tank_reduces_the_roll_in_the_beam_sea():
    """Same sea, same seed: the scenario, and the scenario with the tank's fluid frozen (the
    paper's vessel, no subsystem). 30 minutes, the first 5 left out."""
    tables = scenario_tables()
    frozen = copy.deepcopy(tables)
    frozen.pop("port_hamiltonian")
    frozen["vessel"] = {"from": "paper"}
    with_tank, without = _run(tables, 1800.0), _run(frozen, 1800.0)
    assert with_tank.status == without.status == "completed"
    keep = with_tank.t >= 300.0
    rms = lambda s: float(np.sqrt(np.mean(s.euler[keep, 0] ** 2)))
    assert rms(without) > np.radians(0.5)          # the sea does excite the roll
    assert rms(with_tank) < 0.9 * rms(without)
    # The ledger closes with the tank's dissipation booked, which is never negative.
    assert with_tank.ledger.relative_residual().max() < 1e-10
    booked = with_tank.ledger.by_account["tank"]
    assert booked.min() >= -1e-9 * np.abs(booked).max() and booked.sum() > 0
    # The subsystem's outputs are its storage and Lloyd's moment, from its states and the roll rate.
    k = lloyd_coefficients()
    A, B, C, a, c = k["A"], k["B"], k["C"], k["a"], k["c"]
    eta, pi = with_tank.outputs["tank_eta"][2], with_tank.outputs["tank_pi"][2]
    p = with_tank.w[:, 0]
    np.testing.assert_allclose(with_tank.outputs["tank_storage"][2], 0.5 * C * eta ** 2 + 0.5 * pi ** 2 / A, rtol=1e-10)
    y = (c / C - a / A) * C * eta - a * B / A * (pi / A) + a * a * B / A ** 2 * p
    np.testing.assert_allclose(with_tank.outputs["tank_force_roll"][2], -y, rtol=1e-9, atol=1e-9 * np.abs(y).max())


def test_the_sway_coupled_form_keeps_the_energy_of_hull_and_fluid():
    """The variant with the inputs (the duct's sway velocity, the roll rate) at the duct's point:
    its matrices pass the checks, and its storage plus the hull with the mass correction b bᵀ/A
    taken off is the whole kinetic energy, at random velocities."""
    k = lloyd_coefficients()
    A, B, C, c, q_t = k["A"], k["B"], k["C"], k["c"], k["q_t"]
    r_d = KEEL_BELOW_CG - k["h_d"] / 2
    a = np.array([q_t, q_t * H_R])                     # tau' (a . u): the duct's and the columns' share
    Q = np.diag([C, 1 / A])
    P = np.array([[0.0, 0.0], -B * a / A])
    S = B * np.outer(a, a) / A ** 2
    big = np.block([[np.diag([0.0, B]), P], [P.T, S]])
    assert np.linalg.eigvalsh(big).min() >= -1e-12 * np.abs(big).max()
    b = np.zeros(6)
    b[1], b[3] = q_t, q_t * (r_d + H_R)
    M = np.diag([PAPER["mass"]] * 3 + [PAPER["roll_inertia"], 2.726143e9, 2.9e9])
    reduced = M - np.outer(b, b) / A
    assert np.linalg.eigvalsh(reduced).min() > 0
    rng = np.random.default_rng(3)
    for nu, dtau in zip(rng.normal(scale=0.3, size=(20, 6)), rng.normal(scale=0.05, size=20)):
        nu[3:] *= 0.1
        u = np.array([nu[1] + r_d * nu[3], nu[3]])      # the duct's sway velocity (point [0, 0, -r_d]), the roll rate
        pi = A * dtau + a @ u
        whole = 0.5 * nu @ M @ nu + dtau * (a @ u) + 0.5 * A * dtau ** 2
        assert math.isclose(0.5 * pi ** 2 / A + 0.5 * nu @ reduced @ nu, whole, rel_tol=1e-12)
        # and the dissipation booked is the duct's loss, B tau'^2
        z = np.concatenate([Q @ np.array([0.0, pi]), u])
        assert math.isclose(z @ big @ z, B * dtau ** 2, rel_tol=1e-8, abs_tol=1e-9 * B * dtau ** 2 + 1e-9)
