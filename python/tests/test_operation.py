"""The pipe on the stinger as a port, and moving set points through
Fossen's third-order reference model. References: closed forms (the catenary, solved here with
mpmath at 30 digits; the filter's step response by partial fractions), a published example
(MIT OCW 2.019, 2011), the static balance of the controller and the pipe, and the independent
numpy model (tests/reference.py: the catenary by root finding, the filter integrated as an ODE)
by DOP853."""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

import phsplit
from checks import fitted_order

mp.mp.dps = 30


def vessel(**tables):
    d = phsplit.Vessel.paper().to_dict()
    d.update(tables)
    return phsplit.Vessel.from_dict(d)


def upright(v):
    """The vessel's initial state, upright and at rest at its set point."""
    d = v.to_dict()
    return v.initial_state(euler=[0.0, 0.0, 0.0], position=d["control"]["position_reference"],
                           velocity=[0.0, 0.0, 0.0], angular_velocity=[0.0, 0.0, 0.0])


def hang_off_of(sol, k, r):
    return sol.x[k] + sol.Q[k] @ np.asarray(r, float)


def catenary_mp(w, d, X):
    """(H, T, s) of the catenary with span X and height d, in mpmath: a acosh(1 + d/a) = X."""
    w, d, X = mp.mpf(w), mp.mpf(d), mp.mpf(X)
    a = mp.exp(mp.findroot(lambda la: mp.exp(la) * mp.acosh(1 + d / mp.exp(la)) - X, mp.log(X * X / (2 * d) + d)))
    s = mp.sqrt(d * d + 2 * a * d)
    return w * a, w * a + w * d, s


# -- the catenary ----------------------------------------------------------------------------

@pytest.mark.parametrize("depth,span", [(50.0, 180.0), (300.0, 520.0), (2000.0, 1500.0)])
def test_catenary_matches_the_closed_form_at_three_depths(depth, span):
    r = [-60.0, 0.0, 3.0]
    v0 = vessel()
    y0 = upright(v0)
    top = y0[18:21] + np.asarray(r)  # upright: Q = I
    v = vessel(pipe={"submerged_weight": 1200.0, "water_depth": depth, "hang_off": r,
                     "touchdown": [float(top[0] - span), float(top[1])]})
    s = phsplit.simulate(v, (0.0, 1.0), 0.5, "sp2", control_start=None, initial=y0)
    h_top = hang_off_of(s, 0, r)
    d = depth + h_top[2]
    X = math.hypot(h_top[0] - (top[0] - span), h_top[1] - top[1])
    H, T, sl = (float(q) for q in catenary_mp(1200.0, d, X))
    got = {k: s.outputs[k][2][0] for k in ("pipe_horizontal_tension", "pipe_top_tension", "pipe_suspended_length")}
    for name, want in (("pipe_horizontal_tension", H), ("pipe_top_tension", T), ("pipe_suspended_length", sl)):
        assert abs(got[name] - want) <= 1e-9 * want, (name, got[name], want)
    # the force on the vessel: H towards the touchdown point, the suspended weight down
    k = list(s.ledger.by_account).index("pipe")
    f_spatial = s.Q[0] @ s.account_force[0, k]
    np.testing.assert_allclose(f_spatial, [-H, 0.0, -1200.0 * sl], rtol=1e-9, atol=1e-6 * H)


def test_catenary_reproduces_the_published_example():
    """MIT OpenCourseWare 2.019 Design of Ocean Systems (Spring 2011), Lecture 13 'Mooring
    Dynamics (II)', 'Simple Examples': T = 1510 kN, w = 828 N/m, h = 25 m give
    l_min = 300.93 m, T_H = 1489 kN and x = 300 m (printed to these digits)."""
    r = [0.0, 0.0, 0.0]
    v = vessel(pipe={"submerged_weight": 828.0, "water_depth": 25.0, "hang_off": r, "top_tension": 1510e3,
                     "lay_direction": 0.0})
    y0 = upright(v)
    y0[18:21] = [0.0, 0.0, 0.0]
    s = phsplit.simulate(v, (0.0, 1.0), 0.5, "sp2", control_start=None, initial=y0)
    o = {k: s.outputs[k][2][0] for k in s.outputs}
    assert round(o["pipe_suspended_length"], 2) == 300.93
    assert round(o["pipe_horizontal_tension"] / 1e3) == 1489
    assert round(-o["pipe_touchdown_x"]) == 300  # the span to the touchdown point, 3 figures
    assert o["pipe_top_tension"] == pytest.approx(1510e3, rel=1e-15)


