"""Output when you want it, and events.

``save_at``: the states at chosen times. phsplit steps *exactly* to each time: the run keeps its
grid ``t0 + k h``, and the state at a time ``s`` between grid points ``t_k < s < t_{k+1}`` is one
step of the method of length ``s − t_k`` from the grid state at ``t_k``, the very computation a
run with ``t_span = (t0, s)`` ends with (its last, shorter step). So every ``save_at`` state
has the method's order, and none is interpolated. The grid run itself is not changed by it.
With adaptive steps (``rtol``, ``atol``) the core does the same on its accepted steps (each two
halves): an output inside one is a step from the run's last state before it, at most half the
accepted length, so its error stays within the tolerance (docs/numerics.md, "Adaptive steps").

Events: a condition ``g(t, state) = 0`` watched after every step. A crossing between two grid
points is located by the Illinois variant of regula falsi on the length ``τ`` of a partial step
from the grid state before it (each trial one method step of length ``τ``), to ``|Δτ| ≤ 1e-12
s``. The crossing time is then as accurate as the method's states are. A terminal event ends the
run at the crossing; otherwise it is recorded and the run goes on. With adaptive steps
(``rtol``, ``atol``) the accepted steps take the grid's place, and each trial is the partial
step taken as two halves, as the accepted steps are, so the crossing is within the tolerance
(the run is computed to its end and cut at a terminal event). Built-in conditions:
:func:`watch_circle` (horizontal distance to the set point), :func:`roll_beyond`,
:func:`pitch_beyond`, :func:`energy_above`; any callable ``g(t, y)`` on the flat 27-vector state (followed, for a vessel with rate-limited
thrusters, by their memory: see :meth:`Solution.state`)
works too.

Energy statement: the states at ``save_at`` times and at events lie on the method's own
trajectory through partial steps, and the ledger between two of them is the grid run's booking up
to the last grid point plus the partial step's own booking. ``ΔH = supplied − dissipated`` holds
between any two of them as it does between grid points.

>>> import phsplit
>>> v = phsplit.Vessel.paper()
>>> s = phsplit.simulate(v, (0.0, 100.0), 0.5, "sp2", control_start=0.0, save_at=[0.0, 12.34, 99.9])
>>> s.t.tolist()
[0.0, 12.34, 99.9]
>>> e = phsplit.simulate(v, (0.0, 200.0), 0.5, "sp2", control_start=0.0,
...                      events=[phsplit.events.watch_circle(30.0, direction="enter")])
>>> e.status, round(e.events[0].t, 3)
('event', 7.772)
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from . import _core, _provided
from .runner import continue_from, solution_of
from .settings import Settings
from .vessel import Vessel
from ._arguments import checked

__all__ = ["Event", "EventHit", "watch_circle", "roll_beyond", "pitch_beyond", "energy_above"]


@dataclass(frozen=True)
class Event:
    """A condition ``g(t, y, vessel) = 0`` on the flat state ``y``; a crossing in ``direction``
    (``"both"``, ``"rise"``: g goes from < 0 to ≥ 0, ``"fall"``: the reverse) is an event.
    ``terminal`` ends the run there."""

    name: str
    g: Callable[[float, np.ndarray, Any], float]
    direction: str = "both"
    terminal: bool = True

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise _core.InvalidInputError(f"an event's name must be a non-empty string, got {self.name!r}")
        if not isinstance(self.terminal, (bool, np.bool_)):
            raise _core.InvalidInputError(f"event {self.name!r}: terminal must be True or False, got "
                                          f"{self.terminal!r}")
        if self.direction not in ("both", "rise", "fall"):
            raise _core.InvalidInputError(f"event {self.name!r}: direction must be 'both', 'rise' or 'fall', "
                                          f"got {self.direction!r}")
        if not callable(self.g):
            raise _core.InvalidInputError(f"event {self.name!r}: g must be callable g(t, y, vessel)")

    def value(self, t: float, y, vessel) -> float:
        """``g(t, y, vessel)`` as a float; an exception raised by ``g`` during a run becomes one
        line naming the event and the time."""
        try:
            return float(self.g(t, y, vessel))
        except Exception as e:  # the user's function: any failure of it is theirs to see named
            raise _core.InvalidInputError(f"event {self.name!r}: g(t, y, vessel) raised {type(e).__name__} at "
                                          f"t = {t:g} s: {e}") from None

    def crosses(self, g0: float, g1: float) -> bool:
        if not (math.isfinite(g0) and math.isfinite(g1)):
            return False
        rise, fall = g0 < 0.0 <= g1, g0 >= 0.0 > g1
        return {"both": rise or fall, "rise": rise, "fall": fall}[self.direction]


@dataclass(frozen=True)
class EventHit:
    """An event found: its name, time (s), the state there (flat 27-vector, with the thrusters' memory after it for rate-limited
    thrusters) and whether it
    ended the run."""

    name: str
    t: float
    state: np.ndarray = field(repr=False)
    terminal: bool


def _set_point(vessel) -> np.ndarray:
    c = tomllib.loads(vessel.to_toml()).get("control")
    if not c:
        raise _core.InvalidInputError("watch_circle needs a set point: the vessel has no [control] table")
    return np.asarray(c["position_reference"], dtype=float)


def _positive(name: str, what: str, v) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not (math.isfinite(v) and v > 0):
        raise _core.InvalidInputError(f"{name}: {what} must be a finite number > 0, got {v!r}")
    return float(v)


@checked
def watch_circle(radius: float, direction: str = "leave", terminal: bool = True) -> Event:
    """The horizontal distance to the controller's set point crosses ``radius`` (m):
    ``direction="leave"`` (outward, the alarm), ``"enter"`` or ``"both"``. With a moving set
    point (``[setpoint]``) the circle moves with the desired position of the reference model."""
    r = _positive("watch_circle", "radius (m)", radius)
    _terminal("watch_circle", terminal)
    if direction not in ("leave", "enter", "both"):
        raise _core.InvalidInputError(f"watch_circle: direction must be 'leave', 'enter' or 'both', got {direction!r}")
    cache: dict[int, tuple[Any, np.ndarray]] = {}

    def g(t, y, vessel):
        hit = cache.get(id(vessel))
        if hit is None or hit[0] is not vessel:  # the vessel is held, so its id is not reused
            moving = "setpoint" in tomllib.loads(vessel.to_toml())
            hit = cache[id(vessel)] = (vessel, None if moving else _set_point(vessel))
        if hit[1] is None:
            o = vessel._inner.outputs(np.ascontiguousarray(y, dtype=float), float(t))
            return math.hypot(y[18] - o["setpoint_x"], y[19] - o["setpoint_y"]) - r
        ref = hit[1]
        return math.hypot(y[18] - ref[0], y[19] - ref[1]) - r

    d = {"leave": "rise", "enter": "fall", "both": "both"}[direction]
    return Event(f"watch_circle_{r:g}m_{direction}", g, d, terminal)


def _terminal(name: str, terminal) -> bool:
    if not isinstance(terminal, (bool, np.bool_)):
        raise _core.InvalidInputError(f"{name}: terminal must be True or False, got {terminal!r}")
    return bool(terminal)


#: The largest |roll| and |pitch| an Euler angle (ZYX) can reach, degrees: an event beyond it never fires.
ANGLE_LIMITS = {"roll_beyond": 180.0, "pitch_beyond": 90.0}


def _angle_event(which: int, label: str, limit_deg: float, terminal: bool) -> Event:
    lim_deg = _positive(label, "limit (degrees)", limit_deg)
    top = ANGLE_LIMITS[label]
    if lim_deg >= top:
        raise _core.InvalidInputError(f"{label}: limit (degrees) must be below {top:g} (|{label.split('_')[0]}| "
                                      f"never exceeds {top:g} degrees, so the event could never fire), got {limit_deg!r}")
    lim = math.radians(lim_deg)
    _terminal(label, terminal)

    def g(t, y, vessel):
        q = y[6:15].reshape(3, 3, order="F")
        e = _core.euler_zyx(q.tolist())
        return abs(e[which]) - lim

    return Event(f"{label}_{limit_deg:g}deg", g, "rise", terminal)


@checked
def roll_beyond(degrees: float, terminal: bool = True) -> Event:
    """``|roll|`` rises above ``degrees``."""
    return _angle_event(0, "roll_beyond", degrees, terminal)


@checked
def pitch_beyond(degrees: float, terminal: bool = True) -> Event:
    """``|pitch|`` rises above ``degrees``."""
    return _angle_event(1, "pitch_beyond", degrees, terminal)


@checked
def energy_above(joules: float, terminal: bool = True) -> Event:
    """The stored energy H rises above ``joules``."""
    e_max = _positive("energy_above", "energy (J)", joules)
    _terminal("energy_above", terminal)
    return Event(f"energy_above_{e_max:g}J", lambda t, y, vessel: vessel.energy(y) - e_max, "rise", terminal)


# ----------------------------------------------------------------------------------------------
# the runs

_FIELDS = ("x", "euler", "quaternion", "Q", "p", "m", "mu", "phi_th", "phi_x", "energy", "orthogonality_defect",
           "account_force", "account_moment")


def _check_times(save_at, t0: float, t1: float) -> np.ndarray:
    items = save_at if isinstance(save_at, (list, tuple)) else [save_at]
    if isinstance(save_at, (str, bytes)) or any(isinstance(x, (bool, np.bool_, str, bytes)) for x in items) or (
            isinstance(save_at, np.ndarray) and save_at.dtype.kind not in "fiu"):
        raise _core.InvalidInputError(f"save_at must be a sequence of times (s), numbers, got {save_at!r}")
    try:
        ts = np.asarray(save_at, dtype=float)
    except (TypeError, ValueError):
        raise _core.InvalidInputError("save_at must be a sequence of times (s)") from None
    if ts.ndim > 1:
        raise _core.InvalidInputError(f"save_at must be a flat sequence of times (s), got an array of shape {ts.shape}")
    ts = ts.reshape(-1)
    if ts.size == 0:
        raise _core.InvalidInputError("save_at is empty: give at least one time (s)")
    if not np.all(np.isfinite(ts)):
        raise _core.InvalidInputError("save_at must hold finite times (s)")
    if np.any(np.diff(ts) <= 0):
        raise _core.InvalidInputError("save_at must be strictly increasing")
    if ts[0] < t0 or ts[-1] > t1:
        raise _core.InvalidInputError(f"save_at must lie within t_span [{t0:g}, {t1:g}] s, got "
                                      f"[{ts[0]:g}, {ts[-1]:g}]")
    return ts


class _Rows:
    """Rows taken from the Solutions of several core calls, each with the energy booked since the
    row before it, summed over that interval only: a difference of running totals would lose
    the digits of a settled hour's small bookings to the transient's large ones."""

    def __init__(self):
        self.rows: list[tuple[Any, int, float]] = []  # (solution, index, time)
        self.booked: list[np.ndarray] = []

    def add(self, sol, i: int, booked: np.ndarray, t: float | None = None):
        self.rows.append((sol, i, float(sol.t[i]) if t is None else float(t)))
        self.booked.append(np.array(booked, dtype=float))


def _booked_steps(sol, names) -> np.ndarray:
    """Per saved interval booking of a core call, (N, accounts), first row zero."""
    return np.array([sol.ledger.by_account[n] for n in names]).T.reshape(len(sol.t), len(names))


def _call(vessel, settings, t_a, t_b, h, y, save_every, callback=None):
    """One core call of a run cut into several, continuing from the run's own state ``y``."""
    return continue_from(vessel, settings, t_a, t_b, h, y, save_every, callback=callback)


