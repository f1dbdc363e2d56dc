"""The general vessel of eq. (1), a 6x6 mass matrix M = M_RB + M_A with the centre of
gravity off the origin, and the offshore supply vessel of Fossen's MSS as a preset.

References: the preset's numbers derived again here from the published inputs of osv.m
(docs/research/mss_vessels.md §1); Fossen's equations in the body velocities written again in
numpy (tests/fossen.py) and integrated by DOP853; the ledger; the paper's vessel."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import fossen
import phsplit
from checks import within_passivity_bound

OSV = phsplit.Vessel.preset("osv")


def osv_published():
    """The OSV's M, D, GM_T, GM_L and A_wp from osv.m's published inputs (Fossen's frame: z down,
    y to starboard), by the formulas of osv.m, rbody.m, Gmtrx.m and Dmtrx.m."""
    rho, g, L, B, T, cb, cw = 1025.0, 9.81, 83.0, 18.0, 5.0, 0.65, 0.8
    vol = cb * L * B * T
    m = rho * vol
    rg = np.array([-4.5, 0.0, -1.2])
    awp = cw * B * L
    kb = (5 * T / 2 - vol / awp) / 3
    k = 6 * cw ** 3 / ((1 + cw) * (1 + 2 * cw))
    bg = (T - kb) - rg[2]
    gmt = k * B ** 3 * L / 12 / vol - bg
    gml = 0.7 * L ** 3 * B / 12 / vol - bg
    ig = m * np.array([0.35 * B, 0.25 * L, 0.25 * L]) ** 2
    # M_RB = H(r_g)^T blkdiag(m I, I_g) H(r_g), H(r) = [[I, S(r)^T], [0, I]] (Fossen 2021, eq. 3.27)
    H = np.block([[np.eye(3), fossen.S(rg).T], [np.zeros((3, 3)), np.eye(3)]])
    mrb = H.T @ np.block([[m * np.eye(3), np.zeros((3, 3))], [np.zeros((3, 3)), np.diag(ig)]]) @ H
    ma = 1e9 * np.array([[0.0006, 0, 0, 0, 0, 0], [0, 0.0020, 0, 0.0031, 0, -0.0091],
                         [0, 0, 0.0083, 0, 0.0907, 0], [0, 0.0031, 0, 0.0748, 0, -0.1127],
                         [0, 0, 0.0907, 0, 3.9875, 0], [0, -0.0091, 0, -0.1127, 0, 1.2416]])
    M = mrb + ma
    g33, g44 = rho * g * awp, rho * g * vol * gmt
    g55 = rho * g * vol * gml + 0.5 ** 2 * g33  # LCF = -0.5 m
    w = np.sqrt(np.array([g33 / M[2, 2], g44 / M[3, 3], g55 / M[4, 4]]))
    D = np.array([M[0, 0] / 100, M[1, 1] / 100, 2 * 0.2 * w[0] * M[2, 2], 2 * 0.15 * w[1] * M[3, 3],
                  2 * 0.3 * w[2] * M[4, 4], M[5, 5] / 1])
    return dict(m=m, M=M, D=D, gmt=gmt, gml=gml, awp=awp, ig=ig)


FLIP = np.diag([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])  # Fossen's z down, y starboard -> z up, y port


def test_the_osv_preset_is_osv_m_converted_to_z_up():
    pub = osv_published()
    d = OSV.to_dict()["vessel"]
    want = FLIP @ pub["M"] @ FLIP
    np.testing.assert_allclose(OSV.mass_matrix, want, rtol=1e-12, atol=1e-12 * np.abs(want).max())
    # the research notes' table of M (printed to 7 digits), converted: a check of the frame too
    assert OSV.mass_matrix[1, 5] == pytest.approx(-3.149599e7, rel=1e-6)   # N_v-like, unchanged sign
    assert OSV.mass_matrix[3, 5] == pytest.approx(1.395752e8, rel=1e-6)    # roll-yaw, sign flipped
    assert OSV.mass_matrix[1, 3] == pytest.approx(-9.072265e6, rel=1e-6)   # sway-roll, sign flipped
    assert OSV.mass_matrix[0, 4] == pytest.approx(5.972265e6, rel=1e-6)    # m z_g, z up
    np.testing.assert_allclose(d["damping_translational"] + d["damping_rotational"], pub["D"], rtol=1e-12)
    assert d["mass"] == pytest.approx(pub["m"], rel=1e-15)
    assert d["gm_transverse"] == pytest.approx(pub["gmt"], rel=1e-14)
    assert d["gm_longitudinal"] == pytest.approx(pub["gml"], rel=1e-14)
    assert d["waterplane_area"] == pytest.approx(pub["awp"], rel=1e-15)
    np.testing.assert_allclose(d["inertia"], pub["ig"], rtol=1e-14)
    # the natural periods MSS prints (diagonal terms only; docs/research/mss_vessels.md §1.9)
    M, g = pub["M"], 1025.0 * 9.81
    t3 = 2 * np.pi / np.sqrt(g * pub["awp"] / M[2, 2])
    assert round(t3, 2) == 6.60


def test_the_natural_periods_are_those_of_fossens_linear_model():
    """Without damping, phsplit's linearised flow S2 at rest (the OSV: full M, the heave spring at
    the centre of flotation) has the natural periods of Fossen's linear model M nu' + G eta = 0,
    2 pi / sqrt(eig(M^-1 G)), with osv.m's M and G (Gmtrx.m: G33, G35 = -LCF G33, G44,
    G55 = rho g V GM_L + LCF^2 G33) converted to z up."""
    pub = osv_published()
    t = OSV.to_dict()
    t["vessel"]["damping_translational"] = [0.0] * 3
    t["vessel"]["damping_rotational"] = [0.0] * 3
    del t["crossflow_drag"]
    undamped = phsplit.Vessel.from_dict(t)
    got = undamped.natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    rho_g = 1025.0 * 9.81
    vol = pub["m"] / 1025.0
    G = np.zeros((6, 6))
    G[2, 2] = rho_g * pub["awp"]
    G[2, 4] = G[4, 2] = 0.5 * G[2, 2]  # -LCF G33 with LCF = -0.5 m (Fossen's frame)
    G[3, 3] = rho_g * vol * pub["gmt"]
    G[4, 4] = rho_g * vol * pub["gml"] + 0.25 * G[2, 2]
    lam = np.linalg.eigvals(np.linalg.solve(pub["M"], G))
    want = sorted(2 * np.pi / np.sqrt(lam.real[lam.real > 1e-9]))
    assert len(got) == 3 and len(want) == 3
    np.testing.assert_allclose(got, want, rtol=1e-9)
    # without the centre of flotation (x_F = 0) they differ: the coupling is seen
    t["vessel"]["flotation_center_x"] = 0.0
    other = phsplit.Vessel.from_dict(t).natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    assert np.max(np.abs(np.array(other) - want) / np.array(want)) > 1e-4


def fossen_restoring(c, gt, gl, rf_fossen):
    """Fossen's restoring matrix about the CO from the centre of flotation r (Fossen's frame),
    G = H(r)^T diag(0, 0, c, G_T, G_L, 0) H(r), H(r) = [[I, S(r)^T], [0, I]] (Fossen 2021, §4.2)."""
    H = np.block([[np.eye(3), fossen.S(np.asarray(rf_fossen, float)).T], [np.zeros((3, 3)), np.eye(3)]])
    return H.T @ np.diag([0.0, 0.0, c, gt, gl, 0.0]) @ H


def asymmetric_osv(yf=1.5):
    t = OSV.to_dict()
    t["vessel"]["flotation_center_y"] = yf
    return phsplit.Vessel.from_dict(t)


def test_a_flotation_centre_off_the_centreline_gives_fossens_coupling_terms():
    """A hull that is not port-starboard symmetric: with the centre of flotation at (x_F, y_F),
    the undamped, uncontrolled natural periods are those of M nu' + G eta = 0 with Fossen's
    G = H(r)^T G_CF H(r) (G34, G35, G45 and the shifted G44, G55), r = (x_F, -y_F, 0) in his
    frame (y to starboard), converted to z up."""
    pub = osv_published()
    t = asymmetric_osv().to_dict()
    t["vessel"]["damping_translational"] = [0.0] * 3
    t["vessel"]["damping_rotational"] = [0.0] * 3
    del t["crossflow_drag"]
    got = phsplit.Vessel.from_dict(t).natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    rho_g = 1025.0 * 9.81
    vol = pub["m"] / 1025.0
    G = fossen_restoring(rho_g * pub["awp"], rho_g * vol * pub["gmt"], rho_g * vol * pub["gml"], [-0.5, -1.5, 0.0])
    assert G[2, 3] != 0 and G[3, 4] != 0  # the couplings of an asymmetric hull
    lam = np.linalg.eigvals(np.linalg.solve(pub["M"], G))
    want = sorted(2 * np.pi / np.sqrt(lam.real[lam.real > 1e-9]))
    assert len(got) == 3 and len(want) == 3
    np.testing.assert_allclose(got, want, rtol=1e-9)
    # with y_F = 0 they differ: the new coupling terms are seen
    np.testing.assert_array_less(1e-4, np.max(np.abs(np.array(
        OSV.natural_periods(control=False, euler=[0.0, 0.0, 0.0])) - want) / np.array(want)))


@pytest.mark.parametrize("method,order,hs", [("sp2", 2, [0.5, 0.25, 0.125, 0.0625]), ("sp4", 4, [2.0, 1.0, 0.5, 0.25])])
def test_an_asymmetric_hull_against_fossens_equations(method, order, hs):
    """The OSV with its centre of flotation 1.5 m to port: orders against Fossen's equations (its
    restoring written from the potential V = c/2 (z + r_F . q3)^2 + q3^T G q3/2), and the ledger
    closes (the coupling is conservative)."""
    def closes(s):
        assert s.ledger.relative_residual().max() < 1e-10

    errs = fossen.errors_against(asymmetric_osv(), y0_osv(), method, hs, check=closes)
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - order) < 0.2, (slope, errs)


def y0_osv():
    return dict(euler=[0.04, -0.015, 0.25], position=[12.0, -6.0, 0.3], velocity=[1.2, -0.6, 0.1],
                angular_velocity=[0.01, -0.004, 0.015])


@pytest.mark.parametrize("method,order,hs", [
    ("sp2", 2, [1.0, 0.5, 0.25, 0.125]),
    ("sp4", 4, [2.0, 1.0, 0.5, 0.25]),
    ("sp6", 6, [1.0, 0.75, 0.5]),
])
def test_orders_and_agreement_against_fossens_equations(method, order, hs):
    """SP2/SP4/SP6 on the OSV (full added mass, CG off the origin, cross-flow drag), controller on,
    against Fossen's M nu' + C(nu) nu + D nu + g = tau in numpy by DOP853: fitted orders, and the
    finest step's agreement."""
    errs = fossen.errors_against(OSV, y0_osv(), method, hs)
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - order) < 0.2, (slope, errs)
    assert errs[-1] < {2: 1e-4, 4: 1e-6, 6: 1e-8}[order], errs


