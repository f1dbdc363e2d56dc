"""Many simulations: in-process batches and parameter sweeps on Dask.

* :func:`simulate_many` runs a list of cases on a thread pool. The core releases the GIL, so the
  cases run in parallel in one process. It returns one ``xarray.Dataset`` with a ``case``
  dimension and the varied parameters as coordinates.
* :func:`run_sweep` (CLI: ``phsplit sweep``) expands a grid or a random sample of parameters into
  cases and runs them on ``dask.distributed``: a ``LocalCluster`` bound to 127.0.0.1 started for
  the run, or an existing cluster given by address.
  - Each finished case is written to ``STORE/cases/<id>.nc`` (temporary file, then rename), so
    a case is stored once, whole, or not at all: by the workers of a LocalCluster, by the client
    for a cluster given by address. A large sweep (16 cases or more a worker) runs its cases in
    tasks of up to 32 and writes each task's cases as one file, ``STORE/cases/batch_<digest>.nc``,
    stacked along ``case`` (a netCDF4 file costs about 0.5 ms a variable to write, twice the
    integration of a case in one file of its own); :func:`phsplit.open_sweep` reads both.
  - A rerun on the same store computes only the missing cases.
  - A worker that dies loses only its running tasks (a case, or a batch), which Dask reschedules.
  - A case that fails (bad parameters, divergence) is stored with its error and does not stop
    the others.
  - A case whose task fails for a reason outside the case (a worker killed again and again:
    Dask's ``KilledWorker``) is listed in the summary with status ``error`` but not stored, so
    the next run of the sweep computes it.

A *case* is a mapping of parameter paths to values, applied to a base vessel: ``vessel.mass``,
``control.kp_rotational[2]``, ``initial.euler[0]``, ``thrusters.unit[0].max_thrust``, ... (the
sections and keys of a vessel file).
"""
from __future__ import annotations

import concurrent.futures as futures
import dataclasses
import difflib
import hashlib
import itertools
import json
import math
import os
import re
import time
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core, cf
from . import scenario as scn
from .cluster import (CONNECT_TIMEOUT, MAX_WORKERS, check_cluster,  # noqa: F401 - part of this module's API
                      collecting_warnings, say_warnings)
from .settings import Settings, settings_to_toml
from .sweepstore import (_coord_name, _stackable, _summary_row, _write_batch, _write_case,
                         done_cases, remove_temporaries, store_index, write_summary, write_sweep_file)
from .vessel import Vessel
from ._arguments import checked

_PATH = re.compile(r"^([a-z_]+)((?:\.[a-z_]+|\[[0-9]+\])+)$")
_SEGMENT = re.compile(r"\.([a-z_]+)|\[([0-9]+)\]")
#: Matrices that are symmetric by definition: an off-diagonal entry sets its mirror too.
_SYMMETRIC = {("vessel", "added_mass"), ("vessel", "damping_matrix")}
_SHAPES = ("a parameter path is 'table.name', 'table.name[i]', 'table.name[i][j]' (a matrix entry) or "
           "'table.list[i].name' (a table of a list, like thrusters.unit[0].max_thrust)")


_ADAPTIVE_REFUSED = ("the cases of {what} share one time grid (dims case, time), which adaptive steps (rtol, atol) "
                     "do not give: drop rtol and atol for {what}, or run the cases one by one with phsplit.simulate")


