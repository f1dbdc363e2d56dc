"""The free rigid body, exactly: flow S1 of the splitting (paper eq. 40, §3.4.1).

``m' = m x w``, ``Q' = Q hat(w)``, ``w = T^-1 m``, with ``T = diag(T1, T2, T3)`` the principal
inertias (kg m^2), ``m`` the body angular momentum (kg m^2/s) and ``Q`` the attitude (body to
spatial). The momentum is exact, in Jacobi elliptic functions (Celledoni, Fasso, Safstrom,
Zanna 2008); the attitude is a Magnus expansion of order 2, 4 or 6 in the right-multiplied form
(docs/numerics.md). Both ``|m|`` and the kinetic energy ``m . T^-1 m / 2`` are conserved, and so
is the spatial momentum ``Q m``.

Accuracy (``crates/phsplit-core/tests/rigid_body_reference.rs``): against mpmath (the
closed form at 50 digits, checked against its ODE solver at 30) over random bodies,
near-symmetric bodies (inertia gaps down to 1e-14), states next to the separatrix and next to the
unstable middle axis, and ``t`` up to 1000, the momentum is within 4 times the problem's own
sensitivity (how far ``m(t)`` moves when one input moves one ulp), itself 1e-16 ... 1e-13 of
``|m0|`` there.
"""
from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core

__all__ = ["FreeRigidBody"]

FloatArray = NDArray[np.float64]


def _vec3(x: ArrayLike, name: str) -> FloatArray:
    v = np.ascontiguousarray(x, dtype=np.float64)
    if v.shape != (3,):
        raise _core.InvalidInputError(f"{name} must have shape (3,), got {v.shape}")
    return v


