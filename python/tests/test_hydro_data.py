"""Hydrodynamic datasets checked before use (docs/hydrodynamic-data.md): their structure, their
physics (long-wave limits, B(omega) symmetric positive semidefinite, hydrostatics, the Haskind
relation), and the change of reference point from Capytaine's rotation centre to phsplit's body
origin. References: Capytaine's own solution about the other point (box_barge_capytaine_cg.nc,
made by scripts/gen_capytaine_box.py), the transformation written again here from the rigid-body
kinematics, closed-form hydrostatics of a box, and Newman's Haskind relation evaluated here with
its own quadrature."""
from __future__ import annotations

import math
import os
import warnings

import numpy as np
import pytest
import xarray as xr

import phsplit
from phsplit import hydro

HERE = os.path.dirname(__file__)
BARGE = os.path.join(HERE, "data", "box_barge_capytaine.nc")
BARGE_CG = os.path.join(HERE, "data", "box_barge_capytaine_cg.nc")
PAPER_BOX = os.path.join(os.path.dirname(phsplit.__file__), "scenarios", "paper_box_capytaine.nc")
RHO, G = 1025.0, 9.81


def raw(path=BARGE):
    with xr.open_dataset(path) as f:
        return f.load()


def cplx(ds, name):
    v = ds[name].transpose("complex", "omega", "wave_direction", "influenced_dof")
    return v.sel(complex="re").values + 1j * v.sel(complex="im").values


# -- the shipped datasets are physical ----------------------------------------------------------

def test_the_shipped_datasets_have_a_box_s_hydrostatics_and_long_wave_limits():
    """Closed form for a box L x B x T with its centre of gravity z_G above the waterline:
    A_wp = L B, V = L B T, C33 = rho g A_wp; in long waves |X3| -> rho g A_wp (to first order
    rho g A_wp - omega^2 (rho V + A33)). The old closed-box file had 0.037 rho g A_wp at 0.2
    rad/s and C33 = 0."""
    for path, (L, B, T), lowest in ((BARGE, (20.0, 8.0, 2.0), 0.3), (PAPER_BOX, (76.2, 18.2, 4.49), 0.2)):
        ds = raw(path)
        assert float(ds["waterplane_area"]) == pytest.approx(L * B, rel=1e-12)
        assert float(ds["disp_volume"]) == pytest.approx(L * B * T, rel=1e-12)
        C = ds["hydrostatic_stiffness"].sel(influenced_dof="Heave", radiating_dof="Heave").values
        assert float(C) == pytest.approx(RHO * G * L * B, rel=1e-12)
        assert float(ds["rho"]) == RHO and float(ds["g"]) == G and math.isinf(float(ds["water_depth"]))
        assert float(ds["inertia_matrix"].sel(influenced_dof="Surge", radiating_dof="Surge")) == pytest.approx(RHO * L * B * T)
        assert float(ds["omega"].min()) == lowest
        x3 = np.abs(cplx(ds, "excitation_force")[0, :, 2]) / (RHO * G * L * B)
        assert np.all(x3 > 0.9) and np.all(x3 < 1.0), x3
        assert "added_mass_infinite_frequency" in ds
        for k in ("capytaine_version", "mesh", "lid", "rho", "g", "water_depth", "rotation_center"):
            assert k in ds.attrs, k
    # the paper box's centre of gravity: KG = T/2 + B^2/(12 T) - GM_T (the paper vessel's GM_T)
    assert raw(PAPER_BOX)["center_of_mass"].values[2] == pytest.approx(4.49 / 2 + 18.2 ** 2 / (12 * 4.49) - 2.144 - 4.49)


@pytest.mark.parametrize("path", [BARGE, PAPER_BOX])
def test_the_shipped_datasets_pass_every_physics_check(path):
    out = hydro.from_capytaine(path, symmetric=True)
    assert out["failed_checks"] == []
    names = " | ".join(out["checks"])
    for check in ("hydrostatics", "inertia", "long-wave heave", "long-wave roll", "long-wave pitch",
                  "damping symmetry", "damping positive semidefinite", "Haskind"):
        assert check in names, check


def test_the_paper_box_matches_the_paper_vessel_and_the_barge_does_not():
    out = hydro.from_capytaine(PAPER_BOX, symmetric=True, vessel=phsplit.Vessel.paper())
    assert sum("vessel:" in n for n in out["checks"]) == 4
    with pytest.raises(phsplit.InvalidInputError, match=r"vessel: the dataset's displacement rho V = 3\.28e\+05 kg"):
        hydro.from_capytaine(BARGE, symmetric=True, vessel=phsplit.Vessel.paper())


