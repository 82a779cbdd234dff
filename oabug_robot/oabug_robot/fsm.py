"""The OA-Bug finite state machine (paper Fig. 3, Table I) for all five variants.

States: JUST_STARTED (heading out along a direction, or still on a wall it is about to
leave) and FOLLOWING_WALL. Triggers, checked every control step in this order:

* hitting others (a peer return in the front cone): turn right by 90 deg (``robot_hit_turn``),
  JUST_STARTED;
* hitting a wall while heading out: take up the wall on a side (fixed, or chosen from the
  sound direction), FOLLOWING_WALL;
* at an outer corner while following: Minimum and Sound leave towards the preferred
  direction (Sound updates it from the bearings first); Gas and Gas+Sound keep following
  unless the place smells visited, in which case they count the revisit, switch to
  JUST_STARTED and leave at the *next* outer corner, towards the preferred direction
  flipped by 180 deg once the revisit count reaches ``revisit_flip_count``, otherwise
  (Gas+Sound) towards the sound direction. Going round the end of a thin wall is one outer
  corner: its end face, reached within ``wall_end_face_m`` after a wrap, is wrapped round
  without a new decision.

Random is the blank control: straight legs, a new uniform heading on every hit and, after
each ``random_step_m`` driven, with probability ``random_turn_probability``.

Besides the paper's state the controller keeps a motion mode (turning in place to a
heading, going straight, following a wall, wrapping round a wall end) that turns its
decisions into velocities.
:meth:`OABugFsm.step` is the only entry point: one sensor snapshot in, one command out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum
from typing import NamedTuple

import numpy as np

from oabug_robot.corners import CornerDetector
from oabug_robot.heading import angle_difference, preferred_direction, wrap_angle
from oabug_robot.motion import (
    Twist2D,
    follow_wall,
    go_straight,
    inner_corner_ahead,
    turn_in_place,
    wrap_corner,
)
from oabug_robot.pump import PumpScheduler
from oabug_robot.scan_features import ScanFeatures
from oabug_robot.settings import (
    OABugConfig,
    SoundMemory,
    SoundTurnRule,
    SoundWallSide,
    Variant,
)
from oabug_robot.sound import PeerBearings, opposite_direction

__all__ = ['Command', 'Event', 'FsmMemory', 'FsmState', 'Mode', 'OABugFsm', 'SensorSnapshot']

# Longest time step the Random variant integrates its driven distance over [s].
_MAX_STEP_S = 1.0


class FsmState(Enum):
    """The paper's two main states."""

    JUST_STARTED = 0
    FOLLOWING_WALL = 1


class Mode(Enum):
    """What the robot is physically doing."""

    TURN = 0  # rotating in place to target_yaw_rad, then STRAIGHT
    STRAIGHT = 1  # driving along target_yaw_rad
    FOLLOW = 2  # following the wall on wall_side
    WRAP = 3  # arcing 90 deg round the end of the wall on wall_side, then FOLLOW


class Event(Enum):
    """What happened in a control step (the last one wins when several do)."""

    NONE = 0
    START = 1
    HIT_WALL = 2
    HIT_ROBOT = 3
    OUTER_CORNER = 4  # passed an outer corner and kept following
    REVISIT = 5  # outer corner that smelled visited: leave at the next one
    LEAVE_WALL = 6  # left the wall towards a direction
    FLIP = 7  # left the wall towards the preferred direction flipped by 180 deg
    RANDOM_TURN = 8


# The members every step compares with, as module constants (cheaper to look up).
_NO_EVENT = Event.NONE
_TURN, _STRAIGHT, _FOLLOW, _WRAP = Mode.TURN, Mode.STRAIGHT, Mode.FOLLOW, Mode.WRAP
_JUST_STARTED = FsmState.JUST_STARTED


class SensorSnapshot(NamedTuple):
    """Everything the controller reads in one control step (a named tuple: one is built per
    robot and step, several times faster than a frozen dataclass).

    Attributes:
        time_s: current time [s] (sim time in simulation).
        yaw_rad: heading from the IMU [rad].
        scan: features of the latest lidar scan.
        gas_raw: latest gas reading on the 10-bit scale, or None when there is none.
        bearings: latest peer bearings, or None when none were heard.
    """

    time_s: float
    yaw_rad: float
    scan: ScanFeatures
    gas_raw: int | None = None
    bearings: PeerBearings | None = None


