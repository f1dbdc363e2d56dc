"""A run whose roll or pitch leaves the small angles of the metacentric restoring says so
(``phsplit.ModelRangeWarning``), and a run within them does not."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

import phsplit
from phsplit.runner import LINEAR_RESTORING_LIMITS


def test_a_large_roll_warns_with_its_angle_and_time():
    v = phsplit.Vessel.paper()
    with pytest.warns(phsplit.ModelRangeWarning, match=r"roll reached \d+ degrees \(t = [0-9.]+ s\)"):
        s = phsplit.simulate(v, (0.0, 30.0), 0.5, "sp2", initial={"euler": [0.5, 0.0, 0.54],
                                                                  "position": [780.0, 20.0, 0.0]})
    assert np.degrees(np.abs(s.euler[:, 0])).max() > LINEAR_RESTORING_LIMITS["roll"]


def test_a_small_motion_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error", phsplit.ModelRangeWarning)
        s = phsplit.simulate(phsplit.Vessel.paper(), (0.0, 30.0), 0.5, "sp2")
    assert np.degrees(np.abs(s.euler[:, :2])).max() < 10.0