def run_with_outputs(vessel, settings, y0, save_at=None, events: Sequence[Event] = (), callback=None):
    """``simulate`` with ``save_at`` or ``events`` (see the module documentation).
    ``callback(steps_done, n_steps)``: the progress over the whole run, as the core calls go."""
    if isinstance(events, Event) or not isinstance(events, (list, tuple, type(None))):
        raise _core.InvalidInputError(f"events must be a list of phsplit.events.Event objects, got "
                                      f"{type(events).__name__}")
    events = list(events or ())
    for ev in events:
        if not isinstance(ev, Event):
            raise _core.InvalidInputError(f"events must be phsplit.events.Event objects, got {type(ev).__name__}")
    names = [ev.name for ev in events]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise _core.InvalidInputError(f"events are named {twice[0]!r} twice; each event needs its own name "
                                      f"(the hits are reported by name)")
    if save_at is not None and events:
        raise _core.InvalidInputError("give save_at or events, not both: events end or mark the run on its own "
                                      "saved states (save_every); save_at then has nothing to add")
    checked = settings.checked()
    n_steps = int(checked["n_steps"])
    t0, t1 = settings.t_span
    h = float(settings.h)
    y = np.array(vessel.initial_state() if y0 is None else y0, dtype=float)
    if save_at is not None:
        _check_times(save_at, t0, t1)
    for ev in events:  # a condition that cannot be evaluated would never fire, silently
        try:
            g0 = ev.g(float(t0), y.copy(), vessel)
        except Exception as e:  # noqa: BLE001 - the user's function: its failure is reported by name
            raise _core.InvalidInputError(f"event {ev.name!r}: g(t0, y0, vessel) raised {type(e).__name__}: {e}") from None
        if isinstance(g0, (bool, np.bool_)) or not isinstance(g0, (int, float, np.integer, np.floating)) or not (
                math.isfinite(g0)):
            raise _core.InvalidInputError(f"event {ev.name!r}: g(t0, y0, vessel) must be a finite number (the event "
                                          f"is where it crosses 0), got {g0!r} at the initial state")
    names: list[str] = list(dict(vessel.accounts))
    rows = _Rows()
    hits: list[EventHit] = []
    status, failure, steps = "completed", None, 0

    def t_at(k):
        return t1 if k >= n_steps else t0 + k * h

    def from_step(k):  # the progress of a call that starts at grid step k
        return None if callback is None else (lambda done, _n: callback(k + done, n_steps))

    if save_at is not None:
        ts = _check_times(save_at, t0, t1)
        # pending: booked since the last row, up to the grid point k (less what that row's
        # partial step booked past its grid point)
        k, pending = 0, np.zeros(len(names))
        for s in ts:
            kk = min(int(np.floor((s - t0) / h * (1.0 + 1e-12))), n_steps)
            if t_at(kk) > s:  # round-off put the grid point past s
                kk -= 1
            if kk > k:
                g = _call(vessel, settings, t_at(k), t_at(kk), h, y, 10**9, from_step(k))
                pending = pending + _booked_steps(g, names).sum(axis=0)
                steps += g.steps
                if g.status != "completed":
                    status, failure = g.status, g.failure
                    rows.add(g, -1, pending)  # the last state before the failure, as plain simulate returns it
                    break
                y, k = g.last_good_state, kk
                if callback is not None:
                    callback(k, n_steps)
            tg = t_at(k)
            tol = 1e-12 * max(1.0, abs(tg))
            if abs(s - tg) <= tol:
                p = _call(vessel, settings, tg, tg + h, h, y, 1)  # its row 0 is y itself
                rows.add(p, 0, pending, t=s)
                pending = np.zeros(len(names))
            else:
                p = _call(vessel, settings, tg, s, s - tg, y, 1)
                if p.status != "completed":
                    status, failure = p.status, p.failure
                    break
                part = _booked_steps(p, names).sum(axis=0)
                rows.add(p, -1, pending + part, t=s)
                pending = -part
    elif settings.adaptive:
        return _events_on_adaptive_steps(vessel, settings, y, events, names, n_steps, callback)
    else:
        k, pending = 0, np.zeros(len(names))  # booked since the last row
        chunk = max(settings.save_every, 20_000 // settings.save_every * settings.save_every)
        while k < n_steps:
            kk = min(k + chunk, n_steps)
            g = _call(vessel, settings, t_at(k), t_at(kk), h, y, 1, from_step(k))
            b = _booked_steps(g, names)
            if k == 0:
                rows.add(g, 0, b[0])

            def keep(i, k=k, g=g):
                return (k + i) % settings.save_every == 0 or k + i == n_steps or (
                    i == len(g.t) - 1 and g.status != "completed")

            pending, ended = _watch(vessel, g, b, events, pieces=1, keep=keep, rows=rows, hits=hits,
                                    pending=pending, names=names, settings=settings)
            if ended is not None:
                status, steps = "event", k + ended - 1
                break
            steps = k + g.steps
            if g.status != "completed":
                status, failure = g.status, g.failure
                break
            y, k = g.last_good_state, kk
            if callback is not None:
                callback(k, n_steps)
    return _assemble(rows, names, status, failure, hits, steps, settings)


def _locate(vessel, settings, ev: Event, t_a: float, y_a: np.ndarray, h: float, names, pieces: int = 1):
    """The crossing of ``ev`` within the step of length ``h`` from ``(t_a, y_a)``: Illinois
    regula falsi on the partial-step length, to |Δτ| ≤ 1e-12 s (or 60 iterations), each trial
    ``pieces`` equal steps. Returns the time, the core call that ends there, and its booking."""

    def at(tau):
        return _call(vessel, settings, t_a, t_a + tau, tau / pieces, y_a, pieces)

    lo, hi = 0.0, h
    best = at(h)
    g_lo, g_hi = ev.value(t_a, y_a, vessel), ev.value(t_a + h, best.state(-1), vessel)
    side = 0
    # The shortest partial step the times of the run resolve (the core refuses shorter ones).
    tol = pieces * max(1e-12, 1024.0 * np.finfo(float).eps * max(1.0, abs(t_a) + h))
    for _ in range(60):
        if hi - lo <= tol:
            break
        tau = (lo * g_hi - hi * g_lo) / (g_hi - g_lo) if g_hi != g_lo else 0.5 * (lo + hi)
        if not (lo < tau < hi):
            tau = 0.5 * (lo + hi)
        tau = min(max(tau, tol), h)
        s = at(tau)
        g = ev.value(t_a + tau, s.state(-1), vessel)
        if ev.crosses(g_lo, g):  # the crossing is in [lo, tau]
            hi, g_hi, best = tau, g, s
            if side == 1:
                g_lo *= 0.5
            side = 1
        else:
            lo, g_lo = tau, g
            if side == -1:
                g_hi *= 0.5
            side = -1
    return t_a + hi, best, _booked_steps(best, names).sum(axis=0)


def _events_on_adaptive_steps(vessel, settings, y, events: list[Event], names, n_steps: int, callback=None):
    """Events on adaptive steps: the run is one core call to its end, saving every accepted
    step; a crossing between two accepted states is located as on the fixed grid, each trial a
    partial step from the accepted state before it taken as two halves, the accepted steps' own
    form, so its local error stays within what the controller accepted; a terminal event cuts
    the run there (the steps after it were computed and are dropped). Rows: every
    ``save_every``-th accepted step, the end, and each terminal event."""
    from dataclasses import replace

    t0, t1 = settings.t_span
    g = _call(vessel, replace(settings, save_every=1), t0, t1, settings.h, y, 1, callback)
    if callback is not None and g.status == "completed":  # the core reports only every 0.1 s
        callback(n_steps, n_steps)
    b = _booked_steps(g, names)
    rows, hits = _Rows(), []
    rows.add(g, 0, b[0])
    _, ended = _watch(vessel, g, b, events, pieces=2,
                      keep=lambda i: i % settings.save_every == 0 or i == len(g.t) - 1, rows=rows, hits=hits,
                      pending=np.zeros(len(names)), names=names,
                      settings=replace(settings, rtol=None, atol=None, h_max=None))
    if ended is not None:
        return _assemble(rows, names, "event", None, hits, ended - 1, settings)
    return _assemble(rows, names, g.status, g.failure, hits, g.steps, settings)


def _watch(vessel, g, b, events: list[Event], *, pieces: int, keep, rows: _Rows, hits: list, pending, names,
           settings):
    """Go through the steps of the core call ``g`` (``b``: each row's booking) watching
    ``events``. A crossing within a step is located by :func:`_locate` (with fixed-step
    ``settings``, each trial ``pieces`` steps) and recorded in ``hits``, in time order; a
    terminal one adds its row and ends the watch. The rows where ``keep(i)`` are added with
    what was booked since the row before (``pending`` on entry). Returns what is pending after
    the last row, and the step ``i`` a terminal event ended in (None if none did)."""
    for i in range(1, len(g.t)):
        ta, tb = float(g.t[i - 1]), float(g.t[i])
        ya, yb = g.state(i - 1), g.state(i)
        found = [(*_locate(vessel, settings, ev, ta, ya, tb - ta, names, pieces), ev)
                 for ev in events if ev.crosses(ev.value(ta, ya, vessel), ev.value(tb, yb, vessel))]
        found.sort(key=lambda f: f[0])
        for te, part, w, ev in found:
            hits.append(EventHit(ev.name, te, part.state(-1), ev.terminal))
            if ev.terminal:
                rows.add(part, -1, pending + w, t=te)
                return pending, i
        pending = pending + b[i]
        if keep(i):
            rows.add(g, i, pending)
            pending = np.zeros(len(names))
    return pending, None


def _assemble(rows: _Rows, names, status, failure, hits, steps, settings):
    """One Solution of the recorded rows and the energy booked between them (none before the first)."""
    if not rows.rows:
        raise _core.InvalidInputError("nothing was computed: the run failed at its first step")
    src = rows.rows
    pick = {f: np.array([getattr(s, f)[i] for s, i, _ in src]) for f in _FIELDS}
    t = np.array([tt for _, _, tt in src])
    booked = np.array(rows.booked, dtype=float).reshape(len(src), len(names))
    booked[0] = 0.0
    tmpl = src[-1][0]
    kinds = tmpl.ledger.kinds
    by_account = {nm: booked[:, k] for k, nm in enumerate(names)}
    zero = np.zeros(len(t))
    sup = zero + sum((by_account[nm] for nm in names if kinds[nm] == "supplied"), zero)
    dis = zero + sum((by_account[nm] for nm in names if kinds[nm] == "dissipated"), zero)
    sol = solution_of(
        {"t": t, **pick}, booked, names, kinds, sup, dis, controls=tmpl.ledger.controls,
        status=status, method=tmpl.method, h=settings.h, control_start=settings.control_start, steps=steps,
        failure=failure, last_good_state=src[-1][0].state(src[-1][1]), meta=dict(tmpl.meta),
        settings={**tmpl.settings, "t_span": tuple(settings.t_span), "h": settings.h,
                  "save_every": settings.save_every},
        outputs={k: (u, ln, np.array([s.outputs[k][2][i] for s, i, _ in src])) for k, (u, ln, _) in tmpl.outputs.items()},
        actuators=None if tmpl.actuators is None else np.array([s.actuators[i] for s, i, _ in src]),
        own=None if tmpl.own is None else np.array([s.own[i] for s, i, _ in src]),
    )
    sol.meta["events"] = hits
    sol.meta.pop("provenance", None)  # several core calls: not rerunnable as one
    return sol


def only_times(sol, times: np.ndarray, settings):
    """An adaptive run saved at ``times`` (with its start and end) cut to exactly those rows,
    the ledger between them, as ``save_at`` with fixed steps gives them (numpy slices of the one
    call's arrays)."""
    names = list(sol.ledger.by_account)
    per_step = _booked_steps(sol, names)
    t, times = np.asarray(sol.t), np.asarray(times, dtype=float)
    # The core saves the start, the times asked and the end: most often the rows after the
    # first are exactly the times (compared as such before the general search).
    if len(t) == len(times) + 1 and np.array_equal(t[1:], times):
        idx = np.arange(1, len(t))
    else:
        idx = np.flatnonzero(np.isin(t, times))
    if sol.status != "completed" and (idx.size == 0 or idx[-1] != len(sol.t) - 1):
        idx = np.append(idx, len(sol.t) - 1)  # the last state before the failure, as plain simulate returns it
    if idx.size == 0:
        raise _core.InvalidInputError("nothing was computed: the run failed at its first step")
    # Each kept row's booking: the sum over the steps since the kept row before (summed per
    # interval, not differenced from a running total, which would lose its digits).
    booked = np.zeros((idx.size, len(names)))
    if idx.size > 1:
        booked[1:] = np.add.reduceat(per_step[: idx[-1] + 1], idx[:-1] + 1, axis=0)
    kinds = sol.ledger.kinds
    sup = sum((booked[:, k] for k, nm in enumerate(names) if kinds[nm] == "supplied"), np.zeros(idx.size))
    dis = sum((booked[:, k] for k, nm in enumerate(names) if kinds[nm] == "dissipated"), np.zeros(idx.size))
    meta = {k: v for k, v in sol.meta.items() if k != "provenance"}  # not rerunnable as one call
    if idx[-1] - idx[0] + 1 == idx.size:
        idx = slice(idx[0], idx[-1] + 1)  # consecutive rows: the same rows, as views
    return solution_of(
        {"t": t[idx], **{f: np.asarray(getattr(sol, f))[idx] for f in _FIELDS}}, booked, names,
        kinds, sup, dis, controls=sol.ledger.controls, status=sol.status, method=sol.method, h=sol.h,
        control_start=sol.control_start, steps=sol.steps, failure=sol.failure, last_good_state=sol.last_good_state,
        meta=meta, settings=dict(sol.settings),
        outputs={k: (u, ln, np.asarray(v)[idx]) for k, (u, ln, v) in sol.outputs.items()},
        actuators=None if sol.actuators is None else np.asarray(sol.actuators)[idx],
        own=None if sol.own is None else np.asarray(sol.own)[idx],
    )


def dense_output(sol, times):
    """``Solution.at``: the states at ``times`` within the run of ``sol``, each by stepping from
    the last saved state at or before it (see ``Solution.at``)."""
    prov = sol.meta.get("provenance")
    if not prov or "vessel_toml" not in prov:
        raise _core.InvalidInputError("this Solution does not record its vessel (it was assembled from several "
                                      "runs); rerun with save_at instead")
    if isinstance(times, (str, bytes, bool, np.bool_)):
        raise _core.InvalidInputError(f"times must be a time or a sequence of times (s), numbers, got {times!r}")
    try:
        ts = np.asarray(times, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise _core.InvalidInputError(f"times must be a time or a sequence of times (s), numbers, got {times!r}") from None
    if ts.size == 0 or not np.all(np.isfinite(ts)) or ts.min() < sol.t[0] or ts.max() > sol.t[-1]:
        raise _core.InvalidInputError(f"times must be finite and within the run [{sol.t[0]:g}, {sol.t[-1]:g}] s")
    vessel = Vessel.from_toml_str(prov["vessel_toml"])
    cs = sol.settings.get("control_start")
    base = Settings(t_span=tuple(sol.settings["t_span"]), h=sol.h, method=sol.method, control_start=cs,
                    outer=sol.settings["outer"], save_every=1, linear_flow=sol.settings["linear_flow"],
                    ledger=bool(sol.settings["ledger"]),
                    project_invariants=bool(sol.settings.get("project_invariants", True)),
                    # an adaptive run's states between its saved ones: adaptive steps to its tolerance
                    rtol=sol.settings.get("rtol"), atol=sol.settings.get("atol"), h_max=sol.settings.get("h_max"))
    names = list(sol.ledger.by_account)
    rows = _Rows()
    zero = np.zeros(len(names))
    for t in ts:
        i = int(np.searchsorted(sol.t, t, side="right")) - 1
        if t - sol.t[i] <= 1e-12 * max(1.0, abs(t)):  # on a saved time, to round-off
            p = _call(vessel, base, t, t + sol.h, sol.h, sol.state(i), 1)
            rows.add(p, 0, zero, t=t)
        else:
            span = float(t) - float(sol.t[i])
            p = _call(vessel, base, float(sol.t[i]), float(t), min(sol.h, span), sol.state(i), 1)
            rows.add(p, -1, zero, t=t)
    return _assemble(rows, names, "completed", None, [], 0, base)


_provided.provide("dense_output", dense_output)
