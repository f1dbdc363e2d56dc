"""Static DP capability in the manner of DNV-ST-0111 (December 2021), level 1.

For each direction of a co-linear environment (wind, the sea state that goes with the wind
speed, and a current), the largest wind speed whose mean load the thrusters can balance within
their limits, intact and with thrusters lost (docs/how-to/dp-capability.md).

Every load and every limit is the core's: the wind, current and cross-flow loads are the ledger
accounts' wrenches of the vessel at rest at its heading (``_core.account_wrenches``), the mean
wave drift is the mean of the core's Newman drift with its drift-coefficient tables
(``_core.mean_wave_drift``), and the thrusters' answer is the core's allocation
(``_core.allocate``, ``forces/thrusters.rs``): a demand is held when the allocation needs no
scaling (``scale == 1``).
"""
from __future__ import annotations

import copy
import math
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from . import _core
from .vessel import Vessel
from ._arguments import checked

#: The level-1 environment: Beaufort number, wind speed (m/s, 10 m above the sea, the top of
#: the Beaufort class), significant wave height Hs (m), peak period Tp (s) and current speed
#: (m/s), the level-1 table of DNV-ST-0111 (2021) as it is usually restated (not checked against
#: the standard's text here: pass your own as `environment`); wind, waves and current co-linear.
LEVEL1 = (
    (0, 0.0, 0.0, 0.0, 0.0),
    (1, 1.5, 0.1, 3.5, 0.25),
    (2, 3.4, 0.4, 4.5, 0.50),
    (3, 5.4, 0.8, 5.5, 0.75),
    (4, 7.9, 1.3, 6.5, 0.75),
    (5, 10.7, 2.1, 7.5, 0.75),
    (6, 13.8, 3.1, 8.5, 0.75),
    (7, 17.1, 4.2, 9.0, 0.75),
    (8, 20.7, 5.7, 10.0, 0.75),
    (9, 24.4, 7.4, 10.5, 0.75),
    (10, 28.4, 9.5, 11.5, 0.75),
    (11, 32.6, 12.1, 12.0, 0.75),
)

#: The ledger accounts whose wrench at rest is the environment's static load (besides the
#: mean wave drift): the wind, the current through the linear (and quadratic) damping, and the
#: current through the cross-flow drag.
LOAD_ACCOUNTS = ("wind", "current", "crossflow_current")

#: JONSWAP peak enhancement of the sea states.
GAMMA = 3.3

#: The core's largest wind speed (m/s, `wind.rs`) and current speed (m/s, `current.rs`).
MAX_WIND = 80.0
MAX_CURRENT = 10.0

#: Components of the sea state's mean drift (equal bins in frequency).
DRIFT_COMPONENTS = 200


def _bad(arg: str, msg: str) -> None:
    raise _core.InvalidInputError(f"capability: {arg}: {msg}")


