"""The preset `shipx-supply` (earlier name `supply`), the 82.8 m supply vessel of the ShipX data in Fossen's MSS
(HYDRO/vessels_shipx/supply/supply.mat; docs/research/mss_vessels.md §3), the paper's vessel with
its full hydrodynamics.

References: the published matrices' nonzero entries, as stored in supply.mat (Fossen's frame: x
forward, y to starboard, z down; about the CO, midships in the waterline), written out here; the
frame conversion S M S; Fossen's linear restoring model M nu' + C eta = 0 for the natural periods;
Fossen's equations in numpy (tests/fossen.py) integrated by DOP853 for the orders."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import fossen
import phsplit

SUPPLY = phsplit.Vessel.preset("shipx-supply")
FLIP = np.diag([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])  # Fossen's z down, y starboard -> z up, y port
MASS = 6362208.5  # main.m, kg


def symmetric(entries: dict) -> np.ndarray:
    """A symmetric 6x6 matrix from its entries on and above the diagonal (1-based, as printed)."""
    a = np.zeros((6, 6))
    for (i, j), x in entries.items():
        a[i - 1, j - 1] = a[j - 1, i - 1] = x
    return a


# supply.mat, vessel.MRB
MRB = symmetric({(1, 1): 6362208.5, (2, 2): 6362208.5, (3, 3): 6362208.5,
                 (1, 5): -8270870.5, (2, 4): 8270870.5, (2, 6): -34266343.4594366,
                 (3, 5): 34266343.4594366, (4, 4): 298059260.0, (4, 6): -44546243.535011806,
                 (5, 5): 2921450770.8585114, (6, 6): 2910698770.8585114})
# vessel.A(:,:,1), at vessel.freqs(1) = 0.1047198 rad/s
A1 = symmetric({(1, 1): 846253.1756598908, (2, 2): 2816921.5, (2, 4): 4202437.5,
                (2, 6): -6325379.718511401, (3, 3): 19462218.0, (3, 5): 233234891.3856728,
                (4, 4): 50823888.0, (4, 6): -103396670.499025, (5, 5): 10816486897.216787,
                (6, 6): 1156498348.3105462})
# vessel.B(:,:,1) (its (5,3) is 17134062.598758038, 1 ulp from (3,5)) and vessel.Bv(:,:,1)
B1 = symmetric({(1, 1): 35.393378937543446, (2, 2): 117.81388, (2, 4): 258.89261,
                (2, 6): -357.615615444048, (3, 3): 1456624.9, (3, 5): 17134062.59875804,
                (4, 4): 982.87146, (4, 6): -3491.0353824941562, (5, 5): 793676582.7869186,
                (6, 6): 31797.93956547195})
BV1 = symmetric({(1, 1): 129835.47113706246, (2, 2): 82665.11787129978, (4, 4): 30000000.0,
                 (6, 6): 183141174.19729376})
# vessel.C(:,:,1), the same at every frequency
C = symmetric({(3, 3): 13910359.0, (3, 5): 145649203.1811364, (4, 4): 133797350.0,
               (5, 5): 7633174294.923774})


def test_the_mass_and_damping_matrices_are_shipxs_converted_to_z_up():
    want = FLIP @ (MRB + A1) @ FLIP
    np.testing.assert_allclose(SUPPLY.mass_matrix, want, rtol=0, atol=1e-13 * np.abs(want).max())
    # phsplit builds M_RB from the mass, the inertia about the CG and the CG (Fossen 2021,
    # eq. 3.44): without the added mass it is MRB itself, entry by entry
    t = SUPPLY.to_dict()
    t["vessel"]["added_mass"] = np.zeros((6, 6)).tolist()
    mrb = phsplit.Vessel.from_dict(t).mass_matrix
    np.testing.assert_allclose(mrb, FLIP @ MRB @ FLIP, rtol=0, atol=1e-13 * np.abs(MRB).max())
    # signs of the conversion: sway-roll and roll-yaw flip, sway-yaw and heave-pitch do not
    assert SUPPLY.mass_matrix[1, 3] == pytest.approx(-(8270870.5 + 4202437.5), rel=1e-15)
    assert SUPPLY.mass_matrix[3, 5] == pytest.approx(44546243.535011806 + 103396670.499025, rel=1e-15)
    assert SUPPLY.mass_matrix[1, 5] == pytest.approx(-34266343.4594366 - 6325379.718511401, rel=1e-15)
    D = np.array(SUPPLY.to_dict()["vessel"]["damping_matrix"])
    np.testing.assert_allclose(D, FLIP @ (B1 + BV1) @ FLIP, rtol=1e-15, atol=0)
    assert np.linalg.eigvalsh(D).min() > 0
    assert SUPPLY.to_dict()["vessel"]["mass"] == MASS


def test_the_restoring_is_shipxs_matrix_c():
    """Undamped and uncontrolled at rest, phsplit's linearised flow S2 has the natural periods of
    M nu' + C eta = 0 with ShipX's M = MRB + A(w1) and C (z up): C33, C35 (the centre of
    flotation), C44 and C55 all enter, and they are C's."""
    t = SUPPLY.to_dict()
    t["vessel"]["damping_matrix"] = np.zeros((6, 6)).tolist()
    got = phsplit.Vessel.from_dict(t).natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    lam = np.linalg.eigvals(np.linalg.solve(FLIP @ (MRB + A1) @ FLIP, FLIP @ C @ FLIP))
    want = sorted(2 * np.pi / np.sqrt(lam.real[lam.real > 1e-9]))
    assert len(got) == 3 and len(want) == 3
    np.testing.assert_allclose(got, want, rtol=1e-9)
    # as the file says: heave and pitch 8.4 and 8.6 s, roll 9.9 s
    assert [round(x, 1) for x in got] == [8.4, 8.6, 9.9]
    # the paper's GM_L = 103.628 m in place of the matrix's C55 moves them: C is what is used
    t["vessel"]["gm_longitudinal"] = 103.628
    other = phsplit.Vessel.from_dict(t).natural_periods(control=False, euler=[0.0, 0.0, 0.0])
    assert np.max(np.abs(np.array(other) - want) / np.array(want)) > 1e-3


