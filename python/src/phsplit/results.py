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
from typing import Any, Iterator

import numpy as np

from . import _core
from .simulate import Settings, Solution, Vessel, simulate

__all__ = ["open_dataset", "open_sweep", "sweep_case", "rerun", "compare", "run_chunks", "settings_of", "vessel_of", "cf_finish"]


def open_dataset(path: str | os.PathLike[str], **kw: Any):
    """Open a phsplit result (NetCDF) as an ``xarray.Dataset``, lazily.

    Time stays in seconds (``decode_times=False``: the CF epoch of the file is nominal). Other
    keywords go to ``xarray.open_dataset``. A file that does not exist, is not NetCDF or was not
    written by phsplit raises :class:`phsplit.InvalidInputError`."""
    import xarray as xr

    p = os.fspath(path)
    if not os.path.isfile(p):
        raise _core.InvalidInputError(f"{p!r} does not exist (or is not a file)")
    try:
        ds = xr.open_dataset(p, decode_times=False, **kw)
    except (OSError, ValueError) as e:
        raise _core.InvalidInputError(f"{p!r} is not a NetCDF file phsplit can read: {e}") from None
    if "phsplit_version" not in ds.attrs:
        ds.close()
        raise _core.InvalidInputError(f"{p!r} was not written by phsplit (no phsplit_version attribute)")
    return ds


def _need(ds, key: str) -> str:
    if key not in ds.attrs:
        raise _core.InvalidInputError(f"the file has no {key!r} attribute, so it does not record how to rerun it "
                                      "(results of save_at or events come from several runs, and files of "
                                      f"phsplit before {ds.attrs.get('phsplit_version', '?')} did not record it)")
    return ds.attrs[key]


def vessel_of(ds) -> Vessel:
    """The vessel a result was computed with."""
    return Vessel.from_toml_str(_need(ds, "phsplit_vessel"))


def settings_of(ds) -> Settings:
    """The settings a result was computed with."""
    sim = tomllib.loads(_need(ds, "phsplit_settings"))["simulation"]
    cs = sim.get("control_start", "never")
    return Settings(t_span=tuple(sim["t_span"]), h=sim["h"], method=sim["method"],
                    control_start=None if cs == "never" else cs, outer=sim["outer"],
                    save_every=sim["save_every"], linear_flow=sim["linear_flow"], ledger=sim["ledger"],
                    project_invariants=sim.get("project_invariants", True))


def run_chunks(vessel: Vessel, settings: Settings, state: np.ndarray, chunks: list[int]) -> Iterator[Solution]:
    """Run ``settings`` as consecutive calls of ``chunks[i]`` steps each, the next starting from
    the last state of the one before; the last call ends at ``t1`` itself. Stops after a call
    that did not complete. This is how ``phsplit simulate`` runs (and writes) a long run, and how
    :func:`rerun` repeats it."""
    t0, t1 = settings.t_span
    t = t0
    for i, k in enumerate(chunks):
        end = t1 if i == len(chunks) - 1 else t + k * settings.h
        # a last chunk of only the final, shorter step takes that step's length as its h
        h = min(settings.h, end - t)
        sol = simulate(vessel, initial=state, settings=replace(settings, t_span=(t, end), h=h), _continuing=True)
        yield sol
        if sol.status != "completed":
            return
        state = sol.last_good_state
        t = float(sol.t[-1])


def _joined(sols: list[Solution]):
    """The chunks' datasets as one, as the CLI writes them (each chunk after the first without
    its first row, which repeats the previous chunk's last)."""
    import xarray as xr

    parts = [s.to_xarray() for s in sols]
    if len(parts) == 1:
        return parts[0]
    timed = [p.isel(time=slice(1, None)) if i else p for i, p in enumerate(parts)]
    return xr.concat(timed, dim="time", data_vars="minimal", coords="minimal", compat="override",
                     combine_attrs="override")