def test_the_controller_balances_the_pipe_at_rest():
    """With a constant horizontal tension H along the lay direction and no integral action, the
    vessel comes to rest where the P term balances it: Kp (x - x_ref) = -H e_lay (closed form,
    per axis). With the integral action on, it rests on the set point and Ki phi_x carries H."""
    H, lay = 3.0e5, 30.0
    e = np.array([math.cos(math.radians(lay)), math.sin(math.radians(lay))])
    pipe = {"submerged_weight": 900.0, "water_depth": 200.0, "hang_off": [-50.0, 0.0, 2.0],
            "horizontal_tension": H, "lay_direction": lay}
    d = phsplit.Vessel.paper().to_dict()
    d["pipe"] = pipe
    d["control"] = dict(d["control"], ki_translational=[0.0, 0.0, 0.0], ki_rotational=[0.0, 0.0, 0.0])
    v = phsplit.Vessel.from_dict(d)
    kp = np.array(d["control"]["kp_translational"])
    xr = np.array(d["control"]["position_reference"])
    s = phsplit.simulate(v, (0.0, 6000.0), 1.0, "sp2", control_start=0.0, save_every=600)
    np.testing.assert_allclose(kp[:2] * (s.x[-1, :2] - xr[:2]), -H * e, rtol=1e-6)
    assert np.linalg.norm(s.v[-1]) < 1e-6
    # through the thrusters: the same rest, and the mean thrust balances the pipe's pull
    d["thrusters"] = OSV_THRUSTERS
    vt = phsplit.Vessel.from_dict(d)
    st = phsplit.simulate(vt, (0.0, 6000.0), 1.0, "sp2", control_start=0.0, save_every=600)
    # (the offset itself differs from H/Kp by 1e-5 here: the pipe's weight heels the vessel, and
    # horizontal thrusters do not deliver the demand's component along the tilted body z)
    np.testing.assert_allclose(kp[:2] * (st.x[-1, :2] - xr[:2]), -H * e, rtol=1e-4)
    assert np.linalg.norm(st.v[-1]) < 1e-6
    k = list(st.ledger.by_account).index("thrusters")
    thrust_spatial = st.Q[-1] @ st.account_force[-1, k]
    np.testing.assert_allclose(thrust_spatial[:2], H * e, rtol=1e-6)
    assert st.outputs["thrust_utilisation"][2][-1] < 1.0
    # with integral action: on the set point, Ki phi_x = -H e
    v2 = vessel(pipe=pipe)
    s2 = phsplit.simulate(v2, (0.0, 8000.0), 1.0, "sp2", control_start=0.0, save_every=800)
    ki = np.array(v2.to_dict()["control"]["ki_translational"])
    np.testing.assert_allclose(ki[:2] * s2.phi_x[-1, :2], -H * e, rtol=1e-4)
    assert np.linalg.norm(s2.x[-1, :2] - xr[:2]) < 1e-3


# -- the reference model ---------------------------------------------------------------------

