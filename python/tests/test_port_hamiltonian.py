"""A linear port-Hamiltonian subsystem with states of its own (the vessel file's
[port_hamiltonian] table): the input-state-output system with feedthrough of van der Schaft &
Jeltsema, Port-Hamiltonian Systems Theory (2014), §4.1,

    x' = (J - R) Q x + (G - P) u,    y = (G + P)^T Q x + (N + S) u,

driven by the hull's velocities u = B nu at its point and acting on it by tau = -B^T y, its
storage 1/2 x^T Q x part of the vessel's H and its dissipation [Qx; u]^T [[R, P], [P^T, S]] [Qx; u]
booked in its own account. Checked against the independent numpy model (tests/reference.py,
DOP853 at rtol 1e-13): the model's own balance first (lossless: H conserved; lossy: H falls by the
dissipation), then SP2 and SP4 at their orders, the ledger and the passivity bound at a long
step, the outputs in the dataset and the FMU's variable table, continued runs, and the checks
of the table."""
from __future__ import annotations

import re
from functools import lru_cache

import numpy as np
import pytest
from scipy.integrate import simpson

import phsplit
import reference as ref
from checks import within_passivity_bound

#: A tuned roll absorber (a tank as a rotational mass on a spring): the relative angle q and the
#: absorber's momentum pi, Q = diag(k, 1/I), J the canonical symplectic matrix, R damping of the
#: momentum, G the hull's roll rate driving q. I = 5e7 kg m^2 (a sixth of the hull's roll
#: inertia), tuned to the roll period 9.21 s, 10 % of critical damping; started away from rest.
_I_TANK = 5.0e7
_W_TANK = 2.0 * np.pi / 9.21
TANK = {"name": "tank", "states": ["angle", "momentum"], "units": ["rad", "kg m2 s-1"],
        "J": [[0.0, -1.0], [1.0, 0.0]], "R": [[0.0, 0.0], [0.0, 2.0 * 0.1 * _W_TANK * _I_TANK]],
        "Q": [[_I_TANK * _W_TANK ** 2, 0.0], [0.0, 1.0 / _I_TANK]], "G": [[1.0], [0.0]],
        "input": ["roll"], "initial": [0.02, 1.0e6]}

#: A translational absorber (2e5 kg on a spring, 0.8 rad/s) driven by the sway velocity of a
#: point off the centre of gravity and by the roll rate, with a non-diagonal Q, a dissipative
#: coupling P, a feedthrough S (a dashpot on both inputs) and a lossless N; default name and units.
_M_FEN, _W_FEN = 2.0e5, 0.8
_R22 = 2.0 * 0.1 * _W_FEN * _M_FEN
FENDER = {"states": ["q1", "q2"],
          "J": [[0.0, -1.0], [1.0, 0.0]], "R": [[0.0, 0.0], [0.0, _R22]],
          "Q": [[_M_FEN * _W_FEN ** 2, 0.2], [0.2, 1.0 / _M_FEN]], "G": [[1.0, -2.0], [0.0, 0.0]],
          "P": [[0.0, 0.0], [2.0e4, 1.0e5]], "S": [[1.0e5, 1.0e5], [1.0e5, 2.0e7]], "N": [[0.0, 5.0e4], [-5.0e4, 0.0]],
          "input": ["sway", "roll"], "point": [30.0, -8.0, 2.0], "initial": [0.5, 2.0e4]}

CASES = {"tank": TANK, "fender": FENDER}

#: A moving set point (as the operation tests'): in the reference its filter's 18 states come
#: first (y[27:45]), the subsystem's after them.
SETPOINT = {"natural_frequency": 0.3, "positions": [[780.0, 20.0, 0.0], [980.0, 55.0, 0.0]], "headings": [0.54, 0.6],
            "speed": 2.0}


def name_of(table: dict) -> str:
    return table.get("name", "port_hamiltonian")


