"""Waves as a port. References: the target spectrum (wavespectra)
against an estimate from a 3-hour elevation record; the heave response to a regular wave against
the closed-form transfer function of the mass-spring-damper; the independent numpy model
(tests/reference.py, written again from docs/model.md 5.9) by DOP853; the Capytaine dataset read
independently with xarray."""
from __future__ import annotations

import math
import os

import numpy as np
import pytest
import xarray as xr
from scipy.signal import welch

import phsplit
from checks import fitted_order, within_passivity_bound
from phsplit import hydro, sea

DATA = os.path.join(os.path.dirname(__file__), "data", "box_barge_capytaine.nc")
RHO_G = 1025.0 * 9.81


def rao_table(scale=1.0, drift=False, omegas=(0.2, 0.6, 1.0, 1.4, 2.0, 3.0)):
    """Synthetic transfer functions for the paper's vessel, on four directions (0, 90, 180, 270
    degrees relative to the hull), smooth in frequency: heave force of the order of
    rho g A_wp, surge and sway a tenth of it, moments with a 20 m arm; phases vary."""
    nd, nf = 4, len(omegas)
    awp = 1.3834e3
    re = np.zeros((nd, nf, 6))
    im = np.zeros((nd, nf, 6))
    for i, b in enumerate(np.radians([0.0, 90.0, 180.0, 270.0])):
        for j, w in enumerate(omegas):
            decay = math.exp(-0.5 * w)
            mag = scale * RHO_G * awp * decay * np.array([0.1 * math.cos(b), 0.1 * math.sin(b), 1.0,
                                                           20.0 * 0.05 * math.sin(b), 20.0 * 0.2 * math.cos(b),
                                                           20.0 * 0.02 * math.sin(2 * b)])
            phase = 0.3 * w + 0.1 * i
            re[i, j] = mag * math.cos(phase)
            im[i, j] = mag * math.sin(phase)
    out = {"rao_frequencies": list(omegas), "rao_directions": [0.0, 90.0, 180.0, 270.0],
           "force_rao_real": re.tolist(), "force_rao_imag": im.tolist()}
    if drift:
        d = np.zeros((nd, nf, 3))
        for i, b in enumerate(np.radians([0.0, 90.0, 180.0, 270.0])):
            for j, w in enumerate(omegas):
                d[i, j] = scale * 2e3 * w * np.array([-math.cos(b) - 0.5, -math.sin(b), 3e1 * math.sin(2 * b)])
        out["drift_coefficients"] = d.tolist()
    return out


def vessel_with_waves(components, scale=1.0, drift=False, **extra):
    d = phsplit.Vessel.paper().to_dict()
    d["waves"] = {**rao_table(scale, drift), **components}
    d.update(extra)
    return phsplit.Vessel.from_dict(d)


def test_a_realised_sea_has_the_target_spectrum():
    """3 hours of elevation at the vessel: Hs = 4 std(eta) within 2 %, and the peak of a Welch
    estimate within 5 % of Tp."""
    ss = sea.SeaState(hs=3.0, tp=9.0, gamma=3.3, seed=11, components=300)
    v = vessel_with_waves(ss.realise(), scale=0.0)  # a sea that does not move the vessel
    s = phsplit.simulate(v, (0.0, 10800.0), 0.5, "sp2", control_start=0.0, ledger=False, save_every=1)
    eta = s.outputs["wave_elevation"][2]
    assert abs(4.0 * eta.std() - 3.0) / 3.0 < 0.02, 4.0 * eta.std()
    f, p = welch(eta - eta.mean(), fs=2.0, nperseg=4096)
    tp_est = 1.0 / f[np.argmax(p)]
    assert abs(tp_est - 9.0) / 9.0 < 0.05, tp_est
    # the target, for the record: what wavespectra gives integrates to Hs over the range
    w = np.linspace(*ss.range(), 2001)
    assert abs(4 * math.sqrt(np.trapezoid(ss.density(w), w)) - 3.0) < 1e-3


