"""Static DP capability (phsplit.capability; docs/how-to/dp-capability.md): symmetry, failures
never above intact, the allocation feasible at the limit and not 10 % beyond, a hand computation
of one direction, the core's load scaling, bad arguments, and a time-domain run at the limit."""
import copy
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import phsplit
from phsplit.capability import LEVEL1, Environment, _Loads, _towards, held

#: The thrusters' share of their published thrust in the test vessel: limits inside the table.
SCALE = 0.12

DIRS = [0.0, 30.0, 60.0, 90.0, 120.0, 150.0, 180.0, 210.0, 240.0, 270.0, 300.0, 330.0]


def _symmetric_tables(scale: float = SCALE) -> dict:
    """The dp-capability vessel with a port-starboard symmetric layout (both stern azimuths of
    420 kN) and every thruster at ``scale`` of its thrust, so that the limits fall inside the table."""
    t = copy.deepcopy(phsplit.load_scenario("dp-capability").vessel.to_dict())
    units = t["thrusters"]["unit"]
    units[3]["max_thrust"] = units[2]["max_thrust"]
    for u in units:
        u["max_thrust"] *= scale
    return t


@pytest.fixture(scope="module")
def vessel():
    return phsplit.Vessel.from_dict(_symmetric_tables())


@pytest.fixture(scope="module")
def result(vessel):
    return phsplit.capability(vessel, directions=DIRS)


def test_symmetric_vessel_gives_a_symmetric_curve(result):
    u = result["wind_speed_limit"].values
    d = result["direction"].values
    assert u[:, 0].max() < LEVEL1[-1][1]  # the limits lie inside the table
    assert u[:, 0].min() > 3.0
    # Mirrored, the port azimuth (thruster 2) lost is the starboard one (thruster 3) lost.
    mirror = [0, 1, 2, 4, 3]
    for i, a in enumerate(d):
        j = int(np.flatnonzero(np.isclose(d, (360.0 - a) % 360.0))[0])
        # the same bisection on mirrored loads; the tables' mirroring is exact to round-off
        np.testing.assert_allclose(u[i], u[j, mirror], atol=2 * 0.01)


def test_a_failure_is_nowhere_above_intact(result):
    u = result["wind_speed_limit"].values
    assert np.all(u[:, 1:] <= u[:, :1] + 1e-12)
    assert np.all(result["worst_failure_wind_speed"].values <= u[:, 0])
    assert np.all(result["beaufort_limit"].values[:, 1:] <= result["beaufort_limit"].values[:, :1])
    assert list(result["case_name"].values) == ["intact"] + [f"thruster {i} lost" for i in range(4)]


def test_the_limit_is_held_and_ten_percent_more_is_not(vessel, result):
    loads = _Loads(vessel)
    env = Environment()
    heading = math.degrees(loads.heading)
    for i, d in enumerate(result["direction"].values):
        towards = _towards(heading, float(d))
        for j, name in enumerate(result["case_name"].values):
            lost = [] if name == "intact" else [int(name.split()[1])]
            u = float(result["wind_speed_limit"].values[i, j])
            at = held(vessel, -loads.total(env, u, towards), lost)
            assert at["scale"] == 1.0 and at["utilisation"] <= 1.0
            beyond = held(vessel, -loads.total(env, 1.1 * u, towards), lost)
            assert beyond["scale"] < 1.0, (d, name, u)
            assert result["utilisation_at_limit"].values[i, j] > 0.99  # bisection tolerance 0.01 m/s


