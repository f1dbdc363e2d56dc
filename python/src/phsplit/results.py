"""Results on disk: open a phsplit NetCDF file, and rerun the simulation it records.

Every file phsplit writes for a run (``phsplit simulate``, ``Solution.to_xarray().to_netcdf``,
sweep cases) carries what made it: the vessel file (``phsplit_vessel``, TOML), the settings
(``phsplit_settings``, a ``[simulation]`` table), the initial state (the ``initial_state``
variable, bit for bit) and how the run was cut into calls (``phsplit_chunks``). :func:`rerun`
repeats exactly those calls, so the same phsplit version on the same platform reproduces every
number of the file to the last bit; :func:`compare` says where two results differ.

>>> import phsplit, tempfile, os
>>> sol = phsplit.simulate(phsplit.Vessel.paper(), t_span=(0.0, 5.0), h=0.5, method="sp2")
>>> path = os.path.join(tempfile.mkdtemp(), "run.nc")
>>> sol.to_xarray().to_netcdf(path)
>>> ds = phsplit.open_dataset(path)
>>> float(ds["time"][-1]), ds.attrs["method"]
(5.0, 'sp2')
>>> phsplit.results.compare(ds, phsplit.rerun(ds))
[]
>>> ds.close()
"""
from __future__ import annotations

import os
import tomllib
from dataclasses import replace

import numpy as np

from . import _core, cf
from .chunks import joined as _joined
from .chunks import run_chunks
from .files import open_dataset
from .settings import Settings
from .sweepstore import open_sweep, sweep_case
from .vessel import Vessel
from ._arguments import checked

#: The CF finishing of a dataset (:func:`phsplit.cf.finish`), under its earlier name.
cf_finish = cf.finish

__all__ = ["open_dataset", "open_sweep", "sweep_case", "rerun", "compare", "run_chunks", "settings_of", "vessel_of", "cf_finish",
           "check_record"]


def _need(ds, key: str) -> str:
    if key not in ds.attrs:
        raise _core.InvalidInputError(f"the file has no {key!r} attribute, so it does not record how to rerun it "
                                      "(results of save_at or events come from several runs, and files of "
                                      f"phsplit before {ds.attrs.get('phsplit_version', '?')} did not record it)")
    return ds.attrs[key]


def _damaged(key: str, why: str) -> _core.InvalidInputError:
    return _core.InvalidInputError(f"the file's {key} attribute is damaged: {why}; it cannot be rerun")


@checked
def vessel_of(ds) -> Vessel:
    """The vessel a result was computed with."""
    text = _need(ds, "phsplit_vessel")
    if not isinstance(text, str):
        raise _damaged("phsplit_vessel", f"it must be a vessel file (TOML text), got {type(text).__name__}")
    try:
        return Vessel.from_toml_str(text)
    except (_core.InvalidInputError, _core.ScenarioParseError) as e:
        raise _damaged("phsplit_vessel", str(e)) from None


#: The keys of the ``[simulation]`` table of ``phsplit_settings`` and the types they hold.
_SETTINGS_TYPES = {"t_span": list, "h": (int, float), "method": str, "outer": str, "save_every": int,
                   "linear_flow": str, "ledger": bool}


