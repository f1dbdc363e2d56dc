"""Cummins' fluid memory of the shipped Capytaine box as a port-Hamiltonian subsystem
(phsplit.radiation; docs/explanation/components/fluid-memory.md). References: the dataset's own
K(iw) = B + iw(A - A_inf) read again here with xarray; the subsystem's transfer matrix from its
table's matrices, G^T Q (sI - (J - R)Q)^-1 G; the frequency-domain RAO
[-w^2 (M + A(w)) + iw (B(w) + D) + C]^-1 F(w) written again from the dataset and the paper's
vessel (Fossen 2021, ch. 5); for the orders, the independent model of tests/reference.py
(eq. (39) in numpy with the subsystem and the added mass, by DOP853)."""
from __future__ import annotations

import copy
import math
import os
import warnings

import numpy as np
import phsplit
import pytest
import xarray as xr
from phsplit import hydro, radiation, sea

DATASET = os.path.join(os.path.dirname(phsplit.__file__), "scenarios", "paper_box_capytaine.nc")
DOF = {n: i for i, n in enumerate(("surge", "sway", "heave", "roll", "pitch", "yaw"))}
# The fit's tolerance per main coupling: the largest |K_fit - K| over the dataset's 16
# frequencies, relative to the largest |K| (measured: 0.026, 0.075, 0.113, 0.051, 0.091).
FIT_TOLERANCE = {"heave-heave": 0.04, "roll-roll": 0.10, "pitch-pitch": 0.15, "sway-sway": 0.08, "sway-roll": 0.12}


@pytest.fixture(scope="module")
def memory():
    paper = phsplit.Vessel.paper()
    fm = radiation.fluid_memory(DATASET, vessel=paper)
    return radiation.with_fluid_memory(paper, DATASET, memory=fm), fm


def dataset_K():
    """K(iw) about the centre of gravity, read again from the file: T^T (.) T with T = [[I, S(r)],
    [0, I]], r from the waterline centre (the rotation centre) up to the centre of mass; its
    symmetric part (radiation is reciprocal)."""
    with xr.open_dataset(DATASET) as ds:
        ds = ds.sel(influenced_dof=["Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"],
                    radiating_dof=["Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"])
        w = ds["omega"].values.astype(float)
        A = ds["added_mass"].transpose("omega", "influenced_dof", "radiating_dof").values
        B = ds["radiation_damping"].transpose("omega", "influenced_dof", "radiating_dof").values
        Ainf = ds["added_mass_infinite_frequency"].transpose("influenced_dof", "radiating_dof").values
        r = ds["center_of_mass"].values.reshape(-1)[:3] - ds["rotation_center"].values.reshape(-1)[:3]
    T = np.eye(6)
    T[0:3, 3:6] = [[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]]
    o = np.argsort(w)
    A, B, w = T.T @ A[o] @ T, T.T @ B[o] @ T, w[o]
    Ainf = T.T @ Ainf @ T
    K = B + 1j * w[:, None, None] * (A - Ainf)
    return w, 0.5 * (K + np.transpose(K, (0, 2, 1))), A, B, Ainf


def table_transfer(table, omega):
    J, R, Q, G = (np.array(table[k], float) for k in ("J", "R", "Q", "G"))
    n = len(J)
    return np.array([G.T @ Q @ np.linalg.solve(1j * x * np.eye(n) - (J - R) @ Q, G) for x in omega])


def test_the_subsystem_is_passive_on_a_dense_grid_and_in_its_storage(memory):
    vessel, fm = memory
    t = fm.table
    assert fm.n_states <= 40 and t["name"] == "radiation" and t["input"] == list(DOF)
    J, R, Q = (np.array(t[k], float) for k in ("J", "R", "Q"))
    np.testing.assert_array_equal(J, -J.T)
    assert np.linalg.eigvalsh(R).min() >= 0.0
    assert np.linalg.eigvalsh(Q / np.sqrt(np.outer(np.diag(Q), np.diag(Q)))).min() > 0
    # Re K(iw) >= 0 on 20001 frequencies from 1e-3 to 1e3 rad/s (its eigenvalues, relative)
    w = np.geomspace(1e-3, 1e3, 20001)
    F = fm.transfer(w).real
    ev = np.linalg.eigvalsh(0.5 * (F + np.transpose(F, (0, 2, 1))))
    assert ev.min() >= -1e-12 * np.abs(ev).max(), ev.min()
    # the table's own state space gives the same K (the assembly), on a few frequencies
    ws = np.array([0.05, 0.3, 0.56, 1.0, 1.7, 4.0])
    np.testing.assert_allclose(table_transfer(t, ws), fm.transfer(ws), rtol=0, atol=1e-9 * np.abs(fm.K).max())
    # the storage 1/2 x^T Q x: its rate u^T y - (Qx)^T R (Qx) <= u^T y at random states and inputs
    rng = np.random.default_rng(1)
    G = np.array(t["G"], float)
    for _ in range(20):
        x, u = rng.normal(size=len(J)), rng.normal(size=6)
        e = Q @ x
        rate = e @ ((J - R) @ e + G @ u)
        supplied = u @ (G.T @ e)
        assert math.isclose(rate, supplied - e @ R @ e, rel_tol=1e-9, abs_tol=1e-9 * abs(supplied))
        assert rate <= supplied + 1e-12 * abs(supplied)
    # the vessel: A_inf as its added mass, the paper's damping kept, the subsystem's states its own
    d = vessel.to_dict()
    np.testing.assert_allclose(np.array(d["vessel"]["added_mass"]), fm.added_mass_infinite)
    assert d["vessel"]["damping_translational"] == phsplit.Vessel.paper().to_dict()["vessel"]["damping_translational"]
    assert [s[0] for s in vessel.own_states] == [f"radiation_{x}" for x in t["states"]]