def test_head_on_against_a_hand_computation(vessel):
    """From ahead, the load is a surge force: the wind's q A_F C_X(180°) from the vessel's
    table, the current through the linear damping D_11, and the mean drift 2 ∫ S(ω) D_x(ω, 180°) dω
    from the drift table, with Hs, Tp, V_c interpolated in the level-1 table. The least-norm
    allocation gives each stern azimuth half of it, so the limit is |X| = 2 × SCALE × 420 kN."""
    t = vessel.to_dict()
    w, wv = t["wind"], t["waves"]
    env = np.array(LEVEL1, dtype=float)
    tp_col = env[:, 3].copy()
    tp_col[0] = tp_col[1]
    cx180 = np.interp(180.0, w["angles"], w["cx"])
    d11 = t["vessel"]["damping_translational"][0]
    freqs = np.array(wv["rao_frequencies"])
    k180 = wv["rao_directions"].index(180.0)
    dx = np.array(wv["drift_coefficients"])[k180, :, 0]
    from wavespectra.construct.frequency import jonswap

    def x_load(u):
        hs, tp, vc = (np.interp(u, env[:, 1], c) for c in (env[:, 2], tp_col, env[:, 4]))
        wind = 0.5 * w["air_density"] * u * u * w["frontal_area"] * cx180
        current = -d11 * vc
        lo, hi = 0.5 * 2 * np.pi / tp, 3.0 * 2 * np.pi / tp
        f = np.linspace(lo, hi, 20001) / (2 * np.pi)
        raw = np.asarray(jonswap(f, fp=1 / tp, gamma=3.3))
        s_omega = raw * (hs / 4) ** 2 / np.trapezoid(raw, f) / (2 * np.pi)  # m^2 s/rad
        om = f * 2 * np.pi
        inside = (om >= freqs[0]) & (om <= freqs[-1])
        drift = np.trapezoid((2 * s_omega * np.interp(om, freqs, dx))[inside], om[inside])
        return wind + current + drift

    limit = 2 * SCALE * 4.2e5
    lo, hi = 0.0, LEVEL1[-1][1]
    assert abs(x_load(hi)) > limit
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if abs(x_load(mid)) <= limit else (lo, mid)
    ds = phsplit.capability(vessel, directions=[0.0], failures="none", tolerance=1e-4)
    got = float(ds["wind_speed_limit"].values[0, 0])
    # bisection tolerance and the drift quadrature (200 bins against 20001 points)
    print(f"head-on limit: capability {got:.4f} m/s, by hand {lo:.4f} m/s")
    assert abs(got - lo) < 0.01, (got, lo)
    assert x_load(lo) < 0  # from ahead: pushed astern


def test_the_wind_load_at_rest_scales_with_the_square_of_the_speed(vessel):
    loads = _Loads(vessel)
    for towards in (0.0, 75.0, 200.0):
        np.testing.assert_allclose(loads.wind(17.1, towards), loads.wind_direct(17.1, towards), rtol=1e-12, atol=1e-9)


def test_mean_drift_is_the_cores_mean():
    """The binding's mean drift against the time average of the core's own Newman drift for
    one regular wave (2 s a² |D| cos² θ averages to s a² |D| over a period)."""
    v = phsplit.load_scenario("dp-capability").vessel
    t = copy.deepcopy(v.to_dict())
    omega, a, towards = 0.8, 1.5, 250.0
    t["waves"].update(frequencies=[omega], amplitudes=[a], phases=[0.3], directions=[towards])
    for k in ("thrusters", "wind", "current"):
        t.pop(k)
    one = phsplit.Vessel.from_dict(t)
    s = one.initial_state(velocity=[0.0, 0.0, 0.0], angular_velocity=[0.0, 0.0, 0.0])
    period = 2 * np.pi / omega
    ts = np.linspace(0.0, period, 64, endpoint=False)
    inst = [next((f[0], f[1], m[2]) for n, f, m in phsplit._core.account_wrenches(one._inner, s, tt)
                 if n == "wave_drift") for tt in ts]
    mean = np.mean(inst, axis=0)
    got = phsplit._core.mean_wave_drift(v._inner, 0.54, [omega], [a], [towards])
    np.testing.assert_allclose(got, mean, rtol=1e-9, atol=1e-6 * np.abs(mean).max())


def test_without_drift_data_the_drift_is_left_out():
    t = _symmetric_tables()
    t.pop("waves")
    ds = phsplit.capability(phsplit.Vessel.from_dict(t), directions=[90.0], failures="none")
    assert ds.attrs["wave_drift_included"] == 0
    assert "LEFT OUT" in ds.attrs["loads"]


