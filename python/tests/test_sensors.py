"""The sensors the observer reads, ``[sensors]`` (docs/explanation/components/observer.md,
"Sensors"): a GNSS position and a gyro heading sampled at their rates with bias and seeded
white noise, held between samples, and dropouts during which the observer runs on its model.

References: the statistics of the samples against the table's bias and standard deviation
(the truth is the run's own state at each sample instant); the sampled observer against the
continuously measured one as the sample period and the step shrink together (first order, a
fitted slope); dead reckoning during a dropout against the integral of the observer's own
velocity estimate (its kinematics, ``eta^' = R nu^``, integrated here by Simpson's rule);
the ledger's balance."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import simpson

import phsplit
from checks import within_passivity_bound

W0 = 0.7
DAMPING = [3.53933789e4, 1.1781388e5, 3.15094664584e8]   # the paper's surge, sway, yaw damping
LOAD = {"force": [6e4, -3e4, 0.0], "moment": [0.0, 0.0, 2e6], "frame": "spatial"}
SENSORS = {"gnss_rate": 1.0, "gyro_rate": 2.0, "gnss_noise": 0.5, "gnss_bias": [0.3, -0.2],
           "gyro_noise": 0.002, "gyro_bias": 0.001, "seed": 3}


def vessel(sensors=None, observer=None, external=LOAD, initial=None):
    d = phsplit.Vessel.paper().to_dict()
    if initial is not None:
        d["initial"].update(initial)
    d["control"]["feedback"] = "observer"
    d["observer"] = {"wave_frequency": W0, "damping": DAMPING, "initial_estimate": [790.0, 28.0, 0.6],
                     **(observer or {})}
    if sensors is not None:
        d["sensors"] = sensors
    if external is not None:
        d["external"] = external
    return phsplit.Vessel.from_dict(d)


def own(s, v, name):
    return np.asarray(s.own)[:, [o[0] for o in v.own_states].index(name)]


@pytest.fixture(scope="module")
def noisy():
    v = vessel(SENSORS)
    return v, phsplit.simulate(v, (0.0, 1200.0), 0.5, "sp4", control_start=0.0)


def test_the_samples_carry_the_bias_and_the_noise(noisy):
    v, s = noisy
    at = (np.abs(s.t - np.round(s.t)) < 1e-9) & (s.t > 0)        # the 1 Hz instants
    n = int(at.sum())
    for name, k, bias in (("measured_x", 0, 0.3), ("measured_y", 1, -0.2)):
        e = own(s, v, name)[at] - s.x[at, k]
        assert abs(e.mean() - bias) < 4 * 0.5 / math.sqrt(n), (name, e.mean())
        assert abs(e.std(ddof=1) / 0.5 - 1) < 4 / math.sqrt(2 * n), (name, e.std(ddof=1))
    at2 = (np.abs(2 * s.t - np.round(2 * s.t)) < 1e-9) & (s.t > 0)  # the 2 Hz instants
    e = own(s, v, "measured_heading")[at2] - s.euler[at2, 2]
    m = int(at2.sum())
    assert abs(e.mean() - 0.001) < 4 * 0.002 / math.sqrt(m)
    assert abs(e.std(ddof=1) / 0.002 - 1) < 4 / math.sqrt(2 * m)
    # consecutive samples are independent (white)
    x = own(s, v, "measured_x")[at] - s.x[at, 0]
    x = x - x.mean()
    assert abs(np.dot(x[1:], x[:-1]) / np.dot(x, x)) < 4 / math.sqrt(n)


def test_the_measurement_is_held_between_samples(noisy):
    v, s = noisy
    mx = own(s, v, "measured_x")
    changed = s.t[1:][np.diff(mx) != 0.0]
    np.testing.assert_allclose(changed, np.arange(1.0, 1201.0))   # once a second, at the instants
    k = own(s, v, "gnss_sample")
    assert np.all(k == np.floor(s.t + 1e-9))


def test_off_the_step_grid_a_sample_is_taken_at_the_first_step_end_after_its_instant():
    v = vessel({"gnss_rate": 1.0, "gyro_rate": 1.0})
    s = phsplit.simulate(v, (0.0, 12.0), 0.3, "sp2", control_start=0.0)
    mx = own(s, v, "measured_x")
    changed = s.t[1:][np.diff(mx) != 0.0]
    want = np.ceil(np.arange(1.0, 13.0) / 0.3 - 1e-9) * 0.3
    np.testing.assert_allclose(changed, want[want <= 12.0 + 1e-9], atol=1e-9)
    i = np.searchsorted(s.t, changed - 1e-9)
    np.testing.assert_array_equal(mx[i], s.x[i, 0])           # noise-free: the state at that step end


def test_the_noise_is_the_seeds_and_a_continued_run_draws_the_same():
    v = vessel(SENSORS)
    one = phsplit.simulate(v, (0.0, 200.0), 0.5, "sp2", control_start=0.0)
    first = phsplit.simulate(v, (0.0, 100.0), 0.5, "sp2", control_start=0.0)
    second = phsplit.simulate(v, (100.0, 200.0), 0.5, "sp2", control_start=0.0, initial=first.state(-1),
                              _continuing=True)
    np.testing.assert_array_equal(np.asarray(one.own)[-1], np.asarray(second.own)[-1])
    np.testing.assert_array_equal(one.x[-1], second.x[-1])
    other = phsplit.simulate(vessel({**SENSORS, "seed": 4}), (0.0, 200.0), 0.5, "sp2", control_start=0.0)
    assert np.any(np.asarray(other.own)[-1] != np.asarray(one.own)[-1])


def test_sampling_converges_on_the_continuous_observer_at_first_order():
    """Noise-free sensors sampled once a step hold each step's end for the next: as the step
    (and the sample period with it) shrinks the run approaches the continuously measured
    observer's at first order."""
    t_end = 60.0
    cont = phsplit.simulate(vessel(), (0.0, t_end), 0.005, "sp2", control_start=0.0)
    want = np.asarray(cont.own)[-1][6:9]
    hs = np.array([0.4, 0.2, 0.1, 0.05])
    errs = []
    for h in hs:
        s = phsplit.simulate(vessel({"gnss_rate": 1.0 / h, "gyro_rate": 1.0 / h}), (0.0, t_end), h, "sp2",
                             control_start=0.0)
        errs.append(np.linalg.norm(np.asarray(s.own)[-1][6:8] - want[:2]))
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 0.85 < slope < 1.2, (slope, errs)


