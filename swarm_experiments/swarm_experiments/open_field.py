"""The world of the Bayes-Swarm and MSC missions: point robots in an open field.

Both papers treat robots as points that sense their own pose and the mission's signal (a
scalar field, RSSI), with no obstacles: the robots are 1 mm discs (so they never block each
other, not even at a common depot) and the engine runs odometry alone, at the physics rate.
The mission's own sensing comes from its extension (signal, RSSI).
"""

from __future__ import annotations

from swarm_sim.engine import EngineConfig
from swarm_sim.sensors.odometry import OdometryConfig
from swarm_sim.world import BodyConfig

__all__ = ['POINT_ROBOT_RADIUS_M', 'point_robot_engine_config']

POINT_ROBOT_RADIUS_M = 1e-3


def point_robot_engine_config(
    *,
    physics_rate_hz: float,
    seed: int,
    max_linear_speed_mps: float,
    max_angular_speed_radps: float = 2.0,
) -> EngineConfig:
    """Engine configuration of point robots that sense only their odometry.

    Args:
        physics_rate_hz: physics and odometry rate [Hz].
        seed: seed of the world.
        max_linear_speed_mps: forward speed limit [m/s].
        max_angular_speed_radps: yaw rate limit [rad/s].
    """
    return EngineConfig(
        physics_rate_hz=physics_rate_hz,
        seed=seed,
        sensors=frozenset({'odometry'}),
        body=BodyConfig(
            robot_radius_m=POINT_ROBOT_RADIUS_M,
            max_linear_speed_mps=max_linear_speed_mps,
            max_angular_speed_radps=max_angular_speed_radps,
        ),
        odometry=OdometryConfig(rate_hz=physics_rate_hz),
    )
