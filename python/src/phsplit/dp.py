"""What a DP engineer reads of a run: the position and heading footprint about the set point, the
thrusters' utilisation and time in saturation, and the worst single thruster failure of a
scenario, found by running each one (docs/how-to/dp-failures.md).

* :func:`footprint` summarises a :class:`~phsplit.Solution` of a vessel under DP control.
* :func:`single_failures` runs a vessel intact and with each thruster lost at a time
  (``thrusters.unit[i].lost_at``, docs/model.md §5.8), in parallel, and ranks the cases by their
  largest excursion after the failure; the CLI is ``phsplit failures``.

All numbers are over the saved states (``save_every`` decimates them): a peak between two saved
states is not seen, and the time in saturation counts saved intervals."""
from __future__ import annotations

import concurrent.futures as futures
import math
import os
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from . import _core
from .settings import Settings
from .vessel import Vessel
from ._arguments import checked

#: A thruster counts as saturated when the largest |thrust| over its limit reaches this.
SATURATED = 1.0 - 1e-9


def _reference(s, vessel: Vessel | None, reference: Sequence[float] | None) -> tuple[np.ndarray, np.ndarray]:
    """The set point's x, y and heading at the saved times: the moving set point's outputs, the
    given ``(x, y, heading)``, or the vessel's ``control`` table."""
    n = len(s.t)
    if "setpoint_x" in s.outputs and reference is None:
        o = s.outputs
        return np.column_stack([o["setpoint_x"][2], o["setpoint_y"][2]]), np.asarray(o["setpoint_heading"][2])
    if reference is None:
        if vessel is None:
            raise _core.InvalidInputError("footprint: give the vessel (its control.position_reference and "
                                          "euler_reference) or reference = (x, y, heading in rad)")
        c = vessel.to_dict().get("control")
        if c is None:
            raise _core.InvalidInputError("footprint: the vessel has no [control] table: give reference = (x, y, heading)")
        reference = (c["position_reference"][0], c["position_reference"][1], c["euler_reference"][2])
    bad = _core.InvalidInputError(f"footprint: reference must be 3 finite numbers (x m, y m, heading rad), "
                                  f"got {reference!r}")
    if isinstance(reference, (str, bytes, dict)):
        raise bad
    try:
        r = [float(v) for v in reference if not isinstance(v, (bool, np.bool_, str, bytes))]
    except (TypeError, ValueError):
        raise bad from None
    if len(r) != 3 or len(r) != len(list(reference)) or not all(math.isfinite(v) for v in r):
        raise bad
    if abs(r[2]) > 2 * math.pi:
        raise _core.InvalidInputError(f"footprint: reference heading must lie within ±2π rad (a larger value is "
                                      f"a heading in degrees), got {r[2]!r}")
    if max(abs(r[0]), abs(r[1])) > 1e9:
        raise _core.InvalidInputError(f"footprint: reference position must lie within 1e9 m of the origin, got {reference!r}")
    return np.tile(r[:2], (n, 1)), np.full(n, r[2])


