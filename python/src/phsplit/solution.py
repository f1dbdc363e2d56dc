"""The results of a run: :class:`Solution` (the trajectory at the saved times) and
:class:`Ledger` (its energy balance). Data types of the bottom layer: they import the core,
the settings and the CF conventions only (``Solution.at`` calls the dense output the upper
layer provides, see :mod:`phsplit._provided`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from . import _core, _provided, cf
from .settings import settings_to_toml

#: The statistics of :meth:`Solution.motion_statistics`, in the order a dataset stores them.
MOTION_STATISTICS = ("mean", "std", "rms", "max", "significant")


def statistics_of(signals: dict) -> dict[str, dict[str, float]]:
    """Per named signal (a sequence of samples) the numbers of :data:`MOTION_STATISTICS`."""
    out = {}
    for name, sig in signals.items():
        sig = np.asarray(sig, dtype=float)
        std = float(np.std(sig))
        out[name] = {"mean": float(np.mean(sig)), "std": std, "rms": float(np.sqrt(np.mean(sig ** 2))),
                     "max": float(np.max(np.abs(sig))), "significant": 4.0 * std}
    return out


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
    #: The accounts of the controller's force (the core's accounts of the control role: its P, I
    #: and D parts, or what its thrusters deliver), in the ledger's order.
    controls: tuple[str, ...] = ()
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
    #: The components' own states at the saved states (a port-Hamiltonian subsystem's, in the
    #: vessel's layout: :meth:`Vessel.own_states`), or None for a vessel whose components keep
    #: none. Each is also in :attr:`outputs` under its name.
    own: np.ndarray | None = None

    def force(self, *accounts: str) -> np.ndarray:
        """Body-frame force (N, 3) of the named ledger accounts, summed (all when none given)."""
        return self._by_account(self.account_force, accounts)

    def moment(self, *accounts: str) -> np.ndarray:
        """Body-frame moment (N, 3) about the body origin of the named accounts, summed."""
        return self._by_account(self.account_moment, accounts)

    def _zero_vector(self) -> np.ndarray:
        return np.zeros((len(self.t), 3))

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
        return self.force(*self.ledger.controls) if self.ledger.controls else self._zero_vector()

    @property
    def control_moment(self) -> np.ndarray:
        """The controller's moment (P, I and D terms; with thrusters, what they deliver), body frame (N, 3), N m."""
        return self.moment(*self.ledger.controls) if self.ledger.controls else self._zero_vector()

    def at(self, times: Sequence[float] | np.ndarray) -> "Solution":
        """Dense output on request: the states at any ``times`` within the run, each computed by
        stepping from the last saved state at or before it with the run's step and a last,
        shorter step (as ``save_at`` does), so with the method's own order and no interpolation;
        for an adaptive run, by adaptive steps to the run's tolerance, ending on the time. One
        core call per time. The result's ledger is zero (states only)."""
        return _provided.get("dense_output")(self, times)

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
        phi_x), as the core takes it, followed by the components' own states (:attr:`own`) and,
        for a vessel with rate-limited thrusters, their memory (:attr:`actuators`), so that a run
        continued from it goes on as one run."""
        n = len(self.t)
        if isinstance(i, (bool, np.bool_)) or not isinstance(i, (int, np.integer)) or not -n <= i < n:
            raise _core.InvalidInputError(f"state: i must be a saved index, a whole number from {-n} to {n - 1} "
                                          f"(the run saved {n} states), got {i!r}")
        y = np.concatenate([self.p[i], self.m[i], self.Q[i].reshape(-1, order="F"), self.mu[i], self.x[i],
                            self.phi_th[i], self.phi_x[i]])
        tail = [a[i] for a in (self.own, self.actuators) if a is not None]
        return np.concatenate([y, *tail]) if tail else y

    def motion_statistics(self, after: float = 0.0) -> dict[str, dict[str, float]]:
        """Statistics of heave (``x[:, 2]``, m), roll and pitch (``euler``, rad) over the saved
        samples at ``t >= after`` (s; to leave out a start's transient): per DOF ``mean``,
        ``std`` (σ, about the mean), ``rms`` (about zero: upright, the calm waterline), ``max``
        (the largest ``|value|``) and ``significant`` = 4σ, the significant double amplitude
        (crest to trough, the analogue of the significant wave height Hs; half of it is the
        significant single amplitude). Sample statistics: the samples should be uniform in time
        (``save_every``, not ``save_at``)."""
        if isinstance(after, (bool, np.bool_)) or not isinstance(after, (int, float, np.integer, np.floating)):
            raise _core.InvalidInputError(f"after must be a time in seconds, got {after!r}")
        after = float(after)
        keep = self.t >= after
        if not np.isfinite(after) or keep.sum() < 2:
            raise _core.InvalidInputError(f"after must leave at least two saved samples (the run saved "
                                          f"{self.t[0]:g}-{self.t[-1]:g} s), got {after!r}")
        return statistics_of({"heave": self.x[keep, 2], "roll": self.euler[keep, 0], "pitch": self.euler[keep, 1]})

    def settings_toml(self) -> str:
        """The run's settings as a ``[simulation]`` TOML table (what a scenario file takes)."""
        return settings_to_toml(self.settings)

    def to_xarray(self):
        """The trajectory as a CF-1.8 ``xarray.Dataset``: every variable with ``units`` and
        ``long_name`` (and a ``standard_name`` where CF has one), the velocities in body and
        spatial frames, the forces and moments and the energy of every ledger account, and the
        provenance that reruns it (``phsplit rerun``): the vessel file, the settings, the
        initial state and the chunking of the run."""
        import xarray as xr

        coords = {
            "time": ("time", self.t, {"units": cf.TIME_UNITS, "calendar": "standard",
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
        nodes = _pipe_nodes(self.outputs)
        for name, (unit, long_name, values) in self.outputs.items():
            if name not in nodes["names"]:
                data[name] = var(("time",), values, unit, long_name)
        if nodes["names"]:
            # The dynamic pipe's free nodes as two arrays (time, pipe_node, axis), not a variable
            # per coordinate (docs/model.md §5.18).
            coords["pipe_node"] = ("pipe_node", np.arange(1, nodes["count"] + 1),
                                   {"long_name": "the dynamic pipe's free node, from the top"})
            anchor = _pipe_anchor(self.meta.get("provenance", {}).get("vessel_toml"))
            extra = {"anchor": anchor} if anchor is not None else {}
            data["pipe_node_position"] = var(("time", "pipe_node", "axis"), nodes["position"], "m",
                                             "the dynamic pipe's free nodes' positions, spatial frame (z up)", **extra)
            data["pipe_node_momentum"] = var(("time", "pipe_node", "axis"), nodes["momentum"], "kg m s-1",
                                             "the dynamic pipe's free nodes' momenta, spatial frame")
        prov = self.meta.get("provenance", {})
        if "initial_state" in prov:
            y0 = prov["initial_state"]
            tail = []
            if self.own is not None and np.ndim(self.own) == 2 and np.shape(self.own)[1]:
                tail.append(f"then the components' {np.shape(self.own)[1]} own states")
            if len(y0) > 27 + (np.shape(self.own)[1] if tail else 0):
                tail.append("then the rate-limited thrusters' memory: time, thrusts, angles in rad")
            data["initial_state"] = var(("state",), y0, "1",
                                      "initial state (p, m, Q column-major, mu, x, phi_theta, phi_x; "
                                      + "".join(t + "; " for t in tail) + "SI units)")
        if len(self.t) >= 2:
            # the motion statistics over every saved sample (motion_statistics; the CLI's file
            # holds the whole run's)
            st = self.motion_statistics()
            coords["statistic_name"] = ("statistic", np.array(MOTION_STATISTICS), {
                "long_name": "statistic over every saved sample (std: sigma; significant: 4 sigma)"})
            for k, unit in (("heave", "m"), ("roll", "rad"), ("pitch", "rad")):
                data[f"{k}_statistics"] = var(("statistic",), [st[k][n] for n in MOTION_STATISTICS], unit,
                                              f"{k}: mean, standard deviation, RMS about zero, largest magnitude, "
                                              f"significant double amplitude")
        ds = xr.Dataset(data, coords=coords)
        ds["time"].encoding["_FillValue"] = None  # CF 2.5.1: no fill value on a coordinate
        # Time is the record (unlimited) dimension, as in the CLI's files: appendable, and the
        # vector dimensions may then follow it (CF 2.4).
        ds.encoding["unlimited_dims"] = {"time"}
        ds.attrs.update(cf.global_attrs(
            "phsplit vessel simulation", "simulated",
            source=f"phsplit {_core.__version__} ({self.method}, h = {self.h:g} s), passivity-preserving splitting"))
        ds.attrs.update(
            {
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
                "phsplit_settings": self.settings_toml(),
            }
        )
        if "vessel_toml" in prov:
            ds.attrs["phsplit_vessel"] = prov["vessel_toml"]
        if "chunks" in prov:
            ds.attrs["phsplit_chunks"] = " ".join(str(int(c)) for c in prov["chunks"])
        ds.attrs["software"] = cf.software_versions()
        if "s2_solver" in self.meta:
            # How flow S2 was integrated: the linear flow asked for, or Gauss collocation where S2
            # has a forcing part (runner.SettingWarning).
            ds.attrs["s2_solver"] = str(self.meta["s2_solver"])
        if self.settings.get("tolerance") is not None:
            # Adaptive steps: the tolerance the core took and how the error control went
            # (docs/numerics.md).
            rtol, atol, _ = self.settings["tolerance"]
            ds.attrs["step_size_s"] = "adaptive"
            ds.attrs["first_step_s"] = self.h
            ds.attrs["rtol"], ds.attrs["atol"] = float(rtol), float(atol)
            ds.attrs["rejected_steps"] = int(self.meta.get("rejected", 0))
        if self.failure:
            ds.attrs["failure"] = self.failure
        return ds


def _pipe_nodes(outputs: dict) -> dict:
    """The dynamic pipe's free-node states among a run's outputs (``pipe_node{i}_{x,y,z}`` and
    ``pipe_node{i}_p{x,y,z}``), as arrays (time, node, 3), with the names they replace."""
    import re

    pat = re.compile(r"^pipe_node(\d+)_(p?)([xyz])$")
    found = {}
    for name in outputs:
        m = pat.match(name)
        if m:
            found[name] = (int(m.group(1)), m.group(2) == "p", "xyz".index(m.group(3)))
    if not found:
        return {"names": set()}
    n = max(i for i, _, _ in found.values())
    t = len(next(iter(outputs.values()))[2])
    pos, mom = np.full((t, n, 3), np.nan), np.full((t, n, 3), np.nan)
    for name, (i, is_p, a) in found.items():
        (mom if is_p else pos)[:, i - 1, a] = outputs[name][2]
    return {"names": set(found), "count": n, "position": pos, "momentum": mom}


def _pipe_anchor(vessel_toml) -> list[float] | None:
    """The dynamic pipe's anchor (m, spatial) from the run's vessel file."""
    if not vessel_toml:
        return None
    try:
        import tomllib

        p = tomllib.loads(vessel_toml)["pipe"]
        return [float(p["anchor"][0]), float(p["anchor"][1]), -float(p["water_depth"])]
    except (KeyError, ValueError, TypeError, IndexError):
        return None
