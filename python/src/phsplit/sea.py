"""Sea states for the waves component (docs/model.md §5.9): a wave spectrum, realised as a sum of
regular components with random phases from a seed.

The spectra come from `wavespectra <https://wavespectra.readthedocs.io>`_
(``wavespectra.construct.frequency``): JONSWAP (Hasselmann et al. 1973) and Pierson–Moskowitz
(1964), scaled to the significant wave height ``Hs = 4 √m0``. phsplit only discretises them:

* frequencies: ``n`` equal bins over ``[omega_min, omega_max]`` (rad/s), one component per bin at a
  random frequency inside it (so the realisation does not repeat with the period ``2π/Δω``);
* amplitudes: ``a_k = √(2 S(ω_k) Δω)``, with ``S`` the spectrum per rad/s;
* phases: uniform on ``[0, 2π)``;
* directions: the mean direction, or, with ``spreading`` (the exponent ``s`` of the cos-2s
  spreading function, ``D(θ) ∝ cos^{2s}((θ − θ_mean)/2)``), one direction per component (the
  single-summation model: E. R. Jefferys, "Directional seas should be ergodic", Applied Ocean
  Research 9 (1987) 186–191), at the quantiles of ``D`` given by a low-discrepancy sequence
  (``direction_sampling = "quasi_random"``, the default: :func:`_cos2s_quasi`) or drawn
  independently (``"random"``).

All random numbers come from ``numpy.random.default_rng(seed)``: the same seed gives the same sea.
The result is the ``[waves]`` table's sea-state keys (``frequencies``, ``amplitudes``, ``phases``,
``directions``), ready to merge with the vessel's transfer functions."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _core
from ._arguments import checked

SPECTRA = ("jonswap", "pierson-moskowitz")
#: How a short-crested sea's components take their directions (:class:`SeaState`).
DIRECTION_SAMPLING = ("quasi_random", "random")


def _number(v) -> bool:
    """A real number (not a bool, not a string), finite."""
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


#: The keys that give a direction (degrees, spatial frame, from x towards y): ``direction`` and
#: ``direction_towards`` the direction the waves, the wind or the current go towards (the
#: oceanographic convention), ``direction_from`` the one they come from (the meteorological
#: one: a wind from the north-east blows towards the south-west). One of them at most.
DIRECTION_KEYS = ("direction", "direction_towards", "direction_from")


#: The physical ranges of the sea's own keys (the vessel file's are the core's,
#: ``phsplit._core.physical_ranges``): (low, high, unit, why), both ends allowed.
RANGES = {
    "tp": (0.5, 40.0, "s", "no wind sea or swell peaks outside 0.5 to 40 s"),
    "direction": (-360.0, 360.0, "degrees", "within a full turn either way"),
    "height": (0.1, 500.0, "m", "a reference height above the sea surface, within 500 m"),
    "length": (0.1, 500.0, "m", "no hull is longer than 500 m"),
}


def in_range(where: str, key: str, v) -> float:
    """``v`` if it lies in :data:`RANGES` [key], else an InvalidInputError naming ``where.key``."""
    lo, hi, unit, why = RANGES[key]
    if not (_number(v) and lo <= v <= hi):
        raise _core.InvalidInputError(f"{where}.{key} must lie within [{lo:g}, {hi:g}] ({unit}; {why}), got {v!r}")
    return float(v)


def direction_towards(table, where: str, default: float = 0.0) -> float:
    """The direction (degrees, towards) a table gives by one of :data:`DIRECTION_KEYS`, in
    [0, 360) for ``direction_from``; ``default`` when it gives none. Two of them, or a value
    that is not a finite number, raise :class:`phsplit.InvalidInputError` naming the key."""
    given = [k for k in DIRECTION_KEYS if k in table]
    if len(given) > 1:
        raise _core.InvalidInputError(f"{where}: give one of {', '.join(given)}, not both (degrees; "
                                      "direction and direction_towards: where it goes, direction_from: "
                                      "where it comes from)")
    if not given:
        return default
    k = given[0]
    v = table[k]
    if not _number(v):
        raise _core.InvalidInputError(f"{where}.{k} must be a finite number (degrees), got {v!r}")
    lo, hi, _, why = RANGES["direction"]
    if not lo <= v <= hi:
        raise _core.InvalidInputError(f"{where}.{k} must lie within [{lo:g}, {hi:g}] (degrees; {why}), got {v!r}")
    return (float(v) + 180.0) % 360.0 if k == "direction_from" else float(v)


def _with_direction(table: dict, where: str) -> dict:
    """``table`` with its direction key given as ``direction`` (towards)."""
    out = {k: v for k, v in table.items() if k not in DIRECTION_KEYS}
    if any(k in table for k in DIRECTION_KEYS):
        out["direction"] = direction_towards(table, where)
    return out


def _check_range(where: str, r) -> None:
    ok = (isinstance(r, (tuple, list)) and len(r) == 2 and all(_number(x) for x in r) and 0 < r[0] < r[1])
    if not ok:
        raise _core.InvalidInputError(f"{where}: omega_range must be two increasing frequencies > 0 (rad/s), "
                                      f"got {r!r}")


@dataclass(frozen=True)
class SeaState:
    """A sea state: ``hs`` (m), ``tp`` (s), ``gamma`` (JONSWAP peak enhancement; ignored for
    Pierson–Moskowitz), ``direction`` (degrees, the direction the waves travel towards, spatial,
    from x towards y), ``spreading`` (cos-2s exponent, or None for long-crested waves),
    ``seed``, ``components``, the frequency range ``omega_range`` (rad/s; default
    ``[0.5, 3] ω_p``) and, with ``spreading``, ``direction_sampling``: ``"quasi_random"`` (the
    components' directions at low-discrepancy quantiles of the spreading, the default) or
    ``"random"`` (independent draws)."""

    hs: float
    tp: float
    gamma: float = 3.3
    spectrum: str = "jonswap"
    direction: float = 0.0
    spreading: float | None = None
    seed: int = 0
    components: int = 200
    omega_range: tuple[float, float] | None = None
    direction_sampling: str = "quasi_random"

    def __post_init__(self):
        def bad(msg):
            raise _core.InvalidInputError(f"waves: {msg}")

        for name, v in (("hs", self.hs), ("tp", self.tp)):
            if not (_number(v) and v > 0):
                bad(f"{name} must be a number > 0 ({'m' if name == 'hs' else 's'}), got {v!r}")
        if self.hs < 1e-3 or self.hs > 30.0:
            bad(f"hs must lie in [0.001, 30] m (no sea on record is higher), got {self.hs!r}")
        in_range("waves", "tp", self.tp)
        if _number(self.direction):
            in_range("waves", "direction", self.direction)
        if self.spectrum not in SPECTRA:
            bad(f"spectrum must be one of {', '.join(repr(s) for s in SPECTRA)}, got {self.spectrum!r}")
        if not (_number(self.gamma) and 1.0 <= self.gamma <= 10.0):
            bad(f"gamma must lie in [1, 10] (the JONSWAP peak enhancement; 3.3 is the mean of JONSWAP), got {self.gamma!r}")
        if not _number(self.direction):
            bad(f"direction must be a finite number (degrees), got {self.direction!r}")
        if self.spreading is not None and not (_number(self.spreading) and self.spreading > 0):
            bad(f"spreading must be a number > 0 (the cos-2s exponent) or absent, got {self.spreading!r}")
        if not (isinstance(self.components, int) and not isinstance(self.components, bool)
                and 1 <= self.components <= 10_000):
            bad(f"components must be an integer in [1, 10000], got {self.components!r}")
        if not (isinstance(self.seed, int) and not isinstance(self.seed, bool) and 0 <= self.seed < 2 ** 63):
            bad(f"seed must be an integer in [0, 2^63), got {self.seed!r}")
        if self.omega_range is not None:
            _check_range("waves", self.omega_range)
        if self.direction_sampling not in DIRECTION_SAMPLING:
            bad(f"direction_sampling must be one of {', '.join(repr(s) for s in DIRECTION_SAMPLING)} (how the "
                f"components' directions sample the spreading), got {self.direction_sampling!r}")
        if self.direction_sampling != "quasi_random" and self.spreading is None:
            bad(f"direction_sampling = {self.direction_sampling!r} needs spreading: a long-crested sea's components "
                f"all travel in the mean direction")

    @property
    def omega_p(self) -> float:
        return 2.0 * math.pi / self.tp

    def range(self) -> tuple[float, float]:
        if self.omega_range is None:
            return 0.5 * self.omega_p, 3.0 * self.omega_p
        lo, hi = self.omega_range
        return float(lo), float(hi)

    def density(self, omega) -> np.ndarray:
        """The spectrum S(ω) in m² s/rad at ``omega`` (rad/s), scaled to ``hs`` over the
        realisation's range (wavespectra, per Hz, divided by 2π)."""
        from wavespectra.construct.frequency import jonswap, pierson_moskowitz

        lo, hi = self.range()
        grid = np.linspace(lo, hi, 4001) / (2 * np.pi)  # Hz, for the scaling to hs
        fp = 1.0 / self.tp
        make = (lambda f: jonswap(f, fp=fp, gamma=self.gamma, hs=self.hs)) if self.spectrum == "jonswap" \
            else (lambda f: pierson_moskowitz(f, fp=fp, hs=self.hs))
        ref = np.asarray(make(grid))
        m0 = np.trapezoid(ref, grid)
        f = np.asarray(omega, dtype=float) / (2 * np.pi)
        raw = np.asarray(make(np.atleast_1d(f)))
        # the same shape, scaled so that 4 sqrt(m0) = hs over [lo, hi] exactly
        return raw * (self.hs / 4.0) ** 2 / m0 / (2 * np.pi)

    def realise(self) -> dict[str, list[float]]:
        """The components: the ``[waves]`` table's sea-state keys."""
        rng = np.random.default_rng(self.seed)
        lo, hi = self.range()
        n = self.components
        dw = (hi - lo) / n
        omega = lo + (np.arange(n) + rng.uniform(0.0, 1.0, n)) * dw
        amp = np.sqrt(2.0 * self.density(omega) * dw)
        phase = rng.uniform(0.0, 2 * np.pi, n)
        if self.spreading is None:
            dirs = np.full(n, float(self.direction))
        elif self.direction_sampling == "random":
            dirs = self.direction + np.degrees(_cos2s_draw(rng, self.spreading, n))
        else:
            dirs = self.direction + np.degrees(_cos2s_quasi(rng, self.spreading, n))
        return {"frequencies": omega.tolist(), "amplitudes": amp.tolist(), "phases": phase.tolist(),
                "directions": dirs.tolist()}


def _cos2s_quantiles(s: float, u) -> np.ndarray:
    """The angles (rad) at the quantiles ``u`` of D(θ) ∝ cos^{2s}(θ/2) on (−π, π], by inverting
    its tabulated CDF."""
    th = np.linspace(-np.pi, np.pi, 20001)
    d = np.cos(th / 2.0) ** (2.0 * s)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (d[1:] + d[:-1]) * np.diff(th))])
    cdf /= cdf[-1]
    return np.interp(u, cdf, th)