def params(table: dict, setpoint: bool = False, **vessel) -> dict:
    """The paper's vessel (its tables as a dict) with the subsystem, and with ``setpoint`` the
    moving set point (its defaults filled in by phsplit); ``vessel`` overrides keys of its
    [vessel] table."""
    if setpoint:
        pv = phsplit.Vessel.paper().to_dict()
        d = phsplit.Vessel.from_dict({**pv, "setpoint": SETPOINT}).to_dict()
    else:
        d = phsplit.Vessel.paper().to_dict()
    d["vessel"] = {**d["vessel"], **vessel}
    d["port_hamiltonian"] = {k: (list(v) if isinstance(v, list) else v) for k, v in table.items()}
    return d


def coupled(table: dict, setpoint: bool = False) -> phsplit.Vessel:
    return phsplit.Vessel.from_dict(params(table, setpoint))


def kicked_start() -> np.ndarray:
    """The paper's initial state with momenta in every direction (as the spring's order tests)."""
    y0 = phsplit.Vessel.paper().initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]
    y0[3:6] = [1e6, 2e6, -3e6]
    return y0


def port(table: dict, xc: np.ndarray, nu: np.ndarray):
    """(u, y, storage) of the subsystem at its states xc (N, n) and the hull's body velocities nu
    (N, 6), from the table alone (the spec's B, y = (G + P)^T Q x + (N + S) u)."""
    k = len(table["input"])
    n = len(table["states"])
    Q, G = np.array(table["Q"], float), np.array(table["G"], float)
    P = np.array(table.get("P", np.zeros((n, k))), float)
    NS = np.array(table.get("N", np.zeros((k, k))), float) + np.array(table.get("S", np.zeros((k, k))), float)
    r = np.array(table.get("point", [0.0] * 3), float)
    B = np.zeros((k, 6))
    for i, dof in enumerate(table["input"]):
        j = ("surge", "sway", "heave", "roll", "pitch", "yaw").index(dof)
        if j < 3:
            B[i, :3], B[i, 3:] = np.eye(3)[j], -ref.hat(r)[j]
        else:
            B[i, j] = 1.0
    u = nu @ B.T
    e = xc @ Q.T
    y = e @ (G + P) + u @ NS.T
    return u, y, 0.5 * np.einsum("ni,ni->n", xc, e)


def own_states(s: phsplit.Solution, table: dict) -> np.ndarray:
    """The subsystem's states (N, n) at the saved times, from the outputs ``<name>_<state>``."""
    return np.column_stack([s.outputs[f"{name_of(table)}_{st}"][2] for st in table["states"]])


# -- the reference model's own balance (no phsplit integration) --------------------------------

def test_the_block_dissipation_matrices_of_the_cases_are_positive_semidefinite():
    """The cases are valid subsystems: J skew, R and S symmetric, Q positive definite and
    [[R, P], [P^T, S]] positive semidefinite (with a margin where it is not singular by design)."""
    for table in CASES.values():
        n, k = len(table["states"]), len(table["input"])
        J, R, Q = (np.array(table[key], float) for key in ("J", "R", "Q"))
        P = np.array(table.get("P", np.zeros((n, k))), float)
        S = np.array(table.get("S", np.zeros((k, k))), float)
        assert np.array_equal(J, -J.T) and np.array_equal(R, R.T) and np.array_equal(S, S.T)
        assert np.linalg.eigvalsh(Q).min() > 0
        block = np.block([[R, P], [P.T, S]])
        assert np.linalg.eigvalsh(block).min() >= -1e-12 * np.abs(block).max()


@pytest.mark.parametrize("case", list(CASES))
def test_reference_lossless_subsystem_conserves_the_total_energy(case):
    """R = P = S = 0 (N kept: it is lossless), no hull damping, controller off: the hull and the
    subsystem only exchange energy, so H_total (hull + 1/2 x^T Q x) is constant, while the
    subsystem's storage itself changes by a good part of it."""
    table = {**CASES[case], "R": np.zeros((2, 2)).tolist()}
    table.pop("P", None)
    table.pop("S", None)
    d = params(table, damping_translational=[0.0] * 3, damping_rotational=[0.0] * 3)
    f = ref.Field(d, False)
    t, y = ref.solve(d, kicked_start(), 20.0, None, t_eval=np.linspace(0.0, 20.0, 201))
    assert y.shape[1] == 29
    H = np.array([f.energy(yi) for yi in y])
    storage = np.array([0.5 * yi[27:] @ np.array(table["Q"]) @ yi[27:] for yi in y])
    assert np.abs(H - H[0]).max() <= 1e-10 * H[0], np.abs(H - H[0]).max() / H[0]
    assert np.ptp(storage) > 1e-3 * H[0], (np.ptp(storage), H[0])