class Environment:
    """The level-1 environment as a function of the wind speed ``U`` (m/s): Hs, Tp and the
    current speed interpolated linearly in ``U`` between the rows of ``table`` (rows of
    Beaufort number, wind speed, Hs, Tp, current speed; default :data:`LEVEL1`)."""

    def __init__(self, table: Sequence[Sequence[float]] = LEVEL1) -> None:
        try:
            t = np.asarray(table, dtype=float)
        except (TypeError, ValueError):
            _bad("environment", f"must be rows of 5 numbers (Beaufort, wind m/s, Hs m, Tp s, current m/s), got {table!r}")
        if t.ndim != 2 or t.shape[1] != 5 or t.shape[0] < 2:
            _bad("environment", f"must be at least 2 rows of 5 finite numbers (Beaufort, wind m/s, Hs m, Tp s, "
                 f"current m/s), got shape {t.shape}")
        if not np.all(np.isfinite(t)):
            i, j = np.argwhere(~np.isfinite(t))[0]
            col = ("Beaufort", "wind speed", "Hs", "Tp", "current speed")[j]
            _bad("environment", f"row {i} has {t[i, j]} as its {col} (column {j}): every entry must be a finite number")
        if np.any(np.diff(t[:, 1]) <= 0) or t[0, 1] != 0.0:
            _bad("environment", "the wind speeds must start at 0 and increase row by row")
        if np.any(t[:, 2:] < 0):
            _bad("environment", "Hs, Tp and the current speed must be >= 0")
        bf = t[:, 0]
        if np.any(bf != np.round(bf)) or np.any(bf < 0) or np.any(np.diff(bf) <= 0):
            _bad("environment", f"the Beaufort numbers (first column) must be whole numbers >= 0 that increase row by "
                 f"row, got {bf.tolist()}")
        if t[-1, 1] > MAX_WIND:
            _bad("environment", f"the wind speeds must be at most {MAX_WIND:g} m/s (the core's limit), got {t[-1, 1]:g}")
        if np.any(t[:, 4] > MAX_CURRENT):
            _bad("environment", f"the current speeds must be at most {MAX_CURRENT:g} m/s (the core's limit), got "
                 f"{t[:, 4].max():g}")
        for r in t:
            if r[2] > 0 and r[3] == 0:
                _bad("environment", f"the row of Beaufort {int(r[0])} has Hs {r[2]:g} m and Tp 0: a Tp of 0 is for "
                     f"a calm row (Hs 0) only")
            if r[2] >= 1e-3:
                from .sea import SeaState

                try:
                    SeaState(hs=float(r[2]), tp=float(r[3]), gamma=GAMMA)
                except _core.InvalidInputError as e:
                    _bad("environment", f"the row of Beaufort {int(r[0])} (Hs {r[2]:g} m, Tp {r[3]:g} s): {e}")
        if t[-1, 3] == 0 and np.any(t[:, 2] > 0):
            _bad("environment", "the last row's Tp must be > 0")
        self.table = t
        self.beaufort = t[:, 0].astype(int)
        self.wind = t[:, 1]

    @property
    def top(self) -> float:
        return float(self.wind[-1])

    def at(self, u: float) -> tuple[float, float, float]:
        """(Hs m, Tp s, current m/s) at wind speed ``u``; a Tp of 0 (calm) takes the next row's."""
        t = self.table
        hs = float(np.interp(u, self.wind, t[:, 2]))
        tp_col = t[:, 3].copy()
        for i in range(len(tp_col) - 2, -1, -1):
            if tp_col[i] <= 0:
                tp_col[i] = tp_col[i + 1]
        tp = float(np.interp(u, self.wind, tp_col))
        vc = float(np.interp(u, self.wind, t[:, 4]))
        return hs, tp, vc


def _towards(heading_deg: float, direction_from: float) -> float:
    """The spatial direction (degrees, x towards y, z up) the environment travels towards, for
    one coming from ``direction_from`` degrees off the bow, clockwise seen from above (0: from
    ahead, 90: from starboard)."""
    return heading_deg + 180.0 - direction_from


