"""Compiled arithmetic of the gas sensor and IMU models: one loop over the robots instead of
a dozen numpy calls on 10-element arrays per reading.

Simulation only (numba). Each kernel does the numpy version's floating-point operations in
the same order (no fused multiply-add: numba does not contract without ``fastmath``); the
random draws and the transcendental functions (``exp``) stay in numpy and are passed in, so
the readings are bit-identical (``test_scent_and_gas.py`` and ``test_bearings_imu_odometry.py``
run both versions from the same random state).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from swarm_sim.raycast_kernel import _wrap

__all__ = [
    'gas_update_kernel',
    'heard_pairs_kernel',
    'imu_message_yaw_kernel',
    'imu_update_kernel',
    'wrap_sum_kernel',
    'yaw_change_kernel',
]

_FLOAT_MAX = np.finfo(np.float64).max


@njit(cache=True)
def gas_update_kernel(
    sensed_ppm: np.ndarray,
    concentration_ppm: np.ndarray,
    gain_rise: float,
    gain_fall: float,
    noise_raw: np.ndarray,
    baseline_raw: float,
    span_raw: float,
    half_response_ppm: float,
    raw_max: float,
) -> np.ndarray:  # pragma: no cover - compiled
    """``Mp503Model.update_reference``: lag the sensed concentrations in place, return the
    readings.

    Args:
        sensed_ppm: (N,) lagged concentrations [ppm], updated in place.
        concentration_ppm: (N,) concentrations at the sensors [ppm] (NaN reads 0, +-inf the
            largest float, as ``np.nan_to_num``; negative values 0).
        gain_rise: ``1 - exp(-dt / tau_rise)``, computed by numpy.
        gain_fall: ``1 - exp(-dt / tau_fall)``.
        noise_raw: (N,) reading noise [counts] (empty: none).
        baseline_raw: clean-air reading.
        span_raw: ``RAW_MAX - baseline_raw``.
        half_response_ppm: sensed concentration of half the span [ppm].
        raw_max: largest reading.

    Returns:
        (N,) int64 readings, rounded half to even and clipped to [0, raw_max].
    """
    n = sensed_ppm.shape[0]
    out = np.empty(n, dtype=np.int64)
    for i in range(n):
        c = concentration_ppm[i]
        if math.isnan(c):
            c = 0.0
        elif c == np.inf:
            c = _FLOAT_MAX
        elif c == -np.inf:
            c = -_FLOAT_MAX
        if not c >= 0.0:  # np.maximum(c, 0.0) keeps c (even -0.0) when c >= 0
            c = 0.0
        x = sensed_ppm[i]
        gain = gain_rise if c > x else gain_fall
        x += (c - x) * gain
        sensed_ppm[i] = x
        raw = baseline_raw + span_raw * x / (x + half_response_ppm)
        if noise_raw.shape[0]:
            raw = raw + noise_raw[i]
        out[i] = int(min(max(np.rint(raw), 0.0), raw_max))
    return out


@njit(cache=True)
def imu_update_kernel(
    yaw_rad: np.ndarray,
    true_yaw_change_rad: np.ndarray,
    dt_s: float,
    bias_radps: np.ndarray,
    noise_radps: np.ndarray,
) -> np.ndarray:  # pragma: no cover - compiled
    """``GyroYawModel.update_reference``'s integration: updates ``yaw_rad`` in place and
    returns the (N,) measured yaw rates [rad/s] (true rate + bias + noise)."""
    n = yaw_rad.shape[0]
    rate = np.empty(n)
    for i in range(n):
        r = true_yaw_change_rad[i] / dt_s
        r = r + bias_radps[i]
        r = r + noise_radps[i]
        rate[i] = r
        yaw_rad[i] = _wrap(yaw_rad[i] + r * dt_s)
    return rate


@njit(cache=True)
def imu_message_yaw_kernel(yaw_rad: np.ndarray) -> np.ndarray:  # pragma: no cover - compiled
    """The yaw a node reads back from each IMU message: ``oabug_robot.heading.
    yaw_from_quaternion(*swarm_common.angles.yaw_to_quaternion(yaw))`` for every yaw, with
    their operations (the zero x and y terms included: they turn -0.0 into 0.0). NaN where
    the quaternion has no orientation (the node's function raises there)."""
    out = np.empty(yaw_rad.shape[0])
    x = 0.0
    y = 0.0
    for i in range(yaw_rad.shape[0]):
        half = 0.5 * yaw_rad[i]
        z = math.sin(half)
        w = math.cos(half)
        norm_sq = x * x + y * y + z * z + w * w
        if not norm_sq > 0.0 or not math.isfinite(norm_sq):
            out[i] = math.nan
            continue
        out[i] = math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)
    return out