def test_the_heave_response_to_a_regular_wave_matches_the_transfer_function():
    """Controller off, a regular wave: the steady heave amplitude is a |F3| / |c - w^2 m + i w d3|
    (the paper's vessel has no added mass or wave damping: its own mass and heave damping)."""
    w, a = 1.1, 1.0
    v = vessel_with_waves(sea.regular(a, w, direction=180.0), scale=1.0)
    d = v.to_dict()
    y0 = v.initial_state(euler=[0.0, 0.0, 0.0], position=[0.0, 0.0, 0.0], velocity=[0.0, 0.0, 0.0],
                         angular_velocity=[0.0, 0.0, 0.0])
    s = phsplit.simulate(v, (0.0, 600.0), 0.05, "sp4", control_start=None, initial=y0, save_every=2)
    tab = np.array(rao_table()["force_rao_real"]) + 1j * np.array(rao_table()["force_rao_imag"])
    f3 = np.interp(w, rao_table()["rao_frequencies"], np.abs(tab[2, :, 2]))  # head seas: 180 degrees
    m, d3 = d["vessel"]["mass"], d["vessel"]["damping_translational"][2]
    c = d["vessel"]["gravity"] * d["vessel"]["water_density"] * d["vessel"]["waterplane_area"]
    want = a * f3 / abs(c - w * w * m + 1j * w * d3)
    got = np.abs(s.x[s.t > 400.0, 2]).max()
    assert abs(got - want) / want < 0.02, (got, want)


@pytest.mark.parametrize("method,order", [("sp2", 2), ("sp4", 4)])
def test_orders_with_waves_drift_and_current_against_the_independent_model(method, order):
    ss = sea.SeaState(hs=2.0, tp=8.0, seed=3, components=25, direction=150.0, spreading=8.0)
    v = vessel_with_waves(ss.realise(), drift=True, current={"velocity": [0.3, 0.1, 0.0]})
    y0 = v.initial_state()
    y0[0:3] = [2e6, -1e6, 0.0]
    slope, errs, y_end = fitted_order(v, y0, method, 2.0 ** -np.arange(1, 6))
    assert abs(slope - order) < 0.2, (slope, errs)


@pytest.mark.parametrize("method", ["sp2", "sp4"])
def test_the_ledger_books_each_source_and_closes(method):
    ss = sea.SeaState(hs=3.0, tp=9.0, seed=5, components=60, direction=200.0)
    v = vessel_with_waves(ss.realise(), drift=True, current={"velocity": [0.4, -0.2, 0.0]})
    assert {("waves", "supplied"), ("wave_drift", "supplied"), ("current", "supplied")} <= set(v.accounts)
    s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=0.0)
    assert np.all(s.ledger.relative_residual() < 1e-10)
    for src in ("waves", "wave_drift", "current", "control"):
        assert np.any(s.ledger.by_account[src][1:] != 0), src
    assert np.all(s.ledger.dissipated[1:] >= 0)


def test_sp2_stays_within_its_passivity_bound_for_an_hour_at_h_1():
    """H_n <= H_0 + supplied_n at every step (every dissipation >= 0 and the ledger closed)."""
    ss = sea.SeaState(hs=4.0, tp=10.0, seed=9, components=100, direction=210.0)
    v = vessel_with_waves(ss.realise(), drift=True)
    s = phsplit.simulate(v, (0.0, 3600.0), 1.0, "sp2", control_start=0.0)
    assert s.status == "completed"
    assert within_passivity_bound(s)


# -- Capytaine --------------------------------------------------------------------------------