def test_during_a_dropout_the_observer_reckons_from_its_velocity_estimate():
    """The vessel starts on its set point, the estimate 14 m off; the receiver drops out while
    the estimate is still converging: its position estimate then moves by its velocity estimate
    alone."""
    v = vessel({"gnss_rate": 1.0, "gyro_rate": 1.0, "gnss_dropout": [[20.0, 120.0]]},
               initial={"position": [780.0, 20.0, 0.0], "euler": [0.0, 0.0, 0.54]})
    s = phsplit.simulate(v, (0.0, 900.0), 0.1, "sp4", control_start=0.0)
    valid = own(s, v, "gnss_valid")
    out = (s.t >= 20.0) & (s.t < 120.0)
    assert np.all(valid[out] == 0.0) and np.all(valid[(s.t < 19.9) | (s.t >= 120.0)] == 1.0)
    mx = own(s, v, "measured_x")
    assert np.all(mx[out] == mx[np.argmax(s.t >= 19.95) - 1])  # held at the last sample before it
    # dead reckoning: with no position injection, eta^_xy' = (R(psi_measured) nu^)_xy
    o = np.asarray(s.own)
    psi = own(s, v, "measured_heading")
    c, sn = np.cos(psi), np.sin(psi)
    vx = c * o[:, 12] - sn * o[:, 13]
    vy = sn * o[:, 12] + c * o[:, 13]
    i0, i1 = np.argmax(s.t >= 20.0), np.argmax(s.t >= 119.95)
    dx = simpson(vx[i0:i1 + 1], x=s.t[i0:i1 + 1])
    dy = simpson(vy[i0:i1 + 1], x=s.t[i0:i1 + 1])
    moved = np.hypot(o[i1, 6] - o[i0, 6], o[i1, 7] - o[i0, 7])
    assert moved > 1.0
    np.testing.assert_allclose([o[i1, 6] - o[i0, 6], o[i1, 7] - o[i0, 7]], [dx, dy], atol=1e-4 * moved)
    # and the estimate converges when the receiver is back
    err = s.outputs["observer_position_error"][2]
    assert err[np.argmax(s.t >= 118.0)] > 1.0
    assert err[-1] < 0.05 * err[np.argmax(s.t >= 118.0)]


def test_a_dropout_after_convergence_keeps_the_vessel_near_its_set_point():
    """Converged (after 300 s under the constant load), the receiver drops out for 100 s: on its
    bias estimate the controller keeps balancing the load, and the vessel stays within 2.5 m."""
    v = vessel({"gnss_rate": 1.0, "gyro_rate": 1.0, "gnss_dropout": [[300.0, 400.0]]},
               initial={"position": [780.0, 20.0, 0.0], "euler": [0.0, 0.0, 0.54]})
    s = phsplit.simulate(v, (0.0, 700.0), 0.5, "sp4", control_start=0.0)
    off = np.hypot(s.x[:, 0] - 780.0, s.x[:, 1] - 20.0)
    err = s.outputs["observer_position_error"][2]
    out = (s.t >= 300.0) & (s.t < 400.0)
    assert off[np.argmax(s.t >= 299.0)] < 0.5
    assert off[out].max() < 2.5, off[out].max()
    assert err[-1] < 0.05 * err[out].max()


