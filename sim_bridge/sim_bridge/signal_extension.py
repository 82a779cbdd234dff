"""Signal-field mission for the sim bridge (Bayes-Swarm-P study), as a SimExtension.

The ROS-free :class:`SignalMissionModel` samples the case's field at every robot's true
position on the observation clock (t = k / f_Hz), adds optional Gaussian noise, and detects
the source: a robot within eps of it ends the mission, as does T_max. It also computes tau
(Eq. 12) from the true source and the finder's start position.

The adapter :class:`SignalExtension` publishes, per robot, ``/<name>/signal``
(swarm_interfaces/SignalSample, sensor QoS) and, for the bag, ``/sim/source_search``
(swarm_interfaces/SourceSearchStatus, ground truth the algorithm nodes never read).
Detection is checked on the straight segment between two physics steps, so it does not
depend on the physics rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from swarm_common.segments import first_entry_fraction
from swarm_common.stamps import stamp_from_seconds
from swarm_runtime.ros import message_module, qos_profile_sensor_data

from sim_bridge.extensions import RobotStates
from sim_bridge.signal_fields import SignalCase

__all__ = ['SignalExtension', 'SignalMissionModel', 'SignalSampleBatch']

_STATUS_PERIOD_S = 1.0
_EPS_T = 1e-9


@dataclass(frozen=True)
class SignalSampleBatch:
    """Samples of one observation tick: time [s] and (N,) values in robot order."""

    time_s: float
    values: np.ndarray


class SignalMissionModel:
    """Sampling, detection and tau of a signal-field mission (no ROS)."""

    def __init__(
        self,
        case: SignalCase,
        *,
        noise_std: float = 0.0,
        relative_noise: float = 0.0,
        seed: int = 0,
        max_mission_time_s: float | None = None,
    ) -> None:
        if noise_std < 0.0 or relative_noise < 0.0:
            msg = 'noise_std and relative_noise must be >= 0'
            raise ValueError(msg)
        self.case = case
        self.noise_std = noise_std
        self.relative_noise = relative_noise
        self.max_mission_time_s = (
            case.max_mission_time_s if max_mission_time_s is None else max_mission_time_s
        )
        self._rng = np.random.default_rng(seed)
        self._period_s = 1.0 / case.observation_rate_hz
        self._next_tick = 0
        self._last_positions: np.ndarray | None = None
        self._last_time_s = 0.0
        self.starts: np.ndarray | None = None
        self.found_time_s = math.nan
        self.finder = -1
        self.time_s = 0.0

    @property
    def found(self) -> bool:
        return self.finder >= 0

    @property
    def done(self) -> bool:
        return self.found or self.time_s >= self.max_mission_time_s - _EPS_T

    def tau(self) -> float:
        """Relative completion time (Eq. 12) of the finder, NaN if not found."""
        if not self.found or self.starts is None:
            return math.nan
        ideal = self.case.ideal_time_s(self.starts[self.finder])
        return (self.found_time_s - ideal) / ideal

    def sample(self, positions_m: np.ndarray) -> np.ndarray:
        """(N,) noisy field values at (N, 2) positions."""
        values = np.asarray(self.case.field(positions_m), dtype=float)
        std = self.noise_std + self.relative_noise * np.abs(values)
        if np.any(std > 0.0):
            values = values + std * self._rng.standard_normal(values.shape)
        return values

    def step(self, time_s: float, positions_m: np.ndarray) -> SignalSampleBatch | None:
        """Advance to ``time_s`` with the robots at (N, 2) positions; samples if one is due."""
        pos = np.asarray(positions_m, dtype=float)[:, :2]
        if self.starts is None:
            self.starts = pos.copy()
            self._last_positions = pos.copy()
            self._last_time_s = time_s
        if not self.found:
            self._detect(time_s, pos)
        self._last_positions = pos.copy()
        self._last_time_s = time_s
        self.time_s = time_s
        if time_s + _EPS_T >= self._next_tick * self._period_s:
            self._next_tick = math.floor(time_s / self._period_s + _EPS_T) + 1
            return SignalSampleBatch(time_s, self.sample(pos))
        return None

    def _detect(self, time_s: float, pos: np.ndarray) -> None:
        best: tuple[float, int] | None = None
        for i, (p0, p1) in enumerate(zip(self._last_positions, pos, strict=True)):
            s = first_entry_fraction(p0, p1, self.case.source_m, self.case.detection_radius_m)
            if s is not None:
                t_hit = self._last_time_s + s * (time_s - self._last_time_s)
                if best is None or t_hit < best[0]:
                    best = (t_hit, i)
        if best is not None:
            self.found_time_s, self.finder = best


class SignalExtension:
    """SimExtension publishing ``signal`` per robot and ``/sim/source_search``.

    After the mission ends it lingers ``linger_s`` of sim time before reporting done, so a
    recorder still receives the final status and true poses past the detection.
    """

    def __init__(self, model: SignalMissionModel, linger_s: float = 1.0) -> None:
        self.model = model
        self.linger_s = linger_s
        self._end_time_s: float | None = None
        self._time_s = 0.0
        self._signal_pubs: list[Any] = []
        self._status_pub: Any = None
        self._names: tuple[str, ...] = ()
        self._next_status_s = 0.0
        self._final_sent = False
        self._swarm = message_module('swarm_interfaces')
        self._builtin = message_module('builtin_interfaces')

    def attach(self, node: Any, robot_names: tuple[str, ...]) -> None:
        self._names = tuple(robot_names)
        self._signal_pubs = [
            node.create_publisher(self._swarm.SignalSample, f'/{n}/signal', qos_profile_sensor_data)
            for n in robot_names
        ]
        self._status_pub = node.create_publisher(
            self._swarm.SourceSearchStatus, '/sim/source_search', 10
        )

    def _stamp(self, time_s: float) -> Any:
        return stamp_from_seconds(time_s, self._builtin.Time)

    def on_step(self, sim_time_s: float, states: RobotStates) -> None:
        self._time_s = sim_time_s
        if self._final_sent:
            return
        batch = self.model.step(sim_time_s, states.poses[:, :2])
        if batch is not None:
            stamp = self._stamp(batch.time_s)
            for i, (pub, value) in enumerate(zip(self._signal_pubs, batch.values, strict=True)):
                msg = self._swarm.SignalSample()
                msg.header.stamp = stamp
                msg.header.frame_id = f'{self._names[i]}/base_link'
                msg.value = float(value)
                pub.publish(msg)
        if self.model.done or sim_time_s + _EPS_T >= self._next_status_s:
            self._status_pub.publish(self.status_message(sim_time_s))
            self._next_status_s = sim_time_s + _STATUS_PERIOD_S
            self._final_sent = self.model.done
            if self._final_sent:
                self._end_time_s = sim_time_s

    def status_message(self, time_s: float) -> Any:
        """The SourceSearchStatus describing the mission at ``time_s``."""
        m = self.model
        case = m.case
        msg = self._swarm.SourceSearchStatus()
        msg.header.stamp = self._stamp(time_s)
        msg.header.frame_id = 'map'
        msg.case_name = case.name
        msg.source_x, msg.source_y = (float(v) for v in case.source_m)
        msg.detection_radius_m = float(case.detection_radius_m)
        msg.velocity_mps = float(case.velocity_mps)
        msg.max_mission_time_s = float(m.max_mission_time_s)
        msg.robots = list(self._names)
        starts = m.starts if m.starts is not None else np.zeros((len(self._names), 2))
        msg.start_x = [float(v) for v in starts[:, 0]]
        msg.start_y = [float(v) for v in starts[:, 1]]
        msg.found = m.found
        msg.finder = self._names[m.finder] if m.found else ''
        msg.found_time_s = float(m.found_time_s)
        msg.tau = float(m.tau())
        msg.done = m.done
        return msg

    def is_done(self) -> bool:
        return self._end_time_s is not None and self._time_s >= self._end_time_s + self.linger_s