@checked
def footprint(s, vessel: Vessel | None = None, reference: Sequence[float] | None = None,
              after: float = 0.0) -> dict[str, float]:
    """The footprint of the run ``s`` from time ``after`` (s) on: the horizontal distance from the
    set point (``max_excursion``, ``rms_excursion``, m; ``mean_offset_x``, ``mean_offset_y``, m,
    spatial), the heading's deviation (``max_heading_deviation``, ``rms_heading_deviation``,
    degrees, the short way round) and, with thrusters, their utilisation (the largest
    |thrust| over its limit: ``utilisation_mean``, ``utilisation_p95``, ``utilisation_max``) and
    the time they spent saturated (``time_saturated``, s, and ``fraction_saturated``)."""
    from .solution import Solution

    if not isinstance(s, Solution):
        raise _core.InvalidInputError(f"footprint: the run must be a phsplit.Solution (what phsplit.simulate "
                                      f"returns), got {type(s).__name__}")
    if vessel is not None and not isinstance(vessel, Vessel):
        raise _core.InvalidInputError(f"footprint: vessel must be a phsplit.Vessel, got {type(vessel).__name__}")
    if isinstance(after, bool) or not isinstance(after, (int, float)) or not math.isfinite(after):
        raise _core.InvalidInputError(f"footprint: after must be a finite time in s, got {after!r}")
    keep = np.asarray(s.t) >= after
    if keep.sum() < 2:
        raise _core.InvalidInputError(f"footprint: after = {after:g} s leaves fewer than two saved states "
                                      f"(the run ends at {s.t[-1]:g} s)")
    xy, psi = _reference(s, vessel, reference)
    d = s.x[keep, :2] - xy[keep]
    r = np.hypot(d[:, 0], d[:, 1])
    dpsi = np.degrees((s.euler[keep, 2] - psi[keep] + math.pi) % (2 * math.pi) - math.pi)
    out = {"max_excursion": float(r.max()), "rms_excursion": float(np.sqrt(np.mean(r ** 2))),
           "mean_offset_x": float(d[:, 0].mean()), "mean_offset_y": float(d[:, 1].mean()),
           "max_heading_deviation": float(np.abs(dpsi).max()),
           "rms_heading_deviation": float(np.sqrt(np.mean(dpsi ** 2)))}
    if "thrust_utilisation" in s.outputs:
        u = np.asarray(s.outputs["thrust_utilisation"][2])[keep]
        t = np.asarray(s.t)[keep]
        dt = np.diff(t)
        sat = (u[1:] >= SATURATED) & (u[:-1] >= SATURATED)
        span = float(t[-1] - t[0])
        out.update(utilisation_mean=float(u.mean()), utilisation_p95=float(np.percentile(u, 95)),
                   utilisation_max=float(u.max()), time_saturated=float(dt[sat].sum()),
                   fraction_saturated=float(dt[sat].sum() / span) if span > 0 else 0.0)
    return out


@dataclass
class FailureStudy:
    """The cases of :func:`single_failures`: ``rows`` (one dict per case: ``case``, ``lost``
    (the failed thruster's index, or None), ``mode`` (``"lost"``, ``"stuck"`` or None),
    ``status``, ``error`` and the :func:`footprint` after the
    failure) and ``worst``, the completed failure case with the largest excursion."""

    at: float
    rows: list[dict[str, Any]] = field(default_factory=list)

    @property
    def worst(self) -> dict[str, Any] | None:
        """The completed failure case with the largest excursion after the failure; between
        excursions within a millimetre, the one whose thrusters come closest to their limits
        (the least capacity left)."""
        failed = [r for r in self.rows if r["lost"] is not None and r["status"] == "completed"]
        return max(failed, key=lambda r: (round(r["max_excursion"], 3), r.get("utilisation_max", 0.0)), default=None)

    def table(self) -> str:
        """The cases as a Markdown table."""
        lines = ["| case | status | max excursion (m) | RMS (m) | max heading dev. (deg) | max utilisation | saturated (s) |",
                 "|---|---|---|---|---|---|---|"]
        for r in self.rows:
            if r["status"] != "completed":
                lines.append(f"| {r['case']} | {r['status']}: {r['error']} | | | | | |")
                continue
            lines.append(f"| {r['case']} | completed | {r['max_excursion']:.3f} | {r['rms_excursion']:.3f} | "
                         f"{r['max_heading_deviation']:.3f} | {r.get('utilisation_max', float('nan')):.3f} | "
                         f"{r.get('time_saturated', 0.0):.1f} |")
        return "\n".join(lines)


