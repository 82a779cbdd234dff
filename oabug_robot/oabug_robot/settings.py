"""Configuration of the OA-Bug controller: the paper's parameters as documented defaults.

Paper: Tan et al., "OA-Bug: An Olfactory-Auditory Augmented Bug Algorithm for Swarm Robots
in a Denied Environment" (IROS 2023). Where the authors' simulator or robot code departs
from the paper, the default follows the paper and the alternative is an enum value here
(see docs/oabug.md, "Choices").

Angles are radians in the IMU's yaw frame (REP 103: counter-clockwise positive), distances
metres, durations seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from enum import Enum

from swarm_common.params import parameter, section

from oabug_robot.errors import ConfigError

__all__ = [
    'Departure',
    'MotionConfig',
    'OABugConfig',
    'PerceptionConfig',
    'SoundMemory',
    'SoundTurnRule',
    'SoundWallSide',
    'SoundWeighting',
    'TurnDirection',
    'Variant',
]


class Variant(Enum):
    """The five algorithms of the paper's Table I."""

    RANDOM = 'random'  # blank control: straight legs, random headings
    MINIMUM = 'minimum'  # "Bug 0": fixed turn side, leaves every outer corner towards phi_i
    SOUND = 'sound'  # auditory only: turn side and phi' from the peers' bearings
    GAS = 'gas'  # olfactory only ("Advanced Bug 1"): scent-based revisit rule
    GAS_SOUND = 'gas_sound'  # full OA-Bug

    @classmethod
    def parse(cls, text: str) -> Variant:
        """Return the variant named ``text`` (case-insensitive), or raise ConfigError."""
        try:
            return cls(text.strip().lower())
        except ValueError:
            names = ', '.join(v.value for v in cls)
            msg = f'unknown OA-Bug variant {text!r}; expected one of {names}'
            raise ConfigError(msg) from None

    @property
    def uses_scent(self) -> bool:
        """True for the variants that pump a scent trail and read the gas sensor."""
        return self in (Variant.GAS, Variant.GAS_SOUND)

    @property
    def uses_sound(self) -> bool:
        """True for the variants that steer by the peers' bearings."""
        return self in (Variant.SOUND, Variant.GAS_SOUND)


class Departure(Enum):
    """Where the swarm sets off; decides how the preferred directions fan out."""

    CENTER = 'center'  # full circle: phi_i = bias + i * 360 deg / n (paper Sec. II-B)
    EDGE = 'edge'  # half circle into the building: phi_i = bias + (i + 1/2) * 180 deg / n

    @classmethod
    def parse(cls, text: str) -> Departure:
        """Return the departure named ``text`` (case-insensitive), or raise ConfigError."""
        try:
            return cls(text.strip().lower())
        except ValueError:
            msg = f'unknown departure {text!r}; expected center or edge'
            raise ConfigError(msg) from None


class TurnDirection(Enum):
    """A fixed turn side ("all turn right")."""

    LEFT = 'left'
    RIGHT = 'right'

    @property
    def yaw_sign(self) -> int:
        """Sign of the yaw change of this turn: +1 left (counter-clockwise), -1 right."""
        return 1 if self is TurnDirection.LEFT else -1


class SoundTurnRule(Enum):
    """How a sound variant picks the wall-following side when the sound picks it."""

    AWAY = 'away'  # paper ("turns ... according to" theta_opp) and the authors' robot
    TOWARD = 'toward'  # the authors' simulator: turn toward the peers' resultant


class SoundWallSide(Enum):
    """At which wall contacts (Just Started -> Following Wall) the sound picks the side."""

    EVERY_CONTACT = 'every_contact'  # Table I
    FIRST_CONTACT = 'first_contact'  # the paper's discussion: the first wall hit only
    NEVER = 'never'  # always fixed_turn; theta_opp only says where to leave a wall


class SoundWeighting(Enum):
    """How the peers' bearings are summed into the resultant c_i,opp = -sum_j c_j."""

    DISTANCE = 'distance'  # paper: c_j = (dx_j, dy_j), so far peers weigh more (unit if unknown)
    UNIT = 'unit'  # the authors' robot: unit vectors along each bearing


class SoundMemory(Enum):
    """Whether the sound direction theta_opp becomes the stored preferred direction."""

    STORED = 'stored'  # paper's wording: phi'_i = theta_opp is the new preferred direction
    ONCE = 'once'  # the authors' simulator: used for one turn; flips apply to phi_i


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise ConfigError(message)


