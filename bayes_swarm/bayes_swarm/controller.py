"""The per-robot control loop shared by the ROS node and the batch runner (ROS-free).

One :class:`RobotController` is one robot of the Bayes-Swarm-P study, whatever drives it:

* :meth:`~RobotController.on_pose` takes the robot's pose and the time it was received;
* :meth:`~RobotController.on_signal` pairs a signal sample with the latest pose (sample and
  hold) and hands it to the algorithm;
* :meth:`~RobotController.on_peer` / :meth:`~RobotController.on_glowworm_peer` take peers'
  broadcasts;
* :meth:`~RobotController.control` is one tick of the loop: zero velocity while the pose is
  older than ``odom_timeout_s``; the first decision on the first tick with a pose; a new
  decision (and its broadcast) when the waypoint follower reports arrival; otherwise the
  follower's velocity command;
* :meth:`~RobotController.glowworm_broadcast` and :meth:`~RobotController.glowworm_move`
  are the two halves of one Glowworm iteration: the node's own timer runs them back to back,
  the batch runner runs a swarm's first halves and then its second halves (lockstep).

The node (``bayes_swarm.node``) only converts messages to these calls and the returned
records to messages; the batch runner (``swarm_experiments.bayes_batch``) calls the same
methods from its world model. Times are seconds on one clock (ROS time in the node,
simulated time in the batch runner); the mission time of a decision is measured from the
first tick with a pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bayes_swarm.baselines.exhaustive import partition_arena, strip_sweep
from bayes_swarm.baselines.glowworm import GlowwormAgent
from bayes_swarm.baselines.levy import LevyWalk
from bayes_swarm.follower import WaypointFollower
from bayes_swarm.messages import Decision, DecisionKind, PeerUpdate
from bayes_swarm.node_settings import NodeSettings
from bayes_swarm.planner import BayesSwarmPlanner, first_waypoint

__all__ = ['ControlOutput', 'GlowwormBroadcast', 'RobotController', 'robot_seed']


def robot_seed(mission_seed: int, robot_index: int) -> int:
    """The ``seed`` parameter of robot ``robot_index`` in a mission seeded ``mission_seed``."""
    return int(mission_seed) * 1000 + int(robot_index)


@dataclass(frozen=True)
class ControlOutput:
    """What one control tick produced.

    Attributes:
        linear_mps: forward speed command [m/s].
        angular_radps: yaw-rate command [rad/s].
        decision: the decision taken on this tick, if any.
        broadcast: the Bayes-Swarm broadcast that goes with the decision, if any.
        stale: the pose was missing or older than ``odom_timeout_s`` (the command is zero).
    """

    linear_mps: float
    angular_radps: float
    decision: Decision | None = None
    broadcast: PeerUpdate | None = None
    stale: bool = False


@dataclass(frozen=True)
class GlowwormBroadcast:
    """One Glowworm iteration's broadcast: iteration index, position (2,) [m], luciferin."""

    index: int
    position_m: np.ndarray
    luciferin: float


