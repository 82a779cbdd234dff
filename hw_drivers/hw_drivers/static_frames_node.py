"""Static frames node: latches where the sensors sit on the robot on ``/tf_static``.

It publishes ``<prefix>base_link -> <prefix>laser``, ``<prefix>imu_link`` and
``<prefix>gas_sensor`` once (tf2_msgs/TFMessage, reliable, transient local, as
``static_transform_publisher`` does), so a viewer places the scans and readings of the
drivers on the robot. The frames follow the simulator's (``r0/laser``, ...);
``robot_bringup`` starts this node with ``frame_prefix:=<robot>/``. The offsets are the
mounting positions in base_link (x forward, y left, z up, metres); the defaults are the
simulator's robot model (lidar and IMU at the centre, the gas sensor 8 cm ahead) and should
be measured on a real build. The drivers already turn their data into the robot's axes (the
lidar's ``zero_offset_rad``, the IMU's ``mounting``), so every frame keeps base_link's
orientation.

The odometry transform ``odom -> base_link`` belongs to the robot base's driver, and there is
no ``map`` frame on a robot unless a localization publishes ``map -> odom``.

Run: ``ros2 run hw_drivers static_frames_node --ros-args -r __ns:=/r0 -p frame_prefix:=r0/``.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence
from typing import Any

from swarm_common.frames import BASE_LINK, GAS_SENSOR, IMU_LINK, LASER
from swarm_runtime.parameters import declare_config
from swarm_runtime.ros import Node
from swarm_runtime.tf import (
    PlanarTransform,
    StaticTransformPublisher,
    TfUnavailableError,
    tf_message_class,
)

from hw_drivers.errors import ConfigurationError
from hw_drivers.node_common import run_driver_node
from hw_drivers.parameters import STATIC_FRAMES_PARAMETERS

__all__ = ['StaticFramesNode', 'main', 'mount_transforms']

# Parameter -> child frame.
_MOUNTS = (('laser_xyz_m', LASER), ('imu_xyz_m', IMU_LINK), ('gas_sensor_xyz_m', GAS_SENSOR))


def mount_transforms(prefix: str, offsets: Mapping[str, Sequence[float]]) -> list[PlanarTransform]:
    """The static transforms of the sensor mounts ``offsets`` (parameter name -> x, y, z).

    Raises:
        ConfigurationError: an offset is not three finite numbers.
    """
    transforms = []
    for name, child in _MOUNTS:
        values = [float(v) for v in offsets[name]]
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            msg = f'{name} must be three finite numbers x, y, z [m], got {list(offsets[name])}'
            raise ConfigurationError(msg)
        x, y, z = values
        transforms.append(PlanarTransform(prefix + BASE_LINK, prefix + child, x, y, z))
    return transforms


class StaticFramesNode(Node):
    """Latches the sensor mounting frames of one robot on ``/tf_static``.

    Raises:
        ConfigurationError: a mounting offset is invalid.
        TfUnavailableError: tf2_msgs is not installed.
    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('static_frames_node', **kwargs)
        config = declare_config(self, STATIC_FRAMES_PARAMETERS).config
        offsets = {name: getattr(config, name) for name, _ in _MOUNTS}
        transforms = mount_transforms(config.frame_prefix, offsets)
        self._publisher = StaticTransformPublisher(self)
        now_s = self.get_clock().now().nanoseconds * 1e-9
        self._publisher.send(transforms, now_s)
        self.get_logger().info(
            'static frames: '
            + ', '.join(
                f'{t.parent} -> {t.child} ({t.x_m:g}, {t.y_m:g}, {t.z_m:g}) m' for t in transforms
            )
        )


def main(args: list[str] | None = None) -> int:
    """Entry point of ``ros2 run hw_drivers static_frames_node``; exits 2 with one line where
    tf2_msgs is not installed."""
    argv = list(sys.argv[1:] if args is None else args)
    own = argv[: argv.index('--ros-args')] if '--ros-args' in argv else argv
    if not {'-h', '--help'} & set(own):
        try:
            tf_message_class()
        except TfUnavailableError as err:
            sys.stderr.write(f'static_frames_node: {err}\n')
            raise SystemExit(2) from None
    return run_driver_node(
        StaticFramesNode,
        'static_frames_node',
        args,
        summary=__doc__ or '',
        parameters=STATIC_FRAMES_PARAMETERS,
    )


if __name__ == '__main__':
    raise SystemExit(main())
