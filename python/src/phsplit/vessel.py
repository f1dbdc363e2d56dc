"""The vessel: :class:`Vessel` (rigid body, forces and ports, default initial state) and the
shipped presets. A data type of the bottom layer: it imports only the core."""
from __future__ import annotations

import copy
import os
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core

def presets() -> dict[str, tuple[str, str]]:
    """The shipped vessels: name -> (description with its source, vessel file text)."""
    return {n: (d, t) for n, d, t in _core.Vessel.presets()}


#: Earlier names of shipped vessels, still accepted: old name -> the preset's name now.
#: ``supply`` is ``shipx-supply`` (the 82.8 m vessel of MSS's ShipX data; MSS's own
#: ``supply.m`` is a different, 76.2 m vessel, which the old name suggested).
PRESET_ALIASES = {"supply": "shipx-supply"}


def preset_name(name: str) -> str:
    """A preset's name now, for its name or an earlier one (:data:`PRESET_ALIASES`)."""
    return PRESET_ALIASES.get(name, name) if isinstance(name, str) else name


class Vessel:
    """A vessel: rigid body, forces and ports (components), default initial state (SI units).

    ``Vessel.paper()`` is the paper's vessel (Appendix D; docs/model.md §4);
    ``Vessel.from_toml(path)`` reads a file with tables ``[vessel]``, ``[control]``,
    ``[initial]`` and optional components such as ``[external]`` (the paper's file,
    ``Vessel.paper_toml()``, is the template); ``Vessel.from_dict(d)`` takes the same tables as a
    mapping (``to_dict()`` gives them back, with defaults filled in).
    """

    __slots__ = ("_inner", "source", "_derived")

    def __init__(self, inner: _core.Vessel, source: str = "") -> None:
        self._inner = inner
        self.source = source
        # What every run asks of the vessel (its TOML text, body, mass matrix, components,
        # natural periods), computed once: a vessel does not change after it is built.
        self._derived: dict[Any, Any] = {}
        if inner.own_states():
            _check_output_names(inner)

    def _once(self, key: Any, make):
        try:
            derived = self._derived
        except AttributeError:  # unpickled from a phsplit without the slot
            derived = self._derived = {}
        if key not in derived:
            derived[key] = make()
        return derived[key]

    @classmethod
    def paper(cls) -> "Vessel":
        return cls(_core.Vessel.paper(), "paper (Celledoni, Høiseth, Ramzina 2018, App. D)")

    @classmethod
    def preset(cls, name: str) -> "Vessel":
        """A shipped vessel by name (``phsplit.presets()`` lists them; ``phsplit vessels``):
        ``"paper"`` (the paper's, App. D), ``"osv"`` (the 83 m offshore supply vessel of
        Fossen's MSS, osv.m: full added mass, CG off the origin) or ``"shipx-supply"`` (the
        82.8 m supply vessel of MSS's ShipX data; ``"supply"``, its earlier name, still works). Each number's source is in the
        preset's file (``phsplit.presets()[name]``)."""
        found = presets()
        name = preset_name(name)
        if not isinstance(name, str) or name not in found:
            raise _core.InvalidInputError(
                f"unknown vessel preset {name!r}; the presets are {', '.join(repr(k) for k in found)}")
        if name == "paper":
            return cls.paper()
        return cls(_core.Vessel.from_toml_str(found[name][1]), f"preset {name}")

    @classmethod
    def from_toml(cls, path: str | os.PathLike[str]) -> "Vessel":
        p = os.fspath(path)
        try:
            with open(p, encoding="utf-8-sig") as f:
                text = f.read()
        except OSError as e:
            raise _core.InvalidInputError(f"cannot read vessel file {p!r}: {e.strerror}") from None
        except UnicodeDecodeError:
            raise _core.ScenarioParseError(f"{p}: not a text file (TOML must be UTF-8)") from None
        try:
            return cls(_core.Vessel.from_toml_str(text), p)
        except (_core.ScenarioParseError, _core.InvalidInputError) as e:
            raise type(e)(f"{p}: {e}") from None

    @classmethod
    def from_toml_str(cls, text: str) -> "Vessel":
        return cls(_core.Vessel.from_toml_str(text), "<string>")

    @classmethod
    def from_dict(cls, tables: Mapping[str, Any], source: str = "<dict>") -> "Vessel":
        """A vessel from a mapping of the tables of a vessel file (as ``to_dict()`` returns)."""
        if not isinstance(tables, Mapping):
            raise _core.InvalidInputError(f"a vessel is a mapping of tables, got {type(tables).__name__}")
        try:
            inner = _core.Vessel.from_dict(dict(tables))
        except OverflowError:  # a Python integer beyond any float, which the conversion cannot take
            where = _too_large(tables, "")
            raise _core.InvalidInputError(f"{where or 'a value'} must be a finite number, got an integer too large "
                                          f"for a float") from None
        return cls(inner, source)

    def to_toml(self) -> str:
        """Every parameter as TOML text; ``Vessel.from_toml_str`` rebuilds this vessel exactly."""
        return self._once("toml", self._inner.to_toml)

    @property
    def components(self) -> list[str]:
        """The vessel's force components (ports), in the order they are assembled."""
        return list(self._once("components", self._inner.components))

    @property
    def own_states(self) -> list[tuple[str, str, str, float]]:
        """The states the components keep of their own (a port-Hamiltonian subsystem's), in the
        order they follow the body's 27 numbers in a state: ``(name, unit, long_name, initial)``.
        Empty for a vessel whose components keep none."""
        return list(self._once("own_states", self._inner.own_states))

    @property
    def mass_matrix(self) -> np.ndarray:
        """The 6x6 mass matrix ``M = M_RB + M_A`` (body frame, z up; kg, kg m, kg m^2 blocks):
        the momenta are ``(p, m) = M nu`` (docs/model.md §5.14)."""
        return self._once("mass_matrix", lambda: np.asarray(self._inner.mass_matrix(), dtype=float)).copy()

    def _body(self) -> tuple[Any, Any]:
        """The ``[vessel]`` table's mass and inertia (fresh copies)."""
        mass, inertia = self._once("body", lambda: (lambda b: (b["mass"], b["inertia"]))(self.to_dict()["vessel"]))
        return mass, ([list(r) if isinstance(r, list) else r for r in inertia] if isinstance(inertia, list)
                      else copy.deepcopy(inertia))

    def _natural_periods_at(self, state: np.ndarray, control: bool) -> list[float]:
        key = ("periods", np.asarray(state, dtype=float).tobytes(), bool(control))
        return list(self._once(key, lambda: self._inner.natural_periods(state, bool(control))))

    def natural_periods(self, control: bool = True, **initial: Sequence[float]) -> list[float]:
        """The natural periods (s, ascending) of the vessel's oscillating modes, flow S2
        linearised at the initial attitude (or at ``initial_state(**initial)``'s), with the
        controller on or off. For the paper's vessel: pitch 4.08, heave 4.25, roll 9.21 s."""
        if not isinstance(control, (bool, np.bool_)):
            raise _core.InvalidInputError(f"natural_periods: control must be True or False, got {control!r}")
        return list(self._inner.natural_periods(self.initial_state(**initial), bool(control)))

    @property
    def accounts(self) -> list[tuple[str, str]]:
        """The ledger's accounts: ``(name, "supplied" | "dissipated")``."""
        return self._inner.accounts()

    @staticmethod
    def paper_toml() -> str:
        """The TOML text of the paper's vessel, with its provenance."""
        return _core.Vessel.paper_toml()

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """Every parameter as read, defaults filled in: the tables of a vessel file."""
        return self._inner.to_dict()

    def energy(self, state: np.ndarray) -> float:
        """Stored energy H (eq. 35, J) of a flat 27-vector state (a thrusters' memory after it is
        allowed and stores nothing)."""
        return self._inner.energy(np.ascontiguousarray(state, dtype=float))

    def initial_state(self, **overrides: Sequence[float]) -> np.ndarray:
        """Flat 27-vector initial state; override ``euler``, ``position``, ``velocity``,
        ``angular_velocity`` (body frame) by keyword."""
        allowed = {"euler", "position", "velocity", "angular_velocity"}
        unknown = set(overrides) - allowed
        if unknown:
            raise _core.InvalidInputError(
                f"unknown initial-state field(s) {sorted(unknown)}; allowed: {sorted(allowed)}"
            )
        conv = {k: _vec3(k, v) for k, v in overrides.items()}
        return self._inner.initial_state(**conv)

    def __repr__(self) -> str:
        return f"<phsplit.Vessel {self.source or 'custom'}: {self._inner!r}>"


