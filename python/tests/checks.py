"""Checks the tests share.

* ``fitted_order``: a method of phsplit against the independent reference (reference.py:
  eq. (39) in numpy, by DOP853 at rtol 1e-13), on [0, t_end] with the controller on from t = 0,
  at a sequence of steps. The error is the relative error of the final linear momentum; the
  slope is fitted over the steps whose error is above round-off.
* ``within_passivity_bound``: the discrete passivity inequality with the ports,
  ``H_n <= H_0 + supplied_n`` at every saved state, and every dissipation >= 0."""
from __future__ import annotations

import numpy as np

import phsplit
import reference as ref


def fitted_order(vessel, y0, method: str, hs, t_end: float = 2.0, linear_flow: str = "exact",
                 outer: str = "dissipative"):
    """(slope, errors, reference final state) of ``method`` at the steps ``hs``. The runs keep
    the paper's scheme (exact S2 unless ``linear_flow`` says otherwise, S2 outermost unless
    ``outer`` says otherwise, no projection) and no ledger, as the reference has neither."""
    _, y = ref.solve(vessel.to_dict(), y0, t_end, 0.0, rtol=1e-13)
    pe = y[-1][0:3]
    hs = np.asarray(hs, dtype=float)
    errs = []
    for h in hs:
        s = phsplit.simulate(vessel, (0.0, t_end), h, method, control_start=0.0, ledger=False, initial=y0,
                             project_invariants=False, linear_flow=linear_flow, outer=outer)
        errs.append(np.linalg.norm(s.p[-1] - pe) / np.linalg.norm(pe))
    errs = np.array(errs)
    keep = errs > 1e-13
    slope = np.polyfit(np.log(hs[keep]), np.log(errs[keep]), 1)[0]
    return slope, errs, y[-1]


def within_passivity_bound(s) -> bool:
    """Whether a run kept ``H_n <= H_0 + supplied_n`` (to 1e-10 of the gross flows booked so far)
    and booked no negative dissipation."""
    supplied = np.cumsum(s.ledger.supplied)
    scale = np.cumsum(sum(np.abs(b) for b in s.ledger.by_account.values()))
    bound = bool(np.all(s.energy <= s.energy[0] + supplied + 1e-10 * scale + 1e-9))
    return bound and bool(np.all(s.ledger.dissipated[1:] >= 0))