@pytest.mark.parametrize("zeta", [0.6, 1.0, 1.7])
def test_reference_model_step_response_matches_the_closed_form(zeta):
    """x_d/r = w^3/((s + w)(s^2 + 2 zeta w s + w^2)): the unit step response is
    1 + sum_k w^3 e^{p_k t} / (p_k prod_{j != k} (p_k - p_j)) over the poles (partial fractions,
    in mpmath; zeta = 1 has a double pole at -w and is taken as a limit from both sides)."""
    w, t_step, jump = 0.08, 10.0, 100.0
    sp = {"natural_frequency": w, "relative_damping": zeta, "interpolation": "step", "times": [0.0, t_step],
          "positions": [[780.0, 20.0, 0.0], [780.0 + jump, 20.0, 0.0]]}
    v = vessel(setpoint=sp)
    ts = np.array([0.0, 5.0, 10.0, 10.5, 13.0, 25.0, 60.0, 150.0, 400.0])
    s = phsplit.simulate(v, (0.0, 400.0), 0.5, "sp2", control_start=0.0, save_at=ts)

    def closed(t, z):
        z = mp.mpf(z)
        poles = [-w, -z * w + mp.sqrt(z * z - 1) * w, -z * w - mp.sqrt(z * z - 1) * w]
        y = mp.mpf(1)
        for k, pk in enumerate(poles):
            den = pk
            for j, pj in enumerate(poles):
                if j != k:
                    den *= pk - pj
            y += w ** 3 * mp.exp(pk * t) / den
        return float(mp.re(y))

    for t, got in zip(s.t, s.outputs["setpoint_x"][2]):
        if t <= t_step:
            want = 780.0
        elif zeta == 1.0:
            want = 780.0 + jump * 0.5 * (closed(t - t_step, 1 + 1e-12) + closed(t - t_step, 1 - 1e-12))
        else:
            want = 780.0 + jump * closed(t - t_step, zeta)
        assert abs(got - want) <= 1e-9 * jump, (t, got, want)


# -- the ledger and the orders ---------------------------------------------------------------

#: The thrusters of the offshore supply vessel of Fossen's MSS (`VESSELS/models/osv.m`, 2024:
#: two bow tunnel thrusters of 300 kN at x = 37 and 35 m, two stern azimuths of 420 and 655 kN
#: at x = -L/2 = -41.5 m, y = +-7 m; about midships, L = 83 m, B = 18 m), placed 3 m below the
#: body origin: a layout for the tests, not the paper's vessel's (the paper gives none).
OSV_THRUSTERS = {"hull_length": 83.0, "hull_beam": 18.0, "unit": [
    {"kind": "tunnel", "position": [37.0, 0.0, -3.0], "max_thrust": 300e3},
    {"kind": "tunnel", "position": [35.0, 0.0, -3.0], "max_thrust": 300e3},
    {"kind": "azimuth", "position": [-41.5, 7.0, -3.0], "max_thrust": 420e3},
    {"kind": "azimuth", "position": [-41.5, -7.0, -3.0], "max_thrust": 655e3}]}


# The OSV's thrusters with rate limits (illustrative: half the capacity per second, azimuths
# turning at 90 degrees/s) that the runs below never reach (checked where it matters).
RATED_THRUSTERS = dict(OSV_THRUSTERS, unit=[
    dict(u, thrust_rate=0.5 * u["max_thrust"], **({"turn_rate": 90.0} if u["kind"] == "azimuth" else {}))
    for u in OSV_THRUSTERS["unit"]])


def operation_vessel(thrusters=False, speed=2.0):
    """The pipe, a moving set point and, with ``thrusters`` (True, or a thrusters table), thrusters."""
    y_top = upright(vessel())[18:21] + np.array([-60.0, 0.0, 3.0])
    extra = {"thrusters": OSV_THRUSTERS if thrusters is True else thrusters} if thrusters else {}
    return vessel(pipe={"submerged_weight": 1500.0, "water_depth": 300.0, "hang_off": [-60.0, 0.0, 3.0],
                        "touchdown": [float(y_top[0] - 500.0), float(y_top[1] + 30.0)], "lay_speed": 0.5,
                        "lay_direction": 10.0},
                  setpoint={"natural_frequency": 0.3, "positions": [[780.0, 20.0, 0.0], [980.0, 55.0, 0.0]],
                            "headings": [0.54, 0.6], "speed": speed}, **extra)


@pytest.mark.parametrize("method,order,thrusters", [("sp2", 2, False), ("sp4", 4, False), ("sp2", 2, True),
                                                    ("sp4", 4, True), ("sp2", 2, "rated"), ("sp4", 4, "rated")])