@pytest.mark.parametrize("kw, word", [
    (dict(directions=[400.0]), "directions"),
    (dict(directions=[10.0, 10.0]), "directions"),
    (dict(directions="north"), "directions"),
    (dict(directions=[]), "directions"),
    (dict(failures="double"), "failures"),
    (dict(failures=[[7]]), "failures"),
    (dict(failures=[["a"]]), "failures"),
    (dict(tolerance=0.0), "tolerance"),
    (dict(environment=[[0, 1, 2]]), "environment"),
])
def test_bad_arguments_give_one_line_naming_the_argument(vessel, kw, word):
    with pytest.raises(phsplit.InvalidInputError) as e:
        phsplit.capability(vessel, **kw)
    msg = str(e.value)
    assert "\n" not in msg and f"capability: {word}:" in msg


def test_a_vessel_without_thrusters_or_wind_is_refused():
    with pytest.raises(phsplit.InvalidInputError, match="capability: vessel: has no \\[wind\\]"):
        phsplit.capability(phsplit.Vessel.paper())
    t = _symmetric_tables()
    t.pop("thrusters")
    with pytest.raises(phsplit.InvalidInputError, match="capability: vessel: has no \\[thrusters\\]"):
        phsplit.capability(phsplit.Vessel.from_dict(t))
    with pytest.raises(phsplit.InvalidInputError, match="capability: vessel: must be"):
        phsplit.capability(3.0)


def test_the_command_writes_netcdf_and_png(tmp_path):
    exe = os.path.join(os.path.dirname(sys.executable), "phsplit")
    out = tmp_path / "cap"
    r = subprocess.run([exe, "capability", "dp-capability", "--directions", "0", "90", "180", "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert (out / "dp-capability-capability.nc").exists() and (out / "dp-capability-capability.png").exists()
    ds = phsplit.open_dataset(str(out / "dp-capability-capability.nc"))
    assert ds.attrs["Conventions"] == "CF-1.8" and ds["wind_speed_limit"].attrs["units"] == "m s-1"
    ds.close()
    bad = subprocess.run([exe, "capability", "dp-capability", "--directions", "400", "--out", str(out)],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "directions" in bad.stderr
    assert "Traceback" not in bad.stderr
    (tmp_path / "afile").write_text("x")
    nope = subprocess.run([exe, "capability", "dp-capability", "--out", str(tmp_path / "afile")],
                          capture_output=True, text=True)
    assert nope.returncode == 2 and "Traceback" not in nope.stderr


def test_a_run_at_the_limit_keeps_station_and_ten_percent_beyond_does_not(vessel, result):
    """In the time domain, with the mean loads only (steady wind and current, no waves: the drift
    is then left out of the static limit too), the PID holds the vessel within a 5 m watch
    circle at the limit and loses it 10 % beyond, where the thrusters saturate."""
    t = copy.deepcopy(vessel.to_dict())
    t.pop("waves")
    for k in ("gust_frequencies", "gust_amplitudes", "gust_phases"):
        t["wind"].pop(k, None)
    calm = phsplit.Vessel.from_dict(t)
    d = 90.0
    ds = phsplit.capability(calm, directions=[d], failures="none", tolerance=1e-3)
    u = float(ds["wind_speed_limit"].values[0, 0])
    _, _, vc = Environment().at(u)
    heading = t["initial"]["euler"][2]
    towards = _towards(math.degrees(heading), d)
    a = math.radians(towards)

    def excursion(speed):
        tt = copy.deepcopy(t)
        tt["wind"].update(speed=speed, direction=towards)
        tt["current"] = {"velocity": [vc * math.cos(a), vc * math.sin(a), 0.0]}
        sol = phsplit.simulate(phsplit.Vessel.from_dict(tt), t_span=(0.0, 1500.0), h=0.5, method="sp2",
                               control_start=0.0)
        x0 = np.array(t["initial"]["position"][:2])
        r = np.hypot(*(sol.x[:, :2] - x0).T)
        return r[len(r) // 2:].max(), r[-1]

    held_r, _ = excursion(u)
    lost_max, lost_end = excursion(1.1 * u)
    assert held_r < 5.0, held_r
    assert lost_end > 5.0, lost_end