class _Loads:
    """The environment's static load (X, Y, N) on the vessel at rest at its heading, from the
    core."""

    def __init__(self, vessel: Vessel) -> None:
        tables = vessel.to_dict()
        self.vessel = vessel
        if "wind" not in tables:
            _bad("vessel", "has no [wind] table (its wind coefficients); give a vessel with [wind] "
                 "(a scenario's [environment.wind], e.g. the shipped dp-capability)")
        if "thrusters" not in tables:
            _bad("vessel", "has no [thrusters] table: the capability is that of its thrusters "
                 "(e.g. the shipped scenario dp-capability)")
        lost = [i for i, u in enumerate(tables["thrusters"].get("unit", [])) if "lost_at" in u]
        if lost:
            _bad("vessel", f"thrusters.unit[{lost[0]}].lost_at is set: the capability takes its failure cases from "
                 "`failures` (each thruster lost in turn by default); remove lost_at")
        self.heading = float(tables["initial"]["euler"][2])
        base = copy.deepcopy(tables)
        for k in ("waves", "thrusters", "current"):
            base.pop(k, None)
        w = base["wind"]
        for k in ("gust_frequencies", "gust_amplitudes", "gust_phases"):
            w.pop(k, None)
        self._base = base
        self._state = None
        self._wind: dict[float, np.ndarray] = {}
        self._current: dict[tuple[float, float], np.ndarray] = {}
        self._sea: dict[tuple[float, float], tuple] = {}
        self._total: dict[tuple[float, float], np.ndarray] = {}
        waves = tables.get("waves", {})
        self.has_drift = "drift_coefficients" in waves
        if self.has_drift:
            f = np.asarray(waves["rao_frequencies"], dtype=float)
            self.drift_range = (float(f[0]), float(f[-1]))
        self.accounts_used: set[str] = set()

    def _sum(self, tables: dict) -> np.ndarray:
        v = _core.Vessel.from_dict(tables)
        if self._state is None:
            self._state = np.asarray(v.initial_state(velocity=[0.0, 0.0, 0.0], angular_velocity=[0.0, 0.0, 0.0]))
        out = np.zeros(3)
        for name, f, m in _core.account_wrenches(v, self._state, 0.0):
            if name in LOAD_ACCOUNTS:
                out += (f[0], f[1], m[2])
                if any(abs(x) > 0 for x in (f[0], f[1], m[2])):
                    self.accounts_used.add(name)
        return out

    def wind_unit(self, towards: float) -> np.ndarray:
        """The core's wind load at 1 m/s towards ``towards`` (degrees); at rest it scales with
        the square of the speed (``q = ½ ρ U²``, ``forces/wind.rs``)."""
        key = round(towards % 360.0, 9)
        if key not in self._wind:
            t = copy.deepcopy(self._base)
            t["wind"].update(speed=1.0, direction=towards)
            self._wind[key] = self._sum(t)
        return self._wind[key]

    def wind(self, u: float, towards: float) -> np.ndarray:
        return u * u * self.wind_unit(towards)

    def wind_direct(self, u: float, towards: float) -> np.ndarray:
        """The core's wind load at speed ``u`` itself (a check of the scaling)."""
        t = copy.deepcopy(self._base)
        t["wind"].update(speed=float(u), direction=towards)
        return self._sum(t)

    def current(self, vc: float, towards: float) -> np.ndarray:
        """The core's current load (damping and cross-flow drag on the relative velocity) at
        speed ``vc`` towards ``towards``."""
        key = (round(vc, 12), round(towards % 360.0, 9))
        if key not in self._current:
            if vc == 0.0:
                self._current[key] = np.zeros(3)
            else:
                t = copy.deepcopy(self._base)
                t["wind"]["speed"] = 0.0
                a = math.radians(towards)
                t["current"] = {"velocity": [vc * math.cos(a), vc * math.sin(a), 0.0]}
                self._current[key] = self._sum(t)
        return self._current[key]

    def sea(self, hs: float, tp: float) -> tuple[np.ndarray, np.ndarray, float]:
        """Components (ω, a) of the JONSWAP sea state on the drift table's frequencies (equal
        bins, at their centres), and the fraction of the spectrum's variance they hold. The
        spectrum is wavespectra's JONSWAP (as phsplit.sea's), scaled to ``4 √m0 = Hs`` over
        phsplit.sea's default range ``[0.5, 3] ω_p``: the part outside the drift data is left
        out, not folded into the rest."""
        key = (hs, tp)
        if key in self._sea:
            return self._sea[key]
        from wavespectra.construct.frequency import jonswap

        from .sea import SeaState

        s = SeaState(hs=hs, tp=tp, gamma=GAMMA)
        lo_s, hi_s = s.range()
        lo, hi = max(lo_s, self.drift_range[0]), min(hi_s, self.drift_range[1])
        if not hi > lo:
            out = (np.zeros(0), np.zeros(0), 0.0)
        else:
            n = DRIFT_COMPONENTS
            dw = (hi - lo) / n
            om = lo + (np.arange(n) + 0.5) * dw
            grid = np.linspace(lo_s, hi_s, 4001) / (2 * np.pi)  # Hz, as SeaState.density
            both = np.asarray(jonswap(np.concatenate([grid, om / (2 * np.pi)]), fp=1.0 / tp, gamma=GAMMA))
            m0 = np.trapezoid(both[:grid.size], grid)
            dens = both[grid.size:] * (hs / 4.0) ** 2 / m0 / (2 * np.pi)
            amp = np.sqrt(2.0 * dens * dw)
            out = (om, amp, float(np.sum(dens) * dw / (hs / 4.0) ** 2))
        if len(self._sea) > 4096:
            self._sea.clear()
        self._sea[key] = out
        return out

    def drift(self, hs: float, tp: float, towards: float) -> tuple[np.ndarray, float]:
        """The mean of the core's wave drift in the sea state (Hs, Tp) travelling towards
        ``towards``; zero without drift data or for a sea state below 1 mm."""
        if not self.has_drift or hs < 1e-3:
            return np.zeros(3), 1.0 if hs < 1e-3 else 0.0
        om, amp, covered = self.sea(hs, tp)
        if len(om) == 0:
            return np.zeros(3), 0.0
        d = _core.mean_wave_drift(self.vessel._inner, self.heading, om.tolist(), amp.tolist(),
                                  [towards] * len(om))
        return np.asarray(d), covered

    def total(self, env: Environment, u: float, towards: float) -> np.ndarray:
        """The whole static load (X, Y, N) at wind speed ``u`` towards ``towards``."""
        key = (u, towards)
        if key not in self._total:
            hs, tp, vc = env.at(u)
            if len(self._total) > 65536:
                self._total.clear()
            self._total[key] = self.wind(u, towards) + self.current(vc, towards) + self.drift(hs, tp, towards)[0]
        return self._total[key]


