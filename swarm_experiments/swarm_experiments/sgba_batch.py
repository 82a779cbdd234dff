"""SGBA missions: the spawn settings, the mission spec (node path) and the batch path.

:func:`build_sgba_mission` places the robots as the OA-Bug spawner does (same sites, same
departure fan and seeded bias) and gives each one an :class:`oabug_robot.sgba.node.SgbaNode`;
:func:`swarm_experiments.mission.run_mission` runs that spec on the ROS path.
:func:`run_sgba_batch` runs the same spec without the runtime for sweeps: it steps the world
and drives each robot's :class:`oabug_robot.sgba.loop.SgbaLoop` (the node's own loop) with
the readings the bridge would publish, in its order (scan, bearings stamped with the yaw held
before this step's IMU, IMU through the quaternion, odometry), the control step on the node's
timer grid, and the float32 message fields rounded as serialization does (when the built-in
runtime's CDR round trip is on, as for OA-Bug's batch path). It records no bags.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from oabug_robot.robot_loop import ControlTimer
from oabug_robot.scan_features import LaserScanData
from oabug_robot.sgba.loop import SgbaLoop
from oabug_robot.sgba.settings import SGBA_PARAMETERS
from swarm_common.params import ParameterError
from swarm_common.stamps import seconds_to_ns
from swarm_runtime.builtin._messages import cdr_roundtrip_enabled
from swarm_sim.departure import place_starts
from swarm_sim.engine import EngineConfig, SimEngine, SiteGeometry
from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors.lidar import LidarConfig
from swarm_sim.sensors_kernel import imu_message_yaw_kernel
from swarm_sim.site_geometry import geometry_from_site
from swarm_sim.site_loading import load_site

from swarm_experiments.mission import (
    MissionProgress,
    MissionResult,
    MissionSpec,
    RobotNodeSpec,
)
from swarm_experiments.oabug_batch import run_site_loop
from swarm_experiments.spawn import SiteBudget

__all__ = ['SgbaSettings', 'build_sgba_mission', 'run_sgba', 'run_sgba_batch']

#: SGBA node parameters the mission sets from its own settings.
MISSION_PARAMETERS = (
    'robot_index',
    'robot_count',
    'departure',
    'heading_bias_deg',
    'forward_speed_mps',
    'own_tag_id',
)


@dataclass(frozen=True)
class SgbaSettings(SiteBudget):
    """One SGBA run (the OA-Bug spawner's settings that apply).

    Attributes:
        site: 'small' / 'medium' / 'big' (generated from ``site_seed``) or a site file.
        site_seed: seed of the generated site.
        robots: number of robots.
        departure: the site's departure point ('center' or 'edge').
        seed: seed of the run (world noise and the fan's bias).
        actions: max actions (0.1 m) per robot; None: the site's Table II budget.
        speed_mps: cruise speed [m/s].
        robot_parameters: SGBA node parameters for every robot.
        engine: world configuration (its seed is replaced by ``seed``).
    """

    site: str = 'small'
    site_seed: int = 0
    robots: int = 10
    departure: str = 'center'
    seed: int = 0
    actions: int | None = None
    speed_mps: float = 0.3
    robot_parameters: Mapping[str, object] = field(default_factory=dict)
    engine: EngineConfig = field(default_factory=EngineConfig)

    def __post_init__(self) -> None:
        if self.robots < 1:
            raise ConfigurationError(f'robots must be >= 1, got {self.robots}')
        if not (math.isfinite(self.speed_mps) and self.speed_mps > 0.0):
            raise ConfigurationError(f'speed_mps must be positive and finite, got {self.speed_mps}')
        reserved = sorted(set(self.robot_parameters) & set(MISSION_PARAMETERS))
        if reserved:
            msg = f'set by the mission, not as robot parameters: {", ".join(reserved)}'
            raise ConfigurationError(msg)


def _sgba_factory() -> Callable[..., object]:
    from oabug_robot.sgba.node import SgbaNode

    return SgbaNode


def build_sgba_mission(settings: SgbaSettings) -> tuple[MissionSpec, float]:
    """The mission spec of ``settings`` (one SGBA node per robot) and the fan's bias [rad].

    Raises:
        ConfigurationError: an unknown site or departure point, or too many robots for it.
        swarm_sim.sites.SiteError: the site is invalid.
    """
    site = load_site(settings.site, seed=settings.site_seed)
    starts = place_starts(
        site, settings.departure, settings.robots, seed=settings.seed, body=settings.engine.body
    )
    factory = _sgba_factory()
    robots = []
    for i in range(settings.robots):
        params: dict[str, object] = {
            'robot_index': i,
            'robot_count': settings.robots,
            'departure': starts.fan,
            'heading_bias_deg': math.degrees(starts.bias_rad),
            'forward_speed_mps': float(settings.speed_mps),
            'own_tag_id': f'R{i}',
        }
        params.update(settings.robot_parameters)
        robots.append(RobotNodeSpec(factory, params))
    spec = MissionSpec(
        site=site,
        initial_poses=starts.poses,
        robots=robots,
        max_sim_time_s=settings.budget_s,
        engine_config=dataclasses.replace(settings.engine, seed=int(settings.seed)),
        progress_period_s=min(10.0, max(1.0, settings.budget_s / 100.0)),
    )
    return spec, starts.bias_rad


class SgbaBatchRobot:
    """One SGBA robot as its node runs it, fed with readings instead of messages."""

    def __init__(
        self, parameters: Mapping[str, Any], lidar: LidarConfig, *, float32_fields: bool
    ) -> None:
        """Build the robot from SGBA node parameters.

        Raises:
            ConfigurationError: a name that is not an SGBA node parameter.
            oabug_robot.errors.ConfigError: a parameter value is invalid.
        """
        try:
            settings = SGBA_PARAMETERS.build(
                {k: v for k, v in parameters.items() if k != 'use_sim_time'}
            )
        except ParameterError as err:
            if err.unknown:
                raise ConfigurationError(str(err)) from err
            raise
        self.loop: SgbaLoop[LaserScanData] = SgbaLoop(settings)
        self.timer = ControlTimer(self.loop.control_period_s)
        self.field_type = np.float32 if float32_fields else np.float64
        f = self.field_type
        self.scan_frame = tuple(
            float(f(v))
            for v in (-math.pi, lidar.angle_increment_rad, lidar.range_min_m, lidar.range_max_m)
        )


def run_sgba_batch(
    spec: MissionSpec,
    *,
    progress: Callable[[MissionProgress], None] | None = None,
    float32_fields: bool | None = None,
) -> MissionResult:
    """Run an SGBA mission spec without the runtime (see the module docstring).

    Raises:
        ConfigurationError: the spec asks for a bag, extensions or bridge parameters, or a
            robot parameter is unknown.
    """
    if spec.recording is not None or spec.extensions or spec.bridge_parameters:
        raise ConfigurationError('the SGBA batch path runs no bags, extensions or bridge options')
    wall_start = time.perf_counter()
    site = spec.site
    geometry = site if isinstance(site, SiteGeometry) else geometry_from_site(site)
    config = spec.engine_config or EngineConfig()
    if float32_fields is None:
        float32_fields = cdr_roundtrip_enabled()
    robots = [
        SgbaBatchRobot(robot.parameters, config.lidar, float32_fields=float32_fields)
        for robot in spec.robots
    ]
    engine = SimEngine(
        geometry,
        np.asarray(spec.initial_poses, dtype=float),
        dataclasses.replace(config, sensors=config.sensors - {'gas'}),
        bearing_cycles=True,
    )
    names = tuple(f'r{i}' for i in range(engine.num_robots))
    tags = [name.upper() for name in names]
    return run_site_loop(
        engine,
        spec,
        lambda out: _deliver(engine, out, robots, tags),
        names=names,
        wall_start=wall_start,
        progress=progress,
    )


def _deliver(engine: SimEngine, out: Any, robots: list[SgbaBatchRobot], tags: list[str]) -> None:
    """Hand one step's readings to the robots, in the bridge's order, and apply the
    commands of those whose control timer is due."""
    now_ns = seconds_to_ns(out.time_s)
    now_s = now_ns * 1e-9
    if out.scans is not None:
        ranges_m = out.scans.astype(np.float32).astype(float)
        for i, robot in enumerate(robots):
            if out.published('scan', i):
                robot.loop.hold_scan(LaserScanData(ranges_m[i], *robot.scan_frame), now_s)
    cycle = out.bearing_cycle
    if cycle is not None:
        field_type = robots[0].field_type
        azimuths = cycle.azimuth_rad.astype(field_type).astype(float)
        distances = cycle.distance_m.astype(field_type).astype(float)
        for i, robot in enumerate(robots):
            lo, hi = cycle.bounds[i], cycle.bounds[i + 1]
            heard = [tags[int(t)] for t in cycle.tags[lo:hi]]
            robot.loop.hold_peers(heard, azimuths[lo:hi], distances[lo:hi], now_s)
    if out.imu is not None:
        yaws = out.imu[0]
        for i, (robot, held) in enumerate(
            zip(robots, imu_message_yaw_kernel(yaws).tolist(), strict=True)
        ):
            # A message without orientation gives no yaw: the node drops it (yaw_from_imu).
            if out.published('imu', i) and not math.isnan(held):
                robot.loop.hold_yaw(held, now_s)
    if out.odometry is not None:
        odom_poses = out.odometry[0]
        for robot, pose in zip(robots, odom_poses.tolist(), strict=True):
            robot.loop.hold_position(pose[0], pose[1], now_s)
    due = [i for i, robot in enumerate(robots) if robot.timer.due(now_ns)]
    velocities = []
    for i in due:
        command = robots[i].loop.control(now_s).command
        velocities.append((float(command.linear_mps), float(command.angular_radps)))
    engine.set_commands(due, velocities, [False] * len(due))


def run_sgba(
    settings: SgbaSettings,
    *,
    runner: Callable[..., MissionResult] = run_sgba_batch,
    progress: Callable[[MissionProgress], None] | None = None,
) -> MissionResult:
    """Build and run one SGBA mission (``runner``: this batch path or
    :func:`swarm_experiments.mission.run_mission`)."""
    spec, _ = build_sgba_mission(settings)
    return runner(spec, progress=progress)
