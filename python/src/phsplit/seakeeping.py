"""Response amplitude operators (RAOs) of a vessel in regular waves: in the time domain, by
phsplit's own runs with a Capytaine dataset's first-order excitation (with or without Cummins'
fluid memory, :mod:`phsplit.radiation`), against the frequency-domain RAO of the same dataset
(docs/how-to/seakeeping-rao.md).

The time domain: the vessel, controller off, from rest in one regular wave of ``amplitude`` at
each frequency; the transients are discarded, and the amplitude and phase of each DOF come from
a least-squares sinusoid ``c₀ + c₁ cos ωt + c₂ sin ωt`` over the last ``periods`` periods.

The frequency domain (T. I. Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*,
2nd ed., 2021, ch. 5; the frequency-domain equation of motion):

    ξ(ω) = [−ω² (M + A(ω)) + iω (B(ω) + D) + C]⁻¹ F(ω),

``M`` the rigid body, ``D`` the vessel's linear damping, ``C`` its restoring linearised about
upright (docs/model.md §2.3), and ``A``, ``B``, ``F`` the dataset's about the body origin
(linear in ω between the dataset's frequencies, exact at them). Both are per unit wave
amplitude, with the phase of ``Re(ξ e^{iωt})`` against the wave elevation ``a cos ωt`` where the
waves' phases are taken (the set point; the output ``wave_elevation``)."""
from __future__ import annotations

import math
import os
import warnings

import numpy as np

from . import _core, cf, hydro, radiation, sea
from ._arguments import checked

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
#: The shipped box of the paper's vessel (dp-weather's dataset).
DEFAULT_DATASET = os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenarios", "paper_box_capytaine.nc")
#: The shipped Capytaine dataset of each shipped vessel that has one (``phsplit rao``'s default).
DATASETS = {"paper": DEFAULT_DATASET,
            "osv": os.path.join(os.path.dirname(os.path.abspath(__file__)), "scenarios", "osv_capytaine.nc")}
_UNITS = {"surge": "m m-1", "sway": "m m-1", "heave": "m m-1", "roll": "rad m-1", "pitch": "rad m-1", "yaw": "rad m-1"}


def _err(msg: str) -> _core.InvalidInputError:
    return _core.InvalidInputError(msg)


def _vessel(vessel, what: str) -> None:
    from .vessel import Vessel

    if not isinstance(vessel, Vessel):
        raise _err(f"{what}: vessel must be a phsplit.Vessel, got {type(vessel).__name__}")


def _skew(r) -> np.ndarray:
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


@checked
def linear_model(vessel):
    """``(M, D, C)`` of a vessel about its body origin, without its added mass: the rigid body's
    mass matrix with the centre of gravity at ``r_g`` (Fossen 2021, eq. 3.44:
    ``[[m I, −m S(r_g)], [m S(r_g), I_g − m S(r_g)²]]``, ``I_g`` the file's inertia about the
    centre of gravity), the linear damping (``damping_matrix`` or the diagonal, plus the linear
    part ``B₁`` of ``[roll_damping]``) and the restoring linearised about upright with the centre
    of flotation ``(x_F, y_F)`` (docs/model.md §2.3, §5.15: ``G33 = c``, ``G34 = y_F c``,
    ``G35 = −x_F c``, ``G44 = W GM_T + y_F² c``, ``G45 = −x_F y_F c``, ``G55 = W GM_L + x_F² c``,
    ``c = ρ g A_wp``)."""
    _vessel(vessel, "linear_model")
    d = vessel.to_dict()
    p = d["vessel"]
    m = p["mass"]
    rg = np.asarray(p.get("center_of_gravity", [0.0, 0.0, 0.0]), float)
    S = _skew(rg)
    M = np.zeros((6, 6))
    M[:3, :3] = m * np.eye(3)
    M[:3, 3:] = -m * S
    M[3:, :3] = m * S
    M[3:, 3:] = np.diag(p["inertia"]) - m * S @ S
    if "damping_matrix" in p:
        D = np.array(p["damping_matrix"], float)
    else:
        D = np.diag([*p["damping_translational"], *p["damping_rotational"]])
    g, rho = p["gravity"], p["water_density"]
    c = rho * g * p["waterplane_area"]
    xf, yf = p.get("flotation_center_x", 0.0), p.get("flotation_center_y", 0.0)
    W = m * g
    C = np.zeros((6, 6))
    C[2, 2] = c
    C[2, 3] = C[3, 2] = yf * c
    C[2, 4] = C[4, 2] = -xf * c
    C[3, 3] = W * p["gm_transverse"] + yf ** 2 * c
    C[3, 4] = C[4, 3] = -xf * yf * c
    C[4, 4] = W * p["gm_longitudinal"] + xf ** 2 * c
    b1, _ = roll_damping(vessel)
    D = D.copy()
    D[3, 3] += b1
    return M, D, C