def sweep_case(store: str | os.PathLike[str], case_id: str):
    """One case of a sweep store as the dataset of its own run (loaded into memory), whether it
    is stored in a file of its own or in a batch file: the batch's variables at the case, and its
    per-case variables (``case_status``, ..., ``run_<attribute>``) back as attributes, so that
    :func:`rerun` and :func:`compare` take it like any result file."""
    from .batch import _CASE_ATTRS, store_index

    index = store_index(os.fspath(store))
    if case_id not in index:
        raise _core.InvalidInputError(f"the sweep store {os.fspath(store)!r} holds no case {case_id!r}")
    path, i = index[case_id]
    with open_dataset(path) as ds:
        if i is None:
            return ds.load()
        one = ds.isel(case=i).load()
    if str(one["case_status"].values) == "invalid" or "time" not in one.dims:
        raise _core.InvalidInputError(f"case {case_id!r} of the sweep store did not run: "
                                      f"{one['case_error'].values}")
    # The case's own saved times: the batch pads the shorter runs with NaN.
    one = one.isel(time=slice(0, int(one["case_time_count"].values))).drop_vars("case_time_count")
    per_case = [k for k in one.data_vars if k.startswith("run_") or k in _CASE_ATTRS]
    attrs = {k[4:] if k.startswith("run_") else k: str(one[k].values) for k in per_case}
    one = one.drop_vars(per_case + ["case_id"])
    one.attrs.pop("phsplit_batch", None)
    for k, v in attrs.items():
        one.attrs[k] = int(v) if k == "steps" and v else v
    return one


def rerun(source, progress: bool = False):
    """Rerun the simulation a phsplit file (a path or an open dataset) records, with the same
    calls, and return its result as a dataset laid out like the file. A run the file records as
    interrupted is rerun to the step it reached. A case of a sweep's batch file: take it with
    :func:`sweep_case` first."""
    ds = open_dataset(source) if isinstance(source, (str, os.PathLike)) else source
    if "case" in ds.dims:
        raise _core.InvalidInputError(
            f"the result holds {ds.sizes['case']} cases of a sweep (a batch file of a sweep store); rerun one "
            "case: phsplit.results.rerun(phsplit.results.sweep_case(STORE, CASE_ID))")
    vessel, settings = vessel_of(ds), settings_of(ds)
    if "initial_state" not in ds:
        raise _core.InvalidInputError("the file has no initial_state variable to start the rerun from")
    y0 = np.asarray(ds["initial_state"].values, dtype=np.float64)
    chunks = [int(c) for c in _need(ds, "phsplit_chunks").split()]
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


def compare(a, b) -> list[tuple[str, float]]:
    """The variables of ``a`` whose values differ from ``b``'s (NaN equal to NaN), with the
    largest absolute difference; ``[]`` when every number agrees to the last bit. Variables
    present in only one of them are reported with ``inf``."""
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


REFERENCES = ("E. Celledoni, E. H. Hoiseth, N. Ramzina, Passivity-preserving splitting methods for rigid body "
              "systems, Multibody Syst. Dyn. 44 (2018) 251-275, arXiv:1408.2544")


