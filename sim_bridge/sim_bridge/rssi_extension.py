"""RSSI targets in the sim bridge (MSC + PF mission), as a SimExtension.

The ROS-free model is :class:`swarm_sim.rssi_targets.RssiTargetField`. This adapter, every
physics step:

* lets robots that stand still within D_th of a target work on it (R_w load/s each) and,
  when a target is captured, publishes its ID on ``/<name>/captured``
  (swarm_interfaces/CapturedTargets) of the robots that worked on it;
* every ``sample_period_s`` publishes each robot's ``/<name>/rssi``
  (swarm_interfaces/RssiArray, sensor QoS): one noisy sample of every detectable,
  uncaptured target;
* every ``status_period_s`` and at each capture publishes ``/sim/targets``
  (swarm_interfaces/RssiTargetArray), the ground truth the algorithm nodes never read;
* at the start and at each capture latches ``/sim/markers/targets`` (visualization_msgs/
  MarkerArray, :mod:`sim_bridge.markers`): every target with its work area D_th, orange
  until captured, then green.

The mission is done one physics step after the step that captured the last target, so the
final ``/sim/targets`` message reaches subscribers (e.g. a bag recorder) before the run stops.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from swarm_common.stamps import stamp_from_seconds
from swarm_runtime.ros import message_module, qos_profile_sensor_data
from swarm_sim.rssi_targets import Capture, RssiTargetField

from sim_bridge import markers
from sim_bridge.extensions import RobotStates

__all__ = ['RssiExtension']

_EPS_T = 1e-9
_OPEN_RGBA = (0.95, 0.45, 0.1, 1.0)
_CAPTURED_RGBA = (0.2, 0.7, 0.2, 1.0)


class RssiExtension:
    """SimExtension publishing ``rssi`` and ``captured`` per robot and ``/sim/targets``."""

    def __init__(
        self,
        targets: RssiTargetField,
        *,
        seed: int = 0,
        sample_period_s: float = 1.0,
        status_period_s: float = 1.0,
    ) -> None:
        """Wrap ``targets``; ``seed`` drives the receiver noise."""
        if not (sample_period_s > 0.0 and status_period_s > 0.0):
            raise ValueError('sample_period_s and status_period_s must be positive')
        self.targets = targets
        self.captures: list[Capture] = []
        self._rng = np.random.default_rng([seed, 1])
        self._sample_period_s = sample_period_s
        self._status_period_s = status_period_s
        self._next_sample = 1
        self._next_status_s = 0.0
        self._last_time_s: float | None = None
        self._final_published = False
        self._done = False
        self._names: tuple[str, ...] = ()
        self._rssi_pubs: list[Any] = []
        self._captured_pubs: list[Any] = []
        self._targets_pub: Any = None
        self._markers_pub: Any = None
        self._swarm = message_module('swarm_interfaces')
        self._builtin = message_module('builtin_interfaces')

    def attach(self, node: Any, robot_names: tuple[str, ...]) -> None:
        """Create the publishers on the bridge node."""
        self._names = tuple(robot_names)
        swarm = self._swarm
        self._rssi_pubs = [
            node.create_publisher(swarm.RssiArray, f'/{n}/rssi', qos_profile_sensor_data)
            for n in robot_names
        ]
        self._captured_pubs = [
            node.create_publisher(swarm.CapturedTargets, f'/{n}/captured', 10) for n in robot_names
        ]
        self._targets_pub = node.create_publisher(swarm.RssiTargetArray, '/sim/targets', 10)
        try:
            marker_class = message_module('visualization_msgs').MarkerArray
        except (ImportError, AttributeError, LookupError):
            self._markers_pub = None  # the bridge has logged that markers are off
        else:
            self._markers_pub = node.create_publisher(
                marker_class, markers.TARGETS_TOPIC, markers.marker_qos()
            )
            self._markers_pub.publish(self.targets_markers(0.0))

    def _stamp(self, time_s: float) -> Any:
        return stamp_from_seconds(time_s, self._builtin.Time)

    def on_step(self, sim_time_s: float, states: RobotStates) -> None:
        """Work, capture, sample and publish for the physics step ending at ``sim_time_s``."""
        self._done = self._final_published
        positions = np.asarray(states.poses, dtype=float)[:, :2]
        dt = 0.0 if self._last_time_s is None else sim_time_s - self._last_time_s
        self._last_time_s = sim_time_s
        captures = []
        if dt > 0.0:
            speeds = np.abs(np.asarray(states.velocities, dtype=float)[:, 0])
            captures = self.targets.work(positions, speeds, dt, sim_time_s)
        if captures and self._markers_pub is not None:
            self._markers_pub.publish(self.targets_markers(sim_time_s))
        for capture in captures:
            self.captures.append(capture)
            msg = self._swarm.CapturedTargets(target_ids=[capture.target_id])
            msg.header.stamp = self._stamp(sim_time_s)
            for robot in capture.robot_indices:
                self._captured_pubs[robot].publish(msg)
        if sim_time_s + _EPS_T >= self._next_sample * self._sample_period_s:
            self._next_sample = math.floor(sim_time_s / self._sample_period_s + _EPS_T) + 1
            self._publish_rssi(sim_time_s, positions)
        if captures or sim_time_s + _EPS_T >= self._next_status_s:
            self._targets_pub.publish(self.targets_message(sim_time_s))
            self._next_status_s = sim_time_s + self._status_period_s
            self._final_published = self._final_published or self.targets.all_captured

    def _publish_rssi(self, time_s: float, positions: np.ndarray) -> None:
        samples = self.targets.sample_rssi(positions, self._rng)
        stamp = self._stamp(time_s)
        for i, pub in enumerate(self._rssi_pubs):
            msg = self._swarm.RssiArray()
            msg.header.stamp = stamp
            msg.header.frame_id = f'{self._names[i]}/base_link'
            msg.readings = [
                self._swarm.EmitterRssi(emitter_id=int(t), rssi_dbm=float(samples[i, t]))
                for t in np.flatnonzero(~np.isnan(samples[i]))
            ]
            pub.publish(msg)

    def targets_message(self, time_s: float) -> Any:
        """The /sim/targets ground truth at ``time_s``."""
        field = self.targets
        msg = self._swarm.RssiTargetArray()
        msg.header.stamp = self._stamp(time_s)
        msg.header.frame_id = 'map'
        msg.targets = [
            self._swarm.RssiTarget(
                target_id=i,
                x=float(field.positions_m[i, 0]),
                y=float(field.positions_m[i, 1]),
                remaining_load=float(max(field.remaining_load[i], 0.0)),
                captured=bool(field.captured[i]),
                capture_time_s=float(field.capture_time_s[i]),
            )
            for i in range(field.config.n_targets)
        ]
        msg.all_captured = field.all_captured
        times = field.capture_time_s
        msg.capture_completion_time_s = float(np.max(times)) if field.all_captured else math.nan
        return msg

    def targets_markers(self, time_s: float) -> Any:
        """The /sim/markers/targets MarkerArray at ``time_s``: one sphere per target, orange
        until captured, then green, with its work area (D_th) and its ID."""
        field = self.targets
        config = field.config
        unit = max(config.field_size_m / 150.0, 0.01)
        colours = [_CAPTURED_RGBA if c else _OPEN_RGBA for c in field.captured]
        return markers.target_markers(
            field.positions_m,
            1.5 * unit,
            colours,
            [f'T{i}' for i in range(config.n_targets)],
            unit,
            time_s,
            area_radius_m=config.task_area_m,
        )

    def is_done(self) -> bool:
        """True one step after every target was captured and reported."""
        return self._done