@pytest.mark.parametrize("method,h", [("sp2", 1 / 512), ("sp4", 1 / 16), ("sp6", 0.5)])
def test_fine_steps_agree_to_1e_8(method, h):
    """At a fine step each method agrees with the independent model to 1e-8 relative."""
    init = y0_osv()
    ref = fossen.solve(OSV.to_dict(), fossen.initial(**init), 16.0, rtol=1e-13)
    s = phsplit.simulate(OSV, (0.0, 16.0), h, method, control_start=0.0, initial=OSV.initial_state(**init),
                         ledger=False)
    nu = np.concatenate([s.v[-1], s.w[-1]])
    assert np.linalg.norm(nu - ref[0:6]) / np.linalg.norm(ref[0:6]) < 1e-8
    assert np.linalg.norm(s.x[-1] - ref[15:18]) / np.linalg.norm(ref[15:18]) < 1e-8
    assert np.linalg.norm(s.Q[-1] - ref[6:15].reshape(3, 3, order="F")) < 1e-8


def with_quadratic():
    t = OSV.to_dict()
    t["damping_quadratic"] = {"coefficients": [1.81312e4, 2.0e5, 4.0e5, 3.0e7, 2.0e10, 8.0e9]}
    t["current"] = {"velocity": [0.4, -0.3, 0.0]}
    return phsplit.Vessel.from_dict(t)


