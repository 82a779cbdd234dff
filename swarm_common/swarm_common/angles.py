"""Planar angles: wrapping, and the yaw-only quaternions of REP 103 (rotation about +z)."""

from __future__ import annotations

import math
from typing import overload

import numpy as np

__all__ = [
    'ODOM_QUATERNION_NORM_TOLERANCE',
    'TWO_PI',
    'UNIT_QUATERNION_NORM_SQ_TOLERANCE',
    'wrap_angle',
    'yaw_from_odometry_quaternion',
    'yaw_from_quaternion',
    'yaw_from_unit_quaternion',
    'yaw_to_quaternion',
]

TWO_PI = 2.0 * math.pi
#: A quaternion whose squared norm is within this of 1 counts as unit (float32 fields hold
#: about seven digits).
UNIT_QUATERNION_NORM_SQ_TOLERANCE = 1e-6
#: Largest accepted deviation of an odometry quaternion's norm from 1 (the nodes' shared
#: policy). Within it the quaternion is read as if normalised (float32 fields and integrated
#: orientations drift off unit a little); beyond it (a tiny, huge, zero or non-finite
#: quaternion: a broken publisher) the reader raises, the node drops the message, its pose
#: goes stale and the robot stops.
ODOM_QUATERNION_NORM_TOLERANCE = 0.1


@overload
def wrap_angle(angle_rad: float) -> float: ...
@overload
def wrap_angle(angle_rad: np.ndarray) -> np.ndarray: ...
def wrap_angle(angle_rad: np.ndarray | float) -> np.ndarray | float:
    """Wrap angles [rad] to (-pi, pi]: a float for a scalar, an array for an array.

    Python floats take a ``math`` path (no array round trip); both paths give the same bits.
    """
    if type(angle_rad) is float or isinstance(angle_rad, float | int):
        wrapped = math.fmod(angle_rad + math.pi, TWO_PI)
        if wrapped < 0.0:
            wrapped += TWO_PI
        wrapped -= math.pi
        return wrapped + TWO_PI if wrapped <= -math.pi else wrapped
    array = np.mod(np.asarray(angle_rad, dtype=float) + math.pi, TWO_PI) - math.pi
    array = np.where(array <= -math.pi, array + TWO_PI, array)
    if np.ndim(angle_rad) == 0:
        return float(array)
    return array


def yaw_to_quaternion(yaw_rad: float) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a rotation by ``yaw_rad`` about +z."""
    half = 0.5 * float(yaw_rad)
    return (0.0, 0.0, math.sin(half), math.cos(half))


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw [rad] (rotation about +z) of the quaternion (x, y, z, w), normalised or not.

    Raises:
        ValueError: a zero or non-finite quaternion, which has no orientation.
    """
    norm_sq = x * x + y * y + z * z + w * w
    if not norm_sq > 0.0 or not math.isfinite(norm_sq):
        msg = f'quaternion ({x}, {y}, {z}, {w}) has no orientation'
        raise ValueError(msg)
    return math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)


def yaw_from_odometry_quaternion(
    x: float,
    y: float,
    z: float,
    w: float,
    *,
    max_norm_error: float | None = ODOM_QUATERNION_NORM_TOLERANCE,
) -> float:
    """Yaw [rad] of an odometry orientation (x, y, z, w), read as normalised if it is not unit.

    A unit quaternion (:data:`UNIT_QUATERNION_NORM_SQ_TOLERANCE`) takes
    :func:`yaw_from_unit_quaternion`, any other the scale-free :func:`yaw_from_quaternion`.

    Raises:
        ValueError: a zero or non-finite quaternion (no orientation), or one whose norm is
            further than ``max_norm_error`` from 1 (default
            :data:`ODOM_QUATERNION_NORM_TOLERANCE`; None accepts any other scale).
    """
    x, y, z, w = float(x), float(y), float(z), float(w)
    norm_sq = x * x + y * y + z * z + w * w
    if abs(norm_sq - 1.0) <= UNIT_QUATERNION_NORM_SQ_TOLERANCE:
        return yaw_from_unit_quaternion(x, y, z, w)
    yaw = yaw_from_quaternion(x, y, z, w)
    if max_norm_error is not None and not abs(math.sqrt(norm_sq) - 1.0) <= max_norm_error:
        msg = (
            f'quaternion ({x}, {y}, {z}, {w}) has norm {math.sqrt(norm_sq):.6g}, '
            f'not within {max_norm_error:g} of 1'
        )
        raise ValueError(msg)
    return yaw


def yaw_from_unit_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Yaw [rad] of a unit quaternion (x, y, z, w), as ``atan2(2 (wz + xy), 1 - 2 (y^2 + z^2))``.

    Equal to :func:`yaw_from_quaternion` for unit quaternions up to the last bit (the two
    formulas round differently for about one yaw in five); the odometry readers of the
    Bayes-Swarm and MSC nodes use this one.
    """
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
