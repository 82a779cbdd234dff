"""OA-Bug missions without the runtime: the sweep path of the benchmarks.

The ROS path (:func:`swarm_experiments.mission.run_mission`) runs the sim bridge node and one
:class:`oabug_robot.node.OABugNode` per robot on the built-in runtime, and every reading
travels as a message. This module drives the very same parts directly: the
:class:`swarm_sim.engine.SimEngine` and, per robot, the node's own controller
(:class:`oabug_robot.fsm.OABugFsm`) and scan feature extractor, built from the same node
parameters by :data:`oabug_robot.node_settings.OABUG_PARAMETERS`. It reproduces what the
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
from dataclasses import dataclass
from typing import Any

import numpy as np
from oabug_robot.errors import ScanError
from oabug_robot.fsm import Command, OABugFsm, SensorSnapshot
from oabug_robot.node_settings import OABUG_PARAMETERS
from oabug_robot.scan_features import LaserScanData, ScanFeatureExtractor, ScanFeatures
from oabug_robot.scan_features_kernel import extract_many_flat
from oabug_robot.sound import PeerBearings
from swarm_common.angles import yaw_from_quaternion, yaw_to_quaternion
from swarm_common.params import ParameterError
from swarm_common.stamps import NS_PER_S, seconds_to_ns
from swarm_runtime.builtin._messages import cdr_roundtrip_enabled
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry
from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors.bearings import BearingCycle
from swarm_sim.sensors.bearings import PeerBearings as BearingReport
from swarm_sim.sensors.lidar import LidarConfig
from swarm_sim.sensors_kernel import imu_message_yaw_kernel
from swarm_sim.site_geometry import geometry_from_site

from swarm_experiments.mission import MissionProgress, MissionResult, MissionSpec, StopReason
from swarm_experiments.spawn import OABugRun, SpawnSettings, run

__all__ = ['BatchRobot', 'run_oabug_batch', 'run_spawn_batch']

_STOP = Command(linear_mps=0.0, angular_radps=0.0, pump_on=False)


@dataclass
class _Held:
    """The newest reading of one sensor and the node-clock time it arrived [s]."""

    value: Any = None
    time_s: float | None = None


class BatchRobot:
    """One OA-Bug robot as its node runs it, fed with readings instead of messages."""

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
        self.config = settings.controller_config()
        rate_hz = settings.control_rate_hz
        self.stale_timeout_s = settings.stale_timeout_s
        # The node's timer: period in whole nanoseconds, first deadline one period in.
        self.control_period_ns = int(1.0 / rate_hz * NS_PER_S)
        self.next_control_ns = self.control_period_ns
        self.own_tag = settings.own_tag_id.strip().upper()
        self.fsm = OABugFsm(self.config)
        # Robots of one group have equal perception settings (set by the batch runner).
        self.perception_group = 0
        self._extractor = ScanFeatureExtractor(self.config.perception)
        # Fields of the messages: float32 after serialization, else the Python float.
        self._field_type = np.float32 if float32_fields else np.float64
        field = self._field_type
        self._scan_frame = tuple(
            float(field(v))
            for v in (-math.pi, lidar.angle_increment_rad, lidar.range_min_m, lidar.range_max_m)
        )
        self._needs_gas = self.config.variant.uses_scent
        self._scan = _Held()
        self._features: ScanFeatures | None = None
        self._features_time_s: float | None = None
        self._yaw = _Held(math.nan)
        self._gas = _Held()
        self._bearings: PeerBearings | None = None

    @property
    def needs_gas(self) -> bool:
        """The robot's variant reads the gas sensor (it lays scent)."""
        return self._needs_gas

    # Readings, in the order the bridge publishes them within a step.

    def receive_scan(self, ranges_m: np.ndarray, now_s: float) -> None:
        """A lidar revolution arrives: ranges [m] (REP 117) as the message's float32 hold."""
        self._scan.value = LaserScanData(ranges_m, *self._scan_frame)
        self._scan.time_s = now_s

    def receive_gas(self, raw: int, now_s: float) -> None:
        """A gas reading on the 10-bit scale arrives."""
        self._gas.value = int(raw)
        self._gas.time_s = now_s

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
        self.hold_bearings(azimuths[keep].astype(float), distances[keep].astype(float), now_s)

    def own_tag_index(self, tag_ids: Sequence[str]) -> int:
        """Index of the robot's own tag in ``tag_ids``, -1 when it is not there. The node
        drops its own tag (the engine never reports it, a user's id might)."""
        return tag_ids.index(self.own_tag) if self.own_tag in tag_ids else -1

    @property
    def field_type(self) -> type:
        """The type of the messages' float32 fields as received: np.float32 or np.float64."""
        return self._field_type

    def hold_bearings(
        self, azimuths_rad: np.ndarray, distances_m: np.ndarray, now_s: float
    ) -> None:
        """Hold a locator cycle already converted as the message carries it (the own tag
        dropped, float32 fields rounded, then widened); stamped with the yaw held now."""
        yaw = self._yaw.value if math.isfinite(self._yaw.value) else 0.0
        self._bearings = PeerBearings(
            azimuths_rad=azimuths_rad, distances_m=distances_m, stamp_s=now_s, yaw_at_stamp_rad=yaw
        )

    def receive_imu(self, yaw_rad: float, now_s: float) -> None:
        """An IMU reading arrives; its yaw goes through the message's quaternion."""
        self.hold_yaw(yaw_from_quaternion(*yaw_to_quaternion(yaw_rad)), now_s)

    def hold_yaw(self, yaw_rad: float, now_s: float) -> None:
        """Hold an IMU yaw already read back from the message's quaternion
        (:func:`swarm_sim.sensors_kernel.imu_message_yaw_kernel`)."""
        self._yaw.value = yaw_rad
        self._yaw.time_s = now_s

    # The control step.

    def _near_peers(self, now_s: float) -> tuple[np.ndarray, np.ndarray]:
        bearings = self._bearings
        if bearings is None or now_s - bearings.stamp_s > self.config.bearing_timeout_s:
            return np.zeros(0), np.zeros(0)
        return bearings.near_peers_now(
            self._yaw.value, self.config.perception.peer_bearing_max_distance_m
        )

    def pending_scan(self, now_s: float) -> tuple[LaserScanData, int] | None:
        """The held scan that this control step turns into features and the side whose wall
        is wanted; None when there is nothing to do."""
        scan = self._scan.value
        if scan is None or not math.isfinite(self._yaw.value):
            return None
        return scan, self.fsm.memory.wall_side

    def peer_bearings(self, now_s: float) -> tuple[np.ndarray, np.ndarray, float] | None:
        """The bearings the control step at ``now_s`` reads, before the near-peer selection:
        the held azimuths [rad] and distances [m] and the rotation since they were heard
        (``yaw_at_stamp - yaw`` [rad], added to the azimuths as
        :meth:`~oabug_robot.sound.PeerBearings.near_peers_now` does); None when none are
        held or they are older than the bearing timeout."""
        bearings = self._bearings
        if bearings is None or now_s - bearings.stamp_s > self.config.bearing_timeout_s:
            return None
        return (
            bearings.azimuths_rad,
            bearings.distances_m,
            bearings.yaw_at_stamp_rad - self._yaw.value,
        )

    def take_features(self, features: ScanFeatures) -> None:
        """Hold the features of the pending scan (computed for many robots at once)."""
        self._features = features
        self._features_time_s = self._scan.time_s
        self._scan.value = None

    @property
    def extractor(self) -> ScanFeatureExtractor:
        """The robot's scan feature extractor."""
        return self._extractor

    def _update_features(self, now_s: float) -> None:
        scan, scan_time = self._scan.value, self._scan.time_s
        if scan is None:
            return
        self._scan.value = None
        side = self.fsm.memory.wall_side
        try:
            self._features = self._extractor.extract(
                scan, *self._near_peers(now_s), sides=(side,) if side else ()
            )
        except ScanError:
            return
        self._features_time_s = scan_time

    def control(self, now_s: float) -> Command:
        """One control step at node time ``now_s``: the command the node would publish."""
        held_yaw = self._yaw
        if math.isfinite(held_yaw.value) and self._scan.value is not None:
            self._update_features(now_s)
        # Every reading the step reads must be fresh: stamped at most the stale timeout ago.
        timeout = self.stale_timeout_s
        features_s, yaw_s = self._features_time_s, held_yaw.time_s
        if features_s is None or not 0.0 <= now_s - features_s <= timeout:
            return _STOP
        if yaw_s is None or not 0.0 <= now_s - yaw_s <= timeout:
            return _STOP
        if self._needs_gas:
            gas_s = self._gas.time_s
            if gas_s is None or not 0.0 <= now_s - gas_s <= timeout:
                return _STOP
        if self._features is None:
            return _STOP
        snapshot = SensorSnapshot(
            time_s=now_s,
            yaw_rad=held_yaw.value,
            scan=self._features,
            gas_raw=self._gas.value,
            bearings=self._bearings,
        )
        return self.fsm.step(snapshot)


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
        robot.perception_group = perception_groups.setdefault(
            robot.config.perception, len(perception_groups)
        )
    unused = {'odometry'}
    if not any(robot.needs_gas for robot in robots):
        unused.add('gas')
    engine = SimEngine(
        geometry,
        np.asarray(spec.initial_poses, dtype=float),
        dataclasses.replace(engine_config, sensors=engine_config.sensors - unused),
        bearing_cycles=True,
    )
    n = engine.num_robots
    names = tuple(f'r{i}' for i in range(n))
    tag_ids = tuple(name.upper() for name in names)
    # Per robot, its own tag's index (-1: none); the node drops that tag's bearings.
    own_tags = np.array([robot.own_tag_index(tag_ids) for robot in robots], dtype=np.int64)
    times = [0.0]
    poses = [engine.world.poses]
    next_sample_s = spec.trajectory_period_s
    next_report_s = 0.0
    reason = StopReason.BUDGET

    def snapshot() -> MissionProgress:
        return MissionProgress.of_engine(engine, wall_start)

    while True:
        out = engine.step()
        if out.time_s + 1e-9 >= next_sample_s:
            times.append(out.time_s)
            poses.append(out.poses)
            next_sample_s += spec.trajectory_period_s
        if spec.stop_when_all_rooms_covered and engine.coverage.complete:
            reason = StopReason.ALL_ROOMS_COVERED
            break
        if engine.time_s + 1e-9 >= spec.max_sim_time_s:
            reason = StopReason.BUDGET
            break
        if engine.time_s + 1e-9 >= next_report_s:
            next_report_s += spec.progress_period_s
            report = snapshot()
            if progress is not None:
                progress(report)
            if stop is not None and stop(report):
                reason = StopReason.PREDICATE
                break
        _deliver(engine, out, robots, own_tags)

    final = snapshot()
    if progress is not None:
        progress(final)
    if times[-1] < engine.time_s:
        times.append(engine.time_s)
        poses.append(engine.world.poses)
    return MissionResult(
        robot_names=names,
        site=site,
        stop_reason=reason,
        sim_time_s=engine.time_s,
        wall_time_s=final.wall_time_s,
        rooms_total=engine.coverage.rooms_total,
        room_entries=engine.coverage.entries,
        trajectory_times_s=np.array(times),
        trajectories=np.stack(poses),
        distance_travelled_m=engine.distance_travelled_m.copy(),
    )


