"""The command line's handling of SIGINT and SIGTERM.

Both raise :class:`KeyboardInterrupt` where the main thread is, so the files being staged are
removed on the way out, and both are recorded: Python drops an exception raised inside a
weakref callback or a finaliser ("Exception ignored in ..."), and a signal that arrives there
would otherwise be lost and the command would finish and publish as if it had not come. A
command checks :func:`received` before it publishes.
"""
from __future__ import annotations

_received = False


def handler(signum, frame):
    """SIGINT and SIGTERM while a ``phsplit`` command runs: recorded, then raised."""
    global _received
    _received = True
    raise KeyboardInterrupt


def received() -> bool:
    """Whether a SIGINT or SIGTERM has come since the command started."""
    return _received


def forget_escaped_interrupt() -> None:
    """Let ``python -m phsplit`` end with the status the command returned after an interrupt.

    CPython notes a KeyboardInterrupt that leaves code evaluated through ``PyRun_String``
    (Cython's limited-API modules, netCDF4's and cftime's among them, run code that way), and
    at the end of ``python -m`` kills the process with SIGINT in place of the status returned
    (Modules/main.c, ``Py_RunMain``); the next evaluation on that path clears the note
    (Python/pythonrun.c, ``run_eval_code_obj``). Measured: a SIGTERM in the reproduction study
    ended it with -2, not 130, once in a CI run.
    """
    import sys

    if sys.implementation.name != "cpython":
        return
    try:
        import ctypes

        ctypes.pythonapi.PyRun_SimpleStringFlags(b"", None)
    except (AttributeError, OSError):  # pragma: no cover - a CPython without its C API exported
        pass
