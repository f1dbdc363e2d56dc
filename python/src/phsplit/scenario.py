"""Scenario files (TOML): what to simulate, validated with messages that name the problem.

A scenario has a ``[simulation]`` table and optionally a vessel, either as a path
(``vessel = "my_vessel.toml"``, relative to the scenario file) or inline as the ``[vessel]``,
``[control]`` and ``[initial]`` tables of a vessel file. Without a vessel, the paper's is used.

.. code-block:: toml

    [simulation]
    t_span = [0.0, 200.0]   # s
    h = 0.5                 # s
    method = "sp4"          # lie, sp2, sp4, sp6, euler, heun, rk4
    control_start = 50.0    # s; omit for no control
    outer = "dissipative"   # or "conservative"
    save_every = 1
"""
from __future__ import annotations

import difflib
import os
import tomllib
from dataclasses import dataclass, field
from typing import Any

from . import _core
from .simulate import Vessel

SIMULATION_KEYS = {
    "t_span": "two numbers [t0, t1], s",
    "h": "step size, s",
    "method": "one of " + ", ".join(_core.METHODS),
    "control_start": "time the controller starts, s",
    "outer": "'dissipative' or 'conservative'",
    "save_every": "integer >= 1",
    "name": "a label for the output files",
}
TOP_KEYS = {"simulation", "vessel", "control", "initial"}


@dataclass
class Scenario:
    vessel: Vessel
    t_span: tuple[float, float] = (0.0, 200.0)
    h: float = 0.5
    method: str = "sp4"
    control_start: float | None = 50.0
    outer: str = "dissipative"
    save_every: int = 1
    name: str = "fig2"
    extra: dict[str, Any] = field(default_factory=dict)

    @classmethod
    def paper_fig2(cls) -> "Scenario":
        """The paper's Fig. 2: t in [0, 200], controller on at t = 50, SP4 with h = 0.5."""
        return cls(vessel=Vessel.paper())


def _unknown(key: str, allowed: set[str] | dict[str, str], where: str) -> str:
    near = difflib.get_close_matches(key, list(allowed), n=1)
    hint = f"; did you mean {near[0]!r}?" if near else ""
    return f"unknown key {key!r} in {where}{hint} (allowed: {', '.join(sorted(allowed))})"


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise _core.ScenarioParseError(f"unsupported value {v!r} in a vessel table")


def load(path: str | os.PathLike[str]) -> Scenario:
    """Read and validate a scenario file."""
    p = os.fspath(path)
    try:
        with open(p, "rb") as f:
            data = tomllib.load(f)
    except FileNotFoundError:
        raise _core.InvalidInputError(f"scenario file {p!r} does not exist") from None
    except OSError as e:
        raise _core.InvalidInputError(f"cannot read scenario file {p!r}: {e.strerror}") from None
    except tomllib.TOMLDecodeError as e:
        raise _core.ScenarioParseError(f"{p}: TOML syntax error: {e}") from None
    for k in data:
        if k not in TOP_KEYS:
            raise _core.ScenarioParseError(f"{p}: " + _unknown(k, TOP_KEYS, "the scenario"))
    sim = data.get("simulation", {})
    if not isinstance(sim, dict):
        raise _core.ScenarioParseError(f"{p}: [simulation] must be a table")
    for k in sim:
        if k not in SIMULATION_KEYS:
            raise _core.ScenarioParseError(f"{p}: " + _unknown(k, SIMULATION_KEYS, "[simulation]"))
    v = data.get("vessel")
    base = os.path.dirname(os.path.abspath(p))
    if v is None:
        vessel = Vessel.paper()
    elif isinstance(v, str):
        vessel = Vessel.from_toml(os.path.join(base, v))
    elif isinstance(v, dict):
        text = []
        for section in ("vessel", "control", "initial"):
            table = data.get(section)
            if not isinstance(table, dict):
                raise _core.ScenarioParseError(
                    f"{p}: an inline vessel needs the tables [vessel], [control] and [initial]; [{section}] is missing"
                )
            text.append(f"[{section}]")
            text.extend(f"{key} = {_toml_value(val)}" for key, val in table.items())
        try:
            vessel = Vessel.from_toml_str("\n".join(text))
        except (_core.ScenarioParseError, _core.InvalidInputError) as e:
            raise type(e)(f"{p}: {e}") from None
        vessel.source = p
    else:
        raise _core.ScenarioParseError(f"{p}: 'vessel' must be a file path or a table")
    sc = Scenario(vessel=vessel)
    name = os.path.splitext(os.path.basename(p))[0]
    sc.name = str(sim.get("name", name))
    if "t_span" in sim:
        ts = sim["t_span"]
        if not (isinstance(ts, list) and len(ts) == 2 and all(isinstance(x, (int, float)) for x in ts)):
            raise _core.ScenarioParseError(f"{p}: simulation.t_span must be two numbers [t0, t1] in s, got {ts!r}")
        sc.t_span = (float(ts[0]), float(ts[1]))
    for key, typ in (("h", (int, float)), ("control_start", (int, float)), ("save_every", int),
                     ("method", str), ("outer", str)):
        if key in sim:
            val = sim[key]
            if not isinstance(val, typ) or isinstance(val, bool):
                raise _core.ScenarioParseError(
                    f"{p}: simulation.{key} must be {SIMULATION_KEYS[key]}, got {val!r}"
                )
            setattr(sc, key, float(val) if typ == (int, float) else val)
    if "control_start" not in sim and "simulation" in data:
        sc.control_start = None
    return sc
