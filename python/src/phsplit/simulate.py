"""The user-facing simulation API: :class:`Vessel`, :func:`simulate`, :class:`Solution`."""
from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core

_OUTER = ("dissipative", "conservative")


class PassivityWarning(UserWarning):
    """A composition with negative sub-steps created energy: its discrete map is passive only
    under the condition of the paper's Prop. 2.5, which this run does not meet."""


class Vessel:
    """A vessel: hull data, PID controller and default initial state (SI units).

    ``Vessel.paper()`` is the paper's vessel (Appendix D, reconstructed in MODEL.md §3);
    ``Vessel.from_toml(path)`` reads a file with sections ``[vessel]``, ``[control]``,
    ``[initial]`` (the paper's file, ``Vessel.paper_toml()``, is the template).
    """

    __slots__ = ("_inner", "source")

    def __init__(self, inner: _core.Vessel, source: str = "") -> None:
        self._inner = inner
        self.source = source

    @classmethod
    def paper(cls) -> "Vessel":
        return cls(_core.Vessel.paper(), "paper (Celledoni, Høiseth, Ramzina 2018, App. D)")

    @classmethod
    def from_toml(cls, path: str | os.PathLike[str]) -> "Vessel":
        p = os.fspath(path)
        try:
            with open(p, encoding="utf-8") as f:
                text = f.read()
        except OSError as e:
            raise _core.InvalidInputError(f"cannot read vessel file {p!r}: {e.strerror}") from None
        try:
            return cls(_core.Vessel.from_toml_str(text), p)
        except _core.ScenarioParseError as e:
            raise _core.ScenarioParseError(f"{p}: {_suggest(str(e))}") from None

    @classmethod
    def from_toml_str(cls, text: str) -> "Vessel":
        try:
            return cls(_core.Vessel.from_toml_str(text), "<string>")
        except _core.ScenarioParseError as e:
            raise _core.ScenarioParseError(_suggest(str(e))) from None

    @staticmethod
    def paper_toml() -> str:
        """The TOML text of the paper's vessel, with its provenance."""
        return _core.Vessel.paper_toml()

    def to_dict(self) -> dict[str, dict[str, Any]]:
        return self._inner.to_dict()

    def energy(self, state: np.ndarray) -> float:
        """Stored energy H (eq. 35, J) of a flat 27-vector state."""
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


def _suggest(message: str) -> str:
    """Add the nearest valid key to the parser's "unknown field `x`, expected one of ..."."""
    import difflib
    import re

    m = re.search(r"unknown field `([^`]*)`, expected (?:one of )?(.*)", message)
    if not m:
        return message
    valid = re.findall(r"`([^`]*)`", m.group(2))
    near = difflib.get_close_matches(m.group(1), valid, n=1)
    return message.rstrip() + (f"; did you mean '{near[0]}'?" if near else "")


def _vec3(name: str, v: Any) -> list[float]:
    a = np.asarray(v, dtype=float)
    if a.shape != (3,):
        raise _core.InvalidInputError(f"{name} must have 3 components, got shape {a.shape}")
    return [float(x) for x in a]


