"""The front door: :func:`simulate`, a thin façade over the runner (one core call) and the
multi-call driver of ``save_at`` and events. It checks the arguments, builds the
:class:`Settings` and the initial state, and hands the run to :func:`phsplit.runner.run` or
:func:`phsplit.events.run_with_outputs`.

The names users import from here (``Vessel``, ``Solution``, ``Ledger``, ``Settings``,
``presets``, the warnings, ``settings_to_toml``) live in the modules of the layers below and
are re-exported.
"""
from __future__ import annotations

import functools
import inspect
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core, _provided
from .events import run_with_outputs
from .runner import ModelRangeWarning, PassivityWarning, SettingWarning, StepSizeWarning, run, warn_if_timed_settings_idle
from .settings import Settings, settings_to_toml
from .solution import Ledger, Solution
from .vessel import Vessel, presets
from ._arguments import checked

__all__ = ["simulate", "Vessel", "Solution", "Ledger", "Settings", "presets", "settings_to_toml", "ModelRangeWarning",
           "StepSizeWarning", "PassivityWarning", "SettingWarning"]


#: The arguments of :func:`simulate` that are settings (fields of :class:`Settings`).
_SETTING_ARGUMENTS = ("t_span", "h", "method", "control_start", "outer", "save_every", "ledger", "project_invariants",
                      "linear_flow", "rtol", "atol", "h_max")


def _settings_alone(f):
    """``simulate`` refusing a settings argument given beside ``settings=`` (which gives every
    setting, so the argument would not be used), told from the call's own arguments."""
    sig = inspect.signature(f)
    assert sig.parameters["settings"].kind == inspect.Parameter.KEYWORD_ONLY

    @functools.wraps(f)
    def call(*args, **kw):
        if kw.get("settings") is None:
            return f(*args, **kw)  # settings= is keyword-only: nothing to compare
        try:
            given = sig.bind(*args, **kw).arguments
        except TypeError:
            return f(*args, **kw)
        if given.get("settings") is not None:
            both = [n for n in _SETTING_ARGUMENTS if n in given
                    and not (n in ("rtol", "atol", "h_max") and given[n] is None)]
            if both:
                raise _core.InvalidInputError(
                    f"settings=... gives every setting, so {', '.join(both)} would not be used: give them in the "
                    f"Settings (dataclasses.replace(settings, {both[0]}=...)), or leave settings out")
        return f(*args, **kw)

    return call


