"""Angle wrapping and planar quaternions."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from swarm_common.angles import (
    ODOM_QUATERNION_NORM_TOLERANCE,
    wrap_angle,
    yaw_from_odometry_quaternion,
    yaw_from_quaternion,
    yaw_from_unit_quaternion,
    yaw_to_quaternion,
)

finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


@pytest.mark.parametrize(
    ('angle', 'wrapped'),
    [
        (0.0, 0.0),
        (math.pi, math.pi),
        (-math.pi, math.pi),
        (3.0 * math.pi / 2.0, -math.pi / 2.0),
        (-3.0 * math.pi / 2.0, math.pi / 2.0),
        (7.0 * math.pi, math.pi),
    ],
)
def test_wrap_angle_lands_in_the_half_open_interval_up_to_pi(angle, wrapped):
    assert wrap_angle(angle) == pytest.approx(wrapped)
    assert -math.pi < wrap_angle(angle) <= math.pi


@given(finite)
def test_scalar_and_array_wrapping_give_the_same_bits(angle):
    scalar = wrap_angle(angle)
    array = wrap_angle(np.array([angle, angle]))
    assert isinstance(scalar, float)
    assert -math.pi < scalar <= math.pi
    assert array.tolist() == [scalar, scalar]
    assert wrap_angle(np.float32(angle)) == pytest.approx(wrap_angle(float(np.float32(angle))))
    assert math.cos(scalar - angle) == pytest.approx(1.0, abs=1e-6)


def test_wrap_angle_of_a_zero_dimensional_array_is_a_float():
    value = wrap_angle(np.asarray(4.0))
    assert isinstance(value, float)
    assert value == pytest.approx(4.0 - 2.0 * math.pi)


@given(st.floats(min_value=-math.pi, max_value=math.pi))
def test_yaw_survives_the_quaternion_round_trip(yaw):
    q = yaw_to_quaternion(yaw)
    assert q[0] == q[1] == 0.0
    assert math.cos(yaw_from_quaternion(*q) - yaw) == pytest.approx(1.0)
    assert math.cos(yaw_from_unit_quaternion(*q) - yaw) == pytest.approx(1.0)


def test_unnormalised_quaternions_keep_their_yaw_and_zero_ones_are_rejected():
    x, y, z, w = yaw_to_quaternion(1.2)
    assert yaw_from_quaternion(3 * x, 3 * y, 3 * z, 3 * w) == pytest.approx(1.2)
    with pytest.raises(ValueError, match='no orientation'):
        yaw_from_quaternion(0.0, 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match='no orientation'):
        yaw_from_quaternion(math.nan, 0.0, 0.0, 1.0)


@given(
    yaw=st.floats(-math.pi, math.pi),
    scale=st.floats(0.5, 2.0).filter(lambda s: abs(s - 1.0) > ODOM_QUATERNION_NORM_TOLERANCE),
)
def test_odometry_reader_normalises_near_unit_quaternions_and_rejects_far_ones(yaw, scale):
    z, w = math.sin(yaw / 2), math.cos(yaw / 2)
    near = 1.0 + 0.9 * ODOM_QUATERNION_NORM_TOLERANCE * math.copysign(1.0, scale - 1.0)
    got = yaw_from_odometry_quaternion(0.0, 0.0, near * z, near * w)
    assert got == pytest.approx(yaw_from_unit_quaternion(0.0, 0.0, z, w), abs=1e-12)
    with pytest.raises(ValueError, match='norm'):
        yaw_from_odometry_quaternion(0.0, 0.0, scale * z, scale * w)
    # Without the bound any non-zero scale is read as if normalised.
    free = yaw_from_odometry_quaternion(0.0, 0.0, scale * z, scale * w, max_norm_error=None)
    assert free == pytest.approx(got, abs=1e-12)