@dataclass(frozen=True)
class PerceptionConfig:
    """How the lidar scan and the bearings are read.

    Attributes:
        robot_radius_m: radius of the own body (and of the peers' bodies) [m].
        front_half_width_m: half width of the corridor ahead checked for walls [m].
        wall_hit_distance_m: a wall return this close ahead (from the lidar origin) is a hit
            [m]. The authors' robot hits a wall when its next 0.1 m step would touch it,
            0.2 m from its centre; 0.22 m also lets a robot turn on the spot in the middle of
            a 2-cell (0.53 m) corridor or room without the side walls counting as hits.
        wrap_stop_distance_m: while arcing round a wall end into a door, only a wall this
            close ahead stops the arc (the far jamb of a 0.5 m door is nearer than
            wall_hit_distance_m) [m].
        robot_hit_distance_m: a peer return this close inside the front cone is a hit [m].
            The authors' simulator cancels a 0.1 m step that would bring two 0.2 m robots
            into contact, i.e. it hits a peer 0.3 m centre to centre ahead: 0.2 m from the
            lidar to the peer's surface.
        robot_cone_half_angle_rad: half angle of the cone in which peers count as hit [rad]
            (the authors' robot: 30 deg).
        robot_contact_distance_m: a peer return this close within
            ``robot_contact_half_angle_rad`` of straight ahead, outside the front cone too,
            is a hit [m]: a peer touching the body ahead of abeam blocks the drive as one
            ahead does (the authors' grid: any step a robot blocks is a robot hit). At or
            above the lidar's minimum range (RPLidar A1: 0.15 m), so a peer too close to
            measure (-inf) counts; 0 turns the rule off.
        robot_contact_half_angle_rad: half angle of that contact sector [rad]. A touching
            peer of the same size spans 30 deg either side of its centre's direction, so its
            returns come within 60 deg of straight ahead exactly when its centre is ahead of
            abeam, where it blocks the drive.
        robot_contact_in_path: the contact rule counts only peer returns inside the
            corridor the body sweeps (``front_half_width_m`` either side), i.e. a peer the
            next step would push; a peer beside the path, passed with a gap (two followers
            of opposite walls of a 2-cell corridor are 0.23 m apart), is no hit.
        peer_bearing_tolerance_rad: angular error allowed between a bearing and the peer's
            lidar returns [rad]; added to the angle the peer's body spans.
        peer_mask_range_m: returns farther than this are never attributed to a peer [m]; a
            peer beyond it cannot touch any feature the controller uses.
        peer_bearing_max_distance_m: a bearing whose reported distance exceeds this is not
            used to mask lidar returns (the RSSI distance is coarse, so this is generous) [m].
        peer_distance_factor: a bearing whose coarse distance exceeds this many times the
            distance of the peer-like returns in its direction is a peer behind a wall, and
            those returns stay wall.
        feature_range_m: returns farther than this (or than the capture and hit distances,
            whichever is largest) are ignored [m].
        follow_capture_m: a side return farther than this does not count as the followed wall [m].
        side_lookahead_m: returns farther ahead than this do not count for the wall beside
            the robot, so the jamb across a door gap cannot pull the robot past the door (it
            wraps round the near jamb into the room instead); walls ahead are the front
            check's [m].
        side_window_behind_m: returns up to this far behind the lidar count for the wall
            beside the robot [m].
        side_wall_band_m: returns more than this beyond the closest one (laterally) are not
            part of the wall beside the robot [m].
        side_wall_fit_tolerance_m: returns farther than this from the first line fit are
            left out of the second (a corner inside the window) [m].
        abeam_behind_m: the abeam strip reaches this far behind the lidar: the robot has
            passed a wall's end once no return lies in the strip [m].
        abeam_reach_m: lateral extent of the abeam strip [m].
        lidar_yaw_offset_rad: yaw of the lidar's zero ray in the robot frame [rad].
    """

    robot_radius_m: float = parameter(0.1, 'robot body radius', unit='m', gt=0.0)
    front_half_width_m: float = 0.12
    wall_hit_distance_m: float = parameter(0.22, 'wall this close ahead is hit', unit='m', ge=0.0)
    wrap_stop_distance_m: float = 0.18
    robot_hit_distance_m: float = parameter(
        0.2, 'peer this close in the front cone is hit', unit='m', ge=0.0
    )
    robot_cone_half_angle_rad: float = math.radians(30.0)
    robot_contact_distance_m: float = parameter(
        0.16, 'peer this close ahead of abeam (not only in the cone) is hit', unit='m', ge=0.0
    )
    robot_contact_half_angle_rad: float = math.radians(60.0)
    robot_contact_in_path: bool = parameter(
        True,
        'the contact rule counts only peers inside the corridor the body sweeps, not beside it',
    )
    peer_bearing_tolerance_rad: float = math.radians(10.0)
    peer_mask_range_m: float = 1.0
    peer_bearing_max_distance_m: float = 2.0
    peer_distance_factor: float = 2.0
    feature_range_m: float = 1.0
    follow_capture_m: float = 0.8
    side_lookahead_m: float = 0.05
    side_window_behind_m: float = 0.15
    side_wall_band_m: float = 0.1
    side_wall_fit_tolerance_m: float = 0.02
    abeam_behind_m: float = 0.02
    abeam_reach_m: float = 0.45
    lidar_yaw_offset_rad: float = parameter(
        0.0, 'yaw of the lidar zero ray in the robot frame', unit='deg', degrees=True
    )

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            _require(math.isfinite(value), f'{f.name} must be finite, got {value!r}')
            if f.name != 'lidar_yaw_offset_rad':
                _require(value >= 0.0, f'{f.name} must be >= 0, got {value!r}')
        _require(self.robot_radius_m > 0.0, 'robot_radius_m must be > 0')
        _require(
            self.wall_hit_distance_m > self.robot_radius_m,
            'wall_hit_distance_m must exceed robot_radius_m',
        )
        _require(
            self.wrap_stop_distance_m > self.robot_radius_m,
            'wrap_stop_distance_m must exceed robot_radius_m',
        )
        _require(
            self.robot_cone_half_angle_rad < math.pi / 2,
            'robot_cone_half_angle_rad must be below 90 deg',
        )
        _require(
            self.robot_contact_half_angle_rad <= math.pi / 2,
            'robot_contact_half_angle_rad must be at most 90 deg',
        )
        _require(
            self.robot_contact_distance_m <= self.robot_hit_distance_m,
            'robot_contact_distance_m must not exceed robot_hit_distance_m',
        )