def _deliver(engine: SimEngine, out: Any, robots: list[BatchRobot], own_tags: np.ndarray) -> None:
    """Hand one step's readings to the robots and apply the commands of those whose
    control timer is due (what the executor does between two bridge ticks). ``own_tags``:
    per robot, the index of its own tag (-1 for none)."""
    now_ns = seconds_to_ns(out.time_s)  # the nodes' clock: the /clock stamp
    now_s = now_ns * 1e-9
    if out.scans is not None:
        # The message's float32 values, widened once for every robot's feature extractor.
        ranges_m = out.scans.astype(np.float32).astype(float)
        for i, (robot, ranges) in enumerate(zip(robots, ranges_m, strict=True)):
            if out.published('scan', i):
                robot.receive_scan(ranges, now_s)
    if out.gas_raw is not None:
        for robot, raw in zip(robots, out.gas_raw.tolist(), strict=True):
            robot.receive_gas(raw, now_s)
    if out.bearing_cycle is not None:
        _deliver_bearings(robots, out.bearing_cycle, own_tags, now_s)
    if out.imu is not None:
        # The quaternion round trip of every robot's message in one call.
        yaws = out.imu[0]
        for robot, yaw, held in zip(
            robots, yaws.tolist(), imu_message_yaw_kernel(yaws).tolist(), strict=True
        ):
            if math.isnan(held):
                robot.receive_imu(yaw, now_s)  # no orientation: raises as the node does
            else:
                robot.hold_yaw(held, now_s)
    due = []
    for i, robot in enumerate(robots):
        if now_ns < robot.next_control_ns:
            continue
        period = robot.control_period_ns
        robot.next_control_ns += period
        if robot.next_control_ns < now_ns:
            behind = now_ns - robot.next_control_ns
            robot.next_control_ns += (1 + (behind - 1) // period) * period
        due.append(i)
    # A robot's control step reads only its own readings and controller, so the scan
    # features of every robot due can be computed first, all at once.
    _extract_features([robots[i] for i in due], now_s)
    velocities: list[tuple[float, float]] = []
    pumps: list[bool] = []
    for i in due:
        robot = robots[i]
        command = robot.control(now_s)
        velocities.append((float(command.linear_mps), float(command.angular_radps)))
        pumps.append(bool(command.pump_on))
    engine.set_commands(due, velocities, pumps)


def _deliver_bearings(
    robots: list[BatchRobot], cycle: BearingCycle, own_tags: np.ndarray, now_s: float
) -> None:
    """:meth:`BatchRobot.receive_bearings` for every robot, each conversion done once for
    all (every robot's messages have the same field types) on the cycle's flat arrays."""
    field = robots[0].field_type
    azimuths = cycle.azimuth_rad.astype(field).astype(float)
    distances = cycle.distance_m.astype(field).astype(float)
    bounds = cycle.bounds
    keep = cycle.tags != own_tags[cycle.receivers]
    if not keep.all():
        # Kept before each report's first entry: the bounds in the filtered arrays.
        bounds = np.concatenate(([0], np.cumsum(keep)))[bounds].tolist()
        azimuths, distances = azimuths[keep], distances[keep]
    for robot, lo, hi in zip(robots, bounds[:-1], bounds[1:], strict=True):
        robot.hold_bearings(azimuths[lo:hi], distances[lo:hi], now_s)


def _extract_features(robots: list[BatchRobot], now_s: float) -> None:
    """Turn the held scans of ``robots`` into features, the robots of one perception
    configuration in one compiled call (:func:`oabug_robot.scan_features_kernel.extract_many`,
    equal to each robot's extractor). A robot whose scan the batch cannot take (a
    :class:`ScanError`) is left to its own extractor in its control step."""
    groups: dict[int, list[tuple[BatchRobot, LaserScanData, int]]] = {}
    for robot in robots:
        pending = robot.pending_scan(now_s)
        if pending is not None:
            groups.setdefault(robot.perception_group, []).append((robot, *pending))
    for members in groups.values():
        extractor = members[0][0].extractor
        scans = [scan for _, scan, _ in members]
        sides = [side for _, _, side in members]
        bearing_start, azimuths, distances = _near_peers(
            [robot.peer_bearings(now_s) for robot, _, _ in members],
            extractor.config.peer_bearing_max_distance_m,
        )
        try:
            features = extract_many_flat(
                extractor, scans, bearing_start, azimuths, distances, sides
            )
        except ScanError:
            continue
        for (robot, _, _), robot_features in zip(members, features, strict=True):
            robot.take_features(robot_features)


def _near_peers(
    held: list[tuple[np.ndarray, np.ndarray, float] | None], max_distance_m: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:meth:`oabug_robot.sound.PeerBearings.near_peers_now` of several robots at once (the
    same element-wise operations): the slice bounds of each robot's near peers, their
    bearings at the robots' current yaws [rad] and their distances [m].

    Args:
        held: per robot, what :meth:`BatchRobot.peer_bearings` returns.
        max_distance_m: peers farther than this (by their known distance) are left out.
    """
    counts = [0 if h is None else len(h[0]) for h in held]
    bounds = np.zeros(len(held) + 1, dtype=np.int64)
    np.cumsum(counts, out=bounds[1:])
    if not bounds[-1]:
        return bounds, np.zeros(0), np.zeros(0)
    present = [h for h in held if h is not None]
    rotation = np.repeat([h[2] for h in present], [len(h[0]) for h in present])
    azimuths = np.concatenate([h[0] for h in present]) + rotation
    distances = np.concatenate([h[1] for h in present])
    near = ~(distances > max_distance_m)  # NaN (unknown) distances are kept
    if not near.all():
        bounds = np.concatenate(([0], np.cumsum(near)))[bounds]
        azimuths, distances = azimuths[near], distances[near]
    return bounds, azimuths, distances


def run_spawn_batch(
    config: SpawnSettings, *, progress: Callable[[MissionProgress], None] | None = None
) -> OABugRun:
    """:func:`swarm_experiments.spawn.run` on the batch path: the same run, plots included.

    Raises:
        ConfigurationError: ``config.record`` is set (the batch path records no bags).
    """
    return run(config, progress=progress, runner=run_oabug_batch)