def test_the_capytaine_loader_reproduces_capytaines_values():
    """The stored dataset (scripts/gen_capytaine_box.py, Capytaine 3.0.0), about its rotation
    centre (the waterline centre): the loader's excitation force and drift coefficients equal
    Capytaine's, read here with xarray, moved to the centre of gravity 0.5 m above (the force
    unchanged, exactly; the moment M - r x F, to round-off; the drift, exactly: a vertical move
    leaves the yaw moment), the force as the complex conjugate (e^{-iwt} to e^{+iwt}); the added
    mass that moved written again here from the kinematics (v_O = v_G + r x w)."""
    raw = xr.open_dataset(DATA)
    out = hydro.from_capytaine(DATA, symmetric=True)
    r = raw["center_of_mass"].values - raw["rotation_center"].values
    assert r.tolist() == [0.0, 0.0, 0.5] and out["reference_point"]["shift"] == r.tolist()
    i = int(np.argmax(raw["omega"].values))
    dofs = ["Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw"]
    a = raw["added_mass"].isel(omega=i).sel(influenced_dof=dofs, radiating_dof=dofs).values
    S = np.array([np.cross(r, e) for e in np.eye(3)]).T
    moved = np.block([[a[:3, :3], a[:3, :3] @ S + a[:3, 3:]],
                      [S.T @ a[:3, :3] + a[3:, :3], S.T @ a[:3, :3] @ S + S.T @ a[:3, 3:] + a[3:, :3] @ S + a[3:, 3:]]])
    np.testing.assert_allclose(out["added_mass"], moved, rtol=1e-12, atol=1e-12 * np.abs(a).max())
    exc = raw["excitation_force"]
    for di, beta in enumerate(raw["wave_direction"].values):
        k = out["waves"]["rao_directions"].index(float(np.degrees(beta)))
        for fi, w in enumerate(raw["omega"].values):
            j = out["waves"]["rao_frequencies"].index(float(w))
            x = np.array([complex(float(exc.sel(complex="re", omega=w, wave_direction=beta, influenced_dof=dof)),
                                  float(exc.sel(complex="im", omega=w, wave_direction=beta, influenced_dof=dof)))
                          for dof in dofs])
            want = np.conj(np.concatenate([x[:3], x[3:] - np.cross(r, x[:3])]))
            got = np.array(out["waves"]["force_rao_real"][k][j]) + 1j * np.array(out["waves"]["force_rao_imag"][k][j])
            assert np.all(got[:3] == want[:3])
            np.testing.assert_allclose(got[3:], want[3:], rtol=1e-13, atol=1e-13 * np.abs(x).max())
    # the mean drift (phsplit's drift_force variable, from Capytaine's far field), exactly
    drift = raw["drift_force"]
    for di, beta in enumerate(raw["wave_direction"].values):
        k = out["waves"]["rao_directions"].index(float(np.degrees(beta)))
        for fi, w in enumerate(raw["omega"].values):
            j = out["waves"]["rao_frequencies"].index(float(w))
            want = [float(drift.sel(omega=w, wave_direction=beta, drift_dof=n)) for n in ("Surge", "Sway", "Yaw")]
            assert out["waves"]["drift_coefficients"][k][j] == want
    # and it is physical: along the waves in head and following seas, growing towards the wall
    # limit rho g B / 2 of an 8 m wide box (4.0e4 N/m^2) in short head waves
    surge = drift.sel(drift_dof="Surge")
    assert float(surge.isel(omega=-1).sel(wave_direction=0.0)) > 0 > float(surge.isel(omega=-1).sel(wave_direction=np.pi))
    assert 0.5 < float(surge.isel(omega=-1).sel(wave_direction=0.0)) / (0.5 * 1025 * 9.81 * 8.0) < 1.5
    # mirrored for a symmetric hull: 270 degrees is 90 with sway, roll and yaw reversed
    sym = out["waves"]
    a, b = sym["rao_directions"].index(90.0), sym["rao_directions"].index(270.0)
    np.testing.assert_array_equal(np.array(sym["force_rao_real"][b]),
                                  np.array(sym["force_rao_real"][a]) * np.array([1, -1, 1, -1, 1, -1]))
    np.testing.assert_array_equal(np.array(sym["drift_coefficients"][b]),
                                  np.array(sym["drift_coefficients"][a]) * np.array([1, -1, -1]))
    # and the vessel takes the tables
    d = phsplit.Vessel.paper().to_dict()
    d["waves"] = {**sym, **sea.regular(0.5, 1.0, direction=180.0)}
    phsplit.Vessel.from_dict(d)


