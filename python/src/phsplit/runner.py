"""One core call: :func:`run` integrates a vessel with given settings from a given state and
builds its :class:`~phsplit.solution.Solution` (:func:`solution_of`, the one place a Solution
is made, used by the multi-call drivers too), with the warnings on the step size and on
energy created by negative sub-steps."""
from __future__ import annotations

import math
import os
import sys
import warnings

import numpy as np

from . import _core
from .settings import Settings
from .solution import Ledger, Solution
from .vessel import Vessel

def user_stacklevel() -> int:
    """The ``stacklevel`` that points a warning at the user's code: the first frame, counted from
    the caller of ``warnings.warn``, outside the package (however many of phsplit's own calls and
    argument checks lie between)."""
    here = os.path.dirname(os.path.abspath(__file__)) + os.sep
    frame, level = sys._getframe(1), 1
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(here):
        frame, level = frame.f_back, level + 1
    return level


class StepSizeWarning(UserWarning):
    """The step is longer than half the vessel's shortest natural period: the run stays
    passive and bounded (for the splitting methods) but cannot resolve that motion."""


class SettingWarning(UserWarning):
    """A run setting could not act as asked and the run says what it did instead (the exact
    flow S2 on a vessel whose S2 has a forcing part, which Gauss collocation integrates; a
    thruster failure or a sensor dropout outside the run's span)."""


class PassivityWarning(UserWarning):
    """A composition with negative sub-steps created energy: its discrete map is passive only
    under the condition of the paper's Prop. 2.5, which this run does not meet."""

class ModelRangeWarning(UserWarning):
    """The motion left the range where the model holds: roll or pitch beyond the small angles
    of the metacentric restoring (``GM sin θ``, docs/model.md §2.3), which a real hull's
    righting arm leaves as its deck edge or bilge emerge. The run's numbers are those of the
    model, not of the hull there."""


#: Largest roll and pitch (degrees) the metacentric restoring is taken to hold to. Within the
#: small angles of initial stability the righting arm is GZ ≈ GM sin φ; beyond them a hull's
#: GZ curve departs from it (the wall-sided correction, then deck-edge immersion or bilge
#: emergence), by how much depending on its lines, which phsplit does not have. The limits are
#: a chosen threshold, stated, not a property of a hull.
LINEAR_RESTORING_LIMITS = {"roll": 15.0, "pitch": 10.0}


def _warn_if_out_of_range(sol, stacklevel: int) -> None:
    eu = np.asarray(sol.euler)
    if eu.ndim != 2 or len(eu) == 0:
        return
    for k, (name, limit) in enumerate(LINEAR_RESTORING_LIMITS.items()):
        a = np.degrees(np.abs(eu[:, k]))
        if np.all(np.isfinite(a)) and a.max() > limit:
            i = int(np.argmax(a))
            warnings.warn(ModelRangeWarning(
                f"{name} reached {a[i]:.0f} degrees (t = {float(sol.t[i]):g} s), beyond the {limit:g} degrees to which the "
                f"metacentric restoring (GM sin θ) holds: the run follows the model, not the hull's own righting "
                f"arm there (docs/model.md §2.3)"), stacklevel=user_stacklevel())


def _warn_if_energy_created(raw: dict, info: dict, outer: str, e: np.ndarray, stacklevel: int) -> None:
    """Prop. 2.5: with negative sub-steps the composition dissipates only if
    sum(mu_i c_i) >= 0 over the dissipative flow's coefficients, i.e. if sigma_max/sigma_min of
    H^(1/2) D H^(1/2) is below a bound of the method. Here D acts on the velocities only
    (sigma_min = 0), so the condition never holds; the ledger tells whether energy was created."""
    d = raw["dissipated"][1:]
    scale = abs(e[0]) + np.abs(raw["supplied"]).sum() + np.abs(d[np.isfinite(d)]).sum()
    bad = ~np.isfinite(d) | (d < -1e-12 * scale)
    if not bad.any():
        return
    i = int(np.argmax(bad)) + 1
    key = "dissipation_ratio_bound_outer" if outer == "dissipative" else "dissipation_ratio_bound_inner"
    warnings.warn(PassivityWarning(
        f"{info['name'].upper()} has negative sub-steps and created energy in {int(bad.sum())} saved "
        f"interval(s), first ending at t = {raw['t'][i]:g} s ({d[i - 1]:.3e} J dissipated). Its passivity needs "
        f"the Prop. 2.5 condition sigma_max/sigma_min <= {info[key]:.3g} for H^(1/2) D H^(1/2); this vessel's "
        "D is only semidefinite (sigma_min = 0), so the condition does not hold. Use a smaller h, or "
        "'sp2'/'lie', whose positive steps are passive for any h (Prop. 2.2)."), stacklevel=user_stacklevel())