@checked
def settings_of(ds) -> Settings:
    """The settings a result was computed with (checked as a run's are)."""
    text = _need(ds, "phsplit_settings")
    if not isinstance(text, str):
        raise _damaged("phsplit_settings", f"it must be a [simulation] table (TOML text), got {type(text).__name__}")
    try:
        sim = tomllib.loads(text).get("simulation")
    except tomllib.TOMLDecodeError as e:
        raise _damaged("phsplit_settings", f"TOML syntax error: {e}") from None
    if not isinstance(sim, dict):
        raise _damaged("phsplit_settings", "it has no [simulation] table")
    for k, typ in _SETTINGS_TYPES.items():
        if k not in sim:
            raise _damaged("phsplit_settings", f"simulation.{k} is missing")
        if isinstance(sim[k], bool) and typ is not bool or not isinstance(sim[k], typ):
            raise _damaged("phsplit_settings", f"simulation.{k} = {sim[k]!r} is not what a run records")
    cs = sim.get("control_start", "never")
    if isinstance(cs, bool) or not (cs == "never" or isinstance(cs, (int, float))):
        raise _damaged("phsplit_settings", f"simulation.control_start = {cs!r} is neither a time nor 'never'")
    pi = sim.get("project_invariants", True)
    if not isinstance(pi, bool):
        raise _damaged("phsplit_settings", f"simulation.project_invariants = {pi!r} is not true or false")
    tol = {}
    for k in ("rtol", "atol", "h_max"):
        v = sim.get(k)
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
            raise _damaged("phsplit_settings", f"simulation.{k} = {v!r} is not a number")
        tol[k] = v
    ts = sim["t_span"]
    if len(ts) != 2 or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in ts):
        raise _damaged("phsplit_settings", f"simulation.t_span = {ts!r} is not two numbers")
    settings = Settings(t_span=(float(ts[0]), float(ts[1])), h=sim["h"], method=sim["method"],
                        control_start=None if cs == "never" else cs, outer=sim["outer"],
                        save_every=sim["save_every"], linear_flow=sim["linear_flow"], ledger=sim["ledger"],
                        project_invariants=pi, **tol)
    try:
        settings.checked()
    except _core.InvalidInputError as e:
        raise _damaged("phsplit_settings", str(e)) from None
    return settings


def _chunks_of(ds, settings: Settings) -> list[int]:
    """The calls the run was cut into (``phsplit_chunks``), checked against its settings."""
    text = _need(ds, "phsplit_chunks")
    parts = str(text).split()
    if not parts or not all(p.isdigit() and int(p) >= 1 for p in parts):
        raise _damaged("phsplit_chunks", f"it must be step counts >= 1 separated by spaces, got {str(text)[:60]!r}")
    chunks = [int(c) for c in parts]
    n = int(settings.checked()["n_steps"])
    if sum(chunks) != n:
        raise _damaged("phsplit_chunks", f"its step counts add up to {sum(chunks)}, but the settings make {n} steps")
    return chunks


def check_record(ds) -> tuple[Vessel, Settings, np.ndarray, list[int]]:
    """What :func:`rerun` needs from a result, each part checked before anything is computed:
    the vessel, the settings, the initial state (a finite vector of the vessel's state size) and
    the calls (``phsplit_chunks``, adding up to the settings' steps). Raises
    :class:`phsplit.InvalidInputError` naming the damaged part."""
    if "wind_speed_limit" in ds:
        raise _core.InvalidInputError("the result is a DP capability (phsplit.capability), not a run: there is nothing "
                                      "to repeat; compute it again with phsplit.capability")
    if "case" in ds.dims:
        raise _core.InvalidInputError(
            f"the result holds {ds.sizes['case']} cases of a sweep (a batch file of a sweep store); rerun one "
            "case: phsplit.results.rerun(phsplit.results.sweep_case(STORE, CASE_ID))")
    vessel, settings = vessel_of(ds), settings_of(ds)
    if "initial_state" not in ds:
        raise _core.InvalidInputError("the file has no initial_state variable to start the rerun from")
    try:
        y0 = np.asarray(ds["initial_state"].values, dtype=np.float64)
    except (TypeError, ValueError):
        raise _core.InvalidInputError("the file's initial_state variable is damaged: it does not hold numbers") from None
    n = _core.STATE_DIM  # and the rate-limited thrusters' memory, when the run continued one (the core checks it)
    if y0.ndim != 1 or y0.size < n or not np.all(np.isfinite(y0)):
        raise _core.InvalidInputError(f"the file's initial_state variable is damaged: it must be at least {n} finite "
                                      f"numbers (the vessel's state), got shape {y0.shape}")
    own = vessel.own_states
    k = len(own)
    if y0.size < n + k or (y0.size > n + k and "thrusters" not in vessel.to_dict()):
        names = f" and its {k} own states ({', '.join(s[0] for s in own)})" if k else ""
        raise _core.InvalidInputError(
            f"the file's initial_state does not fit its vessel (phsplit_vessel): it holds {y0.size} numbers, the "
            f"vessel's state {n + k}: the body's {n}{names}" + (", then the thrusters' memory" if "thrusters" in
                                                               vessel.to_dict() else ""))
    chunks = _chunks_of(ds, settings)
    if ds.attrs.get("status") == "interrupted":
        steps = ds.attrs.get("steps")
        if isinstance(steps, (bool, str)) or not isinstance(steps, (int, np.integer)) or not 0 <= steps <= sum(chunks):
            raise _core.InvalidInputError(f"the file's steps attribute is damaged: it must be the steps an "
                                          f"interrupted run reached, 0 to {sum(chunks)}, got {steps!r}")
    return vessel, settings, y0, chunks


