"""The simulated robots' transform tree (REP 105), as :class:`PlanarTransform` lists.

Per robot ``r<i>`` the bridge publishes

* on ``/tf``, at the odometry rate: ``r<i>/odom -> r<i>/base_link``, the pose of the
  published ``r<i>/odom`` message (same stamp, same numbers);
* on ``/tf_static``, once (latched): ``map -> r<i>/odom`` and the sensor mounts
  ``r<i>/base_link -> r<i>/laser``, ``r<i>/imu_link``, ``r<i>/gas_sensor``.

``map`` is the site's frame (the ``world`` of the ``/sim/...`` ground truth). The static
``map -> odom`` transform is where the odometry frame lies in the site at the start:
``T(map, base_link at t=0) * T(odom, base_link at t=0)^-1``. The simulator's odometry starts
at the true start pose in site coordinates (a shared frame, as the Bayes-Swarm and MSC papers
assume), so this is the identity; if odometry drifts (odometry noise), ``map -> odom ->
base_link`` is where the robot believes it is, and ``/sim/poses`` where it is.

Pure functions; the bridge node does the publishing through :mod:`swarm_runtime.tf`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from swarm_common.angles import wrap_angle
from swarm_common.frames import (
    BASE_LINK,
    GAS_SENSOR,
    IMU_LINK,
    LASER,
    MAP_FRAME,
    ODOM,
    robot_frame,
)
from swarm_runtime.tf import PlanarTransform

__all__ = [
    'SensorMounts',
    'compose',
    'invert',
    'odometry_transforms',
    'static_transforms',
]


def compose(a: Sequence[float], b: Sequence[float]) -> tuple[float, float, float]:
    """The planar pose ``a * b`` (x, y, yaw): ``b`` expressed in ``a``'s parent frame."""
    ax, ay, ayaw = (float(v) for v in a)
    bx, by, byaw = (float(v) for v in b)
    c, s = math.cos(ayaw), math.sin(ayaw)
    return ax + c * bx - s * by, ay + s * bx + c * by, float(wrap_angle(ayaw + byaw))


def invert(a: Sequence[float]) -> tuple[float, float, float]:
    """The inverse of the planar pose ``a`` (x, y, yaw)."""
    ax, ay, ayaw = (float(v) for v in a)
    c, s = math.cos(ayaw), math.sin(ayaw)
    return -c * ax - s * ay, s * ax - c * ay, float(wrap_angle(-ayaw))


class SensorMounts:
    """Where the simulated sensors sit on the robot, in base_link [m].

    The lidar and the IMU are at the robot's centre (the ray caster casts from there); the
    gas sensor is ``gas_offset_m`` ahead (``GasSensorConfig.sensor_offset_m``). The world is
    planar, so every height is 0.
    """

    def __init__(self, gas_offset_m: float) -> None:
        self.gas_offset_m = float(gas_offset_m)

    def transforms(self, robot: str) -> list[PlanarTransform]:
        """``<robot>/base_link -> <robot>/laser``, ``imu_link`` and ``gas_sensor``."""
        base = robot_frame(robot, BASE_LINK)
        return [
            PlanarTransform(base, robot_frame(robot, LASER)),
            PlanarTransform(base, robot_frame(robot, IMU_LINK)),
            PlanarTransform(base, robot_frame(robot, GAS_SENSOR), x_m=self.gas_offset_m),
        ]


def static_transforms(
    robot_names: Sequence[str],
    true_start_poses: np.ndarray,
    odometry_start_poses: np.ndarray | None,
    mounts: SensorMounts,
) -> list[PlanarTransform]:
    """Every robot's static frames: ``map -> odom`` (when odometry runs) and the mounts.

    Args:
        robot_names: r0, r1, ...
        true_start_poses: (N, 3) true poses at t = 0 in the site frame.
        odometry_start_poses: (N, 3) odometry poses at t = 0, or None without odometry.
        mounts: the sensors' positions on the robot.
    """
    transforms: list[PlanarTransform] = []
    for i, robot in enumerate(robot_names):
        if odometry_start_poses is not None:
            true_start, odometry_start = true_start_poses[i], odometry_start_poses[i]
            # Equal starts (the simulator's odometry) give exactly the identity.
            x, y, yaw = (
                (0.0, 0.0, 0.0)
                if np.array_equal(true_start, odometry_start)
                else compose(true_start, invert(odometry_start))
            )
            transforms.append(
                PlanarTransform(MAP_FRAME, robot_frame(robot, ODOM), x_m=x, y_m=y, yaw_rad=yaw)
            )
        transforms += mounts.transforms(robot)
    return transforms


def odometry_transforms(robot_names: Sequence[str], poses: np.ndarray) -> list[PlanarTransform]:
    """``r<i>/odom -> r<i>/base_link`` of each robot's (N, 3) odometry pose."""
    return [
        PlanarTransform(
            robot_frame(robot, ODOM),
            robot_frame(robot, BASE_LINK),
            x_m=float(pose[0]),
            y_m=float(pose[1]),
            yaw_rad=float(pose[2]),
        )
        for robot, pose in zip(robot_names, poses, strict=True)
    ]
