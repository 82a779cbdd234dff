"""SGBA's parameters: the controller's (the authors' values as defaults) and the node's own.

The defaults are the values of McGuire et al.'s Crazyflie implementation (Science Robotics
2019, and the app layer published with it): 0.4 m from the wall, 0.5 rad/s turns, an
inter-robot RSSI of -58 dBm to change the preferred direction and -50 dBm to move out of the
way, a peer forgotten after 1 s. What the ground robot needs that a Crazyflie does not (a
differential drive cannot move sideways) are parameters of their own, documented in
docs/sgba.md with every other departure.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from enum import Enum

from swarm_common.params import ParameterSpec, parameter, section

from oabug_robot.errors import ConfigError, ParameterError
from oabug_robot.settings import Departure

__all__ = ['NODE_NAME', 'SGBA_PARAMETERS', 'HeadingScheme', 'SgbaConfig', 'SgbaNodeConfig']

NODE_NAME = 'sgba'


class HeadingScheme(Enum):
    """How the robots' preferred headings are spread over the swarm."""

    #: The OA-Bug departure fan (full circle from the centre, half circle from the edge,
    #: rotated by the common bias): both methods set off in the same directions.
    FAN = 'fan'
    #: The authors' table: +-0.8 and +-2.4 rad (about +-46 and +-138 deg) from the common
    #: start heading, cycled over the robots (plus the common bias).
    AUTHORS = 'authors'


#: The authors' preferred headings [rad] by robot (their radio ids 1..9 map to 0.8, 0.8,
#: -2.4, -0.8, 2.4, 0.8, -2.4, -0.8, 2.4; robot index i takes entry i mod 9).
AUTHORS_HEADINGS_RAD = (0.8, 0.8, -2.4, -0.8, 2.4, 0.8, -2.4, -0.8, 2.4)


