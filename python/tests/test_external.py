"""The external-load component (a constant force and moment at a point of the hull; docs/model.md
§5): from Python, a scenario file and the CLI; booked as its own port in the ledger; checked
against the independent numpy model (tests/reference.py) and a closed-form steady state."""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

import phsplit
import reference as ref
from phsplit.cli import main

LOAD = {"force": [3.0e5, -2.0e5, 0.0], "moment": [0.0, 0.0, 4.0e6], "point": [-30.0, 4.0, 2.0], "frame": "spatial"}


def loaded(**load) -> phsplit.Vessel:
    d = phsplit.Vessel.paper().to_dict()
    d["external"] = {**LOAD, **load}
    return phsplit.Vessel.from_dict(d)


def test_the_component_is_registered_and_booked_as_a_port():
    v = loaded()
    assert v.components == ["damping", "restoring", "pid", "external"]
    assert ("external", "supplied") in v.accounts
    assert "external" not in phsplit.Vessel.paper().components
    assert v.to_dict()["external"]["frame"] == "spatial"


@pytest.mark.parametrize("method", ["sp2", "lie"])
@pytest.mark.parametrize("linear_flow", ["exact", "gauss"])
def test_ledger_closes_with_the_external_port(method, linear_flow):
    """Positive steps (Prop. 2.2): dH = supplied - dissipated per step to 1e-10 relative, with the
    external port booked apart from the controller's."""
    s = phsplit.simulate(loaded(), (0.0, 500.0), 0.5, method, control_start=50.0, linear_flow=linear_flow)
    assert s.status == "completed"
    assert s.ledger.relative_residual().max() <= 1e-10
    ext = s.ledger.by_account["external"]
    assert np.abs(ext).max() > 1e3  # it does work on the vessel
    sup = sum(s.ledger.by_account[a] for a, k in s.ledger.kinds.items() if k == "supplied")
    dis = sum(s.ledger.by_account[a] for a, k in s.ledger.kinds.items() if k == "dissipated")
    np.testing.assert_allclose(sup, s.ledger.supplied, rtol=1e-13, atol=1e-9)
    np.testing.assert_allclose(dis, s.ledger.dissipated, rtol=1e-13, atol=1e-9)
    assert np.all(s.ledger.by_account["damping"][1:] > 0)


@pytest.mark.parametrize("h", [5.0, 20.0, 50.0])
@pytest.mark.parametrize("control_start", [None, 0.0])
def test_exact_s2_ledger_closes_at_rest_beside_a_set_point_under_a_load(h, control_start):
    """A state 1e-9 m from the set point at rest under a body-frame load: the load's forcing
    dwarfs the state. The exact S2's long steps (the matrix exponential's fallback among them)
    kept the ledger to 1e-7 only while the fallback saw the constant coordinate scaled to the state
    (a review's finding); it closes to round-off now, as Gauss does."""
    v = loaded(force=[2e5, -1e5, 3e4], moment=[1e6, 0.0, -2e6], point=[-40.0, 5.0, 3.0], frame="body")
    init = {"euler": [0.05, -0.02, 0.1], "position": [780.0 + 1e-9, 20.0, 0.0]}
    with pytest.warns(phsplit.StepSizeWarning):
        s = phsplit.simulate(v, (0.0, 2 * h), h, "lie", control_start=control_start, linear_flow="exact",
                             initial=init)
    assert s.status == "completed"
    assert s.ledger.relative_residual().max() <= 1e-12


