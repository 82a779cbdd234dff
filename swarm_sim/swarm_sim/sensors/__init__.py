"""ROS-free sensor models of the simulated robots, each seeded and documented with units.

Every model takes the world's true state and returns what the real device would report; the
bridge node only turns those numbers into messages.
"""

from swarm_sim.sensors.bearings import BearingConfig, BearingModel, PeerBearings
from swarm_sim.sensors.gas_sensor import GasSensorConfig, Mp503Model
from swarm_sim.sensors.imu import GyroYawModel, ImuConfig
from swarm_sim.sensors.lidar import LidarConfig, LidarModel
from swarm_sim.sensors.odometry import OdometryConfig, WheelOdometry
from swarm_sim.sensors.scent import ScentConfig, ScentField

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