def _resolve(d: dict, key: str) -> list[str | int]:
    """Check a parameter path against a vessel's dict: the keys and indices that lead to its
    number (the last key of a table in a list may be new: the vessel file's reader checks it)."""
    if not isinstance(key, str):
        raise _core.InvalidInputError(f"{_SHAPES}, got {key!r}")
    m = _PATH.match(key)
    segs: list[str | int] = []
    if m:
        segs = [m.group(1)] + [g1 if g1 else int(g2) for g1, g2 in _SEGMENT.findall(m.group(2))]
    # A key of a table the vessel has may be absent from its dict (left at its default): the
    # vessel file's reader checks the name, as for a key of a table in a list.
    absent_ok = len(segs) == 2 and isinstance(d.get(segs[0]), dict) and bool(d[segs[0]])
    if not m or not isinstance(segs[1], str) or not isinstance(d.get(segs[0]), dict) or (
            segs[1] not in d[segs[0]] and not absent_ok):
        valid = sorted(f"{s}.{k}" for s in d if isinstance(d[s], dict) for k in d[s])
        raise _core.InvalidInputError(f"unknown parameter {key!r}; {_SHAPES}, one of: {', '.join(valid)}")
    cur: object = d
    for n, seg in enumerate(segs):
        where = segs[0] + "".join(f".{x}" if isinstance(x, str) else f"[{x}]" for x in segs[1:n])
        if isinstance(seg, int):
            if not isinstance(cur, (list, tuple)):
                raise _core.InvalidInputError(f"parameter {key!r}: {where} is not a list; give no index there")
            if seg >= len(cur):
                raise _core.InvalidInputError(f"parameter {key!r}: index {seg} out of range (0..{len(cur) - 1})")
            cur = cur[seg]
        else:
            if not isinstance(cur, dict):
                what = ("a list: give an index there" if isinstance(cur, (list, tuple))
                        else "a number: end the path there")
                raise _core.InvalidInputError(f"parameter {key!r}: {where} is {what}")
            new_key = seg not in cur and n == len(segs) - 1 and (
                (n >= 3 and isinstance(segs[n - 1], int)) or (n == 1 and absent_ok))
            if seg not in cur and not new_key:
                raise _core.InvalidInputError(f"unknown parameter {key!r}: {where} has no {seg!r}; it has "
                                              f"{', '.join(sorted(cur))}")
            cur = cur.get(seg, 0.0)
    if isinstance(cur, (list, tuple)):
        # name the list the path's last name gives (a matrix needs both its indices)
        k = max(n for n, x in enumerate(segs) if isinstance(x, str)) + 1
        whole = d
        for seg in segs[:k]:
            whole = whole[seg]
        name = segs[0] + "".join(f".{x}" if isinstance(x, str) else f"[{x}]" for x in segs[1:k])
        if all(isinstance(r, dict) for r in whole):
            example = next((n for n, v in (whole[0] if whole else {}).items()
                            if isinstance(v, (int, float)) and not isinstance(v, bool)), "name")
            shape = f"a list of {len(whole)} tables: give an index and a name, e.g. {name}[0].{example}"
        elif bool(whole) and all(isinstance(r, (list, tuple)) for r in whole):
            shape = f"a {len(whole)}-row matrix: give two indices, e.g. {name}[0][0]"
        else:
            shape = f"a {len(whole)}-vector: give one index, e.g. {name}[0]"
        raise _core.InvalidInputError(f"parameter {key!r}: {name} is {shape}")
    if isinstance(cur, dict):
        raise _core.InvalidInputError(f"parameter {key!r}: {key} is a table: name one of its numbers "
                                      f"({', '.join(sorted(cur))})")
    return segs


@checked
def with_parameters(base: Vessel, params: Mapping[str, float]) -> Vessel:
    """``base`` with parameters replaced: keys ``table.name``, ``table.name[i]`` or, for a
    matrix, ``table.name[i][j]`` of the vessel file (``vessel``, ``control``, ``initial``,
    ``external``, …), and ``table.list[i].name`` (``[i]``) for a table of a list
    (``thrusters.unit[0].max_thrust``, ``thrusters.unit[2].turn_rate``). In the symmetric
    matrices ``vessel.added_mass`` and ``vessel.damping_matrix`` an off-diagonal entry sets its
    mirror ``[j][i]`` too. Unknown paths and bad values raise InvalidInputError."""
    if not isinstance(base, Vessel):
        raise _core.InvalidInputError(f"base must be a phsplit.Vessel, got {type(base).__name__}")
    if not isinstance(params, Mapping):
        raise _core.InvalidInputError(f"parameters must be a mapping of paths to numbers, got {type(params).__name__}")
    d = base.to_dict()
    mirrored: dict[tuple, tuple[str, float]] = {}  # symmetric entries set, by (table, name, i, j)
    for key, value in params.items():
        segs = _resolve(d, key)
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
            raise _core.InvalidInputError(f"parameter {key!r} must be a number, got {value!r}")
        parent = d
        for seg in segs[:-1]:
            parent = parent[seg]
        parent[segs[-1]] = float(value)
        if tuple(segs[:2]) in _SYMMETRIC and len(segs) == 4:
            entry = (segs[0], segs[1], min(segs[2:]), max(segs[2:]))
            if entry in mirrored and mirrored[entry][1] != float(value):
                raise _core.InvalidInputError(
                    f"parameters {mirrored[entry][0]!r} and {key!r} set the same entry of the symmetric matrix "
                    f"{segs[0]}.{segs[1]} to different values ({mirrored[entry][1]} and {float(value)})")
            mirrored[entry] = (key, float(value))
            d[segs[0]][segs[1]][segs[3]][segs[2]] = float(value)
    try:
        return Vessel.from_dict(d, f"{base.source} with {dict(params)}")
    except _core.ScenarioParseError as e:
        absent = [k for k in params if isinstance(k, str) and "." in k and k.split(".")[1].split("[")[0]
                  not in base.to_dict().get(k.split(".")[0], {})]
        if absent and str(e).startswith("unknown field"):
            raise _core.InvalidInputError(f"unknown parameter {absent[0]!r}: {e}") from None
        raise