@pytest.mark.parametrize("drop,words", [(["added_mass"], "lacks added_mass"),
                                        (["excitation_force", "Froude_Krylov_force"], "lacks excitation_force")])
def test_a_malformed_capytaine_dataset_names_what_is_missing(drop, words):
    ds = xr.open_dataset(DATA).drop_vars(drop)
    with pytest.raises(phsplit.InvalidInputError, match=words):
        hydro.from_capytaine(ds)


# -- scenario and bad tables --------------------------------------------------------------------

def test_a_scenario_with_an_environment(tmp_path, capsys):
    from phsplit.cli import main

    os.symlink(DATA, tmp_path / "barge.nc")
    sc = tmp_path / "sea.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 60.0]\nh = 0.5\nmethod = "sp2"\ncontrol_start = 0.0\n\n'
                  '[environment.current]\nvelocity = [0.3, 0.0, 0.0]\n\n'
                  '[environment.waves]\nhs = 2.0\ntp = 8.0\ndirection = 180.0\nseed = 4\ncomponents = 50\n'
                  'omega_range = [0.35, 1.9]\nhydro = "barge.nc"\nsymmetric = true\n')
    # the test barge is not the paper's hull: refused against the vessel's hydrostatics, unless asked
    with pytest.raises(phsplit.InvalidInputError, match=r"environment.waves.hydro: .*vessel: the dataset's displacement"):
        phsplit.load_scenario(str(sc))
    sc.write_text(sc.read_text() + 'hydro_checks = "warn"\n')
    with pytest.warns(phsplit.hydro.HydroDataWarning, match="vessel: the dataset's"):
        loaded = phsplit.load_scenario(str(sc))
    assert loaded.vessel.components[-2:] == ["current", "waves"]
    assert main(["simulate", str(sc), "--out", str(tmp_path), "--no-plot"]) == 0
    out = capsys.readouterr().out
    assert "waves supplied" in out and "current supplied" in out
    ds = phsplit.open_dataset(str(tmp_path / "sea.nc"))
    assert "wave_elevation" in ds and "force_waves" in ds
    # the same seed, the same sea; another seed, another sea
    again = phsplit.load_scenario(str(sc)).vessel.to_dict()["waves"]["phases"]
    assert again == loaded.vessel.to_dict()["waves"]["phases"]
    sc2 = tmp_path / "sea2.toml"
    sc2.write_text(sc.read_text().replace("seed = 4", "seed = 5"))
    assert phsplit.load_scenario(str(sc2)).vessel.to_dict()["waves"]["phases"] != again


@pytest.mark.parametrize("change,words", [
    ({"amplitudes": [1.0, 2.0]}, "one entry per component"),
    ({"frequencies": [5.0]}, r"waves.frequencies\[0\] = 5 rad/s lies outside"),
    ({"rao_directions": [0.0, 90.0, 180.0, 360.0]}, "span less than 360"),
    ({"force_rao_real": [[[0.0] * 6] * 6] * 3}, r"waves.force_rao_real must be 4 × 6 × 6 numbers"),
    ({"rao_frequencies": [0.2, 0.6, 0.6, 1.4, 2.0, 3.0]}, "rao_frequencies must increase strictly"),
])
def test_bad_waves_tables_are_named(change, words):
    d = phsplit.Vessel.paper().to_dict()
    d["waves"] = {**rao_table(), **sea.regular(1.0, 1.0), **change}
    with pytest.raises(phsplit.InvalidInputError, match=words):
        phsplit.Vessel.from_dict(d)


