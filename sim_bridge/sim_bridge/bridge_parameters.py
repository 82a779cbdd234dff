"""The bridge node's parameters: the engine configuration plus the bridge's own (ROS-free).

Every parameter is a field of :class:`BridgeNodeConfig`: the bridge's own settings (robots
and site when none are given, the wall-clock pace, the peer relay, coverage messages) and,
at the top level, the parameters of :class:`swarm_sim.engine.EngineConfig` and its sensor
sections (``scan_*``, ``gas_*``, ``scent_*``, ``bearing_*``, ``imu_*``, ``odom_*``).
:data:`BRIDGE_PARAMETERS` is the spec the node declares; ``config/sim_bridge.yaml`` and the
table in docs/simulation.md are generated from it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from swarm_common.params import ParameterError, ParameterSpec, parameter, section
from swarm_sim.engine import EngineConfig
from swarm_sim.errors import ConfigurationError

__all__ = [
    'BRIDGE_PARAMETERS',
    'NODE_NAME',
    'BridgeNodeConfig',
    'BridgeParameterError',
    'config_from_values',
]

NODE_NAME = 'sim_bridge'


class BridgeParameterError(ConfigurationError, ParameterError):
    """A bridge parameter is unknown, of the wrong type, out of range or not a choice."""


@dataclass(frozen=True)
class BridgeNodeConfig:
    """Everything the bridge node reads from its parameters."""

    engine: EngineConfig = section(EngineConfig, prefix='')
    robot_count: int = parameter(
        1, 'robots r0..r{n-1} when the bridge places them itself (ignored with start poses)', ge=1
    )
    site_file: str = parameter(
        '',
        'site when none is given: small/medium/big preset (seeded), a .lay layout or a site file',
    )
    departure: str = parameter('center', 'departure point of the site (center, edge)')
    heading_bias_rad: float = parameter(0.0, 'common bias of the departure fan', unit='rad')
    real_time_factor: float = parameter(
        1.0, 'sim seconds per wall second of the physics timer', gt=0.0, read_only=False
    )
    peer_msg_type: str = parameter('', "peer message type to relay ('' = no relay)")
    comm_range_m: float = parameter(
        math.inf, 'peer relay range; .inf = unlimited', unit='m', gt=0.0, finite=False
    )
    peer_loss_probability: float = parameter(
        0.0, 'chance one relayed message is lost', ge=0.0, le=1.0
    )
    coverage_rate_hz: float = parameter(
        1.0, 'rate of the periodic /sim/coverage message', unit='Hz', gt=0.0
    )
    tf_rate_hz: float = parameter(10.0, 'most /tf messages per sim second', unit='Hz', gt=0.0)
    path_rate_hz: float = parameter(
        0.5, 'rate of the robot paths on /sim/markers/paths', unit='Hz', gt=0.0
    )
    mission_file: str = parameter(
        '',
        'JSON mission file: site, start poses, sensors and extensions (sim_bridge.mission_file); '
        'overrides site_file, robot_count and departure',
    )
    max_sim_time_s: float = parameter(
        math.inf,
        'end the mission at this sim time: write outcome_file and exit 0; .inf = never',
        unit='s',
        gt=0.0,
        finite=False,
    )
    stop_when_all_rooms_covered: bool = parameter(
        False, 'also end the mission once every room is covered'
    )
    outcome_file: str = parameter(
        '',
        "JSON file the mission's outcome is written to at its end or stop ('' = none); with "
        "it, an extension's end also ends the mission",
    )
    trajectory_period_s: float = parameter(
        0.5, 'sim-time interval of the true poses kept for outcome_file', unit='s', gt=0.0
    )
    start_after_clock_subscribers: int = parameter(
        0,
        'wait until /clock has this many subscribers (robots, recorder) before the first step',
        ge=0,
    )


BRIDGE_PARAMETERS = ParameterSpec(BridgeNodeConfig, error=BridgeParameterError)


def config_from_values(values: Mapping[str, Any], base: EngineConfig | None = None) -> EngineConfig:
    """The engine configuration from bridge parameter values (missing names keep ``base``'s).

    Raises:
        ConfigurationError: an unknown name, a bad value (:class:`BridgeParameterError`), or
            values the engine configuration rejects together.
    """
    node_base = None if base is None else BridgeNodeConfig(engine=base)
    return BRIDGE_PARAMETERS.build(values, node_base).engine