def warn_if_timed_settings_idle(vessel: Vessel, t_span: tuple[float, float], stacklevel: int,
                                control_start: float | None = None, used: dict | None = None) -> None:
    """A :class:`SettingWarning` for each timed setting that this run's span leaves without
    effect: the controller's start (``control_start``) or a moving set point's start
    (``setpoint.start_time``) after the run's end, a thruster lost or stuck (``lost_at``,
    ``stuck_at``) after it, a sensor dropout wholly before its start or after its end. The vessel
    is the same for any span (a run cut into parts sees each part's), so the whole run's span is
    judged here, where the user gives it."""
    t0, t1 = float(t_span[0]), float(t_span[1])
    if used is not None and _core.method_info(used["method"])["kind"] != "splitting":
        for key, default in (("outer", Settings.outer), ("linear_flow", Settings.linear_flow)):
            if used[key] != default:
                warnings.warn(SettingWarning(
                    f"{key} = {used[key]!r} chooses among a splitting method's flows, and {used['method']} is "
                    f"explicit Runge-Kutta: it does not act in this run"), stacklevel=user_stacklevel())
    # The default start (the paper's 50 s) is not the user's choice: a short run with it is no slip.
    if control_start is not None and control_start > t1 and control_start != Settings.control_start:
        warnings.warn(SettingWarning(
            f"control_start = {control_start:g} s is after the run's end ({t1:g} s): the controller does not act in "
            f"this run (control_start = None says so)"), stacklevel=user_stacklevel())
    d = vessel.to_dict()
    start = (d.get("setpoint") or {}).get("start_time")
    if isinstance(start, (int, float)) and not isinstance(start, bool) and start > t1 and "control" in d:
        warnings.warn(SettingWarning(
            f"setpoint.start_time = {start:g} s is after the run's end ({t1:g} s): the set point does not move in "
            f"this run"), stacklevel=user_stacklevel())
    for i, unit in enumerate((d.get("thrusters") or {}).get("unit") or []):
        for key, what in (("lost_at", "lost"), ("stuck_at", "stuck")):
            at = unit.get(key) if isinstance(unit, dict) else None
            if isinstance(at, (int, float)) and not isinstance(at, bool) and at > t1:
                warnings.warn(SettingWarning(
                    f"thrusters.unit[{i}].{key} = {at:g} s is after the run's end ({t1:g} s): the thruster is not "
                    f"{what} in this run"), stacklevel=user_stacklevel())
    for key in ("gnss_dropout", "gyro_dropout"):
        rows = (d.get("sensors") or {}).get(key) or []
        for k, row in enumerate(rows):
            if isinstance(row, (list, tuple)) and len(row) == 2 and all(
                    isinstance(v, (int, float)) and not isinstance(v, bool) for v in row):
                a, b = float(row[0]), float(row[1])
                if b <= t0 or a >= t1:
                    where = "before the run's start" if b <= t0 else "after the run's end"
                    warnings.warn(SettingWarning(
                        f"sensors.{key}[{k}] = [{a:g}, {b:g}] s lies wholly {where} (the run spans [{t0:g}, {t1:g}] "
                        f"s): the sensor does not drop out in this run"), stacklevel=user_stacklevel())


def _warn_if_step_too_long(vessel: Vessel, y0: np.ndarray | None, settings: Settings, stacklevel: int) -> None:
    """A StepSizeWarning when h exceeds half the shortest natural period of the
    vessel (flow S2 linearised at the initial attitude, with the controller as it will act):
    fewer than two steps per period cannot represent that oscillation. Not for adaptive steps:
    ``h`` is then only the first step tried, and the error control chooses the rest."""
    if settings.adaptive:
        return
    try:
        h = float(settings.h)
        if not (math.isfinite(h) and h > 0.0):
            return  # the core refuses it, by name, when the run starts
        state = vessel.initial_state() if y0 is None else y0
        periods = vessel._natural_periods_at(state, settings.control_start is not None)
    except (_core.InvalidInputError, ValueError, TypeError):
        return  # the core reports bad input when the run starts
    if periods and h > 0.5 * periods[0]:
        warnings.warn(StepSizeWarning(
            f"h = {h:g} s is more than half the vessel's shortest natural period ({periods[0]:.3g} s; "
            f"periods {', '.join(f'{p:.3g}' for p in periods[:4])} s): the run cannot resolve that motion. "
            f"The splitting methods stay bounded and passive at such steps; take h < {0.5 * periods[0]:.3g} s to "
            f"resolve it, and about a tenth of the period ({0.1 * periods[0]:.2g} s) to follow it accurately."),
            stacklevel=user_stacklevel())



