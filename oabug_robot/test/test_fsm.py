"""Scripted sensor sequences drive the OA-Bug state machine through its transitions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from oabug_robot.fsm import Event, FsmState, Mode, OABugFsm, SensorSnapshot
from oabug_robot.heading import angle_difference
from oabug_robot.scan_features import ScanFeatures, SideWall
from oabug_robot.settings import (
    MotionConfig,
    OABugConfig,
    PerceptionConfig,
    SoundMemory,
    SoundTurnRule,
    SoundWallSide,
    TurnDirection,
    Variant,
)
from oabug_robot.sound import PeerBearings

DT = 0.1
BUG_VARIANTS = [Variant.MINIMUM, Variant.SOUND, Variant.GAS, Variant.GAS_SOUND]


def free() -> ScanFeatures:
    return ScanFeatures()


def wall_ahead() -> ScanFeatures:
    return ScanFeatures(front_wall_m=0.2, left=SideWall(0.2, 0.0), right=SideWall(0.2, 0.0))


HIT_M = PerceptionConfig().robot_hit_distance_m


def robot_ahead(distance_m: float = HIT_M - 0.05) -> ScanFeatures:
    return ScanFeatures(front_robot_m=distance_m)


def side_wall(side: int, abeam: bool = True) -> ScanFeatures:
    wall = SideWall(0.25, 0.0, abeam=abeam)
    return ScanFeatures(left=wall) if side > 0 else ScanFeatures(right=wall)


class Script:
    """Feeds snapshots at 10 Hz with a fixed yaw unless told otherwise."""

    def __init__(self, fsm: OABugFsm, yaw_rad: float = 0.0) -> None:
        self.fsm = fsm
        self.index = 0
        self.yaw_rad = yaw_rad
        self.gas_raw = 0
        self.bearings: PeerBearings | None = None

    def step(self, scan: ScanFeatures, yaw_rad: float | None = None):
        if yaw_rad is not None:
            self.yaw_rad = yaw_rad
        snapshot = SensorSnapshot(
            time_s=self.time_s,
            yaw_rad=self.yaw_rad,
            scan=scan,
            gas_raw=self.gas_raw,
            bearings=self.bearings,
        )
        command = self.fsm.step(snapshot)
        self.index += 1
        return command

    @property
    def time_s(self) -> float:
        return self.index * DT

    def hear(self, azimuths_deg: list[float], distances_m: list[float] | None = None) -> None:
        azimuths = np.radians(azimuths_deg)
        distances = np.full(azimuths.size, np.nan) if distances_m is None else np.array(distances_m)
        self.bearings = PeerBearings(azimuths, distances, self.time_s, self.yaw_rad)

    def follow_straight(self, side: int, steps: int = 8) -> None:
        """The wall stays abeam while the heading is held: the corner reference settles."""
        for _ in range(steps):
            self.step(side_wall(side))

    def finish_wrap(self, side: int) -> None:
        """The robot has arced 90 deg round the wall end and has the wall abeam again."""
        self.step(side_wall(side), yaw_rad=self.yaw_rad + side * math.pi / 2)

    def pass_outer_corner(self, side: int):
        """The wall is behind the body now: nothing abeam any more, the wall has ended."""
        return self.step(side_wall(side, abeam=False))


def make(variant: Variant, **overrides) -> OABugFsm:
    return OABugFsm(OABugConfig(variant=variant, **overrides))


def reach_wall(script: Script) -> None:
    script.step(free())
    script.step(wall_ahead())


@pytest.mark.parametrize('variant', BUG_VARIANTS)
def test_robot_heads_out_along_its_preferred_direction_first(variant: Variant) -> None:
    fsm = make(variant, robot_index=1, robot_count=4)
    script = Script(fsm, yaw_rad=0.0)
    command = script.step(free())
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.event is Event.START
    assert fsm.memory.mode is Mode.TURN
    assert fsm.memory.target_yaw_rad == pytest.approx(math.pi / 2)
    assert command.linear_mps == 0.0
    assert command.angular_radps > 0.0
    command = script.step(free(), yaw_rad=math.pi / 2)
    assert fsm.memory.mode is Mode.STRAIGHT
    assert command.linear_mps > 0.0


@pytest.mark.parametrize('variant', BUG_VARIANTS)
def test_hitting_a_wall_from_just_started_starts_wall_following(variant: Variant) -> None:
    fsm = make(variant)
    script = Script(fsm)
    reach_wall(script)
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    assert fsm.memory.event is Event.HIT_WALL
    assert fsm.memory.mode is Mode.FOLLOW
    assert fsm.memory.wall_side != 0


@pytest.mark.parametrize('variant', [Variant.MINIMUM, Variant.GAS])
def test_fixed_turn_right_keeps_the_wall_on_the_left_and_turns_clockwise(variant: Variant) -> None:
    fsm = make(variant, fixed_turn=TurnDirection.RIGHT)
    script = Script(fsm)
    script.step(free())
    command = script.step(wall_ahead())
    assert fsm.memory.wall_side == 1
    assert command.linear_mps < fsm.config.motion.forward_speed_mps
    assert command.angular_radps == -fsm.config.motion.turn_rate_radps


def test_fixed_turn_left_keeps_the_wall_on_the_right() -> None:
    fsm = make(Variant.MINIMUM, fixed_turn=TurnDirection.LEFT)
    script = Script(fsm)
    script.step(free())
    command = script.step(wall_ahead())
    assert fsm.memory.wall_side == -1
    assert command.angular_radps > 0.0


@pytest.mark.parametrize('variant', BUG_VARIANTS)
def test_hitting_another_robot_turns_right_and_returns_to_just_started(variant: Variant) -> None:
    fsm = make(variant)
    script = Script(fsm, yaw_rad=0.0)
    reach_wall(script)
    script.follow_straight(1)
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    command = script.step(robot_ahead())
    assert fsm.memory.event is Event.HIT_ROBOT
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.mode is Mode.TURN
    assert fsm.memory.wall_side == 0
    assert fsm.memory.target_yaw_rad == pytest.approx(-math.pi / 2)
    assert command.angular_radps < 0.0


@pytest.mark.parametrize('variant', BUG_VARIANTS)
def test_hitting_another_robot_while_heading_out_stays_just_started(variant: Variant) -> None:
    fsm = make(variant)
    script = Script(fsm)
    script.step(free())
    script.step(robot_ahead())
    assert fsm.memory.event is Event.HIT_ROBOT
    assert fsm.memory.state is FsmState.JUST_STARTED


def test_a_peer_just_beyond_the_hit_distance_is_not_hit() -> None:
    fsm = make(Variant.GAS)
    script = Script(fsm)
    script.step(free())
    script.step(robot_ahead(HIT_M + 0.05))
    assert Event.HIT_ROBOT not in fsm.memory.counts
    assert fsm.memory.mode is Mode.STRAIGHT


def test_a_second_robot_hit_soon_after_the_first_turns_to_a_random_heading() -> None:
    fsm = make(Variant.GAS, robot_hit_repeat_s=4.0, seed=3)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    script.step(robot_ahead())
    assert fsm.memory.target_yaw_rad == pytest.approx(-math.pi / 2)
    script.step(free(), yaw_rad=-math.pi / 2)
    script.step(robot_ahead())
    assert fsm.memory.counts[Event.HIT_ROBOT] == 2
    assert fsm.memory.target_yaw_rad != pytest.approx(-math.pi), 'not another right turn'
    assert fsm.memory.state is FsmState.JUST_STARTED


def test_robot_hits_far_apart_in_time_both_turn_right() -> None:
    fsm = make(Variant.GAS, robot_hit_repeat_s=4.0)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    script.step(robot_ahead())
    script.step(free(), yaw_rad=-math.pi / 2)
    for _ in range(45):
        script.step(free())
    script.step(robot_ahead())
    assert abs(fsm.memory.target_yaw_rad) == pytest.approx(math.pi)


@pytest.mark.parametrize(
    ('fixed_turn', 'hit_turn', 'expected_yaw'),
    [
        (TurnDirection.RIGHT, TurnDirection.RIGHT, -math.pi / 2),
        (TurnDirection.LEFT, TurnDirection.RIGHT, -math.pi / 2),
        (TurnDirection.RIGHT, TurnDirection.LEFT, math.pi / 2),
        (TurnDirection.LEFT, TurnDirection.LEFT, math.pi / 2),
    ],
)
def test_a_robot_hit_turns_to_the_robot_hit_side_whatever_the_wall_side(
    fixed_turn: TurnDirection, hit_turn: TurnDirection, expected_yaw: float
) -> None:
    fsm = make(Variant.GAS, fixed_turn=fixed_turn, robot_hit_turn=hit_turn)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    script.step(robot_ahead())
    assert fsm.memory.event is Event.HIT_ROBOT
    assert fsm.memory.target_yaw_rad == pytest.approx(expected_yaw)


def test_the_wall_side_follows_fixed_turn_not_the_robot_hit_side() -> None:
    fsm = make(Variant.GAS, fixed_turn=TurnDirection.LEFT, robot_hit_turn=TurnDirection.RIGHT)
    script = Script(fsm)
    reach_wall(script)
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    assert fsm.memory.wall_side == -1, 'a left turn keeps the wall on the right'


def test_a_peer_ahead_while_turning_away_from_a_wall_is_not_hit() -> None:
    fsm = make(Variant.GAS)
    script = Script(fsm)
    reach_wall(script)
    jammed = ScanFeatures(front_wall_m=0.2, front_robot_m=0.1)
    command = script.step(jammed)
    assert Event.HIT_ROBOT not in fsm.memory.counts
    assert command.angular_radps < 0.0, 'still turning away from the wall'


def test_a_peer_is_not_hit_while_turning_in_place() -> None:
    fsm = make(Variant.GAS)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    script.step(robot_ahead())
    script.step(robot_ahead())
    assert fsm.memory.counts[Event.HIT_ROBOT] == 1


ARC = MotionConfig(inner_corner_arc_radius_m=0.15)


def corner_ahead_m(distance_m: float) -> ScanFeatures:
    return ScanFeatures(front_wall_m=distance_m, left=SideWall(0.15, 0.0, abeam=True))


def follower(motion: MotionConfig) -> tuple[OABugFsm, Script]:
    """A Gas robot following the wall on its left, heading south."""
    fsm = make(Variant.GAS, robot_count=1, motion=motion)
    script = Script(fsm)
    reach_wall(script)
    script.step(side_wall(1), yaw_rad=-math.pi / 2)
    script.follow_straight(1)
    return fsm, script


def test_an_inner_corner_is_taken_as_an_arc_on_the_move() -> None:
    fsm, script = follower(ARC)
    motion = fsm.config.motion
    start_m = motion.wall_distance_m + motion.inner_corner_arc_radius_m
    command = script.step(corner_ahead_m(start_m + 0.05))
    assert command.linear_mps == pytest.approx(motion.forward_speed_mps)
    assert abs(command.angular_radps) < motion.turn_rate_radps, 'still plain following'
    command = script.step(corner_ahead_m(start_m - 0.01))
    assert command.angular_radps == -motion.turn_rate_radps, 'turning right at full rate'
    arc_m = command.linear_mps / abs(command.angular_radps)
    assert 0.0 < arc_m <= motion.inner_corner_arc_radius_m
    closer = script.step(corner_ahead_m(0.15))
    assert 0.0 < closer.linear_mps < command.linear_mps, 'the arc tightens near the wall'
    touching = script.step(corner_ahead_m(fsm.config.perception.robot_radius_m))
    assert touching.linear_mps == 0.0, 'on the spot where the wall would touch the body'
    assert fsm.memory.state is FsmState.FOLLOWING_WALL


def test_without_the_arc_an_inner_corner_is_turned_on_the_spot() -> None:
    fsm, script = follower(MotionConfig(inner_corner_arc_radius_m=0.0))
    command = script.step(corner_ahead_m(0.28))
    assert abs(command.angular_radps) < fsm.config.motion.turn_rate_radps
    command = script.step(corner_ahead_m(0.2))
    assert command.linear_mps == 0.0
    assert command.angular_radps == -fsm.config.motion.turn_rate_radps


def test_the_side_wall_swinging_away_in_an_inner_corner_arc_is_no_outer_corner() -> None:
    fsm, script = follower(ARC)
    script.step(ScanFeatures(front_wall_m=0.28, left=SideWall(0.2, 0.3, abeam=False)))
    script.step(ScanFeatures(front_wall_m=0.5, left=SideWall(0.3, 0.6, abeam=False)))
    assert Event.OUTER_CORNER not in fsm.memory.counts
    assert Event.REVISIT not in fsm.memory.counts


@pytest.mark.parametrize('variant', [Variant.MINIMUM, Variant.SOUND])
def test_variants_without_scent_leave_the_wall_at_every_outer_corner(variant: Variant) -> None:
    fsm = make(variant, robot_count=1)
    script = Script(fsm, yaw_rad=0.0)
    reach_wall(script)
    script.follow_straight(1)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.LEAVE_WALL
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.mode is Mode.TURN
    assert fsm.memory.target_yaw_rad == pytest.approx(0.0)


def test_minimum_always_returns_to_the_initial_preferred_direction() -> None:
    fsm = make(Variant.MINIMUM, robot_index=2, robot_count=4)
    phi = fsm.memory.preferred_direction_rad
    script = Script(fsm, yaw_rad=phi)
    for _ in range(3):
        reach_wall(script)
        script.follow_straight(1)
        script.pass_outer_corner(1)
        assert fsm.memory.target_yaw_rad == pytest.approx(phi)
        script.step(free(), yaw_rad=phi)


def test_turning_away_at_an_inner_corner_is_not_an_outer_corner() -> None:
    fsm = make(Variant.GAS)
    script = Script(fsm)
    reach_wall(script)
    script.follow_straight(1)
    # A wall ahead: the robot turns on the spot; meanwhile the old wall leaves the strip.
    blocked = ScanFeatures(front_wall_m=0.2, left=SideWall(0.3, 0.9, abeam=False))
    command = script.step(blocked)
    assert command.angular_radps < 0.0
    script.step(blocked)
    script.step(side_wall(1, abeam=False))
    assert Event.OUTER_CORNER not in fsm.memory.counts
    assert fsm.memory.mode is Mode.FOLLOW


def test_a_wall_already_being_followed_does_not_retrigger_wall_hits() -> None:
    fsm = make(Variant.GAS)
    script = Script(fsm)
    reach_wall(script)
    script.step(wall_ahead())
    script.step(wall_ahead())
    assert fsm.memory.counts[Event.HIT_WALL] == 1
    assert fsm.memory.state is FsmState.FOLLOWING_WALL


@pytest.mark.parametrize('variant', [Variant.GAS, Variant.GAS_SOUND])
def test_gas_variants_keep_following_round_an_unscented_outer_corner(variant: Variant) -> None:
    fsm = make(variant)
    script = Script(fsm)
    reach_wall(script)
    script.follow_straight(1)
    script.gas_raw = 150
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.OUTER_CORNER
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    assert fsm.memory.mode is Mode.WRAP, 'it arcs round the wall end (into the room)'


@pytest.mark.parametrize('variant', [Variant.GAS, Variant.GAS_SOUND])
def test_scented_outer_corner_switches_to_just_started_and_leaves_at_the_next_one(
    variant: Variant,
) -> None:
    fsm = make(variant, robot_count=1)
    script = Script(fsm)
    reach_wall(script)
    script.follow_straight(1)
    script.gas_raw = 250
    script.step(side_wall(1))
    script.gas_raw = 40
    command = script.pass_outer_corner(1)
    assert fsm.memory.event is Event.REVISIT
    assert fsm.memory.visit_count == 1
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.mode is Mode.WRAP, 'it keeps following up to the next outer corner'
    assert command.linear_mps > 0.0
    assert command.angular_radps > 0.0, 'arcing left, round the end of the wall on the left'
    script.step(side_wall(1), yaw_rad=math.pi / 2)
    script.follow_straight(1)
    assert fsm.memory.mode is Mode.FOLLOW
    assert fsm.memory.state is FsmState.JUST_STARTED
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.LEAVE_WALL
    assert fsm.memory.mode is Mode.TURN
    assert fsm.memory.target_yaw_rad == pytest.approx(fsm.memory.preferred_direction_rad)


def scented_corner(script: Script) -> None:
    """Hit a wall, follow it and pass a scented outer corner (on the left)."""
    reach_wall(script)
    script.follow_straight(1)
    script.gas_raw = 400
    script.pass_outer_corner(1)
    script.gas_raw = 0


def revisit(script: Script, follow_steps: int = 8) -> None:
    """Hit a wall, pass a scented outer corner and finish the arc round it (Just Started)."""
    scented_corner(script)
    script.finish_wrap(1)
    script.follow_straight(1, steps=follow_steps)


def inner_corner() -> ScanFeatures:
    return ScanFeatures(front_wall_m=0.2, left=SideWall(0.25, 0.0, abeam=True))


@pytest.mark.parametrize('variant', [Variant.GAS, Variant.GAS_SOUND])
def test_an_inner_corner_after_a_revisit_returns_to_following_wall(variant: Variant) -> None:
    """Paper Fig. 3: hitting a wall in Just Started leads to Following Wall."""
    fsm = make(variant, robot_count=1)
    script = Script(fsm)
    revisit(script)
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.leave_at_next_corner
    command = script.step(inner_corner())
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    assert fsm.memory.event is Event.HIT_WALL
    assert not fsm.memory.leave_at_next_corner
    assert fsm.memory.wall_side == 1, 'it keeps the wall it follows'
    assert command.angular_radps < 0.0, 'turning right, away from the wall ahead'
    script.step(side_wall(1), yaw_rad=-math.pi / 2)
    script.follow_straight(1)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.OUTER_CORNER, 'an unscented corner: into the room'
    assert fsm.memory.mode is Mode.WRAP


def test_with_inner_corners_kept_the_robot_leaves_at_the_next_outer_corner() -> None:
    fsm = make(Variant.GAS, robot_count=1, inner_corner_resumes_following=False)
    script = Script(fsm)
    revisit(script)
    script.step(inner_corner())
    assert fsm.memory.state is FsmState.JUST_STARTED
    script.step(side_wall(1), yaw_rad=-math.pi / 2)
    script.follow_straight(1)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.LEAVE_WALL
    assert fsm.memory.mode is Mode.TURN


def pass_thin_wall_end(script: Script, side: int) -> None:
    """Just round the first corner of a thin wall's end: its end face is abeam, then gone."""
    script.finish_wrap(side)
    script.step(side_wall(side, abeam=True))
    script.pass_outer_corner(side)