def test_orders_with_the_pipe_and_a_moving_set_point_against_the_independent_model(method, order, thrusters):
    if thrusters == "rated":  # rate-limited thrusters whose limits do not bind: the same orders
        thrusters = RATED_THRUSTERS
    v = operation_vessel(thrusters, speed=0.05 if thrusters else 2.0)
    if thrusters:
        # near the set point, so that the thrusters are not saturated (checked below)
        y0 = v.initial_state(position=[779.0, 19.5, 0.0], euler=[0.05, -0.02, 0.5])
        y0[0:3] = [2e5, -1e5, 0.0]
    else:
        y0 = v.initial_state()
        y0[0:3] = [2e6, -1e6, 0.0]
    slope, errs, y_end = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    xe = y_end[18:21]
    assert abs(slope - order) < 0.2, (slope, errs)
    s = phsplit.simulate(v, (0.0, 2.0), 2.0 ** -5, method, control_start=0.0, ledger=False, initial=y0)
    assert np.linalg.norm(s.x[-1] - xe) < (1e-4 if order == 2 else 1e-7)
    if thrusters:
        util = s.outputs["thrust_utilisation"][2]
        assert np.all(util < 1.0) and util.max() > 0.05, util.max()
    if thrusters is RATED_THRUSTERS:
        assert s.actuators is not None
        for i, u in enumerate(RATED_THRUSTERS["unit"]):
            reach = u["thrust_rate"] * 2.0 ** -5
            assert np.abs(np.diff(s.outputs[f"thruster{i}_thrust"][2])).max() < 0.9 * reach, i
            turn = np.abs(np.diff(s.outputs[f"thruster{i}_angle"][2]))  # degrees, no wrap near here
            assert turn.max() < 0.9 * u.get("turn_rate", np.inf) * 2.0 ** -5, i


@pytest.mark.parametrize("method", ["lie", "sp2", "sp4", "sp6"])
@pytest.mark.parametrize("thrusters", [False, True])
def test_the_ledger_books_the_pipe_and_the_controller_and_closes(method, thrusters):
    v = operation_vessel(thrusters)
    assert ("pipe", "supplied") in v.accounts
    s = phsplit.simulate(v, (0.0, 120.0), 0.5, method, control_start=5.0)
    assert np.all(s.ledger.relative_residual() < 1e-10), method
    assert np.all(s.ledger.dissipated[1:] >= 0)
    ports = ["pipe", "thrusters"] if thrusters else ["pipe", "control"]
    for port in ports:
        assert np.any(s.ledger.by_account[port][1:] != 0), port
    # each account's own size: the pipe and the thrusters nearly cancel at rest, so the residual
    # is measured against the terms themselves (Ledger.relative_residual)
    gross = sum(np.abs(b) for b in s.ledger.by_account.values()) + np.abs(s.ledger.dH)
    assert np.all(np.abs(s.ledger.residual) <= 1e-10 * gross + 1e-300)


def test_outputs_reach_the_dataset():
    v = operation_vessel()
    s = phsplit.simulate(v, (0.0, 20.0), 0.5, "sp2", control_start=0.0)
    ds = s.to_xarray()
    for name, unit in (("pipe_top_tension", "N"), ("pipe_departure_angle", "degree"), ("pipe_touchdown_x", "m"),
                       ("setpoint_x", "m"), ("setpoint_offset", "m"), ("force_pipe", "N")):
        assert ds[name].attrs["units"] == unit
    # the touchdown point moves with the lay at 0.5 m/s along 10 degrees
    tdx = ds["pipe_touchdown_x"].values
    assert np.all(np.isfinite(tdx))


# -- thrusters -------------------------------------------------------------------------------

