"""Faults injected into a swarm on purpose: robots that drop out, lossy links, bad sensors.

One :class:`FaultConfig` describes the faults of a run; a :class:`FaultPlan` resolves it for
N robots and a seed: which robots fail, when, and how. Everything is deterministic from the
seed and drawn from random streams of its own, so a run without faults is bit-identical to a
run of a build without this module, and adding one fault changes no other random draw.

The same plan serves every simulator of the project:

* the engine (:class:`swarm_sim.engine.SimEngine`, hence the batch runners and the bridge
  node) applies it through :class:`FaultInjector`, a step hook that stops the dropped robots'
  drives and pumps and alters the readings after each physics step;
* the point-robot batch runners (Bayes-Swarm, MSC + PF) ask it who is dropped
  (:meth:`FaultPlan.dropped`), how the peer links behave (:attr:`FaultPlan.comm_range_m`,
  :attr:`FaultPlan.comm_loss_probability`) and what a faulty signal sensor reads
  (:meth:`FaultPlan.signal`).

Faults, with the robots each one hits taken from one seeded permutation of the robots (every
robot has at most one fault):

* **dropout**: ``dropout_robots`` robots stop for good at ``dropout_time_s`` (the node dies;
  the drive and the pump stop; the robot stays where it is, an obstacle for the others; its
  AoA tag keeps beaconing, it has its own battery);
* **stale lidar**: from ``sensor_time_s`` the lidar of ``stale_lidar_robots`` robots
  publishes nothing (a hung driver);
* **stuck gas**: the gas reading of ``stuck_gas_robots`` robots freezes at its value at the
  fault time; **drifting gas**: ``drifting_gas_robots`` robots read ``gas_drift_per_s``
  counts per second more and more (a heated or poisoned MOX sensor);
* **IMU yaw drift**: ``imu_drift_robots`` robots' integrated yaw drifts by
  ``imu_drift_radps`` (an uncalibrated gyro bias);
* **AoA dropouts**: from the fault time every AoA report is lost with
  ``bearing_dropout_probability`` (interference, a flaky locator);
* **peer links**: ``comm_range_m`` and ``comm_loss_probability`` limit the peer messages of
  Bayes-Swarm and MSC + PF on top of their own settings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import TYPE_CHECKING

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.params import parameter

from swarm_sim.errors import ConfigurationError
from swarm_sim.sensors.bearings import BearingCycle, PeerBearings

if TYPE_CHECKING:
    from swarm_sim.engine import StepOutput

__all__ = ['BODY_SENSOR_FAULTS', 'FAULT_KINDS', 'FaultConfig', 'FaultInjector', 'FaultPlan']

# Spawn keys of the fault streams: far from the engine's (0..4) and each other's.
_ROBOT_CHOICE_KEY = 0xFA0
_BEARING_KEY = 0xFA1
_RAW_MAX = 1023

# Per-robot faults, in the order their robots are taken from the permutation.
FAULT_KINDS = ('dropout', 'stale_lidar', 'stuck_gas', 'drifting_gas', 'imu_drift')


@dataclass(frozen=True)
class FaultConfig:
    """The faults of one run (all off by default).

    Attributes:
        dropout_robots: robots that stop for good at ``dropout_time_s``.
        dropout_time_s: when they stop [s].
        sensor_time_s: when the sensor faults start [s].
        stale_lidar_robots: robots whose lidar stops publishing.
        stuck_gas_robots: robots whose gas reading freezes.
        drifting_gas_robots: robots whose gas reading drifts upwards.
        gas_drift_per_s: drift of those readings [10-bit counts / s].
        imu_drift_robots: robots whose integrated yaw drifts.
        imu_drift_radps: that drift [rad/s].
        bearing_dropout_probability: chance that one AoA report is lost, every robot.
        comm_range_m: largest distance of a peer message [m] (inf: the algorithm's own).
        comm_loss_probability: chance that one peer message to one receiver is lost, on top
            of the algorithm's own losses.
    """

    dropout_robots: int = parameter(
        0, 'Robots (chosen from the seed) that stop for good at fault_dropout_time_s.', ge=0
    )
    dropout_time_s: float = parameter(0.0, 'When the dropped robots stop.', unit='s', ge=0.0)
    sensor_time_s: float = parameter(0.0, 'When the sensor faults start.', unit='s', ge=0.0)
    stale_lidar_robots: int = parameter(0, 'Robots whose lidar stops publishing.', ge=0)
    stuck_gas_robots: int = parameter(0, 'Robots whose gas reading freezes.', ge=0)
    drifting_gas_robots: int = parameter(0, 'Robots whose gas reading drifts up.', ge=0)
    gas_drift_per_s: float = parameter(
        2.0, 'Drift of the drifting gas readings (10-bit counts per second).', unit='1/s'
    )
    imu_drift_robots: int = parameter(0, 'Robots whose integrated yaw drifts.', ge=0)
    imu_drift_radps: float = parameter(
        math.radians(0.5), 'Yaw drift of those robots.', unit='rad/s'
    )
    bearing_dropout_probability: float = parameter(
        0.0, 'Chance that one AoA report is lost, every robot.', ge=0.0, le=1.0
    )
    comm_range_m: float = parameter(
        math.inf,
        'Range of the peer messages (inf: only the algorithm limit applies).',
        unit='m',
        gt=0.0,
        finite=False,
    )
    comm_loss_probability: float = parameter(
        0.0, 'Chance that one peer message to one receiver is lost.', ge=0.0, le=1.0
    )

    def __post_init__(self) -> None:
        for name in ('dropout_time_s', 'sensor_time_s'):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0.0):
                msg = f'{name} must be a finite number >= 0, got {value!r}'
                raise ConfigurationError(msg)
        for kind in FAULT_KINDS:
            count = getattr(self, f'{kind}_robots')
            if count < 0:
                msg = f'{kind}_robots must be >= 0, got {count}'
                raise ConfigurationError(msg)
        for name in ('bearing_dropout_probability', 'comm_loss_probability'):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                msg = f'{name} must be in [0, 1], got {value!r}'
                raise ConfigurationError(msg)
        if not self.comm_range_m > 0.0:
            msg = f'comm_range_m must be positive, got {self.comm_range_m!r}'
            raise ConfigurationError(msg)
        for name in ('gas_drift_per_s', 'imu_drift_radps'):
            if not math.isfinite(getattr(self, name)):
                msg = f'{name} must be finite, got {getattr(self, name)!r}'
                raise ConfigurationError(msg)

    @property
    def faulty_robots(self) -> int:
        """How many robots have a fault of their own."""
        return sum(getattr(self, f'{kind}_robots') for kind in FAULT_KINDS)

    @property
    def active(self) -> bool:
        """True when some fault is configured."""
        return self != FaultConfig()

    def describe(self) -> str:
        """The faults that differ from the defaults, as ``name=value`` items."""
        default = FaultConfig()
        items = [
            f'{f.name}={getattr(self, f.name)}'
            for f in fields(self)
            if getattr(self, f.name) != getattr(default, f.name)
        ]
        return ', '.join(items) or 'none'

    def configured(self, names: tuple[str, ...]) -> list[str]:
        """Those of the fields ``names`` that differ from the defaults."""
        default = FaultConfig()
        return [n for n in names if getattr(self, n) != getattr(default, n)]


# The faults that need a lidar, an IMU or AoA reports, which the point-robot runners lack.
BODY_SENSOR_FAULTS = (
    'stale_lidar_robots',
    'imu_drift_robots',
    'imu_drift_radps',
    'bearing_dropout_probability',
)


class FaultPlan:
    """A :class:`FaultConfig` resolved for N robots and a seed.

    Attributes:
        config: the faults.
        num_robots: N.
        robots: per fault kind (:data:`FAULT_KINDS`), the (sorted) indices of its robots.

    Raises:
        ConfigurationError: more faulty robots than robots.
    """

    def __init__(self, config: FaultConfig, num_robots: int, seed: int) -> None:
        if config.faulty_robots > num_robots:
            msg = f'{config.faulty_robots} faulty robots asked for, but only {num_robots} robots'
            raise ConfigurationError(msg)
        self.config = config
        self.num_robots = num_robots
        order = np.random.default_rng(
            np.random.SeedSequence(seed, spawn_key=(_ROBOT_CHOICE_KEY,))
        ).permutation(num_robots)
        self.robots: dict[str, np.ndarray] = {}
        start = 0
        for kind in FAULT_KINDS:
            count = getattr(config, f'{kind}_robots')
            self.robots[kind] = np.sort(order[start : start + count])
            start += count
        self._masks = {kind: self._mask(idx) for kind, idx in self.robots.items()}

    def _mask(self, indices: np.ndarray) -> np.ndarray:
        mask = np.zeros(self.num_robots, dtype=bool)
        mask[indices] = True
        return mask

    def mask(self, kind: str) -> np.ndarray:
        """(N,) bool: the robots with fault ``kind`` (one of :data:`FAULT_KINDS`)."""
        return self._masks[kind]

    def dropped(self, time_s: float) -> np.ndarray:
        """(N,) bool: the robots dropped out by ``time_s``."""
        if time_s + 1e-9 < self.config.dropout_time_s:
            return np.zeros(self.num_robots, dtype=bool)
        return self._masks['dropout']

    def sensors_faulty(self, time_s: float) -> bool:
        """True once the sensor faults have started."""
        return time_s + 1e-9 >= self.config.sensor_time_s

    @property
    def comm_range_m(self) -> float:
        """Range of the peer messages [m] (inf: no limit of the plan's own)."""
        return self.config.comm_range_m

    @property
    def comm_loss_probability(self) -> float:
        """Chance that one peer message to one receiver is lost (the plan's own share)."""
        return self.config.comm_loss_probability

    def combined_loss(self, own_loss: float) -> float:
        """The loss of a link that loses ``own_loss`` of its messages and then the plan's."""
        if self.config.comm_loss_probability == 0.0:
            return own_loss
        return 1.0 - (1.0 - own_loss) * (1.0 - self.config.comm_loss_probability)

    def combined_range_m(self, own_range_m: float | None) -> float | None:
        """The shorter of a link's own range (None: unlimited) and the plan's."""
        if math.isinf(self.config.comm_range_m):
            return own_range_m
        if own_range_m is None:
            return self.config.comm_range_m
        return min(own_range_m, self.config.comm_range_m)

    def signal(self, robot: int, value: float, time_s: float, held: dict[int, float]) -> float:
        """What robot ``robot``'s signal sensor reads at ``time_s`` when the truth is ``value``:
        frozen for a stuck sensor (at its first reading in fault time, kept in ``held``),
        plus the drift (in the sensor's units per second) for a drifting one."""
        if not self.sensors_faulty(time_s):
            return value
        if self._masks['stuck_gas'][robot]:
            return held.setdefault(robot, value)
        if self._masks['drifting_gas'][robot]:
            onset = self.config.sensor_time_s
            return value + self.config.gas_drift_per_s * (time_s - onset)
        return value


class FaultInjector:
    """The engine's step hook of a :class:`FaultPlan`: drives, pumps and readings.

    Args:
        plan: the resolved faults.
        seed: the world's seed (the AoA dropouts draw from a stream of their own).
    """

    def __init__(self, plan: FaultPlan, seed: int) -> None:
        self.plan = plan
        self._rng = np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(_BEARING_KEY,)))
        self._stuck_gas: np.ndarray | None = None

    def actuators(
        self, time_s: float, commands: np.ndarray, pumping: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The commands and pump states in force after the dropouts (copies when changed)."""
        dropped = self.plan.dropped(time_s)
        if not dropped.any():
            return commands, pumping
        return np.where(dropped[:, None], 0.0, commands), pumping & ~dropped

    def readings(self, out: StepOutput) -> None:
        """Alter the readings of one step in place (faults that have not started do nothing)."""
        plan = self.plan
        if not plan.sensors_faulty(out.time_s):
            return
        cfg = plan.config
        t = out.time_s - cfg.sensor_time_s
        if out.scans is not None and cfg.stale_lidar_robots:
            out.withheld['scan'] = plan.mask('stale_lidar')
        if out.gas_raw is not None:
            out.gas_raw = self._gas(out.gas_raw, t)
        if out.imu is not None and cfg.imu_drift_robots:
            yaw, rate = out.imu
            drift = np.where(plan.mask('imu_drift'), cfg.imu_drift_radps, 0.0)
            yaw = np.asarray(wrap_angle(yaw + drift * t), dtype=float)
            out.imu = (yaw, rate + drift)
        if cfg.bearing_dropout_probability > 0.0:
            if out.bearing_cycle is not None:
                out.bearing_cycle = self._drop_cycle(out.bearing_cycle)
            if out.bearings is not None:
                out.bearings = [self._drop_report(r) for r in out.bearings]

    def _gas(self, raw: np.ndarray, t: float) -> np.ndarray:
        plan, cfg = self.plan, self.plan.config
        if not (cfg.stuck_gas_robots or cfg.drifting_gas_robots):
            return raw
        raw = np.asarray(raw).copy()
        stuck = plan.mask('stuck_gas')
        if stuck.any():
            if self._stuck_gas is None:
                self._stuck_gas = raw[stuck].copy()
            raw[stuck] = self._stuck_gas
        drifting = plan.mask('drifting_gas')
        if drifting.any():
            drifted = np.rint(raw[drifting] + cfg.gas_drift_per_s * t)
            raw[drifting] = np.clip(drifted, 0, _RAW_MAX).astype(raw.dtype)
        return raw

    def _keep(self, count: int) -> np.ndarray:
        return self._rng.random(count) >= self.plan.config.bearing_dropout_probability

    def _drop_cycle(self, cycle: BearingCycle) -> BearingCycle:
        keep = self._keep(len(cycle.receivers))
        receivers = cycle.receivers[keep]
        return BearingCycle(
            receivers=receivers,
            tags=cycle.tags[keep],
            azimuth_rad=cycle.azimuth_rad[keep],
            elevation_rad=cycle.elevation_rad[keep],
            distance_m=cycle.distance_m[keep],
            sequence=cycle.sequence[keep],
            bounds=np.searchsorted(receivers, np.arange(len(cycle.bounds))).tolist(),
        )

    def _drop_report(self, report: PeerBearings) -> PeerBearings:
        keep = self._keep(len(report.tags))
        return PeerBearings(
            receiver=report.receiver,
            tags=report.tags[keep],
            azimuth_rad=report.azimuth_rad[keep],
            elevation_rad=report.elevation_rad[keep],
            distance_m=report.distance_m[keep],
            sequence=report.sequence[keep],
        )
