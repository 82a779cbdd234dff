"""The SGBA controller (outbound exploration) on a differential-drive robot.

SGBA (McGuire et al., Science Robotics 2019) is a bug algorithm per robot: each robot has its
own preferred heading, flies it until a wall is in front, follows that wall, and leaves it
at an outer corner when the preferred heading points into free space on the open side. A
robot that sees itself back behind the point where it hit the wall (it loops around an
obstacle) follows the next wall the other way. Peers are sensed only through the RSSI of
their radios: a close peer without right of way makes a wall-following robot change its
preferred heading, and a very close one makes it move out of the way until the peer has
gone by. The return home along the RSSI gradient of a home beacon is not implemented here.

States, with the authors' numbers: 1 forward, 2 rotate to the preferred heading, 3 wall
following, 4 move out of the way; the wall follower's own: 3 turn to find the wall, 5 along
the wall, 6 around an outer corner (the authors' 7 "rotate in corner" is 3 here, their 8
"find corner" part of 6, since the robot cannot slide sideways to align).

Everything is deterministic from the inputs: the controller draws no random numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np
from swarm_common.angles import wrap_angle

from oabug_robot.heading import preferred_direction
from oabug_robot.sgba.settings import AUTHORS_HEADINGS_RAD, HeadingScheme, SgbaConfig

__all__ = [
    'Geometry',
    'Peer',
    'Ranges',
    'SgbaCommand',
    'SgbaController',
    'SgbaInputs',
    'SgbaState',
    'WallState',
    'initial_heading',
    'ranges_from_scan',
    'rssi_from_distance',
]


class SgbaState(IntEnum):
    """SGBA's states (the authors' numbers)."""

    FORWARD = 1
    ROTATE_TO_GOAL = 2
    WALL_FOLLOWING = 3
    MOVE_OUT_OF_WAY = 4


class WallState(IntEnum):
    """The wall follower's states (the authors' numbers where they match)."""

    TURN_TO_FIND_WALL = 3
    ALONG_WALL = 5
    AROUND_CORNER = 6


@dataclass(frozen=True)
class Ranges:
    """The distances SGBA reads [m], in the robot frame: the Crazyflie's four rangers plus
    the two forward diagonals the ground robot's wall follower uses. No return reads the
    sensor's maximum range; a return nearer than its minimum reads 0."""

    front_m: float
    left_m: float
    right_m: float
    back_m: float
    front_left_m: float
    front_right_m: float

    def side(self, direction: int) -> float:
        """The side range of the followed wall (``direction`` +1: right, -1: left)."""
        return self.right_m if direction > 0 else self.left_m

    def diagonal(self, direction: int) -> float:
        """The forward diagonal range towards the followed wall."""
        return self.front_right_m if direction > 0 else self.front_left_m


@dataclass(frozen=True)
class Peer:
    """The strongest peer heard (the authors' "closest" robot).

    Attributes:
        rssi_dbm: its RSSI [dBm].
        bearing_rad: where it is, in the IMU yaw frame [rad].
        has_way: True when the peer has right of way over this robot (the authors: the
            lower radio id; this robot then gives way).
    """

    rssi_dbm: float
    bearing_rad: float
    has_way: bool


@dataclass(frozen=True)
class SgbaInputs:
    """One control step's readings.

    Attributes:
        time_s: node time [s].
        yaw_rad: IMU heading [rad].
        ranges: the range directions.
        position_m: odometry position (x, y) [m] (the Crazyflies: optical flow).
        peer: the strongest peer heard within the peer timeout, or None.
    """

    time_s: float
    yaw_rad: float
    ranges: Ranges
    position_m: tuple[float, float]
    peer: Peer | None = None


@dataclass(frozen=True)
class SgbaCommand:
    """A velocity command: forward speed [m/s] and yaw rate [rad/s] (REP 103)."""

    linear_mps: float
    angular_radps: float


