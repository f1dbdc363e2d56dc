"""Wind as a port. References: closed forms (the controller's integral
action holding the vessel against a steady wind; the Harris spectrum's variance), the published
NPD turbulence intensity, and the independent numpy model (tests/reference.py) by DOP853."""
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest

import phsplit
from checks import fitted_order, within_passivity_bound
from phsplit import sea

#: Illustrative windage and coefficients for the tests (not a published vessel's): areas of an
#: 80 m vessel, C_X = 0.7 cos g, C_Y = 0.9 sin g, C_N = 0.1 sin 2g on 30-degree steps, g the angle
#: of the air's flow relative to the hull (0: from the stern).
ANGLES = list(range(0, 360, 30))
WINDAGE = {"frontal_area": 300.0, "lateral_area": 900.0, "length": 80.0, "air_density": 1.225,
           "angles": [float(a) for a in ANGLES],
           "cx": [0.7 * math.cos(math.radians(a)) for a in ANGLES],
           "cy": [0.9 * math.sin(math.radians(a)) for a in ANGLES],
           "cn": [0.1 * math.sin(2 * math.radians(a)) for a in ANGLES]}


def with_wind(speed=15.0, direction=200.0, gusts=None):
    d = phsplit.Vessel.paper().to_dict()
    d["wind"] = {**WINDAGE, "speed": speed, "direction": direction, **(gusts or {})}
    return phsplit.Vessel.from_dict(d)


def test_the_controller_holds_position_against_a_steady_wind():
    """At rest on the set point the relative wind is the wind itself: the body-frame load is
    q (A_F C_X(g), A_L C_Y(g)) at g = direction - heading (interpolated in the table), and the
    integral action carries it: Ki phi_x = Q F (closed form, horizontal)."""
    v = with_wind()
    d = v.to_dict()
    s = phsplit.simulate(v, (0.0, 8000.0), 1.0, "sp2", control_start=0.0, save_every=800)
    psi = s.euler[-1, 2]
    g = math.radians(200.0) - psi
    cx = np.interp(g, np.radians(ANGLES), WINDAGE["cx"], period=2 * np.pi)
    cy = np.interp(g, np.radians(ANGLES), WINDAGE["cy"], period=2 * np.pi)
    q = 0.5 * 1.225 * 15.0 ** 2
    f_spatial = s.Q[-1] @ np.array([q * 300.0 * cx, q * 900.0 * cy, 0.0])
    ki = np.array(d["control"]["ki_translational"])
    np.testing.assert_allclose(ki[:2] * s.phi_x[-1, :2], f_spatial[:2], rtol=1e-4)
    assert np.linalg.norm(s.x[-1, :2] - np.array(d["control"]["position_reference"][:2])) < 1e-2


def test_the_harris_spectrum_has_its_closed_form_variance():
    """int_0^inf 4 k L U / (2 + (fL/U)^2)^(5/6) df = 4 k U^2 2^(-1/3) sqrt(pi) Gamma(1/3) / (2 Gamma(5/6))
    (a Beta integral, evaluated in mpmath), against the code's spectrum integrated numerically."""
    U, k = 18.0, 0.002
    closed = float(4 * k * U ** 2 * mp.power(2, mp.mpf(-1) / 3) * mp.sqrt(mp.pi) * mp.gamma(mp.mpf(1) / 3)
                   / (2 * mp.gamma(mp.mpf(5) / 6)))
    f = np.logspace(-9, 4, 400001)
    num = np.trapezoid(sea.harris(f, U, k), f)
    assert abs(num - closed) / closed < 1e-3, (num, closed)


def test_the_npd_spectrum_has_its_closed_form_variance():
    """int_0^inf A / (1 + (c f)^n)^(5/(3n)) df = (A/c) (1/n) B(1/n, 2/(3n)) (a Beta integral, in
    mpmath), with A = 320 (U/10)^2 (z/10)^0.45 and c = 172 (z/10)^(2/3) (U/10)^(-0.75),
    against the code's spectrum integrated numerically, at three speeds and two heights.
    (At U = 15 m/s, z = 10 m: sigma = 1.794 m/s, sigma/U = 0.120.)"""
    n = mp.mpf("0.468")
    for U in (10.0, 15.0, 30.0):
        for z in (10.0, 40.0):
            A = 320 * (mp.mpf(U) / 10) ** 2 * (mp.mpf(z) / 10) ** mp.mpf("0.45")
            c = 172 * (mp.mpf(z) / 10) ** (mp.mpf(2) / 3) * (mp.mpf(U) / 10) ** mp.mpf("-0.75")
            closed = float(A / c / n * mp.beta(1 / n, 2 / (3 * n)))
            f = np.logspace(-10, 4, 400001)
            num = np.trapezoid(sea.npd(f, U, z), f)
            assert abs(num - closed) / closed < 1e-3, (U, z, num, closed)
    f = np.logspace(-10, 4, 400001)
    assert abs(math.sqrt(np.trapezoid(sea.npd(f, 15.0), f)) - 1.794) < 1e-3


