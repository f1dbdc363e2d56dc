"""Thrust and azimuth rate limits (docs/model.md §5.8). What rate-limited thrusters
deliver is a memory the state carries from step to step. Checked here: the limits hold at every
step while they bind; a ramp from rest matches its closed form; limits that never bind change
nothing; a run cut into calls, or continued from a saved state, is the same run; the ledger
books what the thrusters deliver and closes; bad rate data and Runge-Kutta methods are refused
with messages."""
from __future__ import annotations

import copy

import numpy as np
import pytest

import phsplit
from phsplit.results import run_chunks
from test_operation import OSV_THRUSTERS, vessel

TURN = 10.0  # degrees/s: an illustrative azimuth turning rate (36 s for a full turn)


def limited(thrust_fraction=0.1, turn=TURN, tunnels=True):
    """The OSV's thrusters with thrust rates `thrust_fraction` of their capacity per second and
    the azimuths turning at `turn` degrees/s (illustrative values, not a published vessel's)."""
    th = copy.deepcopy(OSV_THRUSTERS)
    for u in th["unit"]:
        if u["kind"] == "azimuth" or tunnels:
            u["thrust_rate"] = thrust_fraction * u["max_thrust"]
        if u["kind"] == "azimuth":
            u["turn_rate"] = turn
    return th


def outputs(s):
    return {k: s.outputs[k][2] for k in s.outputs}


@pytest.mark.parametrize("method,h", [("sp2", 0.5), ("sp4", 0.5), ("sp2", 2.0)])
def test_rate_limits_hold_at_every_step(method, h):
    """The paper's run starts 80 m off its set point: the demand jumps far beyond what the
    thrusters can follow. At every step a tunnel thruster's thrust changes by at most its rate
    times the step, an azimuth's force vector too (so its thrust as well), and an azimuth turns by
    at most its turning rate times the step; each limit binds often."""
    th = limited()
    v = vessel(thrusters=th)
    s = phsplit.simulate(v, (0.0, 300.0), h, method, control_start=0.0)
    assert s.status == "completed"
    o = outputs(s)
    n = len(th["unit"])
    thrust, angle = s.actuators[:, 1:1 + n], s.actuators[:, 1 + n:]
    for i, u in enumerate(th["unit"]):
        reach = u["thrust_rate"] * h
        if u["kind"] == "azimuth":
            f = thrust[:, i, None] * np.column_stack([np.cos(angle[:, i]), np.sin(angle[:, i])])
            change = np.linalg.norm(np.diff(f, axis=0), axis=1)
            turn = np.abs((np.diff(angle[:, i]) + np.pi) % (2 * np.pi) - np.pi)
            assert turn.max() <= np.radians(TURN) * h * (1 + 1e-9), (i, turn.max())
            assert (turn >= np.radians(TURN) * h * (1 - 1e-9)).sum() >= 3, i
            assert np.all(thrust[:, i] >= 0.0)
        else:
            change = np.abs(np.diff(thrust[:, i]))
        assert change.max() <= reach * (1 + 1e-9), (i, change.max() / reach)
        assert (change >= reach * (1 - 1e-9)).sum() >= 5, i  # the limit binds
        assert np.abs(np.diff(thrust[:, i])).max() <= reach * (1 + 1e-9)
        assert np.all(np.abs(thrust[:, i]) <= u["max_thrust"] * (1 + 1e-12))
        # what the outputs report is the memory the state carries
        np.testing.assert_allclose(o[f"thruster{i}_thrust"], thrust[:, i], rtol=1e-14, atol=1e-9)
    np.testing.assert_array_equal(s.actuators[:, 0], s.t)
    # the ledger books what they deliver, and closes
    assert np.all(s.ledger.relative_residual() < 1e-10)
    k = list(s.ledger.by_account).index("thrusters")
    dlv = np.column_stack([o["delivered_surge"], o["delivered_sway"]])
    np.testing.assert_allclose(s.account_force[:, k, :2], dlv, rtol=0, atol=1e-6 * np.abs(dlv).max())