def check_failure_study(vessel: Vessel, settings: Settings, at: float, at_name: str = "single_failures: at") -> list:
    """What :func:`single_failures` refuses, before anything runs: its thruster units.
    ``at_name``: how the messages name ``at`` (the CLI's ``--at``)."""
    if not isinstance(vessel, Vessel):
        raise _core.InvalidInputError(f"single_failures: vessel must be a phsplit.Vessel, got {type(vessel).__name__}")
    if not isinstance(settings, Settings):
        raise _core.InvalidInputError(f"single_failures: settings must be a phsplit.Settings, got {type(settings).__name__}")
    d = vessel.to_dict()
    units = d.get("thrusters", {}).get("unit")
    if not units:
        raise _core.InvalidInputError("single_failures: the vessel has no [thrusters] to lose")
    t0, t1 = settings.t_span
    if isinstance(at, bool) or not isinstance(at, (int, float)) or not (t0 <= at < t1):
        raise _core.InvalidInputError(f"{at_name} must be a time within the run's t_span [{t0:g}, {t1:g}) s, got {at!r}")
    already = [(i, k) for i, u in enumerate(units) for k in ("lost_at", "stuck_at") if k in u]
    if already:
        i, k = already[0]
        raise _core.InvalidInputError(
            f"single_failures: thrusters.unit[{i}].{k} = {units[i][k]:g} s is set; "
            f"the study fails each thruster in turn at its own time (at): remove {k} from the vessel")
    # the footprint after the failure needs two saved states from `at` on
    h, every = settings.h, settings.save_every
    n_after = math.floor((t1 - at) / (h * every) + 1e-9)
    if n_after < 1:
        raise _core.InvalidInputError(
            f"{at_name} = {at:g} s leaves fewer than two saved states before the run ends at {t1:g} s "
            f"(a state saved every {h * every:g} s): take an earlier time")

    return units


#: Most threads of a failure study (as of ``simulate_many``).
MAX_THREADS = 512

#: How :func:`single_failures` fails each thruster: the key it sets, and how a case is named.
FAILURE_MODES = {"lost": "lost_at", "stuck": "stuck_at"}


@checked
def single_failures(vessel: Vessel, settings: Settings, at: float, max_workers: int | None = None,
                    mode: str = "lost") -> FailureStudy:
    """Run ``vessel`` with ``settings`` intact and with each of its thrusters failed at ``at`` (s) in
    turn, on a thread pool, and take each case's :func:`footprint` from ``at`` on. ``mode``:
    ``"lost"`` (``thrusters.unit[i].lost_at``: it delivers nothing), ``"stuck"``
    (``stuck_at``: it fails as set, keeping its thrust and angle) or ``"both"`` (each thruster
    each way). A vessel that already fails one is refused. A case the allocation cannot take
    (the thrusters left cannot produce surge, sway and yaw) or whose run fails is listed with
    its error."""
    modes = list(FAILURE_MODES) if mode == "both" else [mode]
    if not isinstance(mode, str) or any(m not in FAILURE_MODES for m in modes):
        raise _core.InvalidInputError(f"single_failures: mode must be one of lost, stuck, both, got {mode!r}")
    units = check_failure_study(vessel, settings, at)
    if max_workers is not None and (isinstance(max_workers, bool) or not isinstance(max_workers, (int, np.integer))
                                    or not 1 <= max_workers <= MAX_THREADS):
        raise _core.InvalidInputError(f"single_failures: max_workers must be a whole number from 1 to {MAX_THREADS} "
                                      f"(or None: one per core), got {max_workers!r}")

    def one(failure):
        lost, how = failure
        case = "intact" if lost is None else f"thruster {lost} {how}"
        row = {"case": case, "lost": lost, "mode": how, "status": "invalid", "error": ""}
        dd = vessel.to_dict()
        if lost is not None:
            dd["thrusters"]["unit"][lost][FAILURE_MODES[how]] = float(at)
        try:
            v = Vessel.from_dict(dd)
        except (_core.InvalidInputError, _core.ScenarioParseError) as e:
            row["error"] = str(e)
            return row
        s = settings.run(v)
        row["status"] = s.status
        row["error"] = s.failure or ""
        if s.status == "completed":
            row.update(footprint(s, vessel=v, after=at))
        return row

    cases = [(None, None)] + [(i, m) for m in modes for i in range(len(units))]
    with futures.ThreadPoolExecutor(max_workers=max_workers or os.cpu_count() or 2) as pool:
        rows = list(pool.map(one, cases))
    return FailureStudy(at=float(at), rows=rows)