@dataclass(frozen=True)
class SgbaConfig:
    """The SGBA controller's configuration (outbound exploration).

    Attributes:
        robot_index: this robot's index in the swarm.
        robot_count: robots that depart together.
        departure: centre (full-circle fan) or edge (half-circle fan), for the ``fan`` scheme.
        heading_bias_rad: common bias of the preferred headings in the IMU yaw frame.
        heading_scheme: ``fan`` or ``authors`` (see :class:`HeadingScheme`).
        forward_speed_mps: cruise speed (the Crazyflies: 0.5 m/s).
        turn_rate_radps: rotation rate of every turn (the authors: 0.5 rad/s).
        wall_distance_m: distance kept from a followed wall (the authors: 0.4 m).
        side_check_m: a side closer than this picks the followed side at a hit (2 m).
        goal_heading_tolerance_rad: a rotation to the preferred heading ends within this.
        leave_bearing_max_rad: the preferred heading must lie within this of the heading, on
            the free side, to leave the wall at an outer corner (1.5 rad).
        loop_angle_rad: the robot is looping when it is seen from its hit point within this of
            the direction opposite to its preferred heading then (1.0 rad).
        loop_min_distance_m: the looping check starts this far from the hit point.
        rssi_heading_dbm: a closer peer without right of way makes the robot change its
            preferred heading (the authors: -58 dBm).
        rssi_collision_dbm: a closer peer without right of way makes it move out of the way
            (the authors: -50 dBm).
        rssi_at_1m_dbm: inter-robot RSSI at 1 m of the log-distance model that turns the
            locator's distance into an RSSI.
        path_loss_exponent: exponent n of that model (RSSI = P1m - 10 n log10(d)).
        peer_timeout_s: a peer not heard for this long is forgotten (the authors: 1 s).
        avoid_distance_m: while moving out of the way, obstacles closer than this push the
            robot away (the authors: 0.7 m).
        side_correction_radps: in forward flight a wall closer than ``wall_distance_m`` on a
            side steers the robot away at this rate (a Crazyflie slides sideways instead).
        wall_angle_gain: wall following: yaw rate per rad of wall angle.
        wall_distance_gain: wall following: yaw rate per m of distance error [rad/s/m].
        max_yaw_rate_radps: limit of the wall-following yaw rate.
        geometry_scale: multiplies every distance above (and the authors' margins: hit at
            the wall distance + 0.2 m, side lost at + 0.3 m, clear ahead at + 0.4 m) and
            divides the peer distance the RSSI model reads, so that the thresholds mean
            distances scaled alike; 1 keeps the authors' Crazyflie-scale values.
        ranger_half_width_rad: each range direction reads the nearest return within this of
            its axis: the Crazyflie's four rangers (the Multiranger deck's VL53L1x time-of-
            flight sensors, 27 deg field of view), taken from the lidar.
    """

    robot_index: int = parameter(0, 'this robot index in the swarm, 0..robot_count-1', ge=0)
    robot_count: int = parameter(1, 'number of robots that depart together', ge=1)
    departure: Departure = parameter(
        Departure.CENTER, 'center: full-circle fan of preferred headings; edge: half-circle fan'
    )
    heading_bias_rad: float = parameter(
        0.0,
        'common bias of the preferred headings in the IMU yaw frame',
        unit='deg',
        degrees=True,
    )
    heading_scheme: HeadingScheme = parameter(
        HeadingScheme.FAN,
        "fan: OA-Bug's departure fan; authors: the SGBA code's +-0.8 / +-2.4 rad table",
    )
    forward_speed_mps: float = parameter(0.3, 'cruise speed', unit='m/s', gt=0.0)
    turn_rate_radps: float = parameter(0.5, 'rate of every turn', unit='rad/s', gt=0.0)
    wall_distance_m: float = parameter(0.4, 'distance kept from a followed wall', unit='m', gt=0.0)
    side_check_m: float = parameter(
        2.0, 'a side closer than this picks the followed side at a hit', unit='m', gt=0.0
    )
    goal_heading_tolerance_rad: float = parameter(
        0.1, 'rotation to the preferred heading ends within this', unit='rad', gt=0.0
    )
    leave_bearing_max_rad: float = parameter(
        1.5, 'preferred heading within this on the free side leaves the wall', unit='rad', gt=0.0
    )
    loop_angle_rad: float = parameter(
        1.0, 'hit point behind within this of the preferred heading: looping', unit='rad', gt=0.0
    )
    loop_min_distance_m: float = parameter(
        0.4, 'the looping check starts this far from the hit point', unit='m', ge=0.0
    )
    rssi_heading_dbm: float = parameter(
        -58.0, 'peer RSSI above this (no right of way): change preferred heading', unit='dBm'
    )
    rssi_collision_dbm: float = parameter(
        -50.0, 'peer RSSI above this (no right of way): move out of the way', unit='dBm'
    )
    rssi_at_1m_dbm: float = parameter(
        -48.0, 'inter-robot RSSI at 1 m (log-distance model)', unit='dBm'
    )
    path_loss_exponent: float = parameter(2.0, 'path-loss exponent n', gt=0.0)
    peer_timeout_s: float = parameter(
        1.0, 'a peer not heard for this long is forgotten', unit='s', gt=0.0
    )
    avoid_distance_m: float = parameter(
        0.7, 'moving out of the way: obstacles closer than this push away', unit='m', gt=0.0
    )
    side_correction_radps: float = parameter(
        0.4, 'forward: yaw rate away from a side wall that is too close', unit='rad/s', ge=0.0
    )
    wall_angle_gain: float = parameter(
        1.0, 'wall following: yaw rate per rad of wall angle', ge=0.0
    )
    wall_distance_gain: float = parameter(
        1.5, 'wall following: yaw rate per m of distance error', unit='rad/s/m', ge=0.0
    )
    max_yaw_rate_radps: float = parameter(
        1.0, 'limit of the wall-following yaw rate', unit='rad/s', gt=0.0
    )
    geometry_scale: float = parameter(
        1.0,
        (
            'multiplies every SGBA distance (wall, margins, side check, avoidance, loop check) '
            "and divides the peer distance of the RSSI model; 1: the authors' values"
        ),
        gt=0.0,
    )
    ranger_half_width_rad: float = parameter(
        math.radians(13.5),
        'each range direction reads the nearest lidar return within this of its axis '
        "(the Multiranger's VL53L1x: 27 deg field of view)",
        unit='deg',
        degrees=True,
        ge=0.0,
    )

    def __post_init__(self) -> None:
        if self.robot_index >= self.robot_count:
            msg = f'robot_index {self.robot_index} must be < robot_count {self.robot_count}'
            raise ConfigError(msg)
        if self.rssi_collision_dbm < self.rssi_heading_dbm:
            msg = (
                f'rssi_collision_dbm ({self.rssi_collision_dbm}) must be >= rssi_heading_dbm '
                f'({self.rssi_heading_dbm}): moving out of the way is for closer peers'
            )
            raise ConfigError(msg)


@dataclass(frozen=True)
class SgbaNodeConfig:
    """Everything the SGBA node reads from its parameters: the controller's at the top level
    and the node's loop settings."""

    controller: SgbaConfig = section(SgbaConfig, prefix='')
    control_rate_hz: float = parameter(10.0, 'control loop rate', unit='Hz', gt=0.0)
    stale_timeout_s: float = parameter(
        1.0, 'stop when scan, imu or odom is older', unit='s', gt=0.0, read_only=False
    )
    own_tag_id: str = parameter(
        '', 'own AoA tag id: ignored in the bearings, and the right-of-way order', read_only=False
    )

    def controller_config(self) -> SgbaConfig:
        """The controller configuration."""
        return dataclasses.replace(self.controller)


SGBA_PARAMETERS = ParameterSpec(SgbaNodeConfig, error=ParameterError)
