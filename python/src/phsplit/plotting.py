"""Figures (matplotlib, headless)."""
from __future__ import annotations

import os

import numpy as np

from . import _core
from .files import publish, temporary_beside
from ._arguments import checked


@checked
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
            _legend_outside(ax, ncol=1)
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
    """Write the figure to ``path`` whole or not at all (a temporary file, then a rename)."""
    tmp = temporary_beside(path)
    try:
        fig.savefig(tmp, dpi=110)
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def reference_of(vessel) -> dict:
    c = vessel.to_dict()["control"]
    xr, er = np.asarray(c["position_reference"]), np.asarray(c["euler_reference"])
    return {"x": xr[0], "y": xr[1], "z": xr[2], "roll": er[0], "pitch": er[1], "yaw": er[2]}


#: The variables the DP figure needs, with their dimensions beyond time and the sizes there.
NEEDED = {"position": 3, "euler": 3, "energy": None}


def check_plottable(ds, where: str = "the result") -> None:
    """Refuse a result the DP figure cannot be drawn from, naming what is missing or damaged:
    a time axis, the variables of :data:`NEEDED` along it (a vector of the stated size at each
    time), and a readable vessel record (``phsplit_vessel``) if it has one."""
    import tomllib

    if "time" not in ds.dims or ds.sizes["time"] < 1:
        raise _core.InvalidInputError(f"{where!r} holds no run to plot (no saved times)")
    for name, width in NEEDED.items():
        if name not in ds:
            raise _core.InvalidInputError(f"{where!r} has no {name!r} variable, which the DP figure needs "
                                          f"(it needs {', '.join(NEEDED)})")
        v = ds[name]
        shape_ok = v.dims[:1] == ("time",) and (v.ndim == 1 if width is None else v.ndim == 2 and v.shape[1] == width)
        if not shape_ok or v.dtype.kind not in "fiu":
            want = "one number" if width is None else f"{width} numbers"
            raise _core.InvalidInputError(f"{where!r}: the variable {name!r} is damaged: it must hold {want} at each "
                                          f"time, got dims {v.dims} and type {v.dtype}")
    if "phsplit_vessel" in ds.attrs:
        try:
            c = tomllib.loads(str(ds.attrs["phsplit_vessel"])).get("control")
            if c:
                for k in ("position_reference", "euler_reference"):
                    if np.asarray(c[k], dtype=float).shape != (3,):
                        raise ValueError(k)
        except (tomllib.TOMLDecodeError, KeyError, TypeError, ValueError, AttributeError):
            raise _core.InvalidInputError(f"{where!r}: the phsplit_vessel attribute is damaged (not a vessel file "
                                          "with its [control] set point)") from None


@checked
def plot_dp(ds, path: str, watch_circle: float | None = None, title: str | None = None) -> None:
    """The main figure of a DP run, from a result dataset (``Solution.to_xarray()`` or a file
    opened with ``phsplit.open_dataset``), written atomically to ``path``:

    * the horizontal track (spatial x, y; z up) with the set point, the start and, if given, a
      watch circle of radius ``watch_circle`` m about the set point;
    * the horizontal distance to the set point and the heading error (degrees, wrapped);
    * roll and pitch (degrees) and heave z (m);
    * the controller's force (surge, sway; kN) and yaw moment (MN m), body frame;
    * the stored energy H and the energy booked by each ledger account since the start (MJ);
    * for an operation (a moving set point, a pipe, thrusters): the desired track and the pipe's
      touchdown points on the track, the offset from the desired position, and a fourth row with
      the pipe's top tension and departure angle and the thrusters' thrusts and utilisation.

    A dotted line marks the start of the controller. Every legend is outside its axes' data
    area, and curves that can coincide (roll and pitch, the thrusters, the ledger's accounts)
    differ in line style as well as colour, the later ones drawn thinner over the earlier, so
    none hides another."""
    import matplotlib.pyplot as plt

    fig = dp_figure(ds, watch_circle=watch_circle, title=title)
    try:
        _save(fig, path)
    finally:
        plt.close(fig)


#: Line styles for curves that can coincide, in the order they are drawn: each a dash pattern
#: that leaves the earlier, wider curves visible through its gaps.
STYLES = ("-", (0, (5, 2)), (0, (1, 1.5)), (0, (6, 2, 1, 2)), (0, (3, 1, 1, 1, 1, 1)), (0, (8, 3)))