@checked
def roll_damping(vessel) -> tuple[float, float]:
    """``(B₁, B₂)`` of the vessel's ``[roll_damping]`` (N m s, N m s²; zeros without one), ``B₁``
    from ``critical_fraction`` as the core computes it: ``2ζ√(M₄₄ C₄₄)``, ``M₄₄`` the roll entry
    of the mass matrix with the vessel's own added mass."""
    _vessel(vessel, "roll_damping")
    d = vessel.to_dict()
    t = d.get("roll_damping")
    if not t:
        return 0.0, 0.0
    b2 = float(t.get("quadratic", 0.0))
    if "linear" in t:
        return float(t["linear"]), b2
    zeta = float(t.get("critical_fraction", 0.0))
    if zeta == 0.0:
        return 0.0, b2
    p = d["vessel"]
    rg = np.asarray(p.get("center_of_gravity", [0.0, 0.0, 0.0]), float)
    m44 = p["inertia"][0] + p["mass"] * (rg[1] ** 2 + rg[2] ** 2)
    if "added_mass" in p:
        m44 += np.asarray(p["added_mass"], float)[3, 3]
    c44 = p["mass"] * p["gravity"] * p["gm_transverse"] + p.get("flotation_center_y", 0.0) ** 2 * (
        p["water_density"] * p["gravity"] * p["waterplane_area"])
    return 2.0 * zeta * math.sqrt(m44 * c44), b2


@checked
def waves_table(vessel, dataset=DEFAULT_DATASET) -> dict:
    """The ``[waves]`` transfer functions of the dataset about the vessel's origin (first order
    only: no drift)."""
    _vessel(vessel, "waves_table")
    out = hydro.from_capytaine(dataset, symmetric=True, vessel=vessel)
    return {k: out["waves"][k] for k in ("rao_frequencies", "rao_directions", "force_rao_real", "force_rao_imag")}


