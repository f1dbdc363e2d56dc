"""The run settings have one definition, the core's (``crates/phsplit-core/src/settings.rs``:
its keys, their defaults, their validation). The front ends expose it: the Python ``Settings``
has exactly its keys with its defaults, ``simulate`` takes each as a keyword, and the vessel
FMU has a parameter for each setting that applies to a co-simulation step. A setting added to
the core and not to a front end fails here, naming it."""
from __future__ import annotations

import dataclasses
import inspect

import phsplit
from phsplit import _core, fmu

#: Settings that name the run or its saving, not how a step is taken: not FMU parameters (the
#: master's communication steps and its own files take their place).
NOT_IN_AN_FMU = {"t_span", "save_every", "name"}
#: Adaptive steps: the FMU takes its fixed internal step within each communication step, and
#: exporting a scenario with a tolerance is refused (``phsplit.fmu.export``).
NOT_IN_AN_FMU |= {"rtol", "atol", "h_max"}


def core_keys() -> set[str]:
    return {k for k, _ in _core.settings_keys()}


def test_python_settings_are_the_cores_keys_with_its_defaults():
    fields = {f.name: f.default for f in dataclasses.fields(phsplit.Settings)}
    assert set(fields) == core_keys() - {"name"}, set(fields) ^ (core_keys() - {"name"})
    defaults = _core.default_settings()
    for k, v in fields.items():
        want = defaults[k]
        assert (list(v) if isinstance(v, tuple) else v) == (list(want) if isinstance(want, tuple) else want), k


def test_simulate_takes_every_setting_as_a_keyword():
    params = inspect.signature(phsplit.simulate).parameters
    missing = (core_keys() - {"name"}) - set(params)
    assert not missing, missing


def test_the_vessel_fmu_has_a_parameter_for_every_step_setting():
    sim = {"method": "sp2", "h": 0.5, "linear_flow": "exact", "outer": "conservative",
           "project_invariants": False, "control_start": 0.0}
    table = _core.fmu_variables('[fmu]\nkind = "vessel"\n\n' + fmu._toml({"simulation": sim}),
                                phsplit.Vessel.paper().to_toml())
    names = {v["name"] for v in table}
    missing = {k for k in core_keys() - NOT_IN_AN_FMU if k not in names}
    assert not missing, (missing, sorted(n for n in names if "." not in n))


def test_the_default_flow_s2_is_chosen_by_the_vessel():
    """``linear_flow = "auto"`` (the default): the exact S2 on the paper's vessel at fixed steps,
    Gauss with adaptive steps, with a general mass matrix, with a forcing, or with component
    states; with a forcing and a second-order splitting at fixed steps, Gauss of order 4; the
    result says which ran, and a named flow is taken as named."""
    def ran(v, **kw):
        return phsplit.simulate(v, (0.0, 2.0), 0.5, "sp2", **kw).meta["s2_solver"]

    assert phsplit.Settings().linear_flow == "auto"
    paper = phsplit.Vessel.paper()
    assert ran(paper) == "exact" and ran(paper, linear_flow="gauss") == "gauss"
    assert ran(paper, atol=1e-3) == "gauss" and ran(paper, atol=1e-3, linear_flow="exact") == "exact"
    osv = phsplit.Vessel.preset("osv")
    assert ran(osv) == "gauss4"  # general M and cross-flow drag, a forcing: order 4 for sp2
    assert ran(osv, atol=1e-3) == "gauss"  # adaptive steps: the method's order
    assert phsplit.simulate(osv, (0.0, 2.0), 0.5, "sp4").meta["s2_solver"] == "gauss"  # order 4 already
    assert phsplit.simulate(osv, (0.0, 2.0), 0.5, "lie").meta["s2_solver"] == "gauss"  # order 1
    d = paper.to_dict()
    d["current"] = {"velocity": [0.3, 0.0, 0.0]}
    assert ran(phsplit.Vessel.from_dict(d)) == "exact"  # a steady current: affine, exact acts
    d["current"] = {"times": [0.0, 100.0], "velocities": [[0.0, 0.0, 0.0], [0.3, 0.0, 0.0]]}
    assert ran(phsplit.Vessel.from_dict(d)) == "gauss4"  # a forcing in time
    tank = phsplit.scenario.load(phsplit.scenario.resolve("anti-roll-tank")).vessel
    assert ran(tank) == "gauss"  # a subsystem's own states