#: Markers of the same curves, a few along each, at places that differ from curve to curve.
MARKERS = ("o", "s", "^", "v", "D", "x", "P", "*")


def _style(i: int, n: int | None = None) -> dict:
    """The ``i``-th of several curves (``n`` samples) that may coincide: colour, dash pattern,
    a width that decreases (a later curve on top of an earlier one leaves it visible) and, for a
    curve of ``n`` samples, a few markers of its own shape, placed where the others have none."""
    style = {"color": f"C{i % 10}", "ls": STYLES[i % len(STYLES)], "lw": max(0.8, 2.0 - 0.3 * i)}
    if n is not None and n >= 16:
        every = max(1, n // 8)
        style.update(marker=MARKERS[i % len(MARKERS)], ms=4.5, markevery=((every // 2 + i * max(1, every // 6)) % every, every))
    return style


def _legend_outside(ax, ncol: int = 2, fontsize: float = 7.5, handles=None) -> None:
    """A legend above the axes, outside its data area (constrained layout makes room)."""
    if handles is None:
        handles, labels = ax.get_legend_handles_labels()
    else:
        labels = [h.get_label() for h in handles]
    if handles:
        # as many columns as the axes' width holds at this size (about 80 characters)
        ncol = max(1, min(ncol, len(handles), 80 // (max(len(s) for s in labels) + 8)))
        ax.legend(handles, labels, loc="lower left", bbox_to_anchor=(0.0, 1.01, 1.0, 0.1), mode="expand",
                  ncol=ncol, fontsize=fontsize, borderaxespad=0.0, frameon=False)


@checked
def dp_figure(ds, watch_circle: float | None = None, title: str | None = None):
    """The figure of :func:`plot_dp` (a matplotlib Figure; the caller closes it)."""
    import tomllib

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = np.asarray(ds["time"].values, dtype=float)
    x = np.asarray(ds["position"].values)
    eul = np.degrees(np.asarray(ds["euler"].values))
    ref_x = ref_e = None
    if "phsplit_vessel" in ds.attrs:
        c = tomllib.loads(ds.attrs["phsplit_vessel"]).get("control")
        if c:
            ref_x, ref_e = np.asarray(c["position_reference"]), np.degrees(np.asarray(c["euler_reference"]))
    tc = ds.attrs.get("control_start_s", "none")
    tc = None if isinstance(tc, str) else float(tc)

    moving = "setpoint_x" in ds
    piped = "pipe_top_tension" in ds
    thrust = "thrust_utilisation" in ds
    env = [a for a in ("current", "wind", "waves", "wave_drift", "external") if f"force_{a}" in ds]
    rows = 4 if (piped or thrust or env) else 3
    fig = plt.figure(figsize=(15, 3 * rows), layout="constrained")
    gs = fig.add_gridspec(rows, 3)
    ax_track = fig.add_subplot(gs[:, 0])
    ax_track.plot(x[:, 1], x[:, 0], lw=1.2, label="track")
    ax_track.plot(x[0, 1], x[0, 0], "o", color="C2", label="start")
    if moving:
        ax_track.plot(ds["setpoint_y"].values, ds["setpoint_x"].values, "k--", lw=1, label="desired (reference model)")
    if piped:
        ax_track.plot(ds["pipe_touchdown_y"].values, ds["pipe_touchdown_x"].values, color="C5", lw=1.2,
                      label="pipe touchdown point")
    if ref_x is not None and not moving:
        ax_track.plot(ref_x[1], ref_x[0], "k+", ms=14, mew=2, label="set point")
        if watch_circle:
            a = np.linspace(0, 2 * np.pi, 361)
            ax_track.plot(ref_x[1] + watch_circle * np.sin(a), ref_x[0] + watch_circle * np.cos(a), "r--", lw=1,
                          label=f"watch circle {watch_circle:g} m")
    ax_track.set_xlabel("y [m]")
    ax_track.set_ylabel("x [m]")
    ax_track.set_aspect("equal", adjustable="datalim")
    ax_track.set_title("horizontal track (spatial frame, z up)")
    ax_track.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.08), ncol=2, frameon=False)
    ax_track.grid(alpha=0.3)

    axes = [fig.add_subplot(gs[i, j]) for i in range(rows) for j in (1, 2)]
    ax_pos, ax_head, ax_rp, ax_heave, ax_ctl, ax_en = axes[:6]
    if moving:
        ax_pos.plot(t, ds["setpoint_offset"].values, **_style(0, len(t)), label="distance")
        if "route_cross_track" in ds:
            ax_pos.plot(t, ds["route_cross_track"].values, **_style(1, len(t)), label="across the route")
            ax_pos.plot(t, ds["route_along_track"].values, **_style(2, len(t)), label="along the route")
            _legend_outside(ax_pos, ncol=3)
        ax_pos.set_ylabel("offset from desired position [m]")
        err = eul[:, 2] - np.degrees(np.asarray(ds["setpoint_heading"].values))
        ax_head.plot(t, (err + 180.0) % 360.0 - 180.0, lw=1.2)
        ax_head.set_ylabel("heading error [deg]")
    elif ref_x is not None:
        ax_pos.plot(t, np.hypot(x[:, 0] - ref_x[0], x[:, 1] - ref_x[1]), lw=1.2)
        ax_pos.set_ylabel("distance to set point [m]")
        if watch_circle:
            ax_pos.axhline(watch_circle, color="r", ls="--", lw=1, label="watch circle")
            _legend_outside(ax_pos)
        ax_head.plot(t, (eul[:, 2] - ref_e[2] + 180.0) % 360.0 - 180.0, lw=1.2)
        ax_head.set_ylabel("heading error [deg]")
    else:
        ax_pos.plot(t, x[:, 0], **_style(0, len(t)), label="x")
        ax_pos.plot(t, x[:, 1], **_style(1, len(t)), label="y")
        ax_pos.set_ylabel("position [m]")
        _legend_outside(ax_pos)
        ax_head.plot(t, eul[:, 2], lw=1.2)
        ax_head.set_ylabel("yaw [deg]")
    # roll (usually the smaller) over pitch: neither hides the other
    ax_rp.plot(t, eul[:, 1], **_style(1, len(t)), label="pitch", zorder=2)
    ax_rp.plot(t, eul[:, 0], **_style(0, len(t)), label="roll", zorder=3)
    ax_rp.set_ylabel("roll, pitch [deg]")
    _legend_outside(ax_rp)
    ax_heave.plot(t, x[:, 2], lw=1.1)
    ax_heave.set_ylabel("heave z [m]")
    if "control_force" in ds:
        f = np.asarray(ds["control_force"].values) / 1e3
        mz = np.asarray(ds["control_moment"].values)[:, 2] / 1e6
        ax_ctl.plot(t, f[:, 0], **_style(0, len(t)), label="surge force [kN]")
        ax_ctl.plot(t, f[:, 1], **_style(1, len(t)), label="sway force [kN]")
        ax2 = ax_ctl.twinx()
        ax2.plot(t, mz, **_style(2, len(t)), label="yaw moment [MN m] (right)")
        ax2.set_ylabel("yaw moment [MN m]", color="C2")
        _legend_outside(ax_ctl, ncol=3, handles=ax_ctl.get_lines() + ax2.get_lines())
    ax_ctl.set_ylabel("controller force [kN]")
    ax_en.plot(t, np.asarray(ds["energy"].values) / 1e6, color="k", ls="-", lw=2.2, label="stored H")
    k = 0
    for name in ds.data_vars:
        if name.startswith("energy_") and name not in ("energy_supplied", "energy_dissipated", "energy_residual"):
            kind = "dissipated" if "dissipated" in ds[name].attrs.get("long_name", "") else "supplied"
            ax_en.plot(t, np.cumsum(np.nan_to_num(ds[name].values)) / 1e6, **_style(k, len(t)),
                       label=f"{name[7:]} ({kind}, cumulative)")
            k += 1
    ax_en.set_ylabel("energy [MJ]")
    _legend_outside(ax_en, ncol=2, fontsize=6.5)
    if rows == 4:
        ax_pipe, ax_thr = axes[6:8]
        if env and not piped:
            # the environment's horizontal force on the hull, by source (spatial frame)
            Q = np.asarray(ds["attitude"].values) if "attitude" in ds else None
            for k, a in enumerate(env):
                fb = np.asarray(ds[f"force_{a}"].values)
                fs = np.einsum("nij,nj->ni", Q, fb) if Q is not None else fb
                ax_pipe.plot(t, np.hypot(fs[:, 0], fs[:, 1]) / 1e3, **_style(k, len(t)), label=a)
            ax_pipe.set_ylabel("horizontal force by source [kN]")
            _legend_outside(ax_pipe, ncol=len(env))
        elif piped and "pipe_departure_angle" not in ds:
            # The dynamic (lumped-mass) pipe: the tensions at its ends and its suspended length.
            ax_pipe.plot(t, ds["pipe_top_tension"].values / 1e3, **_style(0, len(t)), label="top tension [kN]")
            ax_pipe.plot(t, ds["pipe_anchor_tension"].values / 1e3, **_style(1, len(t)), label="anchor tension [kN]")
            ax_pipe.set_ylabel("pipe tension [kN]")
            ax3 = ax_pipe.twinx()
            ax3.plot(t, ds["pipe_suspended_length"].values, **_style(2, len(t)), label="suspended length [m] (right)")
            _legend_outside(ax_pipe, ncol=3, handles=ax_pipe.get_lines() + ax3.get_lines())
        elif piped:
            ax_pipe.plot(t, ds["pipe_top_tension"].values / 1e3, **_style(0, len(t)), label="top tension [kN]")
            ax_pipe.plot(t, ds["pipe_horizontal_tension"].values / 1e3, **_style(1, len(t)), label="horizontal tension [kN]")
            ax_pipe.set_ylabel("pipe tension [kN]")
            ax3 = ax_pipe.twinx()
            ax3.plot(t, ds["pipe_departure_angle"].values, **_style(2, len(t)), label="departure angle [deg] (right)")
            ax3.set_ylabel("departure angle [deg]", color="C2")
            _legend_outside(ax_pipe, ncol=3, handles=ax_pipe.get_lines() + ax3.get_lines())
        else:
            ax_pipe.set_axis_off()
        if thrust:
            i = 0
            while f"thruster{i}_thrust" in ds:
                ax_thr.plot(t, ds[f"thruster{i}_thrust"].values / 1e3, **_style(i, len(t)), label=f"thruster {i} [kN]")
                i += 1
            ax_thr.set_ylabel("thrust [kN]")
            ax4 = ax_thr.twinx()
            ax4.plot(t, ds["thrust_utilisation"].values, color="k", ls=(0, (1, 2)), lw=1.0,
                     label="utilisation (right)")
            ax4.set_ylabel("utilisation (dotted)")
            ax4.set_ylim(0, 1.05)
            _legend_outside(ax_thr, ncol=3, handles=ax_thr.get_lines() + ax4.get_lines())
        elif env and "wave_elevation" in ds:
            ax_thr.plot(t, ds["wave_elevation"].values, **_style(0, len(t)), label="wave elevation [m]")
            ax_thr.set_ylabel("wave elevation [m]")
            handles = ax_thr.get_lines()
            if "wind_speed" in ds:
                ax5 = ax_thr.twinx()
                ax5.plot(t, ds["wind_speed"].values, **_style(1, len(t)), label="wind speed [m/s] (right)")
                ax5.set_ylabel("wind speed [m/s]", color="C1")
                handles = handles + ax5.get_lines()
            _legend_outside(ax_thr, handles=handles)
        else:
            ax_thr.set_axis_off()
    for ax in axes:
        ax.grid(alpha=0.3)
        if tc is not None and t[0] <= tc <= t[-1]:
            ax.axvline(tc, color="0.5", ls=":", lw=1)
    for ax in axes[-2:]:
        ax.set_xlabel("t [s]")
    if tc is not None and t[0] <= tc <= t[-1]:
        ax_pos.annotate("controller on", (tc, 0.0), xycoords=("data", "axes fraction"), fontsize=8, color="0.4",
                        xytext=(3, 3), textcoords="offset points")
    fig.suptitle(title or f"{ds.attrs.get('method', '').upper()}, h = {ds.attrs.get('step_size_s', '?')} s — "
                 f"{ds.attrs.get('status', '')}, t = {t[0]:g} … {t[-1]:g} s")
    return fig


@checked
def plot_pipe(ds, path: str, snapshots: int = 8, title: str | None = None) -> None:
    """The dynamic pipe's figure (docs/model.md §5.18), from a result dataset, written
    atomically to ``path``: its profile in its vertical plane at ``snapshots`` times and its
    envelope over the run (horizontal distance from the anchor and height, m), the tensions at
    its ends and the touchdown's horizontal distance from the anchor over time."""
    import matplotlib.pyplot as plt

    fig = pipe_figure(ds, snapshots=snapshots, title=title)
    try:
        _save(fig, path)
    finally:
        plt.close(fig)


@checked
def pipe_figure(ds, snapshots: int = 8, title: str | None = None):
    """The figure of :func:`plot_pipe`, not yet written."""
    import matplotlib.pyplot as plt

    from .pipe import profile

    x, z = profile(ds)
    t = ds["time"].values
    fig, (ax_shape, ax_t) = plt.subplots(2, 1, figsize=(10, 8), gridspec_kw={"height_ratios": [3, 2]})
    idx = np.unique(np.linspace(0, len(t) - 1, max(snapshots, 1)).round().astype(int))
    for k, i in enumerate(idx):
        ax_shape.plot(x[i], z[i], color=plt.cm.viridis(k / max(len(idx) - 1, 1)), lw=1.0,
                      label=f"t = {t[i]:.0f} s")
    # The envelope: the lowest and highest height of each node over the run.
    ax_shape.fill_between(np.median(x, axis=0), z.min(axis=0), z.max(axis=0), color="0.7", alpha=0.5,
                          label="envelope of the nodes")
    ax_shape.axhline(z[0, -1], color="0.3", lw=0.8)
    ax_shape.set_xlabel("horizontal distance from the anchor [m]")
    ax_shape.set_ylabel("height, z up [m]")
    ax_shape.grid(alpha=0.3)
    _legend_outside(ax_shape, ncol=min(len(idx) + 1, 5))
    ax_t.plot(t, ds["pipe_top_tension"].values / 1e3, **_style(0, len(t)), label="top tension [kN]")
    ax_t.plot(t, ds["pipe_anchor_tension"].values / 1e3, **_style(1, len(t)), label="anchor tension [kN]")
    ax_t.set_xlabel("t [s]")
    ax_t.set_ylabel("tension [kN]")
    ax_t.grid(alpha=0.3)
    ax2 = ax_t.twinx()
    a = np.asarray(ds["pipe_node_position"].attrs.get("anchor", [np.nan] * 3), float)
    td = np.hypot(ds["pipe_touchdown_x"].values - a[0], ds["pipe_touchdown_y"].values - a[1])
    ax2.plot(t, td, **_style(2, len(t)), label="touchdown from the anchor [m] (right)")
    _legend_outside(ax_t, ncol=3, handles=ax_t.get_lines() + ax2.get_lines())
    fig.suptitle(title or "the dynamic pipe: profile, envelope and tensions")
    fig.tight_layout()
    return fig


@checked
def plot_rao(ds, path: str, title: str | None = None) -> None:
    """An RAO dataset of :func:`phsplit.rao` (one heading, or several along ``heading`` as
    ``phsplit rao`` writes it), written atomically to ``path``: per DOF the amplitude per unit
    wave amplitude against frequency, the frequency domain as lines and the time domain as
    markers, one colour per heading."""
    import matplotlib.pyplot as plt

    dofs = [k[: -len("_amplitude")] for k in ds.data_vars if k.endswith("_amplitude")]
    headings = ds["heading"].values if "heading" in ds.dims else [ds.attrs.get("heading")]
    fig, axes = plt.subplots(1, len(dofs), figsize=(4.2 * len(dofs), 3.6), squeeze=False)
    w = ds["frequency"].values
    for ax, k in zip(axes[0], dofs):
        rot = k in ("roll", "pitch", "yaw")
        scale = 180.0 / np.pi if rot else 1.0
        for j, hd in enumerate(headings):
            row = ds.sel(heading=hd) if "heading" in ds.dims else ds
            c = f"C{j}"
            ax.plot(w, scale * row[f"{k}_amplitude_frequency_domain"].values, "-", color=c, lw=1.2,
                    label=f"{hd:g}°, frequency domain")
            ax.plot(w, scale * row[f"{k}_amplitude"].values, "o", color=c, ms=4, mfc="none",
                    label=f"{hd:g}°, time domain")
        ax.set_xlabel("wave frequency (rad/s)")
        ax.set_ylabel(f"{k} ({'deg' if rot else 'm'} per m of wave amplitude)")
        ax.set_title(k)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    try:
        _save(fig, path)
    finally:
        plt.close(fig)