@pytest.mark.parametrize('variant', [Variant.GAS, Variant.GAS_SOUND])
def test_a_thin_wall_end_is_one_outer_corner_after_a_revisit(variant: Variant) -> None:
    """Paper Sec. II-A: a wall is a curve with two endpoints; going round one is one corner."""
    fsm = make(variant, robot_count=1)
    script = Script(fsm)
    scented_corner(script)
    assert fsm.memory.event is Event.REVISIT
    pass_thin_wall_end(script, 1)
    assert fsm.memory.mode is Mode.WRAP, 'round the end face: still the same wall end'
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.leave_at_next_corner
    assert fsm.memory.counts.get(Event.LEAVE_WALL, 0) == 0
    script.finish_wrap(1)
    script.follow_straight(1, steps=10)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.LEAVE_WALL, 'the next wall end is a new corner'


def test_with_wall_end_faces_as_corners_the_robot_leaves_at_the_end_face() -> None:
    """wall_end_face_m = 0: the authors' grid, where a jamb's end face is a second corner."""
    fsm = make(Variant.GAS, robot_count=1, wall_end_face_m=0.0)
    script = Script(fsm)
    scented_corner(script)
    pass_thin_wall_end(script, 1)
    assert fsm.memory.event is Event.LEAVE_WALL
    assert fsm.memory.mode is Mode.TURN