def test_a_realised_gust_record_has_the_spectrums_variance():
    w = sea.Wind(speed=15.0, spectrum="npd", seed=3, components=400, omega_range=(1e-4, 3.0))
    r = w.realise()
    var = 0.5 * np.sum(np.array(r["gust_amplitudes"]) ** 2)
    om = np.linspace(1e-4, 3.0, 200001)
    target = np.trapezoid(w.density(om), om)
    assert abs(var - target) / target < 0.02, (var, target)
    assert sea.Wind(speed=15.0, seed=3).realise() == sea.Wind(speed=15.0, seed=3).realise()


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_wind_and_gusts_against_the_independent_model(method, order):
    gusts = sea.Wind(speed=20.0, direction=120.0, spectrum="harris", seed=2, components=30,
                     omega_range=(0.01, 0.5)).realise()
    v = with_wind(20.0, 120.0, {k: gusts[k] for k in ("gust_frequencies", "gust_amplitudes", "gust_phases")})
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]
    slope, errs, y_end = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    assert abs(slope - order) < 0.2, (slope, errs)


def test_the_ledger_books_the_wind_and_closes():
    gusts = sea.Wind(speed=20.0, direction=120.0, seed=2).realise()
    v = with_wind(20.0, 120.0, {k: gusts[k] for k in ("gust_frequencies", "gust_amplitudes", "gust_phases")})
    assert ("wind", "supplied") in v.accounts
    for method in ("sp2", "sp4"):
        s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=0.0)
        assert np.all(s.ledger.relative_residual() < 1e-10)
        assert np.any(s.ledger.by_account["wind"][1:] != 0)
        assert "wind_speed" in s.outputs


def test_a_scenario_with_wind(tmp_path, capsys):
    from phsplit.cli import main

    lines = "\n".join(f"{k} = {v!r}" if not isinstance(v, list) else f"{k} = {v}" for k, v in WINDAGE.items())
    sc = tmp_path / "wind.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 60.0]\nh = 0.5\nmethod = "sp2"\ncontrol_start = 0.0\n\n'
                  f'[environment.wind]\nspeed = 18.0\ndirection = 250.0\nspectrum = "npd"\nseed = 1\n{lines}\n')
    assert phsplit.load_scenario(str(sc)).vessel.components[-1] == "wind"
    assert main(["simulate", str(sc), "--out", str(tmp_path), "--no-plot"]) == 0
    assert "wind supplied" in capsys.readouterr().out


@pytest.mark.parametrize("change,words", [
    ({"cx": [0.1, 0.2]}, "one value per angle"),
    ({"angles": [0.0, 90.0, 90.0] + [float(a) for a in ANGLES[3:]]}, "wind.angles must increase strictly"),
    ({"speed": 120.0}, "at most 80 m/s"),
    ({"air_density": -1.0}, r"wind.air_density must be > 0 \(kg/m\^3\)"),
    ({"gust_frequencies": [0.1], "gust_amplitudes": [], "gust_phases": [0.0]}, "one entry per component"),
])
def test_bad_wind_tables_are_named(change, words):
    d = phsplit.Vessel.paper().to_dict()
    d["wind"] = {**WINDAGE, "speed": 10.0, "direction": 0.0, **change}
    with pytest.raises(phsplit.InvalidInputError, match=words):
        phsplit.Vessel.from_dict(d)


def all_loads_vessel():
    """The paper's vessel with current (a time table), wind with gusts, waves with drift, all on.
    The waves are long-crested here: with spreading, a component whose relative direction crosses
    a node of the transfer functions' direction grid meets a kink of the linear interpolation,
    which caps the observed order at fine steps (measured: SP4 errors stall near 3e-10)."""
    from test_waves import rao_table

    gusts = sea.Wind(speed=18.0, direction=230.0, spectrum="npd", seed=4, components=40,
                     omega_range=(0.005, 0.5)).realise()
    comps = sea.SeaState(hs=2.5, tp=9.0, seed=6, components=40, direction=210.0).realise()
    d = phsplit.Vessel.paper().to_dict()
    d["wind"] = {**WINDAGE, **gusts}
    d["waves"] = {**rao_table(drift=True), **comps}
    d["current"] = {"times": [0.0, 3600.0], "velocities": [[0.3, 0.1, 0.0], [0.5, -0.1, 0.0]]}
    return phsplit.Vessel.from_dict(d)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_with_all_loads_on_the_orders_hold_and_the_ledger_closes_by_source(method, order):
    v = all_loads_vessel()
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]
    slope, errs, y_end = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    assert abs(slope - order) < 0.2, (slope, errs)
    s = phsplit.simulate(v, (0.0, 600.0), 0.5, method, control_start=0.0)
    assert np.all(s.ledger.relative_residual() < 1e-10)
    for src in ("control", "current", "wind", "waves", "wave_drift"):
        assert np.any(s.ledger.by_account[src][1:] != 0), src


def test_with_all_loads_sp2_at_h_1_stays_within_its_passivity_bound_for_an_hour():
    v = all_loads_vessel()
    s = phsplit.simulate(v, (0.0, 3600.0), 1.0, "sp2", control_start=0.0)
    assert s.status == "completed"
    assert within_passivity_bound(s)


def test_an_unknown_key_in_environment_wind_is_named_there():
    with pytest.raises(phsplit.ScenarioParseError, match=r"unknown field 'speeed' in \[environment.wind\]; did you mean 'speed'"):
        sea.wind({"speeed": 15.0})