class FreeRigidBody:
    """A free rigid body with principal inertias ``inertia = (T1, T2, T3)`` (kg m^2, each > 0).

    >>> import numpy as np
    >>> from phsplit.rigid_body import FreeRigidBody
    >>> body = FreeRigidBody([1.0, 2.0, 3.0])
    >>> m = body.momentum([1e-3, 1.0, 1e-3], [0.0, 10.0, 20.0])  # the tennis-racket flip
    >>> m.shape
    (3, 3)
    >>> bool(np.allclose(np.linalg.norm(m, axis=-1), np.linalg.norm([1e-3, 1.0, 1e-3]), rtol=1e-15))
    True
    """

    def __init__(self, inertia: ArrayLike) -> None:
        self._body = _core.FreeRigidBody(_vec3(inertia, "inertia"))

    @property
    def inertia(self) -> FloatArray:
        """The principal inertias ``(T1, T2, T3)``, kg m^2."""
        return np.array(self._body.inertia)

    def __repr__(self) -> str:
        return repr(self._body)

    def momentum(self, m0: ArrayLike, t: ArrayLike) -> FloatArray:
        """The exact body angular momentum ``m(t)`` from ``m(0) = m0``.

        ``m0`` has shape ``(..., 3)``, ``t`` any shape; they broadcast (``m0[..., i]`` against
        ``t``), and the result has shape ``broadcast(m0.shape[:-1], t.shape) + (3,)``. One
        ``m0`` with an array of times evaluates one orbit at every time (no elliptic integral:
        the addition theorem from the start values). Negative times run backward.

        >>> import numpy as np
        >>> from phsplit.rigid_body import FreeRigidBody
        >>> body = FreeRigidBody([1.0, 2.0, 3.0])
        >>> print(np.array2string(body.momentum([1e-7, 1.0, 2e-7], 0.5), precision=10))
        [8.4318879023e-08 1.0000000000e+00 1.7700005672e-07]
        >>> body.momentum([[0.3, 0.1, 0.2], [1.0, 0.0, 0.0]], np.linspace(0, 1, 5)[:, None]).shape
        (5, 2, 3)
        """
        m = np.asarray(m0, dtype=np.float64)
        if m.ndim == 0 or m.shape[-1] != 3:
            raise _core.InvalidInputError(f"m0 must have shape (..., 3), got {m.shape}")
        tt = np.asarray(t, dtype=np.float64)
        if m.ndim == 1:
            flat = self._body.momentum(np.ascontiguousarray(m), np.ascontiguousarray(tt).reshape(-1))
            return flat.reshape(tt.shape + (3,))
        shape = np.broadcast_shapes(m.shape[:-1], tt.shape)
        mb = np.broadcast_to(m, shape + (3,))
        tb = np.broadcast_to(tt, shape)
        flat = self._body.momentum(np.ascontiguousarray(mb).reshape(-1), np.ascontiguousarray(tb).reshape(-1))
        return flat.reshape(shape + (3,))

    def flow(
        self, m0: ArrayLike, Q0: ArrayLike, h: float, magnus_order: int = 6
    ) -> tuple[FloatArray, FloatArray]:
        """One step of flow S1 over ``h``: ``(m(h), Q(h))`` from ``(m0, Q0)``.

        The momentum is exact; the attitude ``Q(h) = Q0 exp(hat Omega)`` with the Magnus exponent
        ``Omega`` of order ``magnus_order`` (2, 4 or 6) from the exact angular velocity at the
        Gauss nodes, and one Bjorck step to keep ``Q`` orthogonal to round-off. ``Q0`` is 3 x 3.

        >>> import numpy as np
        >>> from phsplit.rigid_body import FreeRigidBody
        >>> body = FreeRigidBody([1.0, 2.0, 3.0])
        >>> m0, Q = np.array([0.3, -0.8, 0.5]), np.eye(3)
        >>> m = m0
        >>> for _ in range(100):
        ...     m, Q = body.flow(m, Q, 0.01, magnus_order=6)
        >>> bool(np.allclose(Q @ m, m0, atol=1e-13))  # the spatial momentum is conserved
        True
        """
        m = _vec3(m0, "m0")
        q = np.ascontiguousarray(Q0, dtype=np.float64)
        if q.shape != (3, 3):
            raise _core.InvalidInputError(f"Q0 must have shape (3, 3), got {q.shape}")
        if isinstance(magnus_order, bool) or not isinstance(magnus_order, (int, np.integer)):
            raise _core.InvalidInputError(f"magnus_order must be 2, 4 or 6, got {magnus_order!r}")
        if int(magnus_order) < 0:
            raise _core.InvalidInputError(f"magnus_order must be 2, 4 or 6, got {magnus_order}")
        m1, q1 = self._body.flow(m, q.reshape(-1), float(h), int(magnus_order))
        return np.array(m1), np.array(q1).reshape(3, 3)

    def period(self, m0: ArrayLike) -> float | None:
        """Period of the momentum through ``m0``: ``4 K(k^2) / |lambda|`` (s).

        ``math.inf`` on the separatrix, ``None`` at a fixed point (zero momentum, a rotation
        about a principal axis, or a sphere).

        >>> import numpy as np
        >>> from phsplit.rigid_body import FreeRigidBody
        >>> body = FreeRigidBody([1.0, 2.0, 3.0])
        >>> T = body.period([0.3, -0.8, 0.5])
        >>> bool(np.allclose(body.momentum([0.3, -0.8, 0.5], T), [0.3, -0.8, 0.5], atol=1e-14))
        True
        >>> body.period([0.0, 1.0, 0.0]) is None
        True
        """
        p = self._body.period(_vec3(m0, "m0"))
        return None if p is None else (math.inf if math.isinf(p) else float(p))

    def elliptic_parameter(self, m0: ArrayLike) -> tuple[float, float] | None:
        """``(k^2, 1 - k^2)`` of the orbit through ``m0`` (``None`` at a fixed point).

        ``1 - k^2`` is formed without cancellation: next to the separatrix it keeps its digits.

        >>> from phsplit.rigid_body import FreeRigidBody
        >>> k2, k1 = FreeRigidBody([1.0, 2.0, 3.0]).elliptic_parameter([1e-7, 1.0, 2e-7])
        >>> print(k2, k1)
        0.9999999999999867 1.333333333333262e-14
        """
        return self._body.elliptic_parameter(_vec3(m0, "m0"))

    def kinetic_energy(self, m: ArrayLike) -> FloatArray:
        """Kinetic energy ``m . T^-1 m / 2`` (J) of momenta of shape ``(..., 3)``.

        >>> from phsplit.rigid_body import FreeRigidBody
        >>> float(FreeRigidBody([1.0, 2.0, 4.0]).kinetic_energy([1.0, 2.0, 4.0]))
        3.5
        """
        mm = np.asarray(m, dtype=np.float64)
        return 0.5 * np.sum(mm * mm / self.inertia, axis=-1)
