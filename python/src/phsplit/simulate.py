"""The user-facing simulation API: :class:`Vessel`, :func:`simulate`, :class:`Solution`."""
from __future__ import annotations

import copy
import math
import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core



class StepSizeWarning(UserWarning):
    """The step is longer than half the vessel's shortest natural period: the run stays
    passive and bounded (for the splitting methods) but cannot resolve that motion."""


class PassivityWarning(UserWarning):
    """A composition with negative sub-steps created energy: its discrete map is passive only
    under the condition of the paper's Prop. 2.5, which this run does not meet."""


def presets() -> dict[str, tuple[str, str]]:
    """The shipped vessels: name -> (description with its source, vessel file text)."""
    return {n: (d, t) for n, d, t in _core.Vessel.presets()}


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
        ``"paper"`` (the paper's, App. D) or ``"osv"`` (the 83 m offshore supply vessel of
        Fossen's MSS, osv.m: full added mass, CG off the origin). Each number's source is in the
        preset's file (``phsplit.presets()[name]``)."""
        found = presets()
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
        return cls(_core.Vessel.from_dict(dict(tables)), source)

    def to_toml(self) -> str:
        """Every parameter as TOML text; ``Vessel.from_toml_str`` rebuilds this vessel exactly."""
        return self._once("toml", self._inner.to_toml)

    @property
    def components(self) -> list[str]:
        """The vessel's force components (ports), in the order they are assembled."""
        return list(self._once("components", self._inner.components))

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


@dataclass(frozen=True)
class Ledger:
    """Energy balance per saved interval (J): ``dH = supplied - dissipated + residual``.

    ``by_account`` holds what each component booked: the work of each port (``control``: the
    P and I control terms; ``external``: a constant load; ``∫ ν·τ dt``), and each dissipation
    (``damping``: hydrodynamic; ``control_damping``: the derivative control terms;
    ``∫ νᵀDν dt ≥ 0``). ``supplied`` and ``dissipated`` are their totals. For splitting
    methods all are exact along the sub-flows; for Runge–Kutta methods they are the method's
    own quadrature of the power. The first entry (no interval) is zero.
    """

    dH: np.ndarray
    supplied: np.ndarray
    dissipated: np.ndarray
    by_account: dict[str, np.ndarray] = field(default_factory=dict)
    kinds: dict[str, str] = field(default_factory=dict)
    #: ``|H_n| + |H_{n-1}|`` per interval (the terms whose difference is ``dH``), or None.
    level: np.ndarray | None = None

    @staticmethod
    def level_of(energy: np.ndarray) -> np.ndarray:
        """``|H_n| + |H_{n-1}|`` per saved interval (the first entry zero)."""
        e = np.abs(np.asarray(energy, dtype=float))
        return np.concatenate([[0.0], e[1:] + e[:-1]]) if len(e) else e

    @property
    def residual(self) -> np.ndarray:
        """``dH - (supplied - dissipated)``: zero up to round-off for a passive discretisation."""
        return self.dH - (self.supplied - self.dissipated)

    def relative_residual(self) -> np.ndarray:
        """Residual over the size of the terms of each interval's balance: ``|dH|`` plus each
        account's ``|booked|`` (two ports that nearly cancel, a pipe pulling against the thrusters,
        count with their own sizes: floating point cannot resolve their sum better than that),
        and at least ``1e-4 (|H_n| + |H_{n-1}|)``: ``dH`` is a difference of two energies, each
        evaluated from a state that carries round-off, so a residual below about 1e-14 of ``|H|``
        (a few tens of ulps) is round-off, not a ledger error. Without that floor a conservative
        run, which books nothing, showed 1.0 however well it kept H."""
        booked = sum((np.abs(v) for v in self.by_account.values()), np.zeros_like(self.dH))
        scale = np.abs(self.dH) + np.maximum(booked, np.abs(self.supplied) + np.abs(self.dissipated))
        if self.level is not None and len(self.level) == len(scale):
            scale = np.maximum(scale, 1e-4 * np.asarray(self.level))
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.abs(self.residual) / scale
        return np.where(scale > 0, r, 0.0)


@dataclass(frozen=True)
class Solution:
    """A simulated trajectory at the saved times.

    Arrays have time as their first axis: ``t`` (N,), ``x`` position (N, 3, spatial, m),
    ``euler`` (N, 3: roll, pitch, yaw, rad, ZYX eq. 21), ``quaternion`` (N, 4, scalar first,
    q0 ≥ 0), ``Q`` attitude (N, 3, 3, body→spatial), ``p`` linear and ``m`` angular momentum
    (N, 3, body frame), ``mu`` (N, 3), ``phi_th`` and ``phi_x`` controller integral states,
    ``energy`` H (N,), ``ledger`` (:class:`Ledger`).
    """

    t: np.ndarray
    x: np.ndarray
    euler: np.ndarray
    quaternion: np.ndarray
    Q: np.ndarray
    p: np.ndarray
    m: np.ndarray
    mu: np.ndarray
    phi_th: np.ndarray
    phi_x: np.ndarray
    energy: np.ndarray
    ledger: Ledger
    orthogonality_defect: np.ndarray
    status: str
    method: str
    h: float
    control_start: float | None
    steps: int
    failure: str | None = None
    last_good_state: np.ndarray | None = None
    meta: dict[str, Any] = field(default_factory=dict)
    account_force: np.ndarray | None = None
    account_moment: np.ndarray | None = None
    settings: dict[str, Any] = field(default_factory=dict)
    #: What the components report at the saved states (the pipe's top tension, the moving set
    #: point, ...): name -> (unit, long name, values).
    outputs: dict[str, tuple[str, str, np.ndarray]] = field(default_factory=dict)
    #: The memory of rate-limited thrusters at the saved states (time, each thruster's thrust,
    #: each thruster's angle in rad; docs/model.md §5.8), or None for a vessel without them.
    actuators: np.ndarray | None = None

    def force(self, *accounts: str) -> np.ndarray:
        """Body-frame force (N, 3) of the named ledger accounts, summed (all when none given)."""
        return self._by_account(self.account_force, accounts)

    def moment(self, *accounts: str) -> np.ndarray:
        """Body-frame moment (N, 3) about the body origin of the named accounts, summed."""
        return self._by_account(self.account_moment, accounts)

    def _by_account(self, arr, accounts) -> np.ndarray:
        names = list(self.ledger.by_account)
        unknown = [a for a in accounts if a not in names]
        if unknown:
            raise _core.InvalidInputError(f"unknown ledger account(s) {unknown}; this run has {names}")
        idx = [names.index(a) for a in accounts] if accounts else list(range(len(names)))
        return arr[:, idx, :].sum(axis=1)

    @property
    def control_force(self) -> np.ndarray:
        """The controller's force (P, I and D terms; with thrusters, what they deliver), body frame (N, 3), N."""
        return self.force(*[a for a in ("control", "control_damping", "thrusters") if a in self.ledger.by_account])

    @property
    def control_moment(self) -> np.ndarray:
        """The controller's moment (P, I and D terms; with thrusters, what they deliver), body frame (N, 3), N m."""
        return self.moment(*[a for a in ("control", "control_damping", "thrusters") if a in self.ledger.by_account])

    def at(self, times: Sequence[float] | np.ndarray) -> "Solution":
        """Dense output on request: the states at any ``times`` within the run, each computed by
        stepping from the last saved state at or before it with the run's step and a last,
        shorter step (as ``save_at`` does), so with the method's own order and no interpolation.
        One core call per time. The result's ledger is zero (states only)."""
        from .events import _assemble, _call, _Rows

        prov = self.meta.get("provenance")
        if not prov or "vessel_toml" not in prov:
            raise _core.InvalidInputError("this Solution does not record its vessel (it was assembled from several "
                                          "runs); rerun with save_at instead")
        ts = np.asarray(times, dtype=float).reshape(-1)
        if ts.size == 0 or not np.all(np.isfinite(ts)) or ts.min() < self.t[0] or ts.max() > self.t[-1]:
            raise _core.InvalidInputError(f"times must be finite and within the run [{self.t[0]:g}, {self.t[-1]:g}] s")
        vessel = Vessel.from_toml_str(prov["vessel_toml"])
        cs = self.settings.get("control_start")
        base = Settings(t_span=tuple(self.settings["t_span"]), h=self.h, method=self.method, control_start=cs,
                        outer=self.settings["outer"], save_every=1, linear_flow=self.settings["linear_flow"],
                        ledger=bool(self.settings["ledger"]),
                        project_invariants=bool(self.settings.get("project_invariants", True)))
        names = list(self.ledger.by_account)
        rows = _Rows()
        zero = np.zeros(len(names))
        for t in ts:
            i = int(np.searchsorted(self.t, t, side="right")) - 1
            if t - self.t[i] <= 1e-12 * max(1.0, abs(t)):  # on a saved time, to round-off
                p = _call(vessel, base, t, t + self.h, self.h, self.state(i), 1)
                rows.add(p, 0, zero, t=t)
            else:
                span = float(t) - float(self.t[i])
                p = _call(vessel, base, float(self.t[i]), float(t), min(self.h, span), self.state(i), 1)
                rows.add(p, -1, zero, t=t)
        return _assemble(rows, names, "completed", None, [], 0, base)

    @property
    def events(self) -> list:
        """The events found (``phsplit.events.EventHit``: name, t, state, terminal), in order."""
        return list(self.meta.get("events", []))

    def _velocities(self) -> np.ndarray:
        """The body velocities ``nu = M^-1 (p, m)`` (N, 6), with the vessel's mass matrix."""
        u = np.hstack([np.atleast_2d(self.p), np.atleast_2d(self.m)])
        M = self.meta.get("mass_matrix")
        if M is None:
            return u / np.concatenate([[self.meta["mass"]] * 3, np.asarray(self.meta["inertia"])])
        M = np.asarray(M, dtype=float)
        d = np.diag(M)
        if not np.any(M - np.diag(d)):
            return u / d
        return np.linalg.solve(M, u.T).T

    @property
    def v(self) -> np.ndarray:
        """Body linear velocity (N, 3), m/s (``nu = M^-1 (p, m)``)."""
        return self._velocities()[:, :3]

    @property
    def w(self) -> np.ndarray:
        """Body angular velocity (N, 3), rad/s (``nu = M^-1 (p, m)``)."""
        return self._velocities()[:, 3:]

    def state(self, i: int = -1) -> np.ndarray:
        """The flat 27-vector state at saved index ``i`` (p, m, Q column-major, mu, x, phi_th,
        phi_x), as the core takes it; for a vessel with rate-limited thrusters followed by
        their memory (:attr:`actuators`), so that a run continued from it goes on as one run."""
        y = np.concatenate([self.p[i], self.m[i], self.Q[i].reshape(-1, order="F"), self.mu[i], self.x[i],
                            self.phi_th[i], self.phi_x[i]])
        return y if self.actuators is None else np.concatenate([y, self.actuators[i]])

    def settings_toml(self) -> str:
        """The run's settings as a ``[simulation]`` TOML table (what a scenario file takes)."""
        return settings_to_toml(self.settings)

    def to_xarray(self):
        """The trajectory as a CF-1.8 ``xarray.Dataset``: every variable with ``units`` and
        ``long_name`` (and a ``standard_name`` where CF has one), the velocities in body and
        spatial frames, the forces and moments and the energy of every ledger account, and the
        provenance that reruns it (``phsplit rerun``): the vessel file, the settings, the
        initial state and the chunking of the run."""
        import datetime as _dt

        import xarray as xr

        coords = {
            "time": ("time", self.t, {"units": "seconds since 1970-01-01 00:00:00", "calendar": "standard",
                                      "standard_name": "time", "axis": "T",
                                      "long_name": "simulated time (t = 0 at the nominal epoch)"}),
            "axis_name": ("axis", np.array(["x", "y", "z"]), {"long_name": "vector component"}),
            "angle_name": ("angle", np.array(["roll", "pitch", "yaw"]), {"long_name": "ZYX Euler angle"}),
            "component_name": ("component", np.array(["q0", "q1", "q2", "q3"]),
                               {"long_name": "quaternion component, scalar first"}),
        }

        def var(dims, data, units, long_name, **extra):
            return (dims, np.asarray(data, dtype=np.float64), {"units": units, "long_name": long_name, **extra})

        v_body = self.v
        v_spatial = np.einsum("nij,nj->ni", self.Q, v_body)
        data = {
            "position": var(("time", "axis"), self.x, "m", "position of the body origin, spatial frame (z up)"),
            "euler": var(("time", "angle"), self.euler, "rad", "ZYX Euler angles (roll, pitch, yaw; paper eq. 21)"),
            "quaternion": var(("time", "component"), self.quaternion, "1", "attitude unit quaternion, scalar first"),
            "attitude": var(("time", "row", "col"), self.Q, "1", "attitude matrix Q (body to spatial)"),
            "velocity": var(("time", "axis"), v_body, "m s-1", "linear velocity of the body origin, body frame"),
            "velocity_spatial": var(("time", "axis"), v_spatial, "m s-1", "linear velocity, spatial frame"),
            "angular_velocity": var(("time", "axis"), self.w, "rad s-1", "angular velocity, body frame"),
            "linear_momentum": var(("time", "axis"), self.p, "kg m s-1", "linear momentum p, body frame"),
            "angular_momentum": var(("time", "axis"), self.m, "kg m2 s-1", "angular momentum m, body frame"),
            "mu": var(("time", "axis"), self.mu, "N m", "restoring-moment variable mu (docs/model.md 2.3)"),
            "phi_theta": var(("time", "angle"), self.phi_th, "rad s", "integral of the Euler-angle error"),
            "phi_x": var(("time", "axis"), self.phi_x, "m s", "integral of the position error"),
            "energy": var(("time",), self.energy, "J", "stored energy H (paper eq. 35)"),
            "energy_supplied": var(("time",), self.ledger.supplied, "J", "work supplied through the ports since the previous sample"),
            "energy_dissipated": var(("time",), self.ledger.dissipated, "J", "energy dissipated since the previous sample"),
            "energy_residual": var(("time",), self.ledger.residual, "J", "dH - (supplied - dissipated) since the previous sample"),
            "orthogonality_defect": var(("time",), self.orthogonality_defect, "1", "Frobenius norm of Q^T Q - I"),
        }
        if self.account_force is not None and len(self.ledger.by_account):
            data["control_force"] = var(("time", "axis"), self.control_force, "N", "controller force (P, I, D), body frame")
            data["control_moment"] = var(("time", "axis"), self.control_moment, "N m",
                                         "controller moment (P, I, D) about the body origin, body frame")
        # Every variable goes into one dict and the Dataset is built once: adding them one by one
        # aligns and merges the growing dataset each time (3.3 → 0.55 ms for a one-hour run saved every 20th step).
        for k, (name, series) in enumerate(self.ledger.by_account.items()):
            kind = self.ledger.kinds.get(name, "")
            data[f"energy_{name}"] = var(("time",), series, "J", f"energy {kind} by {name} since the previous sample")
            data[f"force_{name}"] = var(("time", "axis"), self.account_force[:, k, :], "N",
                                        f"force of {name}, body frame")
            data[f"moment_{name}"] = var(("time", "axis"), self.account_moment[:, k, :], "N m",
                                         f"moment of {name} about the body origin, body frame")
        for name, (unit, long_name, values) in self.outputs.items():
            data[name] = var(("time",), values, unit, long_name)
        prov = self.meta.get("provenance", {})
        if "initial_state" in prov:
            y0 = prov["initial_state"]
            data["initial_state"] = var(("state",), y0, "1",
                                      "initial state (p, m, Q column-major, mu, x, phi_theta, phi_x; SI units)"
                                      if len(y0) == 27 else
                                      "initial state (p, m, Q column-major, mu, x, phi_theta, phi_x; then the "
                                      "rate-limited thrusters' memory: time, thrusts, angles in rad; SI units)")
        ds = xr.Dataset(data, coords=coords)
        ds["time"].encoding["_FillValue"] = None  # CF 2.5.1: no fill value on a coordinate
        # Time is the record (unlimited) dimension, as in the CLI's files: appendable, and the
        # vector dimensions may then follow it (CF 2.4).
        ds.encoding["unlimited_dims"] = {"time"}
        now = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
        ds.attrs.update(
            {
                "Conventions": "CF-1.8",
                "title": "phsplit vessel simulation",
                "institution": "phsplit",
                "source": f"phsplit {_core.__version__} ({self.method}, h = {self.h:g} s), passivity-preserving splitting",
                "history": f"{now} phsplit {_core.__version__}: simulated",
                "references": "E. Celledoni, E. H. Hoiseth, N. Ramzina, Passivity-preserving splitting methods for "
                              "rigid body systems, Multibody Syst. Dyn. 44 (2018) 251-275, arXiv:1408.2544",
                "comment": "Model and conventions: docs/model.md of phsplit. Rerun with `phsplit rerun FILE`.",
                "method": self.method,
                "step_size_s": self.h,
                "outer": str(self.settings.get("outer", "")),
                "linear_flow": str(self.settings.get("linear_flow", "")),
                "save_every": int(self.settings.get("save_every", 1)),
                "components": ", ".join(self.meta.get("components", [])),
                "control_start_s": "none" if self.control_start is None else self.control_start,
                "status": self.status,
                "steps": self.steps,
                "phsplit_version": _core.__version__,
                "phsplit_settings": self.settings_toml(),
            }
        )
        if "vessel_toml" in prov:
            ds.attrs["phsplit_vessel"] = prov["vessel_toml"]
        if "chunks" in prov:
            ds.attrs["phsplit_chunks"] = " ".join(str(int(c)) for c in prov["chunks"])
        ds.attrs["software"] = _software_versions()
        if self.failure:
            ds.attrs["failure"] = self.failure
        return ds


def settings_to_toml(settings: Mapping[str, Any]) -> str:
    """Run settings (as the core returns them) as a ``[simulation]`` TOML table."""
    sim = {k: settings[k] for k in Settings.__dataclass_fields__ if k in settings}
    sim["t_span"] = [float(x) for x in sim["t_span"]]
    if sim.get("control_start") is None:
        sim["control_start"] = "never"
    return _core.dumps_toml({"simulation": sim})


def _software_versions() -> str:
    import platform

    out = [f"phsplit {_core.__version__}", f"python {platform.python_version()}", f"numpy {np.__version__}"]
    for mod in ("xarray", "netCDF4"):
        try:
            out.append(f"{mod} {__import__(mod).__version__}")
        except ImportError:  # pragma: no cover - both are dependencies
            pass
    return ", ".join(out)


def _warn_if_energy_created(raw: dict, info: dict, outer: str, e: np.ndarray) -> None:
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
        "'sp2'/'lie', whose positive steps are passive for any h (Prop. 2.2)."), stacklevel=3)