def test_the_fit_against_the_dataset_per_main_coupling(memory):
    _, fm = memory
    w, K, _, _, Ainf = dataset_K()
    np.testing.assert_allclose(fm.omega, w)
    np.testing.assert_allclose(fm.K, K, rtol=0, atol=1e-9 * np.abs(K).max())
    np.testing.assert_allclose(fm.added_mass_infinite, 0.5 * (Ainf + Ainf.T), rtol=0, atol=1e-9 * np.abs(Ainf).max())
    F = fm.transfer(w)
    for name, tol in FIT_TOLERANCE.items():
        a, b = (DOF[x] for x in name.split("-"))
        err = np.abs(F[:, a, b] - K[:, a, b]).max() / np.abs(K[:, a, b]).max()
        assert err <= tol, (name, err)
        assert math.isclose(fm.report[name]["max"], err, rel_tol=1e-9)
    # heave-pitch: zero by the box's fore-aft symmetry, so dropped; and what is dropped is small
    a, b = DOF["heave"], DOF["pitch"]
    assert np.abs(K[:, a, b]).max() < 1e-12 * math.sqrt(np.abs(K[:, a, a]).max() * np.abs(K[:, b, b]).max())
    assert "heave-pitch" in fm.dropped and max(fm.dropped.values()) < 1e-3


def frequency_rao(w, i, beta, waves):
    """[-w^2 (M + A) + iw (B + D) + C]^-1 F at the dataset's i-th frequency, heading beta (deg)."""
    p = phsplit.Vessel.paper().to_dict()["vessel"]
    m = p["mass"]
    M = np.diag([m, m, m, *p["inertia"]])
    D = np.diag([*p["damping_translational"], *p["damping_rotational"]])
    g, rho = p["gravity"], p["water_density"]
    C = np.diag([0, 0, rho * g * p["waterplane_area"], m * g * p["gm_transverse"], m * g * p["gm_longitudinal"], 0])
    _, _, A, B, _ = dataset_K()
    j = int(np.argmin(np.abs(np.asarray(waves["rao_directions"]) - beta)))
    F = np.asarray(waves["force_rao_real"])[j, i] + 1j * np.asarray(waves["force_rao_imag"])[j, i]
    return np.linalg.solve(-w * w * (M + A[i]) + 1j * w * (B[i] + D) + C, F)


def test_regular_wave_response_matches_the_frequency_domain_rao_and_the_ledger_closes(memory):
    """Controller off, one regular wave of 0.1 m, SP4 at h = 0.5 s for 600 s: the heave, roll and
    pitch amplitudes over the last ten periods within 5 % of the frequency-domain RAO wherever it
    is at least 5 % of its peak over these frequencies (measured: within 2.9 %)."""
    vessel, _ = memory
    waves = {k: v for k, v in hydro.from_capytaine(DATASET, symmetric=True)["waves"].items()
             if k in ("rao_frequencies", "rao_directions", "force_rao_real", "force_rao_imag")}
    wd = np.asarray(waves["rao_frequencies"])
    omegas = (0.44, 0.56, 0.68, 1.04, 1.40)
    a = 0.1
    worst = 0.0
    for beta in (90.0, 180.0):
        ref = {w: np.abs(frequency_rao(w, int(np.argmin(np.abs(wd - w))), beta, waves)[[2, 3, 4]]) for w in omegas}
        peak = np.max(list(ref.values()), axis=0)
        for w in omegas:
            d = vessel.to_dict()
            d["waves"] = {**waves, **sea.regular(a, w, direction=beta)}
            v = phsplit.Vessel.from_dict(d)
            y0 = v.initial_state(euler=[0, 0, 0], position=[0, 0, 0], velocity=[0, 0, 0], angular_velocity=[0, 0, 0])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", phsplit.SettingWarning)
                s = phsplit.simulate(v, (0.0, 600.0), 0.5, "sp4", control_start=None, initial=y0, save_every=1)
            assert s.status == "completed"
            assert s.ledger.relative_residual().max() < 1e-10
            assert np.all(s.ledger.by_account["radiation"] >= 0.0)
            keep = s.t >= 600.0 - 10 * 2 * math.pi / w
            t = s.t[keep]
            X = np.c_[np.cos(w * t), np.sin(w * t), np.ones_like(t)]
            for k, sig in enumerate((s.x[keep, 2], s.euler[keep, 0], s.euler[keep, 1])):
                if not (peak[k] > 1e-6 and ref[w][k] >= 0.05 * peak[k]):
                    continue
                c, *_ = np.linalg.lstsq(X, sig, rcond=None)
                dev = math.hypot(c[0], c[1]) / a / ref[w][k] - 1
                worst = max(worst, abs(dev))
                assert abs(dev) < 0.05, (beta, w, ("heave", "roll", "pitch")[k], dev)
    assert worst > 0