@pytest.mark.parametrize("turn", [None, TURN])
def test_a_command_that_reverses_is_followed_through_zero(turn):
    """Thrust rates on every thruster, with and without the azimuths' turning rate, on the
    shipped pipe-lay scenario, whose surge demand changes sign within seconds: an azimuth's
    force passes through small values instead of jumping, so flow S2's fixed point converges
    and the run completes at the scenario's step and at a tenth of it."""
    import tomllib
    from importlib import resources

    sc = tomllib.loads(resources.files("phsplit").joinpath("scenarios/pipelay.toml").read_text())
    th = copy.deepcopy(sc["thrusters"])
    for u in th["unit"]:
        u["thrust_rate"] = 3.0e4
        if turn and u["kind"] == "azimuth":
            u["turn_rate"] = turn
    tables = {k: sc[k] for k in ("setpoint", "pipe")}
    v = vessel(thrusters=th, **tables)
    y0 = v.initial_state(**sc["initial"])
    for h in (0.5, 0.05):
        s = phsplit.simulate(v, (0.0, 60.0), h, "sp2", control_start=0.0, initial=y0)
        assert s.status == "completed", (h, s.failure)
        assert np.all(s.ledger.relative_residual() < 1e-10)

def test_a_ramp_from_rest_is_the_closed_form():
    """Controller off until t = 10 s: the thrusters idle. Then, 1 km off the set point, the
    demand jumps beyond their capacity and stays there; each tunnel thruster ramps at its rate,
    T(t) = r (t - 10) (sign of the command), for the 6 s that follow (it would need 20 s to
    reach its capacity): the closed form, at every step, to round-off."""
    th = limited(thrust_fraction=0.05)
    v = vessel(thrusters=th)
    y0 = v.initial_state(position=[780.0 + 700.0, 20.0 - 700.0, 0.0])
    h = 0.25
    s = phsplit.simulate(v, (0.0, 16.0), h, "sp4", control_start=10.0, initial=y0)
    assert s.outputs["thrust_utilisation"][2][-1] < 0.5  # far from the command, still ramping
    o = outputs(s)
    before = s.t <= 10.0
    for i, u in enumerate(th["unit"]):
        assert np.all(o[f"thruster{i}_thrust"][before] == 0.0), i
    after = s.t > 10.0
    r = 0.05 * 300e3
    for i in (0, 1):  # the tunnels: the demand of the paper's start asks far more than 6 s of ramp
        t_i = o[f"thruster{i}_thrust"][after]
        expect = np.sign(t_i[-1]) * r * (s.t[after] - 10.0)
        np.testing.assert_allclose(t_i, expect, rtol=1e-12, atol=1e-6)


def test_limits_that_never_bind_change_nothing():
    """Rates far above anything the run asks: the results equal those without rate limits, to
    round-off of the thrusters' polar form."""
    free = phsplit.simulate(vessel(thrusters=OSV_THRUSTERS), (0.0, 200.0), 0.5, "sp2", control_start=0.0)
    fast = phsplit.simulate(vessel(thrusters=limited(thrust_fraction=1e9, turn=1e9)), (0.0, 200.0), 0.5, "sp2",
                            control_start=0.0)
    scale = np.abs(free.x).max()
    assert np.abs(fast.x - free.x).max() <= 1e-9 * scale
    np.testing.assert_allclose(fast.p, free.p, rtol=0, atol=1e-9 * np.abs(free.p).max())


def test_a_run_cut_into_calls_or_continued_from_a_state_is_one_run():
    v = vessel(thrusters=limited())
    settings = phsplit.Settings(t_span=(0.0, 60.0), h=0.5, method="sp2", control_start=0.0)
    one = phsplit.simulate(v, settings=settings)
    parts = list(run_chunks(v, settings, v.initial_state(), [40, 50, 30]))
    assert [p.status for p in parts] == ["completed"] * 3
    last = parts[-1]
    np.testing.assert_array_equal(last.state(-1), one.state(-1))
    assert len(one.state(-1)) == 27 + 1 + 2 * 4
    # a user's continuation from a saved state, memory included
    rest = phsplit.simulate(v, initial=one.state(80), settings=phsplit.Settings(
        t_span=(40.0, 60.0), h=0.5, method="sp2", control_start=0.0))
    np.testing.assert_array_equal(rest.state(-1), one.state(-1))
    # outputs at chosen times go through the same memory
    at = phsplit.simulate(v, settings=settings, save_at=[7.25, 30.0])
    assert np.all(np.isfinite(at.actuators)) and at.actuators.shape == (2, 9)
    np.testing.assert_array_equal(at.state(1), one.state(60))


@pytest.mark.parametrize("method,outer,project", [("sp2", "conservative", False), ("sp4", "dissipative", False),
                                                   ("sp2", "dissipative", True)])