def _vec3(name: str, v: Any) -> list[float]:
    try:
        a = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise _core.InvalidInputError(f"{name} must be 3 numbers, got {v!r}") from None
    if a.shape != (3,):
        raise _core.InvalidInputError(f"{name} must have 3 components, got shape {a.shape}")
    return [float(x) for x in a]


#: The variables (and coordinates) of a run's dataset (``Solution.to_xarray``, the CLI's files)
#: besides the components' outputs, and the prefixes of each ledger account's three.
DATASET_VARIABLES = frozenset({
    "time", "axis", "angle", "component", "row", "col", "state", "axis_name", "angle_name", "component_name",
    "position", "euler", "quaternion", "attitude", "velocity", "velocity_spatial", "angular_velocity",
    "linear_momentum", "angular_momentum", "mu", "phi_theta", "phi_x", "energy", "energy_supplied",
    "energy_dissipated", "energy_residual", "orthogonality_defect", "control_force", "control_moment",
    "initial_state"})
ACCOUNT_PREFIXES = ("energy_", "force_", "moment_")


def _check_output_names(inner: _core.Vessel) -> None:
    """A subsystem's outputs are named after it and its states (``<name>_<state>``): none may
    take the name of a variable the run's dataset holds already, which it would replace there."""
    taken = set(DATASET_VARIABLES) | {p + a for a, _ in inner.accounts() for p in ACCOUNT_PREFIXES}
    for name in inner.outputs(inner.initial_state(), 0.0):
        if name in taken:
            raise _core.InvalidInputError(
                f"a port-Hamiltonian subsystem reports a quantity named {name!r}, the name of a variable the "
                f"results already hold: rename the subsystem or its state (port_hamiltonian.name or "
                f"port_hamiltonian.states)")


def _too_large(x: Any, at: str) -> str | None:
    """Where (``table.key[i][j]``) the first integer too large for a float is in ``x``."""
    if isinstance(x, int) and not isinstance(x, bool):
        try:
            float(x)
        except OverflowError:
            return at
        return None
    if isinstance(x, Mapping):
        for k, v in x.items():
            found = _too_large(v, f"{at}.{k}" if at else str(k))
            if found:
                return found
    elif isinstance(x, (list, tuple)):
        for i, v in enumerate(x):
            found = _too_large(v, f"{at}[{i}]")
            if found:
                return found
    return None