def solution_of(columns: dict[str, np.ndarray], booked: np.ndarray, names: list[str], kinds: dict[str, str],
                supplied: np.ndarray, dissipated: np.ndarray, controls: tuple[str, ...] = (), **rest) -> Solution:
    """The one constructor of a :class:`Solution`: the state ``columns`` at the saved times
    (``t``, ``x``, ``euler``, ``quaternion``, ``Q``, ``p``, ``m``, ``mu``, ``phi_th``,
    ``phi_x``, ``energy``, ``orthogonality_defect``, ``account_force``, ``account_moment``),
    the energy ``booked`` by each account in each saved interval ((N, accounts), first row
    zero) with their ``kinds`` and the names of the controller's accounts (``controls``), their totals ``supplied`` and ``dissipated``, and the run's
    other fields (``status``, ``method``, ``h``, ...). The ledger's ``dH`` and levels come from
    the energy here, the same way for a single call and for a run assembled from several."""
    e = np.asarray(columns["energy"])
    ledger = Ledger(dH=np.concatenate([[0.0], np.diff(e)]) if len(e) else e, supplied=supplied,
                    dissipated=dissipated, by_account={n: booked[:, k] for k, n in enumerate(names)},
                    kinds=dict(kinds), controls=tuple(controls), level=Ledger.level_of(e))
    return Solution(ledger=ledger, **columns, **rest)


_COLUMNS = ("t", "x", "euler", "quaternion", "Q", "p", "m", "mu", "phi_th", "phi_x", "energy",
            "orthogonality_defect", "account_force", "account_moment")


def run(vessel: Vessel, settings: Settings, y0: np.ndarray | None = None, *, orthonormalize: bool = False,
        callback=None, running_max: bool = False, continuing: bool = False, stacklevel: int = 4,
        save_at: np.ndarray | None = None) -> Solution:
    """One core call: ``vessel`` integrated with ``settings`` from ``y0`` (the vessel's initial
    state when None). ``continuing``: ``y0`` is the last state of an earlier call of the same
    run (chunks, ``save_at``, events, ``Solution.at``), taken as it is, only checked to be finite.
    ``callback(steps_done, n_steps)`` is called as the core goes. ``stacklevel`` places the
    warnings at the user's call. ``save_at``: an adaptive run's output times."""
    _warn_if_step_too_long(vessel, y0, settings, stacklevel)
    raw = _core.integrate(vessel._inner, settings.as_core(), y0, bool(orthonormalize), callback, bool(running_max),
                          bool(continuing and y0 is not None), save_at)
    used = raw["settings"]
    e = raw["energy"]
    info = _core.method_info(used["method"])
    if used["linear_flow"] == "exact" and raw["s2_solver"] != "exact" and info["kind"] == "splitting":
        warnings.warn(SettingWarning(
            "linear_flow = 'exact' cannot act on this vessel: its flow S2 has a forcing part (a load that is "
            "not affine in the state, or that depends on time), which Gauss collocation of the method's order "
            "integrates; the run used linear_flow = 'gauss' (docs/model.md §3.7)"), stacklevel=user_stacklevel())
    if used["ledger"] and info["kind"] == "splitting" and not info["all_positive"] and len(e) > 1:
        _warn_if_energy_created(raw, info, used["outer"], e, stacklevel)
    mass, inertia = vessel._body()
    names = list(raw["accounts"])
    sol = solution_of(
        {k: raw[k] for k in _COLUMNS}, raw["booked"], names, dict(zip(names, raw["account_kinds"])),
        raw["supplied"], raw["dissipated"], controls=tuple(raw["control_accounts"]),
        status=raw["status"], method=info["name"], h=used["h"], control_start=used["control_start"],
        steps=raw["steps"], failure=raw.get("failure"), last_good_state=raw["last_good"],
        meta={"mass": mass, "inertia": inertia, "mass_matrix": vessel.mass_matrix, "s2_solver": raw["s2_solver"],
              "rejected": int(raw["rejected"]),
              "t_last_good": raw["t_last_good"], "components": vessel.components},
        settings=dict(used),
        outputs={k: (u, ln, np.asarray(v)) for k, (u, ln, v) in raw.get("outputs", {}).items()},
        actuators=raw.get("actuators"),
        own=raw.get("own"),
    )
    # What reruns it (phsplit rerun): the vessel file, the initial state the core used, one chunk.
    sol.meta["running_max"] = dict(raw["running_max"])
    sol.meta["provenance"] = {"vessel_toml": vessel.to_toml(), "initial_state": sol.state(0),
                              "chunks": [int(used["n_steps"])]}
    _warn_if_out_of_range(sol, stacklevel)
    return sol


def continue_from(vessel: Vessel, settings: Settings, t_a: float, t_b: float, h: float, y: np.ndarray,
                  save_every: int, callback=None) -> Solution:
    """One core call of a run cut into several: ``settings`` on ``[t_a, t_b]`` with step ``h``
    (a call of only a last, shorter step takes that step's length), continuing from the run's
    own state ``y``."""
    from dataclasses import replace

    h = min(h, t_b - t_a)
    y = np.ascontiguousarray(y, dtype=float)
    return run(vessel, replace(settings, t_span=(t_a, t_b), h=h, save_every=save_every), y, callback=callback,
               continuing=True, stacklevel=5)