@njit(cache=True)
def yaw_change_kernel(
    yaw_rad: np.ndarray, previous_yaw_rad: np.ndarray
) -> np.ndarray:  # pragma: no cover - compiled
    """``swarm_common.angles.wrap_angle(yaw_rad - previous_yaw_rad)`` of (N,) yaws [rad]
    (the same operations: ``%`` here is numpy's ``mod``)."""
    out = np.empty(yaw_rad.shape[0])
    for i in range(yaw_rad.shape[0]):
        out[i] = _wrap(yaw_rad[i] - previous_yaw_rad[i])
    return out


@njit(cache=True)
def wrap_sum_kernel(a_rad: np.ndarray, b_rad: np.ndarray) -> np.ndarray:  # pragma: no cover
    """``swarm_common.angles.wrap_angle(a_rad + b_rad)`` of (N,) angles [rad], with its
    operations."""
    out = np.empty(a_rad.shape[0])
    for i in range(a_rad.shape[0]):
        out[i] = _wrap(a_rad[i] + b_rad[i])
    return out


@njit(cache=True)
def heard_pairs_kernel(
    receiver: np.ndarray,
    transmitter: np.ndarray,
    delta_m: np.ndarray,
    distance_m: np.ndarray,
    walls_crossed: np.ndarray,
    reach_table_m: np.ndarray,
    range_m: float,
    uniform: np.ndarray,
    dropout_probability: float,
    sequence: np.ndarray,
    yaw_rad: np.ndarray,
) -> tuple:  # pragma: no cover - compiled
    """The sight lines a locator cycle hears, ``BearingModel._cycle``'s selection: within
    ``range_m`` and the line's reach, and not dropped (a uniform draw at least the dropout
    probability, when it is not 0); and what the reports need of them.

    Args:
        receiver, transmitter: (L,) the lines' robots, receivers ascending.
        delta_m: (L, 2) the offsets from receiver to transmitter [m].
        distance_m: (L,) their lengths [m].
        walls_crossed: (L,) the walls each line crosses.
        reach_table_m: per number of walls crossed (at least the largest in
            ``walls_crossed``), the range left [m].
        range_m: the line-of-sight range [m].
        uniform: (L,) the dropout draws (read only with a dropout probability).
        dropout_probability: chance that one report is lost.
        sequence: (N, N) per receiver and tag, the report counter; the heard ones advance
            (modulo 65536).
        yaw_rad: (N,) every robot's yaw [rad].

    Returns:
        Of the K heard lines: receivers, transmitters, offsets along y and x [m], lengths
        [m], the receivers' yaws [rad] and the new sequence numbers; and the (N + 1,) slice
        bounds of each receiver's among them.
    """
    lines = receiver.shape[0]
    n = sequence.shape[0]
    rx = np.empty(lines, dtype=np.int64)
    tx = np.empty(lines, dtype=np.int64)
    dy = np.empty(lines)
    dx = np.empty(lines)
    dist = np.empty(lines)
    rx_yaw = np.empty(lines)
    numbers = np.empty(lines, dtype=np.int64)
    bounds = np.zeros(n + 1, dtype=np.int64)
    count = 0
    for line in range(lines):
        d = distance_m[line]
        if not (d <= range_m and d <= reach_table_m[walls_crossed[line]]):
            continue
        if dropout_probability > 0.0 and not uniform[line] >= dropout_probability:
            continue
        i = receiver[line]
        j = transmitter[line]
        sequence[i, j] = (sequence[i, j] + 1) % 65536
        rx[count] = i
        tx[count] = j
        dy[count] = delta_m[line, 1]
        dx[count] = delta_m[line, 0]
        dist[count] = d
        rx_yaw[count] = yaw_rad[i]
        numbers[count] = sequence[i, j]
        bounds[i + 1] += 1
        count += 1
    for i in range(n):
        bounds[i + 1] += bounds[i]
    return (
        rx[:count],
        tx[:count],
        dy[:count],
        dx[:count],
        dist[:count],
        rx_yaw[:count],
        numbers[:count],
        bounds,
    )
