"""Files on disk: opening a phsplit result (:func:`open_dataset`) and writing files whole or not
at all (:func:`publish`, :func:`temporary_beside`, :class:`PartialFile`).

Every file phsplit writes is first written under a hidden temporary name in the folder of its
destination and then renamed into place, so a reader never sees a partial file and Ctrl-C
leaves the previous file (or none). A run's output is written through a :class:`PartialFile`:
the temporary file has a fixed name, ``.<file name>.part``, and is itself locked for the whole run,
so a second run writing the same output is refused, and nothing but the output stays behind.
"""
from __future__ import annotations

import os
import tempfile
from typing import Any

from . import _core


#: The first bytes of a NetCDF file: classic (CDF 1, 2, 5) or NetCDF-4 (HDF5).
NETCDF_SIGNATURES = (b"CDF\x01", b"CDF\x02", b"CDF\x05", b"\x89HDF\r\n\x1a\n")


def open_dataset(path: str | os.PathLike[str], **kw: Any):
    """Open a phsplit result (NetCDF) as an ``xarray.Dataset``, lazily.

    Time stays in seconds (``decode_times=False``: the CF epoch of the file is nominal). Other
    keywords go to ``xarray.open_dataset``. A file that does not exist, is not NetCDF or was not
    written by phsplit raises :class:`phsplit.InvalidInputError`."""
    import xarray as xr

    if not isinstance(path, (str, os.PathLike)):
        raise _core.InvalidInputError(f"path must be a file's path (a str or os.PathLike), got {type(path).__name__}")
    p = os.fspath(path)
    if not isinstance(p, str):
        p = os.fsdecode(p)
    if not os.path.isfile(p):
        raise _core.InvalidInputError(f"{p!r} does not exist (or is not a file)")
    try:
        with open(p, "rb") as f:
            head = f.read(8)
    except OSError as e:
        raise _core.InvalidInputError(f"{p!r} cannot be read: {e.strerror or e}") from None
    if not head.startswith(NETCDF_SIGNATURES):
        raise _core.InvalidInputError(f"{p!r} is not a NetCDF file (a phsplit result is NetCDF-4: it starts with "
                                      f"HDF5's signature); give the .nc file a run wrote")
    try:
        ds = xr.open_dataset(p, decode_times=False, **kw)
    except (OSError, ValueError, RuntimeError) as e:
        first = (str(e).strip().splitlines() or [type(e).__name__])[0][:200]
        raise _core.InvalidInputError(f"{p!r} is not a NetCDF file phsplit can read: {first}") from None
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


def _lock(fd: int) -> None:
    """An exclusive lock on the open file ``fd``, without waiting (OSError if it is held). An
    open-file-description lock where the system has one (Linux): it belongs to this open file
    alone, so the netCDF library's own ``flock`` on the same file (HDF5 locks a file it writes)
    and its closing of its own descriptors neither conflict with it nor release it."""
    import fcntl
    import struct

    if hasattr(fcntl, "F_OFD_SETLK"):
        # struct flock: l_type, l_whence, l_start, l_len (0: the whole file), l_pid (0 for OFD locks)
        fcntl.fcntl(fd, fcntl.F_OFD_SETLK, struct.pack("hhqqi4x", fcntl.F_WRLCK, os.SEEK_SET, 0, 0, 0))
    else:  # pragma: no cover - systems without OFD locks
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)


class BusyError(Exception):
    """Another process is writing the same output right now."""


class PartialFile:
    """The temporary file of an output being written, ``<folder>/.<file name>.part``, locked
    (exclusively, :func:`_lock`) from creation until it is published or removed: a second process that
    would write the same output finds it locked and raises :class:`BusyError` before touching
    anything. :meth:`publish` renames it onto the output; :meth:`discard` removes it. Either
    drops the lock with the file, so no lock file is left behind. A process that is killed
    leaves the part file unlocked; the next run of the same output takes it over."""

    def __init__(self, path: str):
        self.path = path
        self.part = os.path.join(os.path.dirname(os.path.abspath(path)), f".{os.path.basename(path)}.part")
        while True:
            fd = os.open(self.part, os.O_RDWR | os.O_CREAT, 0o600)
            try:
                _lock(fd)
            except OSError:
                os.close(fd)
                raise BusyError(path) from None
            try:
                same = os.stat(self.part).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            # The file was published or removed between our open and our lock: try again.
            os.close(fd)
        os.ftruncate(fd, 0)
        self._fd = fd

    def publish(self) -> None:
        """The finished file onto the output, atomically; the lock goes with it."""
        publish(self.part, self.path)
        self._close()

    def discard(self) -> None:
        """Remove the temporary file (nothing is written to the output)."""
        try:
            os.unlink(self.part)
        except FileNotFoundError:
            pass
        self._close()

    def _close(self) -> None:
        if self._fd is not None:
            os.close(self._fd)
            self._fd = None