class Command(NamedTuple):
    """Output of one control step: velocity and pump (a named tuple, as
    :class:`SensorSnapshot`)."""

    linear_mps: float
    angular_radps: float
    pump_on: bool


@dataclass
class FsmMemory:
    """The controller's complete mutable state (everything a step may change).

    Angles are radians in the yaw frame, times seconds.
    """

    state: FsmState = FsmState.JUST_STARTED
    mode: Mode = Mode.TURN
    wall_side: int = 0  # +1 wall on the left, -1 on the right, 0 none
    preferred_direction_rad: float = 0.0
    target_yaw_rad: float = 0.0
    wrap_start_yaw_rad: float = 0.0
    previous_yaw_rad: float | None = None
    arc_without_wall_rad: float = 0.0
    driven_since_wrap_m: float = math.inf
    last_linear_mps: float = 0.0
    leave_at_next_corner: bool = False
    visit_count: int = 0
    flip_count: int = 0
    last_scent_s: float = -math.inf
    started_s: float | None = None
    last_step_s: float | None = None
    last_robot_hit_s: float = -math.inf
    wall_contacts: int = 0  # Just Started -> Following Wall by hitting a wall
    random_distance_m: float = 0.0
    event: Event = Event.NONE
    counts: dict[Event, int] = field(default_factory=dict)


