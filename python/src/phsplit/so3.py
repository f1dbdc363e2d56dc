"""Rotations: the SO(3) exponential and logarithm, ZYX Euler angles and unit quaternions.

Conventions (as in the core, ``lie::so3``, and docs/numerics.md): an attitude ``Q`` maps body to
spatial vectors; ``exp(w) = exp(hat w)`` with ``hat(w) u = w x u``; ZYX Euler angles are
``(phi, theta, psi)`` = (roll, pitch, yaw) with ``Q = Rz(psi) Ry(theta) Rx(phi)`` (paper eq. 21);
quaternions are scalar first, ``(q0, q1, q2, q3)`` with ``q0 >= 0``. Angles in radians.

Every function is vectorised: it takes a stack of vectors ``(..., 3)`` (or quaternions
``(..., 4)``) or of matrices ``(..., 3, 3)`` and returns the matching stack.

Gimbal lock: where ``cos(theta) <= GIMBAL_LOCK`` (4 eps) the pitch is ``+-pi/2`` to round-off and
``Q`` depends on ``psi -+ phi`` only; :func:`euler_zyx` then returns ``phi = 0`` (scipy's
convention) and the yaw that rebuilds ``Q``. Next to it, the roll is read so that the angles
rebuild ``Q`` to round-off at every pitch.
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _core

__all__ = ["GIMBAL_LOCK", "exp", "euler_zyx", "from_euler_zyx", "from_quaternion", "log",
           "quaternion"]

FloatArray = NDArray[np.float64]

#: ``cos(theta)`` at and below which :func:`euler_zyx` treats the pitch as ``+-pi/2``.
GIMBAL_LOCK: float = float(_core.GIMBAL_LOCK)


def _rows(x: ArrayLike, tail: tuple[int, ...], name: str) -> tuple[tuple[int, ...], FloatArray]:
    a = np.asarray(x, dtype=np.float64)
    if a.shape[a.ndim - len(tail):] != tail or a.ndim < len(tail):
        want = "(..., " + ", ".join(map(str, tail)) + ")"
        raise _core.InvalidInputError(f"{name} must have shape {want}, got {a.shape}")
    lead = a.shape[: a.ndim - len(tail)]
    return lead, np.ascontiguousarray(a).reshape(-1)


def exp(w: ArrayLike) -> FloatArray:
    """The rotation ``exp(hat w)`` (Rodrigues' formula, exact to round-off at small angles).

    >>> import numpy as np
    >>> from phsplit import so3
    >>> R = so3.exp([0.0, 0.0, np.pi / 2])
    >>> np.round(R, 12) + 0.0
    array([[ 0., -1.,  0.],
           [ 1.,  0.,  0.],
           [ 0.,  0.,  1.]])
    >>> so3.exp(np.zeros((4, 2, 3))).shape
    (4, 2, 3, 3)
    """
    lead, flat = _rows(w, (3,), "w")
    return _core.so3_exp(flat).reshape(lead + (3, 3))


def log(R: ArrayLike) -> FloatArray:
    """The principal logarithm: ``w`` with ``exp(hat w) = R`` and ``|w| <= pi``.

    Accurate at every angle (``atan2`` of the skew and symmetric parts; the axis from the
    symmetric part next to pi).

    >>> import numpy as np
    >>> from phsplit import so3
    >>> w = np.array([0.3, -1.2, 2.5])
    >>> bool(np.allclose(so3.log(so3.exp(w)), w, atol=1e-15))
    True
    """
    lead, flat = _rows(R, (3, 3), "R")
    return _core.so3_log(flat).reshape(lead + (3,))


def euler_zyx(R: ArrayLike) -> FloatArray:
    """ZYX Euler angles ``(phi, theta, psi)`` of ``R = Rz(psi) Ry(theta) Rx(phi)``.

    ``theta`` in ``[-pi/2, pi/2]``, ``phi`` and ``psi`` in ``(-pi, pi]``. The angles rebuild
    ``R`` to round-off at every pitch; at gimbal lock (``cos(theta) <= GIMBAL_LOCK``) the roll is
    0 and the yaw carries ``psi -+ phi``, as scipy's ``Rotation.as_euler("ZYX")``.

    >>> import numpy as np
    >>> from phsplit import so3
    >>> print(np.round(so3.euler_zyx(so3.from_euler_zyx(0.3, -0.2, 1.1)), 12) + 0.0)
    [ 0.3 -0.2  1.1]
    >>> # gimbal lock, with the round-off of a matrix built through quaternions
    >>> R = so3.from_quaternion(so3.quaternion(so3.from_euler_zyx(0.3, np.pi / 2, -1.1)))
    >>> e = so3.euler_zyx(R)
    >>> print(np.round(e, 12) + 0.0)
    [ 0.          1.57079633 -1.4       ]
    >>> bool(np.allclose(so3.from_euler_zyx(e), R, atol=1e-15))
    True
    """
    lead, flat = _rows(R, (3, 3), "R")
    return _core.so3_euler_zyx(flat).reshape(lead + (3,))


def from_euler_zyx(
    phi: ArrayLike, theta: ArrayLike | None = None, psi: ArrayLike | None = None
) -> FloatArray:
    """The rotation ``Rz(psi) Ry(theta) Rx(phi)`` from ZYX Euler angles (paper eq. 21).

    Either one argument of shape ``(..., 3)`` holding ``(phi, theta, psi)``, or the three angles
    as separate arguments (broadcast against each other).

    >>> import numpy as np
    >>> from phsplit import so3
    >>> R = so3.from_euler_zyx(0.0, 0.0, np.pi / 2)  # a yaw of 90 degrees
    >>> np.round(R @ [1.0, 0.0, 0.0], 12) + 0.0
    array([0., 1., 0.])
    >>> so3.from_euler_zyx(np.zeros((5, 3))).shape
    (5, 3, 3)
    """
    if theta is None and psi is None:
        angles = np.asarray(phi, dtype=np.float64)
    elif theta is None or psi is None:
        raise _core.InvalidInputError(
            "from_euler_zyx takes one (..., 3) array of (phi, theta, psi) or all three angles"
        )
    else:
        angles = np.stack(np.broadcast_arrays(*(np.asarray(a, dtype=np.float64)
                                                for a in (phi, theta, psi))), axis=-1)
    lead, flat = _rows(angles, (3,), "(phi, theta, psi)")
    return _core.so3_from_euler_zyx(flat).reshape(lead + (3, 3))


def quaternion(R: ArrayLike) -> FloatArray:
    """The unit quaternion ``(q0, q1, q2, q3)`` of ``R``, scalar first, ``q0 >= 0``.

    A matrix further than 1e-10 from orthogonal is first projected to the nearest rotation.

    >>> import numpy as np
    >>> from phsplit import so3
    >>> q = so3.quaternion(so3.exp([0.0, 0.0, np.pi / 2]))
    >>> print(np.round(q, 12) + 0.0)
    [0.70710678 0.         0.         0.70710678]
    """
    lead, flat = _rows(R, (3, 3), "R")
    return _core.so3_quaternion(flat).reshape(lead + (4,))


def from_quaternion(q: ArrayLike) -> FloatArray:
    """The rotation of a quaternion ``(q0, q1, q2, q3)`` (normalised first; scalar first):
    ``E(q) = I + 2 q0 hat(qv) + 2 hat(qv)^2`` (paper Appendix A).

    >>> import numpy as np
    >>> from phsplit import so3
    >>> R = so3.exp([0.1, -0.4, 0.8])
    >>> bool(np.allclose(so3.from_quaternion(so3.quaternion(R)), R, atol=1e-15))
    True
    """
    lead, flat = _rows(q, (4,), "q")
    return _core.so3_from_quaternion(flat).reshape(lead + (3, 3))