class RobotController:
    """One robot running the algorithm of its :class:`NodeSettings`."""

    def __init__(self, settings: NodeSettings, robot_name: str) -> None:
        self.robot_name = robot_name
        self.settings = settings
        self.follower_config = settings.follower
        self._follower = WaypointFollower(self.follower_config)
        self._pose: tuple[float, float, float] | None = None
        self._pose_time_s = -math.inf
        self._waypoint: np.ndarray | None = None
        self._start_time_s: float | None = None
        self._last_signal: float | None = None
        self.rejected_samples = 0
        self._n_decisions = 0
        self.decisions: list[Decision] = []
        self._planner: BayesSwarmPlanner | None = None
        self._levy: LevyWalk | None = None
        self._sweep: list[np.ndarray] = []
        self._glow: GlowwormAgent | None = None
        # Per peer: its latest Glowworm broadcast as (index, x [m], y [m], luciferin).
        self._glow_peers: dict[str, tuple[int, float, float, float]] = {}
        self._glow_sent: GlowwormBroadcast | None = None
        s = settings
        if s.algorithm in ('bayes_swarm_p', 'bayes_swarm_o'):
            self._planner = BayesSwarmPlanner(
                s.planner,
                robot_name,
                seed=s.seed,
                fan_index=s.fan_index,
                fan_size=s.fan_size,
                direction_offset_deg=s.initial_direction_offset_deg,
            )
        elif s.algorithm == 'levy':
            self._levy = LevyWalk(s.levy, s.planner.arena, seed=s.seed)
        elif s.algorithm == 'glowworm':
            self._glow = GlowwormAgent(
                s.glowworm, s.planner.arena, s.planner.velocity_mps, seed=s.seed
            )

    def configure(self, settings: NodeSettings) -> None:
        """Take changed settings while running (only the follower's take effect)."""
        self.settings = settings
        self.follower_config = settings.follower
        self._follower = WaypointFollower(self.follower_config)

    @property
    def planner(self) -> BayesSwarmPlanner | None:
        """The Bayes-Swarm planner (None for the baselines)."""
        return self._planner

    @property
    def uses_peers(self) -> str | None:
        """'bayes' or 'glowworm' if the algorithm exchanges messages, else None."""
        if self._planner is not None:
            return 'bayes'
        return 'glowworm' if self._glow is not None else None

    @property
    def pose_m(self) -> tuple[float, float]:
        """The latest position (x, y) [m] (NaN before the first pose)."""
        if self._pose is None:
            return (math.nan, math.nan)
        return (self._pose[0], self._pose[1])

    @property
    def waypoint_m(self) -> np.ndarray | None:
        """The current waypoint (2,) [m], None before the first decision."""
        return None if self._waypoint is None else self._waypoint.copy()

    # ----------------------------------------------------------------- inputs
    def on_pose(self, pose: tuple[float, float, float], time_s: float) -> bool:
        """Latest pose (x [m], y [m], yaw [rad]) received at ``time_s``; False if not finite."""
        if not all(math.isfinite(v) for v in pose):
            return False
        self._pose = (float(pose[0]), float(pose[1]), float(pose[2]))
        self._pose_time_s = time_s
        return True

    def on_signal(self, value: float) -> str:
        """A signal sample, paired with the latest pose; '' if kept, else why it was dropped."""
        value = float(value)
        if not math.isfinite(value) or self._pose is None:
            self.rejected_samples += 1
            return 'no pose yet' if self._pose is None else 'not finite'
        if self._planner is not None:
            point = np.array([[self._pose[0], self._pose[1]]])
            if not self._planner.add_observations(point, np.array([value])):
                self.rejected_samples += 1
                return 'implausible magnitude'
        self._last_signal = value
        return ''

    def on_peer(self, update: PeerUpdate) -> bool:
        """A peer's Bayes-Swarm broadcast; False if ignored (own, stale, malformed, not
        Bayes-Swarm; see :meth:`~bayes_swarm.planner.BayesSwarmPlanner.receive`)."""
        if self._planner is None:
            return False
        return self._planner.receive(update)

    def on_glowworm_peer(
        self, sender: str, index: int, position_m: np.ndarray, luciferin: float
    ) -> bool:
        """A peer's Glowworm broadcast, kept if newer than the last one from ``sender``;
        False if ignored (own, older, or a position or luciferin that is not finite: an
        infinite luciferin would make the leader draw's probabilities NaN)."""
        x, y = float(position_m[0]), float(position_m[1])
        luciferin = float(luciferin)
        if not (math.isfinite(x) and math.isfinite(y) and math.isfinite(luciferin)):
            return False
        known = self._glow_peers.get(sender)
        if sender == self.robot_name or (known is not None and index <= known[0]):
            return False
        self._glow_peers[sender] = (index, x, y, luciferin)
        return True

    # ---------------------------------------------------------------- control
    def control(self, time_s: float) -> ControlOutput:
        """One tick of the loop at ``time_s``."""
        if self._pose is None or time_s - self._pose_time_s > self.settings.odom_timeout_s:
            return ControlOutput(0.0, 0.0, stale=True)
        x, y, yaw = self._pose
        position = np.array([x, y])
        decision: Decision | None = None
        broadcast: PeerUpdate | None = None
        waypoint = self._waypoint
        if waypoint is None:
            self._start_time_s = time_s
            decision, broadcast, waypoint = self._decide(time_s, position)
        cmd = self._follower.command(x, y, yaw, *waypoint)
        if cmd.arrived and not self._glowworm_phase() and decision is None:
            decision, broadcast, waypoint = self._decide(time_s, position)
            cmd = self._follower.command(x, y, yaw, *waypoint)
        return ControlOutput(cmd.linear_mps, cmd.angular_radps, decision, broadcast)

    def _glowworm_phase(self) -> bool:
        return self._glow is not None and self._n_decisions > 0

    def _decide(
        self, time_s: float, position: np.ndarray
    ) -> tuple[Decision, PeerUpdate | None, np.ndarray]:
        """Decide the next waypoint at ``position``; returns it with the decision."""
        s = self.settings
        mission_time = time_s - (self._start_time_s if self._start_time_s is not None else time_s)
        broadcast = None
        if self._planner is not None:
            decision = self._planner.decide(position, mission_time)
            broadcast = self._planner.broadcast(position)
        elif self._levy is not None:
            waypoint = self._levy.next_waypoint(position, self._last_signal)
            decision = Decision(waypoint, self._n_decisions, DecisionKind.RANDOM_JUMP)
        elif s.algorithm == 'exhaustive':
            if self._n_decisions == 0:
                strip = partition_arena(
                    s.planner.arena, s.planner.n_robots, s.exhaustive.partition
                )[s.planner.robot_index]
                spacing = s.exhaustive.spacing_m(s.planner.detection_radius_m)
                self._sweep = list(strip_sweep(strip, spacing, position))
            waypoint = self._sweep.pop(0) if self._sweep else position
            decision = Decision(waypoint, self._n_decisions, DecisionKind.ACQUISITION)
        else:
            waypoint = s.planner.arena.clip(
                first_waypoint(
                    position,
                    fan_index=s.fan_index or s.planner.robot_index + 1,
                    fan_size=s.fan_size or s.planner.n_robots,
                    direction_range_deg=s.planner.initial_direction_range_deg,
                    direction_offset_deg=s.initial_direction_offset_deg,
                    leg_m=s.planner.max_leg_m,
                )
            )
            decision = Decision(waypoint, 0, DecisionKind.FIRST)
        self._n_decisions += 1
        waypoint = np.asarray(decision.waypoint_m, dtype=float)
        self._waypoint = waypoint
        self.decisions.append(decision)
        return decision, broadcast, waypoint

    def glowworm_broadcast(self) -> GlowwormBroadcast | None:
        """First half of a Glowworm iteration: the luciferin from the latest sample and the
        broadcast that carries it. None when the robot does not iterate (not Glowworm, no pose
        or sample yet, or still on its first dispersal leg)."""
        if self._glow is None or self._pose is None or self._waypoint is None:
            return None
        x, y = self._pose[0], self._pose[1]
        follower = self.follower_config
        if self._n_decisions == 1 and math.hypot(self._waypoint[0] - x, self._waypoint[1] - y) > (
            follower.arrival_tolerance_m
        ):
            return None  # still on the first dispersal leg
        if self._last_signal is None:
            return None
        luciferin = self._glow.update_luciferin(self._last_signal)
        self._glow_sent = GlowwormBroadcast(self._n_decisions, np.array([x, y]), luciferin)
        return self._glow_sent

    def glowworm_move(self) -> np.ndarray | None:
        """Second half: the leader among the peers' latest broadcasts and the waypoint toward
        it, from where the robot broadcast. Returns the new waypoint (2,) [m]; None without a
        broadcast since the last move."""
        sent, self._glow_sent = self._glow_sent, None
        if sent is None or self._glow is None:
            return None
        position = sent.position_m
        x, y = float(position[0]), float(position[1])
        peers = [peer[1:] for peer in self._glow_peers.values()]
        target = self._glow.next_waypoint(position, peers)
        dx, dy = float(target[0]) - x, float(target[1]) - y
        length = math.hypot(dx, dy)
        if length <= 0.0:
            self._waypoint = position.copy()  # no brighter neighbour: stay
        else:
            # A GSO step (mm at 100 Hz) is below the follower's arrival tolerance: steer toward
            # a point a few control periods ahead on the same heading, so the robot moves at V.
            follower = self.follower_config
            lookahead = max(
                2.0 * follower.arrival_tolerance_m,
                2.0 * follower.speed_mps / self.settings.control_rate_hz,
            )
            scale = lookahead / length
            arena = self.settings.planner.arena
            self._waypoint = np.array(
                [
                    min(max(x + dx * scale, arena.x_min_m), arena.x_max_m),
                    min(max(y + dy * scale, arena.y_min_m), arena.y_max_m),
                ]
            )
        self._n_decisions += 1
        return self._waypoint.copy()