def test_what_is_saved_does_not_change_the_run(method, outer, project):
    """The memory is written at every step's end, so no sub-step merges across a step boundary
    with rate-limited thrusters: saving every 4th state, or keeping running maxima, gives the
    same states bitwise."""
    v = vessel(thrusters=limited())
    kw = dict(t_span=(0.0, 120.0), h=0.5, method=method, control_start=0.0, outer=outer, project_invariants=project)
    every = phsplit.simulate(v, settings=phsplit.Settings(**kw, save_every=1))
    some = phsplit.simulate(v, settings=phsplit.Settings(**kw, save_every=4))
    peaks = phsplit.simulate(v, settings=phsplit.Settings(**kw, save_every=4), running_max=True)
    assert every.status == some.status == "completed"
    np.testing.assert_array_equal(some.x, every.x[::4])
    np.testing.assert_array_equal(some.actuators, every.actuators[::4])
    np.testing.assert_array_equal(peaks.x, some.x)


def test_states_with_the_memory_go_where_states_go():
    """Vessel.energy, Vessel.outputs and event conditions take a state with the memory after it."""
    from phsplit import events as E

    v = vessel(thrusters=limited())
    s = phsplit.simulate(v, (0.0, 30.0), 0.5, "sp2", control_start=0.0,
                         events=[E.energy_above(1e30), E.watch_circle(1e6)])
    assert s.status == "completed" and len(s.state(3)) == 36
    assert v.energy(s.state(3)) == pytest.approx(s.energy[3], rel=1e-14)
    assert v.energy(s.state(3)) == v.energy(s.state(3)[:27])