@pytest.mark.parametrize("case", list(CASES))
def test_reference_subsystem_loses_exactly_its_dissipation(case):
    """No hull damping, controller off: H_total(t) - H_total(0) = -int_0^t [Qx; u]^T [[R, P],
    [P^T, S]] [Qx; u] dt (the integral by Simpson's rule on 2001 points of the DOP853 solution);
    and pointwise, y^T u - d/dt (1/2 x^T Q x) is that rate (the power balance of §4.1)."""
    table = CASES[case]
    d = params(table, damping_translational=[0.0] * 3, damping_rotational=[0.0] * 3)
    f = ref.Field(d, False)
    t, y = ref.solve(d, kicked_start(), 10.0, None, t_eval=np.linspace(0.0, 10.0, 2001))
    H = np.array([f.energy(yi) for yi in y])
    rate = np.array([f.ph_dissipation(yi) for yi in y])
    assert rate.min() >= 0.0
    lost = simpson(rate, x=t)
    assert lost > 1e-4 * H[0]
    assert abs((H[0] - H[-1]) - lost) <= 1e-8 * lost, (H[0] - H[-1], lost)
    Q = np.array(table["Q"], float)
    for yi in y[::400]:
        xc, e, u, yc = f.ph_port(yi)
        dHc = e @ f(0.0, yi)[27:]
        assert abs(yc @ u - dHc - f.ph_dissipation(yi)) <= 1e-12 * (abs(yc @ u) + abs(dHc))
        np.testing.assert_allclose(e, Q @ xc)


def test_reference_input_is_the_velocity_of_the_point_and_the_load_acts_there():
    """The fender's u = (sway velocity of its point, v + w x r; roll rate), and its load on the
    hull the force -y_sway e_y at the point with its moment r x f, plus the moment -y_roll e_x."""
    d = params(FENDER, damping_translational=[0.0] * 3, damping_rotational=[0.0] * 3)
    bare = params({**FENDER, "G": [[0.0, 0.0], [0.0, 0.0]], "P": [[0.0, 0.0], [0.0, 0.0]],
                   "S": [[0.0, 0.0], [0.0, 0.0]], "N": [[0.0, 0.0], [0.0, 0.0]]},
                  damping_translational=[0.0] * 3, damping_rotational=[0.0] * 3)
    f, f0 = ref.Field(d, False), ref.Field(bare, False)
    y = np.concatenate([kicked_start(), FENDER["initial"]])
    v, w, r = y[0:3] / f.mv, y[3:6] / f.T, np.array(FENDER["point"])
    _, _, u, yc = f.ph_port(y)
    np.testing.assert_allclose(u, [(v + np.cross(w, r))[1], w[0]], rtol=1e-14)
    force = np.array([0.0, -yc[0], 0.0])
    dy, dy0 = f(0.0, y), f0(0.0, y)
    np.testing.assert_allclose(dy[0:3] - dy0[0:3], force, rtol=1e-12, atol=1e-9 * abs(yc[0]))
    np.testing.assert_allclose(dy[3:6] - dy0[3:6], np.cross(r, force) - [yc[1], 0.0, 0.0], rtol=1e-12,
                               atol=1e-9 * np.abs(yc).max() * 31)
    # with every coupling zero the hull is the reference without the table
    np.testing.assert_array_equal(dy0[:27], ref.Field(phsplit.Vessel.paper().to_dict() | {"vessel": bare["vessel"]},
                                                      False)(0.0, y[:27]))


# -- phsplit against the reference ----------------------------------------------------------

T_END = 2.0
HS = 2.0 ** -np.arange(1, 6)


