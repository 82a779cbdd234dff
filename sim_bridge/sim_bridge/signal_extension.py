"""Signal-field mission for the sim bridge (Bayes-Swarm-P study), as a SimExtension.

The ROS-free model is :class:`swarm_sim.signal_mission.SignalMissionModel` (sampling on the
observation clock, noise, continuous detection, tau). The adapter :class:`SignalExtension`
publishes, per robot, ``/<name>/signal`` (swarm_interfaces/SignalSample, sensor QoS) and,
for the bag, ``/sim/source_search`` (swarm_interfaces/SourceSearchStatus, ground truth the
algorithm nodes never read) and ``/sim/markers/targets`` (visualization_msgs/MarkerArray,
latched, :mod:`sim_bridge.markers`): the source with its detection radius, red until a robot
finds it, then green; sent at the start and when the source is found.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from swarm_common.stamps import stamp_from_seconds
from swarm_runtime.ros import message_module, qos_profile_sensor_data
from swarm_sim.signal_mission import SignalMissionModel

from sim_bridge import markers
from sim_bridge.extensions import RobotStates

__all__ = ['SignalExtension']

_STATUS_PERIOD_S = 1.0
_EPS_T = 1e-9
_SOURCE_RGBA = (0.85, 0.15, 0.15, 1.0)
_FOUND_RGBA = (0.2, 0.7, 0.2, 1.0)


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
        self._markers_pub: Any = None
        self._found_shown = False
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
        try:
            marker_class = message_module('visualization_msgs').MarkerArray
        except (ImportError, AttributeError, LookupError):
            self._markers_pub = None  # the bridge has logged that markers are off
        else:
            self._markers_pub = node.create_publisher(
                marker_class, markers.TARGETS_TOPIC, markers.marker_qos()
            )
            self._markers_pub.publish(self.source_markers(0.0))

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
        if self.model.found and not self._found_shown and self._markers_pub is not None:
            self._found_shown = True
            self._markers_pub.publish(self.source_markers(sim_time_s))
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

    def source_markers(self, time_s: float) -> Any:
        """The /sim/markers/targets MarkerArray at ``time_s``: the source, red until found,
        then green, with its detection radius."""
        case = self.model.case
        x0, x1, y0, y1 = case.arena_m
        unit = max(max(x1 - x0, y1 - y0) / 150.0, 0.01)
        colour = _FOUND_RGBA if self.model.found else _SOURCE_RGBA
        return markers.target_markers(
            np.asarray(case.source_m, dtype=float).reshape(1, 2),
            1.5 * unit,
            [colour],
            ['source'],
            unit,
            time_s,
            area_radius_m=float(case.detection_radius_m),
        )

    def is_done(self) -> bool:
        return self._end_time_s is not None and self._time_s >= self._end_time_s + self.linger_s