def _number_or_nan(v) -> float:
    """A case's parameter value for its coordinate (a refused non-number shows as NaN)."""
    if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
        return float("nan")
    return float(v)


def summarize(vessel: Vessel, sol) -> dict[str, Any]:
    """Per-case summary: final distances to the set point (the yaw error wrapped), energy, peak
    control effort (the norms of the controller's force and moment, over every step when the run
    kept its running maxima, as sweeps and ``simulate_many`` do; else over the saved states),
    status."""
    c = vessel.to_dict()["control"]
    xr_, er = np.asarray(c["position_reference"]), np.asarray(c["euler_reference"])
    peak_t = peak_r = 0.0
    rm = sol.meta.get("running_max", {})
    if "control_force" in rm:  # over every step (the core's running maxima)
        peak_t, peak_r = float(rm["control_force"][0]), float(rm["control_moment"][0])
    elif len(sol.t):  # over the saved states only
        peak_t = float(np.max(np.linalg.norm(sol.control_force, axis=1)))
        peak_r = float(np.max(np.linalg.norm(sol.control_moment, axis=1)))
    bound = 100.0 * (sol.energy[0] + max(0.0, float(np.sum(sol.ledger.supplied))))
    diverged = sol.status != "completed" or not np.all(np.isfinite(sol.energy)) or float(np.max(sol.energy)) > bound
    return {
        "position_error_m": float(np.linalg.norm(sol.x[-1] - xr_)),
        # wrapped to [0, pi]: a heading of -3.1 rad is 0.08 rad from a set point of +3.1 rad
        "yaw_error_rad": float(abs(math.remainder(float(sol.euler[-1, 2] - er[2]), 2.0 * math.pi))),
        "energy_final_J": float(sol.energy[-1]),
        "energy_max_J": float(np.max(sol.energy)),
        "peak_force_N": peak_t,
        "peak_moment_Nm": peak_r,
        "diverged": bool(diverged),
        "status": sol.status,
    }


def check_max_workers(where: str, max_workers: Any) -> None:
    """A thread count: ``None`` (one per core) or a whole number from 1 to :data:`MAX_WORKERS`."""
    if max_workers is not None and (isinstance(max_workers, bool) or not isinstance(max_workers, (int, np.integer))
                                    or not 1 <= max_workers <= MAX_WORKERS):
        raise _core.InvalidInputError(f"{where}: max_workers must be a whole number from 1 to {MAX_WORKERS} (or "
                                      f"None: one per core), got {max_workers!r}")


