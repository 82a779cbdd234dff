"""What the sim bridge publishes for viewers: the transform tree and the site's markers.

:class:`BridgeVisualization` is attached to the bridge node and called after every physics
step. It publishes

* ``/tf``: ``r<i>/odom -> r<i>/base_link`` from the odometry output, at most ``tf_rate_hz``
  (every odometry output up to that rate), only while somebody subscribes;
* ``/tf_static`` (latched, once): ``map -> r<i>/odom`` and the sensor mounts
  (:mod:`sim_bridge.frames`);
* the ``/sim/markers/...`` topics of :mod:`sim_bridge.markers`: the site and the robot bodies
  once, the rooms at start and whenever a room is first entered, the paths every
  1 / ``path_rate_hz`` s of sim time while somebody subscribes.

Each part switches itself off with one warning where its message package is not installed
(tf2_msgs has no pip wheel for real rclpy).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from swarm_runtime.ros import message_module
from swarm_runtime.tf import StaticTransformPublisher, TfUnavailableError, TransformPublisher
from swarm_sim.engine import SimEngine, StepOutput

from sim_bridge import frames, markers

__all__ = ['BridgeVisualization']

_EPS_S = 1e-9
# Path simplification [m]: largest distance of a dropped sample from the drawn path, and
# the smallest move recorded.
_PATH_TOLERANCE_M = 0.1
_PATH_MIN_STEP_M = 0.02


class BridgeVisualization:
    """Transforms and markers of one bridge.

    Args:
        node: the bridge node (publishers are created on it).
        engine: the simulated world.
        robot_names: r0, r1, ... in engine order.
        site_model: the :class:`swarm_sim.sites.model.Site`, or None (geometry only).
        tf_rate_hz: most ``/tf`` messages per second of sim time.
        path_rate_hz: ``/sim/markers/paths`` messages per second of sim time.
    """

    def __init__(
        self,
        node: Any,
        engine: SimEngine,
        robot_names: tuple[str, ...],
        site_model: Any,
        *,
        tf_rate_hz: float,
        path_rate_hz: float,
    ) -> None:
        self._engine = engine
        self._names = robot_names
        self._tf_period_s = 1.0 / tf_rate_hz
        self._path_period_s = 1.0 / path_rate_hz
        self._next_tf_s = 0.0
        self._next_path_s = self._path_period_s
        logger = node.get_logger()
        self._tf: TransformPublisher | None = None
        self._tf_static: StaticTransformPublisher | None = None
        try:
            self._tf = TransformPublisher(node)
            self._tf_static = StaticTransformPublisher(node)
        except TfUnavailableError as err:
            logger.warning(str(err))
        site = engine.site
        scene = [np.asarray(site.walls, dtype=float).reshape(-1, 2), engine.world.poses[:, :2]]
        scene += [np.asarray(r, dtype=float).reshape(-1, 4).reshape(-1, 2) for r in site.room_rects]
        self.unit_m = markers.marker_unit_m(np.concatenate(scene))
        self._model_rooms = list(site_model.rooms) if site_model is not None else []
        self._polygons = [room.polygon for room in self._model_rooms]
        self._paths = markers.PathRecorder(engine.world.poses, _PATH_TOLERANCE_M, _PATH_MIN_STEP_M)
        self._marker_pubs: dict[str, Any] = {}
        self._sent_paths = tuple((1, *xy) for xy in engine.world.poses[:, :2])
        try:
            marker_class = message_module('visualization_msgs').MarkerArray
        except (ImportError, AttributeError, LookupError) as err:
            logger.warning(f'visualization_msgs is not available, so /sim/markers is off: {err}')
        else:
            qos = markers.marker_qos()
            for topic in (
                markers.SITE_TOPIC,
                markers.ROOMS_TOPIC,
                markers.ROBOTS_TOPIC,
                markers.PATHS_TOPIC,
            ):
                self._marker_pubs[topic] = node.create_publisher(marker_class, topic, qos)
        self._publish_static_frames()
        self._publish_site()

    # Start ------------------------------------------------------------------------------

    def _publish_static_frames(self) -> None:
        if self._tf_static is None:
            return
        engine = self._engine
        odometry = engine.odometry.poses if engine.odometry is not None else None
        mounts = frames.SensorMounts(engine.config.gas.sensor_offset_m)
        self._tf_static.send(
            frames.static_transforms(self._names, engine.world.poses, odometry, mounts),
            engine.time_s,
        )

    def _room_labels(self) -> list[tuple[str, tuple[float, float]]]:
        labels = []
        rooms = self._engine.site.room_rects
        models = self._model_rooms
        for index, rects in enumerate(rooms):
            r = np.asarray(rects, dtype=float).reshape(-1, 4)
            if len(r):
                areas = (r[:, 2] - r[:, 0]) * (r[:, 3] - r[:, 1])
                x0, y0, x1, y1 = r[int(np.argmax(areas))]
                centre = (0.5 * (x0 + x1), 0.5 * (y0 + y1))
            elif index < len(self._polygons) and self._polygons[index] is not None:
                centre = tuple(np.mean(self._polygons[index], axis=0))
            else:
                continue
            text = models[index].label if index < len(models) and models[index].label else ''
            labels.append((text or str(index), centre))
        return labels

    def _publish_site(self) -> None:
        if not self._marker_pubs:
            return
        engine = self._engine
        body = engine.config.body
        wall_width = max(body.wall_thickness_m, 0.5 * self.unit_m)
        self._marker_pubs[markers.SITE_TOPIC].publish(
            markers.site_markers(
                engine.site.walls, wall_width, self._room_labels(), self.unit_m, engine.time_s
            )
        )
        self._marker_pubs[markers.ROBOTS_TOPIC].publish(
            markers.robot_markers(self._names, body.robot_radius_m, self.unit_m)
        )
        self._publish_rooms()

    def _publish_rooms(self) -> None:
        engine = self._engine
        first = {e.room_index: e.robot_index for e in engine.coverage.entries}
        self._marker_pubs[markers.ROOMS_TOPIC].publish(
            markers.room_markers(
                engine.site.room_rects, first, len(self._names), engine.time_s, self._polygons
            )
        )

    # Every step --------------------------------------------------------------------------

    def on_step(self, out: StepOutput) -> None:
        """Publish what is due after the physics step ``out``."""
        t = out.time_s
        if self._tf is not None and out.odometry is not None and t + _EPS_S >= self._next_tf_s:
            self._next_tf_s = t + self._tf_period_s
            if self._tf.wanted():
                self._tf.send(frames.odometry_transforms(self._names, out.odometry[0]), t)
        if not self._marker_pubs:
            return
        if out.ground_truth_due:
            self._paths.add(out.poses)
        if out.new_room_entries:
            self._publish_rooms()
        if t + _EPS_S >= self._next_path_s:
            self._next_path_s = t + self._path_period_s
            publisher = self._marker_pubs[markers.PATHS_TOPIC]
            if publisher.get_subscription_count():
                self._paths.add(out.poses)
                paths = [self._paths.path(i) for i in range(self._paths.num_robots)]
                # Robots that stand still (or have not moved yet) change nothing to send.
                key = tuple((len(p), *p[-1]) for p in paths)
                if key != self._sent_paths:
                    self._sent_paths = key
                    publisher.publish(markers.path_markers(paths, 0.4 * self.unit_m, t))