@pytest.mark.parametrize("method,lf", [("sp2", "exact"), ("sp4", "gauss"), ("sp6", "exact")])
def test_the_ledger_closes_with_a_general_mass_matrix(method, lf):
    for v in (OSV, with_quadratic()):
        s = phsplit.simulate(v, (0.0, 300.0), 0.5, method, control_start=10.0, linear_flow=lf)
        assert s.status == "completed"
        assert np.all(s.ledger.relative_residual() < 1e-10), s.ledger.relative_residual().max()
        for name, kind in v.accounts:
            if kind == "dissipated":
                assert s.ledger.by_account[name][1:].min() >= 0, name


@pytest.mark.parametrize("h", [1.0, 5.0, 10.0, 20.0])
def test_sp2_stays_within_its_passivity_bound_up_to_20_s(h):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        s = phsplit.simulate(OSV, (0.0, 3600.0), h, "sp2", control_start=0.0)
    assert s.status == "completed" and within_passivity_bound(s)
    # the DP holds: at the set point after an hour
    assert np.linalg.norm(s.x[-1, :2] - [20.0, 10.0]) < 0.5, s.x[-1]


@pytest.mark.parametrize("method", ["lie", "sp2", "sp4", "sp6", "rk4"])
def test_the_paper_vessel_written_as_a_general_vessel_is_the_paper_vessel(method):
    t = phsplit.Vessel.paper().to_dict()
    t["vessel"]["added_mass"] = np.zeros((6, 6)).tolist()
    t["vessel"]["center_of_gravity"] = [0.0, 0.0, 0.0]
    b = phsplit.simulate(phsplit.Vessel.from_dict(t), method=method)
    a = phsplit.simulate(phsplit.Vessel.paper(), method=method)
    for k in ("x", "euler", "p", "m", "energy"):
        ref = getattr(a, k)
        assert np.abs(getattr(b, k) - ref).max() <= 1e-12 * np.abs(ref).max(), k