def test_a_thin_wall_end_is_not_checked_twice_for_scent() -> None:
    fsm = make(Variant.GAS, robot_count=1)
    script = Script(fsm)
    reach_wall(script)
    script.follow_straight(1)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.OUTER_CORNER
    script.gas_raw = 400
    pass_thin_wall_end(script, 1)
    assert fsm.memory.mode is Mode.WRAP
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    assert fsm.memory.visit_count == 0, 'no new decision at the end face'


@pytest.mark.parametrize('variant', BUG_VARIANTS)
def test_a_follower_that_circles_without_a_wall_leaves_towards_its_preferred_direction(
    variant: Variant,
) -> None:
    fsm = make(variant, robot_count=1, heading_bias_rad=0.4)
    script = Script(fsm, yaw_rad=0.4)
    reach_wall(script)
    assert fsm.memory.mode is Mode.FOLLOW
    side = fsm.memory.wall_side
    yaw = script.yaw_rad
    arc_rad = fsm.config.motion.lost_wall_arc_rad
    step_rad = math.radians(5.0)
    turned = 0.0
    while turned + step_rad < arc_rad:
        command = script.step(free(), yaw_rad=yaw + side * turned)
        assert fsm.memory.mode is Mode.FOLLOW, f'still looking for the wall at {turned:.2f} rad'
        assert command.linear_mps > 0.0
        assert command.angular_radps * side > 0.0, 'arcing towards the side of the wall'
        turned += step_rad
    command = script.step(free(), yaw_rad=yaw + side * (turned + step_rad))
    assert fsm.memory.event is Event.LEAVE_WALL
    assert fsm.memory.state is FsmState.JUST_STARTED
    assert fsm.memory.mode is Mode.TURN
    assert fsm.memory.target_yaw_rad == pytest.approx(fsm.memory.preferred_direction_rad)