def test_thrusters_deliver_the_demand_inside_their_capacity_and_its_direction_outside():
    """The paper's run (80 m off the set point at the start) through the OSV's thrusters: in the
    transient the demand is tens of times their capacity; later it is inside. Inside: delivered
    equals commanded to 1e-9. Outside: no thruster beyond its limit, and the delivered (X, Y, N)
    within 1 degree of the demand's direction."""
    v = vessel(thrusters=OSV_THRUSTERS)
    assert ("thrusters", "supplied") in v.accounts and ("control", "supplied") not in v.accounts
    s = phsplit.simulate(v, (0.0, 1500.0), 0.5, "sp4", control_start=0.0)
    o = {k: s.outputs[k][2] for k in s.outputs}
    cmd = np.column_stack([o["commanded_surge"], o["commanded_sway"], o["commanded_yaw"]])
    dlv = np.column_stack([o["delivered_surge"], o["delivered_sway"], o["delivered_yaw"]])
    util = o["thrust_utilisation"]
    inside, outside = util < 1.0 - 1e-12, util >= 1.0 - 1e-12
    assert inside.sum() > 1000 and outside.sum() > 50, (inside.sum(), outside.sum())
    err = np.linalg.norm(dlv[inside] - cmd[inside], axis=1) / np.linalg.norm(cmd[inside], axis=1)
    assert err.max() < 1e-9, err.max()
    cosang = np.sum(dlv[outside] * cmd[outside], axis=1) / (np.linalg.norm(dlv[outside], axis=1)
                                                             * np.linalg.norm(cmd[outside], axis=1))
    assert np.degrees(np.arccos(np.clip(cosang, -1, 1))).max() < 1.0
    limits = [u["max_thrust"] for u in OSV_THRUSTERS["unit"]]
    for i, lim in enumerate(limits):
        assert np.all(np.abs(o[f"thruster{i}_thrust"]) <= lim * (1 + 1e-12))
    # the ledger books what the thrusters deliver, and closes
    assert np.all(s.ledger.relative_residual() < 1e-10)
    # what acts on the vessel is the delivered force: the body force of the thrusters' account
    k = list(s.ledger.by_account).index("thrusters")
    np.testing.assert_allclose(s.account_force[:, k, :2], dlv[:, :2], rtol=0, atol=1e-6 * np.abs(dlv).max())


# -- bad data --------------------------------------------------------------------------------

@pytest.mark.parametrize("table,words", [
    ({"pipe": {"submerged_weight": -10.0, "water_depth": 100.0, "hang_off": [0, 0, 0], "horizontal_tension": 1e5,
               "lay_direction": 0.0}}, r"pipe.submerged_weight must be > 0 \(N/m\)"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, 4000.0], "horizontal_tension": 1e5,
               "lay_direction": 0.0}}, r"pipe.hang_off\[2\] must lie within 1000 m"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, -150.0], "horizontal_tension": 1e5,
               "lay_direction": 0.0}}, r"at or below the seabed"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, 0], "horizontal_tension": 1e5}},
     r"lay_direction"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, 0], "horizontal_tension": 1e5,
               "top_tension": 2e5, "lay_direction": 0.0}}, r"exactly one of .*got horizontal_tension, top_tension"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, 0], "top_tension": 500.0,
               "lay_direction": 0.0}}, r"pipe.top_tension must exceed"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, 0], "departure_angle": 95.0,
               "lay_direction": 0.0}}, r"departure_angle must lie strictly between 0 and 90"),
    ({"pipe": {"submerged_weight": 10.0, "water_depth": 100.0, "hang_off": [0, 0, 0], "touchdown": [1.0, 2.0, 3.0]}},
     r"pipe.touchdown must be 2 numbers"),
    ({"setpoint": {"natural_frequency": 0.1, "times": [0.0, 0.0], "positions": [[0, 0, 0], [1, 0, 0]]}},
     r"setpoint.times must increase strictly"),
    ({"setpoint": {"natural_frequency": 0.1, "times": [0.0], "positions": [[0, 0, 0], [1, 0, 0]]}},
     r"setpoint.times must have one value per row"),
    ({"setpoint": {"natural_frequency": 0.1, "positions": [[0, 0, 0], [1, 0, 0]]}}, r"needs times .* or speed"),
    ({"setpoint": {"natural_frequency": -0.1, "speed": 1.0, "positions": [[0, 0, 0], [1, 0, 0]]}},
     r"setpoint.natural_frequency must be > 0 \(rad/s\)"),
    ({"setpoint": {"natural_frequency": 0.1, "speed": 1.0, "positions": [[0, 0], [1, 0]]}},
     r"setpoint.positions must be a list of rows of 3 numbers"),
    ({"thrusters": dict(OSV_THRUSTERS, unit=[dict(OSV_THRUSTERS["unit"][0], position=[60.0, 0.0, 0.0])]
                        + OSV_THRUSTERS["unit"][1:])},
     r"thrusters.unit\[0\].position\[0\] = 60 m lies outside the hull's box"),
    ({"thrusters": dict(OSV_THRUSTERS, unit=[dict(OSV_THRUSTERS["unit"][0], kind="pod")] + OSV_THRUSTERS["unit"][1:])},
     r"thrusters.unit\[0\].kind must be one of 'tunnel', 'azimuth', 'fixed'"),
    ({"thrusters": dict(OSV_THRUSTERS, unit=[dict(OSV_THRUSTERS["unit"][0], max_thrust=-5.0)] + OSV_THRUSTERS["unit"][1:])},
     r"thrusters.unit\[0\].max_thrust must be > 0 \(N\)"),
    ({"thrusters": dict(OSV_THRUSTERS, unit=OSV_THRUSTERS["unit"][:2])}, r"cannot produce surge, sway and yaw"),
    ({"thrusters": dict(OSV_THRUSTERS, unit=[{"kind": "fixed", "position": [-40.0, 0.0, 0.0], "max_thrust": 1e5,
                                              "min_thrust": 0.0}] + OSV_THRUSTERS["unit"])},
     r"thrusters.unit\[0\].min_thrust must be < 0"),
    ({"thrusters": dict(OSV_THRUSTERS, unit=[dict(OSV_THRUSTERS["unit"][2], angle=30.0)] + OSV_THRUSTERS["unit"][1:])},
     r"unknown field `angle` in \[thrusters.unit\[0\]\]"),
])
def test_bad_pipe_and_set_point_tables_are_named(table, words):
    with pytest.raises(phsplit.InvalidInputError, match=words):
        vessel(**table)


