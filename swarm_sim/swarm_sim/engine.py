"""The simulation engine behind the bridge node: world, sensor models, actuators, schedule.

ROS-free and deterministic from one seed. The bridge node feeds it commands as they arrive
(:meth:`SimEngine.set_velocity_command`, :meth:`SimEngine.set_pump`), calls
:meth:`SimEngine.step` once per physics period and publishes whatever the returned
:class:`StepOutput` holds. Each sensor runs at its own rate; a reading is produced at the
first physics step at or after its due time, so rates that are not divisors of the physics
rate keep their average.

Actuators fail safe: a robot whose last velocity command is older than
``cmd_vel_timeout_s`` stops, like a base driver's watchdog, and a pump whose last "on"
command is older than ``pump_timeout_s`` switches off.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from swarm_common.params import parameter, section

from swarm_sim.errors import ConfigurationError, WorldGeometryError
from swarm_sim.faults import FaultConfig, FaultInjector, FaultPlan
from swarm_sim.ground_truth import CoverageTracker, RoomEntry
from swarm_sim.physics import (
    PHYSICS_BACKENDS,
    PhysicsBackend,
    PhysicsSetup,
    PybulletConfig,
    RenderConfig,
    make_physics,
)
from swarm_sim.sensor_profiles import AoaRealism, AoaRealismConfig
from swarm_sim.sensors.bearings import BearingConfig, BearingCycle, BearingModel, PeerBearings
from swarm_sim.sensors.gas_sensor import GasSensorConfig, Mp503Model
from swarm_sim.sensors.imu import GyroYawModel, ImuConfig
from swarm_sim.sensors.lidar import LidarConfig, LidarModel
from swarm_sim.sensors.odometry import OdometryConfig, WheelOdometry
from swarm_sim.sensors.scent import PumpDepositor, ScentConfig, ScentField
from swarm_sim.sensors_kernel import yaw_change_kernel
from swarm_sim.world import BodyConfig
from swarm_sim.world_kernel import actuators_kernel, body_points_kernel

__all__ = ['SENSORS', 'EngineConfig', 'SimEngine', 'SiteGeometry', 'StepOutput']

# The per-robot sensors the engine can simulate (the bridge's sensor topics): lidar scan, gas
# (the MP503 over the scent field), AoA bearings of peers, IMU yaw, wheel odometry.
SENSORS = frozenset({'scan', 'gas', 'bearings', 'imu', 'odometry'})


@dataclass(frozen=True)
class SiteGeometry:
    """What the engine needs of a site.

    Attributes:
        walls: (M, 2, 2) wall centre lines [m] (the entrance closed).
        room_rects: per room, a (Ki, 4) array of interior rectangles x_min, y_min, x_max,
            y_max [m]; the room order is the room index of coverage messages.
        name: a label for logs and plots.
        room_index_at: optional (N, 2) points -> (N,) room index lookup (-1 outside) for rooms
            that are not unions of rectangles.
    """

    walls: np.ndarray
    room_rects: tuple[np.ndarray, ...] | np.ndarray
    name: str = 'site'
    room_index_at: Callable[[np.ndarray], np.ndarray] | None = None


@dataclass(frozen=True)
class EngineConfig:
    """Configuration of the whole simulated world (see each part's docstring for units).

    Attributes:
        physics_rate_hz: physics steps per second of sim time.
        cmd_vel_timeout_s: a robot stops when its last cmd_vel is older than this [s].
        pump_timeout_s: a pump stops when its last "on" command is older than this [s].
        pump_offset_m: pump nozzle distance behind the robot's centre [m].
        ground_truth_rate_hz: rate of the true-pose output [Hz].
        seed: seed of every random draw in the world.
        sensors: the sensors the mission runs (a subset of :data:`SENSORS`, all by default).
            Each model draws from its own random stream, so leaving one out changes none of
            the others; a sensor left out is not built and costs nothing. Without ``gas``
            there is no scent field either (pumps then lay nothing).
        physics: the physics and ray-casting backend, a name of
            :data:`swarm_sim.physics.PHYSICS_BACKENDS`: 'numpy' (kinematic discs, exact 2D
            rays; fast) or 'pybullet' (rigid bodies with pybullet's contacts and ray tests).
        pybullet: settings of the pybullet backend (ignored by 'numpy').
        render: showing the run (pybullet only: a window or camera frames).
        aoa: non-line-of-sight effects on the AoA bearings (off: the ideal profile; see
            :mod:`swarm_sim.sensor_profiles`).
        faults: faults injected on purpose (none by default; see :mod:`swarm_sim.faults`).
    """

    physics_rate_hz: float = parameter(
        10.0, 'Physics steps per second of sim time.', unit='Hz', gt=0.0
    )
    cmd_vel_timeout_s: float = parameter(
        0.5, 'A robot stops when cmd_vel is older.', unit='s', gt=0.0
    )
    pump_timeout_s: float = parameter(
        1.0, 'A pump stops when its last "on" is older.', unit='s', gt=0.0
    )
    pump_offset_m: float = parameter(
        0.12, 'Pump nozzle distance behind the robot centre.', unit='m'
    )
    ground_truth_rate_hz: float = parameter(2.0, 'Rate of /sim/poses.', unit='Hz', gt=0.0)
    seed: int = parameter(
        0, 'Seed of every random draw in the world; equal seeds give equal runs.', ge=0
    )
    physics: str = parameter(
        'numpy',
        'Physics and ray-casting backend: numpy (kinematic discs, exact 2D rays; fast) or '
        'pybullet (rigid bodies, pybullet contacts and rayTestBatch; needs pybullet).',
        choices=tuple(PHYSICS_BACKENDS),
    )
    sensors: frozenset[str] = SENSORS
    body: BodyConfig = section(BodyConfig, prefix='')
    lidar: LidarConfig = section(LidarConfig, prefix='scan_')
    scent: ScentConfig = section(ScentConfig, prefix='scent_')
    gas: GasSensorConfig = section(GasSensorConfig, prefix='gas_')
    bearings: BearingConfig = section(BearingConfig, prefix='bearing_')
    imu: ImuConfig = section(ImuConfig, prefix='imu_')
    odometry: OdometryConfig = section(OdometryConfig, prefix='odom_')
    pybullet: PybulletConfig = field(default_factory=PybulletConfig)
    render: RenderConfig = field(default_factory=RenderConfig)
    aoa: AoaRealismConfig = section(AoaRealismConfig, prefix='aoa_')
    faults: FaultConfig = section(FaultConfig, prefix='fault_')

    def __post_init__(self) -> None:
        for name in ('physics_rate_hz', 'cmd_vel_timeout_s', 'pump_timeout_s'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                msg = f'{name} must be a positive finite number, got {value!r}'
                raise ConfigurationError(msg)
        if not self.ground_truth_rate_hz > 0.0:
            raise ConfigurationError('ground_truth_rate_hz must be positive')
        if self.seed < 0:
            msg = f'seed must be >= 0, got {self.seed}'
            raise ConfigurationError(msg)
        unknown = set(self.sensors) - SENSORS
        if unknown:
            msg = f'unknown sensors {sorted(unknown)}; choose from {sorted(SENSORS)}'
            raise ConfigurationError(msg)
        object.__setattr__(self, 'sensors', frozenset(self.sensors))
        if self.physics not in PHYSICS_BACKENDS:
            msg = (
                f'unknown physics backend {self.physics!r}; choose from '
                f'{", ".join(PHYSICS_BACKENDS)}'
            )
            raise ConfigurationError(msg)
        if self.render.mode != 'none' and self.physics != 'pybullet':
            msg = f'rendering ({self.render.mode}) needs the pybullet physics, not {self.physics!r}'
            raise ConfigurationError(msg)

    @property
    def physics_period_s(self) -> float:
        """Length of one physics step [s]."""
        return 1.0 / self.physics_rate_hz


@dataclass
class StepOutput:
    """Everything due after one physics step; ``None`` where a sensor was not due.

    Attributes:
        time_s: sim time at the end of the step [s].
        poses: (N, 3) true poses (always present).
        scans: (N, B) lidar ranges [m].
        gas_raw: (N,) gas readings on the 10-bit scale.
        bearings: one :class:`PeerBearings` per robot.
        bearing_cycle: the same reports in flat arrays, instead of ``bearings`` when the
            engine was built with ``bearing_cycles=True``.
        imu: (N,) integrated yaw [rad] and (N,) yaw rate [rad/s].
        odometry: (N, 3) odometry poses and (N, 2) speed [m/s] / yaw rate [rad/s].
        ground_truth_due: True when the true poses should be published.
        new_room_entries: rooms first entered during this step.
        withheld: per sensor name, (N,) bool of the robots whose reading of this step is
            not published (a faulty device; see :mod:`swarm_sim.faults`).
    """

    time_s: float
    poses: np.ndarray
    scans: np.ndarray | None = None
    gas_raw: np.ndarray | None = None
    bearings: list[PeerBearings] | None = None
    bearing_cycle: BearingCycle | None = None
    imu: tuple[np.ndarray, np.ndarray] | None = None
    odometry: tuple[np.ndarray, np.ndarray] | None = None
    ground_truth_due: bool = False
    new_room_entries: list[RoomEntry] = field(default_factory=list)
    withheld: dict[str, np.ndarray] = field(default_factory=dict)

    def published(self, sensor: str, robot: int) -> bool:
        """False when robot ``robot``'s reading of ``sensor`` this step is withheld."""
        mask = self.withheld.get(sensor)
        return mask is None or not mask[robot]


def _headings(poses: np.ndarray) -> np.ndarray:
    """(N, 2) unit vectors cos(yaw), sin(yaw) of (N, 3) poses."""
    headings = np.empty((len(poses), 2))
    np.cos(poses[:, 2], out=headings[:, 0])
    np.sin(poses[:, 2], out=headings[:, 1])
    return headings


class _Schedule:
    """Due times of a periodic output on a stepped clock."""

    def __init__(self, rate_hz: float) -> None:
        self.period_s = 1.0 / rate_hz
        self._next_s = self.period_s
        self.last_s = 0.0

    def due(self, time_s: float) -> tuple[bool, float]:
        """Return (due, time since the last output) and advance when due."""
        if time_s + 1e-9 < self._next_s:
            return False, 0.0
        while self._next_s <= time_s + 1e-9:
            self._next_s += self.period_s
        elapsed = time_s - self.last_s
        self.last_s = time_s
        return True, elapsed


class SimEngine:
    """N robots in a site, with every shared sensor and actuator.

    ``world`` is the physics backend the configuration names (:mod:`swarm_sim.physics`):
    it moves the robots and casts the rays. :meth:`close` releases it (a pybullet client,
    and writes the animation of a recorded run); the engine is also a context manager.
    """

    def __init__(
        self,
        site: SiteGeometry,
        initial_poses: np.ndarray,
        config: EngineConfig | None = None,
        *,
        bearing_cycles: bool = False,
        scan_horizon_m: float | None = None,
    ) -> None:
        """Build the world and its models.

        Args:
            site: walls and rooms.
            initial_poses: (N, 3) start poses x [m], y [m], yaw [rad].
            config: the world's configuration, with the sensors to run.
            bearing_cycles: hand the bearings over as one :class:`BearingCycle` of flat
                arrays (``StepOutput.bearing_cycle``) instead of a report per robot (the
                same values and random draws).
            scan_horizon_m: when given, scan ranges beyond it read ``inf`` (the others,
                and every random draw, as without it), and the lidar skips the walls that
                only farther rays reach (:meth:`LidarModel.measure`). For a consumer that
                reads no farther range; a bridge publishes the full scans.
        """
        self._bearing_cycles = bearing_cycles
        self._scan_horizon_m = scan_horizon_m
        self.config = config or EngineConfig()
        cfg = self.config
        self.site = site
        self.world: PhysicsBackend = make_physics(
            cfg.physics,
            PhysicsSetup(
                walls=site.walls,
                initial_poses=initial_poses,
                body=cfg.body,
                physics_period_s=cfg.physics_period_s,
                scan_bins=cfg.lidar.num_bins if 'scan' in cfg.sensors else None,
                pybullet=cfg.pybullet,
                render=cfg.render,
            ),
        )
        n = self.world.num_robots
        streams = np.random.SeedSequence(cfg.seed).spawn(5)
        rngs = [np.random.default_rng(s) for s in streams]
        self.sensors = cfg.sensors
        poses = self.world.poses
        # One random stream per sensor, in a fixed order, whichever sensors run.
        self.lidar: LidarModel | None = None
        self.scent: ScentField | None = None
        self._depositor: PumpDepositor | None = None
        self.gas: Mp503Model | None = None
        self.bearing_model: BearingModel | None = None
        self.imu: GyroYawModel | None = None
        self.odometry: WheelOdometry | None = None
        if 'scan' in self.sensors:
            self.lidar = LidarModel(self.world, cfg.lidar, rngs[0])
        if 'gas' in self.sensors:
            self.scent = ScentField(cfg.scent, self.world.walls)
            self._depositor = PumpDepositor(self.scent, n)
            self.gas = Mp503Model(n, cfg.gas, rngs[1])
        if 'bearings' in self.sensors:
            self.bearing_model = BearingModel(n, cfg.bearings, rngs[2], self.world.walls)
        if 'imu' in self.sensors:
            self.imu = GyroYawModel(poses[:, 2], cfg.imu, rngs[3])
        if 'odometry' in self.sensors:
            self.odometry = WheelOdometry(poses, cfg.odometry, rngs[4])
        # Step hooks: sensor realism, then faults; none in the ideal profile without faults.
        self.fault_plan: FaultPlan | None = None
        self._hooks: list[AoaRealism | FaultInjector] = []
        if cfg.aoa.active and self.bearing_model is not None:
            self._hooks.append(
                AoaRealism(cfg.aoa, n, self.world.walls, cfg.bearings.rate_hz, cfg.seed)
            )
        if cfg.faults.active:
            self.fault_plan = FaultPlan(cfg.faults, n, cfg.seed)
            self._hooks.append(FaultInjector(self.fault_plan, cfg.seed))
        self.coverage = CoverageTracker(
            site.room_rects, cfg.body.robot_radius_m, site.room_index_at
        )
        self._schedules = {
            'scan': _Schedule(cfg.lidar.rate_hz),
            'gas': _Schedule(cfg.gas.rate_hz),
            'bearings': _Schedule(cfg.bearings.rate_hz),
            'imu': _Schedule(cfg.imu.rate_hz),
            'odometry': _Schedule(cfg.odometry.rate_hz),
            'ground_truth': _Schedule(cfg.ground_truth_rate_hz),
        }
        self._command = np.zeros((n, 2))
        self._command_time_s = np.full(n, -np.inf)
        self._pump_on = np.zeros(n, dtype=bool)
        self._pump_time_s = np.full(n, -np.inf)
        self._imu_last_yaw = poses[:, 2].copy()
        self._step_index = 0
        self.time_s = 0.0
        self.distance_travelled_m = np.zeros(n)
        self.coverage.update(poses, 0.0)

    @property
    def num_robots(self) -> int:
        """Number of robots N."""
        return self.world.num_robots

    def close(self) -> None:
        """Release the physics backend (idempotent)."""
        self.world.close()

    def __enter__(self) -> SimEngine:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def step_index(self) -> int:
        """Number of physics steps taken so far."""
        return self._step_index

    def _check_robot(self, robot: int) -> None:
        if not 0 <= robot < self.num_robots:
            msg = f'robot index {robot} out of range 0..{self.num_robots - 1}'
            raise WorldGeometryError(msg)

    def _check_robots(self, robots: Sequence[int]) -> None:
        if robots and not 0 <= min(robots) <= max(robots) < self.num_robots:
            for robot in robots:
                self._check_robot(robot)  # raises for the first index out of range

    def set_velocity_command(self, robot: int, speed_mps: float, yaw_rate_radps: float) -> None:
        """Record a velocity command (non-finite values are taken as zero)."""
        self._check_robot(robot)
        v = speed_mps if math.isfinite(speed_mps) else 0.0
        w = yaw_rate_radps if math.isfinite(yaw_rate_radps) else 0.0
        self._command[robot] = (v, w)
        self._command_time_s[robot] = self.time_s

    def set_pump(self, robot: int, on: bool) -> None:
        """Record a pump command."""
        self._check_robot(robot)
        self._pump_on[robot] = bool(on)
        self._pump_time_s[robot] = self.time_s

    def set_velocity_commands(
        self, robots: Sequence[int], commands: Sequence[tuple[float, float]]
    ) -> None:
        """Record velocity commands of several robots at once: what
        :meth:`set_velocity_command` does for each, in one call.

        Args:
            robots: K distinct robot indices.
            commands: per robot, speed [m/s] and yaw rate [rad/s] (non-finite taken as zero).

        Raises:
            WorldGeometryError: a robot index is out of range (nothing is recorded).
            ValueError: the two sequences differ in length.
        """
        if len(robots) != len(commands):
            msg = f'{len(robots)} robots and {len(commands)} commands'
            raise ValueError(msg)
        self._check_robots(robots)
        # Element by element: cheaper than array operations for a few robots.
        command, command_time, now = self._command, self._command_time_s, self.time_s
        for robot, (v, w) in zip(robots, commands, strict=True):
            command[robot, 0] = v if math.isfinite(v) else 0.0
            command[robot, 1] = w if math.isfinite(w) else 0.0
            command_time[robot] = now

    def set_commands(
        self, robots: list[int], commands: list[tuple[float, float]], pumps: list[bool]
    ) -> None:
        """Record velocity and pump commands of several robots at once: what
        :meth:`set_velocity_command` and :meth:`set_pump` do for each, in one call.

        Args:
            robots: K distinct robot indices.
            commands: per robot, speed [m/s] and yaw rate [rad/s] (non-finite taken as zero).
            pumps: per robot, pump on.

        Raises:
            WorldGeometryError: a robot index is out of range (nothing is recorded).
            ValueError: the three lists differ in length.
        """
        if not len(robots) == len(commands) == len(pumps):
            msg = f'{len(robots)} robots, {len(commands)} commands and {len(pumps)} pump states'
            raise ValueError(msg)
        self.set_velocity_commands(robots, commands)
        pump_on, pump_time, now = self._pump_on, self._pump_time_s, self.time_s
        for robot, on in zip(robots, pumps, strict=True):
            pump_on[robot] = bool(on)
            pump_time[robot] = now

    def active_commands(self) -> np.ndarray:
        """(N, 2) commands in force now: stale ones are replaced by zero."""
        fresh = self.time_s - self._command_time_s <= self.config.cmd_vel_timeout_s + 1e-9
        return np.where(fresh[:, None], self._command, 0.0)

    def pumps_running(self) -> np.ndarray:
        """(N,) bool: pumps running now (stale "on" commands have timed out)."""
        fresh = self.time_s - self._pump_time_s <= self.config.pump_timeout_s + 1e-9
        return self._pump_on & fresh

    def nozzle_positions(self, poses: np.ndarray, headings: np.ndarray | None = None) -> np.ndarray:
        """(N, 2) pump nozzle positions [m] behind each robot (``headings``: the poses'
        :func:`_headings`, when the caller has them)."""
        off = self.config.pump_offset_m
        return poses[:, :2] - off * (_headings(poses) if headings is None else headings)

    def gas_sensor_positions(
        self, poses: np.ndarray, headings: np.ndarray | None = None
    ) -> np.ndarray:
        """(N, 2) gas sensor positions [m] ahead of each robot (``headings`` as for
        :meth:`nozzle_positions`)."""
        off = self.config.gas.sensor_offset_m
        return poses[:, :2] + off * (_headings(poses) if headings is None else headings)

    def step(self) -> StepOutput:
        """Advance one physics period and return what is due."""
        cfg = self.config
        dt = cfg.physics_period_s
        # active_commands() and pumps_running() in one compiled call.
        commands, pumping = actuators_kernel(
            self.time_s,
            self._command,
            self._command_time_s,
            cfg.cmd_vel_timeout_s + 1e-9,
            self._pump_on,
            self._pump_time_s,
            cfg.pump_timeout_s + 1e-9,
        )
        for hook in self._hooks:
            commands, pumping = hook.actuators(self.time_s, commands, pumping)
        before = self.world.poses
        self.world.step(commands, dt)
        self._step_index += 1
        self.time_s = self._step_index * dt
        poses = self.world.poses
        moved = poses[:, :2] - before[:, :2]
        self.distance_travelled_m += np.hypot(moved[:, 0], moved[:, 1])
        depositor = self._depositor
        if depositor is not None and depositor.busy(pumping):
            # nozzle_positions(poses) in compiled code.
            nozzles = body_points_kernel(poses, -cfg.pump_offset_m)
            depositor.step(pumping, nozzles, self.time_s, dt)
        out = StepOutput(time_s=self.time_s, poses=poses)
        out.new_room_entries = self.coverage.update(poses, self.time_s)
        # A disabled sensor's schedule is not consulted (it has no output to time).
        sched, now = self._schedules, self.time_s
        if self.lidar is not None and sched['scan'].due(now)[0]:
            out.scans = self.lidar.measure(poses, self._scan_horizon_m)
        if self.gas is not None and self.scent is not None:
            due, elapsed = sched['gas'].due(now)
            if due:
                # gas_sensor_positions(poses) in compiled code.
                sensors = body_points_kernel(poses, cfg.gas.sensor_offset_m)
                c = self.scent.concentration(sensors, now)
                out.gas_raw = self.gas.update(c, elapsed)
        if self.bearing_model is not None and sched['bearings'].due(now)[0]:
            if self._bearing_cycles:
                out.bearing_cycle = self.bearing_model.measure_cycle(poses)
            else:
                out.bearings = self.bearing_model.measure(poses)
        if self.imu is not None:
            due, elapsed = sched['imu'].due(now)
            if due:
                change = yaw_change_kernel(poses[:, 2], self._imu_last_yaw)
                self._imu_last_yaw = poses[:, 2].copy()
                out.imu = self.imu.update(change, elapsed)
        if self.odometry is not None:
            due, elapsed = sched['odometry'].due(now)
            if due:
                out.odometry = self.odometry.update(poses, elapsed)
        out.ground_truth_due = sched['ground_truth'].due(now)[0]
        for hook in self._hooks:
            hook.readings(out)
        return out