def test_bad_mass_matrices_are_named():
    t = OSV.to_dict()
    t["vessel"]["added_mass"][1][5] = -8.0e6
    with pytest.raises(phsplit.InvalidInputError, match=r"vessel.added_mass must be symmetric: entry \[1\]\[5\]"):
        phsplit.Vessel.from_dict(t)
    t = OSV.to_dict()
    t["vessel"]["added_mass"][1][1] = -6.0e6  # more negative than the body's mass
    with pytest.raises(phsplit.InvalidInputError, match="mass matrix M = M_RB \\+ M_A .* positive definite; its smallest eigenvalue is -"):
        phsplit.Vessel.from_dict(t)
    t = OSV.to_dict()
    t["vessel"]["added_mass"] = t["vessel"]["added_mass"][:5]
    with pytest.raises(phsplit.InvalidInputError, match="6 rows of 6"):
        phsplit.Vessel.from_dict(t)
    with pytest.raises(phsplit.InvalidInputError, match="unknown vessel preset 'osw'.*'osv'"):
        phsplit.Vessel.preset("osw")


def test_the_presets_on_the_command_line_and_in_scenarios(tmp_path, capsys):
    from phsplit import cli

    assert cli.main(["vessels"]) == 0
    out = capsys.readouterr().out
    assert "osv" in out and "osv.m" in out and "paper" in out
    sc = tmp_path / "dp.toml"
    sc.write_text('vessel = "osv"\n[simulation]\nt_span = [0.0, 20.0]\nh = 0.5\n[control]\nposition_reference = [5.0, 0.0, 0.0]\n')
    s = phsplit.load_scenario(str(sc))
    np.testing.assert_array_equal(s.vessel.mass_matrix, OSV.mass_matrix)
    assert s.vessel.to_dict()["control"]["position_reference"] == [5.0, 0.0, 0.0]
    assert cli.main(["simulate", str(sc), "--vessel", "paper", "--out", str(tmp_path), "--no-plot"]) == 0
    assert (tmp_path / "dp-paper.nc").exists()
    assert cli.main(["simulate", "--vessel", "osv", "--t-end", "10", "--out", str(tmp_path), "--no-plot"]) == 0
    import xarray as xr

    with xr.open_dataset(tmp_path / "osv-t10.nc") as ds:  # named after its vessel
        # the body velocities are M^-1 (p, m) with the general M
        u = np.hstack([ds["linear_momentum"].values, ds["angular_momentum"].values])
        nu = np.linalg.solve(OSV.mass_matrix, u.T).T
        np.testing.assert_allclose(ds["velocity"].values, nu[:, :3], rtol=1e-10, atol=1e-14)
        np.testing.assert_allclose(ds["angular_velocity"].values, nu[:, 3:], rtol=1e-10, atol=1e-16)
    assert cli.main(["simulate", "--vessel", "osw", "--out", str(tmp_path)]) == 2
    assert "neither a file nor a shipped vessel (shipped: paper, osv, shipx-supply)" in capsys.readouterr().err


