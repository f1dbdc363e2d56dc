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

import concurrent.futures as cf
import hashlib
import itertools
import json
import math
import os
import re
import tempfile
import time
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np

from . import _core
from .simulate import Settings, Vessel, settings_to_toml, simulate

_PATH = re.compile(r"^([a-z_]+)((?:\.[a-z_]+|\[[0-9]+\])+)$")
_SEGMENT = re.compile(r"\.([a-z_]+)|\[([0-9]+)\]")
#: Matrices that are symmetric by definition: an off-diagonal entry sets its mirror too.
_SYMMETRIC = {("vessel", "added_mass"), ("vessel", "damping_matrix")}
_SHAPES = ("a parameter path is 'table.name', 'table.name[i]', 'table.name[i][j]' (a matrix entry) or "
           "'table.list[i].name' (a table of a list, like thrusters.unit[0].max_thrust)")


def _resolve(d: dict, key: str) -> list[str | int]:
    """Check a parameter path against a vessel's dict: the keys and indices that lead to its
    number (the last key of a table in a list may be new: the vessel file's reader checks it)."""
    if not isinstance(key, str):
        raise _core.InvalidInputError(f"{_SHAPES}, got {key!r}")
    m = _PATH.match(key)
    segs: list[str | int] = []
    if m:
        segs = [m.group(1)] + [g1 if g1 else int(g2) for g1, g2 in _SEGMENT.findall(m.group(2))]
    if not m or not isinstance(segs[1], str) or not isinstance(d.get(segs[0]), dict) or segs[1] not in d[segs[0]]:
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
            new_key = seg not in cur and n == len(segs) - 1 and n >= 3 and isinstance(segs[n - 1], int)
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
    return Vessel.from_dict(d, f"{base.source} with {dict(params)}")


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


def _coord_name(key: str) -> str:
    return key.replace(".", "_").replace("[", "_").replace("]", "")


def simulate_many(cases: Sequence[Mapping[str, float]], base: Vessel | None = None,
                  settings: Settings | None = None, max_workers: int | None = None, **kw):
    """Run every case (a mapping of parameter paths to values) on a thread pool; the core releases
    the GIL, so they run in parallel. Returns an ``xarray.Dataset`` with dims ``case`` and
    ``time`` (all cases share the time grid), the varied parameters as coordinates, and the
    summary of each case. A case whose parameters are invalid gets ``status = "invalid"`` and
    NaN series; it does not stop the others. Settings may be given as keyword arguments."""
    import xarray as xr

    base = base or Vessel.paper()
    settings = settings or Settings(**kw)
    if not isinstance(settings, Settings):
        raise _core.InvalidInputError(f"settings must be a phsplit.Settings, got {type(settings).__name__}")
    if isinstance(cases, (str, bytes, Mapping)) or not isinstance(cases, Sequence) or not all(
            isinstance(c, Mapping) for c in cases):
        raise _core.InvalidInputError("cases must be a sequence of mappings {parameter path: value}, "
                                      f"got {type(cases).__name__}")
    keys = sorted({k for c in cases for k in c})

    def one(case):
        try:
            v = with_parameters(base, case)
        except (_core.InvalidInputError, _core.ScenarioParseError) as e:
            return None, {"status": "invalid", "error": str(e)}
        sol = settings.run(v, running_max=True)  # peaks over every step
        return sol, {**summarize(v, sol), "error": sol.failure or ""}

    with cf.ThreadPoolExecutor(max_workers=max_workers or os.cpu_count() or 2) as pool:
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
    from .results import cf_finish

    ds["time"].attrs.update({"units": "seconds since 1970-01-01 00:00:00", "standard_name": "time", "axis": "T",
                             "long_name": "simulated time (t = 0 at the nominal epoch)"})
    return cf_finish(ds, "phsplit simulate_many: one run per case", "simulate_many")


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


SWEEP_KEYS = {"mode": "'grid' or 'random'", "samples": "number of random cases", "seed": "random seed",
              "parameters": "table of parameter paths"}