def _cases(failures: Any, n: int) -> list[tuple[str, list[int]]]:
    if failures is None:
        _bad("failures", "must be 'single' (each thruster lost in turn), 'none', or a list of lists of thruster "
             "indices, got None")
    if isinstance(failures, str) and failures == "none":
        return [("intact", [])]
    if isinstance(failures, str):
        if failures != "single":
            _bad("failures", f"must be 'single' (each thruster lost in turn), 'none', or a list of lists of "
                 f"thruster indices, got {failures!r}")
        return [("intact", [])] + [(f"thruster {i} lost", [i]) for i in range(n)]
    try:
        groups = [list(g) if not isinstance(g, (str, bytes)) else None for g in failures]
        if any(g is None for g in groups):
            raise TypeError
    except TypeError:
        _bad("failures", f"must be 'single', 'none', or a list of lists of thruster indices, got {failures!r}")
    out = [("intact", [])]
    for g in groups:
        if not g or not all(isinstance(i, (int, np.integer)) and not isinstance(i, bool) for i in g):
            _bad("failures", f"each failure is a non-empty list of thruster indices (integers), got {g!r}")
        bad = [int(i) for i in g if not 0 <= int(i) < n]
        if bad:
            _bad("failures", f"thruster index {bad[0]} does not exist (the vessel has {n} thrusters, 0..{n - 1})")
        if len({int(i) for i in g}) != len(g):
            _bad("failures", f"{g!r} names a thruster twice in one failure case; each thruster once")
        g = sorted({int(i) for i in g})
        if any(c[1] == g for c in out):
            _bad("failures", f"names the failure of thruster(s) {g} twice; each failure case once")
        out.append(("thrusters " + ", ".join(map(str, g)) + " lost" if len(g) > 1 else f"thruster {g[0]} lost", g))
    return out


def _directions(directions: Any) -> np.ndarray:
    if directions is None:
        return np.arange(0.0, 360.0, 10.0)
    items = np.atleast_1d(np.asarray(directions, dtype=object)).ravel() if not isinstance(directions, Mapping) else []
    if isinstance(directions, Mapping) or any(isinstance(x, (str, bytes, bool, np.bool_)) for x in items):
        _bad("directions", f"must be numbers (degrees), got {directions!r}")
    try:
        d = np.asarray(directions, dtype=float)
    except (TypeError, ValueError):
        _bad("directions", f"must be numbers (degrees), got {directions!r}")
    d = np.atleast_1d(d)
    if d.ndim != 1 or d.size == 0 or not np.all(np.isfinite(d)):
        _bad("directions", f"must be a non-empty list of finite numbers (degrees), got {directions!r}")
    if np.any((d < 0) | (d >= 360)):
        _bad("directions", f"must lie in [0, 360) degrees (where the environment comes from, off the bow, clockwise), "
             f"got {float(d[(d < 0) | (d >= 360)][0]):g}")
    if len(np.unique(d)) != len(d):
        _bad("directions", "must not repeat a direction")
    return d


def _vessel_of(vessel: Any) -> Vessel:
    """A :class:`Vessel` from a vessel, a :class:`~phsplit.scenario.Scenario`, or a scenario file
    or shipped scenario name."""
    from .scenario import Scenario, load

    if isinstance(vessel, str) or hasattr(vessel, "__fspath__"):
        vessel = load(vessel).vessel
    elif isinstance(vessel, Scenario):
        vessel = vessel.vessel
    if not isinstance(vessel, Vessel):
        _bad("vessel", f"must be a phsplit.Vessel, a Scenario, or a scenario file or name, got {type(vessel).__name__}")
    return vessel