def test_the_ledger_closes_with_sensors(noisy):
    _, s = noisy
    assert np.max(s.ledger.relative_residual()) < 1e-10
    assert within_passivity_bound(s)


def test_the_vessel_file_round_trips_the_sensors():
    v = vessel({**SENSORS, "gnss_dropout": [[10.0, 20.0], [30.0, 31.0]]})
    again = phsplit.Vessel.from_toml_str(v.to_toml())
    assert again.to_dict()["sensors"] == v.to_dict()["sensors"]
    assert v.to_dict()["sensors"]["gnss_dropout"] == [[10.0, 20.0], [30.0, 31.0]]



def test_the_shipped_dp_observer_scenario_sits_off_by_the_gnss_bias():
    """dp-observer: the controller on the estimates of the observer, which reads a biased GNSS.
    A constant sensor bias is indistinguishable from a displaced vessel: the estimate follows the
    measurement, so it sits off the true position by the bias, and the ledger closes."""
    sc = phsplit.load_scenario("dp-observer")
    v = sc.vessel
    s = phsplit.simulate(v, (0.0, 900.0), 0.5, "sp4", control_start=0.0)
    assert s.status == "completed"
    late = s.t >= 300.0
    est = np.column_stack([own(s, v, "observer_x"), own(s, v, "observer_y")])[late]
    off = (est - s.x[late, :2]).mean(axis=0)
    bias = np.array(v.to_dict()["sensors"]["gnss_bias"])
    np.testing.assert_allclose(off, bias, atol=0.05)
    assert np.max(s.ledger.relative_residual()) < 1e-10


ARM = [-10.0, 4.0, 25.0]    # m, body frame: the antenna 25 m up a mast aft of the origin (z up)


def test_the_gnss_antenna_is_referred_to_the_origin_with_the_mru_and_the_gyro():
    """``gnss_antenna``: the receiver measures ``x + Q r_a``; the DP system subtracts ``R(Θ~) r_a``
    with the MRU's roll and pitch and the gyro's heading. With a perfect MRU and gyro the fix is
    the origin's to round-off, although the arm alone moves the antenna by metres as the vessel
    rolls; with biased ones it is off by exactly ``Q r_a - R(Θ~) r_a``, computed again here with
    scipy's rotations from the run's attitude."""
    from scipy.spatial.transform import Rotation

    base = {"gnss_rate": 1.0, "gyro_rate": 1.0, "gnss_antenna": ARM}
    initial = {"euler": [0.1, -0.05, 0.1]}   # rolled and trimmed: the vessel rolls and pitches freely
    arm = np.array(ARM)
    for extra in ({}, {"mru_bias": [0.01, -0.02], "gyro_bias": 0.004}):
        v = vessel({**base, **extra}, external=None, initial=initial)
        s = phsplit.simulate(v, (0.0, 60.0), 0.5, "sp4", control_start=None)
        at = np.flatnonzero((np.abs(s.t - np.round(s.t)) < 1e-9) & (s.t > 0))
        mx, my = own(s, v, "measured_x")[at], own(s, v, "measured_y")[at]
        zyx = Rotation.from_matrix(s.Q[at]).as_euler("ZYX")           # (psi, theta, phi)
        b = extra.get("mru_bias", [0.0, 0.0])
        measured = Rotation.from_euler("ZYX", np.column_stack(
            [zyx[:, 0] + extra.get("gyro_bias", 0.0), zyx[:, 1] + b[1], zyx[:, 2] + b[0]]))
        want = s.x[at] + s.Q[at] @ arm - measured.apply(arm)
        np.testing.assert_allclose(mx, want[:, 0], rtol=0, atol=1e-9)
        np.testing.assert_allclose(my, want[:, 1], rtol=0, atol=1e-9)
        if not extra:
            np.testing.assert_allclose(mx, s.x[at, 0], rtol=0, atol=1e-9)
            heading_only = Rotation.from_euler("z", zyx[:, :1]).apply(arm)
            assert np.max(np.hypot(*(s.Q[at] @ arm - heading_only)[:, :2].T)) > 1.0   # the arm matters
        else:
            assert np.max(np.abs(mx - s.x[at, 0])) > 0.1   # the MRU's and gyro's errors times the arm