@pytest.mark.parametrize("kw,words", [({"hs": -1.0}, "hs must be a number > 0"), ({"spectrum": "bretschneider"},
                                      "spectrum must be one of"), ({"gamma": 30.0}, r"gamma must lie in \[1, 10\]")])
def test_bad_sea_states_are_named(kw, words):
    with pytest.raises(phsplit.InvalidInputError, match=words):
        sea.SeaState(**{"hs": 2.0, "tp": 8.0, **kw})


def test_the_shipped_dp_weather_scenario_runs_reruns_and_is_cf_compliant(tmp_path, capsys):
    from phsplit.cli import main
    from test_results import cf_problems

    assert "dp-weather" in phsplit.scenario.shipped()
    sc = phsplit.load_scenario("dp-weather")
    assert sc.vessel.components[-3:] == ["current", "waves", "wind"]
    assert main(["simulate", "dp-weather", "--t-end", "60", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    for src in ("current supplied", "waves supplied", "wave_drift supplied", "wind supplied"):
        assert src in out
    assert "environment: current 0.50 m/s towards 190 deg; waves jonswap Hs 3 m Tp 9 s" in out
    nc = tmp_path / "dp-weather-t60.nc"
    assert nc.exists() and (tmp_path / "dp-weather-t60.png").exists()
    ds = phsplit.open_dataset(str(nc))
    for name in ("force_waves", "force_wind", "force_current", "wave_elevation", "wind_speed"):
        assert name in ds, name
    assert ds.attrs["phsplit_environment"].startswith("current 0.50 m/s")
    assert cf_problems(nc) == []
    assert phsplit.results.compare(ds, phsplit.rerun(ds)) == []
    # the scenario's wind coefficients are Blendermann's for an offshore supply vessel
    w = sc.vessel.to_dict()["wind"]
    ref_coef = sea.blendermann("offshore supply vessel", 182.0, 533.0, 76.2)
    assert w["cx"] == ref_coef["cx"] and w["angles"] == ref_coef["angles"]


def test_blendermann_coefficients_follow_the_published_formula():
    """Offshore supply vessel (CD_t 0.90, CD_l,AF 0.55 bow / 0.80 stern, delta 0.55): a head wind
    (air flowing aft, phsplit's 180 degrees) gives C_X = -0.55; a wind from astern +0.80; a beam
    wind C_Y = CD_t towards the flow; in between, the formula with its denominator, written again."""
    t = sea.blendermann("offshore supply vessel", 182.0, 533.0, 76.2, step=15.0)
    at = {a: (cx, cy, cn) for a, cx, cy, cn in zip(t["angles"], t["cx"], t["cy"], t["cn"])}
    assert at[180.0][0] == pytest.approx(-0.55) and at[0.0][0] == pytest.approx(0.80)
    assert at[90.0][1] == pytest.approx(0.90) and at[270.0][1] == pytest.approx(-0.90)
    g = math.radians(135.0) + math.pi  # phsplit's 135 degrees is Fossen's angle of attack 315 = -45 degrees
    gr = math.atan2(math.sin(g), math.cos(g))
    cdl = 0.55 * 182.0 / 533.0
    den = 1 - 0.5 * 0.55 * (1 - cdl / 0.90) * math.sin(2 * gr) ** 2
    assert at[135.0][0] == pytest.approx(-0.55 * math.cos(gr) / den)
    assert at[135.0][1] == pytest.approx(-0.90 * math.sin(gr) / den)
    # the yaw moment is antisymmetric: a wind from the other bow turns the other way
    assert at[135.0][2] == pytest.approx(-at[225.0][2])
    with pytest.raises(phsplit.InvalidInputError, match="unknown ship type 'yacht'"):
        sea.blendermann("yacht", 1.0, 1.0, 1.0)


@pytest.mark.parametrize("table,words", [
    ({"hs": 2.0, "tp": 8.0, "direction": "north"}, "direction must be a finite number"),
    ({"hs": 2.0, "tp": 8.0, "gamma": "3.3"}, r"gamma must lie in \[1, 10\]"),
    ({"hs": 2.0, "tp": 8.0, "omega_range": [0.3, 1.0, 2.0]}, "omega_range must be two increasing"),
    ({"hs": 2.0, "tp": 8.0, "omega_range": 2.0}, "omega_range must be two increasing"),
    ({"hs": True, "tp": 8.0}, "hs must be a number > 0"),
    ({"hs": 1e-300, "tp": 8.0}, r"hs must lie in \[0.001, 30\] m"),
    ({"hs": 2.0, "tp": 8.0, "components": True}, "components must be an integer"),
])
def test_sea_state_keys_of_the_wrong_type_are_named(table, words):
    with pytest.raises(phsplit.InvalidInputError, match=words):
        sea.sea_state(table)


@pytest.mark.parametrize("table,words", [
    ({"speed": 15.0, "direction": "N"}, "direction must be a finite number"),
    ({"speed": 15.0, "height": "10"}, "height must be a number > 0"),
    ({"speed": 15.0, "drag": -0.002, "spectrum": "harris"}, "drag must be a number > 0"),
    ({"speed": 15.0, "omega_range": [0.1]}, "omega_range must be two increasing"),
    ({"speed": 15.0, "ship_type": "tender", "frontal_area": 10.0, "lateral_area": 30.0, "length": 0.0},
     "must be numbers > 0"),
    ({"speed": 15.0, "ship_type": "tender", "frontal_area": 10.0, "lateral_area": 30.0, "length": 20.0,
      "cx": [1.0]}, "either ship_type or your own cx"),
])
def test_wind_keys_of_the_wrong_type_are_named(table, words):
    with pytest.raises(phsplit.InvalidInputError, match=words):
        sea.wind(table)


def test_symmetric_must_be_a_boolean(tmp_path):
    os.symlink(DATA, tmp_path / "barge.nc")
    sc = tmp_path / "s.toml"
    sc.write_text('[environment.waves]\nhs = 2.0\ntp = 8.0\nomega_range = [0.35, 1.9]\nhydro = "barge.nc"\n'
                  'symmetric = "false"\n')
    with pytest.raises(phsplit.ScenarioParseError, match="symmetric must be true or false"):
        phsplit.load_scenario(str(sc))
    with pytest.raises(phsplit.InvalidInputError, match="omega must lie within"):
        hydro.from_capytaine(DATA, omega=5.0)


def test_the_default_spectral_range_stays_inside_the_dataset():
    """Without omega_range, a sea on a dataset takes [0.5, 3] omega_p within the dataset's
    frequencies: Tp = 6 s (3 omega_p = 3.14 rad/s) on the box's 0.2-2 rad/s runs, its
    components inside, and Hs is that of the range; a sea wholly outside is refused naming
    omega_range."""
    from phsplit import scenario

    d = scenario._read_toml(scenario.resolve("dp-weather"), "scenario file")
    d["environment"]["waves"].pop("omega_range")
    d["environment"]["waves"]["tp"] = 6.0
    w = scenario.from_dict(d, scenario.resolve("dp-weather")).vessel.to_dict()["waves"]
    assert 0.5 * 2 * np.pi / 6.0 <= min(w["frequencies"]) and max(w["frequencies"]) <= 2.0
    a = np.asarray(w["amplitudes"])
    assert abs(4.0 * np.sqrt(np.sum(a ** 2) / 2.0) - 3.0) < 0.15   # Hs = 4 sqrt(m0) of the realisation
    d["environment"]["waves"].update(tp=1.5, hs=0.1)   # a short swell, not a breaking sea
    with pytest.raises(phsplit.InvalidInputError, match=r"environment.waves: the spectrum's range .* give omega_range"):
        scenario.from_dict(d, scenario.resolve("dp-weather"))