@lru_cache(maxsize=None)
def reference_end(case: str, setpoint: bool) -> np.ndarray:
    """The reference's state at T_END from the kicked start, controller on from t = 0."""
    _, y = ref.solve(params(CASES[case], setpoint), kicked_start(), T_END, 0.0, rtol=1e-13)
    assert y.shape[1] == 27 + 18 * setpoint + len(CASES[case]["states"])
    return y[-1]


def errors(case: str, method: str, linear_flow: str, setpoint: bool = False) -> np.ndarray:
    """The largest relative error of p, m, x and the subsystem's states at T_END, at each step HS."""
    table, ye = CASES[case], reference_end(case, setpoint)
    v = coupled(table, setpoint)
    out = []
    for h in HS:
        s = phsplit.simulate(v, (0.0, T_END), h, method, control_start=0.0, ledger=False, initial=kicked_start(),
                             project_invariants=False, linear_flow=linear_flow)
        assert s.status == "completed" and s.t[-1] == T_END
        got = np.concatenate([s.p[-1], s.m[-1], s.x[-1], own_states(s, table)[-1]])
        want = np.concatenate([ye[0:6], ye[18:21], ye[-len(table["states"]):]])
        out.append(max(np.linalg.norm(got[a:b] - want[a:b]) / np.linalg.norm(want[a:b])
                       for a, b in ((0, 3), (3, 6), (6, 9), (9, 11))))
    return np.array(out)


def assert_order(errs: np.ndarray, order: int):
    keep = errs > 1e-13  # as checks.fitted_order: the steps above round-off
    assert keep.sum() >= 3, errs
    slope = np.polyfit(np.log(HS[keep]), np.log(errs[keep]), 1)[0]
    assert abs(slope - order) < 0.3, (slope, errs)
    assert errs[-1] < (1e-3 if order == 2 else 1e-8), errs  # loose: the slope is the check


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
@pytest.mark.parametrize("linear_flow", ["exact", "gauss"])
def test_orders_with_the_subsystem_against_the_independent_model(case, method, order, linear_flow):
    assert_order(errors(case, method, linear_flow), order)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_the_subsystem_and_a_moving_set_point(method, order):
    assert_order(errors("tank", method, "gauss", setpoint=True), order)


def test_the_account_books_the_dissipation_and_the_outputs_are_the_port():
    """SP4 at h = 1/32 s: the account `tank` (kind dissipated) over 2 s equals the reference's
    int [Qx; u]^T [[R, P], [P^T, S]] [Qx; u] dt; at every saved state the outputs are the port
    written out from the table: the storage 1/2 x^T Q x, the power y^T u, the forces -y_i."""
    for case, table in CASES.items():
        d = params(table)
        v = phsplit.Vessel.from_dict(d)
        assert (name_of(table), "dissipated") in v.accounts, v.accounts
        h = 2.0 ** -5
        s = phsplit.simulate(v, (0.0, T_END), h, "sp4", control_start=0.0, initial=kicked_start(),
                             linear_flow="exact")
        f = ref.Field(d, True)
        t, y = ref.solve(d, kicked_start(), T_END, 0.0, t_eval=np.linspace(0.0, T_END, 1025))
        want = simpson(np.array([f.ph_dissipation(yi) for yi in y]), x=t)
        booked = s.ledger.by_account[name_of(table)]
        assert np.all(booked[1:] >= 0.0), case
        assert abs(booked[1:].sum() - want) <= 1e-9 * want, (case, booked[1:].sum(), want)
        assert s.ledger.relative_residual().max() < 1e-10, case
        xc = own_states(s, table)
        u, yc, storage = port(table, xc, np.hstack([s.v, s.w]))
        o = {k: s.outputs[k][2] for k in s.outputs}
        nm = name_of(table)
        np.testing.assert_allclose(o[f"{nm}_storage"], storage, rtol=1e-12, err_msg=case)
        np.testing.assert_allclose(o[f"{nm}_power"], np.einsum("ni,ni->n", yc, u), rtol=1e-9,
                                   atol=1e-12 * np.abs(yc * u).max(), err_msg=case)
        for i, dof in enumerate(table["input"]):
            np.testing.assert_allclose(o[f"{nm}_force_{dof}"], -yc[:, i], rtol=1e-12,
                                       atol=1e-12 * np.abs(yc[:, i]).max(), err_msg=f"{case} {dof}")
        # the storage is part of the vessel's H: H = (the hull's H of eq. 35) + 1/2 x^T Q x
        hull = ref.Field(phsplit.Vessel.paper().to_dict(), True)
        H_hull = np.array([hull.energy(s.state(i)[:27]) for i in range(len(s.t))])
        np.testing.assert_allclose(s.energy, H_hull + storage, rtol=1e-12, err_msg=case)