def test_going_round_a_wall_end_does_not_count_as_losing_the_wall() -> None:
    fsm = make(Variant.MINIMUM, robot_count=1)
    script = Script(fsm)
    reach_wall(script)
    for k in range(40):
        # Half a turn without a wall beside it, then the wall is back: the count restarts.
        script.step(free(), yaw_rad=math.radians(4.5 * k))
    script.step(side_wall(1, abeam=False), yaw_rad=math.pi)
    for k in range(40):
        script.step(free(), yaw_rad=math.pi + math.radians(4.5 * k))
    assert fsm.memory.mode is Mode.FOLLOW
    assert fsm.memory.state is FsmState.FOLLOWING_WALL


def test_scent_older_than_the_window_does_not_count_as_a_revisit() -> None:
    fsm = make(Variant.GAS, scent_window_s=1.0)
    script = Script(fsm)
    reach_wall(script)
    script.gas_raw = 300
    script.step(side_wall(1))
    script.gas_raw = 0
    script.follow_straight(1, steps=15)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.OUTER_CORNER
    assert fsm.memory.state is FsmState.FOLLOWING_WALL


def test_scent_below_the_threshold_is_not_a_revisit() -> None:
    fsm = make(Variant.GAS, gas_threshold=200)
    script = Script(fsm)
    reach_wall(script)
    script.follow_straight(1)
    script.gas_raw = 199
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.OUTER_CORNER