@dataclass(frozen=True)
class Ledger:
    """Energy balance per saved interval (J): ``dH = supplied - dissipated + residual``.

    ``supplied`` is the work of the port (the P and I control terms, ``∫ ν·τ dt``);
    ``dissipated`` is ``∫ νᵀDν dt`` with D the hydrodynamic damping plus the derivative control
    terms. For splitting methods both are exact along the sub-flows; for Runge–Kutta methods they
    are the method's own quadrature of the power. The first entry (no interval) is zero.
    """

    dH: np.ndarray
    supplied: np.ndarray
    dissipated: np.ndarray

    @property
    def residual(self) -> np.ndarray:
        """``dH - (supplied - dissipated)``: zero up to round-off for a passive discretisation."""
        return self.dH - (self.supplied - self.dissipated)

    def relative_residual(self) -> np.ndarray:
        """Residual over the size of the terms of each interval's balance."""
        scale = np.abs(self.dH) + np.abs(self.supplied) + np.abs(self.dissipated)
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

    @property
    def v(self) -> np.ndarray:
        """Body linear velocity (N, 3), m/s."""
        return self.p / self.meta["mass"]

    @property
    def w(self) -> np.ndarray:
        """Body angular velocity (N, 3), rad/s."""
        return self.m / np.asarray(self.meta["inertia"])

    def to_xarray(self):
        """The trajectory as an ``xarray.Dataset`` with named variables, units and long names."""
        import xarray as xr

        ax = ["x", "y", "z"]
        ang = ["roll", "pitch", "yaw"]
        coords = {"time": ("time", self.t, {"units": "s", "long_name": "time"}),
                  "axis": ax, "angle": ang, "component": ["q0", "q1", "q2", "q3"],
                  "row": [0, 1, 2], "col": [0, 1, 2]}

        def var(dims, data, units, long_name):
            return (dims, data, {"units": units, "long_name": long_name})

        ds = xr.Dataset(
            {
                "position": var(("time", "axis"), self.x, "m", "spatial position x"),
                "euler": var(("time", "angle"), self.euler, "rad", "ZYX Euler angles (roll, pitch, yaw)"),
                "quaternion": var(("time", "component"), self.quaternion, "1", "attitude unit quaternion, scalar first"),
                "attitude": var(("time", "row", "col"), self.Q, "1", "attitude matrix Q (body to spatial)"),
                "linear_momentum": var(("time", "axis"), self.p, "kg m s-1", "linear momentum p, body frame"),
                "angular_momentum": var(("time", "axis"), self.m, "kg m2 s-1", "angular momentum m, body frame"),
                "mu": var(("time", "axis"), self.mu, "N m", "restoring-moment variable mu"),
                "phi_theta": var(("time", "angle"), self.phi_th, "rad s", "integral of Euler-angle error"),
                "phi_x": var(("time", "axis"), self.phi_x, "m s", "integral of position error"),
                "energy": var(("time",), self.energy, "J", "stored energy H (eq. 35)"),
                "energy_supplied": var(("time",), self.ledger.supplied, "J", "port work since previous sample"),
                "energy_dissipated": var(("time",), self.ledger.dissipated, "J", "energy dissipated since previous sample"),
                "energy_residual": var(("time",), self.ledger.residual, "J", "dH - (supplied - dissipated)"),
                "orthogonality_defect": var(("time",), self.orthogonality_defect, "1", "||Q^T Q - I||_F"),
            },
            coords=coords,
        )
        ds.attrs.update(
            {
                "title": "phsplit vessel simulation",
                "method": self.method,
                "step_size_s": self.h,
                "control_start_s": "none" if self.control_start is None else self.control_start,
                "status": self.status,
                "steps": self.steps,
                "reference": "Celledoni, Hoiseth, Ramzina, Multibody Syst. Dyn. 44 (2018) 251-275",
                "phsplit_version": _core.__version__,
            }
        )
        if self.failure:
            ds.attrs["failure"] = self.failure
        return ds


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


