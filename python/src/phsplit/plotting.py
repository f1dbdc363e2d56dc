"""Figures (matplotlib, headless)."""
from __future__ import annotations

import os
import tempfile

import numpy as np


def plot_positions(sol, path: str, reference: dict | None = None, title: str | None = None) -> None:
    """x, y, z, roll, pitch, yaw against time (the paper's Fig. 2), written atomically to ``path``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(12, 6), sharex=True, layout="constrained")
    series = [(sol.x[:, 0], "x [m]"), (sol.x[:, 1], "y [m]"), (sol.x[:, 2], "z [m]"),
              (sol.euler[:, 0], "roll φ [rad]"), (sol.euler[:, 1], "pitch θ [rad]"),
              (sol.euler[:, 2], "yaw ψ [rad]")]
    ref = reference or {}
    for ax, (y, label) in zip(axes.flat, series):
        ax.plot(sol.t, y, lw=1.4)
        key = label.split(" ")[0]
        if key in ref:
            ax.axhline(ref[key], color="k", ls="--", lw=0.8, label=f"reference {ref[key]:g}")
            ax.legend(loc="best", fontsize=8)
        if sol.control_start is not None:
            ax.axvline(sol.control_start, color="0.6", ls=":", lw=0.8)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("t [s]")
    fig.suptitle(title or f"{sol.method.upper()}, h = {sol.h:g} s (controller on at t = {sol.control_start})")
    _save(fig, path)
    plt.close(fig)


def _save(fig, path: str) -> None:
    d = os.path.dirname(os.path.abspath(path))
    ext = os.path.splitext(path)[1]
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".tmp-", suffix=ext)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=110)
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def publish(tmp: str, path: str) -> None:
    """Move a finished temporary file into place atomically, with the usual permissions
    (mkstemp creates files readable by their owner only)."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    os.replace(tmp, path)


def reference_of(vessel) -> dict:
    c = vessel.to_dict()["control"]
    xr, er = np.asarray(c["position_reference"]), np.asarray(c["euler_reference"])
    return {"x": xr[0], "y": xr[1], "z": xr[2], "roll": er[0], "pitch": er[1], "yaw": er[2]}
