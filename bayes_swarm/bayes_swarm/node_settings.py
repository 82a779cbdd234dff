"""The bayes_swarm node's parameters and the frozen settings they give (ROS-free).

Every parameter is a field of :class:`NodeSettings` or of the planner and baseline
configurations it holds (:class:`~bayes_swarm.settings.BayesSwarmConfig` at the top level,
its arena as ``arena_*``, the baselines as ``levy_*``, ``glowworm_*``, ``exhaustive_*``).
:data:`BAYES_SWARM_PARAMETERS` is the spec the node declares and the spawner reads
``--param`` with; ``config/bayes_swarm.yaml`` and the table in docs/bayes_swarm.md are
generated from it. The case files (``config/case1.yaml``, ...) set the case's values on top.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from swarm_common.params import ParameterSpec, parameter, section

from bayes_swarm.errors import ParameterError
from bayes_swarm.follower import FollowerConfig
from bayes_swarm.settings import (
    BayesSwarmConfig,
    ExhaustiveConfig,
    GlowwormConfig,
    LevyConfig,
)

__all__ = [
    'ALGORITHMS',
    'BAYES_SWARM_PARAMETERS',
    'NODE_NAME',
    'NodeSettings',
    'settings_from_values',
]

NODE_NAME = 'bayes_swarm'
ALGORITHMS = ('bayes_swarm_p', 'bayes_swarm_o', 'glowworm', 'levy', 'exhaustive')


@dataclass(frozen=True)
class NodeSettings:
    """Everything the node needs, validated.

    ``planner.penalty_enabled`` follows ``algorithm`` (only Bayes-Swarm-P penalises); the
    follower's speed and slow-down distance follow ``velocity_mps`` and ``control_rate_hz``
    (:attr:`follower`).
    """

    algorithm: str = parameter('bayes_swarm_p', 'the algorithm this robot runs', choices=ALGORITHMS)
    seed: int = parameter(0, "seed of this robot's random draws", ge=0)
    planner: BayesSwarmConfig = section(BayesSwarmConfig, prefix='')
    initial_direction_offset_deg: float = parameter(
        0.0, 'heading the first-decision fan starts at', unit='deg'
    )
    fan_index: int | None = parameter(
        None, 'position r in the first-decision fan (-1: robot_index + 1)', ge=1, none=-1
    )
    fan_size: int | None = parameter(
        None, 'robots sharing the first-decision fan (-1: n_robots)', ge=1, none=-1
    )
    levy: LevyConfig = section(LevyConfig, prefix='levy_')
    glowworm: GlowwormConfig = section(GlowwormConfig, prefix='glowworm_')
    exhaustive: ExhaustiveConfig = section(ExhaustiveConfig, prefix='exhaustive_')
    control_rate_hz: float = parameter(20.0, 'waypoint follower rate', unit='Hz', gt=0.0)
    arrival_tolerance_m: float = parameter(
        0.01, 'distance at which a waypoint is reached', unit='m', gt=0.0, read_only=False
    )
    max_turn_rate_radps: float = parameter(
        2.0, 'yaw-rate limit of the follower', unit='rad/s', gt=0.0, read_only=False
    )
    odom_timeout_s: float = parameter(
        0.5, 'stop when odometry is older than this', unit='s', gt=0.0, read_only=False
    )

    def __post_init__(self) -> None:
        penalty = self.algorithm == 'bayes_swarm_p'
        if self.planner.penalty_enabled != penalty:
            planner = dataclasses.replace(self.planner, penalty_enabled=penalty)
            object.__setattr__(self, 'planner', planner)

    @property
    def follower(self) -> FollowerConfig:
        """The waypoint follower's configuration: cruise at V, slow down over two periods."""
        speed = self.planner.velocity_mps
        return FollowerConfig(
            speed_mps=speed,
            arrival_tolerance_m=self.arrival_tolerance_m,
            max_turn_rate_radps=self.max_turn_rate_radps,
            slow_down_m=2.0 * speed / self.control_rate_hz,
        )


BAYES_SWARM_PARAMETERS = ParameterSpec(NodeSettings, error=ParameterError)


def settings_from_values(values: Mapping[str, Any]) -> NodeSettings:
    """Validate parameter values (missing names take their defaults).

    Raises:
        ConfigError: an unknown name or a bad value (:class:`ParameterError`, naming the
            parameter), or values that do not fit together.
    """
    return BAYES_SWARM_PARAMETERS.build(values)