def revisit_and_leave(script: Script) -> None:
    """Hit a wall, pass a scented corner, pass the next corner (and leave), head out again."""
    revisit(script, follow_steps=25)
    script.pass_outer_corner(1)
    script.step(free(), yaw_rad=script.fsm.memory.target_yaw_rad)


@pytest.mark.parametrize('variant', [Variant.GAS, Variant.GAS_SOUND])
def test_third_revisit_flips_the_preferred_direction_by_180_degrees(variant: Variant) -> None:
    fsm = make(variant, robot_count=1, revisit_flip_count=3, heading_bias_rad=0.3)
    script = Script(fsm, yaw_rad=0.3)
    revisit_and_leave(script)
    revisit_and_leave(script)
    assert fsm.memory.visit_count == 2
    assert fsm.memory.flip_count == 0
    phi_before = fsm.memory.preferred_direction_rad
    reach_wall(script)
    script.follow_straight(1)
    script.gas_raw = 400
    script.pass_outer_corner(1)
    assert fsm.memory.visit_count == 3
    script.gas_raw = 0
    script.finish_wrap(1)
    script.follow_straight(1, steps=25)
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.FLIP
    assert fsm.memory.flip_count == 1
    assert fsm.memory.visit_count == 0
    flipped = angle_difference(fsm.memory.preferred_direction_rad, phi_before)
    assert abs(flipped) == pytest.approx(math.pi)
    assert fsm.memory.target_yaw_rad == pytest.approx(fsm.memory.preferred_direction_rad)


