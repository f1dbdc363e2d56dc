"""No hang on the way to a cluster: a sweep's cluster arguments are checked before anything is
written or started, and an address that cannot serve as a Dask scheduler is a one-line error
well within 10 s, whether nothing listens there, something listens and says nothing, or
something else answers."""
from __future__ import annotations

import contextlib
import io
import os
import socket
import threading
import time

import pytest

from phsplit import batch
from phsplit.cli import main

SWEEP = ('[simulation]\nh = 1.0\nt_span = [0.0, 2.0]\n[sweep]\nmode = "random"\nsamples = 2\nseed = 1\n'
         '[sweep.parameters]\n"vessel.mass" = {low = 6e6, high = 7e6}\n')


@contextlib.contextmanager
def _server(greeting: bytes | None):
    """A TCP server on 127.0.0.1 that accepts connections and sends ``greeting`` (``None``:
    says nothing, holding the connection open; ``b""``: closes it at once)."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    stop = threading.Event()
    held = []

    def serve():
        srv.settimeout(0.1)
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
            except OSError:
                continue
            held.append(conn)
            if greeting == b"":
                conn.close()
            elif greeting is not None:
                conn.sendall(greeting)

    th = threading.Thread(target=serve, daemon=True)
    th.start()
    try:
        yield f"tcp://127.0.0.1:{srv.getsockname()[1]}"
    finally:
        stop.set()
        th.join()
        for c in held:
            c.close()
        srv.close()


def _sweep(tmp_path, *extra: str) -> tuple[int, str, float]:
    (tmp_path / "s.toml").write_text(SWEEP)
    err = io.StringIO()
    t0 = time.monotonic()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(["sweep", str(tmp_path / "s.toml"), "--out", str(tmp_path / "st"), "--no-progress", *extra])
    return code, err.getvalue(), time.monotonic() - t0


@pytest.mark.parametrize("greeting, says", [
    (None, "no answer within 3 s"),
    (b"HTTP/1.1 400 Bad Request\r\n\r\n", "not as a dask scheduler"),
    (b"", "not as a dask scheduler"),  # accepts, then closes at once
])
def test_an_address_that_is_no_scheduler_fails_in_one_line_within_seconds(tmp_path, greeting, says):
    with _server(greeting) as addr:
        code, err, dt = _sweep(tmp_path, "--scheduler", addr)
    assert code == 2 and len(err.strip().splitlines()) == 1 and says in err, err
    assert dt < batch.CONNECT_TIMEOUT + 2.0 < 10.0, dt
    assert not (tmp_path / "st").exists()  # the store was never created


def test_a_refused_connection_and_bad_worker_counts_fail_at_once(tmp_path):
    port = socket.socket()
    port.bind(("127.0.0.1", 0))
    free = port.getsockname()[1]
    port.close()  # nothing listens there now
    for extra, says in ((["--scheduler", f"tcp://127.0.0.1:{free}"], "cannot reach the scheduler"),
                        (["--workers", "-2"], "--workers must be an integer from 1"),
                        (["--workers", "0"], "--workers must be an integer from 1")):
        code, err, dt = _sweep(tmp_path, *extra)
        assert code == 2 and says in err and "Traceback" not in err, (extra, err)
        assert dt < 2.0, (extra, dt)
        assert sorted(os.listdir(tmp_path)) == ["s.toml"], (extra, os.listdir(tmp_path))


def test_a_real_scheduler_passes_the_check():
    from dask.distributed import LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://", host="127.0.0.1",
                      dashboard_address=None) as cluster:
        assert cluster.scheduler_address.startswith("tcp://")
        batch.check_cluster(cluster.scheduler_address)  # no error: its greeting is Dask's