def cf_finish(ds, title: str, what: str):
    """Make a dataset phsplit writes CF-1.8 conforming: the global attributes (``Conventions``,
    ``title``, ``institution``, ``source``, ``history``, ``references``), ``units`` and
    ``long_name`` on every variable (``"1"`` and the name in words where the writer gave none),
    booleans as ``int8`` flags, labels along a dimension as auxiliary coordinates (``<dim>_name``)
    instead of string coordinate variables, and no fill value on coordinates. Returns the
    dataset (a copy)."""
    import datetime

    ds = ds.copy()
    for dim in list(ds.dims):
        if dim in ds.coords and ds[dim].dtype.kind in "OUS":
            labels = ds[dim].values.astype(str)
            ds = ds.drop_vars(dim).assign_coords({f"{dim}_name": (dim, labels, {"long_name": f"{dim} label"})})
    for name in list(ds.variables):
        v = ds[name]
        if v.dtype == bool:
            ds[name] = v.astype(np.int8)
            ds[name].attrs.update({"flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": "false true",
                                   **{k: x for k, x in v.attrs.items() if k != "units"}})
            v = ds[name]
        if v.dtype.kind in "iu" and v.dtype.itemsize == 8:  # CF 2.2: no 64-bit integers
            if np.abs(v.values).max(initial=0) < 2**31:
                ds[name] = v.astype(np.int32)
            else:
                ds[name] = v.astype(np.float64)
            v = ds[name]
        if v.dtype.kind in "fiu" and "units" not in v.attrs and "flag_values" not in v.attrs:
            v.attrs["units"] = "1"
        v.attrs.setdefault("long_name", name.replace("_", " "))
        if name in ds.coords:
            v.encoding["_FillValue"] = None
    if "time" in ds.dims:
        ds.encoding["unlimited_dims"] = {"time"}
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    ds.attrs = {
        "Conventions": "CF-1.8",
        "title": title,
        "institution": "phsplit",
        "source": f"phsplit {_core.__version__}",
        "history": f"{now} phsplit {_core.__version__}: {what}",
        "references": REFERENCES,
        "phsplit_version": _core.__version__,
        **{k: v for k, v in ds.attrs.items() if k not in ("Conventions", "title", "history")},
    }
    return ds


def open_sweep(store: str | os.PathLike[str]):
    """The cases of a sweep store (``phsplit sweep``) as one dataset with a ``case`` dimension,
    opened lazily through Dask, in the order of the sweep file, from files of one case
    (``cases/<id>.nc``) and batch files (``cases/batch_<digest>.nc``, a large sweep's cases
    stacked along ``case``) alike. Cases that did not run (invalid parameters) are left out;
    ``summary.nc`` lists every case with its status. The varied parameters are coordinates along
    ``case``, and ``case_id`` names each."""
    import json

    import xarray as xr

    from .batch import store_index

    root = os.fspath(store)
    meta = os.path.join(root, "sweep.json")
    if not os.path.isfile(meta):
        raise _core.InvalidInputError(f"{root!r} is not a sweep store (no sweep.json in it)")
    with open(meta) as f:
        cases = json.load(f)["cases"]
    index = store_index(root)
    opened: dict[str, Any] = {}
    parts, ids, params = [], [], []
    try:
        for cid, case in cases.items():
            if cid not in index:
                continue  # not computed yet
            path, i = index[cid]
            if path not in opened:
                opened[path] = xr.open_dataset(path, decode_times=False, chunks={})
            d = opened[path]
            if "time" not in d.dims:
                continue  # an invalid case: nothing ran
            if i is None:
                one = d.expand_dims("case")
            else:
                if str(d["case_status"].values[i]) == "invalid":
                    continue
                one = d.isel(case=[i]).drop_vars(["case_id", "case_status", "case_error", "case_parameters",
                                                   "case_summary", "case_time_count"]
                                                  + [k for k in d.data_vars if k.startswith("run_")])
            parts.append(one)
            ids.append(cid)
            params.append(case)
        if not parts:
            raise _core.InvalidInputError(f"the sweep store {root!r} holds no computed case yet")
        ds = xr.concat(parts, dim="case", data_vars="all", coords="minimal", compat="override", join="outer",
                       combine_attrs="drop_conflicts")
    except BaseException:
        for d in opened.values():
            d.close()
        raise
    ds = ds.assign_coords(case_id=("case", np.array(ids)))
    for k in sorted({k for c in params for k in c}):
        name = k.replace(".", "_").replace("[", "_").replace("]", "")
        ds = ds.assign_coords({name: ("case", np.array([c.get(k, np.nan) if isinstance(c.get(k), (int, float)) else np.nan
                                                         for c in params], float), {"parameter": k})})
    ds.set_close(lambda: [d.close() for d in opened.values()])  # last: assign_coords drops it
    return ds