@checked
def frequency_rao(vessel, omega: float, heading: float, dataset=DEFAULT_DATASET, *, data=None,
                  amplitude: float | None = None) -> np.ndarray:
    """``[−ω²(M + A(ω)) + iω(B(ω) + D) + C]⁻¹ F(ω)`` for a wave of unit amplitude (complex, the
    six DOFs), ``A``, ``B``, ``F`` linear in ω between the dataset's frequencies. ``data``: the
    :func:`phsplit.radiation.retardation_data` of the dataset and vessel, read once.

    A quadratic roll damping ``B₂`` (``[roll_damping]``) makes the response depend on the wave's
    ``amplitude`` (m, then required): it enters as its harmonic equivalent linear damping
    ``(8/3π) ω φ_a B₂`` (the energy per cycle of ``B₂|φ'|φ'`` in ``φ = φ_a cos ωt``; ITTC
    7.5-02-07-04.5, Himeno 1981), with the roll amplitude ``φ_a`` found by fixed-point iteration."""
    _vessel(vessel, "frequency_rao")
    if not (_real(omega) and math.isfinite(float(omega)) and float(omega) > 0):
        raise _err(f"frequency_rao: omega must be a positive number (rad/s), got {omega!r}")
    if not (_real(heading) and math.isfinite(float(heading)) and -360.0 <= float(heading) <= 360.0):
        raise _err(f"frequency_rao: heading must be a number of degrees within ±360, got {heading!r}")
    if amplitude is not None and not (_real(amplitude) and math.isfinite(float(amplitude)) and float(amplitude) > 0):
        raise _err(f"frequency_rao: amplitude must be a positive number (m) or None, got {amplitude!r}")
    w, K, Ainf, _, out = data if data is not None else radiation.retardation_data(dataset, vessel=vessel)
    if not w[0] - 1e-9 <= omega <= w[-1] + 1e-9:
        raise _err(f"frequencies: {omega:g} rad/s is outside the dataset's {w[0]:g}-{w[-1]:g} rad/s")
    wv = out["waves"]
    dirs = np.asarray(wv["rao_directions"], float)
    gap = np.abs((dirs - heading + 180.0) % 360.0 - 180.0)   # the circular distance, degrees
    j = int(np.argmin(gap))
    if gap[j] > 1e-6:
        raise _err(f"heading {heading:g} deg is not a direction of the dataset (with its mirror images: "
                    f"{', '.join(f'{d:g}' for d in dirs)})")
    A_all = Ainf + np.asarray(K).imag / w[:, None, None]
    B_all = np.asarray(K).real
    Fw = np.asarray(wv["force_rao_real"])[j] + 1j * np.asarray(wv["force_rao_imag"])[j]
    i = int(np.searchsorted(w, omega))
    if i < len(w) and abs(w[i] - omega) <= 1e-9:
        A, B, F = A_all[i], B_all[i], Fw[i]
    elif i > 0 and abs(w[i - 1] - omega) <= 1e-9:
        A, B, F = A_all[i - 1], B_all[i - 1], Fw[i - 1]
    else:
        i = min(max(i, 1), len(w) - 1)
        s = (omega - w[i - 1]) / (w[i] - w[i - 1])
        A, B, F = ((1 - s) * X[i - 1] + s * X[i] for X in (A_all, B_all, Fw))
    M, D, C = linear_model(vessel)
    Z = -omega ** 2 * (M + A) + 1j * omega * (B + D) + C
    xi = np.linalg.solve(Z, F)
    _, b2 = roll_damping(vessel)
    if b2 == 0.0:
        return xi
    if amplitude is None:
        raise _err("the vessel's roll_damping.quadratic makes the RAO depend on the wave amplitude: give amplitude= (m)")
    eq = 8.0 / (3.0 * math.pi) * omega * b2
    for _ in range(200):
        Zk = Z.copy()
        Zk[3, 3] += 1j * omega * eq * amplitude * abs(xi[3])
        new = np.linalg.solve(Zk, F)
        if abs(abs(new[3]) - abs(xi[3])) <= 1e-12 * abs(new[3]):
            return new
        xi = 0.5 * (xi + new)   # damped: the map is monotone in |xi_4|
    raise _core.IntegrationError(f"the equivalent linearisation of the quadratic roll damping did not converge at {omega:g} rad/s")


def _fit(t, sig, omega):
    """The complex amplitude ``X`` of ``sig ≈ c₀ + Re(X e^{iωt})`` (least squares)."""
    X = np.c_[np.cos(omega * t), np.sin(omega * t), np.ones_like(t)]
    c, *_ = np.linalg.lstsq(X, sig, rcond=None)
    return complex(c[0], -c[1])