def simulate(
    vessel: Vessel,
    t_span: tuple[float, float] = (0.0, 200.0),
    h: float = 0.5,
    method: str = "sp4",
    control_start: float | None = 50.0,
    *,
    outer: str = "dissipative",
    save_every: int = 1,
    ledger: bool = True,
    initial: np.ndarray | Mapping[str, Sequence[float]] | None = None,
    linear_flow: str = "exact",
    orthonormalize: bool = False,
) -> Solution:
    """Simulate the vessel with fixed steps ``h`` over ``t_span``.

    ``method`` is one of ``phsplit.METHODS``: splitting ``lie``, ``sp2`` (Strang), ``sp4``,
    ``sp6`` (Blanes–Moan) or explicit Runge–Kutta ``euler``, ``heun``, ``rk4``. The controller
    acts from the first step that starts at or after ``control_start`` (``None``: never).
    ``outer`` chooses the outermost flow of a splitting: ``"dissipative"`` (S2, default) or
    ``"conservative"`` (S1). The run takes ``floor((t1 - t0) / h)`` steps (to round-off) and
    saves every ``save_every``-th step and the last. ``initial`` overrides the vessel's initial
    state: a flat 27-vector or a mapping with ``euler``, ``position``, ``velocity``,
    ``angular_velocity``. ``linear_flow`` integrates the linear flow S2 exactly (``"exact"``,
    matrix exponentials) or by Gauss collocation of the method's order (``"gauss"``, the
    diagonal Padé approximant: faster, same order, still passive; paper Remark 2.3). An initial
    attitude that is not a rotation is rejected unless ``orthonormalize=True`` asks for its
    projection to the nearest rotation.

    A run whose state becomes non-finite stops there: ``status == "failed"``, ``failure`` says
    where, the arrays hold what was saved before, ``last_good_state`` the last finite state.
    """
    if not isinstance(vessel, Vessel):
        raise _core.InvalidInputError(f"vessel must be a phsplit.Vessel, got {type(vessel).__name__}")
    try:
        t0, t1 = (float(v) for v in t_span)
    except (TypeError, ValueError):
        raise _core.InvalidInputError(f"t_span must be two numbers (t0, t1) in s, got {t_span!r}") from None
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise _core.InvalidInputError(f"t_span must be finite with t1 > t0 (s), got ({t0}, {t1})")
    h = float(h)
    if not (math.isfinite(h) and h > 0):
        raise _core.InvalidInputError(f"h must be finite and > 0 (s), got {h}")
    if method not in _core.METHODS and method not in ("strang",):
        raise _core.InvalidInputError(f"unknown method {method!r}; valid methods: {', '.join(_core.METHODS)}")
    if outer not in _OUTER:
        raise _core.InvalidInputError(f"outer must be one of {_OUTER}, got {outer!r}")
    if not isinstance(save_every, (int, np.integer)) or save_every < 1:
        raise _core.InvalidInputError(f"save_every must be an integer >= 1, got {save_every!r}")
    n = math.floor((t1 - t0) / h * (1 + 1e-12))
    if n < 1:
        raise _core.InvalidInputError(f"h = {h} s is longer than t_span ({t1 - t0} s): no step to take")
    if n > _core.MAX_STEPS:
        raise _core.InvalidInputError(
            f"t_span / h asks for {n:.3e} steps; a run takes at most {_core.MAX_STEPS:.0e} steps "
            "(split it into several runs, or take a longer h)")
    if control_start is not None and not math.isfinite(float(control_start)):
        raise _core.InvalidInputError(f"control_start must be finite (s) or None, got {control_start}")
    if control_start is not None:
        control_start = float(control_start)
    if initial is None:
        y0 = vessel.initial_state()
    elif isinstance(initial, Mapping):
        y0 = vessel.initial_state(**initial)
    else:
        y0 = np.ascontiguousarray(initial, dtype=float).reshape(-1)
    if linear_flow not in ("exact", "gauss"):
        raise _core.InvalidInputError(f"linear_flow must be 'exact' or 'gauss', got {linear_flow!r}")
    raw = _core.integrate(vessel._inner, t0, h, n, method, control_start, outer, int(save_every), bool(ledger), y0,
                          linear_flow, bool(orthonormalize))
    e = raw["energy"]
    dH = np.concatenate([[0.0], np.diff(e)])
    info = _core.method_info(method)
    if ledger and info["kind"] == "splitting" and not info["all_positive"] and len(e) > 1:
        _warn_if_energy_created(raw, info, outer, e)
    hull = vessel.to_dict()["vessel"]
    return Solution(
        t=raw["t"], x=raw["x"], euler=raw["euler"], quaternion=raw["quaternion"], Q=raw["Q"],
        p=raw["p"], m=raw["m"], mu=raw["mu"], phi_th=raw["phi_th"], phi_x=raw["phi_x"],
        energy=e, ledger=Ledger(dH=dH, supplied=raw["supplied"], dissipated=raw["dissipated"]),
        orthogonality_defect=raw["orthogonality_defect"], status=raw["status"],
        method=_core.method_info(method)["name"], h=h, control_start=control_start, steps=raw["steps"],
        failure=raw.get("failure"), last_good_state=raw["last_good"],
        meta={"mass": hull["mass"], "inertia": hull["inertia"], "t_last_good": raw["t_last_good"]},
    )