@dataclass
class SgbaMemory:
    """The controller's mutable state."""

    state: SgbaState = SgbaState.ROTATE_TO_GOAL
    wall_state: WallState = WallState.TURN_TO_FIND_WALL
    preferred_heading_rad: float = 0.0
    #: Sign of (yaw - preferred heading) when a rotation to it started: it turns the other way.
    rotate_sign: float = 0.0
    #: Followed wall: +1 on the right, -1 on the left (the authors' "direction").
    direction: int = 1
    hit_position_m: tuple[float, float] = (0.0, 0.0)
    hit_preferred_heading_rad: float = 0.0
    reverse_next_hit: bool = False
    cannot_go_to_goal: bool = False
    #: Rotation [rad] since the current wall-follower manoeuvre began (the fail-safes: a
    #: half turn without finding the wall, a full circle around a corner).
    corner_turned_rad: float = 0.0
    last_yaw_rad: float = math.nan
    heading_changes: int = 0
    events: list[str] = field(default_factory=list)


def initial_heading(config: SgbaConfig) -> float:
    """The robot's first preferred heading [rad] in the IMU yaw frame."""
    if config.heading_scheme is HeadingScheme.AUTHORS:
        offset = AUTHORS_HEADINGS_RAD[config.robot_index % len(AUTHORS_HEADINGS_RAD)]
        return wrap_angle(config.heading_bias_rad + offset)
    return preferred_direction(
        config.robot_index, config.robot_count, config.departure, config.heading_bias_rad
    )


def rssi_from_distance(distance_m: float, config: SgbaConfig) -> float:
    """Inter-robot RSSI [dBm] of the log-distance path-loss model at ``distance_m`` divided
    by the geometry scale (distances below 0.1 m count as 0.1 m): P1m - 10 n log10(d)."""
    d = max(float(distance_m) / config.geometry_scale, 0.1)
    return config.rssi_at_1m_dbm - 10.0 * config.path_loss_exponent * math.log10(d)


def ranges_from_scan(
    ranges_m: np.ndarray,
    angle_min_rad: float,
    angle_increment_rad: float,
    range_min_m: float,
    range_max_m: float,
    half_width_rad: float,
) -> Ranges:
    """The six range directions from a lidar revolution: per direction, the nearest return
    within ``half_width_rad`` of its axis. NaN and +inf (no return) read ``range_max_m``;
    -inf and returns under ``range_min_m`` (too close) read 0."""
    values = np.asarray(ranges_m, dtype=float)
    count = values.size
    clean = np.where(np.isnan(values) | (values == np.inf), range_max_m, values)
    clean = np.where(clean < range_min_m, 0.0, np.minimum(clean, range_max_m))
    width = max(0, round(half_width_rad / abs(angle_increment_rad)))
    offsets = np.arange(-width, width + 1)

    def nearest(axis_rad: float) -> float:
        centre = round((wrap_angle(axis_rad - angle_min_rad) % (2 * math.pi)) / angle_increment_rad)
        return float(clean[(centre + offsets) % count].min())

    quarter = 0.5 * math.pi
    return Ranges(
        front_m=nearest(0.0),
        left_m=nearest(quarter),
        right_m=nearest(-quarter),
        back_m=nearest(math.pi),
        front_left_m=nearest(0.5 * quarter),
        front_right_m=nearest(-0.5 * quarter),
    )


@dataclass(frozen=True)
class Geometry:
    """SGBA's distances [m] at the configured geometry scale: the wall distance and the
    authors' margins on it (hit at +0.2 m, side lost at +0.3 m, clear ahead to leave at
    +0.4 m), the side check, the avoidance distance, the loop check's start."""

    wall_m: float
    hit_m: float
    side_lost_m: float
    leave_clear_m: float
    side_check_m: float
    avoid_m: float
    loop_min_m: float
    distance_gain: float

    @classmethod
    def of(cls, config: SgbaConfig) -> Geometry:
        """The distances of ``config`` (each times ``geometry_scale``)."""
        k = config.geometry_scale
        wall = config.wall_distance_m * k
        return cls(
            wall_m=wall,
            hit_m=wall + 0.2 * k,
            side_lost_m=wall + 0.3 * k,
            leave_clear_m=wall + 0.4 * k,
            side_check_m=config.side_check_m * k,
            avoid_m=config.avoid_distance_m * k,
            loop_min_m=config.loop_min_distance_m * k,
            distance_gain=config.wall_distance_gain / k,
        )