@checked
def held(vessel: Vessel, demand: Sequence[float], lost: Sequence[int] = ()) -> dict:
    """The core's allocation of a demand (X, Y, N) on the vessel's thrusters without ``lost``:
    ``scale`` (1 when held), ``utilisation``, ``thrust``, ``angle``."""
    if not isinstance(vessel, Vessel):
        _bad("vessel", f"must be a phsplit.Vessel, got {type(vessel).__name__}")
    try:
        dem = [float(x) for x in demand if not isinstance(x, (bool, str, bytes))]
        ok = len(dem) == len(list(demand)) == 3 and all(math.isfinite(x) for x in dem)
    except (TypeError, ValueError):
        ok = False
    if isinstance(demand, (str, bytes)) or not ok:
        _bad("demand", f"must be 3 finite numbers (X N, Y N, N N m), got {demand!r}")
    if isinstance(lost, (str, bytes)) or not all(isinstance(i, (int, np.integer)) and not isinstance(i, bool)
                                                  for i in lost):
        _bad("lost", f"must be a list of thruster indices (whole numbers), got {lost!r}")
    return _core.allocate(vessel._inner, dem, [int(i) for i in lost])


def _feasible(vessel: Vessel, load: np.ndarray, lost: list[int]) -> bool:
    return held(vessel, -load, lost)["scale"] >= 1.0 - 1e-12