def _broken(change):
    with xr.open_dataset(DATASET) as f:
        ds = f.load()
    change(ds)
    return ds


def _scale_damping(dof, factor):
    def change(ds):
        sel = dict(influenced_dof=dof, radiating_dof=dof)
        ds["radiation_damping"].loc[sel] = ds["radiation_damping"].loc[sel] * factor
    return change


def _zero_radiation(dof):
    def change(ds):
        for name in ("added_mass", "radiation_damping"):
            ds[name].loc[dict(influenced_dof=dof)] = 0.0
            ds[name].loc[dict(radiating_dof=dof)] = 0.0
        ds["added_mass_infinite_frequency"].loc[dict(influenced_dof=dof)] = 0.0
        ds["added_mass_infinite_frequency"].loc[dict(radiating_dof=dof)] = 0.0
    return change


@pytest.mark.parametrize("change,words", [
    (_scale_damping("Heave", -1.0), "radiation damping of heave-heave is negative"),
    (_zero_radiation("Yaw"), "retardation of yaw-yaw is zero at every frequency"),
])
def test_a_bad_dataset_is_refused_naming_the_coupling(change, words):
    ds = _broken(change)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hydro.HydroDataWarning)
        with pytest.raises(phsplit.InvalidInputError, match=words):
            radiation.fluid_memory(ds, checks="warn")


def test_a_vessel_with_a_subsystem_already_is_refused():
    d = phsplit.Vessel.paper().to_dict()
    d["port_hamiltonian"] = {"name": "tank", "states": ["q", "p"], "input": ["roll"], "J": [[0.0, 1.0], [-1.0, 0.0]],
                             "R": [[0.0, 0.0], [0.0, 1.0]], "Q": [[1.0, 0.0], [0.0, 1.0]], "G": [[0.0], [1.0]]}
    with pytest.raises(phsplit.InvalidInputError, match="already has a port-Hamiltonian subsystem"):
        radiation.with_fluid_memory(phsplit.Vessel.from_dict(d), DATASET)


def test_the_scenario_key_switches_it_on_and_a_second_subsystem_is_refused(memory):
    """``fluid_memory = true`` in dp-weather's [environment.waves]: the vessel gets the subsystem
    and A_inf (the same fit as Python's, the origin at the dataset's centre of mass, which is the
    paper vessel's), and a short run's ledger closes; with the anti-roll tank it is refused."""
    from phsplit import scenario

    _, fm = memory
    data = scenario._read_toml(scenario.resolve("dp-weather"), "scenario file")
    data["environment"]["waves"]["fluid_memory"] = True
    data["simulation"]["t_span"] = [0.0, 20.0]
    sc = scenario.from_dict(data, scenario.resolve("dp-weather"))
    d = sc.vessel.to_dict()
    assert d["port_hamiltonian"]["states"] == fm.table["states"]
    np.testing.assert_allclose(np.array(d["port_hamiltonian"]["G"]), np.array(fm.table["G"]), rtol=1e-12, atol=0)
    np.testing.assert_allclose(np.array(d["vessel"]["added_mass"]), fm.added_mass_infinite, rtol=1e-12, atol=0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.SettingWarning)
        s = phsplit.simulate(sc.vessel, settings=sc.settings)
    assert s.status == "completed" and s.ledger.relative_residual().max() < 1e-10
    tank = scenario._read_toml(scenario.resolve("anti-roll-tank"), "scenario file")
    tank["environment"]["waves"]["fluid_memory"] = True
    with pytest.raises(phsplit.InvalidInputError, match="already has a port-Hamiltonian subsystem"):
        scenario.from_dict(tank, scenario.resolve("anti-roll-tank"))
    bad = copy.deepcopy(data)
    bad["environment"]["waves"]["fluid_memory"] = "yes"
    with pytest.raises(phsplit.ScenarioParseError, match="fluid_memory must be true or false"):
        scenario.from_dict(bad, scenario.resolve("dp-weather"))