def test_the_papers_dp_operation_settles_and_keeps_the_ledger():
    """The paper's controller on the complete vessel: the set point is reached (integral action),
    the attitude comes upright at the commanded heading, and the ledger closes."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", phsplit.StepSizeWarning)
        s = phsplit.simulate(SUPPLY, (0.0, 3600.0), 0.5, "sp2", control_start=0.0, save_every=100)
    assert s.status == "completed"
    np.testing.assert_allclose(s.x[-1][:2], [780.0, 20.0], atol=1e-3)
    np.testing.assert_allclose(s.euler[-1], [0.0, 0.0, 0.54], atol=1e-6)
    assert s.ledger.relative_residual().max() < 1e-10


@pytest.mark.parametrize("method,order,hs", [("sp2", 2, [0.5, 0.25, 0.125, 0.0625]),
                                             ("sp4", 4, [2.0, 1.0, 0.5, 0.25])])
def test_orders_against_fossens_equations(method, order, hs):
    """SP2/SP4 on the preset (full added mass, CG off the origin, full damping, heave-pitch
    restoring coupling), controller on, against Fossen's equations in numpy by DOP853."""
    init = dict(euler=[0.04, -0.015, 0.25], position=[770.0, 12.0, 0.2], velocity=[0.8, -0.4, 0.05],
                angular_velocity=[0.01, -0.004, 0.012])
    errs = fossen.errors_against(SUPPLY, init, method, hs)
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert abs(slope - order) < 0.2, (slope, errs)


def test_the_preset_is_listed_and_runs_from_the_command_line(tmp_path, capsys):
    from phsplit import cli
    assert "shipx-supply" in phsplit.presets()
    assert cli.main(["vessels"]) == 0
    assert "shipx-supply" in capsys.readouterr().out
    assert cli.main(["simulate", "--vessel", "shipx-supply", "--t-end", "20", "--out", str(tmp_path), "--no-plot"]) == 0
    assert (tmp_path / "shipx-supply-t20.nc").exists()