@checked
def simulate_many(cases: Sequence[Mapping[str, float]], base: Vessel | None = None,
                  settings: Settings | None = None, max_workers: int | None = None, **kw):
    """Run every case (a mapping of parameter paths to values) on a thread pool; the core releases
    the GIL, so they run in parallel. Returns an ``xarray.Dataset`` with dims ``case`` and
    ``time`` (all cases share the time grid), the varied parameters as coordinates, and the
    summary of each case. A case whose parameters are invalid gets ``status = "invalid"`` and
    NaN series; it does not stop the others. Settings may be given as keyword arguments."""
    import xarray as xr

    if base is not None and not isinstance(base, Vessel):
        raise _core.InvalidInputError(f"base must be a phsplit.Vessel (e.g. phsplit.Vessel.preset('osv')) or None for "
                                      f"the paper's vessel, got {type(base).__name__} {base!r}")
    base = base or Vessel.paper()
    per_run = [k for k in ("events", "save_at", "initial", "running_max", "progress") if k in kw]
    if per_run:
        raise _core.InvalidInputError(
            f"simulate_many does not take {per_run[0]}: its cases share one time grid and one summary; "
            f"run phsplit.simulate(with_parameters(base, case), {per_run[0]}=...) for each case instead")
    fields = [f.name for f in dataclasses.fields(Settings)]
    unknown = [k for k in kw if k not in fields]
    if unknown:
        close = difflib.get_close_matches(unknown[0], fields, n=1)
        hint = f" (did you mean {close[0]}?)" if close else ""
        raise _core.InvalidInputError(f"simulate_many() has no argument {unknown[0]!r}{hint}: it takes cases, base, "
                                      f"settings, max_workers and the settings {', '.join(fields)}")
    if settings is not None and kw:
        raise _core.InvalidInputError(f"settings=... gives every setting, so {', '.join(kw)} would not be used: give "
                                      f"them in the Settings, or leave settings out")
    settings = settings or Settings(**kw)
    if not isinstance(settings, Settings):
        raise _core.InvalidInputError(f"settings must be a phsplit.Settings, got {type(settings).__name__}")
    check_max_workers("simulate_many", max_workers)
    if settings.adaptive:
        raise _core.InvalidInputError(_ADAPTIVE_REFUSED.format(what="simulate_many"))
    if isinstance(cases, (str, bytes, Mapping)) or not isinstance(cases, Sequence) or not all(
            isinstance(c, Mapping) for c in cases):
        raise _core.InvalidInputError("cases must be a sequence of mappings {parameter path: value}, "
                                      f"got {type(cases).__name__}")
    if not cases:
        raise _core.InvalidInputError("cases is empty: give at least one mapping {parameter path: value} "
                                      "({} runs the base vessel as it is)")
    keys = sorted({k for c in cases for k in c})

    def one(case):
        try:
            v = with_parameters(base, case)
        except (_core.InvalidInputError, _core.ScenarioParseError) as e:
            return None, {"status": "invalid", "error": str(e)}
        sol = settings.run(v, running_max=True)  # peaks over every step
        return sol, {**summarize(v, sol), "error": sol.failure or ""}

    with futures.ThreadPoolExecutor(max_workers=max_workers or os.cpu_count() or 2) as pool:
        results = list(pool.map(one, cases))
    t = next((s.t for s, _ in results if s is not None and s.status == "completed"), None)
    if t is None:
        t = next((s.t for s, _ in results if s is not None), np.zeros(1))
    n, nt = len(cases), len(t)

    def stack(attr, shape):
        out = np.full((n,) + shape, np.nan)
        for i, (s, _) in enumerate(results):
            if s is not None:
                a = getattr(s, attr)
                out[i, : len(a)] = a[:nt]
        return out

    ds = xr.Dataset(
        {
            "position": (("case", "time", "axis"), stack("x", (nt, 3)), {"units": "m"}),
            "euler": (("case", "time", "angle"), stack("euler", (nt, 3)), {"units": "rad"}),
            "energy": (("case", "time"), stack("energy", (nt,)), {"units": "J"}),
        },
        coords={"case": np.arange(n), "time": ("time", t, {"units": "s"}), "axis": ["x", "y", "z"],
                "angle": ["roll", "pitch", "yaw"]},
        attrs={"method": settings.method, "step_size_s": settings.h, "phsplit_version": _core.__version__,
               "phsplit_settings": settings_to_toml(settings.checked()),
               "phsplit_vessel": base.to_toml()},
    )
    for k in keys:
        ds = ds.assign_coords({_coord_name(k): ("case", np.array([_number_or_nan(c.get(k, np.nan)) for c in cases], float),
                                                {"parameter": k})})
    summary_keys = ["position_error_m", "yaw_error_rad", "energy_final_J", "energy_max_J", "peak_force_N",
                    "peak_moment_Nm"]
    for k in summary_keys:
        ds[k] = ("case", np.array([r.get(k, np.nan) for _, r in results], float))
    ds["diverged"] = ("case", np.array([bool(r.get("diverged", True)) for _, r in results]))
    ds["status"] = ("case", np.array([r["status"] for _, r in results], dtype=object))
    ds["error"] = ("case", np.array([r.get("error", "") for _, r in results], dtype=object))
    ds["time"].attrs.update({"units": cf.TIME_UNITS, "standard_name": "time", "axis": "T",
                             "long_name": "simulated time (t = 0 at the nominal epoch)"})
    return cf.finish(ds, "phsplit simulate_many: one run per case", "simulate_many")