# -- orders against the independent model (tests/reference.py: eq. (39) in numpy with the
# [port_hamiltonian] table and the added mass A_inf, by DOP853 at rtol 1e-13) ----------------

ORDER_T_END = 2.0
ORDER_HS = 2.0 ** -np.arange(1, 6)


def kicked_start() -> np.ndarray:
    """The paper's initial state with momenta in every direction (as test_port_hamiltonian's)."""
    y0 = phsplit.Vessel.paper().initial_state()
    y0[0:3] = [2e6, -1e6, 1e6]
    y0[3:6] = [1e6, 2e6, -3e6]
    return y0


@pytest.fixture(scope="module")
def reference_end(memory):
    import reference as ref

    vessel, fm = memory
    _, y = ref.solve(vessel.to_dict(), kicked_start(), ORDER_T_END, 0.0, rtol=1e-13)
    assert y.shape[1] == 27 + fm.n_states
    return y[-1]


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_the_memory_against_the_independent_model(memory, reference_end, method, order):
    """The paper's vessel with the whole 40-state memory and A_inf, the controller on from a kicked
    start for 2 s: the largest relative error of p, m, x and the memory's states at the end, at
    h = 1/2 ... 1/32 s, falls with the method's order (measured: slopes 1.995 and 3.996)."""
    vessel, fm = memory
    states = [f"radiation_{x}" for x in fm.table["states"]]
    want = np.concatenate([reference_end[0:6], reference_end[18:21], reference_end[27:]])
    errs = []
    for h in ORDER_HS:
        s = phsplit.simulate(vessel, (0.0, ORDER_T_END), h, method, control_start=0.0, ledger=False,
                             initial=kicked_start(), project_invariants=False)
        assert s.status == "completed" and s.t[-1] == ORDER_T_END
        got = np.concatenate([s.p[-1], s.m[-1], s.x[-1], [s.outputs[k][2][-1] for k in states]])
        errs.append(max(np.linalg.norm(got[a:b] - want[a:b]) / np.linalg.norm(want[a:b])
                        for a, b in ((0, 3), (3, 6), (6, 9), (9, len(want)))))
    errs = np.array(errs)
    keep = errs > 1e-13
    assert keep.sum() >= 3, errs
    slope = np.polyfit(np.log(ORDER_HS[keep]), np.log(errs[keep]), 1)[0]
    print(f"{method}: slope {slope:.3f}, errors {errs}")
    assert abs(slope - order) < 0.3, (slope, errs)
    assert errs[-1] < (1e-3 if order == 2 else 1e-7), errs


@pytest.mark.parametrize("h", [1.0, "nyquist"])
def test_sp2_with_the_memory_in_a_sea_for_an_hour_within_its_passivity_bound(h):
    """dp-weather (its JONSWAP sea, wind and current, DP on) with ``fluid_memory = true``, SP2 at
    h = 1 s and at the longest step that still resolves the sea, the Nyquist step pi/omega_max of
    its highest component (2 rad/s: 1.571 s), for one hour: the ledger closes per step,
    H(t) - H(0) <= supplied work, and the account ``radiation`` books >= 0 in every interval
    (and something)."""
    from checks import within_passivity_bound
    from phsplit import scenario

    data = scenario._read_toml(scenario.resolve("dp-weather"), "scenario file")
    data["environment"]["waves"]["fluid_memory"] = True
    if h == "nyquist":
        h = math.pi / max(data["environment"]["waves"]["omega_range"])
    n = int(math.ceil(3600.0 / h))
    data["simulation"].update(t_span=[0.0, n * h], h=h, method="sp2", save_every=1)
    sc = scenario.from_dict(data, scenario.resolve("dp-weather"))
    assert max(sc.vessel.to_dict()["waves"]["frequencies"]) <= math.pi / h + 1e-12   # resolved
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.SettingWarning)
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)   # the memory's 2.2 s modes, unresolved
        s = phsplit.simulate(sc.vessel, settings=sc.settings)
    assert s.status == "completed" and len(s.t) == n + 1
    assert s.ledger.relative_residual().max() < 1e-10
    assert within_passivity_bound(s)
    booked = s.ledger.by_account["radiation"]
    assert s.ledger.kinds["radiation"] == "dissipated"
    assert np.all(booked[1:] >= 0.0) and booked.sum() > 0.0
    print(f"residual {s.ledger.relative_residual().max():.2e}, radiation {booked.sum():.4g} J, "
          f"H(T) - H(0) - supplied {s.energy[-1] - s.energy[0] - s.ledger.supplied.sum():.4g} J")