@checked
def capability(vessel: Any, directions: Any = None, failures: Any = "single",
               environment: Sequence[Sequence[float]] = LEVEL1, tolerance: float = 0.01):
    """The static DP capability of ``vessel`` (a :class:`phsplit.Vessel` with ``[wind]`` and
    ``[thrusters]``, a :class:`phsplit.scenario.Scenario`, or a scenario file or shipped scenario
    name) in the level-1 environment of DNV-ST-0111 (2021).

    ``directions``: degrees the environment comes from, off the bow, clockwise seen from above
    (0 from ahead, 90 from starboard; default every 10°). ``failures``: ``"single"`` (intact and
    each thruster lost in turn; the default), ``"none"`` (intact only), or a list of lists of
    thruster indices. ``environment``: rows of (Beaufort, wind m/s, Hs m, Tp s, current m/s)
    (default :data:`LEVEL1`). ``tolerance``: of the bisection in wind speed, m/s.

    Returns an xarray Dataset over (direction, case): ``wind_speed_limit`` (m/s, the largest wind
    speed held, with its sea state and current), ``beaufort_limit`` (the largest Beaufort number
    whose row, and every row below it, is held), ``at_table_top`` (held at the table's last
    row: the limit is at least that), ``hs_limit``, ``tp_limit``, ``current_limit``, and
    ``utilisation_at_limit``; ``worst_failure_wind_speed`` (direction) over the failure cases.
    """
    import xarray as xr

    from . import cf

    vessel = _vessel_of(vessel)
    if isinstance(tolerance, (np.integer, np.floating)) and not isinstance(tolerance, np.bool_):
        tolerance = float(tolerance)
    if not (isinstance(tolerance, (int, float)) and not isinstance(tolerance, bool)
            and math.isfinite(tolerance) and 1e-9 <= tolerance <= 1.0):
        _bad("tolerance", f"must be a number in [1e-9, 1] (m/s), got {tolerance!r}")
    dirs = _directions(directions)
    env = Environment(environment)
    loads = _Loads(vessel)
    units = _core.thruster_units(vessel._inner)
    cases = _cases(failures, len(units))
    heading_deg = math.degrees(loads.heading)

    shape = (len(dirs), len(cases))
    u_lim = np.zeros(shape)
    bf_lim = np.zeros(shape, dtype=np.int32)
    top = np.zeros(shape, dtype=bool)
    util = np.full(shape, np.nan)
    rank_ok = np.ones(len(cases), dtype=bool)
    covered = np.ones(shape)
    for j, (_, lost) in enumerate(cases):
        try:
            held(vessel, [0.0, 0.0, 0.0], lost)
        except _core.InvalidInputError:
            rank_ok[j] = False  # the rest cannot produce surge, sway and yaw: nothing is held
    for i, d in enumerate(dirs):
        towards = _towards(heading_deg, float(d))
        for j, (_, lost) in enumerate(cases):
            if not rank_ok[j]:
                continue
            ok = lambda u: _feasible(vessel, loads.total(env, u, towards), lost)  # noqa: E731
            # the Beaufort number: every row up to it held
            n = 0
            for k in range(1, len(env.wind)):
                if not ok(float(env.wind[k])):
                    break
                n = k
            bf_lim[i, j] = env.beaufort[n]
            if n == len(env.wind) - 1:
                u_lim[i, j], top[i, j] = env.top, True
            else:
                lo, hi = float(env.wind[n]), float(env.wind[n + 1])
                while hi - lo > tolerance:
                    mid = 0.5 * (lo + hi)
                    if ok(mid):
                        lo = mid
                    else:
                        hi = mid
                u_lim[i, j] = lo
            hs, tp, _ = env.at(u_lim[i, j])
            util[i, j] = held(vessel, -loads.total(env, u_lim[i, j], towards), lost)["utilisation"]
            covered[i, j] = loads.drift(hs, tp, towards)[1]
    hs_l, tp_l, vc_l = (np.vectorize(lambda u, k=k: env.at(u)[k])(u_lim) for k in range(3))
    names = [c[0] for c in cases]
    ds = xr.Dataset(
        {
            "wind_speed_limit": (("direction", "case"), u_lim, {
                "units": "m s-1", "standard_name": "wind_speed",
                "long_name": "largest wind speed held (10 m, level-1 environment)"}),
            "beaufort_limit": (("direction", "case"), bf_lim, {
                "units": "1", "long_name": "DP capability number: largest Beaufort number held, with every one below it"}),
            "at_table_top": (("direction", "case"), top, {
                "long_name": "held at the environment table's last row (the limit is at least that)"}),
            "hs_limit": (("direction", "case"), hs_l, {
                "units": "m", "standard_name": "sea_surface_wave_significant_height",
                "long_name": "significant wave height at the limit"}),
            "tp_limit": (("direction", "case"), tp_l, {
                "units": "s", "long_name": "peak period at the limit"}),
            "current_limit": (("direction", "case"), vc_l, {
                "units": "m s-1", "long_name": "current speed at the limit"}),
            "utilisation_at_limit": (("direction", "case"), util, {
                "units": "1", "long_name": "largest thrust over its limit at the limit (core allocation)"}),
            "drift_variance_covered": (("direction", "case"), covered, {
                "units": "1", "long_name": "fraction of the sea state's variance inside the drift data's frequencies"}),
            "case_rank_ok": (("case",), rank_ok, {
                "long_name": "the remaining thrusters can produce surge, sway and yaw (else nothing is held)"}),
        },
        coords={
            "direction": ("direction", dirs, {
                "units": "degree",
                "long_name": "direction the wind, waves and current come from, off the bow, clockwise seen from above"}),
            "case": ("case", names),
        },
    )
    failed = [j for j, c in enumerate(cases) if c[1]]
    if failed:
        worst = u_lim[:, failed].min(axis=1)
        ds["worst_failure_wind_speed"] = (("direction",), worst, {
            "units": "m s-1", "standard_name": "wind_speed",
            "long_name": "largest wind speed held with the worst of the failure cases"})
        ds["worst_failure_beaufort"] = (("direction",), bf_lim[:, failed].min(axis=1).astype(np.int32), {
            "units": "1", "long_name": "DP capability number with the worst of the failure cases"})
    ds.attrs.update({
        "method": "static balance of the mean environmental load and the thrusters' allocation (DNV-ST-0111 "
                  "(2021) level 1 style): bisection in wind speed on the core's allocation needing no scaling",
        "environment_table": "; ".join(f"BF{int(r[0])}: {r[1]:g} m/s, Hs {r[2]:g} m, Tp {r[3]:g} s, current "
                                       f"{r[4]:g} m/s" for r in env.table),
        "loads": "wind (the vessel's [wind] coefficients), current (damping and cross-flow drag on the relative "
                 "velocity), mean wave drift: the core's, on the vessel at rest at its heading"
                 + ("" if loads.has_drift else "; the mean wave drift is LEFT OUT: the vessel has no drift coefficients"),
        "wave_drift_included": int(loads.has_drift),
        "load_accounts": ", ".join(sorted(loads.accounts_used)) or "none",
        "heading_deg": heading_deg,
        "thrusters": "; ".join(f"{k}: {kind} at ({x:g}, {y:g}) m, {mx:g} N" for k, (kind, x, y, _z, mx, _mn) in enumerate(units)),
        "wave_spectrum": f"JONSWAP, gamma {GAMMA}, long-crested, co-linear with the wind",
        "tolerance_m_s": float(tolerance),
        "vessel_source": vessel.source,
        "not_modelled": "thrust losses, thruster interaction, forbidden zones, dynamic allowance, power limits",
    })
    return cf.finish(ds, "phsplit DP capability (static, level 1)", "phsplit.capability")


