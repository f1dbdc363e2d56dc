"""The dynamic pipe (docs/model.md §5.18): a vessel file's lumped-mass line (``[pipe]`` with
``model = "lumped_mass"``) driven at its top alone, and its shape in a run's results.

>>> import numpy as np, phsplit
>>> v = phsplit.Vessel.from_toml(PIPE_VESSEL_TOML)            # doctest: +SKIP
>>> t = np.linspace(0.0, 100.0, 1001)
>>> tops = np.column_stack([2 * np.sin(0.6 * t), 0 * t, -10 + np.sin(0.6 * t)])
>>> r = phsplit.pipe.drive(v, t, tops)                          # doctest: +SKIP
>>> r["segment_tension"]                                        # doctest: +SKIP
"""
from __future__ import annotations

import numpy as np

from . import _core
from ._arguments import checked

__all__ = ["drive", "node_positions", "profile"]


@checked
def drive(vessel, times, tops) -> dict[str, np.ndarray]:
    """Drive ``vessel``'s dynamic pipe with its top at ``tops[i]`` (m, spatial, shape (n, 3)) at
    ``times[i]`` (s, increasing), from its static shape under ``tops[0]``, with the core's
    passive step between the times (the discrete gradient, docs/model.md §5.18), as a line code
    is driven with a prescribed fairlead motion.

    Returns numpy arrays per time: ``segment_tension`` (the top segment's, N: MoorDyn's
    fairlead tension), ``top_tension`` (the force at the top with half a segment's weight, N),
    ``storage`` (the line's energy, J) and, since the previous time, ``top_work`` (done on the
    line at its top), ``drag``, ``axial_damping``, ``seabed`` (dissipated) and ``current``
    (supplied), J; and ``nodes`` (the positions at the end, m, shape (N + 1, 3)). The energy
    closes: ``diff(storage) == top_work + current - drag - axial_damping - seabed``."""
    from .vessel import Vessel

    if not isinstance(vessel, Vessel):
        raise _core.InvalidInputError(f"vessel must be a phsplit.Vessel with a dynamic pipe, got {type(vessel).__name__}")
    try:
        t = np.ascontiguousarray(times, dtype=np.float64)
    except (TypeError, ValueError):
        raise _core.InvalidInputError(f"times must be increasing numbers (s), got {times!r}") from None
    try:
        x = np.ascontiguousarray(tops, dtype=np.float64)
    except (TypeError, ValueError):
        raise _core.InvalidInputError(f"tops must be one row of 3 numbers (m, spatial) per time, got {tops!r}") from None
    if t.ndim != 1 or t.size < 2:
        raise _core.InvalidInputError(f"times must be at least two increasing numbers (s), got {times!r}")
    if x.ndim != 2 or x.shape != (t.size, 3):
        raise _core.InvalidInputError(f"tops must be one row of 3 numbers (m, spatial) per time: {t.size} rows, "
                                      f"got shape {x.shape}")
    out = _core.drive_pipe(vessel._inner, t, x)
    return {k: np.asarray(v, dtype=np.float64) for k, v in out.items()}


@checked
def node_positions(ds) -> np.ndarray:
    """The pipe's node positions in a run's dataset (m, spatial), shape (time, node, 3): the
    top (node 0, on the hang-off point), the free nodes, and the anchor (the last)."""
    if "pipe_node_position" not in ds:
        raise _core.InvalidInputError("the dataset has no dynamic pipe (pipe_node_position): its vessel's [pipe] "
                                      "needs model = \"lumped_mass\"")
    top = np.stack([ds["pipe_top_x"].values, ds["pipe_top_y"].values, ds["pipe_top_z"].values], axis=-1)
    free = ds["pipe_node_position"].values
    anchor = np.broadcast_to(np.asarray(ds["pipe_node_position"].attrs["anchor"], float), top.shape)
    return np.concatenate([top[:, None, :], free, anchor[:, None, :]], axis=1)


@checked
def profile(ds) -> tuple[np.ndarray, np.ndarray]:
    """The pipe's profile in its vertical plane: the horizontal distance of each node from the
    anchor and its height (m), each of shape (time, node)."""
    q = node_positions(ds)
    a = q[:, -1:, :2]
    return np.linalg.norm(q[:, :, :2] - a, axis=-1), q[:, :, 2]