def test_the_haskind_relation_holds_for_the_barge_s_heave_and_pitch():
    """Newman, Marine Hydrodynamics (1977) §6.18-6.19, deep water: B_jj = k/(8 pi rho g c_g)
    * integral over the circle of |X_j|^2 with c_g = g/(2 omega), i.e. omega^3/(4 pi rho g^3)
    times it. The integral by Simpson's rule on [0, pi] (|X_j(-b)| = |X_j(b)| for a hull
    symmetric port-starboard), written here, not the loader's trapezoid on the circle.
    Capytaine's radiation and diffraction solutions are separate BEM solves."""
    ds = raw(BARGE)
    b = ds["wave_direction"].values
    assert np.allclose(np.diff(b), np.pi / 8) and b[0] == 0.0 and b[-1] == pytest.approx(np.pi)
    x = cplx(ds, "excitation_force")
    w = ds["omega"].values
    h = b[1] - b[0]
    simpson = np.array([1, 4, 2, 4, 2, 4, 2, 4, 1]) * h / 3
    for j, dof in ((2, "Heave"), (4, "Pitch")):
        integral = 2 * (np.abs(x[:, :, j]) ** 2 * simpson).sum(axis=1)
        haskind = w ** 3 / (4 * np.pi * RHO * G ** 3) * integral
        bem = ds["radiation_damping"].sel(influenced_dof=dof, radiating_dof=dof).values
        mid = (w > 0.4) & (w < 1.3)  # long enough waves for 9 directions, damping near its peak
        assert np.all(np.abs(haskind[mid] / bem[mid] - 1) < 0.05), (dof, haskind[mid] / bem[mid])


# -- datasets made bad here are refused, with the check named -----------------------------------

def _scaled(ds, name, dof, factor, omega_index=None):
    ds = ds.copy(deep=True)
    sel = {"influenced_dof": dof}
    if omega_index is not None:
        sel["omega"] = ds["omega"].values[omega_index]
    ds[name].loc[sel] = ds[name].loc[sel] * factor
    return ds


def _negative_damping(ds):
    ds = ds.copy(deep=True)
    w = ds["omega"].values[3]
    ds["radiation_damping"].loc[{"omega": w, "influenced_dof": "Heave", "radiating_dof": "Heave"}] *= -1.0
    return ds


def _zero_c33(ds):
    ds = ds.copy(deep=True)
    ds["hydrostatic_stiffness"].loc[{"influenced_dof": "Heave", "radiating_dof": "Heave"}] = 0.0
    return ds


def _rho_1000_inertia(ds):
    ds = ds.copy(deep=True)
    ds["inertia_matrix"] *= 1000.0 / 1025.0
    return ds


@pytest.mark.parametrize("make,words", [
    (lambda ds: _scaled(ds, "excitation_force", "Heave", 0.04), r"long-wave heave: \|X3\| = 0\.037\d* rho g A_wp at 0\.3 rad/s"),
    (lambda ds: _scaled(ds, "excitation_force", "Roll", 3.0), r"long-wave roll: \|X4\| = (2\.8|2\.9|3\.0)\d* \|k sin b"),
    (lambda ds: _scaled(ds, "excitation_force", "Pitch", 0.5), r"long-wave pitch: \|X5\| = 0\.[45]\d* \|k cos b"),
    (_negative_damping, r"damping positive semidefinite: B at 0\.866667 rad/s .*negative diagonal: Heave"),
    (lambda ds: _scaled(ds, "radiation_damping", "Pitch", 0.5), r"Haskind: B\[Pitch,Pitch\]"),
    (_zero_c33, r"hydrostatics: C33 = 0 N/m, expected > 0"),
    (_rho_1000_inertia, r"inertia: the inertia matrix's mass is 320000 kg, expected the displacement rho V = 328000 kg"),
])
def test_a_dataset_made_unphysical_is_refused_naming_the_check(make, words):
    bad = make(raw())
    with pytest.raises(phsplit.InvalidInputError, match=words) as e:
        hydro.from_capytaine(bad, symmetric=True)
    assert "\n" not in str(e.value) and 'hydro_checks = "warn"' in str(e.value)
    # used with a warning when asked for
    with pytest.warns(hydro.HydroDataWarning, match=words):
        out = hydro.from_capytaine(bad, symmetric=True, checks="warn")
    assert out["failed_checks"] and out["waves"]["rao_frequencies"]


