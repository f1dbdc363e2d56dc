"""Jacobi elliptic functions and elliptic integrals of the first kind.

The core's implementations (``phsplit-core``, ``lie::elliptic``) with scipy's names and argument
order: :func:`ellipj`, :func:`ellipk`, :func:`ellipkm1`, :func:`ellipkinc`. The parameter is
``m = k**2`` throughout, as in scipy and mpmath. Every function takes numpy arrays (or anything
``numpy.asarray`` accepts), broadcasts them against each other, releases the GIL while it
computes, and returns float64 arrays of the broadcast shape (numpy scalars for scalar inputs).

Accuracy, against mpmath (``crates/phsplit-core/tests/elliptic_reference.rs``):

* ``sn, cn, dn`` within 8 ulp, or within ``4 eps |u|`` absolute where the argument reduction
  limits it, for every ``m`` in ``[0, 1]`` and ``|u|`` up to ``1e15`` (the tables of Boost.Math
  and an adversarial grid reach 3 ulp); the argument is reduced by the periods with ``K`` in
  double-double, so accuracy does not degrade with ``|u|``, and subnormal or signed-zero
  arguments are exact;
* ``K`` within 4 ulp (correctly rounded on all tested inputs), ``F`` within 8 ulp or twice its own
  conditioning limit.

Domain (documented choices where scipy returns NaN):

* :func:`ellipj`: every finite ``m``; ``m < 0`` and ``m > 1`` through the imaginary- and
  reciprocal-modulus transformations (DLMF 22.17). scipy returns NaN outside ``[0, 1]``.
* :func:`ellipk`: ``m <= 1`` (``K(1) = inf``); ``m > 1`` raises.
* :func:`ellipkinc`: where ``F`` is real: every ``phi`` for ``m < 1``; ``|phi| <= pi/2`` for
  ``m = 1`` (``inf`` beyond; a double never equals pi/2, so ``F(fl(pi/2) | 1) = 38.03``, where
  scipy returns ``inf``); ``m sin(phi)**2 <= 1`` for ``m > 1``. Elsewhere it raises.

Out-of-domain input raises :class:`phsplit.InvalidInputError` (a ``ValueError``) naming the
argument, the range and the offending value; infinite ``u`` or ``phi`` raise too. NaN inputs give
NaN outputs, as in numpy.

References: DLMF chapters 19 and 22; Abramowitz & Stegun 16-17.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core

__all__ = ["ellipj", "ellipk", "ellipkinc", "ellipkm1"]

FloatArray = NDArray[np.float64]


def _flat(*args: ArrayLike) -> tuple[tuple[int, ...], list[FloatArray]]:
    """Broadcast to float64, return the shape and contiguous flat copies."""
    arrays = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in args))
    shape = arrays[0].shape if arrays else ()
    return shape, [np.ascontiguousarray(a).reshape(-1) for a in arrays]


def _shaped(a: FloatArray, shape: tuple[int, ...]) -> FloatArray:
    out = a.reshape(shape)
    return out[()] if shape == () else out


def ellipj(u: ArrayLike, m: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Jacobi elliptic functions ``(sn, cn, dn, ph)`` of ``u`` at parameter ``m = k**2``.

    As ``scipy.special.ellipj(u, m)``: ``ph = am(u | m)`` is the amplitude, the continuous angle
    with ``sin ph = sn``, ``cos ph = cn`` and ``F(ph | m) = u``. ``u`` and ``m`` broadcast.

    Any finite ``m`` is accepted (``m < 0`` and ``m > 1`` by the modulus transformations of
    DLMF 22.17); ``u`` must be finite. See the module docstring for accuracy.

    >>> import numpy as np
    >>> from phsplit.special import ellipj
    >>> sn, cn, dn, ph = ellipj(0.5, 0.3)
    >>> print(f"{sn:.15f} {cn:.15f} {dn:.15f} {ph:.15f}")
    0.474215622711821 0.880408736426462 0.965678964745951 0.494072893711047
    >>> sn, cn, dn, ph = ellipj(np.array([0.0, 1.0, 709.0]), 0.9990000000000001)
    >>> np.round(sn, 6)
    array([ 0.      ,  0.76168 , -0.975702])
    """
    shape, (uu, mm) = _flat(u, m)
    sn, cn, dn, ph = _core.special_ellipj(uu, mm)
    return _shaped(sn, shape), _shaped(cn, shape), _shaped(dn, shape), _shaped(ph, shape)


def ellipk(m: ArrayLike) -> FloatArray:
    """Complete elliptic integral of the first kind ``K(m)``, ``m <= 1``.

    As ``scipy.special.ellipk(m)``: ``K(m) = F(pi/2 | m)``, ``K(1) = inf``, ``K(-inf) = 0``;
    ``m > 1`` (where ``K`` is complex) raises :class:`phsplit.InvalidInputError`. Computed by
    the arithmetic-geometric mean in double-double arithmetic (DLMF 19.8.5).

    >>> from phsplit.special import ellipk
    >>> print(f"{ellipk(0.5):.16f}")
    1.8540746773013719
    >>> ellipk([0.0, 1.0])
    array([1.57079633,        inf])
    """
    shape, (mm,) = _flat(m)
    return _shaped(_core.special_ellipk(mm), shape)


def ellipkm1(p: ArrayLike) -> FloatArray:
    """``K(1 - p)``: the complete integral from the complementary parameter ``p = 1 - m >= 0``.

    As ``scipy.special.ellipkm1(p)``: use it where ``m`` is next to 1 and ``p`` is known to more
    digits than ``1 - m`` keeps (``K`` depends on ``p`` logarithmically, ``K ~ ln(16/p)/2``).

    >>> from phsplit.special import ellipk, ellipkm1
    >>> print(f"{ellipkm1(1e-20):.12f}")
    24.412145291060
    >>> bool(ellipk(1.0 - 1e-20) == ellipk(1.0))  # 1 - 1e-20 rounds to 1
    True
    """
    shape, (pp,) = _flat(p)
    return _shaped(_core.special_ellipkm1(pp), shape)


def ellipkinc(phi: ArrayLike, m: ArrayLike) -> FloatArray:
    """Incomplete elliptic integral of the first kind ``F(phi | m)``.

    As ``scipy.special.ellipkinc(phi, m)``: ``F(phi | m) = int_0^phi dt / sqrt(1 - m sin(t)**2)``;
    ``phi`` and ``m`` broadcast. Real, and computed, for every finite ``phi`` when ``m < 1``, for
    ``|phi| <= pi/2`` when ``m = 1`` (``+-inf`` beyond), and for ``m sin(phi)**2 <= 1`` when
    ``m > 1``; elsewhere it raises :class:`phsplit.InvalidInputError`. It inverts the
    amplitude: ``ellipkinc(ellipj(u, m)[3], m) == u`` to round-off.

    >>> import numpy as np
    >>> from phsplit.special import ellipj, ellipkinc
    >>> print(f"{ellipkinc(1.0, 0.5):.15f}")
    1.083216772845169
    >>> u = np.array([0.3, 2.0, 25.0])
    >>> np.allclose(ellipkinc(ellipj(u, 0.7)[3], 0.7), u, rtol=1e-15)
    True
    """
    shape, (pp, mm) = _flat(phi, m)
    return _shaped(_core.special_ellipkinc(pp, mm), shape)
