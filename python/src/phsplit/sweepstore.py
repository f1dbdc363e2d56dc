"""The sweep store (``phsplit sweep``): its format, written and read in this module alone.

A store is a folder: ``sweep.json`` (the sweep's identity and its cases), ``cases/<id>.nc``
(a case in a file of its own) and ``cases/batch_<digest>.nc`` (a task's cases stacked along
``case``), and ``summary.csv`` / ``summary.nc`` (one row per case). Every file is written
whole or not at all (a temporary file beside it, then a rename). :func:`open_sweep` and
:func:`sweep_case` read it back (``phsplit.open_sweep``, ``phsplit.results.sweep_case``)."""
from __future__ import annotations

import hashlib
import json
import math
import os
from typing import Any

import numpy as np

from . import _core, cf
from .files import open_dataset, publish, temporary_beside
from ._arguments import checked


def _coord_name(key: str) -> str:
    return key.replace(".", "_").replace("[", "_").replace("]", "")


def _summary_row(cid: str, case: dict, summary: dict, status: str, error: str) -> dict:
    """A case's row of the sweep's summary table."""
    return {"case_id": cid, **case, **summary, "status": status, "error": error}


def _store_file(ds, path: str, encoding: dict) -> None:
    """Write ``ds`` to ``path`` atomically: a temporary file beside it, then a rename, so a store
    holds a file whole or not at all."""
    import dask

    tmp = temporary_beside(path)
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
        ds = cf.finish(xr.Dataset(), "phsplit sweep case (not run)", "sweep")
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
    ds = xr.Dataset(variables, coords=coords, attrs=attrs)
    ds = cf.finish(ds, attrs.get("title", "phsplit sweep cases"), "sweep")
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
    taken from the first file in name order. A store that does not exist is refused; one not yet
    written to holds no case."""
    import xarray as xr

    if not isinstance(store, (str, os.PathLike)) or not os.path.isdir(store):
        raise _core.InvalidInputError(f"the sweep store {store!r} is not a folder (phsplit sweep makes it)")
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
    """The ids of the cases a sweep store holds (in files of one case or in batch files); none
    for a store not made yet."""
    return set(store_index(store)) if os.path.isdir(store) else set()



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
    cf.finish(xr.Dataset(data), "phsplit sweep summary: one row per case", "sweep").to_netcdf(
        os.path.join(store, "summary.nc"))
    return path


@checked
def sweep_case(store: str | os.PathLike[str], case_id: str):
    """One case of a sweep store as the dataset of its own run (loaded into memory), whether it
    is stored in a file of its own or in a batch file: the batch's variables at the case, and its
    per-case variables (``case_status``, ..., ``run_<attribute>``) back as attributes, so that
    :func:`rerun` and :func:`compare` take it like any result file."""
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


@checked
def open_sweep(store: str | os.PathLike[str]):
    """The cases of a sweep store (``phsplit sweep``) as one dataset with a ``case`` dimension,
    opened lazily through Dask, in the order of the sweep file, from files of one case
    (``cases/<id>.nc``) and batch files (``cases/batch_<digest>.nc``, a large sweep's cases
    stacked along ``case``) alike. Cases that did not run (invalid parameters) are left out;
    ``summary.nc`` lists every case with its status. The varied parameters are coordinates along
    ``case``, and ``case_id`` names each."""
    import json

    import xarray as xr

    root = os.fspath(store)
    meta = os.path.join(root, "sweep.json")
    if not os.path.isfile(meta):
        raise _core.InvalidInputError(f"{root!r} is not a sweep store (no sweep.json in it)")
    try:
        with open(meta) as f:
            cases = json.load(f)["cases"]
        if not isinstance(cases, dict):
            raise TypeError
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError):
        raise _core.InvalidInputError(f"{meta!r} is damaged: a sweep store's sweep.json is the JSON object "
                                      f"phsplit sweep writes, with its cases") from None
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


def write_sweep_file(store: str, content: dict) -> None:
    """``STORE/sweep.json``, whole or not at all."""
    tmp = temporary_beside(os.path.join(store, "sweep.json"))
    with open(tmp, "w") as f:
        json.dump(content, f, indent=1, default=repr)
    publish(tmp, os.path.join(store, "sweep.json"))


def remove_temporaries(store: str) -> None:
    """The temporary files a writer left in ``STORE/cases`` when it was killed mid-write."""
    d = os.path.join(store, "cases")
    for f in os.listdir(d):
        if f.startswith(".tmp-"):
            os.unlink(os.path.join(d, f))
