"""Scenario files (TOML): what to simulate, validated with messages that name the problem.

A scenario has a ``[simulation]`` table (every key optional; the defaults are the paper's
Fig. 2 run with flow S2 by Gauss collocation, shared with :func:`phsplit.simulate`; the
paper's exact S2 is ``linear_flow = "exact"``) and optionally a vessel: a path
(``vessel = "my_vessel.toml"``, relative to the scenario file), a shipped vessel by name
(``vessel = "osv"``; ``phsplit vessels``), or the paper's when absent.
Any table of a vessel file given in the scenario (``[vessel]``, ``[control]``, ``[initial]``,
``[external]``, …) overrides that vessel key by key, so one gain or one load can be changed
without copying the vessel file. To change keys of the ``[vessel]`` table itself, name the base
vessel inside it (TOML has no key that is both a string and a table)::

    [vessel]
    from = "osv"        # a shipped vessel or a vessel file
    mass = 6.5e6        # kg: this key replaced, the others the preset's

Directions (degrees, spatial frame, from x towards y) of the waves, the wind and the current:
``direction`` or ``direction_towards`` where they go, ``direction_from`` where they come from.
The current may be given by ``speed`` (m/s) and a direction instead of ``velocity``. The
angles a vessel file takes in radians (``[initial] euler``, ``[control] euler_reference``,
``[setpoint] headings``) may be given in degrees as ``euler_deg``, ``euler_reference_deg``,
``headings_deg``. Every key either acts or is refused: the core reads the
settings and the vessel, and names a key nobody reads, with the nearest valid one.

.. code-block:: toml

    [simulation]
    t_span = [0.0, 200.0]   # s
    h = 0.5                 # s
    method = "sp4"          # lie, sp2, sp4, sp6, euler, heun, rk4
    control_start = 50.0    # s, or "never"
    outer = "dissipative"   # or "conservative"
    save_every = 1
    linear_flow = "auto"    # the default, or "exact" (the paper's), "gauss", "gauss4", "gauss6"

    [external]              # a constant load at a point of the hull
    force = [2.0e5, 0.0, 0.0]   # N
    point = [-40.0, 0.0, 5.0]   # m, body frame
    frame = "spatial"           # or "body"

    [environment.current]   # the [current] component
    velocity = [0.4, 0.0, 0.0]  # m/s, spatial

    [environment.waves]     # a sea state (phsplit.sea), realised with its seed
    hs = 2.5                    # m
    tp = 9.0                    # s
    gamma = 3.3
    direction = 180.0           # degrees, the direction the waves travel towards
    seed = 7
    hydro = "barge.nc"          # a Capytaine dataset: the force transfer functions
"""
from __future__ import annotations

import copy
import dataclasses
import difflib
import math
import os
import re
import tomllib
from dataclasses import dataclass, field
from typing import Any, Mapping

from . import _core
from . import hydro, sea
from .settings import Settings
from .vessel import PRESET_ALIASES, Vessel, presets
from ._arguments import checked


@dataclass
class Scenario:
    """A vessel, the settings of a run, and a name for its output."""

    vessel: Vessel
    settings: Settings = field(default_factory=Settings)
    name: str = "fig2"
    path: str | None = None
    #: The scenario's ``[environment]`` table as written (before the sea and wind are realised).
    environment: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def paper_fig2(cls) -> "Scenario":
        """The paper's Fig. 2: t in [0, 200], controller on at t = 50, SP4 with h = 0.5, and the
        paper's exact flow S2 (the library's default is Gauss collocation, README)."""
        return cls(vessel=Vessel.paper(), settings=Settings(linear_flow="exact"))

    # The settings, for reading and overriding (the CLI's options).
    def __getattr__(self, key: str) -> Any:
        if key in Settings.__dataclass_fields__:
            return getattr(self.settings, key)
        raise AttributeError(key)

    def replace(self, **kw: Any) -> "Scenario":
        from dataclasses import replace

        return Scenario(self.vessel, replace(self.settings, **kw), self.name, self.path, self.environment)