@dataclass(frozen=True)
class MotionConfig:
    """Speeds and gains of the motion primitives (turn in place, go straight, follow wall).

    Attributes:
        forward_speed_mps: cruise speed [m/s].
        turn_rate_radps: largest yaw rate commanded [rad/s]. A turn costs at most one action
            on the authors' grid but real time from the mission budget here, so turns run at
            the simulated body's limit (2 rad/s).
        min_turn_rate_radps: smallest yaw rate of a turn in place, so turns finish [rad/s].
        heading_gain_per_s: P gain of the heading controller [1/s].
        heading_tolerance_rad: a turn in place ends when the heading error is below this [rad].
        wall_distance_m: distance kept from the followed wall, lidar origin to wall [m]. The
            authors' grid robots hug their wall at 0.1-0.2 m centre to wall; 0.15 m is the
            middle of that range and the closest a lidar with the RPLidar A1's 0.15 m minimum
            range still measures (nearer returns read -inf, i.e. at the minimum range).
            Chosen against 0.16, 0.18 and 0.2 m (docs/notes/oabug_measurements.md).
        inner_corner_arc_radius_m: a follower meeting a wall ahead (an inner corner) turns
            away from it on an arc of this radius while driving on, from this far beyond
            ``wall_distance_m``, instead of stopping at the wall and turning on the spot
            (the grid's 90 deg turn, on the move); the arc tightens as the wall comes
            closer and becomes a turn on the spot where the wall would touch the body.
            0 turns on the spot [m].
        wall_distance_gain_radps_per_m: yaw rate per metre of wall-distance error [rad/(s m)].
        wall_angle_gain_per_s: yaw rate per radian of wall-direction error [1/s].
        random_step_m: the Random variant redraws its heading with probability
            random_turn_probability after each such distance driven (the authors' action
            length, 0.1 m).
        random_turn_probability: see random_step_m (authors' simulator: 1/2).
        lost_wall_arc_rad: a follower that has arced this far towards its side without a
            wall beside it has lost the wall and leaves towards its preferred direction
            (going round a wall end takes at most half a turn) [rad].
    """

    forward_speed_mps: float = parameter(0.3, 'cruise speed', unit='m/s', gt=0.0)
    turn_rate_radps: float = parameter(2.0, 'largest yaw rate', unit='rad/s', gt=0.0)
    min_turn_rate_radps: float = parameter(
        0.3,
        'smallest yaw rate of a turn in place, so turns finish; at most turn_rate_radps',
        unit='rad/s',
        gt=0.0,
    )
    heading_gain_per_s: float = 3.0
    heading_tolerance_rad: float = math.radians(3.0)
    wall_distance_m: float = parameter(
        0.15, 'distance kept from the followed wall', unit='m', gt=0.0
    )
    inner_corner_arc_radius_m: float = parameter(
        0.15,
        (
            'a follower takes an inner corner as an arc of this radius, starting when the '
            'wall ahead is this much beyond wall_distance_m (0: stop and turn on the spot)'
        ),
        unit='m',
        ge=0.0,
    )
    wall_distance_gain_radps_per_m: float = 6.0
    wall_angle_gain_per_s: float = 2.5
    random_step_m: float = parameter(
        0.1, 'Random variant: distance per random draw', unit='m', gt=0.0
    )
    random_turn_probability: float = 0.5
    lost_wall_arc_rad: float = 1.5 * math.pi

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            _require(math.isfinite(value), f'{f.name} must be finite, got {value!r}')
            if f.name == 'inner_corner_arc_radius_m':
                _require(value >= 0.0, f'{f.name} must be >= 0, got {value!r}')
            else:
                _require(value > 0.0, f'{f.name} must be > 0, got {value!r}')
        _require(
            self.min_turn_rate_radps <= self.turn_rate_radps,
            'min_turn_rate_radps must not exceed turn_rate_radps',
        )
        _require(self.random_turn_probability <= 1.0, 'random_turn_probability must be <= 1')