# ------------------------------------------------------------------------------------------
# sweeps on Dask


@dataclass
class Sweep:
    settings: Settings
    base: Vessel
    cases: list[dict[str, float]] = field(default_factory=list)
    name: str = "sweep"

    def identity(self) -> dict[str, Any]:
        """Everything besides a case's own parameters that determines its result: the run
        settings as the core reads them (aliases resolved), the base vessel with every
        component's parameters (environment and loads included) and the phsplit version."""
        settings = dict(self.settings.checked())
        settings.pop("name", None)  # names the output, changes no number
        return {"phsplit": _core.__version__, "settings": settings, "vessel": self.base.to_dict()}

    def case_id(self, i: int) -> str:
        """``case_<index>_<digest>``, the digest over the case's parameters and :meth:`identity`:
        a rerun with any other setting, vessel or version gets other ids, so the store never
        hands back a result computed under different conditions."""
        key = json.dumps({"case": self.cases[i], **self.identity()}, sort_keys=True, default=repr)
        digest = hashlib.sha256(key.encode()).hexdigest()[:16]
        return f"case_{i:05d}_{digest}"


#: Most cases of one sweep (a grid's product, or random samples).
MAX_CASES = 1_000_000

SWEEP_KEYS = {"mode": "'grid' or 'random'", "samples": "number of random cases", "seed": "random seed",
              "parameters": "table of parameter paths"}