# -- the shipped scenario ----------------------------------------------------------------------

def test_the_shipped_pipelay_scenario_runs_reruns_and_is_cf_compliant(tmp_path, capsys):
    from phsplit.cli import main
    from test_results import cf_problems

    assert "pipelay" in phsplit.scenario.shipped()
    sc = phsplit.load_scenario("pipelay")
    assert sc.vessel.components == ["damping", "restoring", "pid", "pipe"]
    assert main(["simulate", "pipelay", "--t-end", "120", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "pipe supplied" in out and "thrusters supplied" in out
    nc = tmp_path / "pipelay-t120.nc"
    assert nc.exists() and (tmp_path / "pipelay-t120.png").exists()
    ds = phsplit.open_dataset(str(nc))
    for name in ("pipe_top_tension", "pipe_touchdown_x", "thruster3_angle", "thrust_utilisation", "setpoint_offset",
                 "force_thrusters", "force_pipe"):
        assert name in ds, name
    assert cf_problems(nc) == []
    assert phsplit.results.compare(ds, phsplit.rerun(ds)) == []
    with pytest.raises(phsplit.InvalidInputError, match="neither a file nor a shipped scenario.*pipelay"):
        phsplit.load_scenario("pipelya")


def test_the_offset_from_the_route_is_split_across_and_along():
    """On a straight route along 30 degrees, the cross-track offset is the component of
    (x - x_d) normal to the route (left positive) and the along-track offset the component along
    it, recomputed here from the saved positions and desired positions."""
    d = phsplit.Vessel.paper().to_dict()
    ang = math.radians(30.0)
    d["setpoint"] = {"natural_frequency": 0.05, "speed": 0.5, "start_time": 20.0,
                     "positions": [[780.0, 20.0, 0.0], [780.0 + 500 * math.cos(ang), 20.0 + 500 * math.sin(ang), 0.0]]}
    v = phsplit.Vessel.from_dict(d)
    s = phsplit.simulate(v, (0.0, 300.0), 0.5, "sp2", control_start=0.0, save_every=10)
    o = {k: s.outputs[k][2] for k in s.outputs}
    ex, ey = s.x[:, 0] - o["setpoint_x"], s.x[:, 1] - o["setpoint_y"]
    u = np.array([math.cos(ang), math.sin(ang)])
    np.testing.assert_allclose(o["route_cross_track"], u[0] * ey - u[1] * ex, atol=1e-9)
    np.testing.assert_allclose(o["route_along_track"], u[0] * ex + u[1] * ey, atol=1e-9)
    np.testing.assert_allclose(np.hypot(o["route_cross_track"], o["route_along_track"]), o["setpoint_offset"],
                               atol=1e-9)
    assert np.abs(o["route_cross_track"]).max() > 1e-3  # the vessel does leave the route


# -- from a review ------------------------------------------------------------

def test_a_heading_table_across_pi_turns_the_short_way():
    """Headings 3.1 then -3.1 rad: a turn of 0.083 rad through pi, not of 6.2 rad; the heading
    error is taken the short way round, so the vessel follows it and settles at -3.1 (mod 2 pi)."""
    d = phsplit.Vessel.paper().to_dict()
    d["setpoint"] = {"natural_frequency": 0.1, "times": [0.0, 20.0], "interpolation": "step",
                     "positions": [[780.0, 20.0, 0.0], [780.0, 20.0, 0.0]], "headings": [3.1, -3.1]}
    v = phsplit.Vessel.from_dict(d)
    y0 = v.initial_state(euler=[0.0, 0.0, 3.1], position=[780.0, 20.0, 0.0], velocity=[0, 0, 0],
                         angular_velocity=[0, 0, 0])
    s = phsplit.simulate(v, (0.0, 600.0), 0.5, "sp4", control_start=0.0, initial=y0, save_every=20)
    desired = s.outputs["setpoint_heading"][2]
    assert np.max(np.abs(np.diff(desired))) < 0.1 and abs(desired[-1] - (2 * np.pi - 3.1)) < 1e-6
    yaw = s.euler[:, 2]
    err = np.angle(np.exp(1j * (yaw - desired)))
    assert np.abs(err).max() < 0.05 and abs(err[-1]) < 1e-4
    assert abs(np.angle(np.exp(1j * (yaw[-1] + 3.1)))) < 1e-4


def test_thrusters_allow_steps_beyond_the_d_terms_fixed_point():
    """The controller's surge, sway and yaw rows stay implicit with thrusters: SP2 at h = 5 and
    10 s completes on the pipelay scenario (the fixed point alone diverged beyond 4.5 s)."""
    sc = phsplit.load_scenario("pipelay")
    for h in (5.0, 10.0):
        s = phsplit.simulate(sc.vessel, (0.0, 600.0), h, "sp2", control_start=0.0, initial=sc.vessel.initial_state())
        assert s.status == "completed", (h, s.failure)
        assert np.all(s.ledger.relative_residual() < 1e-10)


def test_a_run_that_loses_its_catenary_fails_cleanly():
    """A touchdown point 100 km away: the pipe pulls the vessel away at speed until the run
    blows up; the run then fails with what it had, never with an internal error."""
    d = phsplit.load_scenario("pipelay").vessel.to_dict()
    d["pipe"] = {k: v for k, v in d["pipe"].items() if k not in ("horizontal_tension",)}
    d["pipe"]["touchdown"] = [100780.0, 20.0]
    v = phsplit.Vessel.from_dict(d)
    s = phsplit.simulate(v, (0.0, 60.0), 0.5, "sp2", control_start=0.0)
    assert s.status in ("completed", "failed")
    if s.status == "failed":
        assert "non-finite" in s.failure


def test_the_watch_circle_follows_a_moving_set_point():
    sc = phsplit.load_scenario("pipelay")
    s = phsplit.simulate(sc.vessel, (0.0, 1200.0), 0.5, "sp4", control_start=0.0,
                         events=[phsplit.events.watch_circle(2.0)])
    assert s.status == "completed"  # the vessel stays within 1 m of the moving desired position
    s = phsplit.simulate(sc.vessel, (0.0, 1200.0), 0.5, "sp4", control_start=0.0,
                         events=[phsplit.events.watch_circle(0.5)])
    assert s.status == "event"
    o = sc.vessel._inner.outputs(s.state(-1), float(s.t[-1]))
    assert abs(math.hypot(s.x[-1, 0] - o["setpoint_x"], s.x[-1, 1] - o["setpoint_y"]) - 0.5) < 1e-6