def overlay(base: Mapping[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    """``base`` with the tables of ``over`` merged in key by key (a new dict)."""
    out = copy.deepcopy(dict(base))
    for k, v in over.items():
        if isinstance(v, Mapping) and isinstance(out.get(k), Mapping):
            out[k] = {**out[k], **v}
        else:
            out[k] = copy.deepcopy(v)
    return out


def _read_toml(p: str, what: str) -> dict[str, Any]:
    try:
        with open(p, "rb") as f:
            raw = f.read()
    except FileNotFoundError:
        raise _core.InvalidInputError(f"{what} {p!r} does not exist") from None
    except OSError as e:
        raise _core.InvalidInputError(f"cannot read {what} {p!r}: {e.strerror}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise _core.ScenarioParseError(f"{p}: not a text file (TOML must be UTF-8)") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        hint = ""
        if re.search(r"^\s*vessel\s*=", text, re.M) and re.search(r"^\s*\[vessel\]", text, re.M):
            hint = ("; to change keys of a shipped vessel or a vessel file, name it in the table instead: "
                    "[vessel] from = \"osv\", then the keys to change")
        twice = _given_twice(str(e), text)
        if twice:
            raise _core.ScenarioParseError(f"{p}: {twice}{hint}") from None
        raise _core.ScenarioParseError(f"{p}: TOML syntax error: {e}{hint}") from None


def _given_twice(error: str, text: str) -> str | None:
    """What tomllib's "Cannot overwrite a value" or "Cannot declare" means, with the key and its
    table named: a key (or a table) given twice."""
    m = re.search(r"^Cannot (?:overwrite a value|declare .*?)\s*\(at line (\d+), column \d+\)", error)
    if not m:
        return None
    lines = text.splitlines()
    n = int(m.group(1))
    if not 1 <= n <= len(lines):
        return None
    line = lines[n - 1].strip()
    table = next((h.strip() for h in reversed(lines[:n - 1]) if re.match(r"^\s*\[", h)), None)
    key = re.match(r"^([A-Za-z0-9_.\"'-]+)\s*=", line)
    if key:
        where = f" of {table}" if table else ""
        return f"the key {key.group(1)}{where} is given twice (again at line {n}): give each key once"
    head = re.match(r"^(\[\[?[^\]]+\]\]?)", line)
    if head:
        return f"the table {head.group(1)} is given twice (again at line {n}), or a key already set it: give it once"
    return None


def from_dict(data: Mapping[str, Any], path: str, allowed_extra: tuple[str, ...] = (),
              vessel: str | None = None) -> Scenario:
    """A scenario from its parsed tables; ``path`` names the file in messages and resolves a
    relative vessel path. ``vessel`` (a shipped vessel's name or a vessel file, relative to the
    working folder) replaces the scenario's own vessel as the base its tables apply to: the
    scenario's environment, operation (set point, pipe, thrusters) and overrides stay."""
    tables = set(_core.vessel_tables())
    top = {"simulation", "vessel", "environment"} | tables | set(allowed_extra)
    for k in data:
        if k not in top:
            near = difflib.get_close_matches(k, sorted(top), n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise _core.ScenarioParseError(f"{path}: unknown table {k!r} in the scenario{hint} "
                                           f"(allowed: {', '.join(sorted(top))})")
    sim = data.get("simulation", {})
    if not isinstance(sim, Mapping):
        raise _core.ScenarioParseError(f"{path}: [simulation] must be a table")
    try:
        checked = _core.check_settings(dict(sim), api=False)
    except (_core.ScenarioParseError, _core.InvalidInputError) as e:
        raise type(e)(f"{path}: {e}") from None
    settings = Settings(**{k: (tuple(checked[k]) if k == "t_span" else checked[k])
                           for k in Settings.__dataclass_fields__})
    v = data.get("vessel")
    base_dir = os.path.dirname(os.path.abspath(path))
    named = None
    body: dict[str, Any] = {}
    if isinstance(v, str):
        named = v
    elif isinstance(v, Mapping):
        body = dict(v)
        if "from" in body:
            named = body.pop("from")
            if not isinstance(named, str):
                raise _core.ScenarioParseError(f"{path}: vessel.from must be a shipped vessel's name (phsplit vessels) "
                                               f"or a vessel file's path, got {named!r}")
    elif v is not None:
        raise _core.ScenarioParseError(f"{path}: 'vessel' must be a file path or a table, got {v!r}")
    if vessel is not None:  # the command line's --vessel: the base the scenario's tables apply to
        base, source = vessel_named(vessel), vessel
    elif named is not None:
        base, source = vessel_named(named, base_dir), named
    else:
        base, source = Vessel.paper(), "paper"
    over = {k: val for k, val in data.items() if k in tables and k != "vessel"}
    if body:
        over["vessel"] = body
    if isinstance(over.get("current"), Mapping):
        over["current"] = current_table(dict(over["current"]), f"{path}: current")
    for table, key in DEGREE_KEYS:
        if isinstance(over.get(table), Mapping):
            over[table] = in_radians(dict(over[table]), table, key, path)
    if "environment" in data:
        waves = data["environment"].get("waves") if isinstance(data["environment"], Mapping) else None
        if (isinstance(waves, Mapping) and waves.get("fluid_memory") is True
                and ("port_hamiltonian" in over or "port_hamiltonian" in base.to_dict())):
            # refused before the memory is fitted (tens of seconds)
            raise _core.InvalidInputError(f"{path}: environment.waves.fluid_memory: the vessel already has a "
                                          f"port-Hamiltonian subsystem, and a vessel holds one")
        hull = overlay(base.to_dict(), {"vessel": over["vessel"]} if "vessel" in over else {})
        env_tables = _environment(data["environment"], path, base_dir, hull)
        if "port_hamiltonian" in env_tables and "added_mass" in (over.get("vessel") or {}):
            raise _core.InvalidInputError(f"{path}: environment.waves.fluid_memory sets the vessel's added mass to the "
                                          f"dataset's infinite-frequency added mass, and [vessel] gives added_mass "
                                          f"too: remove one of them")
        over = overlay(over, env_tables)
    if over:
        try:
            vessel = Vessel.from_dict(overlay(base.to_dict(), over), f"{source} with the tables of {path}")
        except (_core.ScenarioParseError, _core.InvalidInputError) as e:
            raise type(e)(f"{path}: {e}") from None
    else:
        vessel = base
    name = checked.get("name") or _name_of_file(path)
    env = data.get("environment")
    return Scenario(vessel=vessel, settings=settings, name=name, path=path,
                    environment=copy.deepcopy(dict(env)) if isinstance(env, Mapping) else {})


def describe_environment(env: Mapping[str, Any]) -> str:
    """One line for the CLI's summary: the current, the sea state and the wind of a scenario."""
    parts = []
    cur = env.get("current")
    if isinstance(cur, Mapping):
        try:
            cur = current_table(dict(cur), "environment.current")
        except _core.InvalidInputError:
            pass
        if "velocity" in cur:
            v = [float(x) for x in cur["velocity"]]
            parts.append(f"current {math.hypot(v[0], v[1]):.2f} m/s towards "
                         f"{math.degrees(math.atan2(v[1], v[0])) % 360:.0f} deg")
        elif "times" in cur:
            parts.append(f"current from a table of {len(cur['times'])} rows")
    w = env.get("waves")
    if isinstance(w, Mapping):
        spread = f", spreading s = {w['spreading']:g}" if "spreading" in w else ", long-crested"
        parts.append(f"waves {w.get('spectrum', 'jonswap')} Hs {w['hs']:g} m Tp {w['tp']:g} s towards "
                     f"{sea.direction_towards(w, 'environment.waves'):g} deg{spread}, {w.get('components', 200)} components, "
                     f"seed {w.get('seed', 0)}" + (f", transfer functions {w['hydro']}" if "hydro" in w else ""))
    wd = env.get("wind")
    if isinstance(wd, Mapping):
        spec = wd.get("spectrum", "npd")
        parts.append(f"wind {wd['speed']:g} m/s towards {sea.direction_towards(wd, 'environment.wind'):g} deg, gusts {spec}"
                     + (f" (seed {wd.get('seed', 0)})" if spec not in (None, "none") else "")
                     + (f", {wd['ship_type']} coefficients" if "ship_type" in wd else ""))
    return "; ".join(parts)


#: The scenarios shipped with phsplit (``python/src/phsplit/scenarios``), by name.
SHIPPED_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenarios")


def shipped() -> list[str]:
    """The names of the scenarios shipped with phsplit (``phsplit simulate NAME``)."""
    return sorted(f[:-5] for f in os.listdir(SHIPPED_DIR) if f.endswith(".toml"))


def resolve(path: str | os.PathLike[str]) -> str:
    """A scenario path: ``path`` itself if it is a file or looks like a path, else the shipped
    scenario of that name."""
    p = os.fspath(path)
    if os.path.exists(p) or os.sep in p or p.endswith(".toml"):
        return p
    if p in shipped():
        return os.path.join(SHIPPED_DIR, p + ".toml")
    return p


def _environment(env: Any, path: str, base_dir: str, vessel: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The vessel tables an ``[environment]`` table stands for: ``[environment.current]`` is the
    ``[current]`` component; ``[environment.wind]`` a wind (``phsplit.sea.Wind``: speed,
    direction, gust spectrum, seed), realised into the ``[wind]`` component, whose windage and
    coefficients come from the vessel file or from the same table; ``[environment.waves]`` is a sea state (``phsplit.sea``), realised
    into the ``[waves]`` component's components, with its transfer functions from a Capytaine
    dataset (``hydro = "file.nc"``, relative to the scenario; ``symmetric = true`` mirrors a
    port–starboard symmetric hull's directions; ``hydro_checks = "warn"`` uses a dataset that fails
    a physics check with a warning instead of refusing it, docs/hydrodynamic-data.md) or from the
    vessel file's own ``[waves]`` keys; ``fluid_memory = true`` adds the dataset's Cummins fluid
    memory (``phsplit.radiation``: the ``[port_hamiltonian]`` table ``radiation`` and ``A∞`` as
    ``vessel.added_mass``; docs/explanation/components/fluid-memory.md). ``vessel``: the tables
    of the vessel the scenario runs, whose centre of gravity places the dataset's loads at its
    body origin and whose hydrostatics the dataset must match (``phsplit.hydro.from_capytaine``)."""
    if not isinstance(env, Mapping):
        raise _core.ScenarioParseError(f"{path}: [environment] must be a table")
    allowed = ("current", "waves", "wind")
    for k, v in env.items():
        if k not in allowed:
            near = difflib.get_close_matches(k, allowed, n=1)
            hint = f"; did you mean {near[0]!r}?" if near else ""
            raise _core.ScenarioParseError(f"{path}: unknown table [environment.{k}]{hint} (allowed: "
                                           f"{', '.join(allowed)})")
        if not isinstance(v, Mapping):
            raise _core.ScenarioParseError(f"{path}: [environment.{k}] must be a table")
    out: dict[str, Any] = {}
    if "current" in env:
        out["current"] = current_table(dict(env["current"]), f"{path}: environment.current")
    if "waves" in env:
        w = dict(env["waves"])
        try:
            state = sea.sea_state(w)
        except (_core.ScenarioParseError, _core.InvalidInputError) as e:
            raise type(e)(f"{path}: {e}") from None
        table: dict[str, Any] = {}
        if "hydro" in w:
            src = w["hydro"]
            if not isinstance(src, str):
                raise _core.ScenarioParseError(f"{path}: environment.waves.hydro must be a file path, got {src!r}")
            p = src if os.path.isabs(src) else os.path.join(base_dir, src)
            if not os.path.exists(p):
                raise _core.InvalidInputError(f"{path}: environment.waves.hydro: the Capytaine dataset {p!r} does not exist")
            sym = w.get("symmetric", False)
            if not isinstance(sym, bool):
                raise _core.ScenarioParseError(f"{path}: environment.waves.symmetric must be true or false, got {sym!r}")
            checks = w.get("hydro_checks", "refuse")
            if checks not in hydro.CHECK_MODES:
                raise _core.ScenarioParseError(f"{path}: environment.waves.hydro_checks must be one of "
                                               f"{', '.join(map(repr, hydro.CHECK_MODES))}, got {checks!r}")
            try:
                table = hydro.from_capytaine(p, symmetric=sym, checks=checks, vessel=vessel)["waves"]
            except _core.InvalidInputError as e:
                raise _core.InvalidInputError(f"{path}: environment.waves.hydro: {e}") from None
            f0, f1 = float(table["rao_frequencies"][0]), float(table["rao_frequencies"][-1])
            lo, hi = state.range()
            if state.omega_range is not None and not (f0 - 1e-9 <= lo and hi <= f1 + 1e-9):
                raise _core.InvalidInputError(
                    f"{path}: environment.waves.omega_range = [{lo:g}, {hi:g}] rad/s reaches outside the dataset's "
                    f"{f0:g}-{f1:g} rad/s (its transfer functions are not extrapolated): give a range inside it, "
                    f"or leave omega_range out for the default within it")
            if state.omega_range is None:   # the default range, [0.5, 3] omega_p, within the dataset's
                if not max(lo, f0) < min(hi, f1):
                    raise _core.InvalidInputError(
                        f"{path}: environment.waves: the spectrum's range [0.5, 3] omega_p = [{lo:.3g}, {hi:.3g}] "
                        f"rad/s lies outside the dataset's {f0:g}-{f1:g} rad/s: give omega_range, or a dataset "
                        f"that covers tp = {state.tp:g} s")
                state = dataclasses.replace(state, omega_range=(max(lo, f0), min(hi, f1)))
            comps = state.realise()
            outside = _outside_directions(table.get("rao_directions", []), comps.get("directions", []))
            if outside is not None:
                raise _core.InvalidInputError(
                    f"{path}: environment.waves: waves travel towards {outside:g} degrees, outside the directions of "
                    f"the hydrodynamic dataset ({_degree_list(table['rao_directions'])}); its transfer functions "
                    "are not extrapolated across the gap: use a dataset with that direction, change "
                    "environment.waves.direction (or its spreading)"
                    + ("" if sym else ", or symmetric = true for a port-starboard symmetric hull"))
        memory = w.get("fluid_memory", False)
        if not isinstance(memory, bool):
            raise _core.ScenarioParseError(f"{path}: environment.waves.fluid_memory must be true or false, got {memory!r}")
        if memory:
            if "hydro" not in w:
                raise _core.ScenarioParseError(f"{path}: environment.waves.fluid_memory needs environment.waves.hydro "
                                               f"(the Capytaine dataset whose added mass and damping it fits)")
            from . import radiation

            try:
                fm = radiation.fluid_memory(p, symmetric=sym, checks=checks, vessel=vessel)
            except _core.InvalidInputError as e:
                raise _core.InvalidInputError(f"{path}: environment.waves.fluid_memory: {e}") from None
            out["port_hamiltonian"] = fm.table
            out["vessel"] = {"added_mass": fm.added_mass_infinite.tolist()}
        if "hydro" not in w:
            given = [k for k in ("symmetric", "hydro_checks") if k in w]
            if given:
                raise _core.ScenarioParseError(f"{path}: environment.waves.{given[0]} applies to a dataset: it needs "
                                               f"environment.waves.hydro")
            if vessel is not None and "rao_frequencies" not in (vessel.get("waves") or {}):
                raise _core.InvalidInputError(f"{path}: environment.waves needs the hull's transfer functions: "
                                              f"environment.waves.hydro (a Capytaine dataset) or the vessel's own "
                                              f"[waves] rao_frequencies, rao_directions, force_rao_real, force_rao_imag")
            comps = state.realise()
        out["waves"] = {**table, **comps}
    if "wind" in env:
        try:
            realised, rest = sea.wind(dict(env["wind"]))
        except (_core.ScenarioParseError, _core.InvalidInputError) as e:
            raise type(e)(f"{path}: {e}") from None
        out["wind"] = {**rest, **realised}
    return out


#: Angles the vessel file takes in radians that a scenario may give in degrees, as ``<key>_deg``.
def _degree_list(dirs) -> str:
    d = sorted(float(x) % 360.0 for x in dirs)
    return ", ".join(f"{x:g}" for x in d[:12]) + (", ..." if len(d) > 12 else "") + " degrees"


def _outside_directions(dataset, waves) -> float | None:
    """A wave direction (degrees) that lies in a gap of the dataset's directions wider than its
    regular spacing (where its transfer functions would be interpolated across a range it does
    not cover), or ``None``. A dataset over the full circle has no such gap; one direction alone
    covers only itself."""
    import numpy as np

    d = np.unique(np.round(np.mod(np.asarray(dataset, float), 360.0), 9))
    w = np.mod(np.asarray(waves, float), 360.0)
    if d.size == 0 or w.size == 0:
        return None
    if d.size == 1:
        off = np.abs(np.remainder(w - d[0] + 180.0, 360.0) - 180.0)
        return float(w[np.argmax(off)]) if off.max() > 1e-6 else None
    gaps = np.diff(np.append(d, d[0] + 360.0))  # gap k from d[k] to the next direction
    spacing = float(np.median(gaps))
    for k in np.flatnonzero(gaps > 1.5 * spacing + 1e-9):
        inside = np.remainder(w - d[k], 360.0)
        hit = (inside > 1e-6) & (inside < gaps[k] - 1e-6)
        if hit.any():
            return float(w[np.argmax(hit)])
    return None


DEGREE_KEYS = (("initial", "euler"), ("control", "euler_reference"), ("setpoint", "headings"))


def in_radians(table: dict[str, Any], name: str, key: str, path: str) -> dict[str, Any]:
    """``table`` with ``<key>_deg`` (degrees: a number or a list of numbers) given as ``key``
    (radians); both at once are refused."""
    deg = f"{key}_deg"
    if deg not in table:
        return table
    if key in table:
        raise _core.InvalidInputError(f"{path}: give {name}.{key} (rad) or {name}.{deg} (degrees), not both")
    v = table.pop(deg)
    values = v if isinstance(v, list) else None
    if values is None or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                                 for x in values):
        raise _core.InvalidInputError(f"{path}: {name}.{deg} must be a list of finite numbers (degrees), got {v!r}")
    table[key] = [math.radians(float(x)) for x in values]
    return table


#: The current component's largest speed (m/s; forces/current.rs).
MAX_CURRENT_SPEED = 10.0


def current_table(table: dict[str, Any], where: str) -> dict[str, Any]:
    """A ``[current]`` table with the current given by ``speed`` (m/s) and a direction
    (``direction``/``direction_towards``: where it goes, ``direction_from``: where it comes from;
    degrees in the spatial frame, from x towards y) as the component reads it: a ``velocity``
    vector. A table that gives ``velocity`` (or ``times``) is returned as it is."""
    keys = ("speed",) + sea.DIRECTION_KEYS
    if not any(k in table for k in keys):
        return table
    if "velocity" in table or "times" in table:
        given = [k for k in keys if k in table]
        raise _core.InvalidInputError(f"{where}: give the current either as velocity (or a table of times) or by "
                                      f"speed and direction, not both (got {', '.join(given)} with "
                                      f"{'velocity' if 'velocity' in table else 'times'})")
    speed = table.get("speed")
    if speed is None:
        raise _core.InvalidInputError(f"{where}: a direction needs the current's speed (m/s): add speed = ...")
    if isinstance(speed, bool) or not isinstance(speed, (int, float)) or not math.isfinite(speed) or not (
            0 <= speed <= MAX_CURRENT_SPEED):
        raise _core.InvalidInputError(f"{where}.speed must be a number from 0 to {MAX_CURRENT_SPEED:g} m/s (the "
                                      f"current component's range; a sea's currents stay below 3 m/s), got {speed!r}")
    if not any(k in table for k in sea.DIRECTION_KEYS):
        raise _core.InvalidInputError(f"{where}: speed needs a direction (degrees): direction_towards = ... "
                                      "(where the current goes) or direction_from = ... (where it comes from)")
    towards = math.radians(sea.direction_towards(table, where))
    out = {k: v for k, v in table.items() if k not in keys}
    out["velocity"] = [float(speed) * math.cos(towards), float(speed) * math.sin(towards), 0.0]
    return out


def vessel_named(name: str, base_dir: str = ".") -> Vessel:
    """A vessel file (a path, relative to ``base_dir``) or, where no such file exists, a shipped
    vessel by name (``"osv"``; ``phsplit vessels`` lists them)."""
    p = os.path.join(base_dir, name)
    if not os.path.exists(p) and os.sep not in name and not name.endswith(".toml"):
        if name in presets() or name in PRESET_ALIASES:
            return Vessel.preset(name)
        known = ", ".join(presets())
        raise _core.InvalidInputError(f"vessel {name!r} is neither a file nor a shipped vessel (shipped: {known})")
    return Vessel.from_toml(p)


@checked
def load(path: str | os.PathLike[str], vessel: str | None = None) -> Scenario:
    """Read and validate a scenario file, or a shipped scenario by name (``"pipelay"``);
    ``vessel`` replaces its vessel (see :func:`from_dict`)."""
    if not isinstance(path, (str, os.PathLike)):
        raise _core.InvalidInputError(f"a scenario is a file's path or a shipped scenario's name (a str), got "
                                      f"{type(path).__name__} {path!r}")
    p = resolve(path)
    if not os.path.exists(p) and os.fspath(path) == p and os.sep not in p and not p.endswith(".toml"):
        names = ", ".join(shipped())
        raise _core.InvalidInputError(f"scenario {p!r} is neither a file nor a shipped scenario (shipped: {names})")
    return from_dict(_read_toml(p, "scenario file"), p, vessel=vessel)


def _name_of_file(path: str) -> str:
    """An output name from a scenario's file name, confined to the characters a ``name`` may hold
    (letters, digits, '.', '_', '-', starting with a letter or digit, at most 100)."""
    import re

    stem = re.sub(r"[^A-Za-z0-9._-]", "_", os.path.splitext(os.path.basename(path))[0])
    stem = stem.lstrip("._-")[:100]
    return stem or "scenario"
