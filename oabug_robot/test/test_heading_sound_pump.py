"""Angles, the sound direction and the pump schedule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from oabug_robot.heading import (
    angle_difference,
    preferred_direction,
    wrap_angle,
    yaw_from_quaternion,
)
from oabug_robot.pump import PumpScheduler
from oabug_robot.settings import Departure, SoundWeighting
from oabug_robot.sound import PeerBearings, opposite_direction


@pytest.mark.parametrize(
    ('angle', 'wrapped'),
    [
        (0.0, 0.0),
        (math.pi, math.pi),
        (-math.pi, math.pi),
        (3 * math.pi, math.pi),
        (7.0, 7.0 - 2 * math.pi),
    ],
)
def test_wrap_angle_maps_into_minus_pi_exclusive_to_pi(angle: float, wrapped: float) -> None:
    assert wrap_angle(angle) == pytest.approx(wrapped)


def test_angle_difference_takes_the_short_way_round() -> None:
    assert angle_difference(math.radians(170), math.radians(-170)) == pytest.approx(
        math.radians(-20)
    )


@pytest.mark.parametrize('yaw_deg', [-179.0, -90.0, 0.0, 45.0, 135.0])
def test_yaw_is_recovered_from_a_yaw_only_quaternion(yaw_deg: float) -> None:
    half = math.radians(yaw_deg) / 2
    assert yaw_from_quaternion(0.0, 0.0, math.sin(half), math.cos(half)) == pytest.approx(
        math.radians(yaw_deg)
    )


def test_a_zero_quaternion_has_no_yaw() -> None:
    with pytest.raises(ValueError, match='no orientation'):
        yaw_from_quaternion(0.0, 0.0, 0.0, 0.0)


def test_centre_departure_spreads_directions_over_the_full_circle() -> None:
    bias = math.radians(10.0)
    directions = [preferred_direction(i, 4, Departure.CENTER, bias) for i in range(4)]
    expected = [10.0, 100.0, -170.0, -80.0]
    assert np.degrees(directions) == pytest.approx(expected)


def test_edge_departure_fans_into_the_building() -> None:
    inward = math.pi / 2
    directions = np.degrees(
        [preferred_direction(i, 10, Departure.EDGE, inward - math.pi / 2) for i in range(10)]
    )
    assert directions == pytest.approx(np.arange(9.0, 180.0, 18.0))
    assert np.mean(directions) == pytest.approx(90.0)


def test_sound_direction_points_away_from_the_weighted_resultant() -> None:
    # A near peer ahead (1 m) and a far one on the left (3 m): the paper's c_j weighting.
    theta = opposite_direction(
        np.radians([0.0, 90.0]), np.array([1.0, 3.0]), SoundWeighting.DISTANCE
    )
    assert theta == pytest.approx(math.atan2(-3.0, -1.0))
    unit = opposite_direction(np.radians([0.0, 90.0]), np.array([1.0, 3.0]), SoundWeighting.UNIT)
    assert unit == pytest.approx(math.radians(-135.0))


def test_unknown_distances_count_as_unit_vectors() -> None:
    theta = opposite_direction(
        np.radians([0.0, 90.0]), np.array([np.nan, np.nan]), SoundWeighting.DISTANCE
    )
    assert theta == pytest.approx(math.radians(-135.0))


def test_silence_and_cancelling_peers_give_no_direction() -> None:
    assert opposite_direction(np.zeros(0), np.zeros(0), SoundWeighting.DISTANCE) is None
    assert opposite_direction(np.array([np.nan]), np.array([1.0]), SoundWeighting.UNIT) is None
    balanced = opposite_direction(np.radians([0.0, 180.0]), np.ones(2), SoundWeighting.UNIT)
    assert balanced is None


def test_bearings_rotate_back_when_the_robot_turns() -> None:
    bearings = PeerBearings(np.array([0.5]), np.array([1.0]), 0.0, yaw_at_stamp_rad=0.2)
    assert bearings.azimuths_now(0.7) == pytest.approx([0.0])


def test_pump_bursts_half_a_second_every_five_seconds_while_driving() -> None:
    pump = PumpScheduler(on_s=0.5, period_s=5.0, min_speed_mps=0.2)
    times = [k * 0.1 for k in range(120)]
    on = [pump.update(t, 0.3) for t in times]
    starts = [
        t for t, now, before in zip(times, on, [False, *on[:-1]], strict=True) if now and not before
    ]
    assert starts == pytest.approx([0.0, 5.0, 10.0])
    assert sum(on) == 15


def test_pump_waits_for_the_robot_to_drive_before_a_burst() -> None:
    pump = PumpScheduler(on_s=0.5, period_s=5.0, min_speed_mps=0.2)
    assert not pump.update(0.0, 0.0), 'turning on the spot: no puff under the own sensor'
    assert not pump.update(1.0, 0.1)
    assert pump.update(2.0, 0.3)
    assert pump.update(2.4, 0.0), 'a started burst runs its length'
    assert not pump.update(2.5, 0.3)
    assert not pump.update(6.9, 0.3)
    assert pump.update(7.0, 0.3)


def test_pump_with_zero_minimum_speed_follows_the_plain_clock() -> None:
    pump = PumpScheduler(on_s=0.5, period_s=5.0, min_speed_mps=0.0)
    assert [pump.update(t, 0.0) for t in (0.0, 0.4, 0.6, 5.0, 5.6)] == [
        True,
        True,
        False,
        True,
        False,
    ]
    assert not pump.update(math.nan, 0.3)