@checked
def time_rao(vessel, waves, omega: float, heading: float, *, amplitude: float = 0.1, h: float = 0.5,
             t_end: float = 600.0, periods: float = 10.0, method: str = "sp4", dofs=DOFS):
    """The complex amplitudes per unit wave amplitude (a dict by DOF: m/m, rad/m) of ``vessel``
    (with its fluid memory if any) in one regular wave, from rest with the controller off, over
    the last ``periods`` periods of ``t_end``, and the solution. ``waves``: :func:`waves_table`."""
    from .simulate import SettingWarning, Vessel, simulate

    _vessel(vessel, "time_rao")
    for name, v, lo in (("amplitude", amplitude, 0.0), ("h", h, 0.0), ("t_end", t_end, 0.0), ("periods", periods, 1.0)):
        if not (_real(v) and math.isfinite(float(v)) and float(v) >= lo and float(v) > 0):
            raise _err(f"time_rao: {name} must be a number {'>= 1 (the fit window in periods)' if lo else '> 0'}, "
                       f"got {v!r}")
    if not isinstance(waves, dict):
        raise _err(f"time_rao: waves must be the transfer functions of waves_table (a dict), got {type(waves).__name__}")
    d = vessel.to_dict()
    d["waves"] = {**waves, **sea.regular(amplitude, omega, direction=heading)}
    v = Vessel.from_dict(d, f"{vessel.source} in a regular wave")
    zero = [0.0, 0.0, 0.0]
    y0 = v.initial_state(euler=zero, position=zero, velocity=zero, angular_velocity=zero)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SettingWarning)
        s = simulate(v, (0.0, t_end), h, method, control_start=None, initial=y0, save_every=1)
    if s.status == "interrupted":   # Ctrl-C or SIGTERM: the caller's to handle, as for simulate
        raise KeyboardInterrupt
    if s.status != "completed":
        raise _core.IntegrationError(f"the run at {omega:g} rad/s did not complete: {s.failure}")
    keep = s.t >= t_end - periods * 2 * math.pi / omega - 1e-9
    t = s.t[keep]
    signal = {"surge": s.x[keep, 0], "sway": s.x[keep, 1], "heave": s.x[keep, 2],
              "roll": s.euler[keep, 0], "pitch": s.euler[keep, 1], "yaw": s.euler[keep, 2]}
    # the phase against the wave elevation where the waves' phases are taken (the set point,
    # docs/explanation/components/waves.md), its amplitude ``amplitude``
    eta = _fit(t, np.asarray(s.outputs["wave_elevation"][2])[keep], omega)
    ref = amplitude * eta / abs(eta)
    return {k: _fit(t, signal[k], omega) / ref for k in dofs}, s


def drift(s, omega: float, periods: float) -> float:
    """How far (m) the body origin moved horizontally over the fit window of a :func:`time_rao`
    run: the first-order loads on the nonlinear rigid body have a mean part (products of the
    wave-frequency motions and loads, growing as the amplitude squared), and with the
    controller off nothing holds the vessel on station."""
    for name, v in (("omega", omega), ("periods", periods)):
        if not (_real(v) and math.isfinite(float(v)) and float(v) > 0):
            raise _err(f"drift: {name} must be a positive number, got {v!r}")
    t_end = float(s.t[-1])
    keep = s.t >= t_end - periods * 2 * math.pi / omega - 1e-9
    xy = s.x[keep, :2]
    return float(np.linalg.norm(xy[-1] - xy[0]))


#: The largest drift over the fit window, as a fraction of the wavelength, that :func:`rao`
#: accepts without a warning: 2 % shifts the wave's phase at the hull by 0.13 rad over the
#: window, and the encounter frequency by 2 % of a period over the window's length.
DRIFT_FRACTION = 0.02


def _real(x) -> bool:
    """A real number, not a bool, a string or anything else float() would take."""
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))


def _positive(name, x):
    if not (_real(x) and math.isfinite(float(x)) and float(x) > 0):
        raise _err(f"{name} must be a positive number, got {x!r}")
    return float(x)