def test_a_vessel_file_with_full_matrices_in_a_scenario(tmp_path):
    """A user's vessel file with the full matrices (the OSV's, written out by to_toml) named by
    path in a scenario rebuilds the same vessel."""
    (tmp_path / "my_osv.toml").write_text(OSV.to_toml())
    sc = tmp_path / "run.toml"
    sc.write_text('vessel = "my_osv.toml"\n[simulation]\nt_span = [0.0, 10.0]\nh = 0.5\nmethod = "sp2"\n')
    s = phsplit.load_scenario(str(sc))
    np.testing.assert_array_equal(s.vessel.mass_matrix, OSV.mass_matrix)
    a = phsplit.simulate(s.vessel, (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    b = phsplit.simulate(OSV, (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    np.testing.assert_array_equal(a.x, b.x)


def test_matrix_entries_can_be_swept():
    """``vessel.added_mass[i][j]`` addresses one entry (its mirror follows: M_A is symmetric);
    a wrong number of indices or a row as a value makes the case invalid with a message."""
    v = phsplit.with_parameters(OSV, {"vessel.added_mass[1][5]": -8.0e6})
    d = v.to_dict()["vessel"]["added_mass"]
    assert d[1][5] == d[5][1] == -8.0e6
    assert v.mass_matrix[1, 5] == pytest.approx(OSV.mass_matrix[1, 5] + 1.1e6, rel=1e-12)
    ds = phsplit.simulate_many([{"vessel.added_mass[1][5]": x} for x in (-9.1e6, -7.0e6)]
                               + [{"vessel.added_mass[1]": 1.0}, {"vessel.added_mass[1][5]": [1.0] * 6}],
                               base=OSV, t_span=(0.0, 10.0), h=0.5, method="sp2", control_start=0.0)
    assert list(ds.status.values) == ["completed", "completed", "invalid", "invalid"]
    assert "give two indices" in ds["error"].values[2] and "must be a number" in ds["error"].values[3]
    a = phsplit.simulate(OSV, (0.0, 10.0), 0.5, "sp2", control_start=0.0)
    np.testing.assert_array_equal(ds.position.values[0], a.x)
    assert np.isnan(ds["vessel_added_mass_1_5"].values[3])


def test_a_sub_flow_that_gives_up_says_why():
    """A run that fails because a sub-flow gave up (rather than return an unconverged result)
    says which and what to do; the run ends cleanly with what it had."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        # A yaw rate of 50 rad/s at h = 100 s: h|ω| = 5000, beyond 1024 sub-steps at the first
        # step (a long DP run at h = 500 s failed there too, but where is chaotic).
        t = OSV.to_dict()
        del t["crossflow_drag"]
        v = phsplit.Vessel.from_dict(t)
        y0 = v.initial_state(angular_velocity=[0.0, 0.0, 50.0], velocity=[5.0, 0.0, 0.0])
        s = phsplit.simulate(v, (0.0, 1000.0), 100.0, "sp2", control_start=None, initial=y0)
        assert s.status == "failed" and len(s.t) >= 1
        assert "Kirchhoff's equations" in s.failure and "take a shorter step" in s.failure
        t = phsplit.Vessel.paper().to_dict()
        t["damping_quadratic"] = {"coefficients": [1e6, 1e6, 1e6, 1e10, 1e11, 1e11]}
        s = phsplit.simulate(phsplit.Vessel.from_dict(t), (0.0, 2000.0), 100.0, "sp2", control_start=0.0)
        assert s.status == "failed"
        assert "fixed point of flow S2's non-affine" in s.failure and "take a shorter step" in s.failure
        # a run that overflows without a sub-flow giving up says only that
        s = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 200.0), 4.0, "rk4", control_start=0.0)
        assert s.status == "failed" and s.failure.endswith("the state became non-finite")


@pytest.mark.parametrize("h,method", [(10.0, "lie"), (30.0, "lie"), (10.0, "sp4"), (10.0, "sp6")])
def test_the_ledger_closes_at_long_steps_with_quadratic_damping(h, method):
    """With quadratic damping the collocation's fixed point must converge in the velocities too,
    not only in the stage vector as a whole (dominated by the integral states): the ledger books
    the power at the stages. Before, Lie at h = 10 s booked to 1.2e-8 relative here."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        for v in (with_quadratic(), phsplit.Vessel.from_dict({**phsplit.Vessel.paper().to_dict(),
                  "damping_quadratic": {"coefficients": [4e3, 1.75e5, 2e5, 3e8, 4e9, 2e10]}})):
            s = phsplit.simulate(v, (0.0, 1200.0), h, method, control_start=0.0)
            assert s.status == "completed", s.failure
            assert s.ledger.relative_residual().max() < 1e-10


def test_a_conservative_run_has_a_small_relative_residual():
    """Without damping or control nothing is booked; dH is then round-off of H, and the
    relative residual says so (it was 1.0 whatever the run did), while a real imbalance of
    that size relative to H would still show."""
    t = OSV.to_dict()
    t["vessel"]["damping_translational"] = [0.0] * 3
    t["vessel"]["damping_rotational"] = [0.0] * 3
    del t["crossflow_drag"]
    v = phsplit.Vessel.from_dict(t)
    y0 = v.initial_state(velocity=[1.0, 0.3, 0.0], angular_velocity=[0.01, 0.0, 0.02])
    s = phsplit.simulate(v, (0.0, 200.0), 0.5, "sp2", control_start=None, initial=y0)
    assert s.status == "completed"
    assert np.abs(s.energy - s.energy[0]).max() < 1e-12 * s.energy[0]
    assert s.ledger.relative_residual().max() < 1e-10
    bad = phsplit.Ledger(dH=s.ledger.dH + 1e-9 * s.energy[0], supplied=s.ledger.supplied,
                         dissipated=s.ledger.dissipated, by_account=s.ledger.by_account,
                         kinds=s.ledger.kinds, level=s.ledger.level)
    assert bad.relative_residual()[1:].min() > 1e-6  # 1e-9 of H shows as 5e-6


def test_the_ledger_takes_every_account_of_the_osv_in_weather():
    """The OSV with the shipped dp-weather scenario's waves, wind and current keeps nine ledger
    accounts, one more than the ledger keeps inline (solve::Work; docs/model.md §3.5): each is
    booked and the ledger closes, with and without the ninth."""
    weather = phsplit.scenario.load("dp-weather").vessel.to_dict()
    d = OSV.to_dict()
    d.update({k: weather[k] for k in ("waves", "wind", "current")})
    for n, vessel in ((9, phsplit.Vessel.from_dict(d)), (8, phsplit.Vessel.from_dict({k: v for k, v in d.items() if k != "wind"}))):
        s = phsplit.simulate(vessel, (0.0, 30.0), 0.5, "sp2", control_start=0.0)
        assert s.status == "completed" and len(s.ledger.by_account) == n
        assert all(np.any(v[1:] != 0.0) for v in s.ledger.by_account.values())
        assert s.ledger.relative_residual().max() < 1e-10