@checked
def hold(vessel: Any, direction: float, wind_speed: float, lost: Sequence[int] = (),
         environment: Sequence[Sequence[float]] = LEVEL1, t_end: float = 1200.0, h: float = 0.5,
         method: str = "sp2"):
    """A time-domain check of one point of a capability plot: the vessel under its controller
    and thrusters, ``lost`` thrusters lost from the start, in the mean environment of wind speed
    ``wind_speed`` (m/s; its current and sea state from ``environment``, as :func:`capability`)
    coming from ``direction`` (degrees off the bow, clockwise). The loads are those of the static
    balance, acting on the moving vessel: the steady wind and the current through the core's
    components, and the mean wave drift of the sea state as a constant body-frame load
    (``[external]``; the first-order waves and the slowly varying drift are left out, as in the
    static balance). The run starts on the set point at rest, with the controller's integral
    states already balancing the load (the vessel has been holding station in this weather);
    the thrusters then deliver what they can. Returns ``(solution, excursion)``: the
    :class:`Solution` and the horizontal distance from the set point at each saved time (m).

    Where the thrusters can balance the load (at or below the static limit) the vessel stays on
    its set point; beyond it they saturate and the vessel is pushed off (test_osv_capability.py).
    """
    from .simulate import simulate

    vessel = _vessel_of(vessel)
    d = float(_directions([direction])[0])
    if not (isinstance(wind_speed, (int, float, np.integer, np.floating)) and not isinstance(wind_speed, (bool, np.bool_))
            and 0.0 <= float(wind_speed) <= MAX_WIND):
        _bad("wind_speed", f"must be a number in [0, {MAX_WIND:g}] m/s, got {wind_speed!r}")
    if not (isinstance(t_end, (int, float)) and not isinstance(t_end, bool) and math.isfinite(t_end)
            and 0.0 < t_end <= 86400.0):
        _bad("t_end", f"must be a number in (0, 86400] s, got {t_end!r}")
    env = Environment(environment)
    loads = _Loads(vessel)
    tables = vessel.to_dict()
    if "control" not in tables:
        _bad("vessel", "has no [control] table: the time-domain check needs the controller that holds the set point")
    if "external" in tables:
        _bad("vessel", "has an [external] load; the check books the mean wave drift there: remove it")
    if tables["control"].get("feedback", "true_state") != "true_state":
        _bad("vessel", "acts on observer estimates; the check starts the controller's integral states balanced, "
             "which needs control.feedback = \"true_state\"")
    if isinstance(lost, (str, bytes, Mapping)) or not isinstance(lost, (Sequence, np.ndarray)):
        _bad("lost", f"must be a list of thruster indices, got {lost!r}")
    n_units = len(_core.thruster_units(vessel._inner))
    if not all(isinstance(i, (int, np.integer)) and not isinstance(i, (bool, np.bool_)) and 0 <= int(i) < n_units
               for i in lost) or len(set(int(i) for i in lost)) != len(lost):
        _bad("lost", f"must be distinct thruster indices 0..{n_units - 1} (the vessel has {n_units}), got {list(lost)!r}")
    lost_ = sorted(int(i) for i in lost)
    u = float(wind_speed)
    hs, tp, vc = env.at(u)
    towards = _towards(math.degrees(loads.heading), d)
    load_ = loads.total(env, u, towards)
    drift = loads.drift(hs, tp, towards)[0]
    t = copy.deepcopy(tables)
    t.pop("waves", None)
    for k in ("gust_frequencies", "gust_amplitudes", "gust_phases"):
        t["wind"].pop(k, None)
    a = math.radians(towards)
    t["wind"].update(speed=u, direction=towards)
    t["current"] = {"velocity": [vc * math.cos(a), vc * math.sin(a), 0.0]}
    t["external"] = {"force": [float(drift[0]), float(drift[1]), 0.0], "moment": [0.0, 0.0, float(drift[2])]}
    for i in lost_:
        t["thrusters"]["unit"][i]["lost_at"] = 0.0
    run_vessel = Vessel.from_dict(t, vessel.source)
    y0 = np.array(run_vessel._inner.initial_state(velocity=[0.0] * 3, angular_velocity=[0.0] * 3), dtype=float)
    # The integral states holding the load (docs/explanation/vessel.md §2.6; forces/pid.rs): at rest on
    # the set point the controller's force is -Q^T Ki phi_x and its yaw moment -Ki psi phi_th.
    c = t["control"]
    ki_t, ki_r = np.asarray(c["ki_translational"], float), np.asarray(c["ki_rotational"], float)
    if ki_t[0] <= 0 or ki_t[1] <= 0 or ki_r[2] <= 0:
        _bad("vessel", "needs integral gains in surge, sway and yaw (control.ki_translational, ki_rotational) "
             "for a controller that holds a mean load on the set point")
    ref = np.asarray(c["position_reference"][:2], float)
    y0[18:20] = ref
    q = y0[6:15].reshape(3, 3, order="F")
    phi = q @ np.array([load_[0], load_[1], 0.0])
    y0[24:26] = phi[:2] / ki_t[:2]
    y0[23] = load_[2] / ki_r[2]
    sol = simulate(run_vessel, (0.0, float(t_end)), h, method, control_start=0.0, initial=y0)
    return sol, np.hypot(*(sol.x[:, :2] - ref).T)