def test_the_checks_setting_takes_refuse_or_warn_only():
    with pytest.raises(phsplit.InvalidInputError, match=r"hydro_checks must be one of 'refuse', 'warn', got 'off'"):
        hydro.from_capytaine(BARGE, symmetric=True, checks="off")
    with pytest.raises(phsplit.InvalidInputError, match=r"symmetric must be true or false, got 'yes'"):
        hydro.from_capytaine(BARGE, symmetric="yes")


def test_directions_over_half_the_circle_need_the_symmetry_for_the_haskind_check():
    with pytest.raises(phsplit.InvalidInputError, match=r"Haskind: the directions .* not an even number .*symmetric = true"):
        hydro.from_capytaine(BARGE)


# -- the structure ------------------------------------------------------------------------------

def _relabel(ds, coord, old, new):
    return ds.assign_coords({coord: [new if str(v) == old else str(v) for v in ds[coord].values]})


@pytest.mark.parametrize("make,words", [
    (lambda ds: ds.drop_vars("radiation_damping"), r"lacks radiation_damping"),
    (lambda ds: ds.drop_vars("hydrostatic_stiffness"), r"lacks hydrostatic_stiffness"),
    (lambda ds: ds.drop_vars("rotation_center"), r"lacks rotation_center"),
    (lambda ds: _relabel(ds, "influenced_dof", "Yaw", "Yaw2"), r"influenced_dof must be the labels Surge, Sway, Heave, "
                                                               r"Roll, Pitch, Yaw, got .*Yaw2"),
    (lambda ds: ds.isel(radiating_dof=[0, 1, 2]), r"radiating_dof must be the labels .*got Surge, Sway, Heave$"),
    (lambda ds: _relabel(ds, "drift_dof", "Yaw", "Heave"), r"drift_dof must be the labels Surge, Sway, Yaw, got Surge, Sway, Heave"),
    (lambda ds: ds.assign(added_mass=ds["added_mass"].astype(str)), r"added_mass must hold numbers, got dtype <U"),
    (lambda ds: ds.assign(added_mass=ds["added_mass"].where(ds["omega"] != ds["omega"][2])),
     r"added_mass holds a non-finite value \(nan\) at omega = 0\.677778, influenced_dof = Surge"),
    (lambda ds: ds.assign(radiation_damping=ds["radiation_damping"].rename(omega="frequency")),
     r"radiation_damping must have the dimensions \(omega, influenced_dof, radiating_dof\), got \(frequency"),
    (lambda ds: ds.assign_coords(water_depth=50.0), r"water_depth is 50 m: phsplit's waves are deep-water"),
    (lambda ds: ds.assign_coords(rho=-1.0), r"rho must be a number > 0"),
    (lambda ds: ds.assign_coords(omega=ds["omega"].values * 0 + 1.0), r"omega repeats a value"),
])
def test_a_malformed_dataset_names_the_variable_and_what_was_expected(make, words):
    with pytest.raises(phsplit.InvalidInputError, match=words):
        hydro.from_capytaine(make(raw()), symmetric=True)


