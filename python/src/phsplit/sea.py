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
  spreading function, ``D(θ) ∝ cos^{2s}((θ − θ_mean)/2)``), one random direction per component
  drawn from it.

All random numbers come from ``numpy.random.default_rng(seed)``: the same seed gives the same sea.
The result is the ``[waves]`` table's sea-state keys (``frequencies``, ``amplitudes``, ``phases``,
``directions``), ready to merge with the vessel's transfer functions."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _core

SPECTRA = ("jonswap", "pierson-moskowitz")


@dataclass(frozen=True)
class SeaState:
    """A sea state: ``hs`` (m), ``tp`` (s), ``gamma`` (JONSWAP peak enhancement; ignored for
    Pierson–Moskowitz), ``direction`` (degrees, the direction the waves travel towards, spatial,
    from x towards y), ``spreading`` (cos-2s exponent, or None for long-crested waves),
    ``seed``, ``components`` and the frequency range ``omega_range`` (rad/s; default
    ``[0.5, 3] ω_p``)."""

    hs: float
    tp: float
    gamma: float = 3.3
    spectrum: str = "jonswap"
    direction: float = 0.0
    spreading: float | None = None
    seed: int = 0
    components: int = 200
    omega_range: tuple[float, float] | None = None

    def __post_init__(self):
        def bad(msg):
            raise _core.InvalidInputError(f"waves: {msg}")

        for name, v in (("hs", self.hs), ("tp", self.tp)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                bad(f"{name} must be a number > 0 ({'m' if name == 'hs' else 's'}), got {v!r}")
        if self.spectrum not in SPECTRA:
            bad(f"spectrum must be one of {', '.join(repr(s) for s in SPECTRA)}, got {self.spectrum!r}")
        if not (math.isfinite(self.gamma) and 1.0 <= self.gamma <= 10.0):
            bad(f"gamma must lie in [1, 10] (the JONSWAP peak enhancement; 3.3 is the mean of JONSWAP), got {self.gamma!r}")
        if not math.isfinite(self.direction):
            bad(f"direction must be finite (degrees), got {self.direction!r}")
        if self.spreading is not None and not (math.isfinite(self.spreading) and self.spreading > 0):
            bad(f"spreading must be > 0 (the cos-2s exponent) or absent, got {self.spreading!r}")
        if not (isinstance(self.components, int) and 1 <= self.components <= 10_000):
            bad(f"components must be an integer in [1, 10000], got {self.components!r}")
        if not (isinstance(self.seed, int) and self.seed >= 0):
            bad(f"seed must be an integer >= 0, got {self.seed!r}")
        lo, hi = self.range()
        if not (0 < lo < hi and math.isfinite(hi)):
            bad(f"omega_range must be two increasing frequencies > 0 (rad/s), got {self.omega_range!r}")

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
        else:
            dirs = self.direction + np.degrees(_cos2s_draw(rng, self.spreading, n))
        return {"frequencies": omega.tolist(), "amplitudes": amp.tolist(), "phases": phase.tolist(),
                "directions": dirs.tolist()}


def _cos2s_draw(rng, s: float, n: int) -> np.ndarray:
    """n angles (rad) from D(θ) ∝ cos^{2s}(θ/2) on (−π, π], by inverting its tabulated CDF."""
    th = np.linspace(-np.pi, np.pi, 20001)
    d = np.cos(th / 2.0) ** (2.0 * s)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (d[1:] + d[:-1]) * np.diff(th))])
    cdf /= cdf[-1]
    return np.interp(rng.uniform(0.0, 1.0, n), cdf, th)


def regular(amplitude: float, omega: float, direction: float = 0.0, phase: float = 0.0) -> dict[str, list[float]]:
    """One regular wave: amplitude (m), frequency (rad/s), direction (degrees), phase (rad)."""
    return {"frequencies": [float(omega)], "amplitudes": [float(amplitude)], "phases": [float(phase)],
            "directions": [float(direction)]}


def sea_state(table: dict) -> SeaState:
    """A :class:`SeaState` from a scenario's ``[environment.waves]`` keys (unknown keys named)."""
    allowed = {"hs", "tp", "gamma", "spectrum", "direction", "spreading", "seed", "components", "omega_range"}
    unknown = sorted(set(table) - allowed - {"hydro", "symmetric"})
    if unknown:
        import difflib

        near = difflib.get_close_matches(unknown[0], sorted(allowed), n=1)
        hint = f"; did you mean {near[0]!r}?" if near else ""
        raise _core.ScenarioParseError(f"unknown field {unknown[0]!r} in [environment.waves]{hint} "
                                       f"(allowed: {', '.join(sorted(allowed | {'hydro', 'symmetric'}))})")
    for k in ("hs", "tp"):
        if k not in table:
            raise _core.ScenarioParseError(f"missing field {k!r} in [environment.waves] "
                                           f"({'significant wave height, m' if k == 'hs' else 'peak period, s'})")
    kw = {k: table[k] for k in allowed if k in table}
    if "omega_range" in kw:
        kw["omega_range"] = tuple(kw["omega_range"])
    return SeaState(**kw)
