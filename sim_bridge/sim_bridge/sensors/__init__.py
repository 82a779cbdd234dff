"""ROS-free sensor models of the simulated robots, each seeded and documented with units.

Every model takes the world's true state and returns what the real device would report; the
bridge node only turns those numbers into messages.
"""

from sim_bridge.sensors.bearings import BearingConfig, BearingModel, PeerBearings
from sim_bridge.sensors.gas_sensor import GasSensorConfig, Mp503Model
from sim_bridge.sensors.imu import GyroYawModel, ImuConfig
from sim_bridge.sensors.lidar import LidarConfig, LidarModel
from sim_bridge.sensors.odometry import OdometryConfig, WheelOdometry
from sim_bridge.sensors.scent import ScentConfig, ScentField

__all__ = [
    'BearingConfig',
    'BearingModel',
    'GasSensorConfig',
    'GyroYawModel',
    'ImuConfig',
    'LidarConfig',
    'LidarModel',
    'Mp503Model',
    'OdometryConfig',
    'PeerBearings',
    'ScentConfig',
    'ScentField',
    'WheelOdometry',
]