@checked
def rerun(source, progress: bool = False):
    """Rerun the simulation a phsplit file (a path or an open dataset) records, with the same
    calls, and return its result as a dataset laid out like the file. A run the file records as
    interrupted is rerun to the step it reached. A case of a sweep's batch file: take it with
    :func:`sweep_case` first."""
    import xarray as xr

    if not isinstance(source, (str, os.PathLike, xr.Dataset)):
        raise _core.InvalidInputError(f"rerun takes a phsplit result file's path or its open xarray.Dataset, got "
                                      f"{type(source).__name__}")
    ds = open_dataset(source) if isinstance(source, (str, os.PathLike)) else source
    vessel, settings, y0, chunks = check_record(ds)
    if ds.attrs.get("status") == "interrupted" and settings.adaptive:
        raise _core.InvalidInputError(
            "the file records an interrupted run with adaptive steps (rtol, atol): its steps depend on where the run "
            "ends, so it cannot be rerun to the step it reached; rerun the whole run from its scenario")
    if ds.attrs.get("status") == "interrupted":
        left, cut = int(ds.attrs["steps"]), []
        for c in chunks:
            if left <= 0:
                break
            cut.append(min(c, left))
            left -= c
        t_end = settings.t_span[0] + sum(cut) * settings.h
        chunks, settings = cut, replace(settings, t_span=(settings.t_span[0], t_end))
    sols = list(run_chunks(vessel, settings, y0, chunks))
    out = _joined(sols)
    # The run's own record (the file's), not the first call's: a written rerun reruns again.
    keep = ("phsplit_settings", "phsplit_chunks", "phsplit_vessel", "phsplit_scenario", "phsplit_scenario_path",
            "phsplit_environment",
            "steps", "status")
    out.attrs.update({k: ds.attrs[k] for k in keep if k in ds.attrs})
    return out


@checked
def compare(a, b) -> list[tuple[str, float]]:
    """The variables of ``a`` whose values differ from ``b``'s (NaN equal to NaN), with the
    largest absolute difference; ``[]`` when every number agrees to the last bit. Variables
    present in only one of them are reported with ``inf``."""
    import xarray as xr

    for name, ds in (("a", a), ("b", b)):
        if not isinstance(ds, xr.Dataset):
            raise _core.InvalidInputError(f"compare: {name} must be an xarray.Dataset (a result), got "
                                          f"{type(ds).__name__}")
    diffs = []
    for name in sorted(set(a.data_vars) | set(b.data_vars) | {"time"}):
        if name not in a.variables or name not in b.variables:
            diffs.append((name, float("inf")))
            continue
        x, y = np.asarray(a[name].values), np.asarray(b[name].values)
        if x.shape != y.shape:
            diffs.append((name, float("inf")))
        elif not np.array_equal(x, y, equal_nan=x.dtype.kind in "fc" and y.dtype.kind in "fc"):
            with np.errstate(invalid="ignore"):
                diffs.append((name, float(np.nanmax(np.abs(x.astype(float) - y.astype(float))))))
    return diffs