def test_an_unscented_corner_resets_the_revisit_count_by_default() -> None:
    fsm = make(Variant.GAS)
    script = Script(fsm)
    revisit_and_leave(script)
    assert fsm.memory.visit_count == 1
    reach_wall(script)
    script.follow_straight(1)
    script.pass_outer_corner(1)
    assert fsm.memory.visit_count == 0


def test_revisit_count_can_accumulate_across_fresh_corners() -> None:
    fsm = make(Variant.GAS, visit_count_resets_on_fresh_corner=False)
    script = Script(fsm)
    revisit_and_leave(script)
    reach_wall(script)
    script.follow_straight(1)
    script.pass_outer_corner(1)
    assert fsm.memory.visit_count == 1


def test_sound_direction_is_opposite_to_the_resultant_of_the_bearings() -> None:
    fsm = make(Variant.SOUND, robot_count=3, sound_memory=SoundMemory.STORED)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free(), yaw_rad=fsm.memory.preferred_direction_rad)
    script.step(free(), yaw_rad=0.0)
    # Peers ahead-right (-45 deg) and behind-right (-135 deg): resultant to the right (-90).
    script.hear([-45.0, -135.0], [2.0, 2.0])
    script.step(wall_ahead())
    assert fsm.memory.preferred_direction_rad == pytest.approx(math.pi / 2)


@pytest.mark.parametrize(
    ('rule', 'expected_side'), [(SoundTurnRule.AWAY, -1), (SoundTurnRule.TOWARD, 1)]
)
@pytest.mark.parametrize('variant', [Variant.SOUND, Variant.GAS_SOUND])
def test_sound_variants_choose_the_wall_side_from_the_peers(
    variant: Variant, rule: SoundTurnRule, expected_side: int
) -> None:
    fsm = make(
        variant,
        robot_count=2,
        sound_turn_rule=rule,
        sound_wall_side=SoundWallSide.EVERY_CONTACT,
        gas_sound_wall_side=SoundWallSide.EVERY_CONTACT,
    )
    script = Script(fsm, yaw_rad=0.0)
    script.step(free(), yaw_rad=fsm.memory.preferred_direction_rad)
    script.step(free(), yaw_rad=0.0)
    script.hear([-90.0])  # the peer is on the right, theta_opp on the left
    command = script.step(wall_ahead())
    assert fsm.memory.wall_side == expected_side
    # AWAY turns left (counter-clockwise) so the wall ends up on the right.
    assert math.copysign(1.0, command.angular_radps) == -expected_side


def sound_pair(variant: Variant, **overrides) -> OABugFsm:
    """A sound variant with one peer, turning right by default and away from the peers."""
    return make(
        variant,
        robot_count=2,
        fixed_turn=TurnDirection.RIGHT,
        sound_turn_rule=SoundTurnRule.AWAY,
        **overrides,
    )


def own_and_other_field(variant: Variant, suffix: str) -> tuple[str, str]:
    """Config fields ``sound_<suffix>`` and ``gas_sound_<suffix>``: the variant's own first."""
    sound, gas_sound = f'sound_{suffix}', f'gas_sound_{suffix}'
    return (gas_sound, sound) if variant is Variant.GAS_SOUND else (sound, gas_sound)


@pytest.mark.parametrize(
    ('peer_deg', 'deadband_deg', 'expected_side'),
    [
        (-150.0, 45.0, 1),  # theta_opp 30 deg left of ahead: no side, the fixed right turn
        (-150.0, 0.0, -1),  # any offset decides: towards theta_opp, wall on the right
        (-150.0, 25.0, -1),  # 30 deg is outside a 25 deg deadband
        (20.0, 45.0, 1),  # theta_opp 160 deg right, 20 deg from behind: no side
        (20.0, 0.0, 1),  # decided: away from the peer ahead-left, wall on the left
        (-20.0, 0.0, -1),
        (-20.0, 45.0, 1),
        (-90.0, 45.0, -1),  # theta_opp square to the left: the sound decides
    ],
)
@pytest.mark.parametrize('variant', [Variant.SOUND, Variant.GAS_SOUND])
def test_sound_gives_no_wall_side_when_theta_opp_is_near_ahead_or_behind(
    variant: Variant, peer_deg: float, deadband_deg: float, expected_side: int
) -> None:
    """Each variant reads its own deadband; the other variant's is set to the opposite."""
    own, other = own_and_other_field(variant, 'side_deadband_rad')
    fsm = sound_pair(
        variant,
        gas_sound_wall_side=SoundWallSide.EVERY_CONTACT,
        **{own: math.radians(deadband_deg), other: math.radians(45.0 - deadband_deg)},
    )
    assert first_wall_side(fsm, peer_deg) == expected_side


def first_wall_side(fsm: OABugFsm, peer_deg: float) -> int:
    """Wall side taken at the first wall contact, heading 0, with one peer heard at peer_deg."""
    script = Script(fsm, yaw_rad=0.0)
    script.step(free(), yaw_rad=fsm.memory.preferred_direction_rad)
    script.step(free(), yaw_rad=0.0)
    script.hear([peer_deg])
    script.step(wall_ahead())
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    return fsm.memory.wall_side