class SgbaController:
    """One robot's SGBA: :meth:`step` maps a step's readings to a velocity command."""

    def __init__(self, config: SgbaConfig) -> None:
        self.config = config
        self.geometry = Geometry.of(config)
        self.memory = SgbaMemory(preferred_heading_rad=initial_heading(config))
        self._started = False

    @property
    def preferred_heading_rad(self) -> float:
        """The current preferred heading [rad]."""
        return self.memory.preferred_heading_rad

    # Transitions.

    def _start_rotation(self, yaw: float) -> None:
        m = self.memory
        m.rotate_sign = math.copysign(1.0, wrap_angle(yaw - m.preferred_heading_rad))
        m.state = SgbaState.ROTATE_TO_GOAL

    def _start_wall_following(self, inputs: SgbaInputs) -> None:
        m = self.memory
        m.state = SgbaState.WALL_FOLLOWING
        m.wall_state = WallState.TURN_TO_FIND_WALL
        m.corner_turned_rad = 0.0
        m.events.append('hit_wall')

    def _on_hit(self, inputs: SgbaInputs) -> None:
        """A wall in front while going forward: pick the side, remember the hit."""
        g, m, r = self.geometry, self.memory, inputs.ranges
        if m.reverse_next_hit:
            m.direction = -m.direction
            m.reverse_next_hit = False
        elif r.left_m < r.right_m and r.left_m < g.side_check_m:
            m.direction = -1
        elif (r.left_m > r.right_m and r.right_m < g.side_check_m) or (
            r.left_m > g.side_check_m and r.right_m > g.side_check_m
        ):
            m.direction = 1
        m.hit_position_m = inputs.position_m
        m.hit_preferred_heading_rad = m.preferred_heading_rad
        self._start_wall_following(inputs)

    def _peer_rules(self, inputs: SgbaInputs) -> None:
        """While wall following: give way to a close peer that has right of way."""
        cfg, m, peer = self.config, self.memory, inputs.peer
        if peer is None or not peer.has_way or peer.rssi_dbm <= cfg.rssi_heading_dbm:
            return
        # The authors compare the signs of the two robots' preferred headings (broadcast by
        # radio); here the peer's bearing stands for it: mirror the preferred heading when
        # the mirror image points farther away from the peer.
        old = m.preferred_heading_rad
        new = wrap_angle(-old)
        if math.cos(new - peer.bearing_rad) < math.cos(old - peer.bearing_rad) - 1e-9:
            m.preferred_heading_rad = new
            m.heading_changes += 1
            m.events.append('heading_change')
        if peer.rssi_dbm > cfg.rssi_collision_dbm:
            m.state = SgbaState.MOVE_OUT_OF_WAY
            m.events.append('move_out_of_way')

    def _looping(self, inputs: SgbaInputs) -> bool:
        m = self.memory
        dx = inputs.position_m[0] - m.hit_position_m[0]
        dy = inputs.position_m[1] - m.hit_position_m[1]
        if math.hypot(dx, dy) < self.geometry.loop_min_m:
            return False
        seen = math.atan2(dy, dx)
        return abs(wrap_angle(m.hit_preferred_heading_rad + math.pi - seen)) < (
            self.config.loop_angle_rad
        )

    def _transitions(self, inputs: SgbaInputs) -> None:
        cfg, m, r = self.config, self.memory, inputs.ranges
        g = self.geometry
        hit = r.front_m < g.hit_m
        if m.state is SgbaState.FORWARD:
            if hit:
                self._on_hit(inputs)
        elif m.state is SgbaState.ROTATE_TO_GOAL:
            if hit:
                m.cannot_go_to_goal = True
                self._start_wall_following(inputs)
            elif abs(wrap_angle(inputs.yaw_rad - m.preferred_heading_rad)) < (
                cfg.goal_heading_tolerance_rad
            ):
                m.state = SgbaState.FORWARD
        elif m.state is SgbaState.WALL_FOLLOWING:
            self._peer_rules(inputs)
            if m.state is not SgbaState.WALL_FOLLOWING:
                return
            if m.wall_state is WallState.ALONG_WALL:
                m.cannot_go_to_goal = False
            if self._looping(inputs):
                m.reverse_next_hit = True
            bearing = wrap_angle(m.preferred_heading_rad - inputs.yaw_rad)
            free_side = m.direction * bearing  # > 0: on the side away from the wall
            goal_free = 0.0 < free_side < cfg.leave_bearing_max_rad
            if (
                m.wall_state is WallState.AROUND_CORNER
                and goal_free
                and r.front_m > g.leave_clear_m
                and not m.cannot_go_to_goal
            ):
                m.events.append('leave_wall')
                self._start_rotation(inputs.yaw_rad)
        elif m.state is SgbaState.MOVE_OUT_OF_WAY:
            # Once the peer to give way to has gone by. The authors wait for the strongest
            # peer whatever its right of way, which deadlocks robots that wait next to each
            # other (as robots starting together on the ground do).
            peer = inputs.peer
            if peer is None or not peer.has_way or peer.rssi_dbm <= cfg.rssi_collision_dbm:
                m.events.append('way_clear')
                self._start_rotation(inputs.yaw_rad)

    # The wall follower.

    def _wall_follow(self, inputs: SgbaInputs) -> SgbaCommand:
        cfg, m, r = self.config, self.memory, inputs.ranges
        s = m.direction
        g = self.geometry
        ref = g.wall_m
        side, diagonal = r.side(s), r.diagonal(s)
        if m.last_yaw_rad == m.last_yaw_rad:  # not NaN
            m.corner_turned_rad += abs(wrap_angle(inputs.yaw_rad - m.last_yaw_rad))
        # Transitions of the wall follower.
        if m.wall_state is WallState.TURN_TO_FIND_WALL:
            clear = r.front_m > g.side_lost_m and diagonal > ref
            if clear and (side < g.side_lost_m or m.corner_turned_rad > math.pi):
                m.wall_state = WallState.ALONG_WALL
        elif m.wall_state is WallState.ALONG_WALL:
            if r.front_m < g.hit_m:
                self._enter(WallState.TURN_TO_FIND_WALL, inputs)
            elif side > g.side_lost_m:
                self._enter(WallState.AROUND_CORNER, inputs)
        elif m.wall_state is WallState.AROUND_CORNER:
            if r.front_m < g.hit_m:
                self._enter(WallState.TURN_TO_FIND_WALL, inputs)
            elif side < g.hit_m or m.corner_turned_rad > 2 * math.pi:
                m.wall_state = WallState.ALONG_WALL
        # Actions.
        if m.wall_state is WallState.TURN_TO_FIND_WALL:
            return SgbaCommand(0.0, s * cfg.turn_rate_radps)
        if m.wall_state is WallState.AROUND_CORNER:
            return SgbaCommand(cfg.forward_speed_mps, -s * cfg.forward_speed_mps / ref)
        # Along the wall: hold the distance and the wall's direction (side beam and diagonal).
        c = math.sqrt(0.5)
        alpha = math.atan2(side - diagonal * c, diagonal * c)
        alpha = max(-0.6, min(0.6, alpha))
        distance = side * math.cos(alpha)
        rate = s * (cfg.wall_angle_gain * alpha + g.distance_gain * (ref - distance))
        limit = cfg.max_yaw_rate_radps
        return SgbaCommand(cfg.forward_speed_mps, max(-limit, min(limit, rate)))

    def _enter(self, state: WallState, inputs: SgbaInputs) -> None:
        m = self.memory
        m.wall_state = state
        m.corner_turned_rad = 0.0

    def _actions(self, inputs: SgbaInputs) -> SgbaCommand:
        cfg, m, r = self.config, self.memory, inputs.ranges
        if m.state is SgbaState.FORWARD:
            rate = 0.0
            if r.left_m < self.geometry.wall_m:
                rate -= cfg.side_correction_radps
            if r.right_m < self.geometry.wall_m:
                rate += cfg.side_correction_radps
            return SgbaCommand(cfg.forward_speed_mps, rate)
        if m.state is SgbaState.ROTATE_TO_GOAL:
            return SgbaCommand(0.0, -m.rotate_sign * cfg.turn_rate_radps)
        if m.state is SgbaState.WALL_FOLLOWING:
            return self._wall_follow(inputs)
        # Move out of the way: back off obstacles that are too close, otherwise hold still.
        linear = 0.0
        if r.front_m < self.geometry.avoid_m:
            linear -= cfg.forward_speed_mps
        if r.back_m < self.geometry.avoid_m:
            linear += cfg.forward_speed_mps
        return SgbaCommand(linear, 0.0)

    def step(self, inputs: SgbaInputs) -> SgbaCommand:
        """One control step: update the state from the readings, return the command."""
        m = self.memory
        m.events.clear()
        if not self._started:
            self._started = True
            m.events.append('start')
            self._start_rotation(inputs.yaw_rad)
        self._transitions(inputs)
        command = self._actions(inputs)
        m.last_yaw_rad = inputs.yaw_rad
        return command