def _cos2s_draw(rng, s: float, n: int) -> np.ndarray:
    """n independent angles (rad) from D(θ) ∝ cos^{2s}(θ/2)."""
    return _cos2s_quantiles(s, rng.uniform(0.0, 1.0, n))


#: The golden ratio's fractional part: the Kronecker sequence ``{u₀ + k g}`` with it has the
#: lowest discrepancy of all such sequences, its continued fraction being all ones (H. Niederreiter,
#: *Random Number Generation and Quasi-Monte Carlo Methods*, SIAM, 1992, §3.1).
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def _cos2s_quasi(rng, s: float, n: int) -> np.ndarray:
    """n angles (rad) at the quantiles ``u_k = {u₀ + k g}`` of D(θ) ∝ cos^{2s}(θ/2), ``u₀``
    random: consecutive components (neighbours in frequency) spread over the whole distribution,
    so every band of frequencies carries the directional spectrum, not a handful of random draws
    of it. A narrow-band response (a lightly damped roll) sees a few dozen components; with
    independent draws the variance of its realisation scatters by several per cent from seed to
    seed (docs/explanation/components/waves.md, measured on the OSV)."""
    u = np.mod(rng.uniform(0.0, 1.0) + GOLDEN * np.arange(n), 1.0)
    return _cos2s_quantiles(s, u)