@dataclass(frozen=True)
class OABugConfig:
    """Everything one OA-Bug robot needs to know; built once from the node's parameters.

    Attributes:
        variant: which algorithm of Table I runs.
        robot_index: i, this robot's index in the swarm, 0 <= i < robot_count.
        robot_count: n, the number of robots that depart together.
        departure: centre (full-circle fan) or edge (half-circle fan into the building).
        heading_bias_rad: the paper's common "bias" [rad]; for an edge departure, the
            direction into the building minus 90 deg, so the fan is centred on it.
        gas_threshold: raw 10-bit gas reading at or above which a place smells visited
            (paper: 200).
        scent_window_s: a reading above the threshold counts as "scent at this corner" for
            this long, because the MP503 is slow [s].
        revisit_flip_count: after this many revisits the preferred direction flips by 180 deg
            (paper: "e.g., three times"; counted as >=, like the authors' simulator).
        visit_count_resets_on_fresh_corner: forget the revisit count at an unscented corner,
            i.e. count revisits in a row (the paper's "nearby area thoroughly searched").
        inner_corner_resumes_following: a wall hit at an inner corner while the robot is
            still on its wall after a revisit (Just Started) takes it back to Following Wall,
            as paper Fig. 3 and the authors' simulator do, so the next outer corner is
            checked for scent again; False keeps the departure for the next outer corner.
        wall_end_face_m: an outer corner reached within this distance driven after the
            robot finished wrapping round a corner is the end face of the same thin wall:
            it keeps wrapping without a new decision (no scent check, no departure), so
            going round a wall end is one outer corner, as for the paper's walls, curves
            with two endpoints (Sec. II-A). The authors' grid gives a 2.5 cm thick wall end
            two corners, and a robot that revisited one door jamb left the wall in the
            doorway; 0 does the same here [m]. In two Gas+Sound runs, 75 corners came within
            0.2 m of driving after a wrap (68 of them within 0.15 m: end faces, 2.5 cm), none
            between 0.2 and 0.25 m, and the rest from 0.25 m on (faces of one cell, 0.27 m,
            or longer).
        fixed_turn: side turned to at a first wall contact without sound (paper: "turns in
            the same direction (e.g., right)"); right keeps the wall on the left.
        robot_hit_turn: side turned to by 90 deg after hitting another robot (paper: "all
            turn right"). Turning towards the followed wall, as the authors' simulator does
            (fixed_turn left, walls on the right, robot hits right), can lock two robots
            for good: turn into the wall, turn back to the peer, hit it again
            (docs/notes/oabug.md, "Why Gas trails Gas+Sound from the edge on the authors'
            grid").
        robot_hit_repeat_s: a robot hit this soon after the previous one turns to a random
            heading instead of ``robot_hit_turn``, to break jams of two robots (0
            disables) [s].
        sound_turn_rule: see SoundTurnRule. Table I has the robot update phi'_i = theta_opp
            and turn "according to its direction", i.e. towards theta_opp, away from the
            peers, as the authors' robot does (default); their simulator turns toward the
            peers' resultant.
        sound_wall_side: at which wall contacts the Sound variant takes its side from
            theta_opp (see SoundWallSide; Table I: every contact).
        gas_sound_wall_side: the same for Gas+Sound. Table I says every contact; the
            paper's discussion explains Gas+Sound's lead from the edge by robots that "turn
            in different directions" when first hitting the wall. Default (not Table I):
            the first contact only, the fixed side after it, so followers keep one hand and
            do not meet head on along a wall; compared with every contact and never in
            docs/notes/oabug.md ("The wall side of Gas+Sound").
        sound_side_deadband_rad: for the Sound variant, a theta_opp within this angle of
            straight ahead or straight behind gives no side (both turns point equally
            towards it, and bearing noise decides): such a contact takes ``fixed_turn``.
            0 (default) lets any offset decide, as the paper and the authors' code do; the
            Sound variant, which has no scent trail, spreads by those split sides [rad].
        gas_sound_side_deadband_rad: the same for Gas+Sound. Default 45 deg (not in the
            paper): robots that leave the centre in a symmetric fan hear their peers behind
            them, and splitting their sides at random lowers Gas+Sound's coverage with 2-8
            robots (docs/notes/oabug.md, "Robot count") [rad].
        sound_weighting: see SoundWeighting (paper: distance).
        sound_memory: see SoundMemory; the paper's text says stored, its 180 deg flip
            ("an area symmetrical ... with respect to the departure point") only makes sense
            for the original phi_i (default: once, as in the authors' simulator).
        sound_updates_at_corner: the Sound variant updates phi' from the bearings at outer
            corners (paper, Table I); False leaves it at phi_i (the authors' simulator).
        pump_on_s: pump burst length (paper: 0.5 s).
        pump_period_s: time between burst starts (paper: every 5 s).
        pump_min_speed_mps: a burst starts only at this forward speed or faster, so the robot
            does not sit in its own puff (see oabug_robot.pump); 0 pumps on the clock [m/s].
        bearing_timeout_s: bearings older than this are not used [s].
        seed: seed of the Random variant's generator.
        perception: lidar and bearing interpretation.
        motion: speeds and controller gains.
    """

    variant: Variant = parameter(Variant.GAS_SOUND, 'which algorithm of Table I runs')
    robot_index: int = parameter(0, 'i: this robot index in the swarm, 0..robot_count-1', ge=0)
    robot_count: int = parameter(1, 'n: number of robots that depart together', ge=1)
    departure: Departure = parameter(
        Departure.CENTER, 'center: full-circle fan of preferred directions; edge: half-circle fan'
    )
    heading_bias_rad: float = parameter(
        0.0,
        (
            'bias of the preferred directions in the IMU yaw frame; for edge departure, the '
            'direction into the building minus 90'
        ),
        unit='deg',
        degrees=True,
    )
    gas_threshold: int = parameter(200, 'raw 10-bit gas reading that means scent', ge=0, le=1023)
    scent_window_s: float = parameter(
        2.0, 'scent counts at a corner for this long', unit='s', ge=0.0
    )
    revisit_flip_count: int = parameter(3, 'revisits before the 180 deg flip', ge=1)
    visit_count_resets_on_fresh_corner: bool = parameter(
        True, 'an unscented outer corner resets the revisit count (count revisits in a row)'
    )
    inner_corner_resumes_following: bool = parameter(
        True, 'an inner corner after a revisit returns to Following Wall (paper Fig. 3)'
    )
    wall_end_face_m: float = parameter(
        0.15,
        'an outer corner this soon after a wrap is the same wall end: keep wrapping',
        unit='m',
        ge=0.0,
    )
    fixed_turn: TurnDirection = parameter(
        TurnDirection.RIGHT, 'side turned to at a wall without sound'
    )
    robot_hit_turn: TurnDirection = parameter(
        TurnDirection.RIGHT, 'side of the 90 deg turn after hitting another robot (paper: right)'
    )
    robot_hit_repeat_s: float = parameter(
        4.0,
        'a robot hit this soon after the previous one turns to a random heading',
        unit='s',
        ge=0.0,
    )
    sound_turn_rule: SoundTurnRule = parameter(
        SoundTurnRule.AWAY,
        'wall side from the sound: away (towards theta_opp, paper) or toward the peers',
    )
    sound_wall_side: SoundWallSide = parameter(
        SoundWallSide.EVERY_CONTACT,
        (
            'Sound variant: wall contacts whose side the sound picks: every_contact '
            '(paper), first_contact or never (fixed_turn)'
        ),
    )
    gas_sound_wall_side: SoundWallSide = parameter(
        SoundWallSide.FIRST_CONTACT,
        (
            'Gas+Sound: the same; first_contact (the paper discussion), every_contact '
            '(Table I) or never'
        ),
    )
    sound_side_deadband_rad: float = parameter(
        0.0,
        (
            'Sound variant: theta_opp this close to straight ahead or behind picks no side, '
            'fixed_turn is taken (paper: 0)'
        ),
        unit='deg',
        degrees=True,
        ge=0.0,
        le=90.0,
    )
    gas_sound_side_deadband_rad: float = parameter(
        math.radians(45.0), 'Gas+Sound: the same', unit='deg', degrees=True, ge=0.0, le=90.0
    )
    sound_weighting: SoundWeighting = parameter(
        SoundWeighting.DISTANCE,
        "how the peers' bearings are summed: distance-weighted (paper) or unit vectors",
    )
    sound_memory: SoundMemory = parameter(
        SoundMemory.ONCE,
        "theta_opp is used once (authors' simulator) or stored as the preferred direction "
        '(paper wording)',
    )
    sound_updates_at_corner: bool = parameter(
        True, 'Sound variant updates phi from the bearings at outer corners (paper)'
    )
    pump_on_s: float = parameter(0.5, 'pump burst length', unit='s', ge=0.0)
    pump_period_s: float = parameter(5.0, 'time between pump bursts', unit='s', gt=0.0)
    pump_min_speed_mps: float = parameter(
        0.2,
        'a burst starts only at this forward speed or faster (0: plain clock)',
        unit='m/s',
        ge=0.0,
    )
    bearing_timeout_s: float = parameter(
        1.0, 'bearings older than this are unused', unit='s', ge=0.0
    )
    seed: int = 0
    perception: PerceptionConfig = section(PerceptionConfig, prefix='')
    motion: MotionConfig = section(MotionConfig, prefix='')

    def __post_init__(self) -> None:
        _require(self.robot_count >= 1, f'robot_count must be >= 1, got {self.robot_count}')
        _require(
            0 <= self.robot_index < self.robot_count,
            f'robot_index must be in [0, {self.robot_count - 1}], got {self.robot_index}',
        )
        _require(math.isfinite(self.heading_bias_rad), 'heading_bias_rad must be finite')
        _require(
            0 <= self.gas_threshold <= 1023,
            f'gas_threshold must be on the 10-bit scale 0..1023, got {self.gas_threshold}',
        )
        _require(self.revisit_flip_count >= 1, 'revisit_flip_count must be >= 1')
        for name in (
            'scent_window_s',
            'bearing_timeout_s',
            'robot_hit_repeat_s',
            'wall_end_face_m',
        ):
            value = getattr(self, name)
            _require(math.isfinite(value) and value >= 0.0, f'{name} must be >= 0')
        _require(
            math.isfinite(self.pump_period_s) and self.pump_period_s > 0.0,
            'pump_period_s must be > 0',
        )
        _require(
            math.isfinite(self.pump_on_s) and 0.0 <= self.pump_on_s <= self.pump_period_s,
            f'pump_on_s must be in [0, pump_period_s], got {self.pump_on_s}',
        )
        _require(
            math.isfinite(self.pump_min_speed_mps) and self.pump_min_speed_mps >= 0.0,
            'pump_min_speed_mps must be >= 0',
        )
        for name in ('sound_side_deadband_rad', 'gas_sound_side_deadband_rad'):
            deadband = getattr(self, name)
            _require(
                0.0 <= deadband <= math.pi / 2,
                f'{name.removesuffix("_rad")} must be in [0, 90] deg, '
                f'got {math.degrees(deadband):g} deg',
            )
        _require(self.seed >= 0, 'seed must be >= 0')

    @property
    def active_wall_side(self) -> SoundWallSide:
        """The wall-side rule of the configured sound variant (Gas+Sound's or Sound's)."""
        if self.variant is Variant.GAS_SOUND:
            return self.gas_sound_wall_side
        return self.sound_wall_side

    @property
    def active_side_deadband_rad(self) -> float:
        """The side deadband of the configured sound variant (Gas+Sound's or Sound's) [rad]."""
        if self.variant is Variant.GAS_SOUND:
            return self.gas_sound_side_deadband_rad
        return self.sound_side_deadband_rad
