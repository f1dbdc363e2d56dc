"""CF-1.8 conventions of every file phsplit writes: the global attributes (:func:`global_attrs`)
and the finishing of a dataset (:func:`finish`: units, long names, flags, no 64-bit integers,
no fill value on coordinates). Every writer (``Solution.to_xarray``, the CLI's run files, sweep
stores, ``simulate_many``, the reproduction's data) goes through this module."""
from __future__ import annotations

import datetime
import platform

import numpy as np

from . import _core

REFERENCES = ("E. Celledoni, E. H. Hoiseth, N. Ramzina, Passivity-preserving splitting methods for rigid body "
              "systems, Multibody Syst. Dyn. 44 (2018) 251-275, arXiv:1408.2544")

#: The epoch of the files' time coordinate (nominal: t = 0 of every run).
TIME_UNITS = "seconds since 1970-01-01 00:00:00"


def utc_now() -> str:
    """The current time, ISO 8601 in UTC to the second (for ``history``)."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def software_versions() -> str:
    """phsplit's version and those of the libraries its results depend on."""
    out = [f"phsplit {_core.__version__}", f"python {platform.python_version()}", f"numpy {np.__version__}"]
    for mod in ("xarray", "netCDF4"):
        try:
            out.append(f"{mod} {__import__(mod).__version__}")
        except ImportError:  # pragma: no cover - both are dependencies
            pass
    return ", ".join(out)


def global_attrs(title: str, what: str, source: str | None = None) -> dict[str, str]:
    """The CF global attributes of a file phsplit writes: ``Conventions``, ``title``,
    ``institution``, ``source``, ``history`` (now, and ``what`` made it), ``references``,
    ``phsplit_version``."""
    return {
        "Conventions": "CF-1.8",
        "title": title,
        "institution": "phsplit",
        "source": source or f"phsplit {_core.__version__}",
        "history": f"{utc_now()} phsplit {_core.__version__}: {what}",
        "references": REFERENCES,
        "phsplit_version": _core.__version__,
    }


def finish(ds, title: str, what: str):
    """Make a dataset phsplit writes CF-1.8 conforming: the global attributes
    (:func:`global_attrs`), ``units`` and ``long_name`` on every variable (``"1"`` and the name
    in words where the writer gave none), booleans as ``int8`` flags, labels along a dimension
    as auxiliary coordinates (``<dim>_name``) instead of string coordinate variables, and no fill
    value on coordinates. Returns the dataset (a copy)."""
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
    ds.attrs = {
        **global_attrs(title, what),
        **{k: v for k, v in ds.attrs.items() if k not in ("Conventions", "title", "history")},
    }
    return ds