@checked
def load_sweep(path: str) -> Sweep:
    """Read a sweep file: a scenario's ``[simulation]`` (and optional vessel) plus ``[sweep]``.

    ``mode = "grid"``: every parameter is a list of values; the cases are their product.
    ``mode = "random"``: every parameter is ``{low = ., high = .}`` (uniform) or a list (choice);
    ``samples`` cases drawn with ``seed``."""
    import difflib

    if not isinstance(path, (str, os.PathLike)):
        raise _core.InvalidInputError(f"the sweep file must be a path, got {type(path).__name__}")
    path = os.fspath(path)
    if os.path.isdir(path):
        raise _core.InvalidInputError(f"sweep file {path!r} is a folder, not a TOML file")
    data = scn._read_toml(path, "sweep file")
    sw = data.pop("sweep", None)
    if not isinstance(sw, dict):
        raise _core.ScenarioParseError(f"{path}: a sweep file needs a [sweep] table with [sweep.parameters]")
    for k in sw:
        if k not in SWEEP_KEYS:
            near = difflib.get_close_matches(k, list(SWEEP_KEYS), n=1)
            raise _core.ScenarioParseError(f"{path}: unknown key {k!r} in [sweep]"
                                           + (f"; did you mean {near[0]!r}?" if near else "")
                                           + f" (allowed: {', '.join(SWEEP_KEYS)})")
    # the rest is a scenario
    sc = scn.from_dict(data, path)
    settings = sc.settings
    if settings.adaptive:
        raise _core.ScenarioParseError(f"{path}: " + _ADAPTIVE_REFUSED.format(what="a sweep"))
    params = sw.get("parameters", {})
    if not isinstance(params, dict) or not params:
        raise _core.ScenarioParseError(f"{path}: [sweep.parameters] must list at least one parameter")
    mode = sw.get("mode", "grid")
    if mode not in ("grid", "random"):
        raise _core.ScenarioParseError(f"{path}: sweep.mode must be 'grid' or 'random', got {mode!r}")
    if mode == "grid":
        for k in ("samples", "seed"):
            if k in sw:
                raise _core.ScenarioParseError(f"{path}: sweep.{k} goes with mode = \"random\"; a grid sweep's cases "
                                               "are every combination of the lists")
    keys = list(params)
    d0 = sc.vessel.to_dict()
    for k in keys:
        _resolve(d0, k)  # the paths are checked now; the values case by case
        spec = params[k]
        if isinstance(spec, dict) and set(spec) != {"low", "high"}:
            raise _core.ScenarioParseError(f"{path}: sweep.parameters.{k} must be a list of values or "
                                           f"{{low = ..., high = ...}}, got the keys {sorted(spec)}")
        values = list(spec.values()) if isinstance(spec, dict) else spec if isinstance(spec, list) else [spec]
        bad = [v for v in values if isinstance(v, bool) or not isinstance(v, (int, float))]
        if bad:
            raise _core.ScenarioParseError(f"{path}: sweep.parameters.{k} must hold numbers, got {bad[0]!r}")
        bad = [v for v in values if not math.isfinite(v)]
        if bad:
            raise _core.InvalidInputError(f"{path}: sweep.parameters.{k} must hold finite numbers, got {bad[0]!r}")
        if isinstance(spec, dict) and not spec["low"] <= spec["high"]:
            raise _core.InvalidInputError(f"{path}: sweep.parameters.{k} must have low <= high, got low = "
                                          f"{spec['low']!r}, high = {spec['high']!r}")
        if len(values) > MAX_CASES:
            raise _core.InvalidInputError(f"{path}: sweep.parameters.{k} lists {len(values)} values; at most "
                                          f"{MAX_CASES}")
        if isinstance(spec, list) and len(set(map(float, values))) != len(values):
            twice = next(v for i, v in enumerate(values) if float(v) in map(float, values[:i]))
            raise _core.InvalidInputError(f"{path}: sweep.parameters.{k} lists {twice!r} twice: each case once")
        cur = d0
        for seg in _resolve(d0, k):
            cur = cur[seg] if isinstance(cur, list) or seg in cur else 0.0
        if isinstance(cur, (bool, str)) or not isinstance(cur, (int, float)):
            raise _core.InvalidInputError(f"{path}: sweep.parameters.{k}: {k} is {cur!r}, not a number; only "
                                          "numbers can be swept")
        # each value on its own, with the rest of the vessel as it is: a value the vessel refuses
        # is refused here, before anything is written or started
        for v in sorted(set(map(float, values))):
            try:
                with_parameters(sc.vessel, {k: v})
            except (_core.InvalidInputError, _core.ScenarioParseError) as e:
                raise _core.InvalidInputError(f"{path}: sweep.parameters.{k} = {v:g}: {e}") from None
    if mode == "grid":
        n_grid = math.prod(len(params[k]) if isinstance(params[k], list) else 1 for k in keys)
        if n_grid > MAX_CASES:
            raise _core.InvalidInputError(f"{path}: the grid has {n_grid} cases; at most {MAX_CASES} "
                                          "(split the sweep, or sample it: mode = \"random\")")
        for k in keys:
            if not isinstance(params[k], list) or not params[k]:
                raise _core.ScenarioParseError(f"{path}: in grid mode, sweep.parameters.{k} must be a list of values")
        cases = [dict(zip(keys, map(float, combo))) for combo in itertools.product(*(params[k] for k in keys))]
    elif mode == "random":
        n = sw.get("samples")
        if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_CASES:
            raise _core.ScenarioParseError(f"{path}: random mode needs sweep.samples, an integer from 1 to "
                                           f"{MAX_CASES}, got {n!r}")
        seed = sw.get("seed", 0)
        if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**63:
            raise _core.ScenarioParseError(f"{path}: sweep.seed must be an integer from 0 to 2^63 - 1, got {seed!r}")
        rng = np.random.default_rng(seed)
        cases = [{} for _ in range(n)]
        for k in keys:
            spec = params[k]
            if isinstance(spec, dict) and set(spec) == {"low", "high"}:
                vals = rng.uniform(float(spec["low"]), float(spec["high"]), size=n)
            elif isinstance(spec, list) and spec:
                vals = rng.choice(np.asarray(spec, float), size=n)
            else:
                raise _core.ScenarioParseError(
                    f"{path}: sweep.parameters.{k} must be {{low = ..., high = ...}} or a list in random mode")
            for c, v in zip(cases, vals):
                c[k] = float(v)
    return Sweep(settings=settings, base=sc.vessel, cases=cases,
                 name=os.path.splitext(os.path.basename(path))[0])


