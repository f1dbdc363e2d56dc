"""A run as consecutive core calls (chunks): how ``phsplit simulate`` runs and writes a long
run, and how :func:`phsplit.rerun` repeats it. A multi-call driver above the runner."""
from __future__ import annotations

from dataclasses import replace
from typing import Callable, Iterator

import numpy as np

from .runner import run
from .settings import Settings
from .solution import Solution
from .vessel import Vessel


def run_chunks(vessel: Vessel, settings: Settings, state: np.ndarray, chunks: list[int],
               progress: Callable[[int], None] | None = None) -> Iterator[Solution]:
    """Run ``settings`` as consecutive calls of ``chunks[i]`` steps each, the next starting from
    the last state of the one before; the last call ends at ``t1`` itself. Stops after a call
    that did not complete. ``progress(steps)`` is called with the number of steps each call
    has done since its last report, while it runs (not only between calls)."""
    t0, t1 = settings.t_span
    t = t0
    for i, k in enumerate(chunks):
        end = t1 if i == len(chunks) - 1 else t + k * settings.h
        # a last chunk of only the final, shorter step takes that step's length as its h
        h = min(settings.h, end - t)
        callback = None
        if progress is not None:
            reported = [0]

            def callback(done, total, _reported=reported):
                progress(done - _reported[0])
                _reported[0] = done
        sol = run(vessel, replace(settings, t_span=(t, end), h=h), state, callback=callback, continuing=True)
        if progress is not None and sol.steps > reported[0]:
            progress(sol.steps - reported[0])
        yield sol
        if sol.status != "completed":
            return
        state = sol.last_good_state
        t = float(sol.t[-1])


def joined(sols: list[Solution]):
    """The chunks' datasets as one, as the CLI writes them (each chunk after the first without
    its first row, which repeats the previous chunk's last)."""
    import xarray as xr

    parts = [s.to_xarray() for s in sols]
    if len(parts) == 1:
        return parts[0]
    timed = [p.isel(time=slice(1, None)) if i else p for i, p in enumerate(parts)]
    ds = xr.concat(timed, dim="time", data_vars="minimal", coords="minimal", compat="override",
                   combine_attrs="override")
    for k, values in motion_of(sols).items():   # the whole run's, not the first chunk's
        if f"{k}_statistics" in ds:
            ds[f"{k}_statistics"].values[:] = values
    return ds


def motion_of(sols: list[Solution]) -> dict[str, list[float]]:
    """The motion statistics of the chunks joined (each after the first without its first row):
    heave (m), roll and pitch (rad), the numbers of ``solution.MOTION_STATISTICS`` over every
    saved sample, as one Solution's ``motion_statistics`` computes them."""
    from .solution import MOTION_STATISTICS, statistics_of

    sig = {"heave": [sols[0].x[:, 2]] + [s.x[1:, 2] for s in sols[1:]],
           "roll": [sols[0].euler[:, 0]] + [s.euler[1:, 0] for s in sols[1:]],
           "pitch": [sols[0].euler[:, 1]] + [s.euler[1:, 1] for s in sols[1:]]}
    st = statistics_of({k: np.concatenate(parts) for k, parts in sig.items()})
    return {k: [st[k][n] for n in MOTION_STATISTICS] for k in st}
