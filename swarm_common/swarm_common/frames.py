"""Frame ids of the swarm's transform tree (REP 105), shared by the simulator and the robots.

Every robot ``<robot>`` (r0, r1, ...) has its own frames, prefixed with its name::

    map                         (simulation only: the site's frame)
    └── <robot>/odom            (odometry frame)
        └── <robot>/base_link   (robot centre on the floor, x forward, y left, z up)
            ├── <robot>/laser        lidar (scan)
            ├── <robot>/imu_link     IMU (imu)
            └── <robot>/gas_sensor   gas sensor (gas)

Bearings (AoA) and every other robot-frame reading use ``<robot>/base_link``.
"""

from __future__ import annotations

__all__ = [
    'BASE_LINK',
    'GAS_SENSOR',
    'IMU_LINK',
    'LASER',
    'MAP_FRAME',
    'ODOM',
    'SENSOR_FRAMES',
    'robot_frame',
]

MAP_FRAME = 'map'
ODOM = 'odom'
BASE_LINK = 'base_link'
LASER = 'laser'
IMU_LINK = 'imu_link'
GAS_SENSOR = 'gas_sensor'
#: The sensor frames below base_link, in the order they are published.
SENSOR_FRAMES = (LASER, IMU_LINK, GAS_SENSOR)


def robot_frame(robot: str, frame: str) -> str:
    """The frame id of ``frame`` on robot ``robot``: ``robot_frame('r0', 'laser')`` is
    ``'r0/laser'``; an empty robot name gives the bare frame."""
    return f'{robot}/{frame}' if robot else frame