@checked
def rao(vessel, frequencies, heading: float, dofs=("heave", "roll", "pitch"), *, amplitude: float = 0.1,
        dataset=None, fluid_memory=True, h: float = 0.5, t_end: float = 600.0, periods: float = 10.0,
        method: str = "sp4", check_only: bool = False):
    """The RAO of ``vessel`` at ``frequencies`` (rad/s) in regular waves from ``heading``
    (degrees, the waves' direction relative to the bow: 90 beam seas, 180 head seas; a
    direction of the dataset), in the time domain against the frequency domain, as an
    ``xarray.Dataset`` along ``frequency`` with CF attributes.

    Per DOF of ``dofs`` (of surge, sway, heave, roll, pitch, yaw): ``<dof>_amplitude`` and
    ``<dof>_phase`` (the time domain: m/m or rad/m, and rad against the wave elevation where
    the waves' phases are taken), ``<dof>_amplitude_frequency_domain`` and ``<dof>_phase_frequency_domain``,
    ``<dof>_deviation`` (time over frequency domain, minus one); and per frequency the run's
    ``ledger_residual`` (the largest relative residual) and ``radiation_dissipated`` (J, the
    memory's account; zero without it).

    ``dataset``: a Capytaine dataset (a path or an ``xarray.Dataset``; default the shipped box of
    the paper's vessel, :data:`DEFAULT_DATASET`), whose first-order excitation drives the runs;
    ``fluid_memory``: ``True`` (fit Cummins' memory here, :func:`phsplit.radiation.with_fluid_memory`),
    a :class:`phsplit.radiation.FluidMemory` of the same dataset and vessel, or ``False`` (the
    vessel as it is, its own added mass and damping); ``amplitude`` (m), the step ``h`` (s),
    ``t_end`` (s), ``periods`` (the fit window) and ``method`` of the runs. ``check_only``: check
    the arguments and return ``None`` without a run.

    ``horizontal_drift`` (m) is how far the vessel moved over each fit window (controller off,
    the first-order loads on the nonlinear body have a mean part growing as the amplitude
    squared); past :data:`DRIFT_FRACTION` of the wavelength a :class:`phsplit.ModelRangeWarning`
    says so, as the wave the hull meets is then no longer the regular one."""
    import xarray as xr

    from .simulate import Vessel

    if not isinstance(vessel, Vessel):
        raise _err(f"vessel must be a phsplit.Vessel, got {type(vessel).__name__}")
    items = list(frequencies) if isinstance(frequencies, (list, tuple, np.ndarray)) else [frequencies]
    if not all(_real(x) for x in np.ravel(np.asarray(items, dtype=object))):
        raise _err(f"frequencies must be positive numbers (rad/s), got {frequencies!r}")
    freqs = np.atleast_1d(np.asarray(items, dtype=float))
    if freqs.ndim != 1 or freqs.size == 0 or not np.all(np.isfinite(freqs)) or np.any(freqs <= 0):
        raise _err(f"frequencies must be a non-empty list of positive numbers (rad/s), got {frequencies!r}")
    if len(np.unique(freqs)) != len(freqs):
        raise _err(f"frequencies must be distinct, got {frequencies!r}")
    if not _real(heading):
        raise _err(f"heading must be a number (degrees), got {heading!r}")
    heading = float(heading)
    if not (math.isfinite(heading) and -360.0 <= heading <= 360.0):
        raise _err(f"heading must be a number of degrees within ±360, got {heading!r}")
    if isinstance(dofs, str):
        dofs = (dofs,)
    if not isinstance(dofs, (list, tuple)):
        raise _err(f"dofs must be distinct names of {', '.join(DOFS)}, got {dofs!r}")
    dofs = tuple(dofs)
    bad = [d for d in dofs if d not in DOFS]
    if not dofs or bad or len(set(dofs)) != len(dofs):
        raise _err(f"dofs must be distinct names of {', '.join(DOFS)}, got {list(dofs)!r}")
    amplitude = _positive("amplitude", amplitude)
    h = _positive("h", h)
    t_end = _positive("t_end", t_end)
    periods = _positive("periods", periods)
    if periods < 1.0:
        raise _err(f"periods must be at least 1 (the fit window, in periods of the lowest frequency), got {periods:g}")
    # a regular wave steeper than 1/7 (height over length, deep water) breaks (Michell 1893;
    # DNV-RP-C205 §3.2.2): a larger amplitude is no wave linear theory describes
    g = float(vessel.to_dict()["vessel"]["gravity"])
    length = 2 * math.pi * g / float(freqs.max()) ** 2
    if 2 * amplitude / length > 1 / 7:
        raise _err(f"amplitude = {amplitude:g} m makes the wave of {float(freqs.max()):g} rad/s steeper than it can be "
                   f"(height/length {2 * amplitude / length:.3g} > 1/7, where waves break): take amplitude <= "
                   f"{length / 14:.3g} m")
    shortest = 2 * math.pi / float(freqs.max())
    if h > shortest / 4:
        raise _err(f"h = {h:g} s cannot follow the wave of {float(freqs.max()):g} rad/s (period {shortest:.4g} s): "
                   f"take h <= {shortest / 4:.3g} s, a quarter of its period")
    if t_end / h > 2_000_000:
        raise _err(f"t_end / h = {t_end / h:.3g} steps per frequency; at most 2e6 (take a longer h or a shorter t_end)")
    if not isinstance(check_only, bool):
        raise _err(f"check_only must be True or False, got {check_only!r}")
    window = periods * 2 * math.pi / float(freqs.min())
    if t_end < 2 * window:
        raise _err(f"t_end must be at least twice the fit window ({periods:g} periods of the lowest frequency, "
                   f"{window:.4g} s), so that the transients are discarded; got {t_end:g} s")
    if method not in _core.METHODS:
        raise _err(f"method must be one of {', '.join(_core.METHODS)}, got {method!r}")
    dataset = DEFAULT_DATASET if dataset is None else dataset
    data = radiation.retardation_data(dataset, vessel=vessel)
    for w in freqs:   # refused before any run
        frequency_rao(vessel, float(w), heading, dataset, data=data, amplitude=amplitude)
    if not (fluid_memory is True or fluid_memory is False or isinstance(fluid_memory, radiation.FluidMemory)):
        raise _err(f"fluid_memory must be True, False or a FluidMemory, got {type(fluid_memory).__name__}")
    tables = vessel.to_dict()
    if "pipe" in tables:
        raise _err("the RAO is the free vessel's in regular waves: the vessel has a [pipe], which holds it; "
                   "give the vessel without it")
    if fluid_memory is not False and _core.method_info(method)["kind"] != "splitting":
        raise _err(f"method = {method!r} is explicit Runge-Kutta, which takes no subsystem with states of its own, "
                   f"and the fluid memory is one: use a splitting method (sp2, sp4, ...), or fluid_memory=False")
    if fluid_memory is not False and "port_hamiltonian" in tables:
        name = tables["port_hamiltonian"].get("name")
        raise _err(f"the vessel already has a port-Hamiltonian subsystem ({name!r}"
                   + (": its fluid memory" if name == "radiation" else "")
                   + "), and the RAO would add the fluid memory's: run it with fluid_memory=False "
                   "(phsplit rao --no-fluid-memory)")
    if check_only:
        return None
    if fluid_memory is True:
        td = radiation.with_fluid_memory(vessel, dataset)
    elif isinstance(fluid_memory, radiation.FluidMemory):
        td = radiation.with_fluid_memory(vessel, dataset, memory=fluid_memory)
    elif fluid_memory is False:
        td = vessel
    else:
        raise _err(f"fluid_memory must be True, False or a FluidMemory, got {type(fluid_memory).__name__}")
    wt = waves_table(vessel, dataset)
    n = len(freqs)
    out = {k: np.zeros(n, complex) for k in dofs}
    ref = {k: np.zeros(n, complex) for k in dofs}
    residual, booked, moved = np.zeros(n), np.zeros(n), np.zeros(n)
    for i, w in enumerate(freqs):
        got, s = time_rao(td, wt, float(w), heading, amplitude=amplitude, h=h, t_end=t_end, periods=periods,
                          method=method, dofs=dofs)
        fd = frequency_rao(td, float(w), heading, dataset, data=data, amplitude=amplitude)
        for k in dofs:
            out[k][i], ref[k][i] = got[k], fd[DOFS.index(k)]
        moved[i] = drift(s, float(w), periods)
        wavelength = 2 * math.pi * 9.81 / float(w) ** 2   # deep water (the dataset's)
        if moved[i] > DRIFT_FRACTION * wavelength:
            from .runner import ModelRangeWarning
            warnings.warn(f"rao at {float(w):g} rad/s: the vessel drifted {moved[i]:.3g} m over the fit window "
                          f"({100 * moved[i] / wavelength:.2g} % of the {wavelength:.4g} m wavelength), so the wave "
                          f"it meets is no longer the regular one; give a smaller amplitude (now {amplitude:g} m)",
                          ModelRangeWarning, stacklevel=2)
        residual[i] = float(s.ledger.relative_residual().max())
        booked[i] = float(s.ledger.by_account["radiation"].sum()) if "radiation" in s.ledger.by_account else 0.0
    variables = {}
    for k in dofs:
        u = _UNITS[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            dev = np.abs(out[k]) / np.abs(ref[k]) - 1.0
        variables[f"{k}_amplitude"] = ("frequency", np.abs(out[k]), {"units": u, "long_name": f"{k} amplitude per unit wave amplitude, time domain"})
        variables[f"{k}_phase"] = ("frequency", np.angle(out[k]), {"units": "rad", "long_name": f"{k} phase against the wave elevation, time domain"})
        variables[f"{k}_amplitude_frequency_domain"] = ("frequency", np.abs(ref[k]), {"units": u, "long_name": f"{k} amplitude per unit wave amplitude, frequency domain"})
        variables[f"{k}_phase_frequency_domain"] = ("frequency", np.angle(ref[k]), {"units": "rad", "long_name": f"{k} phase against the wave elevation, frequency domain"})
        variables[f"{k}_deviation"] = ("frequency", dev, {"units": "1", "long_name": f"{k} time-domain amplitude over the frequency-domain one, minus one"})
    variables["horizontal_drift"] = ("frequency", moved, {"units": "m", "long_name": "horizontal distance the body origin moved over the fit window"})
    variables["ledger_residual"] = ("frequency", residual, {"units": "1", "long_name": "largest relative residual of the run's ledger"})
    variables["radiation_dissipated"] = ("frequency", booked, {"units": "J", "long_name": "energy booked by the fluid memory's account over the run"})
    ds = xr.Dataset(variables, coords={"frequency": ("frequency", freqs, {"units": "rad s-1", "long_name": "wave angular frequency"})})
    ds.attrs.update({"heading": heading, "heading_units": "degree (wave direction relative to the bow; 90 beam, 180 head seas)",
                     "wave_amplitude": amplitude, "method": method, "step": h, "t_end": t_end, "fit_periods": periods,
                     "fluid_memory": int(fluid_memory is not False),
                     "dataset": dataset if isinstance(dataset, str) else "an xarray.Dataset",
                     "comment": "time domain: phsplit runs from rest, controller off, a least-squares sinusoid over the last "
                                "fit_periods periods; frequency domain: [-w^2 (M + A(w)) + iw (B(w) + D) + C]^-1 F(w) of the "
                                "same dataset (Fossen 2021, ch. 5)"})
    return cf.finish(ds, "phsplit RAO", "phsplit.rao")