def test_sp2_within_its_passivity_bound_for_an_hour_at_a_long_step():
    """SP2 at h = 20 s for an hour, the controller on from the start and the tank coupled: the
    ledger closes per step, H(t) - H(0) <= supplied work, and the tank's account books a
    dissipation >= 0 at every step that is not zero."""
    v = coupled(TANK)
    with pytest.warns(phsplit.StepSizeWarning):  # h beyond half the shortest period, on purpose
        s = phsplit.simulate(v, (0.0, 3600.0), 20.0, "sp2", control_start=0.0, linear_flow="exact")
    assert s.status == "completed" and s.t[-1] == 3600.0 and len(s.t) == 181
    assert s.ledger.relative_residual().max() < 1e-10
    assert within_passivity_bound(s)
    booked = s.ledger.by_account["tank"]
    assert s.ledger.kinds["tank"] == "dissipated"
    assert np.all(booked[1:] >= 0.0)
    # it dissipates a good part of its start's storage, 1/2 x0^T Q x0
    x0 = np.array(TANK["initial"])
    assert booked.sum() > 0.1 * 0.5 * x0 @ np.array(TANK["Q"]) @ x0, booked.sum()


# -- outputs, the FMU's variables, continued runs -------------------------------------------

def expected_outputs(table: dict) -> dict[str, str]:
    """The outputs the spec names, with their units."""
    nm = name_of(table)
    units = table.get("units", ["1"] * len(table["states"]))
    out = {f"{nm}_{st}": u for st, u in zip(table["states"], units)}
    out[f"{nm}_storage"], out[f"{nm}_power"] = "J", "W"
    for dof in table["input"]:
        out[f"{nm}_force_{dof}"] = "N" if dof in ("surge", "sway", "heave") else "N m"
    return out