def _run_case(base_tables: dict, settings: Settings, case: dict, store: str | None = None,
              cid: str | None = None) -> dict:
    """Run one case (on a Dask worker). Returns plain data: arrays and the summary, or the error.
    With ``store`` (a worker that shares the client's file system: a LocalCluster), the worker
    writes the case's file itself and returns only its summary row (``{"row": ...}``)."""
    base = Vessel.from_dict(base_tables)
    try:
        v = with_parameters(base, case)
    except (_core.InvalidInputError, _core.ScenarioParseError) as e:
        result = {"status": "invalid", "error": str(e), "case": case}
    else:
        sol = settings.run(v, running_max=True)  # peaks over every step
        result = {"status": sol.status, "error": sol.failure or "", "case": case, "summary": summarize(v, sol),
                  "dataset": sol.to_xarray()}
    if store is not None:
        return {"row": _write_case(store, cid, result)}
    return result


#: Most cases in one task and one file of a sweep store (a *batch*; :func:`_batch_size`).
MAX_BATCH = 32


#: Most bytes of saved results in one batch (about 640 bytes a saved row of a case).
MAX_BATCH_BYTES = 64 * 2**20


def _batch_size(n: int, workers: int, rows: int = 1) -> int:
    """Cases per task for ``n`` cases on ``workers`` workers, each saving ``rows`` rows: one (a
    file per case) below 16 cases a worker; beyond, about 8 tasks a worker, at most
    :data:`MAX_BATCH` cases and :data:`MAX_BATCH_BYTES` of results each (a batch is held in a
    worker's memory until written; long runs saved densely stay one case a file). A netCDF4 file
    costs about 0.5 ms per variable to write whatever its length (HDF5's object headers; 17 ms
    for a case's 29 variables against 9 ms to integrate it), so a large sweep writes its cases
    stacked along ``case``, and loses at most one batch a worker if a worker dies."""
    by_size = MAX_BATCH_BYTES // (640 * max(1, rows))
    return max(1, min(MAX_BATCH, by_size, n // (8 * max(1, workers))))


def _saved_rows(settings: Settings) -> int:
    """How many rows a case of ``settings`` saves (an upper bound)."""
    t0, t1 = settings.t_span
    steps = math.ceil((t1 - t0) / settings.h) if settings.h > 0 else 1
    return steps // max(1, int(settings.save_every)) + 2


def _run_cases(base_tables: dict, settings: Settings, cases: list[dict], store: str | None = None,
               cids: list[str] | None = None) -> list[dict]:
    """Run one task's cases (on a Dask worker): one case as :func:`_run_case`; several, each by
    :func:`_run_case`, and with ``store`` (a LocalCluster's worker) written as one batch file, of
    which only the summary rows come back."""
    cids = cids or [None] * len(cases)
    if len(cases) == 1:
        return [_run_case(base_tables, settings, cases[0], store, cids[0])]
    results = [_run_case(base_tables, settings, c, None, cid) for c, cid in zip(cases, cids)]
    if store is not None:
        if not _stackable(results):
            return [{"row": _write_case(store, cid, r)} for cid, r in zip(cids, results)]
        return [{"row": r} for r in _write_batch(store, cids, results)]
    return results


@checked
def run_sweep(sweep: Sweep, store: str, scheduler: str | None = None, n_workers: int | None = None,
              progress: bool = True, retries: int = 3) -> dict[str, Any]:
    """Run the missing cases of ``sweep`` on Dask and store them; returns counts and the summary
    table path. The cluster arguments are checked (:func:`check_cluster`) before the store is
    touched."""
    from dask.distributed import Client, LocalCluster, as_completed
    from tqdm import tqdm

    if not isinstance(sweep, Sweep):
        raise _core.InvalidInputError(f"sweep must be a phsplit.batch.Sweep, got {type(sweep).__name__}")
    check_cluster(scheduler, n_workers)
    if isinstance(retries, bool) or not isinstance(retries, (int, np.integer)) or not 0 <= retries <= 100:
        raise _core.InvalidInputError(f"retries must be a whole number from 0 to 100 (how often a lost case is tried "
                                      f"again), got {retries!r}")
    for name, flag in (("progress", progress),):
        if not isinstance(flag, (bool, np.bool_)):
            raise _core.InvalidInputError(f"{name} must be True or False, got {flag!r}")
    if not isinstance(store, (str, os.PathLike)):
        raise _core.InvalidInputError(f"store must be a folder's path, got {type(store).__name__}")
    if os.path.exists(store) and not os.path.isdir(store):
        raise _core.InvalidInputError(f"the store {store!r} is a file, not a folder")
    ids = [sweep.case_id(i) for i in range(len(sweep.cases))]
    have = done_cases(store)  # cases of other settings stay in the store under their own ids, unused
    todo = [i for i, cid in enumerate(ids) if cid not in have]
    workers = n_workers or os.cpu_count() or 2
    cluster = client = None
    if todo and scheduler:  # connected before the store is touched: an address that fails writes nothing
        try:
            client = Client(scheduler, set_as_default=False, timeout=CONNECT_TIMEOUT + 2.0)
        except Exception as e:  # noqa: BLE001 - whatever the connection raised, one line
            raise _core.InvalidInputError(f"cannot connect to the scheduler {scheduler!r}: "
                                          f"{type(e).__name__}: {str(e)[:200]}") from None
    try:
        os.makedirs(os.path.join(store, "cases"), exist_ok=True)
        remove_temporaries(store)  # left by a client that was killed mid-write
        write_sweep_file(store, {"name": sweep.name, **sweep.identity(), "cases": dict(zip(ids, sweep.cases))})
    except BaseException:
        if client is not None:
            client.close()
        raise
    rows: dict[str, dict] = {}  # the summary rows of the cases computed now
    said: dict[tuple[type, str], int] = {}  # the cases' warnings, said once each at the end
    lost: list[str] = []  # cases whose task failed outside the case: not stored
    t0 = time.perf_counter()
    if todo:
        if client is None:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1,
                                   processes=True, host="127.0.0.1", dashboard_address=None)
            client = Client(cluster, set_as_default=False)
        try:
            base_tables = sweep.base.to_dict()
            # On a LocalCluster the workers share this file system: each writes its own cases
            # (atomically, as the client would), so writing runs on every worker instead of
            # queueing on the client. Elsewhere the store is local to the client, which writes.
            at = os.path.abspath(store) if scheduler is None else None
            if scheduler is not None:
                workers = max(1, len(client.scheduler_info().get("workers", {})))
            k = _batch_size(len(todo), workers, _saved_rows(sweep.settings))
            tasks = [todo[j:j + k] for j in range(0, len(todo), k)]
            futures = {client.submit(collecting_warnings, _run_cases, base_tables, sweep.settings,
                                     [sweep.cases[i] for i in task], at,
                                     [ids[i] for i in task], key=ids[task[0]], retries=retries, pure=False): task
                       for task in tasks}
            with tqdm(total=len(ids), initial=len(ids) - len(todo), unit="case", disable=not progress) as bar:
                for fut in as_completed(futures, loop=client.loop):
                    task = futures[fut]
                    cids = [ids[i] for i in task]
                    try:
                        results, caught = fut.result()
                        for w in caught:
                            said[w] = said.get(w, 0) + 1
                    except Exception as e:  # noqa: BLE001 - a task's failure is reported, not fatal
                        # Not the cases' own outcome (that comes back as a result): listed in the
                        # summary, not stored, so that the next run computes them.
                        for i, cid in zip(task, cids):
                            lost.append(cid)
                            rows[cid] = _summary_row(cid, sweep.cases[i], {}, "error",
                                                     f"{type(e).__name__}: {e} (not stored: run the sweep again)")
                        bar.update(len(task))
                        continue
                    if all("row" in r for r in results):
                        for cid, r in zip(cids, results):
                            rows[cid] = r["row"]
                    elif len(results) == 1:
                        rows[cids[0]] = _write_case(store, cids[0], results[0])
                    elif _stackable(results):
                        rows.update(zip(cids, _write_batch(store, cids, results)))
                    else:
                        rows.update((cid, _write_case(store, cid, r)) for cid, r in zip(cids, results))
                    bar.update(len(task))
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
                remove_temporaries(store)  # a worker killed while writing a case leaves its temporary file
    elapsed = time.perf_counter() - t0
    summary = write_summary(store, ids, rows)
    say_warnings(said, len(todo))
    return {"cases": len(ids), "computed": len(todo) - len(lost), "reused": len(ids) - len(todo), "lost": len(lost),
            "seconds": elapsed, "summary": summary}