def test_a_truncated_or_foreign_file_is_refused_on_one_line(tmp_path):
    data = open(BARGE, "rb").read()
    cut = tmp_path / "cut.nc"
    cut.write_bytes(data[: len(data) // 2])
    text = tmp_path / "notes.nc"
    text.write_text("not a NetCDF file\n")
    for p in (cut, text):
        with pytest.raises(phsplit.InvalidInputError, match=r"cannot read the Capytaine dataset .*(expected a NetCDF file|not a NetCDF file)") as e:
            hydro.from_capytaine(str(p), symmetric=True)
        assert "\n" not in str(e.value)
    with pytest.raises(phsplit.InvalidInputError, match="does not exist"):
        hydro.from_capytaine(str(tmp_path / "none.nc"))


@pytest.mark.parametrize("kind", ["truncated", "unphysical"])
def test_the_cli_refuses_a_bad_dataset_with_one_line_and_exit_2(tmp_path, capsys, kind):
    from phsplit.cli import main

    if kind == "truncated":
        data = open(BARGE, "rb").read()
        (tmp_path / "barge.nc").write_bytes(data[: len(data) // 3])
        words = "cannot read the Capytaine dataset"
    else:
        _scaled(raw(), "excitation_force", "Heave", 0.04).to_netcdf(tmp_path / "barge.nc")
        words = "long-wave heave"
    sc = tmp_path / "sea.toml"
    sc.write_text('[simulation]\nt_span = [0.0, 10.0]\nh = 0.5\n\n[environment.waves]\nhs = 2.0\ntp = 8.0\n'
                  'omega_range = [0.35, 1.9]\nhydro = "barge.nc"\nsymmetric = true\n')
    assert main(["simulate", str(sc), "--out", str(tmp_path / "out"), "--no-plot"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("phsplit: error: ") and words in err and "Traceback" not in err
    assert not (tmp_path / "out").exists() or not os.listdir(tmp_path / "out")


def test_a_scenario_uses_a_failing_dataset_only_when_it_asks_with_hydro_checks(tmp_path):
    from phsplit import scenario

    _scaled(raw(), "excitation_force", "Heave", 0.04).to_netcdf(tmp_path / "barge.nc")
    head = ('[simulation]\nt_span = [0.0, 10.0]\nh = 0.5\n\n[environment.waves]\nhs = 2.0\ntp = 8.0\n'
            'omega_range = [0.35, 1.9]\nhydro = "barge.nc"\nsymmetric = true\n')
    for value, outcome in [(None, "refused"), ('"refuse"', "refused"), ('"warn"', "warned"), ('"off"', "bad key")]:
        sc = tmp_path / "sea.toml"
        sc.write_text(head + (f"hydro_checks = {value}\n" if value else ""))
        if outcome == "refused":
            with pytest.raises(phsplit.InvalidInputError, match="long-wave heave"):
                scenario.load(sc)
        elif outcome == "warned":
            with pytest.warns(hydro.HydroDataWarning, match="long-wave heave"):
                s = scenario.load(sc)
            assert "waves" in s.vessel.components
        else:
            with pytest.raises(phsplit.ScenarioParseError, match=r"hydro_checks must be one of 'refuse', 'warn', got 'off'"):
                scenario.load(sc)


# -- the reference point ------------------------------------------------------------------------

def _moved(A, r):
    """A 6x6 matrix about a point O moved to P = O + r, written from the kinematics block by block:
    v_O = v_P + r x w, so with S the matrix of r x ., A_P = [[A11, A11 S + A12], [S^T A11 + A21,
    S^T A11 S + S^T A12 + A21 S + A22]]."""
    S = np.array([np.cross(r, e) for e in np.eye(3)]).T  # S @ w = r x w
    a11, a12, a21, a22 = A[:3, :3], A[:3, 3:], A[3:, :3], A[3:, 3:]
    return np.block([[a11, a11 @ S + a12], [S.T @ a11 + a21, S.T @ a11 @ S + S.T @ a12 + a21 @ S + a22]])


def test_the_loader_moves_the_data_to_the_centre_of_gravity_as_capytaine_computes_them_there():
    """The barge about its waterline centre, moved by the loader to its centre of gravity (0.5 m
    above), against Capytaine's solution with the rotation centre at the centre of gravity."""
    wl = hydro.from_capytaine(BARGE, symmetric=True)
    with pytest.warns(hydro.HydroDataWarning, match="Haskind"):  # 3 directions: too few for the quadrature
        cg = hydro.from_capytaine(BARGE_CG, symmetric=True, checks="warn")
    assert wl["reference_point"]["shift"] == [0.0, 0.0, 0.5] and cg["reference_point"]["shift"] == [0.0, 0.0, 0.0]
    fw, fc = wl["waves"], cg["waves"]
    iw = [fw["rao_frequencies"].index(x) for x in fc["rao_frequencies"]]
    jw = [fw["rao_directions"].index(x) for x in fc["rao_directions"]]
    xw = (np.array(fw["force_rao_real"]) + 1j * np.array(fw["force_rao_imag"]))[jw][:, iw]
    xc = np.array(fc["force_rao_real"]) + 1j * np.array(fc["force_rao_imag"])
    np.testing.assert_allclose(xw, xc, rtol=0, atol=1e-9 * np.abs(xc).max())
    np.testing.assert_allclose(wl["radiation_damping"][iw], cg["radiation_damping"], rtol=0,
                               atol=1e-9 * np.abs(cg["radiation_damping"]).max())
    for key in ("added_mass", "added_mass_infinite_frequency"):
        np.testing.assert_allclose(wl[key], cg[key], rtol=0, atol=1e-9 * np.abs(cg[key]).max())
    # and the move matters: the pitch moment about the waterline centre in head seas at 2 rad/s
    # is not the one about the centre of gravity
    ds = raw(BARGE)
    k, j = fw["rao_directions"].index(180.0), int(np.argmin(np.abs(ds["wave_direction"].values - np.pi)))
    about_wl = np.conj(cplx(ds, "excitation_force")[-1, j, 4])
    about_cg = fw["force_rao_real"][k][-1][4] + 1j * fw["force_rao_imag"][k][-1][4]
    assert abs(about_cg - about_wl) > 0.01 * abs(about_wl)


def test_the_loader_s_move_equals_the_kinematics_written_again():
    """An off-centre origin (all three components of r non-zero) on the barge: the loader's
    matrices against _moved, its forces against F and M - r x F, and the drift's yaw moment
    against N - (r_x F_y - r_y F_x)."""
    ds = raw(BARGE)
    cgp = np.array([1.5, -0.7, 0.9])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", hydro.HydroDataWarning)
        out = hydro.from_capytaine(BARGE, symmetric=True, center_of_gravity=cgp)
    r = cgp - ds["rotation_center"].values
    dofs = list(hydro.DOFS)
    w = ds["omega"].values
    B = ds["radiation_damping"].sel(influenced_dof=dofs, radiating_dof=dofs).values
    for i in range(len(w)):
        np.testing.assert_allclose(out["radiation_damping"][i], _moved(B[i], r), rtol=1e-12, atol=1e-9 * np.abs(B[i]).max())
    A = ds["added_mass"].sel(influenced_dof=dofs, radiating_dof=dofs).values[-1]
    np.testing.assert_allclose(out["added_mass"], _moved(A, r), rtol=1e-12, atol=1e-9 * np.abs(A).max())
    x = cplx(ds.sel(influenced_dof=dofs), "excitation_force")  # [omega][direction][dof], e^{-iwt}
    f = np.array(out["waves"]["force_rao_real"]) + 1j * np.array(out["waves"]["force_rao_imag"])
    dirs = out["waves"]["rao_directions"]
    drift = ds["drift_force"].sel(drift_dof=["Surge", "Sway", "Yaw"]).values
    for j, b in enumerate(np.degrees(ds["wave_direction"].values)):
        k = dirs.index(float(b))
        F, M = x[:, j, :3], x[:, j, 3:]
        want = np.concatenate([F, M - np.cross(r, F)], axis=1)
        np.testing.assert_allclose(f[k], np.conj(want), rtol=1e-12, atol=1e-9 * np.abs(want).max())
        d = drift[:, j]
        np.testing.assert_allclose(np.array(out["waves"]["drift_coefficients"][k])[:, 2],
                                   d[:, 2] - (r[0] * d[:, 1] - r[1] * d[:, 0]), rtol=1e-12, atol=1e-9)
    # the vessel's own centre of gravity offset r_g moves the origin by -r_g
    v = phsplit.Vessel.paper().to_dict()
    v["vessel"]["center_of_gravity"] = [0.0, 0.0, 0.25]
    with pytest.raises(phsplit.InvalidInputError, match="vessel: the dataset's displacement"):
        hydro.from_capytaine(BARGE, symmetric=True, vessel=v)
    with pytest.warns(hydro.HydroDataWarning):
        moved = hydro.from_capytaine(BARGE, symmetric=True, vessel=v, checks="warn")
    assert moved["reference_point"]["origin"] == pytest.approx([0.0, 0.0, 0.25])
    with pytest.raises(phsplit.InvalidInputError, match="center_of_gravity must be three finite numbers"):
        hydro.from_capytaine(BARGE, symmetric=True, center_of_gravity=[0.0, float("nan"), 0.0])


def test_dp_weather_s_spectral_range_lies_inside_its_dataset_s_frequencies():
    import tomllib

    with open(os.path.join(os.path.dirname(phsplit.__file__), "scenarios", "dp-weather.toml"), "rb") as f:
        waves = tomllib.load(f)["environment"]["waves"]
    w = raw(PAPER_BOX)["omega"].values
    assert waves["hydro"] == "paper_box_capytaine.nc" and waves["symmetric"] is True
    assert w.min() <= waves["omega_range"][0] < waves["omega_range"][1] <= w.max()
    comps = phsplit.load_scenario("dp-weather").vessel.to_dict()["waves"]["frequencies"]
    assert w.min() <= min(comps) and max(comps) <= w.max()


def test_complex_values_as_capytaine_returns_them_in_memory_load_the_same():
    ds = raw()
    merged = ds.copy()
    for name in ("excitation_force", "Froude_Krylov_force"):
        merged[name] = ds[name].sel(complex="re") + 1j * ds[name].sel(complex="im")
    merged = merged.drop_dims("complex")
    a = hydro.from_capytaine(ds, symmetric=True)
    b = hydro.from_capytaine(merged, symmetric=True)
    assert a["waves"] == b["waves"] and np.array_equal(a["added_mass"], b["added_mass"])