@pytest.mark.parametrize("case", list(CASES))
def test_the_outputs_reach_the_dataset_with_their_units(case):
    table = CASES[case]
    s = phsplit.simulate(coupled(table), (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    ds = s.to_xarray()
    for name, unit in expected_outputs(table).items():
        assert name in ds, (name, sorted(ds.data_vars))
        assert ds[name].attrs["units"] == unit, (name, ds[name].attrs["units"], unit)
        assert ds[name].dims == ("time",) and np.all(np.isfinite(ds[name].values)), name
    # the states start at the table's initial values
    np.testing.assert_array_equal(own_states(s, table)[0], table["initial"])
    assert "energy_" + name_of(table) in ds


def test_the_outputs_are_in_the_fmu_variable_table():
    """The FMU's variable table (what the exporter writes into modelDescription.xml), without
    packing an FMU: every output of the subsystem as an output, with its unit, and its account."""
    from phsplit import _core
    from phsplit import fmu

    v = coupled(TANK)
    sim = {"method": "sp2", "h": 0.5, "linear_flow": "exact", "outer": "conservative", "project_invariants": False,
           "control_start": 0.0}
    table = _core.fmu_variables('[fmu]\nkind = "vessel"\n\n' + fmu._toml({"simulation": sim}), v.to_toml())
    names = {var["name"]: var for var in table}
    for name, unit in expected_outputs(TANK).items():
        assert name in names, (name, sorted(n for n in names if n.startswith("tank")))
        assert names[name]["causality"] == "output", name
    assert names["tank_storage"]["unit"] == "J" and names["tank_power"]["unit"] == "W"
    assert "ledger.tank" in names and names["ledger.tank"]["causality"] == "output"


#: The blocks of a state that continues a run: p, m, Q, mu, x, phi_th, phi_x, the own states.
BLOCKS = [(0, 3), (3, 6), (6, 15), (15, 18), (18, 21), (21, 24), (24, 27), (27, None)]


def same_to_round_off(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two states agree to 1e-12 of each block's size."""
    return len(a) == len(b) and all(np.abs(a[i:j] - b[i:j]).max() <= 1e-12 * np.abs(b[i:j]).max() + 1e-300
                                    for i, j in BLOCKS)


def test_a_continued_run_is_one_run():
    """A run cut into calls (run_chunks, as the CLI and rerun run), or continued by the user from
    a saved state, equals one run to round-off: the state that continues it (Solution.state,
    last_good_state) is the 27 numbers, then the subsystem's states."""
    from phsplit.chunks import run_chunks

    v = coupled(FENDER)
    settings = phsplit.Settings(t_span=(0.0, 60.0), h=0.5, method="sp2", control_start=0.0)
    one = phsplit.simulate(v, settings=settings)
    parts = list(run_chunks(v, settings, v.initial_state(), [40, 50, 30]))
    assert [p.status for p in parts] == ["completed"] * 3
    rest = phsplit.simulate(v, initial=one.state(80), settings=phsplit.Settings(
        t_span=(40.0, 60.0), h=0.5, method="sp2", control_start=0.0))
    # first what a user sees: the position and the subsystem's states at the end
    for what, s in (("chunks", parts[-1]), ("continued", rest)):
        for block, got, want in (("x", s.x[-1], one.x[-1]), ("own", own_states(s, FENDER)[-1], own_states(one, FENDER)[-1])):
            assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max(), (what, block, got, want)
    # the energy continues too: the ledger of the parts adds up to the one run's
    booked = sum(p.ledger.by_account["port_hamiltonian"][1:].sum() for p in parts)
    np.testing.assert_allclose(booked, one.ledger.by_account["port_hamiltonian"][1:].sum(), rtol=1e-12)
    # then the states that continue runs
    assert len(one.last_good_state) == 29 and len(one.state(-1)) == 29, (len(one.last_good_state), len(one.state(-1)))
    np.testing.assert_array_equal(one.state(-1)[27:], own_states(one, FENDER)[-1])
    for got in (parts[-1].last_good_state, rest.state(-1), rest.last_good_state):
        assert same_to_round_off(got, one.state(-1)), (got - one.state(-1))


def test_a_continued_run_reruns_from_its_file(tmp_path):
    """The file of a run continued from a saved state records the subsystem's states in its
    initial_state, so `rerun` repeats it bitwise."""
    v = coupled(TANK)
    a = phsplit.simulate(v, (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    b = phsplit.simulate(v, (10.0, 20.0), 0.5, "sp2", control_start=0.0, initial=a.state(-1))
    b.to_xarray().to_netcdf(tmp_path / "b.nc")
    with phsplit.open_dataset(tmp_path / "b.nc") as ds:
        assert ds["initial_state"].size == 29
        np.testing.assert_array_equal(ds["initial_state"].values[27:], own_states(a, TANK)[-1])
        assert phsplit.results.compare(ds, phsplit.rerun(ds)) == []


def test_runge_kutta_is_refused_with_the_subsystem():
    v = coupled(TANK)
    for method in ("rk4", "heun"):
        with pytest.raises(phsplit.InvalidInputError, match="port_hamiltonian|port-Hamiltonian|tank"):
            phsplit.simulate(v, (0.0, 1.0), 0.5, method, control_start=0.0)


# -- the checks of the table ----------------------------------------------------------------

BASE = {"states": ["q", "pi"], "J": [[0.0, -1.0], [1.0, 0.0]], "R": [[0.0, 0.0], [0.0, 0.1]],
        "Q": [[2.0, 0.0], [0.0, 1.0]], "G": [[1.0], [0.0]], "input": ["roll"]}


def test_the_valid_table_the_bad_ones_change_is_accepted():
    d = phsplit.Vessel.paper().to_dict()
    d["port_hamiltonian"] = dict(BASE)
    v = phsplit.Vessel.from_dict(d)
    assert ("port_hamiltonian", "dissipated") in v.accounts and "port_hamiltonian" in v.components


@pytest.mark.parametrize("change,key", [
    ({"J": [[0.0, -1.0], [0.5, 0.0]]}, "J"),                      # not skew
    ({"J": [[1.0, -1.0], [1.0, 0.0]]}, "J"),                      # a diagonal entry
    ({"R": [[0.0, 0.1], [0.0, 0.1]]}, "R"),                       # not symmetric
    ({"R": [[0.0, 0.0], [0.0, -0.1]]}, "R"),                      # not positive semidefinite
    ({"Q": [[2.0, 0.5], [0.0, 1.0]]}, "Q"),                       # not symmetric
    ({"Q": [[2.0, 0.0], [0.0, 0.0]]}, "Q"),                       # only semidefinite
    ({"Q": [[1.0, 2.0], [2.0, 1.0]]}, "Q"),                       # indefinite
    ({"G": [[1.0], [0.0], [0.0]]}, "G"),                          # 3 rows for 2 states
    ({"G": [[1.0, 0.0], [0.0, 0.0]]}, "G"),                       # 2 columns for 1 input
    ({"J": [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]}, "J"),  # 3x3 for 2 states
    ({"J": [[0.0, -1.0], [1.0]]}, "J"),                           # a short row
    ({"P": [[0.0, 0.0], [0.1, 0.0]]}, "P"),                       # n x 2 for 1 input
    ({"S": [[1.0, 0.0], [0.0, 1.0]]}, "S"),                       # 2 x 2 for 1 input
    ({"input": ["roll", "sway"], "G": [[1.0, 0.0], [0.0, 0.0]], "S": [[1.0, 0.5], [0.2, 1.0]]}, "S"),  # not symmetric
    ({"input": ["roll", "sway"], "G": [[1.0, 0.0], [0.0, 0.0]], "N": [[0.0, 1.0], [1.0, 0.0]]}, "N"),  # not skew
    ({"input": ["rol"]}, "input"),                                # unknown DOF
    ({"input": ["roll", "roll"], "G": [[1.0, 0.0], [0.0, 0.0]]}, "input"),  # twice
    ({"states": ["q", "q"]}, "states"),                           # duplicate names
    ({"states": ["q", "pi"], "initial": [0.0, 0.0, 0.0]}, "initial"),  # 3 values for 2 states
    ({"units": ["rad"]}, "units"),                                # 1 unit for 2 states
    ({"point": [1.0, 2.0]}, "point"),
    ({"J": [[0.0, -np.inf], [np.inf, 0.0]]}, "J"),                # not finite
])
def test_a_bad_matrix_or_list_is_refused_naming_its_key(change, key):
    d = phsplit.Vessel.paper().to_dict()
    d["port_hamiltonian"] = {**BASE, **change}
    with pytest.raises(phsplit.InvalidInputError, match=re.escape(f"port_hamiltonian.{key}")):
        phsplit.Vessel.from_dict(d)


def test_a_dissipation_block_that_is_not_positive_semidefinite_is_refused():
    """R, S each fine (R >= 0, S = 1 > 0) but [[R, P], [P^T, S]] indefinite: S - P^T R^+ P = 1 - 10."""
    d = phsplit.Vessel.paper().to_dict()
    d["port_hamiltonian"] = {**BASE, "P": [[0.0], [1.0]], "S": [[1.0]]}
    with pytest.raises(phsplit.InvalidInputError) as info:
        phsplit.Vessel.from_dict(d)
    msg = str(info.value)
    assert "port_hamiltonian" in msg and re.search(r"\bP\b", msg) and re.search(r"\bS\b", msg), msg
    # with P small enough the block is accepted: S - P^T R^+ P = 1 - 0.3^2 / 0.1 = 0.1
    d["port_hamiltonian"] = {**BASE, "P": [[0.0], [0.3]], "S": [[1.0]]}
    assert ("port_hamiltonian", "dissipated") in phsplit.Vessel.from_dict(d).accounts


@pytest.mark.parametrize("change,words", [
    ({"name": "damping"}, ("port_hamiltonian.name", "damping")),  # another account's name
    ({"name": "tank-1"}, ("port_hamiltonian.name", "tank-1")),    # not letters, digits, underscore
    ({"states": []}, ("port_hamiltonian.states",)),               # no state
])
def test_bad_names_are_refused(change, words):
    d = phsplit.Vessel.paper().to_dict()
    d["port_hamiltonian"] = {**BASE, **change}
    with pytest.raises(phsplit.InvalidInputError) as info:
        phsplit.Vessel.from_dict(d)
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_a_tuned_tank_splits_the_roll_mode_as_the_two_degree_of_freedom_model_says():
    """The natural periods of the vessel with a subsystem are those of the coupled system: a
    U-tube tank (Lloyd's linear model) on the paper's roll splits its 9.2 s mode in two, as the
    2-DOF Lagrangian model [[I, a], [a, A]] q'' + [[K, c], [c, C]] q = 0 of roll and tank says
    (written here from Lloyd's coefficients, not from the port-Hamiltonian form)."""
    d = phsplit.Vessel.paper().to_dict()
    v0 = d["vessel"]
    I, m, g, gm = v0["inertia"][0], v0["mass"], v0["gravity"], v0["gm_transverse"]
    K = m * g * gm
    A, C = 3.3e7, 1.55e7 * (2 * np.pi / 9.2) ** 2 / (1.55e7 / 3.3e7)  # tuned near the roll period
    # undamped (tank and hull's roll), where |λ| of each mode is its natural frequency
    a, c, B = 1.4e7, 1.5e7, 0.0
    d["vessel"] = {**v0, "inertia": [I - a * a / A, *v0["inertia"][1:]], "gm_transverse": (K - c * c / C) / (m * g),
                   "damping_rotational": [0.0, *v0["damping_rotational"][1:]]}
    d["port_hamiltonian"] = {"name": "tank", "states": ["eta", "pi"], "J": [[0.0, 1.0], [-1.0, 0.0]],
                             "R": [[0.0, 0.0], [0.0, B]], "Q": [[C, 0.0], [0.0, 1.0 / A]],
                             "G": [[c / C - a / A], [0.0]], "P": [[0.0], [-a * B / A]], "S": [[a * a * B / A / A]],
                             "input": ["roll"]}
    got = phsplit.Vessel.from_dict(d).natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    w2 = np.linalg.eigvals(np.linalg.solve([[I, a], [a, A]], [[K, c], [c, C]])).real
    want = sorted(2 * np.pi / np.sqrt(w2))
    alone = phsplit.Vessel.paper().natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    assert want[0] < 9.2 < want[1]
    # heave and pitch as without the tank; roll split into the two coupled modes
    np.testing.assert_allclose(sorted(got), sorted([p for p in alone if p < 5.0] + want), rtol=1e-8)


def test_the_fmu_of_a_vessel_with_a_subsystem_validates_and_steps(tmp_path):
    """The FMU of the shipped anti-roll tank: valid for FMPy, every output of the subsystem a
    variable (units the exporter has not seen before, 'W' and 'kg m2 s-1', declared with their
    SI base units), and a short co-simulation with the tank's account booked."""
    fmpy = pytest.importorskip("fmpy")
    from fmpy.validation import validate_fmu

    from phsplit import fmu, scenario

    p = fmu.export(scenario.load("anti-roll-tank"), tmp_path / "tank.fmu")
    assert validate_fmu(str(p)) == []
    md = fmpy.read_model_description(str(p))
    names = {v.name for v in md.modelVariables}
    assert {"tank_eta", "tank_pi", "tank_storage", "tank_power", "ledger.tank", "force_tank.y"} <= names
    units = {u.name: u.baseUnit for u in md.unitDefinitions}
    assert units["W"].kg == 1 and units["W"].m == 2 and units["W"].s == -3
    r = fmpy.simulate_fmu(str(p), stop_time=10.0, output_interval=5.0, output=["tank_storage", "ledger.tank"])
    assert np.all(np.isfinite(r["tank_storage"])) and r["ledger.tank"][-1] > 0.0


def test_export_refuses_a_vessel_where_a_scenario_goes(tmp_path):
    from phsplit import fmu

    with pytest.raises(phsplit.InvalidInputError, match="Scenario"):
        fmu.export(phsplit.Vessel.paper(), tmp_path / "x.fmu")
    assert not (tmp_path / "x.fmu").exists()