@checked
@_settings_alone
def simulate(
    vessel: Vessel,
    t_span: tuple[float, float] = Settings.t_span,
    h: float = Settings.h,
    method: str = Settings.method,
    control_start: float | None = Settings.control_start,
    *,
    outer: str = Settings.outer,
    save_every: int = Settings.save_every,
    ledger: bool = Settings.ledger,
    project_invariants: bool = Settings.project_invariants,
    initial: np.ndarray | Mapping[str, Sequence[float]] | None = None,
    linear_flow: str = Settings.linear_flow,
    rtol: float | None = None,
    atol: float | None = None,
    h_max: float | None = None,
    orthonormalize: bool = False,
    settings: Settings | None = None,
    progress: bool | Any = None,
    save_at: Sequence[float] | np.ndarray | None = None,
    events: Sequence[Any] | None = None,
    running_max: bool = False,
    _continuing: bool = False,
) -> Solution:
    """Simulate the vessel over ``t_span`` with fixed steps ``h``, or adaptive steps to a
    tolerance (``rtol``, ``atol``; ``h`` is then the first step tried, ``h_max`` the longest).

    ``method`` is one of ``phsplit.METHODS``: splitting ``lie``, ``sp2`` (Strang), ``sp4``,
    ``sp6`` (Blanes–Moan) or explicit Runge–Kutta ``euler``, ``heun``, ``rk4``. The controller
    acts from the first step that starts at or after ``control_start`` (``None``: never).
    ``outer`` chooses the outermost flow of a splitting: ``"dissipative"`` (S2, default) or
    ``"conservative"`` (S1). The run takes ``ceil((t1 - t0) / h)`` steps (to round-off), the
    last one shorter when the span is not a whole number of steps, and saves every
    ``save_every``-th step and the last. ``project_invariants`` (default on) turns the attitude
    after every step so that the restoring invariant ``mu = G Q^T e3`` of the exact flow holds
    again; it changes no energy (docs/model.md §3.6); ``False`` runs the paper's scheme as
    printed. ``initial`` overrides the vessel's initial state: a flat 27-vector (for rate-limited thrusters optionally
    followed by their memory, as :meth:`Solution.state` gives it) or a mapping with ``euler``, ``position``, ``velocity``,
    ``angular_velocity``. ``linear_flow`` integrates the linear flow S2 exactly
    (``"exact"``, matrix exponentials: the paper's scheme, §3.4.2) or by Gauss collocation of
    the method's order (``"gauss"``: the diagonal Padé approximant, same order, still passive,
    paper Remark 2.3), or of order 4 or 6 whatever the method (``"gauss4"``, ``"gauss6"``: two
    or three stages, still passive; in a sea, ``sp2`` with ``"gauss4"`` reaches 1 cm over an
    hour at about four times the step of ``"gauss"``, docs/how-to, "The linear flow S2");
    ``"auto"``, the default, takes the exact flow with fixed steps where
    it acts on a vessel with the paper's diagonal mass matrix and no component states,
    ``"gauss4"`` with fixed steps of ``sp2`` or ``mcl2`` where S2 has a forcing part (and no
    component states), Gauss elsewhere and with adaptive steps (measured: docs/how-to,
    "The linear flow S2"); ``Solution.meta["s2_solver"]`` says which ran. An initial
    attitude that is not a rotation is rejected unless ``orthonormalize=True`` asks for its
    projection to the nearest rotation. ``settings`` (a :class:`Settings`) gives all the
    settings at once; with it, a settings argument given as well is refused (it would not be used).

    Every setting is validated by the core; a bad one raises ``InvalidInputError`` naming it.
    A span that is not a whole number of steps ends with one shorter step, at ``t1``.
    A run whose state becomes non-finite stops there: ``status == "failed"``, ``failure`` says
    where, the arrays hold what was saved before, ``last_good_state`` the last finite state.

    Long runs: the core checks for Ctrl-C about every 0.1 s; an interrupted run returns what it
    computed, ending on its last completed step, with ``status == "interrupted"``.
    ``progress=True`` shows a progress bar (tqdm); a callable is called as
    ``progress(steps_done, n_steps)`` as often (an exception it raises stops the run and is
    raised).

    ``save_at`` (times within ``t_span``) returns the states at exactly those times instead of the
    grid's: each is one method step from the grid point before it, as a run ending there would
    compute it (no interpolation). ``events`` (``phsplit.events``: watch circle, roll or pitch
    beyond a limit, energy above a level, or your own condition) are located within a step to
    1e-12 s in the partial-step length; a terminal one ends the run there (``status ==
    "event"``), and every one found is in ``Solution.events``. ``running_max=True`` keeps the
    largest controller force and moment over every step, saved or not
    (``Solution.meta["running_max"]``: name → (value, time)).

    Adaptive steps (splitting methods): each step is taken whole and as two halves, the
    difference gives the halves' local error (Richardson), and a PI controller chooses the next
    step; the halves are kept, so every accepted step is two ordinary steps of the method and
    keeps its energy statement. The error is weighed per component as ``atol + rtol·|y|`` on the
    position (m), the attitude (rad), the body velocities (m/s, rad/s) and the controller's
    integrals; with one of ``rtol``, ``atol`` the other takes ``solve_ivp``'s default (1e-3,
    1e-6). ``save_every`` counts accepted steps; ``Solution.meta["rejected"]`` counts the
    rejected trials (docs/numerics.md).
    """
    if not isinstance(vessel, Vessel):
        raise _core.InvalidInputError(f"vessel must be a phsplit.Vessel, got {type(vessel).__name__}")
    for name, flag in (("orthonormalize", orthonormalize), ("running_max", running_max)):
        if not isinstance(flag, (bool, np.bool_)):
            raise _core.InvalidInputError(f"{name} must be True or False, got {flag!r}")
    if settings is None:
        settings = Settings(t_span=t_span, h=h, method=method, control_start=control_start, outer=outer,
                            save_every=save_every, linear_flow=linear_flow, ledger=ledger,
                            project_invariants=project_invariants, rtol=rtol, atol=atol, h_max=h_max)
    elif not isinstance(settings, Settings):
        raise _core.InvalidInputError(f"settings must be a phsplit.Settings, got {type(settings).__name__}")
    if not _continuing:
        used = settings.checked()
        warn_if_timed_settings_idle(vessel, used["t_span"], stacklevel=4, control_start=used["control_start"],
                                    used=used)
    if isinstance(settings.save_every, float):
        raise _core.InvalidInputError(f"save_every must be an integer >= 1, got {settings.save_every!r}")
    if initial is None:
        y0 = None
    elif isinstance(initial, Mapping):
        y0 = vessel.initial_state(**initial)
    else:
        try:
            y0 = np.ascontiguousarray(initial, dtype=float)
        except (TypeError, ValueError):
            raise _core.InvalidInputError("initial must be a flat 27-vector of numbers or a mapping with euler, "
                                          "position, velocity, angular_velocity") from None
        if y0.ndim != 1:
            raise _core.InvalidInputError(f"a flat initial state is a 1-D array of {_core.STATE_DIM} numbers, "
                                          f"got shape {y0.shape}")
    if save_at is not None and settings.save_every != 1:
        raise _core.InvalidInputError(f"save_at gives the saved times itself, so save_every = {settings.save_every!r} "
                                      f"would not be used: give one of them")
    adaptive_at = None
    if settings.adaptive and save_at is not None:
        # The core computes the output times itself, without cutting its adaptive steps.
        from .events import _check_times

        if settings.save_every != 1:
            raise _core.InvalidInputError(f"save_at gives the saved times itself, so save_every = "
                                          f"{settings.save_every!r} would not be used: give one of them")
        adaptive_at, save_at = np.ascontiguousarray(_check_times(save_at, *settings.t_span), dtype=float), None
    if running_max and (save_at is not None or adaptive_at is not None or events):
        raise _core.InvalidInputError("running_max cannot be combined with save_at or events")
    if events is not None and not isinstance(events, (list, tuple)):
        events = [events]  # a single Event
    if (save_at is not None or events) and y0 is not None and not _continuing:
        y0 = _core.check_state(y0, bool(orthonormalize))  # a user's state: checked once, here
    bars: list = []  # the progress bar, drawn from the first report on (not before an input error)
    if progress is True:
        from tqdm import tqdm

        n = settings.checked()["n_steps"]

        def cb(done, total):
            if not bars:
                bars.append(tqdm(total=n, unit="step", unit_scale=True, leave=False))
            bars[0].update(done - bars[0].n)
    elif progress is None or progress is False:
        cb = None
    elif callable(progress):
        cb = progress
    else:
        raise _core.InvalidInputError(f"progress must be True, False, None or a callable f(steps_done, n_steps), "
                                      f"got {type(progress).__name__}")
    try:
        if save_at is not None or events:
            # Output at chosen times, or events: several core calls (phsplit.events).
            return run_with_outputs(vessel, settings, y0, save_at=save_at, events=events, callback=cb)
        # _continuing: y0 is the last state of an earlier call of the same run, taken as it is.
        sol = run(vessel, settings, y0, orthonormalize=bool(orthonormalize), callback=cb,
                  running_max=bool(running_max), continuing=bool(_continuing), save_at=adaptive_at)
        if adaptive_at is not None:
            # Exactly the rows asked for (the core also saves the start and the end), as with
            # fixed steps; not rerunnable as one call, as save_at with fixed steps.
            from .events import only_times

            return only_times(sol, adaptive_at, settings)
        return sol
    finally:
        for b in bars:
            b.close()


_provided.provide("simulate", simulate)