def test_runge_kutta_and_bad_rates_are_refused_with_messages():
    v = vessel(thrusters=limited())
    with pytest.raises(phsplit.InvalidInputError, match="rate-limited thrusters .* stuck ones .* use a splitting method"):
        phsplit.simulate(v, (0.0, 5.0), 0.5, "rk4", control_start=0.0)
    bad = copy.deepcopy(OSV_THRUSTERS)
    bad["unit"][0]["thrust_rate"] = -1.0
    with pytest.raises(phsplit.InvalidInputError, match=r"thrusters.unit\[0\].thrust_rate must be > 0 \(N/s\)"):
        vessel(thrusters=bad)
    bad = copy.deepcopy(OSV_THRUSTERS)
    bad["unit"][0]["turn_rate"] = 10.0  # a tunnel thruster does not turn
    with pytest.raises(phsplit.InvalidInputError, match=r"unknown field `turn_rate` in \[thrusters.unit\[0\]\]"):
        vessel(thrusters=bad)
    many = copy.deepcopy(limited())
    many["unit"] = many["unit"] * 3
    with pytest.raises(phsplit.InvalidInputError, match="at most 8 are kept"):
        vessel(thrusters=many)
    state = v.initial_state()
    with pytest.raises(phsplit.InvalidInputError, match="or 36 with the memory of the vessel's 4 thrusters that keep one"):
        phsplit.simulate(v, (0.0, 1.0), 0.5, "sp2", initial=np.concatenate([state, [0.0, 1.0]]))
    # a memory that is not one a run could have written
    s = phsplit.simulate(v, (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    y = s.state(-1)
    run = lambda y, t0=10.0: phsplit.simulate(v, (t0, t0 + 1.0), 0.5, "sp2", control_start=0.0, initial=y)  # noqa: E731
    assert run(y).status == "completed"
    with pytest.raises(phsplit.InvalidInputError, match=r"memory after the state is at t = 10 s, but the run starts at t0 = 0"):
        run(y, 0.0)
    bad = y.copy()
    bad[27 + 1 + 2] = 1e9  # thruster 2's thrust
    with pytest.raises(phsplit.InvalidInputError, match=r"thruster 2 \(azimuth\) a thrust of 1000000000 N; allowed: 0 to 420000"):
        run(bad)
    bad = y.copy()
    bad[27 + 1 + 4 + 0] = 0.3  # a tunnel thruster's angle is its axis
    with pytest.raises(phsplit.InvalidInputError, match=r"thruster 0 \(tunnel\) an angle of 0.3 rad; allowed: its axis"):
        run(bad)
    bad = y.copy()
    bad[27 + 1 + 4 + 3] = 100.0
    with pytest.raises(phsplit.InvalidInputError, match=r"thruster 3 \(azimuth\) an angle of 100 rad"):
        run(bad)


def test_the_fmu_carries_the_memory_across_communication_steps(tmp_path):
    """An FMU of the pipe-lay scenario with rate-limited thrusters: its communication steps (1 s,
    two internal steps) continue the memory, so its positions are simulate's."""
    from dataclasses import replace
    from importlib import resources

    from fmpy import simulate_fmu

    from phsplit import fmu, scenario

    text = resources.files("phsplit").joinpath("scenarios/pipelay.toml").read_text()
    text = text.replace("max_thrust = 3.0e5\n", "max_thrust = 3.0e5\nthrust_rate = 3.0e4\n")
    text = text.replace("max_thrust = 4.2e5\n", "max_thrust = 4.2e5\nthrust_rate = 3.0e4\nturn_rate = 10.0\n")
    assert text.count("thrust_rate") == 3
    (tmp_path / "rl.toml").write_text(text)
    sc = scenario.load(str(tmp_path / "rl.toml"))
    r = simulate_fmu(str(fmu.export(sc, tmp_path / "rl.fmu")), stop_time=60.0, output_interval=1.0,
                     output=["position.x", "position.y"])
    sol = phsplit.simulate(sc.vessel, settings=replace(sc.settings, t_span=(0.0, 60.0), save_every=2))
    assert sol.actuators is not None and np.allclose(sol.t, r["time"])
    np.testing.assert_allclose(r["position.x"], sol.x[:, 0], rtol=1e-12)
    np.testing.assert_allclose(r["position.y"], sol.x[:, 1], rtol=1e-12)


def test_a_thrusters_numbers_can_be_swept():
    """Sweeps address a table of a list: `thrusters.unit[i].name`, also a rate the unit does
    not have yet; a case equals the simulation of its vessel, and bad paths are named."""
    base = vessel(thrusters=OSV_THRUSTERS)
    cases = [{"thrusters.unit[0].max_thrust": 2.0e5, "thrusters.unit[2].turn_rate": 5.0},
             {"thrusters.unit[3].position[1]": -6.0},
             {"thrusters.unit[0].turn_rate": 5.0}]  # a tunnel thruster does not turn
    ds = phsplit.simulate_many(cases, base=base, t_span=(0.0, 20.0), h=0.5, method="sp2", control_start=0.0)
    assert list(ds.status.values) == ["completed", "completed", "invalid"]
    assert "turn_rate" in ds["error"].values[2] and "thrusters.unit[0]" in ds["error"].values[2]
    v = phsplit.with_parameters(base, cases[0])
    units = v.to_dict()["thrusters"]["unit"]
    assert units[0]["max_thrust"] == 2.0e5 and units[2]["turn_rate"] == 5.0
    direct = phsplit.simulate(v, (0.0, 20.0), 0.5, "sp2", control_start=0.0)
    np.testing.assert_array_equal(ds.position.values[0], direct.x)
    for path, words in [("thrusters.unit[7].max_thrust", r"index 7 out of range \(0..3\)"),
                        ("thrusters.unit[0].max_thrus", "unknown field `max_thrus` in \\[thrusters.unit\\[0\\]\\]; "
                                                        "did you mean 'max_thrust'"),
                        ("thrusters.unit[0]", "thrusters.unit\\[0\\] is a table: name one of its numbers"),
                        ("thrusters.unit.max_thrust", "thrusters.unit is a list: give an index there"),
                        ("thrusters.unit", r"a list of 4 tables: give an index and a name, e\.g\. thrusters\.unit\[0\]\.max_thrust"),
                        ("thrusters.unit[0].position", r"thrusters\.unit\[0\]\.position is a 3-vector: give one index"),
                        ("control.kp_rotational[2].x", r"control\.kp_rotational\[2\] is a number: end the path there")]:
        with pytest.raises(phsplit.InvalidInputError, match=words):
            phsplit.with_parameters(base, {path: 1.0})


def test_a_continued_run_reruns_from_its_file(tmp_path):
    """A run continued from a saved state records the thrusters' memory in its file's
    initial_state, so `rerun` repeats it bitwise."""
    v = vessel(thrusters=limited())
    a = phsplit.simulate(v, (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    b = phsplit.simulate(v, (10.0, 20.0), 0.5, "sp2", control_start=0.0, initial=a.state(-1))
    b.to_xarray().to_netcdf(tmp_path / "b.nc")
    with phsplit.open_dataset(tmp_path / "b.nc") as ds:
        assert ds["initial_state"].size == 36
        assert phsplit.results.compare(ds, phsplit.rerun(ds)) == []