def load_sweep(path: str) -> Sweep:
    """Read a sweep file: a scenario's ``[simulation]`` (and optional vessel) plus ``[sweep]``.

    ``mode = "grid"``: every parameter is a list of values; the cases are their product.
    ``mode = "random"``: every parameter is ``{low = ., high = .}`` (uniform) or a list (choice);
    ``samples`` cases drawn with ``seed``."""
    import difflib
    import tomllib

    from . import scenario as scn

    try:
        with open(path, "rb") as f:
            data = tomllib.load(f)
    except FileNotFoundError:
        raise _core.InvalidInputError(f"sweep file {path!r} does not exist") from None
    except tomllib.TOMLDecodeError as e:
        raise _core.ScenarioParseError(f"{path}: TOML syntax error: {e}") from None
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
    params = sw.get("parameters", {})
    if not isinstance(params, dict) or not params:
        raise _core.ScenarioParseError(f"{path}: [sweep.parameters] must list at least one parameter")
    mode = sw.get("mode", "grid")
    keys = list(params)
    d0 = sc.vessel.to_dict()
    for k in keys:
        _resolve(d0, k)  # the paths are checked now; the values case by case
        spec = params[k]
        values = list(spec.values()) if isinstance(spec, dict) else spec if isinstance(spec, list) else [spec]
        bad = [v for v in values if isinstance(v, bool) or not isinstance(v, (int, float))]
        if bad:
            raise _core.ScenarioParseError(f"{path}: sweep.parameters.{k} must hold numbers, got {bad[0]!r}")
    if mode == "grid":
        for k in keys:
            if not isinstance(params[k], list) or not params[k]:
                raise _core.ScenarioParseError(f"{path}: in grid mode, sweep.parameters.{k} must be a list of values")
        cases = [dict(zip(keys, map(float, combo))) for combo in itertools.product(*(params[k] for k in keys))]
    elif mode == "random":
        n = sw.get("samples")
        if not isinstance(n, int) or n < 1:
            raise _core.ScenarioParseError(f"{path}: random mode needs sweep.samples, an integer >= 1")
        rng = np.random.default_rng(sw.get("seed", 0))
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
    else:
        raise _core.ScenarioParseError(f"{path}: sweep.mode must be 'grid' or 'random', got {mode!r}")
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


def _summary_row(cid: str, case: dict, summary: dict, status: str, error: str) -> dict:
    """A case's row of the sweep's summary table."""
    return {"case_id": cid, **case, **summary, "status": status, "error": error}


