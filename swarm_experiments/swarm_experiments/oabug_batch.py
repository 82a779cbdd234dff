"""OA-Bug missions without the runtime: the sweep path of the benchmarks.

The ROS path (:func:`swarm_experiments.mission.run_mission`) runs the sim bridge node and one
:class:`oabug_robot.node.OABugNode` per robot on the built-in runtime, and every reading
travels as a message. This module steps the world (:class:`swarm_sim.engine.SimEngine`)
and drives, per robot, the node's own control loop (:class:`oabug_robot.robot_loop.RobotLoop`:
sample and hold, staleness, scan features, controller step), built from the same node
parameters by :data:`oabug_robot.node_settings.OABUG_PARAMETERS`. What it adds is what the
messages and the executor do to the data, so a batch run's trajectories and first room
entries equal the ROS path's (tested):

* per physics step the engine steps, then every reading due is handed over in the bridge's
  publish order (scan, gas, bearings, IMU): the bearings are stamped with the yaw of the
  *previous* IMU reading, as the node receives them before this step's IMU message;
* a robot keeps the newest reading of each sensor (sample and hold), stamped with the sim
  time the node's clock reads (the ``/clock`` stamp, rounded to the nanosecond);
* the control step runs on the node's timer grid (``control_rate_hz`` on sim time), after
  every reading of that step, and reads the scan features, the staleness and the near peers
  exactly as :class:`~oabug_robot.node.OABugNode` does; a robot with stale inputs gets a zero
  command and the pump off;
* scan ranges pass through float32 as in ``LaserScan.ranges``, the IMU yaw through the
  quaternion of ``sensor_msgs/Imu``. The other float32 fields (scan angles and limits,
  bearing azimuths and distances) are rounded to float32 when messages are serialized: by
  DDS on a robot, and in the built-in runtime with its CDR round trip
  (``SWARM_RUNTIME_CDR_ROUNDTRIP=1``, which the test suite sets). The batch path follows
  that setting unless told otherwise (``float32_fields``), since the rounding changes
  trajectories after a few seconds.

It does not record bags, publish state messages, or support bridge extensions or the peer
relay (OA-Bug uses neither): it is for sweeps. The ROS path stays the product.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
from oabug_robot.fsm import Command
from oabug_robot.node_settings import OABUG_PARAMETERS
from oabug_robot.robot_loop import ControlTimer, RobotLoop, extract_features
from oabug_robot.scan_features import LaserScanData
from swarm_common.angles import yaw_from_quaternion, yaw_to_quaternion
from swarm_common.params import ParameterError
from swarm_common.stamps import seconds_to_ns
from swarm_runtime.builtin._messages import cdr_roundtrip_enabled
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry, StepOutput
from swarm_sim.errors import ConfigurationError
from swarm_sim.mission_rules import TIME_TOLERANCE_S, TrajectorySampler, end_reason
from swarm_sim.sensors.bearings import BearingCycle
from swarm_sim.sensors.bearings import PeerBearings as BearingReport
from swarm_sim.sensors.lidar import LidarConfig
from swarm_sim.sensors_kernel import imu_message_yaw_kernel
from swarm_sim.site_geometry import geometry_from_site

from swarm_experiments.mission import MissionProgress, MissionResult, MissionSpec, StopReason
from swarm_experiments.spawn import OABugRun, SpawnSettings, run

__all__ = ['BatchRobot', 'BatchSwarm', 'run_oabug_batch', 'run_spawn_batch']

# Scan ranges this far beyond every robot's feature range [m] read inf on the batch path.
_SCAN_HORIZON_MARGIN_M = 1e-3


class BatchRobot:
    """One OA-Bug robot as its node runs it, fed with readings instead of messages.

    The control loop is the node's own (:class:`oabug_robot.robot_loop.RobotLoop`); this
    class only does to the readings what the messages do (float32 fields, the IMU
    quaternion, the own tag dropped) and keeps the node's control timer.
    """

    def __init__(
        self, parameters: Mapping[str, Any], lidar: LidarConfig, *, float32_fields: bool = False
    ) -> None:
        """Build the robot from OA-Bug node parameters (missing ones take their defaults).

        Args:
            parameters: node parameter overrides, as the spawner passes them.
            lidar: the simulated lidar (the scan message's angles and limits).
            float32_fields: round the float32 scalar message fields as serialization does.

        Raises:
            oabug_robot.errors.ConfigError: a parameter value is invalid.
            ConfigurationError: a name that is not an OA-Bug node parameter.
        """
        try:
            settings = OABUG_PARAMETERS.build(
                {k: v for k, v in parameters.items() if k != 'use_sim_time'}
            )
        except ParameterError as err:
            if err.unknown:
                raise ConfigurationError(str(err)) from err
            raise
        self.loop: RobotLoop[LaserScanData] = RobotLoop(settings)
        self.config = self.loop.config
        self.fsm = self.loop.fsm
        self.stale_timeout_s = settings.stale_timeout_s
        # The node's timer on sim time.
        self.timer = ControlTimer(self.loop.control_period_s)
        self.own_tag = settings.own_tag_id.strip().upper()
        # Fields of the messages: float32 after serialization, else the Python float.
        self._field_type = np.float32 if float32_fields else np.float64
        field = self._field_type
        self._scan_frame = tuple(
            float(field(v))
            for v in (-math.pi, lidar.angle_increment_rad, lidar.range_min_m, lidar.range_max_m)
        )

    @property
    def needs_gas(self) -> bool:
        """The robot's variant reads the gas sensor (it lays scent)."""
        return self.loop.needs_gas

    # Readings, in the order the bridge publishes them within a step.

    def receive_scan(self, ranges_m: np.ndarray, now_s: float) -> None:
        """A lidar revolution arrives: ranges [m] (REP 117) as the message's float32 hold."""
        self.loop.hold_scan(LaserScanData(ranges_m, *self._scan_frame), now_s)

    def receive_gas(self, raw: int, now_s: float) -> None:
        """A gas reading on the 10-bit scale arrives."""
        self.loop.hold_gas(int(raw), now_s)

    def receive_bearings(self, report: BearingReport, tag_ids: Sequence[str], now_s: float) -> None:
        """A locator cycle arrives; stamped with the yaw held now (the previous IMU).

        Args:
            report: the locator's report; its tags index ``tag_ids``.
            tag_ids: the tag id of every robot.
            now_s: node time [s].
        """
        azimuths = np.asarray(report.azimuth_rad, dtype=self._field_type)
        distances = np.asarray(report.distance_m, dtype=self._field_type)
        keep = report.tags != self.own_tag_index(tag_ids)
        self.loop.hold_bearings(azimuths[keep].astype(float), distances[keep].astype(float), now_s)

    def own_tag_index(self, tag_ids: Sequence[str]) -> int:
        """Index of the robot's own tag in ``tag_ids``, -1 when it is not there. The node
        drops its own tag (the engine never reports it, a user's id might)."""
        return tag_ids.index(self.own_tag) if self.own_tag in tag_ids else -1

    @property
    def scan_frame(self) -> tuple[float, ...]:
        """The scan message's angle_min, angle_increment, range_min and range_max as the
        robot receives them (the same for every robot of a mission: one lidar model)."""
        return self._scan_frame

    @property
    def field_type(self) -> type:
        """The type of the messages' float32 fields as received: np.float32 or np.float64."""
        return self._field_type

    def receive_imu(self, yaw_rad: float, now_s: float) -> None:
        """An IMU reading arrives; its yaw goes through the message's quaternion."""
        self.loop.hold_yaw(yaw_from_quaternion(*yaw_to_quaternion(yaw_rad)), now_s)

    def control(self, now_s: float) -> Command:
        """One control step at node time ``now_s``: the command the node would publish."""
        return self.loop.control(now_s).command


def _check_spec(spec: MissionSpec) -> None:
    if spec.recording is not None:
        raise ConfigurationError('the batch path records no bags: use the ROS path')
    if spec.extensions or spec.bridge_parameters:
        raise ConfigurationError(
            'the batch path runs OA-Bug only: no bridge extensions or bridge parameters'
        )


def run_oabug_batch(
    spec: MissionSpec,
    *,
    progress: Callable[[MissionProgress], None] | None = None,
    stop: Callable[[MissionProgress], bool] | None = None,
    float32_fields: bool | None = None,
) -> MissionResult:
    """Run an OA-Bug mission (one node parameter set per robot) without the runtime.

    ``spec`` is what :func:`swarm_experiments.spawn.build_mission` builds for the ROS path; the
    robots' node factories are not called, their parameters configure the controllers. The
    stop conditions, progress reports and trajectory samples are those of
    :func:`swarm_experiments.mission.run_mission`. ``float32_fields`` rounds the float32 scalar
    fields of the messages as serialization does; None follows the built-in runtime's CDR
    round-trip setting, so the result equals the ROS path's in the same process.

    Raises:
        ConfigurationError: the spec asks for a bag, extensions or bridge parameters, or a
            robot parameter is unknown.
        oabug_robot.errors.ConfigError: a robot parameter value is invalid.
    """
    _check_spec(spec)
    wall_start = time.perf_counter()
    site = spec.site
    geometry = site if isinstance(site, SiteGeometry) else geometry_from_site(site)
    # The OA-Bug node subscribes to no odometry, and to no gas when its variant lays no
    # scent; every other reading is consumed.
    engine_config = spec.engine_config or EngineConfig()
    if float32_fields is None:
        float32_fields = cdr_roundtrip_enabled()
    robots = [
        BatchRobot(robot.parameters, engine_config.lidar, float32_fields=float32_fields)
        for robot in spec.robots
    ]
    # Robots with equal perception settings share one compiled feature call per step.
    perception_groups: dict[Any, int] = {}
    for robot in robots:
        robot.loop.perception_group = perception_groups.setdefault(
            robot.config.perception, len(perception_groups)
        )
    unused = {'odometry'}
    if not any(robot.needs_gas for robot in robots):
        unused.add('gas')
    # No feature reads a range beyond the robots' feature range: the engine may read the
    # farther ones as inf (the margin is far beyond the float32 rounding of a range).
    horizon_m = max(robot.loop.extractor.feature_range_m for robot in robots)
    engine = SimEngine(
        geometry,
        np.asarray(spec.initial_poses, dtype=float),
        dataclasses.replace(engine_config, sensors=engine_config.sensors - unused),
        bearing_cycles=True,
        scan_horizon_m=horizon_m + _SCAN_HORIZON_MARGIN_M,
    )
    names = tuple(f'r{i}' for i in range(engine.num_robots))
    swarm = BatchSwarm(robots, tuple(name.upper() for name in names))
    return run_site_loop(
        engine,
        spec,
        lambda out: _deliver(engine, out, swarm),
        names=names,
        wall_start=wall_start,
        progress=progress,
        stop=stop,
    )


def run_site_loop(
    engine: SimEngine,
    spec: MissionSpec,
    deliver: Callable[[StepOutput], None],
    *,
    names: tuple[str, ...],
    wall_start: float,
    progress: Callable[[MissionProgress], None] | None = None,
    stop: Callable[[MissionProgress], bool] | None = None,
) -> MissionResult:
    """Step ``engine`` through ``spec``'s mission, handing each step's output to ``deliver``,
    and close it; the batch paths' (OA-Bug, SGBA) mission loop.

    The stop conditions (every room covered if the spec asks, the time budget, ``stop`` on a
    progress report), the progress reports and the trajectory samples are those of
    :func:`swarm_experiments.mission.run_mission`; the step that ends the mission is not
    delivered.
    """
    trajectory = TrajectorySampler.starting_at(engine.world.poses, spec.trajectory_period_s)
    next_report_s = 0.0
    reports = progress is not None or stop is not None
    while True:
        out = engine.step()
        trajectory.offer(out.time_s, out.poses)
        reason = end_reason(
            engine,
            stop_when_all_rooms_covered=spec.stop_when_all_rooms_covered,
            max_sim_time_s=spec.max_sim_time_s,
        )
        if reason:
            break
        if reports and engine.time_s + TIME_TOLERANCE_S >= next_report_s:
            next_report_s += spec.progress_period_s
            report = MissionProgress.of_engine(engine, wall_start)
            if progress is not None:
                progress(report)
            if stop is not None and stop(report):
                reason = StopReason.PREDICATE
                break
        deliver(out)

    # Release the physics backend (a pybullet client; a recorded run's animation is written).
    engine.close()
    final = MissionProgress.of_engine(engine, wall_start)
    if progress is not None:
        progress(final)
    return MissionResult.of_engine(
        engine,
        robot_names=names,
        site=spec.site,
        stop_reason=reason,
        wall_time_s=final.wall_time_s,
        times=trajectory.times_s,
        poses=trajectory.poses,
    )


class BatchSwarm:
    """The robots of a batch mission and what handing them their readings needs, worked out
    once: the loops, each robot's own tag and the control timers.

    Robots whose control timers have the same period fire at the same steps (the same
    deadlines from the same start), so one timer per period decides for all of them.
    """

    def __init__(self, robots: Sequence[BatchRobot], tag_ids: Sequence[str]) -> None:
        """Take the robots (in engine order) and the tag id of every robot (``R0``, ...)."""
        self.robots = list(robots)
        self.loops = [robot.loop for robot in self.robots]
        #: Per robot, its own tag's index (-1: none); the node drops that tag's bearings.
        self.own_tags = np.array(
            [robot.own_tag_index(tuple(tag_ids)) for robot in self.robots], dtype=np.int64
        )
        by_period: dict[int, list[int]] = {}
        for i, robot in enumerate(self.robots):
            by_period.setdefault(robot.timer.period_ns, []).append(i)
        self._timers = [(self.robots[members[0]].timer, members) for members in by_period.values()]
        frames = {robot.scan_frame for robot in self.robots}
        #: The scan frame every robot receives, None when they differ.
        self.scan_frame = frames.pop() if len(frames) == 1 else None

    def due(self, now_ns: int) -> list[int]:
        """The robots whose control step runs at ``now_ns``, in index order."""
        if len(self._timers) == 1:
            timer, members = self._timers[0]
            return members if timer.due(now_ns) else []
        return sorted(i for timer, members in self._timers if timer.due(now_ns) for i in members)


def _deliver(engine: SimEngine, out: Any, swarm: BatchSwarm) -> None:
    """Hand one step's readings to the robots and apply the commands of those whose
    control timer is due (what the executor does between two bridge ticks)."""
    now_ns = seconds_to_ns(out.time_s)  # the nodes' clock: the /clock stamp
    now_s = now_ns * 1e-9
    robots, loops = swarm.robots, swarm.loops
    if out.scans is not None:
        # The message's float32 values, widened once for every robot's feature extractor.
        ranges_m = out.scans.astype(np.float32).astype(float)
        withheld = out.withheld.get('scan')
        frame = swarm.scan_frame
        if withheld is None and frame is not None:
            # receive_scan of every robot, the scan built here (one call less per robot).
            for loop, ranges in zip(loops, ranges_m, strict=True):
                loop.hold_scan(LaserScanData(ranges, *frame), now_s)
        else:
            for i, (robot, ranges) in enumerate(zip(robots, ranges_m, strict=True)):
                if withheld is None or not withheld[i]:
                    robot.receive_scan(ranges, now_s)
    if out.gas_raw is not None:
        # The int64 readings as Python ints (what receive_gas makes of them), held directly.
        for loop, raw in zip(loops, out.gas_raw.tolist(), strict=True):
            loop.hold_gas(raw, now_s)
    if out.bearing_cycle is not None:
        _deliver_bearings(robots, out.bearing_cycle, swarm.own_tags, now_s)
    if out.imu is not None:
        # The quaternion round trip of every robot's message in one call.
        yaws = out.imu[0]
        for robot, yaw, held in zip(
            robots, yaws.tolist(), imu_message_yaw_kernel(yaws).tolist(), strict=True
        ):
            if math.isnan(held):
                robot.receive_imu(yaw, now_s)  # no orientation: raises as the node does
            else:
                robot.loop.hold_yaw(held, now_s)
    due = swarm.due(now_ns)
    if not due:
        return
    # A robot's control step reads only its own readings and controller, so the scan
    # features of every robot due can be computed first, all at once.
    due_loops = loops if len(due) == len(loops) else [loops[i] for i in due]
    extract_features(due_loops, now_s)
    commands = [loop.command(now_s) for loop in due_loops]
    engine.set_commands(
        due,
        [(command.linear_mps, command.angular_radps) for command in commands],
        [command.pump_on for command in commands],
    )


def _deliver_bearings(
    robots: list[BatchRobot], cycle: BearingCycle, own_tags: np.ndarray, now_s: float
) -> None:
    """:meth:`BatchRobot.receive_bearings` for every robot, each conversion done once for
    all (every robot's messages have the same field types) on the cycle's flat arrays."""
    field = robots[0].field_type
    if field is np.float64:  # one copy of the float64 values (rounding them is a no-op)
        azimuths = cycle.azimuth_rad.astype(float)
        distances = cycle.distance_m.astype(float)
    else:
        azimuths = cycle.azimuth_rad.astype(field).astype(float)
        distances = cycle.distance_m.astype(field).astype(float)
    bounds = cycle.bounds
    keep = cycle.tags != own_tags[cycle.receivers]
    if np.count_nonzero(keep) < keep.size:  # not keep.all(), a cheaper call
        # Kept before each report's first entry: the bounds in the filtered arrays.
        bounds = np.concatenate(([0], np.cumsum(keep)))[bounds].tolist()
        azimuths, distances = azimuths[keep], distances[keep]
    for robot, lo, hi in zip(robots, bounds[:-1], bounds[1:], strict=True):
        robot.loop.hold_bearings(azimuths[lo:hi], distances[lo:hi], now_s)


def run_spawn_batch(
    config: SpawnSettings, *, progress: Callable[[MissionProgress], None] | None = None
) -> OABugRun:
    """:func:`swarm_experiments.spawn.run` on the batch path: the same run, plots included.

    Raises:
        ConfigurationError: ``config.record`` is set (the batch path records no bags).
    """
    return run(config, progress=progress, runner=run_oabug_batch)
