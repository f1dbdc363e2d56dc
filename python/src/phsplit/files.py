"""Files on disk: opening a phsplit result (:func:`open_dataset`) and writing files whole or not
at all (:func:`publish`, :func:`temporary_beside`).

Every file phsplit writes is first written under a hidden temporary name in the folder of its
destination and then renamed into place, so a reader never sees a partial file and Ctrl-C
leaves the previous file (or none).
"""
from __future__ import annotations

import os
import tempfile
from typing import Any

from . import _core


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


def publish(tmp: str, path: str) -> None:
    """Move a finished temporary file into place atomically, with the usual permissions
    (mkstemp creates files readable by their owner only)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, path)


def temporary_beside(path: str, prefix: str = ".tmp-") -> str:
    """A new, empty temporary file in the folder of ``path``, with its extension (for writers
    that choose the format by the name); the caller publishes or removes it."""
    d = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=d, prefix=prefix, suffix=os.path.splitext(path)[1])
    os.close(fd)
    return tmp