class OABugFsm:
    """One robot's OA-Bug controller; deterministic given its config (and seed)."""

    def __init__(self, config: OABugConfig) -> None:
        self._config = config
        self._rng = np.random.default_rng(config.seed)
        self._pump = PumpScheduler(
            config.pump_on_s, config.pump_period_s, config.pump_min_speed_mps
        )
        self._corners = CornerDetector()
        phi = preferred_direction(
            config.robot_index, config.robot_count, config.departure, config.heading_bias_rad
        )
        self._memory = FsmMemory(preferred_direction_rad=phi, target_yaw_rad=phi)
        # What every step asks of the (frozen) configuration, looked up once.
        self._uses_scent = config.variant.uses_scent
        self._random = config.variant is Variant.RANDOM
        self._gas_threshold = config.gas_threshold
        perception, motion = config.perception, config.motion
        self._motion = motion
        self._wall_hit_m = perception.wall_hit_distance_m
        self._robot_hit_m = perception.robot_hit_distance_m
        self._wrap_stop_m = perception.wrap_stop_distance_m
        self._body_radius_m = perception.robot_radius_m
        self._heading_tolerance_rad = motion.heading_tolerance_rad
        self._wrap_done_rad = math.pi / 2 - motion.heading_tolerance_rad

    @property
    def config(self) -> OABugConfig:
        """The configuration this controller runs with."""
        return self._config

    @property
    def memory(self) -> FsmMemory:
        """The controller's state (read it; do not modify it)."""
        return self._memory

    def scent_detected(self, time_s: float) -> bool:
        """True when the gas reading crossed the threshold within the scent window."""
        return time_s - self._memory.last_scent_s <= self._config.scent_window_s

    def step(self, snapshot: SensorSnapshot) -> Command:
        """Advance one control step and return the command to apply until the next one."""
        mem = self._memory
        mem.event = _NO_EVENT
        time_s = snapshot.time_s
        if mem.started_s is None:
            mem.started_s = time_s
            self._record(Event.START)
        last = mem.last_step_s
        dt = 0.0 if last is None else time_s - last
        mem.last_step_s = time_s
        # min(max(dt, 0.0), _MAX_STEP_S), written out (NaN stays NaN as there).
        if dt < 0.0:
            dt = 0.0
        elif dt > _MAX_STEP_S:
            dt = _MAX_STEP_S
        gas = snapshot.gas_raw
        uses_scent = self._uses_scent
        if uses_scent and gas is not None and gas >= self._gas_threshold:
            mem.last_scent_s = time_s
        if self._random:
            linear, angular = self._step_random(snapshot, dt)
        else:
            linear, angular = self._step_bug(snapshot, dt)
        mem.last_linear_mps = linear
        pump = uses_scent and self._pump.update(time_s, linear)
        return Command(float(linear), float(angular), bool(pump))

    def _step_bug(self, snap: SensorSnapshot, dt_s: float) -> Twist2D:
        # The configuration values are the ones __init__ looked up (every step reads them).
        mem = self._memory
        motion = self._motion
        scan = snap.scan
        yaw = snap.yaw_rad
        front_wall_m = scan.front_wall_m
        front_blocked = front_wall_m <= self._wall_hit_m
        # A wall ahead at an inner corner (inner_corner_ahead), or one blocking the way.
        corner_ahead = front_blocked or inner_corner_ahead(front_wall_m, motion)
        yaw_change = 0.0
        previous = mem.previous_yaw_rad
        if previous is not None:
            yaw_change = wrap_angle(yaw - previous)  # angle_difference(yaw, previous)
        mem.previous_yaw_rad = yaw
        mem.driven_since_wrap_m += mem.last_linear_mps * dt_s  # dt_s >= 0 (or NaN)
        # Only a robot that drives can hit another: not while it turns on the spot (to a
        # heading, or away from a wall at an inner corner).
        mode = mem.mode
        driving = mode is not _TURN and not (mode is _FOLLOW and front_blocked)
        if driving and scan.front_robot_m <= self._robot_hit_m:
            self._on_hit_robot(snap)
            mode = mem.mode
        if mode is _TURN:
            error = wrap_angle(mem.target_yaw_rad - yaw)
            if abs(error) > self._heading_tolerance_rad:
                return turn_in_place(error, motion)
            mem.mode = mode = _STRAIGHT
        if mode is _STRAIGHT:
            if not front_blocked:
                return go_straight(wrap_angle(mem.target_yaw_rad - yaw), motion)
            self._on_hit_wall(snap)
        elif mode is _WRAP:
            turned = mem.wall_side * wrap_angle(yaw - mem.wrap_start_yaw_rad)
            wrap_blocked = front_wall_m <= self._wrap_stop_m
            if wrap_blocked or turned >= self._wrap_done_rad:
                mem.mode = _FOLLOW
                mem.driven_since_wrap_m = 0.0
            else:
                return wrap_corner(mem.wall_side, motion)
        elif corner_ahead:
            # Turning away from an inner corner swings the old wall out of the abeam strip
            # before the new one comes in: that is no outer corner.
            self._corners.reset()
            mem.driven_since_wrap_m = math.inf
            if mem.state is _JUST_STARTED and self._config.inner_corner_resumes_following:
                self._on_inner_corner_after_revisit()
        elif self._corners.update(scan.left if mem.wall_side > 0 else scan.right):
            if mem.driven_since_wrap_m <= self._config.wall_end_face_m:
                # The end face of a thin wall: still the same wall end, keep wrapping.
                self._wrap(snap)
            else:
                self._on_outer_corner(snap)
            if mem.mode is _TURN:
                return turn_in_place(wrap_angle(mem.target_yaw_rad - yaw), motion)
            if mem.mode is _WRAP:
                return wrap_corner(mem.wall_side, motion)
        side = mem.wall_side
        wall = scan.left if side > 0 else scan.right  # scan.side(side)
        if mem.mode is _FOLLOW and self._wall_lost(
            math.isfinite(wall.distance_m), corner_ahead, yaw_change
        ):
            self._leave_wall(mem.preferred_direction_rad, Event.LEAVE_WALL)
            return turn_in_place(wrap_angle(mem.target_yaw_rad - yaw), motion)
        return follow_wall(
            side,
            wall,
            front_blocked,
            motion,
            front_wall_m=front_wall_m,
            body_radius_m=self._body_radius_m,
        )

    def _wall_lost(self, wall_found: bool, front_blocked: bool, yaw_change_rad: float) -> bool:
        """True once the follower has arced ``lost_wall_arc_rad`` towards its side unseen.

        With no wall beside it the follower arcs towards its side until one is back (round
        a wall end that is not a corner of the grid, or a thin jamb). A "wall" that was a
        peer taken for a wall, or a follower pushed off its wall into open space, leaves it
        circling on the spot for ever; the authors' grid robots, always touching their wall,
        could not lose it. After that much arc the robot leaves towards its preferred
        direction, as it does when it starts.
        """
        mem = self._memory
        if wall_found or front_blocked:
            mem.arc_without_wall_rad = 0.0
            return False
        mem.arc_without_wall_rad += max(0.0, mem.wall_side * yaw_change_rad)
        return mem.arc_without_wall_rad >= self._config.motion.lost_wall_arc_rad

    def _on_hit_robot(self, snap: SensorSnapshot) -> None:
        """Hitting others: turn by 90 deg (``robot_hit_turn``, paper: right) and start again.

        Two robots jammed in a corner can hit each other, turn into the wall, turn back and
        hit each other again for ever (on the authors' grid, where nothing is random, such
        pairs stay locked to the end of the run). A hit within ``robot_hit_repeat_s`` of the
        previous one therefore turns to a random heading instead, which breaks the symmetry.
        """
        mem = self._memory
        repeat_s = self._config.robot_hit_repeat_s
        if snap.time_s - mem.last_robot_hit_s <= repeat_s:
            heading = float(self._rng.uniform(-math.pi, math.pi))
        else:
            heading = snap.yaw_rad + self._config.robot_hit_turn.yaw_sign * math.pi / 2
        mem.last_robot_hit_s = snap.time_s
        self._turn_to(wrap_angle(heading))
        mem.state = FsmState.JUST_STARTED
        self._record(Event.HIT_ROBOT)

    def _on_hit_wall(self, snap: SensorSnapshot) -> None:
        """Just Started -> Following Wall: pick the side to keep the wall on."""
        mem = self._memory
        # Turning right (clockwise) away from the wall leaves it on the left.
        side = -self._config.fixed_turn.yaw_sign
        if self._config.variant.uses_sound:
            theta = self._sound_direction(snap)
            if theta is not None:
                if self._config.sound_memory is SoundMemory.STORED:
                    mem.preferred_direction_rad = theta
                if self._sound_picks_wall_side():
                    side = self._side_from_sound(theta, snap.yaw_rad, side)
        mem.wall_contacts += 1
        mem.state = FsmState.FOLLOWING_WALL
        mem.mode = Mode.FOLLOW
        mem.wall_side = side
        mem.leave_at_next_corner = False
        mem.arc_without_wall_rad = 0.0
        mem.driven_since_wrap_m = math.inf
        self._corners.reset()
        self._record(Event.HIT_WALL)

    def _sound_picks_wall_side(self) -> bool:
        """Whether this wall contact takes its side from theta_opp (sound variants only)."""
        rule = self._config.active_wall_side
        if rule is SoundWallSide.EVERY_CONTACT:
            return True
        return rule is SoundWallSide.FIRST_CONTACT and self._memory.wall_contacts == 0

    def _on_inner_corner_after_revisit(self) -> None:
        """Hitting a wall in Just Started (still on the wall after a revisit): Following Wall.

        Paper Fig. 3: hitting a wall takes Just Started to Following Wall, so the pending
        departure is dropped and the next outer corner is checked for scent again. The robot
        keeps its wall side: at an inner corner it can only turn away from the wall ahead.
        """
        mem = self._memory
        mem.state = FsmState.FOLLOWING_WALL
        mem.leave_at_next_corner = False
        self._record(Event.HIT_WALL)

    def _side_from_sound(self, theta_rad: float, yaw_rad: float, default_side: int) -> int:
        """Wall side for turning towards (TOWARD) or away from (AWAY) the peers.

        Turning left (towards theta_opp on the left) keeps the wall on the right (-1). A
        theta_opp within the deadband of straight ahead or behind keeps ``default_side``.
        """
        relative = angle_difference(theta_rad, yaw_rad)
        deadband = self._config.active_side_deadband_rad
        if abs(relative) <= deadband or abs(relative) >= math.pi - deadband:
            return default_side
        away_side = -1 if relative > 0.0 else 1
        return away_side if self._config.sound_turn_rule is SoundTurnRule.AWAY else -away_side

    def _on_outer_corner(self, snap: SensorSnapshot) -> None:
        mem = self._memory
        cfg = self._config
        variant = cfg.variant
        if mem.state is FsmState.FOLLOWING_WALL:
            if not variant.uses_scent:
                heading = mem.preferred_direction_rad
                if variant.uses_sound and cfg.sound_updates_at_corner:
                    theta = self._sound_direction(snap)
                    if theta is not None:
                        heading = theta
                        if cfg.sound_memory is SoundMemory.STORED:
                            mem.preferred_direction_rad = theta
                self._leave_wall(heading, Event.LEAVE_WALL)
            elif self.scent_detected(snap.time_s):
                mem.last_scent_s = -math.inf
                mem.visit_count += 1
                mem.state = FsmState.JUST_STARTED
                self._wrap(snap)
                mem.leave_at_next_corner = True
                self._record(Event.REVISIT)
            else:
                if cfg.visit_count_resets_on_fresh_corner:
                    mem.visit_count = 0
                self._wrap(snap)
                self._record(Event.OUTER_CORNER)
            return
        # Just Started, still on the wall after a revisit: leave now.
        if mem.visit_count >= cfg.revisit_flip_count:
            mem.visit_count = 0
            mem.flip_count += 1
            mem.preferred_direction_rad = wrap_angle(mem.preferred_direction_rad + math.pi)
            self._leave_wall(mem.preferred_direction_rad, Event.FLIP)
            return
        heading = mem.preferred_direction_rad
        if variant.uses_sound:
            theta = self._sound_direction(snap)
            if theta is not None:
                heading = theta
                if cfg.sound_memory is SoundMemory.STORED:
                    mem.preferred_direction_rad = theta
        self._leave_wall(heading, Event.LEAVE_WALL)

    def _wrap(self, snap: SensorSnapshot) -> None:
        """Keep following: arc round the end of the wall."""
        mem = self._memory
        mem.mode = Mode.WRAP
        mem.driven_since_wrap_m = math.inf
        mem.wrap_start_yaw_rad = snap.yaw_rad
        mem.arc_without_wall_rad = 0.0
        self._corners.reset()

    def _leave_wall(self, heading_rad: float, event: Event) -> None:
        mem = self._memory
        self._turn_to(heading_rad)
        mem.state = FsmState.JUST_STARTED
        self._record(event)

    def _turn_to(self, heading_rad: float) -> None:
        mem = self._memory
        mem.mode = Mode.TURN
        mem.target_yaw_rad = wrap_angle(heading_rad)
        mem.wall_side = 0
        mem.arc_without_wall_rad = 0.0
        mem.driven_since_wrap_m = math.inf
        mem.leave_at_next_corner = False

    def _sound_direction(self, snap: SensorSnapshot) -> float | None:
        """theta_opp in the yaw frame [rad], or None when no fresh bearings are heard."""
        bearings = snap.bearings
        if bearings is None or snap.time_s - bearings.stamp_s > self._config.bearing_timeout_s:
            return None
        theta = opposite_direction(
            bearings.azimuths_rad, bearings.distances_m, self._config.sound_weighting
        )
        return None if theta is None else wrap_angle(theta + bearings.yaw_at_stamp_rad)

    def _step_random(self, snap: SensorSnapshot, dt_s: float) -> Twist2D:
        mem = self._memory
        cfg = self._config
        if mem.mode is Mode.TURN:
            error = angle_difference(mem.target_yaw_rad, snap.yaw_rad)
            if abs(error) > cfg.motion.heading_tolerance_rad:
                return turn_in_place(error, cfg.motion)
            mem.mode = Mode.STRAIGHT
            mem.random_distance_m = 0.0
        scan = snap.scan
        if scan.front_wall_m <= cfg.perception.wall_hit_distance_m:
            return self._random_turn(snap, Event.HIT_WALL)
        if scan.front_robot_m <= cfg.perception.robot_hit_distance_m:
            return self._random_turn(snap, Event.HIT_ROBOT)
        mem.random_distance_m += cfg.motion.forward_speed_mps * dt_s
        while mem.random_distance_m >= cfg.motion.random_step_m:
            mem.random_distance_m -= cfg.motion.random_step_m
            if self._rng.random() < cfg.motion.random_turn_probability:
                return self._random_turn(snap, Event.RANDOM_TURN)
        return go_straight(angle_difference(mem.target_yaw_rad, snap.yaw_rad), cfg.motion)

    def _random_turn(self, snap: SensorSnapshot, event: Event) -> Twist2D:
        mem = self._memory
        mem.mode = Mode.TURN
        mem.target_yaw_rad = float(self._rng.uniform(-math.pi, math.pi))
        self._record(event)
        return turn_in_place(
            angle_difference(mem.target_yaw_rad, snap.yaw_rad), self._config.motion
        )

    def _record(self, event: Event) -> None:
        self._memory.event = event
        self._memory.counts[event] = self._memory.counts.get(event, 0) + 1