def _check_capability_result(ds: Any) -> None:
    """What :func:`polar_plot` reads of a :func:`capability` result, checked first."""
    import xarray as xr

    if not isinstance(ds, xr.Dataset):
        _bad("polar_plot: ds", f"must be the xarray.Dataset that phsplit.capability returns, got {type(ds).__name__}")
    need = {"wind_speed_limit": ("direction", "case"), "at_table_top": ("direction", "case")}
    for name, dims in need.items():
        if name not in ds or ds[name].dims != dims or "direction" not in ds.coords:
            _bad("polar_plot: ds", f"is not a capability result (phsplit.capability): it needs {name} along "
                 f"{dims} and the coordinate direction")
    if ds.sizes["direction"] < 1 or ds.sizes["case"] < 1:
        _bad("polar_plot: ds", "is a capability result with no direction or no case")


@checked
def polar_plot(ds, path: str, title: str | None = None) -> None:
    """Draw a capability dataset's wind speed limits as a polar plot (0 from ahead, clockwise)."""
    _check_capability_result(ds)
    if not isinstance(path, (str, os.PathLike)) or not str(path):
        _bad("polar_plot: path", f"must be a file's path (e.g. capability.png), got {path!r}")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder) or os.path.isdir(path):
        _bad("polar_plot: path", f"{str(path)!r} is not a file in an existing folder")
    from matplotlib.figure import Figure

    kinds = Figure().canvas.get_supported_filetypes()
    ext = os.path.splitext(str(path))[1].lower().lstrip(".")
    if ext not in kinds:
        _bad("polar_plot: path", f"{str(path)!r} names no image format matplotlib writes: end it in "
             f"{', '.join('.' + k for k in sorted(kinds))}")
    if title is not None and not isinstance(title, str):
        _bad("polar_plot: title", f"must be a string or None, got {type(title).__name__}")
    import matplotlib

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    th = np.radians(np.append(ds["direction"].values, ds["direction"].values[0]))
    fig = plt.figure(figsize=(6.5, 6.5))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    labels = ds["case_name"].values if "case_name" in ds.coords else ds["case"].values
    for j, name in enumerate(labels):
        u = ds["wind_speed_limit"].values[:, j]
        ax.plot(th, np.append(u, u[0]), lw=2.0 if j == 0 else 1.0, ls="-" if j == 0 else "--", label=str(name))
    top = ds["wind_speed_limit"].values[ds["at_table_top"].values.astype(bool)]
    if top.size:
        ring = np.linspace(0.0, 2 * np.pi, 361)
        ax.plot(ring, np.full(ring.size, top.max()), color="0.5", lw=0.8, ls=":", label="top of the table")
    ax.set_rlim(0.0, 1.05 * float(np.nanmax(ds["wind_speed_limit"].values)) or 1.0)
    ax.set_rlabel_position(135)
    ax.set_title(title or "DP capability: wind speed held (m/s)", pad=20)
    ax.legend(loc="lower left", bbox_to_anchor=(-0.12, -0.16), fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