@checked
def regular(amplitude: float, omega: float, direction: float = 0.0, phase: float = 0.0) -> dict[str, list[float]]:
    """One regular wave: amplitude (m), frequency (rad/s), direction (degrees), phase (rad)."""
    if not (_number(amplitude) and 0 < amplitude <= 50):
        raise _core.InvalidInputError(f"regular: amplitude must be a number in (0, 50] (m; no wave is higher), "
                                      f"got {amplitude!r}")
    if not (_number(omega) and 0 < omega <= 10):
        raise _core.InvalidInputError(f"regular: omega must be a number in (0, 10] (rad/s; a sea's waves are below "
                                      f"10 rad/s), got {omega!r}")
    in_range("regular", "direction", direction)
    if not _number(phase):
        raise _core.InvalidInputError(f"regular: phase must be a finite number (rad), got {phase!r}")
    return {"frequencies": [float(omega)], "amplitudes": [float(amplitude)], "phases": [float(phase)],
            "directions": [float(direction)]}


@checked
def sea_state(table: dict) -> SeaState:
    """A :class:`SeaState` from a scenario's ``[environment.waves]`` keys (unknown keys named;
    the direction by ``direction``/``direction_towards`` or ``direction_from``, degrees)."""
    allowed = {"hs", "tp", "gamma", "spectrum", "direction", "spreading", "seed", "components", "omega_range",
               "direction_sampling"}
    table = _with_direction(table, "environment.waves")
    allowed_shown = allowed | set(DIRECTION_KEYS)
    unknown = sorted(set(table) - allowed - {"hydro", "symmetric", "hydro_checks", "fluid_memory"})
    if unknown:
        import difflib

        near = difflib.get_close_matches(unknown[0], sorted(allowed_shown), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise _core.ScenarioParseError(f"unknown field {unknown[0]!r} in [environment.waves]{hint} "
                                       f"(allowed: {', '.join(sorted(allowed_shown | {'hydro', 'symmetric', 'hydro_checks', 'fluid_memory'}))})")
    for k in ("hs", "tp"):
        if k not in table:
            raise _core.ScenarioParseError(f"missing field {k!r} in [environment.waves] "
                                           f"({'significant wave height, m' if k == 'hs' else 'peak period, s'})")
    kw = {k: table[k] for k in allowed if k in table}
    if "direction_sampling" in kw and "spreading" not in kw:
        raise _core.InvalidInputError("environment.waves.direction_sampling needs spreading: a long-crested sea's "
                                      "components all travel in the mean direction (add spreading, or remove "
                                      "direction_sampling)")
    if "gamma" in kw and kw.get("spectrum", "jonswap") != "jonswap":
        raise _core.InvalidInputError(f"environment.waves.gamma is the JONSWAP spectrum's peak enhancement, and this "
                                      f"sea's spectrum is {kw['spectrum']!r}: remove gamma, or set spectrum = 'jonswap'")
    if "omega_range" in kw:
        _check_range("waves", kw["omega_range"])
        kw["omega_range"] = tuple(kw["omega_range"])
    sea = SeaState(**kw)
    steep = steepness(sea.hs, sea.tp)
    if steep > MAX_STEEPNESS:
        raise _core.InvalidInputError(
            f"environment.waves: hs = {sea.hs:g} m at tp = {sea.tp:g} s is a sea of steepness 2 pi Hs/(g Tp^2) = "
            f"{steep:.3g}, beyond the 1/7 at which even a regular wave breaks (Michell 1893); lower hs or raise tp "
            f"(real seas stay below about 1/15)")
    return sea


#: The steepest wave: a regular wave breaks at H/L = 1/7 (J. H. Michell, "The highest waves in
#: water", Phil. Mag. 36 (1893) 430-437); a sea state's average steepness stays far below it
#: (about 1/15 at most: DNV-RP-C205, Environmental conditions and environmental loads, 3.5.5).
MAX_STEEPNESS = 1.0 / 7.0


def steepness(hs: float, tp: float, g: float = 9.81) -> float:
    """A sea state's average steepness ``S_p = 2π Hs / (g Tp²)``, Hs over the deep-water
    wavelength at the peak period."""
    return 2.0 * math.pi * hs / (g * tp * tp)


# ----------------------------------------------------------------------------------------------
# wind

WIND_SPECTRA = ("harris", "npd")


@checked
def harris(f, speed: float, drag: float = 0.002, length: float = 1800.0):
    """The Harris gust spectrum (m² s⁻² per Hz) at frequencies ``f`` (Hz) for the mean speed
    ``speed`` at 10 m: ``S(f) = 4 κ L U / (2 + (f L / U)²)^(5/6)`` with the surface drag
    coefficient ``κ`` and the length scale ``L = 1800 m`` (R. I. Harris, "The nature of the
    wind", 1971). ``κ = 0.002`` is the default of SINTEF's SIMA/SIMO for this spectrum
    (values from 0.002 to 0.0026 are in use); its variance is ``6.6775 κ U²`` whatever ``L``.
    (DNV-RP-C205 gives a σ-normalised variant of it; this is the κ form.)"""
    f = np.asarray(f, dtype=float)
    for name, v in (("speed", speed), ("drag", drag), ("length", length)):
        if not (_number(v) and v > 0):
            raise _core.InvalidInputError(f"harris: {name} must be a number > 0, got {v!r}")
    return 4.0 * drag * length * speed / (2.0 + (f * length / speed) ** 2) ** (5.0 / 6.0)


@checked
def npd(f, speed: float, height: float = 10.0):
    """The NPD (Frøya) gust spectrum (m² s⁻² per Hz) at frequencies ``f`` (Hz) for the 1-hour
    mean speed ``speed`` at 10 m, at the height ``height`` (m):
    ``S(f) = 320 (U/10)² (z/10)^0.45 / (1 + f̃ⁿ)^(5/(3n))``, ``f̃ = 172 f (z/10)^(2/3) (U/10)^(−0.75)``,
    ``n = 0.468`` (the Frøya model of Andersen & Løvseth; API 2MET / ISO 19901-1:2005, A.7.4;
    DNV-RP-C205, §2.3; as implemented in OpenFAST TurbSim's ``Spec_API``). Its variance is
    ``(A/c)(1/n) B(1/n, 2/(3n))`` with ``A = 320 (U/10)² (z/10)^0.45``, ``c`` the factor of ``f``
    in ``f̃``."""
    for name, v in (("speed", speed), ("height", height)):
        if not (_number(v) and v > 0):
            raise _core.InvalidInputError(f"npd: {name} must be a number > 0, got {v!r}")
    f = np.asarray(f, dtype=float)
    n = 0.468
    ft = 172.0 * f * (height / 10.0) ** (2.0 / 3.0) * (speed / 10.0) ** -0.75
    return 320.0 * (speed / 10.0) ** 2 * (height / 10.0) ** 0.45 / (1.0 + ft ** n) ** (5.0 / (3.0 * n))


@dataclass(frozen=True)
class Wind:
    """A wind: mean ``speed`` (m/s at 10 m), ``direction`` (degrees, towards), and gusts from
    the ``spectrum`` (``"harris"``, ``"npd"`` or None for a steady wind), realised with ``seed``
    into ``components`` over ``omega_range`` (rad/s; default 0.001-0.5 rad/s, the slowly-varying
    band a DP vessel responds to)."""

    speed: float
    direction: float = 0.0
    spectrum: str | None = "npd"
    seed: int = 0
    components: int = 100
    omega_range: tuple[float, float] = (0.001, 0.5)
    height: float = 10.0
    drag: float = 0.002

    def __post_init__(self):
        def bad(msg):
            raise _core.InvalidInputError(f"wind: {msg}")

        if not (_number(self.speed) and 0 <= self.speed <= 80):
            bad(f"speed must be a number in [0, 80] (m/s), got {self.speed!r}")
        if not _number(self.direction):
            bad(f"direction must be a finite number (degrees), got {self.direction!r}")
        if self.spectrum is not None and self.spectrum not in WIND_SPECTRA:
            bad(f"spectrum must be one of {', '.join(repr(s) for s in WIND_SPECTRA)} or 'none', got {self.spectrum!r}")
        if not (isinstance(self.components, int) and not isinstance(self.components, bool)
                and 1 <= self.components <= 10_000):
            bad(f"components must be an integer in [1, 10000], got {self.components!r}")
        if not (isinstance(self.seed, int) and not isinstance(self.seed, bool) and 0 <= self.seed < 2 ** 63):
            bad(f"seed must be an integer in [0, 2^63), got {self.seed!r}")
        _check_range("wind", self.omega_range)
        if not (_number(self.height) and self.height > 0):
            bad(f"height must be a number > 0 (m), got {self.height!r}")
        in_range("wind", "height", self.height)
        if _number(self.direction):
            in_range("wind", "direction", self.direction)
        if not (_number(self.drag) and self.drag > 0):
            bad(f"drag must be a number > 0 (the Harris surface drag coefficient), got {self.drag!r}")

    def density(self, omega) -> np.ndarray:
        """The gust spectrum per rad/s at ``omega`` (rad/s)."""
        f = np.asarray(omega, dtype=float) / (2 * np.pi)
        if self.spectrum == "harris":
            s = harris(f, self.speed, self.drag)
        else:
            s = npd(f, self.speed, self.height)
        return s / (2 * np.pi)

    def realise(self) -> dict:
        """The ``[wind]`` table's wind keys: speed, direction and the gust components. The gust
        spectra span decades and peak at the lowest frequencies, so the bins are equal in
        ``log ω`` (each component at a random frequency inside its bin, its amplitude
        ``√(2 S(ω_k) Δω_k)`` from the bin's width)."""
        out = {"speed": float(self.speed), "direction": float(self.direction)}
        if self.spectrum is None or self.speed == 0:
            return out
        rng = np.random.default_rng(self.seed)
        lo, hi = self.omega_range
        n = self.components
        edges = np.geomspace(lo, hi, n + 1)
        dw = np.diff(edges)
        omega = edges[:-1] + rng.uniform(0.0, 1.0, n) * dw
        amp = np.sqrt(2.0 * self.density(omega) * dw)
        phase = rng.uniform(0.0, 2 * np.pi, n)
        out.update(gust_frequencies=omega.tolist(), gust_amplitudes=amp.tolist(), gust_phases=phase.tolist())
        return out


@checked
def wind(table: dict) -> tuple[dict, dict]:
    """A scenario's ``[environment.wind]``: the realised wind keys, and the rest (the windage
    and coefficients), which go to the vessel's ``[wind]`` table unchanged."""
    own = {"speed", "direction", "spectrum", "seed", "components", "omega_range", "height", "drag"}
    table = _with_direction(table, "environment.wind")
    windage = {"ship_type", "centroid_x", "frontal_area", "lateral_area", "length", "air_density", "angles", "cx",
               "cy", "cn"}
    unknown = sorted(set(table) - own - windage)
    if unknown:
        import difflib

        near = difflib.get_close_matches(unknown[0], sorted(own | windage | set(DIRECTION_KEYS)), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise _core.ScenarioParseError(f"unknown field {unknown[0]!r} in [environment.wind]{hint} "
                                       f"(allowed: {', '.join(sorted(own | windage | set(DIRECTION_KEYS)))})")
    if "speed" not in table:
        raise _core.ScenarioParseError("missing field 'speed' in [environment.wind] (mean wind speed at 10 m, m/s)")
    kw = {k: table[k] for k in own if k in table}
    spectrum = kw.get("spectrum", "npd")
    if "centroid_x" in table and "ship_type" not in table:
        raise _core.InvalidInputError("environment.wind.centroid_x places the lateral area for Blendermann's "
                                      "coefficients of a ship_type; without ship_type nothing reads it: give ship_type, "
                                      "or remove centroid_x")
    if spectrum == "none":
        idle = [k for k in ("components", "seed", "omega_range") if k in kw]
        if idle:
            raise _core.InvalidInputError(f"environment.wind.{idle[0]} draws the gusts, and spectrum = 'none' has none: "
                                          f"remove {', '.join(idle)}, or give a gust spectrum ('npd' or 'harris')")
    for key, used_by in (("drag", "harris"), ("height", "npd")):
        if key in kw and spectrum != used_by:
            raise _core.InvalidInputError(
                f"environment.wind.{key} is a parameter of the {used_by!r} gust spectrum, and this wind's spectrum is "
                f"{spectrum!r}: remove {key}, or set spectrum = {used_by!r}")
    if "omega_range" in kw:
        _check_range("wind", kw["omega_range"])
        kw["omega_range"] = tuple(kw["omega_range"])
    if kw.get("spectrum") == "none":
        kw["spectrum"] = None
    rest = {k: v for k, v in table.items() if k not in own | {"ship_type", "centroid_x"}}
    if "ship_type" in table:
        given = [k for k in ("angles", "cx", "cy", "cn") if k in table]
        if given:
            raise _core.InvalidInputError(f"environment.wind: ship_type computes the coefficients; give either "
                                          f"ship_type or your own {', '.join(given)}, not both")
        # Blendermann's coefficients for the ship type, from the windage given with it
        for k in ("frontal_area", "lateral_area", "length"):
            if k not in table:
                raise _core.ScenarioParseError(f"missing field '{k}' in [environment.wind]: ship_type needs "
                                               "frontal_area, lateral_area and length")
        dims = [table[k] for k in ("frontal_area", "lateral_area", "length")] + [table.get("centroid_x", 0.0)]
        if not (all(_number(x) for x in dims) and all(x > 0 for x in dims[:3])):
            raise _core.InvalidInputError("environment.wind: frontal_area, lateral_area and length must be numbers "
                                          f"> 0 (m^2, m^2, m) and centroid_x a number (m), got {dims}")
        in_range("environment.wind", "length", dims[2])
        rest.update(blendermann(str(table["ship_type"]), *dims))
    return Wind(**kw).realise(), rest


#: Blendermann's wind load parameters per ship type: (CD_t, CD_l,AF at 0 deg (bow), at 180 deg
#: (stern), delta, kappa). W. Blendermann, "Parameter identification of wind loads on ships",
#: J. Wind Eng. Ind. Aerodyn. 51 (1994) 339-351, as tabulated in Fossen's MSS toolbox
#: (LIBRARY/environment/blendermann94.m).
BLENDERMANN = {
    "car carrier": (0.95, 0.55, 0.60, 0.80, 1.2),
    "cargo vessel, loaded": (0.85, 0.65, 0.55, 0.40, 1.7),
    "cargo vessel, container on deck": (0.85, 0.55, 0.50, 0.40, 1.4),
    "container ship, loaded": (0.90, 0.55, 0.55, 0.40, 1.4),
    "destroyer": (0.85, 0.60, 0.65, 0.65, 1.1),
    "diving support vessel": (0.90, 0.60, 0.80, 0.55, 1.7),
    "drilling vessel": (1.00, 0.85, 0.925, 0.10, 1.7),
    "ferry": (0.90, 0.45, 0.50, 0.80, 1.1),
    "fishing vessel": (0.95, 0.70, 0.70, 0.40, 1.1),
    "lng tanker": (0.70, 0.60, 0.65, 0.50, 1.1),
    "offshore supply vessel": (0.90, 0.55, 0.80, 0.55, 1.2),
    "passenger liner": (0.90, 0.40, 0.40, 0.80, 1.2),
    "research vessel": (0.85, 0.55, 0.65, 0.60, 1.4),
    "speed boat": (0.90, 0.55, 0.60, 0.60, 1.1),
    "tanker, loaded": (0.70, 0.90, 0.55, 0.40, 3.1),
    "tanker, in ballast": (0.70, 0.75, 0.55, 0.40, 2.2),
    "tender": (0.85, 0.55, 0.55, 0.65, 1.1),
}


@checked
def blendermann(ship_type: str, frontal_area: float, lateral_area: float, length: float,
                centroid_x: float = 0.0, step: float = 10.0) -> dict:
    """The ``[wind]`` coefficient table (``angles``, ``cx``, ``cy``, ``cn``, in phsplit's
    convention) from Blendermann's (1994) formulas for a ship type of :data:`BLENDERMANN`:

    ``C_X = −CD_l,AF cos γ_r / Δ``, ``C_Y = CD_t sin γ_r / Δ``, ``C_N = (s_L/L − 0.18 (γ_r − π/2)) C_Y``,
    ``Δ = 1 − ½ δ (1 − CD_l/CD_t) sin²(2γ_r)``, ``CD_l = CD_l,AF A_F / A_L``,

    with ``γ_r`` the angle of attack from the bow (0: a head wind) in the frame x forward, y to
    starboard, z down (Fossen's), and ``s_L = centroid_x`` the longitudinal position of the
    lateral area's centroid from midships (m). phsplit's body frame has y to port and z up, and
    its angle is that of the air's flow (0: from the stern): ``γ_r = π + γ``, and the sway force
    and yaw moment change sign. The yaw formula holds for ``γ_r`` in [0, π]; the other half is
    its mirror image (``C_N(−γ_r) = −C_N(γ_r)``)."""
    for name, v in (("frontal_area", frontal_area), ("lateral_area", lateral_area), ("length", length)):
        if not (_number(v) and v > 0):
            raise _core.InvalidInputError(f"blendermann: {name} must be a number > 0 (m^2, m^2, m), got {v!r}")
    in_range("blendermann", "length", length)
    if not _number(centroid_x) or abs(centroid_x) > length:
        raise _core.InvalidInputError(f"blendermann: centroid_x must be a number within ±length ({length:g} m) of "
                                      f"midships, got {centroid_x!r}")
    if not (_number(step) and 0 < step <= 90 and abs(360.0 / step - round(360.0 / step)) < 1e-9):
        raise _core.InvalidInputError(f"blendermann: step must be a number of degrees in (0, 90] that divides 360, "
                                      f"got {step!r}")
    if not isinstance(ship_type, str) or ship_type not in BLENDERMANN:
        raise _core.InvalidInputError(f"unknown ship type {ship_type!r} for Blendermann's wind loads; known: "
                                      f"{', '.join(sorted(BLENDERMANN))}")
    cdt, bow, stern, delta, _kappa = BLENDERMANN[ship_type]
    angles = np.arange(0.0, 360.0, step)
    g = np.radians(angles)
    gr = np.angle(np.exp(1j * (np.pi + g)))  # Fossen's angle of attack, in (−π, π]
    cdl_af = np.where(np.abs(gr) <= np.pi / 2, bow, stern)
    cdl = cdl_af * frontal_area / lateral_area
    den = 1.0 - 0.5 * delta * (1.0 - cdl / cdt) * np.sin(2.0 * gr) ** 2
    cx_f = -cdl_af * np.cos(gr) / den
    cy_f = cdt * np.sin(gr) / den
    a = np.abs(gr)
    cn_f = np.sign(gr) * (centroid_x / length - 0.18 * (a - np.pi / 2)) * cdt * np.sin(a) / den
    return {"angles": angles.tolist(), "cx": cx_f.tolist(), "cy": (-cy_f).tolist(), "cn": (-cn_f).tolist()}
