import numpy as np
import pytest

import phsplit


def test_simulate_returns_labelled_arrays():
    sol = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, 10.0), h=0.5, method="sp2")
    assert sol.t.shape == (21,)
    assert sol.x.shape == (21, 3) and sol.Q.shape == (21, 3, 3) and sol.quaternion.shape == (21, 4)
    np.testing.assert_allclose(sol.euler[0], [0.05, -0.02, 0.10], atol=1e-15)
    np.testing.assert_allclose(sol.x[0], [723.0, 0.0, 0.0])
    ds = sol.to_xarray()
    assert ds["position"].attrs["units"] == "m"
    assert ds.attrs["method"] == "sp2"


def test_unknown_method_lists_valid_ones():
    with pytest.raises(phsplit.InvalidInputError, match="sp4"):
        phsplit.simulate(phsplit.Vessel.paper(), method="rk45")