def _store_file(ds, path: str, encoding: dict) -> None:
    """Write ``ds`` to ``path`` atomically: a temporary file beside it, then a rename, so a store
    holds a file whole or not at all."""
    import dask

    from .plotting import publish

    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), prefix=".tmp-", suffix=".nc")
    os.close(fd)
    try:
        # The dataset is in memory: no dask scheduler is involved. Said explicitly, so that on a
        # Dask worker xarray takes a local lock, not a distributed one (a round trip to the
        # scheduler per write made writing on the workers 7 times slower).
        with dask.config.set(scheduler="synchronous"):
            ds.to_netcdf(tmp, encoding=encoding)
        publish(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def _write_case(store: str, cid: str, result: dict) -> dict:
    """Write one case atomically: STORE/cases/<cid>.nc via a temporary file and a rename.
    Returns the case's summary row (as :func:`write_summary` would read it back)."""
    import xarray as xr

    ds = result.get("dataset")
    if ds is None:  # an invalid case: no run, only what was asked and why it was refused
        from .results import cf_finish

        ds = cf_finish(xr.Dataset(), "phsplit sweep case (not run)", "sweep")
    ds = ds.copy()
    ds.attrs.update({"case_id": cid, "case_status": result["status"], "case_error": result.get("error", ""),
                     "case_parameters": json.dumps(result["case"], sort_keys=True),
                     "case_summary": json.dumps(result.get("summary", {}), sort_keys=True)})
    # A case file is written once: each variable along the record dimension in one HDF5 chunk
    # (netCDF's default chunk of one record made writing 2.2x as slow, the file 2.1x as large).
    _store_file(ds, os.path.join(store, "cases", f"{cid}.nc"),
                {k: {"chunksizes": ds[k].shape} for k in ds.data_vars if "time" in ds[k].dims and ds[k].size})
    a = ds.attrs
    return _summary_row(cid, json.loads(a["case_parameters"]), json.loads(a["case_summary"]),
                        a["case_status"], a["case_error"])


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


def _stackable(results: list[dict]) -> bool:
    """Whether the cases that ran have the same variables, of the same dimensions and sizes
    beyond time, all floating point (a parameter can add an account, or the rate-limited
    thrusters' memory to the initial state): else each case gets a file of its own."""
    done = [r["dataset"] for r in results if r.get("dataset") is not None]
    if not done:
        return True

    def shape(d):
        return {k: (v.dims, tuple(n for dim, n in zip(v.dims, v.shape) if dim != "time"), v.dtype.kind)
                for k, v in d.variables.items() if k != "time"}

    first = shape(done[0])
    return all(kind in "f" or k in done[0].coords for k, (_, _, kind) in first.items()) and all(
        shape(d) == first for d in done[1:])


#: The per-case attributes of a case file that a batch file holds as variables along ``case``.
_CASE_ATTRS = ("case_status", "case_error", "case_parameters", "case_summary")


def _batch_dataset(cids: list[str], results: list[dict]):
    """The cases of one task stacked along ``case``: every variable of the case files with a
    leading ``case`` dimension (NaN beyond a case's last saved time and for a case that did not
    run), ``case_id`` as a coordinate, the case files' own attributes (status, error, parameters,
    summary) as variables along ``case``, and each run attribute that differs between the cases
    (the vessel file with its parameters, the number of steps, ...) as a variable
    ``run_<attribute>`` (empty for a case that did not run); the attributes the cases that ran
    share stay global."""
    import xarray as xr

    n = len(results)
    ran = [r.get("dataset") for r in results]
    done = [d for d in ran if d is not None]
    ref = max(done, key=lambda d: d.sizes.get("time", 0)) if done else None
    variables: dict[str, Any] = {}
    coords: dict[str, Any] = {"case_id": ("case", np.array(cids, dtype=object), {"long_name": "case identifier"})}
    attrs: dict[str, Any] = {}
    if ref is not None:
        for name, c in ref.coords.items():
            coords[name] = c.variable
        names = list(dict.fromkeys(k for d in done for k in d.data_vars))
        for name in names:
            # Variables, not DataArrays: building a DataArray per case and name cost 30 ms a batch.
            proto = next(d.variables[name] for d in done if name in d.data_vars)
            shape = tuple(ref.sizes[k] if k == "time" else proto.sizes[k] for k in proto.dims)
            out = np.full((n,) + shape, np.nan)
            for i, d in enumerate(ran):
                if d is not None and name in d.data_vars:
                    a = np.asarray(d.variables[name].values, dtype=float)
                    out[(i,) + tuple(slice(0, k) for k in a.shape)] = a
            variables[name] = (("case",) + proto.dims, out, dict(proto.attrs))
        keys = list(dict.fromkeys(k for d in done for k in d.attrs))
        for k in keys:
            vals = [d.attrs.get(k) if d is not None else None for d in ran]
            if all(k in d.attrs and str(d.attrs[k]) == str(ref.attrs.get(k)) for d in done):
                attrs[k] = ref.attrs[k]  # the same for every case that ran
            else:
                variables[f"run_{k}"] = ("case", np.array(["" if v is None else str(v) for v in vals], dtype=object),
                                         {"long_name": f"the run attribute {k} of each case"})
    rows = [d.sizes.get("time", 0) if d is not None else 0 for d in ran]
    variables["case_time_count"] = ("case", np.array(rows, dtype=np.int32),
                                    {"long_name": "number of saved times of each case (the rest is padding)"})
    for k, key in zip(_CASE_ATTRS, ("status", "error", "case", "summary")):
        if key in ("case", "summary"):
            vals = [json.dumps(r.get(key, {}), sort_keys=True) for r in results]
        else:
            vals = [str(r.get(key, "")) for r in results]
        variables[k] = ("case", np.array(vals, dtype=object), {"long_name": k.replace("_", " ")})
    from .results import cf_finish

    ds = xr.Dataset(variables, coords=coords, attrs=attrs)
    ds = cf_finish(ds, attrs.get("title", "phsplit sweep cases"), "sweep")
    ds.attrs["phsplit_batch"] = f"{n} cases of a sweep along 'case' (phsplit.open_sweep reads the store)"
    return ds


def _write_batch(store: str, cids: list[str], results: list[dict]) -> list[dict]:
    """Write one task's cases as one file, atomically: ``STORE/cases/batch_<digest>.nc`` (the
    digest over the case ids), via a temporary file and a rename. Returns their summary rows."""
    ds = _batch_dataset(cids, results)
    name = "batch_" + hashlib.sha256("\n".join(cids).encode()).hexdigest()[:16] + ".nc"
    # Each variable in one HDF5 chunk (as a case file). Text as character arrays:
    # variable-length strings in a file that is opened twice at once (open_sweep and the store's
    # index) broke HDF5's reads (a review reproduced it).
    encoding = {k: {"chunksizes": ds[k].shape} for k in ds.data_vars if ds[k].dtype.kind == "f" and ds[k].size}
    encoding.update({k: {"dtype": "S1"} for k in ds.variables if ds[k].dtype.kind in "OU"})
    _store_file(ds, os.path.join(store, "cases", name), encoding)
    # The rows as write_summary reads them back from the file (the JSON's sorted keys).
    meta = {k: [str(x) for x in ds[k].values] for k in _CASE_ATTRS}
    return [_summary_row(cid, json.loads(meta["case_parameters"][i]), json.loads(meta["case_summary"][i]),
                         meta["case_status"][i], meta["case_error"][i]) for i, cid in enumerate(cids)]


def store_index(store: str) -> dict[str, tuple[str, int | None]]:
    """Where each stored case of a sweep store is: ``{case id: (file, index along case)}``, the
    index ``None`` for a file of one case (``cases/<id>.nc``), else its place in a batch file
    (``cases/batch_<digest>.nc``). A case stored twice (two sweeps writing one store at once) is
    taken from the first file in name order."""
    import xarray as xr

    d = os.path.join(store, "cases")
    out: dict[str, tuple[str, int | None]] = {}
    if not os.path.isdir(d):
        return out
    for f in sorted(os.listdir(d)):
        if f.startswith(".") or not f.endswith(".nc"):
            continue
        p = os.path.join(d, f)
        if f.startswith("batch_"):
            try:
                # Through xarray, as every other read of the store: its cache of open files
                # and netCDF4 handles of its own on one file do not mix (a crash in HDF5).
                with xr.open_dataset(p, decode_times=False) as nc:
                    ids = [str(x) for x in nc["case_id"].values]
            except (OSError, ValueError, KeyError) as e:
                raise _core.InvalidInputError(f"{p!r} is not a batch file of a sweep store that phsplit can read: "
                                              f"{e}; remove it and run the sweep again to compute its cases") from None
            for i, cid in enumerate(ids):
                out.setdefault(cid, (p, i))
        else:
            out.setdefault(f[:-3], (p, None))
    return out


def done_cases(store: str) -> set[str]:
    """The ids of the cases a sweep store holds (in files of one case or in batch files)."""
    return set(store_index(store))


def run_sweep(sweep: Sweep, store: str, scheduler: str | None = None, n_workers: int | None = None,
              progress: bool = True, retries: int = 3) -> dict[str, Any]:
    """Run the missing cases of ``sweep`` on Dask and store them; returns counts and the summary
    table path."""
    from dask.distributed import Client, LocalCluster, as_completed
    from tqdm import tqdm

    os.makedirs(os.path.join(store, "cases"), exist_ok=True)
    for f in os.listdir(os.path.join(store, "cases")):
        if f.startswith(".tmp-"):
            os.unlink(os.path.join(store, "cases", f))  # left by a client that was killed mid-write
    ids = [sweep.case_id(i) for i in range(len(sweep.cases))]
    have = done_cases(store)  # cases of other settings stay in the store under their own ids, unused
    todo = [i for i, cid in enumerate(ids) if cid not in have]
    workers = n_workers or os.cpu_count() or 2
    from .plotting import publish

    fd, tmp = tempfile.mkstemp(dir=store, prefix=".tmp-", suffix=".json")
    with os.fdopen(fd, "w") as f:
        json.dump({"name": sweep.name, **sweep.identity(), "cases": dict(zip(ids, sweep.cases))},
                  f, indent=1, default=repr)
    publish(tmp, os.path.join(store, "sweep.json"))  # whole or not at all
    cluster = None
    rows: dict[str, dict] = {}  # the summary rows of the cases computed now
    lost: list[str] = []  # cases whose task failed outside the case: not stored
    t0 = time.perf_counter()
    if todo:
        if scheduler:
            client = Client(scheduler, set_as_default=False)
        else:
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
            futures = {client.submit(_run_cases, base_tables, sweep.settings, [sweep.cases[i] for i in task], at,
                                     [ids[i] for i in task], key=ids[task[0]], retries=retries, pure=False): task
                       for task in tasks}
            with tqdm(total=len(ids), initial=len(ids) - len(todo), unit="case", disable=not progress) as bar:
                for fut in as_completed(futures, loop=client.loop):
                    task = futures[fut]
                    cids = [ids[i] for i in task]
                    try:
                        results = fut.result()
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
                # a worker killed while writing a case leaves its temporary file
                for f in os.listdir(os.path.join(store, "cases")):
                    if f.startswith(".tmp-"):
                        os.unlink(os.path.join(store, "cases", f))
    elapsed = time.perf_counter() - t0
    summary = write_summary(store, ids, rows)
    return {"cases": len(ids), "computed": len(todo) - len(lost), "reused": len(ids) - len(todo), "lost": len(lost),
            "seconds": elapsed, "summary": summary}


def write_summary(store: str, ids: list[str], known: dict[str, dict] | None = None) -> str:
    """One row per case: parameters, summary, status and error; as CSV and NetCDF. The rows of
    ``known`` (by case id, as :func:`_write_case` returns them) are used as given; the other
    cases' rows are read from their files in the store."""
    import csv

    import xarray as xr

    rows = []
    index = store_index(store) if not known or any(cid not in known for cid in ids) else {}
    batches: dict[str, dict[str, list[str]]] = {}  # a batch file's metadata, read once
    for cid in ids:
        if known and cid in known:
            rows.append(known[cid])
            continue
        path, i = index[cid]
        if i is None:
            with xr.open_dataset(path) as ds:
                a = {k: ds.attrs[k] for k in _CASE_ATTRS}
        else:
            if path not in batches:
                with xr.open_dataset(path) as ds:
                    batches[path] = {k: [str(x) for x in ds[k].values] for k in _CASE_ATTRS}
            a = {k: v[i] for k, v in batches[path].items()}
        rows.append(_summary_row(cid, json.loads(a["case_parameters"]), json.loads(a["case_summary"]),
                                 a["case_status"], a["case_error"]))
    cols = list(dict.fromkeys(k for r in rows for k in r))
    path = os.path.join(store, "summary.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols)
        w.writeheader()
        w.writerows(rows)
    data = {}
    for c in cols:
        vals = [r.get(c, math.nan) for r in rows]
        if all(isinstance(v, (int, float, bool)) for v in vals):
            data[_coord_name(c)] = ("case", np.asarray(vals, float))
        else:
            data[_coord_name(c)] = ("case", np.asarray([str(v) for v in vals], dtype=object))
    from .results import cf_finish

    cf_finish(xr.Dataset(data), "phsplit sweep summary: one row per case", "sweep").to_netcdf(
        os.path.join(store, "summary.nc"))
    return path
