"""The cluster a sweep runs on (:func:`phsplit.batch.run_sweep`): its arguments checked before
anything is started or written, so a bad worker count or an address where no Dask scheduler
answers fails within seconds, with one line; and the warnings of the cases its workers run,
carried back to the client and said there once each."""
from __future__ import annotations

import time
import warnings
from typing import Any, Callable

import numpy as np

from . import _core


#: Most worker processes of a local cluster.
MAX_WORKERS = 512

#: Seconds to wait for a scheduler given by address to accept a connection.
CONNECT_TIMEOUT = 3.0


def check_cluster(scheduler: str | None = None, n_workers: int | None = None) -> None:
    """Refuse cluster arguments that cannot work, before anything is written or started: a
    worker count that is not an integer from 1 to :data:`MAX_WORKERS`, a worker count with a
    scheduler (whose workers are its own), and a scheduler address that is malformed or where
    nothing accepts a connection within :data:`CONNECT_TIMEOUT` seconds."""
    import socket
    from urllib.parse import urlsplit

    if n_workers is not None:
        if isinstance(n_workers, bool) or not isinstance(n_workers, (int, np.integer)) or not (
                1 <= n_workers <= MAX_WORKERS):
            raise _core.InvalidInputError(f"workers must be an integer from 1 to {MAX_WORKERS} (processes of the "
                                          f"local cluster), got {n_workers!r}")
        if scheduler is not None:
            raise _core.InvalidInputError("give workers (a local cluster) or a scheduler (an existing cluster, "
                                          "with its own workers), not both")
    if scheduler is None:
        return
    if not isinstance(scheduler, str) or not scheduler.strip():
        raise _core.InvalidInputError(f"scheduler must be an address like tcp://host:8786, got {scheduler!r}")
    addr = scheduler if "://" in scheduler else "tcp://" + scheduler
    if addr.startswith("inproc://"):
        return  # a scheduler in this process (a LocalCluster with processes=False): the client finds it or fails at once
    try:
        u = urlsplit(addr)
        host, port = u.hostname, u.port
    except ValueError:
        host = port = None
    if u.scheme not in ("tcp", "tls", "ws", "wss") or not host or port is None or u.path not in ("", "/"):
        raise _core.InvalidInputError(f"scheduler must be an address like tcp://host:8786 (tcp, tls, ws or wss, a host "
                                      f"and a port), got {scheduler!r}")
    deadline = time.monotonic() + CONNECT_TIMEOUT
    try:
        with socket.create_connection((host, port), timeout=CONNECT_TIMEOUT) as sock:
            if u.scheme == "tcp":
                # A Dask server greets a new connection with its handshake: a frame whose 8-byte
                # little-endian length is small. Anything else does not speak Dask's protocol.
                head = b""
                while len(head) < 8:
                    sock.settimeout(max(0.05, deadline - time.monotonic()))
                    part = sock.recv(8 - len(head))
                    if not part:
                        break
                    head += part
                if len(head) < 8 or not 0 < int.from_bytes(head, "little") < 2**20:
                    raise _core.InvalidInputError(
                        f"the address {scheduler!r} answers, but not as a dask scheduler (its greeting is not "
                        "Dask's); give the address the scheduler prints (e.g. tcp://host:8786)")
    except OSError as e:
        why = "no answer" if isinstance(e, TimeoutError) else (e.strerror or str(e))
        raise _core.InvalidInputError(f"cannot reach the scheduler {scheduler!r}: {why} within "
                                      f"{CONNECT_TIMEOUT:g} s (is a dask scheduler running there?)") from None


def collecting_warnings(fn: Callable[..., Any], *args) -> tuple[Any, list[tuple[type, str]]]:
    """``fn(*args)`` on a worker, with the warnings it raised as (category, message), returned to
    the client instead of printed by the worker's process (each a line on the terminal, once
    per case and worker, not in the CLI's form)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn(*args)
    return out, [(w.category, str(w.message)) for w in caught]


#: Most distinct warnings of a sweep's cases said one by one (:func:`say_warnings`).
MAX_WARNINGS_SAID = 10


def say_warnings(said: dict[tuple[type, str], int], cases: int) -> None:
    """Each distinct warning of a sweep's cases once, in this process, with the number of times
    the cases raised it (the CLI prints each as one line); the most frequent first, at most
    :data:`MAX_WARNINGS_SAID`, then how many more there were."""
    for k, ((category, message), n) in enumerate(sorted(said.items(), key=lambda kv: -kv[1])):
        if k == MAX_WARNINGS_SAID:
            rest = len(said) - MAX_WARNINGS_SAID
            warnings.warn(f"sweep: {rest} more distinct warning{'s' if rest > 1 else ''} of the cases not shown",
                          UserWarning, stacklevel=3)
            return
        times = f"{n} time{'s' if n != 1 else ''} in {cases} case{'s' if cases != 1 else ''}"
        warnings.warn(f"sweep ({times}): {message}", category, stacklevel=3)