def test_by_default_only_gas_sound_ignores_a_theta_opp_near_straight_ahead() -> None:
    # theta_opp 30 deg left of ahead: the Sound variant turns towards it (wall on the
    # right), Gas+Sound takes the fixed right turn (wall on the left).
    assert first_wall_side(make(Variant.SOUND, robot_count=2), -150.0) == -1
    assert first_wall_side(make(Variant.GAS_SOUND, robot_count=2), -150.0) == 1
    # Square to the left, both follow the sound.
    assert first_wall_side(make(Variant.GAS_SOUND, robot_count=2), -90.0) == -1


def test_sound_turn_side_uses_bearings_rotated_into_the_current_heading() -> None:
    fsm = make(Variant.SOUND, robot_count=2, sound_turn_rule=SoundTurnRule.AWAY)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    script.hear([-90.0])  # heard at yaw 0: theta_opp points to yaw +90 deg
    script.step(free(), yaw_rad=math.radians(120.0))
    script.step(wall_ahead())
    # From heading 120 deg, +90 deg lies to the right: turn right, wall on the left.
    assert fsm.memory.wall_side == 1


@pytest.mark.parametrize('variant', [Variant.SOUND, Variant.GAS_SOUND])
def test_without_bearings_sound_variants_fall_back_to_the_fixed_turn(variant: Variant) -> None:
    fsm = make(variant, fixed_turn=TurnDirection.RIGHT)
    script = Script(fsm)
    reach_wall(script)
    assert fsm.memory.wall_side == 1


def test_stale_bearings_are_not_used() -> None:
    fsm = make(Variant.SOUND, robot_count=2, bearing_timeout_s=0.5, fixed_turn=TurnDirection.RIGHT)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    script.hear([-90.0])
    for _ in range(10):
        script.step(free())
    script.step(wall_ahead())
    assert fsm.memory.wall_side == 1


def test_sound_variant_updates_the_preferred_direction_at_outer_corners() -> None:
    fsm = make(Variant.SOUND, robot_count=2, sound_memory=SoundMemory.STORED)
    script = Script(fsm, yaw_rad=0.0)
    reach_wall(script)
    script.follow_straight(1)
    script.hear([0.0], [3.0])  # peer straight ahead: go back
    script.pass_outer_corner(1)
    assert fsm.memory.event is Event.LEAVE_WALL
    assert abs(fsm.memory.target_yaw_rad) == pytest.approx(math.pi)
    assert abs(fsm.memory.preferred_direction_rad) == pytest.approx(math.pi)


def test_sound_variant_with_theta_used_once_turns_to_it_but_keeps_phi() -> None:
    fsm = make(Variant.SOUND, robot_count=2, sound_memory=SoundMemory.ONCE)
    phi = fsm.memory.preferred_direction_rad
    script = Script(fsm, yaw_rad=0.0)
    reach_wall(script)
    script.follow_straight(1)
    script.hear([0.0], [3.0])
    script.pass_outer_corner(1)
    assert abs(fsm.memory.target_yaw_rad) == pytest.approx(math.pi)
    assert fsm.memory.preferred_direction_rad == pytest.approx(phi)


def test_sound_variant_as_in_the_authors_simulator_keeps_its_initial_direction() -> None:
    fsm = make(Variant.SOUND, robot_count=2, sound_updates_at_corner=False)
    phi = fsm.memory.preferred_direction_rad
    script = Script(fsm, yaw_rad=phi)
    reach_wall(script)
    script.follow_straight(1)
    script.hear([0.0], [3.0])
    script.pass_outer_corner(1)
    assert fsm.memory.target_yaw_rad == pytest.approx(phi)


@pytest.mark.parametrize(
    ('memory', 'stored'), [(SoundMemory.STORED, True), (SoundMemory.ONCE, False)]
)
def test_gas_sound_leaves_a_revisited_wall_towards_the_sound_direction(
    memory: SoundMemory, stored: bool
) -> None:
    fsm = make(
        Variant.GAS_SOUND, robot_count=2, sound_memory=memory, fixed_turn=TurnDirection.RIGHT
    )
    phi = fsm.memory.preferred_direction_rad
    script = Script(fsm, yaw_rad=phi)
    revisit(script, follow_steps=25)
    script.hear([0.0], [2.0])  # peer straight ahead: theta_opp behind
    expected = script.yaw_rad + math.pi
    script.pass_outer_corner(1)
    assert angle_difference(fsm.memory.target_yaw_rad, expected) == pytest.approx(0.0, abs=1e-9)
    changed = abs(angle_difference(fsm.memory.preferred_direction_rad, phi)) > 1e-6
    assert changed is stored