def _warn_if_step_too_long(vessel: "Vessel", y0: np.ndarray, settings: "Settings") -> None:
    """Issue 13: a StepSizeWarning when h exceeds half the shortest natural period of the
    vessel (flow S2 linearised at the initial attitude, with the controller as it will act):
    fewer than two steps per period cannot represent that oscillation."""
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
            stacklevel=3)


_DEFAULTS = _core.default_settings()


@dataclass(frozen=True)
class Settings:
    """The settings of a run, with the one set of defaults (the core's; the paper's Fig. 2:
    SP4, h = 0.5 s on [0, 200] s, the controller from t = 50 s; flow S2 by Gauss collocation,
    ``linear_flow = "exact"`` for the paper's exact S2) shared by :func:`simulate`,
    scenario files, :func:`~phsplit.simulate_many` and sweeps. Values are checked by the core
    when a run starts (or by :meth:`checked`)."""

    t_span: tuple[float, float] = tuple(_DEFAULTS["t_span"])  # type: ignore[assignment]
    h: float = _DEFAULTS["h"]
    method: str = _DEFAULTS["method"]
    control_start: float | None = _DEFAULTS["control_start"]
    outer: str = _DEFAULTS["outer"]
    save_every: int = _DEFAULTS["save_every"]
    linear_flow: str = _DEFAULTS["linear_flow"]
    ledger: bool = _DEFAULTS["ledger"]
    project_invariants: bool = _DEFAULTS["project_invariants"]

    def as_core(self) -> dict[str, Any]:
        """The settings as the core takes them: numpy scalars as Python numbers, ``None`` for
        ``control_start`` as ``"never"``; ``None`` anywhere else is refused by name."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__}
        if d["control_start"] is None:
            d["control_start"] = "never"
        for k, v in d.items():
            if v is None:
                what = dict(_core.settings_keys())
                raise _core.InvalidInputError(f"{k} must be given ({what.get(k, 'a value')}), got None")
            if isinstance(v, np.bool_):
                d[k] = bool(v)
            elif isinstance(v, np.integer):
                d[k] = int(v)
            elif isinstance(v, np.floating):
                d[k] = float(v)
        return d

    def checked(self) -> dict[str, Any]:
        """The settings as the core validated them, with the step count ``n_steps``."""
        return _core.check_settings(self.as_core())

    def run(self, vessel: "Vessel", **kw) -> "Solution":
        return simulate(vessel, settings=self, **kw)


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
    orthonormalize: bool = False,
    settings: Settings | None = None,
    progress: bool | Any = None,
    save_at: Sequence[float] | np.ndarray | None = None,
    events: Sequence[Any] | None = None,
    running_max: bool = False,
    _continuing: bool = False,
) -> Solution:
    """Simulate the vessel with fixed steps ``h`` over ``t_span``.

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
    ``angular_velocity``. ``linear_flow`` integrates the linear flow S2 by Gauss collocation of
    the method's order (``"gauss"``, the default: the diagonal Padé approximant, same order,
    still passive, paper Remark 2.3; 2 to 8 times sooner to a given accuracy, README) or
    exactly (``"exact"``, matrix exponentials: the paper's scheme, §3.4.2). An initial
    attitude that is not a rotation is rejected unless ``orthonormalize=True`` asks for its
    projection to the nearest rotation. ``settings`` (a :class:`Settings`) replaces all the
    settings arguments at once.

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
    """
    if not isinstance(vessel, Vessel):
        raise _core.InvalidInputError(f"vessel must be a phsplit.Vessel, got {type(vessel).__name__}")
    if settings is None:
        settings = Settings(t_span=t_span, h=h, method=method, control_start=control_start, outer=outer,
                            save_every=save_every, linear_flow=linear_flow, ledger=ledger,
                            project_invariants=project_invariants)
    elif not isinstance(settings, Settings):
        raise _core.InvalidInputError(f"settings must be a phsplit.Settings, got {type(settings).__name__}")
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
    if running_max and (save_at is not None or events):
        raise _core.InvalidInputError("running_max cannot be combined with save_at or events")
    if events is not None and not isinstance(events, (list, tuple)):
        events = [events]  # a single Event
    if save_at is not None or events:
        # Output at chosen times, or events: several core calls (phsplit.events).
        from .events import run_with_outputs

        if y0 is not None and not _continuing:
            y0 = _core.check_state(y0, bool(orthonormalize))  # a user's state: checked once, here
        return run_with_outputs(vessel, settings, y0, save_at=save_at, events=events)
    if progress is True:
        from tqdm import tqdm

        n = settings.checked()["n_steps"]
        bar = tqdm(total=n, unit="step", unit_scale=True, leave=False)

        def cb(done, total, _bar=bar):
            _bar.update(done - _bar.n)
    elif progress is None or progress is False:
        bar, cb = None, None
    elif callable(progress):
        bar, cb = None, progress
    else:
        raise _core.InvalidInputError(f"progress must be True, False, None or a callable f(steps_done, n_steps), "
                                      f"got {type(progress).__name__}")
    _warn_if_step_too_long(vessel, y0, settings)
    try:
        # _continuing: y0 is the last state of an earlier call of the same run (run_chunks,
        # save_at, events, Solution.at): taken as it is, only checked to be finite.
        raw = _core.integrate(vessel._inner, settings.as_core(), y0, bool(orthonormalize), cb, bool(running_max),
                              bool(_continuing and y0 is not None))
    finally:
        if bar is not None:
            bar.close()
    used = raw["settings"]
    e = raw["energy"]
    dH = np.concatenate([[0.0], np.diff(e)])
    info = _core.method_info(used["method"])
    if used["ledger"] and info["kind"] == "splitting" and not info["all_positive"] and len(e) > 1:
        _warn_if_energy_created(raw, info, used["outer"], e)
    mass, inertia = vessel._body()
    names = list(raw["accounts"])
    sol = Solution(
        t=raw["t"], x=raw["x"], euler=raw["euler"], quaternion=raw["quaternion"], Q=raw["Q"],
        p=raw["p"], m=raw["m"], mu=raw["mu"], phi_th=raw["phi_th"], phi_x=raw["phi_x"],
        energy=e,
        ledger=Ledger(dH=dH, supplied=raw["supplied"], dissipated=raw["dissipated"],
                      by_account={n: raw["booked"][:, k] for k, n in enumerate(names)},
                      kinds=dict(zip(names, raw["account_kinds"])), level=Ledger.level_of(e)),
        orthogonality_defect=raw["orthogonality_defect"], status=raw["status"],
        method=info["name"], h=used["h"], control_start=used["control_start"], steps=raw["steps"],
        failure=raw.get("failure"), last_good_state=raw["last_good"],
        meta={"mass": mass, "inertia": inertia, "mass_matrix": vessel.mass_matrix,
              "t_last_good": raw["t_last_good"],
              "components": vessel.components},
        account_force=raw["account_force"], account_moment=raw["account_moment"], settings=dict(used),
        outputs={k: (u, ln, np.asarray(v)) for k, (u, ln, v) in raw.get("outputs", {}).items()},
        actuators=raw.get("actuators"),
    )
    # What reruns it (phsplit rerun): the vessel file, the initial state the core used, one chunk.
    sol.meta["running_max"] = dict(raw["running_max"])
    sol.meta["provenance"] = {"vessel_toml": vessel.to_toml(), "initial_state": sol.state(0),
                              "chunks": [int(used["n_steps"])]}
    return sol