def test_force_and_moment_outputs_are_the_load_in_the_body_frame():
    s = phsplit.simulate(loaded(), (0.0, 20.0), 0.5, "sp2")
    f, m, r = (np.array(LOAD[k]) for k in ("force", "moment", "point"))
    fb = np.einsum("nji,j->ni", s.Q, f)  # Q^T f
    mb = np.einsum("nji,j->ni", s.Q, m) + np.cross(r, fb)
    np.testing.assert_allclose(s.force("external"), fb, rtol=1e-12, atol=1e-6)
    np.testing.assert_allclose(s.moment("external"), mb, rtol=1e-12, atol=1e-4)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_the_load_against_the_independent_model(method, order):
    """SP2 and SP4 keep their orders with the load on; the reference is the numpy model of
    eq. (39) plus the load, by DOP853 at rtol 1e-13 (no phsplit code)."""
    v = loaded()
    y0 = v.initial_state()
    _, y = ref.solve(v.to_dict(), y0, 2.0, 0.0, rtol=1e-13)
    xe, pe = y[-1][18:21], y[-1][0:3]
    for project in (False, True):
        hs, errs = [], []
        for k in range(1, 6):
            h = 2.0 ** -k
            s = phsplit.simulate(v, (0.0, 2.0), h, method, control_start=0.0, ledger=False,
                                 project_invariants=project, linear_flow="exact")
            hs.append(h)
            errs.append(np.linalg.norm(s.p[-1] - pe) / np.linalg.norm(pe))
        errs = np.array(errs)
        keep = errs > 1e-12
        slope = np.polyfit(np.log(np.array(hs)[keep]), np.log(errs[keep]), 1)[0]
        if project:  # order kept, error constants changed: see test_acceptance's order test
            assert order - 0.2 <= slope <= order + 1.0, (slope, errs)
        else:
            assert abs(slope - order) < 0.2, (slope, errs)
    # and the finest run agrees with the reference position to well within a millimetre: the
    # paper's scheme (exact S2, no projection) to 1e-6 m; with the projection onto the restoring
    # invariant, whose error constant in x is larger on short runs (docs/model.md §3.6), to
    # 1e-5 m; with the defaults (Gauss S2 and the projection), to 1e-4 m
    s = phsplit.simulate(v, (0.0, 2.0), 2.0**-5, method, control_start=0.0, ledger=False,
                         project_invariants=False, linear_flow="exact")
    assert np.linalg.norm(s.x[-1] - xe) < 1e-6
    s = phsplit.simulate(v, (0.0, 2.0), 2.0**-5, method, control_start=0.0, ledger=False,
                         linear_flow="exact")
    assert np.linalg.norm(s.x[-1] - xe) < 1e-5
    s = phsplit.simulate(v, (0.0, 2.0), 2.0**-5, method, control_start=0.0, ledger=False)
    assert np.linalg.norm(s.x[-1] - xe) < 1e-4


def test_the_controller_holds_position_against_a_constant_force():
    """Closed form: at rest with the set point reached, the integral action balances the load,
    Ki phi_x = F (spatial x, y), and the position error vanishes."""
    f = np.array([2.0e5, -1.0e5, 0.0])
    v = loaded(force=f.tolist(), moment=[0.0, 0.0, 0.0], point=[0.0, 0.0, 0.0])
    s = phsplit.simulate(v, (0.0, 6000.0), 1.0, "sp2", control_start=0.0, linear_flow="gauss", save_every=100)
    ki = np.array(v.to_dict()["control"]["ki_translational"])
    xr_ = np.array(v.to_dict()["control"]["position_reference"])
    np.testing.assert_allclose(ki[:2] * s.phi_x[-1, :2], f[:2], rtol=1e-3)
    assert np.linalg.norm(s.x[-1, :2] - xr_[:2]) < 1e-2


def test_scenario_file_and_cli(tmp_path, capsys):
    sc = tmp_path / "pushed.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 60.0]\nh = 0.5\nmethod = "sp2"\ncontrol_start = 0.0\n\n'
                  '[external]\nforce = [1.0e5, 0.0, 0.0]\npoint = [-40.0, 0.0, 3.0]\nframe = "spatial"\n')
    from phsplit import scenario

    loaded_sc = scenario.load(sc)
    assert loaded_sc.vessel.components[-1] == "external"
    assert main(["simulate", str(sc), "--out", str(tmp_path), "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "external" in out and "components: damping, restoring, pid, external" in out
    with phsplit.open_dataset(tmp_path / "pushed.nc") as ds:
        assert "energy_external" in ds and "force_external" in ds
        direct = phsplit.simulate(loaded_sc.vessel, settings=loaded_sc.settings)
        np.testing.assert_array_equal(ds["position"].values, direct.x)
        np.testing.assert_array_equal(ds["energy_external"].values, direct.ledger.by_account["external"])


def test_a_scenario_table_overrides_the_vessel_key_by_key(tmp_path):
    """A [control] table alone changes the paper's vessel (it used to be ignored)."""
    sc = tmp_path / "gain.toml"
    sc.write_text("[control]\nkp_translational = [8e5, 8e5, 0.0]\n")
    from phsplit import scenario

    v = scenario.load(sc).vessel
    assert v.to_dict()["control"]["kp_translational"] == [8e5, 8e5, 0.0]
    assert v.to_dict()["control"]["ki_translational"] == phsplit.Vessel.paper().to_dict()["control"]["ki_translational"]
    a = phsplit.simulate(v)
    b = phsplit.simulate(phsplit.Vessel.paper())
    assert np.abs(a.x[-1] - b.x[-1]).max() > 1e-3
