"""The dynamic pipe (docs/model.md §5.18): a lumped-mass line with states of its own, hung from the
hang-off point of the hull as a power port. Checked against the independent model of
tests/reference_pipe.py (the line of Hall & Goupee 2015, MoorDyn's, written again in numpy and
coupled to tests/reference.py's vessel, integrated by scipy's Radau): SP2's order; then the
shipped pipelay-dynamic scenario for an hour at h = 0.5 s and 1 s within the passivity bound
with the ledger closing per step; the results' node arrays and profile; the driven line's
energy; and the table's checks through the front doors."""
from __future__ import annotations

import subprocess
import sys
from functools import lru_cache

import numpy as np
import pytest

import phsplit
import reference_pipe as rp
from checks import within_passivity_bound

#: The line of the MoorDyn comparison, shortened to 10 segments for the reference's speed.
PIPE = {"model": "lumped_mass", "length": 600.0, "segments": 10, "axial_stiffness": 3.0e9, "mass": 120.0,
        "diameter": 0.3, "water_depth": 200.0, "hang_off": [-40.0, 0.0, -10.0], "anchor": [143.8, -4.0]}


def vessel(**pipe) -> phsplit.Vessel:
    d = phsplit.Vessel.paper().to_dict()
    d["control"]["euler_reference"] = [0.0, 0.0, 0.10]
    d["control"]["position_reference"] = [723.0, 0.0, 0.0]
    d["pipe"] = {**PIPE, **pipe}
    return phsplit.Vessel.from_dict(d)


def full_initial(v: phsplit.Vessel) -> np.ndarray:
    """The initial state with the line's own states (its static shape under the hang-off)."""
    return phsplit.simulate(v, (0.0, 0.5), 0.5, "sp2", control_start=0.0).state(0)


#: For the order: the anchor 560 m from the hang-off point, the line suspended all along (its
#: lowest node 2.6 m above the seabed): a node touching down or lifting off is a kink of the
#: forces, which no method of order 2 crosses at its order.
SUSPENDED = {"anchor": [123.2, -4.0]}


@lru_cache(maxsize=None)
def reference_end(t_end: float):
    v = vessel(**SUSPENDED)
    y0 = full_initial(v)
    n = PIPE["segments"] - 1
    nodes = y0[30:30 + 3 * n].reshape(n, 3)
    _, y, q, vel = rp.solve_coupled(v.to_dict(), None, y0[:27], nodes, t_end, control_start=0.0)
    return y0, y[-1], q[-1], vel[-1]


def test_sp2_has_order_two_against_the_independent_model():
    """SP2 on the hull and the line against Radau at rtol 1e-11 on the separately written
    model: the hull's momentum and the nodes' positions converge with slope 2. The order is
    the asymptotic one, at steps that resolve the line's axial period (0.1 s for these 60 m
    segments; at the vessel's steps the discrete gradient keeps the energy, not the phase, of
    the axial waves)."""
    t_end = 2.0
    y0, yv, q, _ = reference_end(t_end)
    v = vessel(**SUSPENDED)
    hs = np.array([0.0025, 0.00125, 0.000625])
    errs_p, errs_q = [], []
    n = PIPE["segments"] - 1
    for h in hs:
        s = phsplit.simulate(v, (0.0, t_end), h, "sp2", control_start=0.0, ledger=False, initial=y0,
                             project_invariants=False)
        errs_p.append(np.linalg.norm(s.p[-1] - yv[0:3]) / np.linalg.norm(yv[0:3]))
        qn = s.own[-1][3:3 + 3 * n].reshape(n, 3)
        errs_q.append(np.abs(qn - q).max())
    for errs in (errs_p, errs_q):
        slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
        assert 1.8 < slope < 2.3, (slope, errs)
    assert errs_q[-1] < 1e-3  # m


def test_the_reference_agrees_with_phsplit_on_the_static_shape():
    """Both solve the static equilibrium by Newton's method from their own catenary guess."""
    v = vessel()
    y0 = full_initial(v)
    n = PIPE["segments"] - 1
    mine = y0[30:30 + 3 * n].reshape(n, 3)
    theirs = rp.initial_pipe(v.to_dict(), None, y0[:27])
    assert np.abs(mine - theirs).max() < 1e-6