def test_random_variant_turns_to_a_random_heading_on_every_hit() -> None:
    fsm = make(Variant.RANDOM, seed=4)
    script = Script(fsm, yaw_rad=0.0)
    script.step(free())
    targets = set()
    for scan in (wall_ahead(), robot_ahead()):
        script.step(free(), yaw_rad=fsm.memory.target_yaw_rad)
        script.step(scan)
        assert fsm.memory.mode is Mode.TURN
        targets.add(round(fsm.memory.target_yaw_rad, 9))
    assert fsm.memory.counts[Event.HIT_WALL] == 1
    assert fsm.memory.counts[Event.HIT_ROBOT] == 1
    assert len(targets) == 2
    assert fsm.memory.state is FsmState.JUST_STARTED


def test_random_variant_redraws_its_heading_after_driving_one_step() -> None:
    fsm = make(Variant.RANDOM)
    fsm_config = fsm.config
    assert fsm_config.motion.random_step_m == pytest.approx(0.1)
    always = OABugFsm(
        OABugConfig(
            variant=Variant.RANDOM,
            motion=type(fsm_config.motion)(random_turn_probability=1.0),
        )
    )
    script = Script(always, yaw_rad=always.memory.target_yaw_rad)
    script.step(free())
    script.step(free())  # 0.1 s at 0.3 m/s: 0.03 m driven
    assert always.memory.mode is Mode.STRAIGHT
    for _ in range(3):
        script.step(free())
    assert always.memory.counts.get(Event.RANDOM_TURN, 0) == 1


def test_random_variant_is_deterministic_for_a_seed() -> None:
    def run(seed: int) -> list[float]:
        fsm = make(Variant.RANDOM, seed=seed)
        script = Script(fsm)
        targets = []
        for _ in range(200):
            script.step(free(), yaw_rad=fsm.memory.target_yaw_rad)
            targets.append(fsm.memory.target_yaw_rad)
        return targets

    assert run(7) == run(7)
    assert run(7) != run(8)


@pytest.mark.parametrize('variant', list(Variant))
def test_pump_runs_half_a_second_every_five_seconds_only_for_gas_variants(variant: Variant) -> None:
    fsm = make(variant)
    script = Script(fsm)
    pump = [script.step(free()).pump_on for _ in range(100)]
    if variant.uses_scent:
        assert pump[:5] == [True] * 5
        assert pump[5:50] == [False] * 45
        assert pump[50:55] == [True] * 5
        assert sum(pump) == 10
    else:
        assert not any(pump)


def test_commands_are_python_floats_and_bools() -> None:
    fsm = make(Variant.GAS_SOUND)
    command = Script(fsm).step(free())
    assert type(command.linear_mps) is float
    assert type(command.angular_radps) is float
    assert type(command.pump_on) is bool


def wall_sides_of_two_contacts(fsm: OABugFsm) -> tuple[int, int]:
    """Wall side taken at a first wall contact, and at a second one after a robot hit.

    The peer is on the right both times, so theta_opp lies to the left: the sound side
    (away: towards theta_opp) keeps the wall on the right (-1), the fixed right turn on
    the left (+1).
    """
    script = Script(fsm, yaw_rad=0.0)
    script.step(free(), yaw_rad=fsm.memory.preferred_direction_rad)
    script.step(free(), yaw_rad=0.0)
    script.hear([-90.0])
    script.step(wall_ahead())
    first = fsm.memory.wall_side
    script.follow_straight(first)
    script.step(robot_ahead())
    assert fsm.memory.state is FsmState.JUST_STARTED
    script.step(free(), yaw_rad=fsm.memory.target_yaw_rad)
    script.hear([-90.0])
    script.step(wall_ahead())
    assert fsm.memory.state is FsmState.FOLLOWING_WALL
    assert fsm.memory.wall_contacts == 2
    return first, fsm.memory.wall_side


@pytest.mark.parametrize(
    ('rule', 'expected_sides'),
    [
        (SoundWallSide.EVERY_CONTACT, (-1, -1)),
        (SoundWallSide.FIRST_CONTACT, (-1, 1)),
        (SoundWallSide.NEVER, (1, 1)),
    ],
)
@pytest.mark.parametrize('variant', [Variant.SOUND, Variant.GAS_SOUND])
def test_wall_side_rule_decides_which_contacts_take_the_side_from_the_sound(
    variant: Variant, rule: SoundWallSide, expected_sides: tuple[int, int]
) -> None:
    """Each sound variant reads its own rule; the other variant's rule does not matter."""
    other = (
        SoundWallSide.NEVER if rule is SoundWallSide.EVERY_CONTACT else SoundWallSide.EVERY_CONTACT
    )
    own, others = own_and_other_field(variant, 'wall_side')
    fsm = sound_pair(variant, **{own: rule, others: other})
    assert wall_sides_of_two_contacts(fsm) == expected_sides


def test_defaults_take_the_sound_side_at_every_contact_for_sound_and_the_first_for_gas_sound():
    sound = make(Variant.SOUND, robot_count=2)
    gas_sound = make(Variant.GAS_SOUND, robot_count=2)
    assert wall_sides_of_two_contacts(sound) == (-1, -1)
    assert wall_sides_of_two_contacts(gas_sound) == (-1, 1)