@pytest.mark.parametrize("h", [0.5, 1.0])
def test_the_pipelay_scenario_keeps_its_ledger_for_an_hour(h):
    """The shipped pipelay-dynamic scenario (waves, wind, current, the 800 m line), an hour at
    the vessel's step: completed, within the passivity bound, the ledger closing per step to
    1e-10 of H, the port's two sides cancelling, the line's storage in H."""
    sc = phsplit.load_scenario("pipelay-dynamic")
    s = phsplit.simulate(sc.vessel, (0.0, 3600.0), h, "sp2", control_start=0.0, save_every=1)
    assert s.status == "completed"
    assert within_passivity_bound(s)
    rel = np.abs(s.ledger.residual) / np.abs(s.energy)
    assert rel.max() < 1e-10, rel.max()
    a = s.ledger.by_account
    assert abs(a["pipe_on_vessel"].sum() + a["vessel_on_pipe"].sum()) < 1e-9 * np.abs(a["pipe_on_vessel"]).sum()
    # H holds the line: the vessel's energy at the last state is the run's.
    y = np.concatenate([s.state(-1)])
    assert sc.vessel.energy(y) == pytest.approx(s.energy[-1], rel=1e-14)
    drift = s.outputs["pipe_hang_off_drift"][2]
    assert drift.max() < 0.1 * h * h * 10, drift.max()


def test_the_results_hold_the_line_as_arrays():
    sc = phsplit.load_scenario("pipelay-dynamic")
    s = phsplit.simulate(sc.vessel, (0.0, 20.0), 0.5, "sp2", control_start=0.0, save_every=4)
    ds = s.to_xarray()
    n = sc.vessel.to_dict()["pipe"]["segments"] - 1
    assert ds["pipe_node_position"].shape == (len(ds.time), n, 3)
    assert ds["pipe_node_position"].attrs["units"] == "m"
    assert not any(name.startswith("pipe_node1_") for name in ds.data_vars)
    x, z = phsplit.pipe.profile(ds)
    assert z[0, 0] == pytest.approx(ds["pipe_top_z"].values[0])
    assert z[0, -1] == -300.0 and x[0, -1] == 0.0
    # The static shape's top tension: the catenary's, w (a + h) with H = 4e5 N (the scenario's
    # comment), within a percent (the elastic stretch and the lumping).
    w = (259.8 - 1025 * np.pi * 0.4039 ** 2 / 4) * 9.81
    hh = 300.0 - 5.0
    assert ds["pipe_top_tension"].values[0] == pytest.approx(4e5 + w * hh, rel=0.03)


def test_a_driven_line_books_its_energy():
    """phsplit.pipe.drive: what the line stores changes by the work at its top less the
    dissipation, step by step."""
    v = vessel(segments=20, axial_damping=1e5)
    t = np.linspace(0.0, 30.0, 61)
    s = np.sin(0.6 * t)
    tops = np.column_stack([683.0 + 2 * s, -4.0 + 0 * t, -10.0 + s])
    r = phsplit.pipe.drive(v, t, tops)
    booked = r["top_work"] + r["current"] - r["drag"] - r["axial_damping"] - r["seabed"]
    assert np.abs(np.diff(r["storage"]) - booked[1:]).max() < 1e-9 * np.abs(r["storage"]).max()
    assert r["nodes"].shape == (21, 3)
    with pytest.raises(phsplit.InvalidInputError, match="increasing"):
        phsplit.pipe.drive(v, t[::-1], tops)
    with pytest.raises(phsplit.InvalidInputError, match="lumped_mass"):
        phsplit.pipe.drive(phsplit.Vessel.paper(), t, tops)


@pytest.mark.parametrize("key, value, needle", [
    ("segments", 1, "pipe.segments"),
    ("axial_stiffness", -1.0, "pipe.axial_stiffness"),
    ("length", 100.0, "pipe.length"),
    ("hang_off", [-40.0, 0.0, -300.0], "pipe.hang_off"),
    ("model", "fem", "pipe.model"),
])
def test_bad_pipe_data_gets_one_line_naming_the_key(key, value, needle):
    with pytest.raises(phsplit.InvalidInputError, match=needle.replace(".", r"\.")) as e:
        vessel(**{key: value})
    assert "\n" not in str(e.value)


def test_higher_orders_are_refused_before_running():
    with pytest.raises(phsplit.InvalidInputError, match="Strang"):
        phsplit.simulate(vessel(), (0.0, 10.0), 0.5, "sp4", control_start=0.0)


def test_the_cli_refuses_a_bad_pipe_without_a_traceback(tmp_path):
    text = (phsplit.Vessel.paper().to_toml() + "\n[pipe]\n" + "\n".join(
        f"{k} = {v!r}".replace("'", '"') for k, v in {**PIPE, "segments": 1}.items()) + "\n")
    f = tmp_path / "v.toml"
    f.write_text(text)
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-m", "phsplit", "simulate", "--vessel", str(f), "--out", str(out),
                        "--t-end", "10"], capture_output=True, text=True)
    assert r.returncode != 0
    assert "pipe.segments" in r.stderr and "Traceback" not in r.stderr
    assert not out.exists() or not any(out.iterdir())
